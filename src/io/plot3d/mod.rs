//! PLOT3D "whole" 3-D files of one or several grids: a grid file (`*xyz.bin`) and,
//! optionally, its Q (solution) file (`*q.bin`).
//!
//! # Layout
//! The layout is detected, not configured (see [`detect_layout`] and the rules in
//! [`detect`]): byte order, `f32` or `f64`, an IBLANK block or not, Fortran unformatted record
//! markers or not, and a leading grid count or none (one grid). The one layout whose predicted
//! size equals the file's size is used, or else one that holds the file's data with bytes
//! after it where its record markers (or, for a Q file, its grid's layout) prove it, the bytes
//! after ignored ([`read_logged`] says how many); none or several give an error listing each
//! reading tried and the size it expects. 2-D files are refused with an error saying so.
//! Record markers are the common 4-byte kind, one record for the grid count, one for all the
//! dimensions, one for each grid's whole body (x, y, z, IBLANK), and in a Q file two for each
//! grid: the four free-stream values, then the five variables.
//!
//! # Grid
//! After the dimensions `ni nj nk` of every grid, each grid's body: the x block, the y block,
//! the z block (`ni·nj·nk` values each, i fastest, then j, then k), then, if present, the
//! IBLANK block (one `i32` per point). Cells are the `(ni−1)(nj−1)(nk−1)` hexahedra of
//! [`crate::io::structured::hexahedra`], which orients left-handed grids.
//!
//! **Several grids** (VTK's reader gives one block each) are joined into one mesh, the points
//! and cells of each grid after those of the grid before it, and the Q file's arrays likewise;
//! [`read_logged`] says so. Where grids overlap (overset grids), a sample in the overlap takes
//! the value of one of them.
//!
//! **IBLANK.** As VTK's `vtkMultiBlockPLOT3DReader` does (it blanks points with IBLANK = 0,
//! and a structured grid hides every cell with a blanked point), a cell is kept when all eight
//! of its points have a non-zero IBLANK and dropped when any has IBLANK = 0. Other values
//! (negative ones mark overset or periodic boundaries, e.g. −1 on the LOX post's seam) keep
//! their cells. All points are kept, used or not, so point data lines up with the file. The
//! IBLANK values themselves are not kept as an array.
//!
//! # Q file
//! Same grids of the same dimensions as the grid file (else an error naming both), its own
//! detected layout (byte order, precision, record markers), for each grid four floats (Mach,
//! alpha, Reynolds, time), then five blocks: density, x, y, z momentum, stagnation energy.
//! They become the point arrays `Density`, `Momentum` (3 components) and `StagnationEnergy`.
//! Without a Q file the mesh has no arrays.

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
    read_logged(xyz, q, &mut |_| {})
}

/// [`read`], giving `log` what a user should know of the read: bytes after the data that were
/// ignored (in which file, how many, and whether they are all zero), and how many grids were
/// joined into the mesh.
///
/// ```
/// // A unit cube as a big-endian 2×2×2 grid, then 100 bytes of padding, in record markers.
/// let record = |body: Vec<u8>| {
///     let n = (body.len() as u32).to_be_bytes();
///     [&n[..], &body, &n].concat()
/// };
/// let dims: Vec<u8> = [2i32, 2, 2].iter().flat_map(|v| v.to_be_bytes()).collect();
/// let coords: Vec<u8> = (0..3)
///     .flat_map(|axis| (0..8).flat_map(move |n| (((n >> axis) & 1) as f32).to_be_bytes()))
///     .collect();
/// let xyz = [record(dims), record(coords), vec![0; 100]].concat();
/// let mut notes = Vec::new();
/// let mesh = cylvol::io::plot3d::read_logged(&xyz, None, &mut |n| notes.push(n)).unwrap();
/// assert_eq!(mesh.cell_count(), 1);
/// assert_eq!(
///     notes,
///     ["the grid file: 100 bytes after its last record (all zero) were ignored"]
/// );
/// ```
pub fn read_logged(
    xyz: &[u8],
    q: Option<&[u8]>,
    log: &mut dyn FnMut(String),
) -> Result<Mesh, Error> {
    read_blaming(xyz, q, &mut |kind, note| {
        log(format!("the {}: {note}", kind.file_name()))
    })
    .map_err(|(_, e)| e)
}

