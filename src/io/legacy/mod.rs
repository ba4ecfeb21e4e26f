//! Legacy VTK files (`.vtk`): a focused reader for `UNSTRUCTURED_GRID` and `STRUCTURED_GRID`
//! datasets, ASCII or BINARY, and a writer of unstructured grids VTK 9.1 reads.
//!
//! # Reading
//! [`read`] takes the file's bytes; [`read_file`] reads a file from disk, a BINARY one block
//! by block as it is parsed, never holding it whole. They accept what VTK's own legacy writers
//! (and OpenFOAM's `foamToVTK -legacy`) produce:
//! - the header: `# vtk DataFile Version x.y`, a title line, `ASCII` or `BINARY` (big-endian data
//!   after the rest of its keyword line), `DATASET UNSTRUCTURED_GRID` or `STRUCTURED_GRID`
//!   (any other dataset type is an error naming it);
//! - `POINTS n type`, `DIMENSIONS ni nj nk` (structured grids: cells come from
//!   [`crate::io::structured::hexahedra`]), `CELLS` in both layouts — the classic one (a count
//!   before each cell's ids) and VTK 5.1's (`OFFSETS` and `CONNECTIVITY` arrays) — and
//!   `CELL_TYPES n`;
//! - `POINT_DATA n` / `CELL_DATA n` sections with `SCALARS` (any number of components),
//!   `VECTORS` and `NORMALS` (kept as 3-component arrays) and `FIELD` arrays (kept, `NULL_ARRAY`
//!   entries skipped); `TENSORS`, `TENSORS6`, `TEXTURE_COORDINATES`, `COLOR_SCALARS`,
//!   `GLOBAL_IDS`, `PEDIGREE_IDS`, `EDGE_FLAGS` and `LOOKUP_TABLE` definitions are read and
//!   dropped; dataset-level `FIELD` data (such as a `TimeValue`) is read and dropped; VTK 9's
//!   `METADATA` / `INFORMATION` blocks are skipped up to their blank line;
//! - ghost cells (VTK's `vtkGhostType` flags, a `FIELD` array as VTK writes it) dropped, the
//!   ghost arrays too, as the VTU reader does;
//! - the numeric data types `char`, `signed_char`, `unsigned_char`, `short`, `unsigned_short`,
//!   `int`, `unsigned_int`, `long`, `unsigned_long` (8 bytes), `vtktypeint64`, `vtktypeuint64`,
//!   `vtkIdType` (4 bytes, as VTK writes it), `float`, `double`, and `bit` in `FIELD` arrays
//!   and attributes (a `vtkBitArray`, which VTK's reader gives the pipeline as a numeric
//!   array): values 0 and 1, kept like any other number;
//! - `string` (and `utf8_string`) and `variant` arrays, which VTK writes for a
//!   `vtkStringArray` or `vtkVariantArray` in field data (a case name, say) or as pedigree ids:
//!   read past and not kept, as the VTU reader skips string arrays, since no mesh array holds
//!   them. Elsewhere (`POINTS`, `SCALARS`, …) they are an error, as VTK's reader takes no
//!   points or attribute from them either.
//!
//! Every parse failure is an [`Error::Read`] with the byte offset (and, in text, the line) where
//! it was found; a file that ends early says in which section and after how many items. Cell
//! conversion ([`crate::mesh::cells_from_vtk`]) and mesh validation ([`Mesh::from_parts`])
//! report unsupported cell types, bad ids, non-finite values and inverted cells as
//! [`Error::Mesh`]. No count in a file makes the reader allocate more than the file can hold.
//!
//! # Writing
//! [`write()`] writes a BINARY `UNSTRUCTURED_GRID` with `double` points, the classic `CELLS` layout
//! (VTK 5.1's when ids do not fit 32 bits), `CELL_TYPES`, then `CELL_DATA` and `POINT_DATA`:
//! in each, arrays keep their order; the first 1-component array is written as `SCALARS … double`
//! with `LOOKUP_TABLE default`, the first 3-component one as `VECTORS`, and every other array as
//! a one-array `FIELD`, so VTK's reader with default settings keeps them all. [`write_ascii`]
//! and [`write_with`] ([`LegacyOptions`]) give text files and the VTK 5.1 cell layout.

mod cursor;
mod read;
mod values;
mod write;

use std::path::Path;

use crate::{Error, Mesh};

/// Text or binary data.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Encoding {
    /// `BINARY`: big-endian values (the default: compact and exact).
    #[default]
    Binary,
    /// `ASCII`: values as text (shortest representations that read back exactly).
    Ascii,
}

/// How the `CELLS` section is laid out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CellLayout {
    /// `CELLS n size` with a vertex count before each cell's ids, 32-bit (file version 3.0;
    /// every VTK reads it). The writer falls back to [`CellLayout::Vtk51`] when ids or the
    /// list size do not fit 32 bits.
    #[default]
    Classic,
    /// VTK 5.1: `CELLS n+1 m` followed by `OFFSETS vtktypeint64` and
    /// `CONNECTIVITY vtktypeint64` (file version 5.1; VTK ≥ 9.0).
    Vtk51,
}

