//! The checks [`super::Mesh::from_parts`] runs: everything the renderer relies on, reported
//! as a typed [`MeshError`] naming the first offender.

use rayon::prelude::*;

use super::{Association, DataArray, MeshParts};
use crate::error::MeshError;
use crate::geometry::trilinear::corner_jacobian_determinants;

/// Relative tolerance below which a corner Jacobian counts as negative: `det < -TOL · L³`
/// with `L` the cell's longest bounding-box side. Collapsed corners of wedges, pyramids and
/// tetrahedra (and zero-volume seam cells of structured grids) have `det = 0` and pass.
pub const INVERTED_TOLERANCE: f64 = 1e-9;

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
    if let Some((cell, ids)) = parts
        .cells
        .iter()
        .enumerate()
        .find(|(_, ids)| ids.iter().any(|&i| i as usize >= n_points))
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

fn check_arrays(
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
        if let Some(index) = a.values.iter().position(|v| !v.is_finite()) {
            return Err(MeshError::NonFiniteScalar {
                name: a.name.clone(),
                association,
                index,
                value: a.values[index],
            });
        }
    }
    Ok(())
}

/// True when a cell's trilinear map has a clearly negative Jacobian at a corner.
pub fn is_inverted(corners: &[glam::DVec3; 8]) -> bool {
    let (lo, hi) = corners
        .iter()
        .fold((corners[0], corners[0]), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let l = (hi - lo).max_element();
    let tol = -INVERTED_TOLERANCE * l * l * l;
    corner_jacobian_determinants(corners)
        .iter()
        .any(|&d| d < tol)
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