/// [`read_logged`], with each note and error paired with the file it concerns: the grid,
/// or the Q file (its layout, its size, its dimensions against the grid's, its values).
pub(crate) fn read_blaming(
    xyz: &[u8],
    q: Option<&[u8]>,
    log: &mut dyn FnMut(FileKind, String),
) -> Result<Mesh, (FileKind, Error)> {
    let grid_error = |e: Error| (FileKind::Grid, e);
    let layout = detect_layout(xyz).map_err(grid_error)?;
    note_trailing(xyz, &layout, FileKind::Grid, log);
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
        Some(q) => solution(q, &layout, log).map_err(|e| (FileKind::Solution, e))?,
        None => Vec::new(),
    };
    let grids = grid::read_grids(xyz, &layout).map_err(grid_error)?;
    if grids.len() > 1 {
        log(
            FileKind::Grid,
            format!(
                "its {} grids are joined into one mesh, each grid's points and cells after \
                 those of the grid before it (VTK's reader gives them as {} blocks)",
                grids.len(),
                grids.len()
            ),
        );
    }
    let (points, cells) = join_grids(grids, layout.points());
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

/// Every grid's points, one after the other, and the hexahedra of each (those IBLANK keeps)
/// with their point ids offset to match; `points` is the number of points of all grids.
fn join_grids(grids: Vec<grid::Grid>, points: usize) -> (Vec<glam::DVec3>, Vec<[u32; 8]>) {
    let mut all_points = Vec::with_capacity(points);
    let mut cells = Vec::new();
    for g in grids {
        let mut grid_cells = hexahedra(g.dims, &g.points);
        if let Some(iblank) = &g.iblank {
            grid_cells.retain(|cell| {
                cell.iter()
                    .all(|&p| iblank.get(p as usize).is_some_and(|&b| b != 0))
            });
        }
        // The ids fit: the points of all grids were checked against u32 above.
        let base = all_points.len() as u32;
        cells.extend(grid_cells.into_iter().map(|c| c.map(|i| i + base)));
        all_points.extend(g.points);
    }
    (all_points, cells)
}

/// Says in `log` how many bytes after its data a file of layout `layout` holds, if any.
fn note_trailing(
    bytes: &[u8],
    layout: &Layout,
    kind: FileKind,
    log: &mut dyn FnMut(FileKind, String),
) {
    let n = layout.trailing_bytes;
    if n == 0 {
        return;
    }
    let zero = bytes[bytes.len() - n..].iter().all(|&b| b == 0);
    let what = if zero { "all zero" } else { "not all zero" };
    let (noun, verb) = if n == 1 {
        ("byte", "was")
    } else {
        ("bytes", "were")
    };
    log(
        kind,
        format!("{n} {noun} after its last record ({what}) {verb} ignored"),
    );
}

/// The point arrays of a Q file for a grid of the given layout: its own layout detected (with
/// bytes after its data, read as the grid is), its grids the grid file's.
fn solution(
    q: &[u8],
    grid: &Layout,
    log: &mut dyn FnMut(FileKind, String),
) -> Result<Vec<crate::mesh::DataArray>, Error> {
    let q_layout = detect::detect_for(q, FileKind::Solution, Some(grid))?;
    if q_layout.grids != grid.grids {
        let text = |grids: &[[usize; 3]]| {
            let dims: Vec<String> = grids
                .iter()
                .map(|[a, b, c]| format!("{a}×{b}×{c}"))
                .collect();
            match grids.len() {
                1 => format!("dimensions {}", dims[0]),
                n => format!("{n} grids {}", dims.join(", ")),
            }
        };
        return Err(ReadError::new(
            FileKind::Solution.format(),
            0,
            format!(
                "the Q file's {} differ from the grid's {}",
                text(&q_layout.grids),
                text(&grid.grids)
            ),
        )
        .into());
    }
    note_trailing(q, &q_layout, FileKind::Solution, log);
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
