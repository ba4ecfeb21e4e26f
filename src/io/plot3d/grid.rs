//! The grid (`xyz`) file's body: for each grid, in one record, the x, y and z blocks (i
//! fastest), then the IBLANK block.

use glam::DVec3;

use super::detect::{FileKind, Layout};
use super::{floats, ints};
use crate::error::Error;

/// One grid's points and, when the file has them, IBLANK flags (one per point).
pub(super) struct Grid {
    /// Points along i, j, k.
    pub dims: [usize; 3],
    /// Point coordinates, i fastest, then j, then k.
    pub points: Vec<DVec3>,
    /// IBLANK per point: 0 hides the point (and every cell it belongs to).
    pub iblank: Option<Vec<i32>>,
}

/// Reads every grid of a file whose layout [`super::detect::detect`] has found (so its size
/// is known to be right; every read is still bounds-checked).
pub(super) fn read_grids(bytes: &[u8], layout: &Layout) -> Result<Vec<Grid>, Error> {
    let kind = FileKind::Grid;
    let s = layout.precision.bytes();
    let mut pos = layout.data_offset;
    let mut grids = Vec::with_capacity(layout.grids.len());
    for &dims in &layout.grids {
        let n: usize = dims.iter().product();
        let x = floats(bytes, pos, n, layout, kind)?;
        pos += n * s;
        let y = floats(bytes, pos, n, layout, kind)?;
        pos += n * s;
        let z = floats(bytes, pos, n, layout, kind)?;
        pos += n * s;
        let points = x
            .iter()
            .zip(&y)
            .zip(&z)
            .map(|((&x, &y), &z)| DVec3::new(x, y, z))
            .collect();
        let iblank = if layout.iblank {
            let flags = ints(bytes, pos, n, layout, kind)?;
            pos += n * 4;
            Some(flags)
        } else {
            None
        };
        if layout.record_markers {
            pos += 8; // this record's end marker and the next one's start marker
        }
        grids.push(Grid {
            dims,
            points,
            iblank,
        });
    }
    Ok(grids)
}
