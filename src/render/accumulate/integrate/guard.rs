//! Where the error-bounded steps stay short whatever the samples say ([`Guard`]): every cell's
//! thickness (the least distance between the centres of two opposite faces), and which cells
//! are *active*: those across whose scalar range the transfer function varies enough that a
//! feature smaller than a step could hide between two samples that agree (a thin layer the
//! field rises and falls across) — the total variation of the extinction and of the emission
//! density over the cell's range, times its extent (its box diagonal), exceeds a share of the
//! error allowed. A sample in an active cell takes a step no longer than the cell is thin
//! (twice that where the transfer function is straight over its range: [`STRAIGHT`]);
//! elsewhere the samples alone choose. A sample's tangent is not followed much further than its
//! cell is thin, active or not.
//!
//! Made once per render from the cells' scalar ranges and the transfer table, in parallel.

use rayon::prelude::*;

use super::table::Extinction;
use crate::geometry::bounds::cell_bounds;
use crate::geometry::trilinear::index;
use crate::Mesh;

use glam::DVec3;

/// An active cell is *straight* where the steepest slope of the transfer function over its
/// scalar range, times that range, is within this factor of the variation over it: no band
/// of the transfer function narrower than the range lies in it, so what the field does
/// between two samples reaches the light about linearly, as the error estimate takes it.
const STRAIGHT: f64 = 1.5;

/// The longest step in a straight active cell, in its thicknesses.
const STRAIGHT_CELLS: f64 = 2.0;

/// Per cell, its thickness and whether it is active.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Guard {
    /// The thickness, negative where the cell is active (times [`STRAIGHT_CELLS`] where it
    /// is straight).
    thickness: Vec<f32>,
}

impl Guard {
    /// The cells of `mesh`, whose scalar ranges are `ranges`, under `table`: a cell is active
    /// where the variation over its range times its extent exceeds `threshold`.
    pub(crate) fn new(
        mesh: &Mesh,
        ranges: &[[f64; 2]],
        table: &Extinction,
        threshold: f64,
    ) -> Guard {
        let thickness = (0..mesh.cell_count())
            .into_par_iter()
            .with_min_len(1024)
            .map(|c| {
                let [lo, hi] = ranges[c];
                let corners = mesh.cell_corners(c);
                let thin = thickness(&corners) as f32;
                let variation = table.variation(lo, hi);
                if variation > 0.0 && variation * cell_bounds(&corners).diagonal() > threshold {
                    if table.steepest(lo, hi) * (hi - lo) <= STRAIGHT * variation {
                        -thin * STRAIGHT_CELLS as f32
                    } else {
                        -thin
                    }
                } else {
                    thin
                }
            })
            .collect();
        Guard { thickness }
    }

    /// The longest step a sample in `cell` takes: its thickness (or [`STRAIGHT_CELLS`] of them)
    /// where it is active, else `∞`.
    #[inline]
    pub(crate) fn cap(&self, cell: u32) -> f64 {
        match self.thickness.get(cell as usize) {
            Some(&t) if t < 0.0 => -t as f64,
            _ => f64::INFINITY,
        }
    }
}

/// The least distance between the centres of two opposite faces of a cell.
fn thickness(corners: &[DVec3; 8]) -> f64 {
    let centre = |axis: usize, side: usize| {
        let mut sum = DVec3::ZERO;
        for a in 0..2 {
            for b in 0..2 {
                let (u, v, w) = match axis {
                    0 => (side, a, b),
                    1 => (a, side, b),
                    _ => (a, b, side),
                };
                sum += corners[index(u, v, w)];
            }
        }
        sum * 0.25
    };
    (0..3)
        .map(|axis| (centre(axis, 1) - centre(axis, 0)).length())
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::trilinear::CORNER_PARAMETERS;

    #[test]
    fn thickness_of_a_flat_box() {
        let corners = CORNER_PARAMETERS.map(|p| DVec3::new(p[0] * 2.0, p[1] * 0.1, p[2] * 3.0));
        assert!((thickness(&corners) - 0.1).abs() < 1e-15);
    }
}
