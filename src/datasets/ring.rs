//! The bladed ring shared by `pump-rotor` and `pump-diffuser`: a full 360° annular channel
//! about the z axis between a lower wall (hub) and an upper wall (shroud) whose heights vary
//! with radius, cut by `B` thick blades, meshed as a periodic structured (i, j, k) grid.
//!
//! - `i` runs outward in radius through three block rows: an upstream row (`r_in → r_le`,
//!   packed towards the leading edge), the bladed row (`r_le → r_te`, packed towards both
//!   edges) and a downstream row (`r_te → r_out`, packed towards the trailing edge).
//! - `j` runs around the ring, `nt` cells per blade passage, packed towards the blades. The
//!   azimuth of a point is `camber(r, ζ) + (b + phase)·pitch`: every grid line follows the
//!   twisted blade camber, so cells are arcs sheared in θ like a real turbomachinery mesh.
//!   Inside the bladed row, `phase` spans `[t/2, pitch − t/2]` of the passage (`t` the blade's
//!   angular thickness), so each blade is a slit with two walls; its two sides meet at the
//!   leading and trailing edges, where the thickness is zero and both sides use one point.
//!   The last `j` column wraps onto the first: the ring closes by sharing the seam points.
//! - `k` runs from hub (`ζ = 0`) to shroud (`ζ = 1`), packed towards both walls.
//!
//! Point numbering: the base grid, `j` fastest, then `i`, then `k`; then the extra points on
//! the second side of each blade (interior bladed radii only), blade fastest, then `i`, then
//! `k`. Cells: `j` fastest, then `i`, then `k`, corners in VTK order with `(u, v, w) =
//! (i, j, k)` (outward, anticlockwise, upward: a right-handed, positive orientation).

use std::f64::consts::TAU;

use glam::DVec3;

use super::blocks::{assemble, cluster_both, cluster_end, cluster_start, PointValue, Resolution};
use super::field::cylindrical_vector;
use crate::{Error, Mesh};

/// Where a ring point lies, in the coordinates its fields are written in.
pub(crate) struct RingNode {
    /// Radius.
    pub r: f64,
    /// Azimuth (not wrapped).
    pub theta: f64,
    /// Fraction of the channel height: 0 on the hub, 1 on the shroud.
    pub zeta: f64,
    /// Fraction of the radial extent: 0 at `r_in`, 1 at `r_out`.
    pub s: f64,
    /// Fraction of the blade chord (radially, 0 at the leading edge, 1 at the trailing edge)
    /// inside the bladed row; `None` upstream and downstream.
    pub chord: Option<f64>,
    /// Angular position from the blade camber, in pitches: 0 on one blade line, 1 on the next.
    pub phase: f64,
    /// Slope `dz/dr` of the constant-`ζ` line through the point (meridional flow direction).
    pub dzdr: f64,
}

/// The shape, resolution rule and fields of a bladed ring.
pub(crate) struct RingShape {
    /// Number of blades `B`.
    pub blades: usize,
    /// `[r_in, r_le, r_te, r_out]`.
    pub radii: [f64; 4],
    /// Shares of the radial cells in the upstream and downstream rows.
    pub zone_share: [f64; 2],
    /// Hub height `z(r)`.
    pub hub: fn(f64) -> f64,
    /// Shroud height `z(r)` (above the hub).
    pub shroud: fn(f64) -> f64,
    /// Blade camber azimuth `θ_c(r, ζ)`.
    pub camber: fn(f64, f64) -> f64,
    /// Physical blade thickness along the chord fraction (zero at both ends).
    pub thickness: fn(f64) -> f64,
    /// Clustering strengths in r, θ, z.
    pub beta: [f64; 3],
    /// Radial cells, cells per passage, axial cells at scale 1.
    pub weights: [f64; 3],
    /// `pressure` and cylindrical velocity `[v_r, v_θ, v_z]` at a point.
    pub field: fn(&RingNode) -> (f64, [f64; 3]),
}

/// The resolution of a ring: radial cells per row, cells per passage, axial cells.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct RingDims {
    /// Radial cells in the upstream, bladed and downstream rows.
    pub radial: [usize; 3],
    /// Cells across one blade passage.
    pub per_passage: usize,
    /// Cells from hub to shroud.
    pub axial: usize,
}

impl RingShape {
    /// The resolution for about `cells` cells: total radial cells `nr`, cells per passage
    /// `nt` and axial cells `nz` (`B·nr·nt·nz` cells) as [`Resolution::choose`] picks them
    /// from `weights`; the radial cells are then split between the rows by `zone_share`
    /// (at least 1 upstream, 1 downstream and 2 bladed).
    pub fn dims(&self, cells: usize) -> RingDims {
        let b = self.blades;
        let resolution = Resolution {
            weights: self.weights,
            min: [4, 2, 2],
            first_step: 1,
        };
        let [nr, nt, nz] = resolution.choose(cells, |[nr, nt, nz]| b * nr * nt * nz);
        let mut up = ((nr as f64 * self.zone_share[0]).round() as usize).max(1);
        let mut down = ((nr as f64 * self.zone_share[1]).round() as usize).max(1);
        if up + down + 2 > nr {
            (up, down) = (1, 1);
        }
        RingDims {
            radial: [up, nr - up - down, down],
            per_passage: nt,
            axial: nz,
        }
    }

