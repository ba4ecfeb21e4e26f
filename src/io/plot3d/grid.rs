//! The grid (`xyz`) file's body: the x, y and z blocks (i fastest), then the IBLANK block.

use glam::DVec3;

use super::detect::{FileKind, Layout};
use super::{floats, ints};
use crate::error::Error;

/// Points and, when the file has them, IBLANK flags (one per point).
pub(super) struct Grid {
    /// Point coordinates, i fastest, then j, then k.
    pub points: Vec<DVec3>,
    /// IBLANK per point: 0 hides the point (and every cell it belongs to).
    pub iblank: Option<Vec<i32>>,
}

/// Reads a grid body whose layout [`super::detect::detect`] has found (so its size is known to
/// be right; every read is still bounds-checked).
pub(super) fn read_grid(bytes: &[u8], layout: &Layout) -> Result<Grid, Error> {
    let kind = FileKind::Grid;
    let n = layout.points();
    let s = layout.precision.bytes();
    let mut pos = layout.data_offset;
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
        Some(ints(bytes, pos, n, layout, kind)?)
    } else {
        None
    };
    Ok(Grid { points, iblank })
}
