//! `pump-diffuser`: the vaned diffuser around the impeller, a full 360° widening annulus with
//! 11 log-spiral vanes (see [`super::ring`] for the mesh).
//!
//! Geometry (units of the impeller's outer radius, as for `pump-rotor`):
//! - radii: `r_in = 1.05`, vane leading edge `r_le = 1.12`, trailing edge `r_te = 1.62`,
//!   `r_out = 1.80`; with `s = (r − 1.05)/0.75`,
//! - axial width `b(r) = 0.11 (1 + 1.3 s²)` (0.11 → 0.253) about a mid-height
//!   `z_m(r) = 0.05 + 0.03 s²`: walls at `z_m ∓ b/2`; all points lie in `−0.0465 ≤ z ≤ 0.2065`;
//! - vane camber `θ_c(r, ζ) = 2.4 ln(r/1.05) + 0.06 (ζ − 0.5) s`: a logarithmic spiral at
//!   22.6° from the tangent, turning with the impeller's swirl (74° of wrap), slightly leaned;
//! - vane thickness `0.035 · 2.598 √c (1 − c)` along the chord fraction `c`;
//! - 10 % of the radial cells upstream of the vanes (the vaneless gap), 18 % downstream;
//!   clustering 2.0 / 2.5 / 3.0 (radial / azimuthal / axial); resolution shape
//!   `nr : nt : nz = 1 : 0.9 : 0.3` (`nt` per passage): 3.4 M cells are
//!   (11 + 75 + 19) × 11·92 × 32 = 3,400,320.
//!
//! Fields: `pressure` recovers with radius (`0.60 + 0.40 (1 − (r_in/r)²)/(1 − (r_in/r_out)²)`),
//! carries the 7 impeller wakes spiralling out with the flow and fading with radius, the vane
//! loading and the vane wakes, and varies across the width; `velocity` is the through-flow
//! (slowing as the annulus widens) plus a swirl decaying like a free vortex.

use std::f64::consts::{PI, TAU};

use super::field::{gaussian, loading, wake};
use super::ring::{RingNode, RingShape};

const R_IN: f64 = 1.05;
const R_OUT: f64 = 1.80;

fn s_of(r: f64) -> f64 {
    (r - R_IN) / (R_OUT - R_IN)
}

fn width(r: f64) -> f64 {
    let s = s_of(r);
    0.11 * (1.0 + 1.3 * s * s)
}

fn middle(r: f64) -> f64 {
    let s = s_of(r);
    0.05 + 0.03 * s * s
}

fn hub(r: f64) -> f64 {
    middle(r) - 0.5 * width(r)
}

fn shroud(r: f64) -> f64 {
    middle(r) + 0.5 * width(r)
}

fn camber(r: f64, zeta: f64) -> f64 {
    2.4 * (r / R_IN).ln() + 0.06 * (zeta - 0.5) * s_of(r)
}

fn thickness(c: f64) -> f64 {
    0.035 * 2.598 * c.max(0.0).sqrt() * (1.0 - c)
}

fn field(n: &RingNode) -> (f64, [f64; 3]) {
    let recovery = (1.0 - (R_IN / n.r).powi(2)) / (1.0 - (R_IN / R_OUT).powi(2));
    // Impeller wakes: 7 lobes convected along the absolute flow's spiral.
    let spiral = n.theta - 2.2 * (n.r / R_IN).ln();
    let rotor_wakes = (-(n.r - R_IN) / 0.15).exp() * wake(7.0 * spiral / TAU, 3.0);
    let load = loading(n.chord);
    let side = 2.0 * n.phase - 1.0;
    let w = wake(n.phase, 5.0) * gaussian(n.r, 1.66, 0.10);
    let across = 0.03 * (n.zeta - 0.5) + 0.02 * (TAU * n.zeta).cos() * (1.0 - n.s);
    let pressure =
        0.60 + 0.40 * recovery - 0.05 * rotor_wakes + 0.06 * load * side - 0.05 * w + across;

    let through = 0.4 * (R_IN * 0.11) / (n.r * width(n.r));
    let cm = through * (0.55 + 0.45 * (PI * n.zeta).sin()) * (1.0 - 0.3 * w - 0.2 * rotor_wakes);
    let norm = (1.0 + n.dzdr * n.dzdr).sqrt();
    let swirl = 0.55 * R_IN / n.r * (1.0 + 0.1 * rotor_wakes) - 0.05 * load * side;
    (pressure, [cm / norm, swirl, cm * n.dzdr / norm])
}

/// The diffuser ring.
pub(crate) const SHAPE: RingShape = RingShape {
    blades: 11,
    radii: [R_IN, 1.12, 1.62, R_OUT],
    zone_share: [0.10, 0.18],
    hub,
    shroud,
    camber,
    thickness,
    beta: [2.0, 2.5, 3.0],
    weights: [1.0, 0.9, 0.3],
    field,
};
