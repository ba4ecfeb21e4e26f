//! The checks [`super::Mesh::from_parts`] runs: everything the renderer relies on, reported
//! as a typed [`MeshError`] naming the first offender.

use rayon::prelude::*;

use super::{Association, DataArray, MeshParts};
use crate::error::MeshError;
use crate::geometry::trilinear::{corner_jacobian_determinants, jacobian};

/// Rounding noise allowed in Jacobian determinants, relative to `L³` with `L` the cell's
/// longest bounding-box side: zero-volume cells (the seam cells of O-grids whose seam points
/// coincide, collapsed corners of wedges, pyramids and tetrahedra) have determinants of this
/// order of either sign and are accepted.
pub const JACOBIAN_NOISE: f64 = 1e-9;

/// How far below zero a corner's Jacobian determinant may fall, as a fraction of the cell's
/// largest corner determinant, before the cell counts as inverted. Real meshes have slightly
/// folded corners (two cells of VTK's combustor have a corner at −3 % of their largest) which
/// VTK renders; a corner pulled through the cell is far below this.
pub const FOLD_TOLERANCE: f64 = 0.25;

pub(super) fn validate(parts: &MeshParts) -> Result<(), MeshError> {
    let n_points = parts.points.len();
    let n_cells = parts.cells.len();
    if n_points == 0 || n_cells == 0 {
        return Err(MeshError::Empty {
            points: n_points,
            cells: n_cells,
        });
    }
    if parts.kinds.len() != n_cells {
        return Err(MeshError::CellArrays(format!(
            "{} cell kinds for {} cells",
            parts.kinds.len(),
            n_cells
        )));
    }
    if let Some(index) = parts.points.iter().position(|p| !p.is_finite()) {
        return Err(MeshError::NonFinitePoint {
            index,
            coordinates: parts.points[index].to_array(),
        });
    }
    // The largest id first (a reduction the compiler vectorises); the offender is searched
    // for only when there is one.
    let largest = parts.cells.as_flattened().iter().copied().max();
    let bad = |ids: &&[u32; 8]| ids.iter().any(|&i| i as usize >= n_points);
    if let Some((cell, ids)) = largest
        .filter(|&i| i as usize >= n_points)
        .and_then(|_| parts.cells.iter().enumerate().find(|(_, ids)| bad(ids)))
    {
        let index = ids
            .iter()
            .copied()
            .find(|&i| i as usize >= n_points)
            .unwrap_or(0);
        return Err(MeshError::IndexOutOfRange {
            cell,
            index: index as i64,
            points: n_points,
        });
    }
    check_arrays(&parts.point_data, Association::Point, n_points)?;
    check_arrays(&parts.cell_data, Association::Cell, n_cells)?;
    check_orientation(parts)
}

/// Checks that each array has `tuples` tuples. NaN and infinite values are kept: only the
/// scalars a render draws must be finite ([`super::Mesh::drawn_scalars`]).
pub(super) fn check_arrays(
    arrays: &[DataArray],
    association: Association,
    tuples: usize,
) -> Result<(), MeshError> {
    for a in arrays {
        let expected = tuples * a.components;
        if a.components == 0 || a.values.len() != expected {
            return Err(MeshError::ArrayLength {
                name: a.name.clone(),
                association,
                expected,
                got: a.values.len(),
            });
        }
    }
    Ok(())
}

/// True when a cell is inverted: a corner's Jacobian determinant is negative by more than
/// [`FOLD_TOLERANCE`] times the largest corner determinant, or a corner is negative and the
/// volume is negative too.
pub fn is_inverted(corners: &[glam::DVec3; 8]) -> bool {
    let (lo, hi) = corners
        .iter()
        .fold((corners[0], corners[0]), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let l = (hi - lo).max_element();
    let noise = JACOBIAN_NOISE * l * l * l;
    let dets = corner_jacobian_determinants(corners);
    let min = dets.iter().copied().fold(f64::INFINITY, f64::min);
    if min >= -noise {
        // No corner folds (the common case). A cell twisted so hard that det J is negative only
        // inside, between positive corners, is not detected here; the inverse map reports
        // failure rather than a wrong answer in such a cell.
        return false;
    }
    let max = dets.iter().copied().fold(0.0, f64::max);
    min < -(FOLD_TOLERANCE * max).max(noise) || cell_volume(corners) < -noise
}

/// The signed volume of a trilinear cell: `∫ det J` over the unit cube, exact with 2×2×2
/// Gauss points (`det J` has degree at most 2 in each parameter).
pub fn cell_volume(corners: &[glam::DVec3; 8]) -> f64 {
    let g = 0.5 / 3f64.sqrt();
    let mut sum = 0.0;
    for p in crate::geometry::trilinear::CORNER_PARAMETERS {
        let q = glam::DVec3::from_array(p.map(|c| 0.5 + if c > 0.5 { g } else { -g }));
        sum += jacobian(corners, q).determinant();
    }
    sum / 8.0
}

fn check_orientation(parts: &MeshParts) -> Result<(), MeshError> {
    let corners = |c: &[u32; 8]| c.map(|i| parts.points[i as usize]);
    let inverted: Vec<usize> = parts
        .cells
        .par_iter()
        .enumerate()
        .filter(|(_, c)| is_inverted(&corners(c)))
        .map(|(i, _)| i)
        .collect();
    match inverted.first() {
        None => Ok(()),
        Some(&first) => Err(MeshError::InvertedCells {
            count: inverted.len(),
            first,
        }),
    }
}
