//! `pump-inlet`: the suction pipe in front of the impeller eye, a pipe about the z axis meshed
//! as an O-grid ("butterfly"): a central H-block of `n × n` cells surrounded by four O-blocks
//! of `n × m` cells each reaching the wall, stacked in `l` layers along z.
//!
//! Geometry (units of the impeller's outer radius, as for `pump-rotor`):
//! - the pipe runs from `z = 0.10` (the impeller eye, where it meets `pump-rotor`'s inlet
//!   radius 0.30) to `z = 2.10`; its radius is `R(z) = 0.30 + 0.10 · smootherstep((z − 0.6)/0.8)`
//!   (0.30 up to `z = 0.6`, widening to 0.40 from `z = 1.4`); layers are packed towards the
//!   eye (one-sided clustering, strength 1.2);
//! - the core is the square `[−a, a]²`, `a = R/2`, with sides bulged outward by 8 % of `a`;
//!   the O-blocks' grid lines run from the core boundary to the wall by interpolation in
//!   polar coordinates (radius and angle), so they turn from the core's shape into circular
//!   arcs; wall points are evenly spaced in angle; O-layers are packed towards the wall
//!   (strength 2.5);
//! - the whole cross-section turns by `0.25 (z − 0.10)/2.0` rad about the axis (a mild swirl);
//! - the core centre: `n` is even, so a grid line of the core runs through the centre. Up to
//!   45 % of the length (`z ≤ 1.0`) it lies exactly on the z axis: there the four central
//!   cells of every layer **touch** the axis along an edge. Beyond, the core centre drifts off
//!   the axis along a slow helix, by up to 0.35 of a core cell (`smootherstep` from 45 % to
//!   65 % of the length): there the axis passes through the interior of one cell per layer
//!   (it **straddles** it).
//! - resolution shape `n : m : l = 1 : 0.6 : 2` (`n` even): cells are `l · n (n + 4m)`;
//!   0.9 M cells are
//!   `n, m, l` = 52, 29, 103: 899,808 cells.
//!
//! Fields: `pressure` falls towards the eye (the flow accelerates), rises with radius (swirl),
//! carries a 7-lobed upstream imprint of the impeller blades near the eye and a slight
//! one-sided distortion of the inflow; `velocity` is the axial flow towards the eye (a flat,
//! turbulent-like profile vanishing at the wall), contracting with the pipe, with a swirl
//! that grows towards the eye.

use std::f64::consts::{FRAC_PI_4, PI, TAU};

use glam::{DVec2, DVec3};

use super::blocks::{assemble, cluster_end, cluster_start, smootherstep, PointValue, Resolution};
use crate::{Error, Mesh};

const Z0: f64 = 0.10;
const LENGTH: f64 = 2.0;
const BULGE: f64 = 0.08;
const TWIST: f64 = 0.25;

/// Pipe radius at height `z`.
fn radius(z: f64) -> f64 {
    0.30 + 0.10 * smootherstep((z - 0.6) / 0.8)
}

/// The O-grid resolution: core cells per side `n` (even), O-layers `m`, axial layers `l`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct PipeDims {
    /// Core cells per side (even).
    pub core: usize,
    /// Cells from the core boundary to the wall.
    pub layers: usize,
    /// Cells along the axis.
    pub levels: usize,
}

/// Cells of a layout `[n, m, l]`.
pub(crate) fn cells([n, m, l]: [usize; 3]) -> usize {
    l * n * (n + 4 * m)
}

/// The resolution for about `target` cells (see [`Resolution::choose`]).
pub(crate) fn dims(target: usize) -> PipeDims {
    let [core, layers, levels] = Resolution {
        weights: [1.0, 0.6, 2.0],
        min: [2, 1, 1],
        first_step: 2,
    }
    .choose(target, cells);
    PipeDims {
        core,
        layers,
        levels,
    }
}

/// The cross-section's frame at height `z`: its rotation about the axis and the offset of
/// the core centre from the axis (in units of the core half-size `a`).
fn frame(z: f64, n: usize) -> (f64, DVec2) {
    let t = (z - Z0) / LENGTH;
    let turn = TWIST * t;
    let cell = 2.0 / n as f64; // a core cell, in units of a
    let drift = 0.35 * cell * smootherstep((t - 0.45) / 0.2);
    let phase = 0.4 + 5.0 * t;
    (turn, drift * DVec2::new(phase.cos(), phase.sin()))
}

