//! PLOT3D "whole" 3-D single-grid files: a grid (`*xyz.bin`) and, optionally, its Q
//! (solution) file (`*q.bin`).
//!
//! # Layout
//! The layout is detected, not configured (see [`detect_layout`] and the rules in
//! [`detect`]): byte order, `f32` or `f64`, an IBLANK block or not, Fortran unformatted record
//! markers or not, and a leading grid count of 1 or none. The one layout whose predicted size
//! equals the file's size is used; none or several give an error listing each reading tried
//! and the size it expects. Multi-grid files (a grid count above 1) and 2-D files are refused
//! with an error saying so. Record markers are the common 4-byte kind, one record for the
//! dimensions, one for the whole body of a grid (x, y, z, IBLANK), and for a Q file one for the
//! four free-stream values and one for the five variables.
//!
//! # Grid
//! After the dimensions `ni nj nk`: the x block, the y block, the z block (`ni·nj·nk` values
//! each, i fastest, then j, then k), then, if present, the IBLANK block (one `i32` per point).
//! Cells are the `(ni−1)(nj−1)(nk−1)` hexahedra of [`crate::io::structured::hexahedra`], which
//! orients left-handed grids.
//!
//! **IBLANK.** As VTK's `vtkMultiBlockPLOT3DReader` does (it blanks points with IBLANK = 0,
//! and a structured grid hides every cell with a blanked point), a cell is kept when all eight
//! of its points have a non-zero IBLANK and dropped when any has IBLANK = 0. Other values
//! (negative ones mark overset or periodic boundaries, e.g. −1 on the LOX post's seam) keep
//! their cells. All points are kept, used or not, so point data lines up with the file. The
//! IBLANK values themselves are not kept as an array.
//!
//! # Q file
//! Same dimensions as the grid (else an error naming both), its own detected layout (byte
//! order, precision, record markers), four floats (Mach, alpha, Reynolds, time), then five
//! blocks: density, x, y, z momentum, stagnation energy. They become the point arrays
//! `Density`, `Momentum` (3 components) and `StagnationEnergy`. Without a Q file the mesh has
//! no arrays.

pub mod detect;
mod grid;
mod q;

pub use detect::{ByteOrder, Layout, Precision};

pub(crate) use detect::FileKind;

use crate::error::{Error, MeshError, ReadError};
use crate::io::structured::hexahedra;
use crate::mesh::{CellKind, Mesh, MeshParts};

/// Detects the layout of a PLOT3D grid (`xyz`) file from its header and size.
///
/// ```
/// use cylvol::io::plot3d::{detect_layout, ByteOrder, Precision};
/// // A big-endian 2×2×2 grid without IBLANK: 3 ints, then 3 × 8 floats.
/// let mut xyz: Vec<u8> = [2i32, 2, 2].iter().flat_map(|v| v.to_be_bytes()).collect();
/// xyz.extend((0..24).flat_map(|n| (n as f32).to_be_bytes()));
/// let layout = detect_layout(&xyz).unwrap();
/// assert_eq!(layout.dims, [2, 2, 2]);
/// assert_eq!((layout.byte_order, layout.precision), (ByteOrder::Big, Precision::F32));
/// assert!(!layout.iblank && !layout.record_markers && !layout.grid_count);
/// ```
pub fn detect_layout(xyz: &[u8]) -> Result<Layout, Error> {
    detect::detect(xyz, FileKind::Grid)
}

/// Detects the layout of a PLOT3D Q (solution) file from its header and size
/// ([`Layout::iblank`] is always `false`).
pub fn detect_q_layout(q: &[u8]) -> Result<Layout, Error> {
    detect::detect(q, FileKind::Solution)
}

/// Reads a PLOT3D grid and, optionally, its Q file into a validated mesh.
///
/// ```
/// // A unit cube as a big-endian 2×2×2 grid, no IBLANK, no Q file.
/// let mut xyz: Vec<u8> = [2i32, 2, 2].iter().flat_map(|v| v.to_be_bytes()).collect();
/// for axis in 0..3 {
///     xyz.extend((0..8).flat_map(|n| (((n >> axis) & 1) as f32).to_be_bytes()));
/// }
/// let mesh = cylvol::io::plot3d::read(&xyz, None).unwrap();
/// assert_eq!((mesh.point_count(), mesh.cell_count()), (8, 1));
/// assert!(mesh.point_data().is_empty());
/// ```
pub fn read(xyz: &[u8], q: Option<&[u8]>) -> Result<Mesh, Error> {
    read_blaming(xyz, q).map_err(|(_, e)| e)
}