    /// Builds the ring at a resolution.
    pub fn build(&self, dims: RingDims) -> Result<Mesh, Error> {
        let b = self.blades;
        let [n_up, n_bl, n_dn] = dims.radial;
        let nr = n_up + n_bl + n_dn;
        let nt = dims.per_passage;
        let nz = dims.axial;
        let nj = b * nt;
        let (i_le, i_te) = (n_up, n_up + n_bl);
        let [r_in, r_le, r_te, r_out] = self.radii;
        let [beta_r, beta_t, beta_z] = self.beta;
        let pitch = TAU / b as f64;

        // One-dimensional tables: radius, chord fraction, angular thickness; ζ; passage fraction.
        let radial: Vec<(f64, Option<f64>)> = (0..=nr)
            .map(|i| {
                if i < i_le {
                    let e = i as f64 / n_up as f64;
                    (r_in + (r_le - r_in) * cluster_end(e, beta_r), None)
                } else if i <= i_te {
                    let c = cluster_both((i - i_le) as f64 / n_bl as f64, beta_r);
                    (r_le + (r_te - r_le) * c, Some(c))
                } else {
                    let e = (i - i_te) as f64 / n_dn as f64;
                    (r_te + (r_out - r_te) * cluster_start(e, beta_r), None)
                }
            })
            .collect();
        let angular_thickness: Vec<f64> = (0..=nr)
            .map(|i| match radial[i].1 {
                Some(c) if i > i_le && i < i_te => (self.thickness)(c) / radial[i].0,
                _ => 0.0,
            })
            .collect();
        let zeta: Vec<f64> = (0..=nz)
            .map(|k| cluster_both(k as f64 / nz as f64, beta_z))
            .collect();
        let fraction: Vec<f64> = (0..nt)
            .map(|j| cluster_both(j as f64 / nt as f64, beta_t))
            .collect();

        let n_base = (nr + 1) * nj * (nz + 1);
        let n_inner = n_bl - 1; // bladed radii with a second blade side
        let n_extra = n_inner * b * (nz + 1);
        let base = |i: usize, j: usize, k: usize| ((k * (nr + 1) + i) * nj + j) as u32;
        let extra = |blade: usize, i: usize, k: usize| {
            (n_base + (k * n_inner + (i - i_le - 1)) * b + blade) as u32
        };
        // The point at grid position (i, j, k) as seen from passage `j / nt` or, for a
        // column index that is a multiple of nt reached from the passage before it, from
        // the second side of the blade.
        let node = |i: usize, j: usize, k: usize, from_below: bool| {
            if from_below && j % nt == 0 && i > i_le && i < i_te {
                extra(j / nt, i, k)
            } else {
                base(i, j, k)
            }
        };

        let point = |id: usize| {
            let (i, k, blade, phase) = if id < n_base {
                let j = id % nj;
                let rest = id / nj;
                let (i, k) = (rest % (nr + 1), rest / (nr + 1));
                let t = angular_thickness[i];
                let phase = (0.5 * t + fraction[j % nt] * (pitch - t)) / pitch;
                (i, k, (j / nt) as f64, phase)
            } else {
                let e = id - n_base;
                let blade = e % b;
                let rest = e / b;
                let (i, k) = (i_le + 1 + rest % n_inner, rest / n_inner);
                // The blade's far side, as the end of the passage before it.
                let phase = 1.0 - 0.5 * angular_thickness[i] / pitch;
                (i, k, blade as f64 - 1.0, phase)
            };
            let (r, chord) = radial[i];
            let zeta = zeta[k];
            let theta = (self.camber)(r, zeta) + (blade + phase) * pitch;
            let (lo, hi) = ((self.hub)(r), (self.shroud)(r));
            let z = lo + zeta * (hi - lo);
            let h = 1e-6;
            let slope = |f: fn(f64) -> f64| (f(r + h) - f(r - h)) / (2.0 * h);
            let dzdr = slope(self.hub) + zeta * (slope(self.shroud) - slope(self.hub));
            let at = RingNode {
                r,
                theta,
                zeta,
                s: (r - r_in) / (r_out - r_in),
                chord,
                phase,
                dzdr,
            };
            let (pressure, v) = (self.field)(&at);
            let (sin, cos) = theta.sin_cos();
            PointValue {
                position: DVec3::new(r * cos, r * sin, z),
                pressure,
                velocity: cylindrical_vector(theta, v),
            }
        };
        let cell = |c: usize| {
            let j = c % nj;
            let rest = c / nj;
            let (i, k) = (rest % nr, rest / nr);
            let j1 = (j + 1) % nj;
            let corners = |k: usize| {
                [
                    node(i, j, k, false),
                    node(i + 1, j, k, false),
                    node(i + 1, j1, k, true),
                    node(i, j1, k, true),
                ]
            };
            let [a, bb, cc, d] = corners(k);
            let [e, f, g, h] = corners(k + 1);
            [a, bb, cc, d, e, f, g, h]
        };
        assemble(n_base + n_extra, nr * nj * nz, point, cell)
    }
}