/// Options for [`write_with`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LegacyOptions {
    /// Binary or text data.
    pub encoding: Encoding,
    /// The `CELLS` layout.
    pub cell_layout: CellLayout,
}

/// Reads a legacy VTK file's bytes (`UNSTRUCTURED_GRID` or `STRUCTURED_GRID`, ASCII or
/// BINARY) into a validated mesh. See the [module documentation](self) for what is kept.
///
/// ```
/// let file = b"# vtk DataFile Version 3.0\none tetrahedron\nASCII\n\
///     DATASET UNSTRUCTURED_GRID\nPOINTS 4 float\n0 0 0 1 0 0 0 1 0 0 0 1\n\
///     CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n\
///     POINT_DATA 4\nSCALARS t float\nLOOKUP_TABLE default\n0 1 2 3\n";
/// let mesh = cylvol::io::legacy::read(file).unwrap();
/// assert_eq!((mesh.point_count(), mesh.cell_count()), (4, 1));
/// assert_eq!(mesh.scalar_range(), Some([0.0, 3.0]));
/// ```
pub fn read(bytes: &[u8]) -> Result<Mesh, Error> {
    read::read(bytes, &mut |_| {})
}

/// Bytes of text the file reader scans at a time between binary blocks.
const TEXT_CHUNK: usize = 64 << 10;

/// Reads a legacy VTK file from disk: what [`read`] gives for its bytes (errors name the
/// file). A BINARY file is read as it is parsed, each array's block with positioned reads of
/// just its bytes (in parallel chunks) and decoded before the next, so the file is never held
/// whole: reading VTK's binary file of a 2.1 M-cell mesh peaks at about the mesh's own size.
/// ASCII files, and any file on other platforms, are read whole.
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("tet.vtk");
/// std::fs::write(&path, b"# vtk DataFile Version 3.0\ntet\nASCII\n\
///     DATASET UNSTRUCTURED_GRID\nPOINTS 4 float\n0 0 0 1 0 0 0 1 0 0 0 1\n\
///     CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n").unwrap();
/// let mesh = cylvol::io::legacy::read_file(&path).unwrap();
/// let mut bytes = Vec::new();
/// cylvol::io::legacy::write(&mesh, &mut bytes).unwrap(); // BINARY
/// std::fs::write(&path, &bytes).unwrap();
/// assert_eq!(cylvol::io::legacy::read_file(&path).unwrap(), mesh);
/// ```
pub fn read_file(path: &Path) -> Result<Mesh, Error> {
    read_file_logged(path, &mut |_| {})
}

/// [`read_file`], giving `log` what was done beyond reading: empty cells (VTK type 0) dropped
/// with their cell data, ghost and blanked cells dropped (see [`crate::io::read_file_logged`]).
pub fn read_file_logged(path: &Path, log: &mut dyn FnMut(String)) -> Result<Mesh, Error> {
    let file = std::fs::File::open(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    #[cfg(unix)]
    if let Ok(meta) = file.metadata() {
        if let (true, Ok(len)) = (meta.is_file(), usize::try_from(meta.len())) {
            if let Some(result) = read::read_file(&file, len, TEXT_CHUNK, log) {
                return result.map_err(|e| e.in_file(path));
            }
        }
    }
    read::read(&crate::io::read_open_file(&file, path)?, log).map_err(|e| e.in_file(path))
}

/// Writes a mesh as a BINARY legacy VTK unstructured grid (classic `CELLS` layout).
///
/// ```
/// # let file = b"# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n\
/// #     POINTS 4 float\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n";
/// # let mesh = cylvol::io::legacy::read(file).unwrap();
/// let mut bytes = Vec::new();
/// cylvol::io::legacy::write(&mesh, &mut bytes).unwrap();
/// assert_eq!(cylvol::io::legacy::read(&bytes).unwrap(), mesh);
/// ```
pub fn write(mesh: &Mesh, out: &mut dyn std::io::Write) -> std::io::Result<()> {
    write_with(mesh, out, &LegacyOptions::default())
}

/// Writes a mesh as an ASCII legacy VTK unstructured grid (classic `CELLS` layout).
pub fn write_ascii(mesh: &Mesh, out: &mut dyn std::io::Write) -> std::io::Result<()> {
    write_with(
        mesh,
        out,
        &LegacyOptions {
            encoding: Encoding::Ascii,
            ..LegacyOptions::default()
        },
    )
}

/// Writes a mesh as a legacy VTK unstructured grid with the given encoding and cell layout.
pub fn write_with(
    mesh: &Mesh,
    out: &mut dyn std::io::Write,
    options: &LegacyOptions,
) -> std::io::Result<()> {
    write::write(mesh, out, options)
}