/// Builds the pipe at a resolution.
pub(crate) fn build(d: PipeDims) -> Result<Mesh, Error> {
    let (n, m, l) = (d.core, d.layers, d.levels);
    let ring = 4 * n;
    let core_points = (n + 1) * (n + 1);
    let per_level = core_points + ring * m;
    let core_cells = n * n;
    let cells_per_level = core_cells + ring * m;

    let levels: Vec<f64> = (0..=l)
        .map(|k| Z0 + LENGTH * cluster_start(k as f64 / l as f64, 1.2))
        .collect();
    let wall_fraction: Vec<f64> = (0..=m)
        .map(|i| cluster_end(i as f64 / m as f64, 2.5))
        .collect();

    // Core node (a, b) of the square, before rotation, in units of the pipe radius.
    let core_xy = |a: usize, b: usize, z: f64| {
        let xi = -1.0 + 2.0 * a as f64 / n as f64;
        let eta = -1.0 + 2.0 * b as f64 / n as f64;
        let half = 0.5 * radius(z);
        let (turn, drift) = frame(z, n);
        let p = DVec2::new(
            xi * (1.0 + BULGE * (1.0 - eta * eta)),
            eta * (1.0 + BULGE * (1.0 - xi * xi)),
        ) + drift;
        DVec2::from_angle(turn).rotate(p * half)
    };
    // Core boundary node at position q around it (anticlockwise from the corner (−1, −1)).
    let boundary = |q: usize| match q / n {
        0 => (q, 0),
        1 => (n, q - n),
        2 => (n - (q - 2 * n), n),
        _ => (0, n - (q - 3 * n)),
    };
    let o_xy = |layer: usize, q: usize, z: f64| {
        let (a, b) = boundary(q);
        let c = core_xy(a, b, z);
        let (rho_c, phi_c) = (c.length(), c.y.atan2(c.x));
        let (turn, _) = frame(z, n);
        let phi_w = turn - 3.0 * FRAC_PI_4 + TAU * q as f64 / ring as f64;
        let delta = (phi_w - phi_c + PI).rem_euclid(TAU) - PI;
        let g = wall_fraction[layer];
        let rho = rho_c + g * (radius(z) - rho_c);
        DVec2::from_angle(phi_c + g * delta) * rho
    };

    let point = |id: usize| {
        let (k, p) = (id / per_level, id % per_level);
        let z = levels[k];
        let xy = if p < core_points {
            core_xy(p % (n + 1), p / (n + 1), z)
        } else {
            let o = p - core_points;
            o_xy(o / ring + 1, o % ring, z)
        };
        let position = DVec3::new(xy.x, xy.y, z);
        let (pressure, velocity) = field(position);
        PointValue {
            position,
            pressure,
            velocity,
        }
    };
    let id = |k: usize, p: usize| (k * per_level + p) as u32;
    let core_id = |a: usize, b: usize| a + (n + 1) * b;
    // O-grid node: layer 0 is the core boundary.
    let o_id = |layer: usize, q: usize| {
        let q = q % ring;
        if layer == 0 {
            let (a, b) = boundary(q);
            core_id(a, b)
        } else {
            core_points + (layer - 1) * ring + q
        }
    };
    let cell = |c: usize| {
        let (k, r) = (c / cells_per_level, c % cells_per_level);
        // (u, v) = (x, y) in the core, (outward, anticlockwise) in the O-blocks: both
        // right-handed with w = z, so every cell is positively oriented.
        let quad = if r < core_cells {
            let (a, b) = (r % n, r / n);
            [
                core_id(a, b),
                core_id(a + 1, b),
                core_id(a + 1, b + 1),
                core_id(a, b + 1),
            ]
        } else {
            let o = r - core_cells;
            let (layer, q) = (o / ring, o % ring);
            [
                o_id(layer, q),
                o_id(layer + 1, q),
                o_id(layer + 1, q + 1),
                o_id(layer, q + 1),
            ]
        };
        let lo = quad.map(|p| id(k, p));
        let hi = quad.map(|p| id(k + 1, p));
        [lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]]
    };
    assemble(per_level * (l + 1), cells_per_level * l, point, cell)
}

/// `pressure` and `velocity` at a point of the pipe.
fn field(p: DVec3) -> (f64, DVec3) {
    let big_r = radius(p.z);
    let t = (p.z - Z0) / LENGTH;
    let rho2 = (p.x * p.x + p.y * p.y) / (big_r * big_r);
    let rho8 = rho2 * rho2 * rho2 * rho2;
    let near_eye = (-(p.z - Z0) / 0.3).exp();
    // ρ⁷ cos 7θ = Re((x + iy)⁷)/R⁷, smooth through the axis.
    let (u, v) = (p.x / big_r, p.y / big_r);
    let mut re = 1.0;
    let mut im = 0.0;
    for _ in 0..7 {
        (re, im) = (re * u - im * v, re * v + im * u);
    }
    let pressure =
        0.02 + 0.06 * t + 0.015 * rho2 + 0.012 * near_eye * re - 0.01 * u * smootherstep(t);

    let h = 1e-6;
    let slope = (radius(p.z + h) - radius(p.z - h)) / (2.0 * h);
    let axial = -(0.30 / big_r).powi(2) * (1.0 - rho8);
    let swirl = 0.25 * (-(p.z - Z0) / 0.4).exp() * (1.0 - rho8) / big_r; // v_θ / r
    let contract = axial * slope / big_r; // v_r / r
    let velocity = DVec3::new(
        contract * p.x - swirl * p.y,
        contract * p.y + swirl * p.x,
        axial,
    );
    (pressure, velocity)
}