/// [`read`], with each error paired with the file it concerns: the grid, or the Q file (its
/// layout, its size, its dimensions against the grid's, its values).
pub(crate) fn read_blaming(xyz: &[u8], q: Option<&[u8]>) -> Result<Mesh, (FileKind, Error)> {
    let grid_error = |e: Error| (FileKind::Grid, e);
    let layout = detect_layout(xyz).map_err(grid_error)?;
    let n = layout.points();
    if n > u32::MAX as usize {
        return Err(grid_error(
            ReadError::new(
                FileKind::Grid.format(),
                0,
                format!("{n} points are more than 32-bit point indices can address"),
            )
            .into(),
        ));
    }
    let point_data = match q {
        Some(q) => solution(q, &layout).map_err(|e| (FileKind::Solution, e))?,
        None => Vec::new(),
    };
    let grid::Grid { points, iblank } = grid::read_grid(xyz, &layout).map_err(grid_error)?;
    let mut cells = hexahedra(layout.dims, &points);
    if let Some(iblank) = &iblank {
        cells.retain(|cell| {
            cell.iter()
                .all(|&p| iblank.get(p as usize).is_some_and(|&b| b != 0))
        });
    }
    let kinds = vec![CellKind::Hexahedron; cells.len()];
    Mesh::from_parts(MeshParts {
        points,
        cells,
        kinds,
        point_data,
        cell_data: Vec::new(),
    })
    .map_err(|e| {
        // Point arrays come from the Q file alone; the rest is the grid's.
        let kind = match e {
            MeshError::ArrayLength { .. } => FileKind::Solution,
            _ => FileKind::Grid,
        };
        (kind, e.into())
    })
}

/// The point arrays of a Q file for a grid of the given layout: its own layout detected, its
/// dimensions the grid's.
fn solution(q: &[u8], grid: &Layout) -> Result<Vec<crate::mesh::DataArray>, Error> {
    let q_layout = detect_q_layout(q)?;
    if q_layout.dims != grid.dims {
        let [a, b, c] = q_layout.dims;
        let [i, j, k] = grid.dims;
        return Err(ReadError::new(
            FileKind::Solution.format(),
            0,
            format!("the Q file's dimensions {a}×{b}×{c} differ from the grid's {i}×{j}×{k}"),
        )
        .into());
    }
    q::read_solution(q, &q_layout)
}

/// `count` floats of the layout's precision and byte order from `offset`, as `f64`.
fn floats(
    bytes: &[u8],
    offset: usize,
    count: usize,
    layout: &Layout,
    kind: FileKind,
) -> Result<Vec<f64>, Error> {
    let s = layout.precision.bytes();
    let block = block(bytes, offset, count, s, kind)?;
    let big = layout.byte_order == ByteOrder::Big;
    Ok(match layout.precision {
        detect::Precision::F32 => block
            .chunks_exact(4)
            .map(|w| {
                let w = [w[0], w[1], w[2], w[3]];
                f64::from(if big {
                    f32::from_be_bytes(w)
                } else {
                    f32::from_le_bytes(w)
                })
            })
            .collect(),
        detect::Precision::F64 => block
            .chunks_exact(8)
            .map(|w| {
                let w = [w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7]];
                if big {
                    f64::from_be_bytes(w)
                } else {
                    f64::from_le_bytes(w)
                }
            })
            .collect(),
    })
}

/// `count` 4-byte integers in the layout's byte order from `offset`.
fn ints(
    bytes: &[u8],
    offset: usize,
    count: usize,
    layout: &Layout,
    kind: FileKind,
) -> Result<Vec<i32>, Error> {
    let block = block(bytes, offset, count, 4, kind)?;
    let big = layout.byte_order == ByteOrder::Big;
    Ok(block
        .chunks_exact(4)
        .map(|w| {
            let w = [w[0], w[1], w[2], w[3]];
            if big {
                i32::from_be_bytes(w)
            } else {
                i32::from_le_bytes(w)
            }
        })
        .collect())
}

/// The bytes of `count` values of `size` bytes from `offset`, or a truncation error.
fn block(
    bytes: &[u8],
    offset: usize,
    count: usize,
    size: usize,
    kind: FileKind,
) -> Result<&[u8], Error> {
    let end = count
        .checked_mul(size)
        .and_then(|b| b.checked_add(offset))
        .filter(|&end| end <= bytes.len());
    match end {
        Some(end) => Ok(&bytes[offset..end]),
        None => Err(ReadError::new(
            kind.format(),
            offset as u64,
            format!(
                "truncated file: a block of {count} values of {size} bytes starts at byte \
                 {offset}, but the file has {} bytes",
                bytes.len()
            ),
        )
        .into()),
    }
}
