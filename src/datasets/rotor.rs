//! `pump-rotor`: the impeller of a centrifugal pump, a full 360° ring of 7 backward-swept,
//! twisted, thick blades between a curved hub and shroud (see [`super::ring`] for the mesh).
//!
//! Geometry (lengths in units of the impeller's outer radius):
//! - radii: `r_in = 0.30` (eye), leading edge `r_le = 0.36`, trailing edge `r_te = 0.94`,
//!   `r_out = 1.00`; with `s = (r − 0.30)/0.70`,
//! - hub `z = 0.10 (1 − s)²`, shroud `z = 0.10 + 0.35 (1 − s)²`: the channel is 0.35 high at
//!   the eye and 0.10 at the rim; all points lie in `0 ≤ z ≤ 0.45`;
//! - blade camber `θ_c(r, ζ) = −(1.7 ln(r/0.30) + 0.3 s²) + 0.35 (ζ − 0.5)(1 − s)²`: a
//!   backward-swept spiral (about 135° of wrap; blade angle from 30° to the tangent at the
//!   eye to 21° at the rim) twisted
//!   from hub (`ζ = 0`) to shroud (`ζ = 1`), most near the eye;
//! - blade thickness `0.028 · 2.598 √c (1 − c)` along the chord fraction `c` (round leading
//!   edge, sharp trailing edge, 0.028 at most);
//! - 12 % of the radial cells upstream of the blades, 12 % downstream; clustering strengths
//!   2.0 (radial, towards the blade edges), 2.5 (azimuthal, towards the blades), 3.0 (axial,
//!   towards hub and shroud); resolution shape `nr : nt : nz = 1 : 0.85 : 0.35` (`nt` per
//!   passage): 2.1 M cells are (12 + 78 + 12) × 7·84 × 35 = 2,099,160.
//!
//! Fields: `pressure` rises with radius (centrifugal, `0.10 + 0.50 (r² − r_in²)/(r_out² − r_in²)`),
//! with blade loading (pressure side above suction side, `±0.10 sin²(π c)`), blade wakes
//! (a 0.06 deficit around the trailing edge, decaying across the passage), and a hub-to-shroud
//! variation; `velocity` is the absolute velocity: the meridional through-flow along the
//! channel (slower in the wakes and near the walls) plus a swirl growing with radius.

use std::f64::consts::PI;

use super::field::{gaussian, loading, wake};
use super::ring::{RingNode, RingShape};

const R_IN: f64 = 0.30;
const R_OUT: f64 = 1.00;

fn s_of(r: f64) -> f64 {
    (r - R_IN) / (R_OUT - R_IN)
}

fn hub(r: f64) -> f64 {
    0.10 * (1.0 - s_of(r)).powi(2)
}

fn shroud(r: f64) -> f64 {
    0.10 + 0.35 * (1.0 - s_of(r)).powi(2)
}

fn camber(r: f64, zeta: f64) -> f64 {
    let s = s_of(r);
    -(1.7 * (r / R_IN).ln() + 0.3 * s * s) + 0.35 * (zeta - 0.5) * (1.0 - s).powi(2)
}

fn thickness(c: f64) -> f64 {
    0.028 * 2.598 * c.max(0.0).sqrt() * (1.0 - c)
}

fn field(n: &RingNode) -> (f64, [f64; 3]) {
    let q = (n.r * n.r - R_IN * R_IN) / (R_OUT * R_OUT - R_IN * R_IN);
    let load = loading(n.chord);
    let side = 2.0 * n.phase - 1.0;
    let w = wake(n.phase, 5.0) * gaussian(n.r, 0.97, 0.08);
    let axial = 0.04 * (n.zeta - 0.5) * (1.0 - n.s) + 0.015 * (PI * n.zeta).sin() * n.s;
    let pressure = 0.10 + 0.50 * q + 0.10 * load * side - 0.06 * w + axial;

    let height = shroud(n.r) - hub(n.r);
    let through = 0.35 * (R_IN * 0.35) / (n.r * height);
    let cm = through * (0.55 + 0.45 * (PI * n.zeta).sin()) * (1.0 - 0.3 * w);
    let norm = (1.0 + n.dzdr * n.dzdr).sqrt();
    let swirl = n.r * (0.15 + 0.55 * n.s) - 0.08 * load * side - 0.1 * w;
    (pressure, [cm / norm, swirl, cm * n.dzdr / norm])
}

/// The rotor ring.
pub(crate) const SHAPE: RingShape = RingShape {
    blades: 7,
    radii: [R_IN, 0.36, 0.94, R_OUT],
    zone_share: [0.12, 0.12],
    hub,
    shroud,
    camber,
    thickness,
    beta: [2.0, 2.5, 3.0],
    weights: [1.0, 0.85, 0.35],
    field,
};
