//! VTK XML unstructured grid files (`.vtu`): a focused reader and a writer.
//!
//! The reader takes what VTK's `vtkXMLUnstructuredGridWriter` and other tools write:
//! - `VTKFile type="UnstructuredGrid"`, `byte_order` `LittleEndian` or `BigEndian`,
//!   `header_type` `UInt32` (the default) or `UInt64`, no compressor or any of the three VTK's
//!   writers offer (ParaView's "Compressor Type"): `vtkZLibDataCompressor`,
//!   `vtkLZ4DataCompressor` (raw LZ4 blocks) and `vtkLZMADataCompressor` (`.xz` streams);
//! - one or several `<Piece>`s (joined; point ids are offset per piece), and the parallel
//!   index (`.pvtu`) of several such files, [`read_parallel`];
//! - ghost cells (`vtkGhostType`'s duplicate and hidden flags) dropped, the ghost arrays too;
//! - `DataArray`s in `ascii`, `binary` (inline base64) or `appended` format, the appended block
//!   `raw` or `base64`, of any numeric type (Int8 … UInt64, Float32, Float64);
//! - `<Points>`, `<Cells>` (`connectivity`, `offsets`, `types`: hexahedra, voxels, wedges,
//!   pyramids, tetrahedra), and the numeric arrays of `<PointData>` and `<CellData>` (string
//!   arrays and `<FieldData>` are skipped). The `Scalars` attribute picks the active scalar.
//!
//! Anything else, or any inconsistency — truncation, bad base64, corrupt compressed blocks, sizes
//! or offsets beyond the data — is a [`crate::ReadError`] with the byte offset; the reader never
//! panics and allocates nothing from a stated size before checking the bytes are there.
//!
//! The same walker and decoders read the point arrays of VTK image data (`.vti`) for
//! [`super::vti::read_point_scalars`].
//!
//! The writer writes Float64 points and arrays, Int64 connectivity and offsets and UInt8 types
//! in the encoding [`VtuOptions`] asks for (compressed with zlib, if at all); every mode reads
//! back in VTK 9.1.

mod decode;
mod parallel;
mod read;
mod write;
mod xml;

pub use parallel::read_parallel;
pub(crate) use parallel::{read_index_with, Indexed};

/// The XML walker and decoders also read VTK images' point arrays, for [`super::vti`], and
/// structured grids, for [`super::vts`].
pub(crate) use read::{mesh_with_active, read_image_points, read_structured_parts};
pub use write::{ByteOrder, Encoding, HeaderType, VtuOptions};
/// XML attribute escaping, shared with the other VTK XML writer ([`super::vti`]).
pub(crate) use xml::escape as xml_escape;

use std::path::Path;

use crate::{Error, Mesh};

/// The format name in read errors.
const FORMAT: &str = "VTU";

/// Reads a VTU file's bytes into a validated mesh.
///
/// ```
/// use cylvol::io::vtu;
/// let file = br#"<?xml version="1.0"?>
/// <VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">
///  <UnstructuredGrid><Piece NumberOfPoints="4" NumberOfCells="1">
///   <Points><DataArray type="Float32" NumberOfComponents="3" format="ascii">
///     0 0 0  1 0 0  0 1 0  0 0 1</DataArray></Points>
///   <Cells>
///    <DataArray type="Int32" Name="connectivity" format="ascii">0 1 2 3</DataArray>
///    <DataArray type="Int32" Name="offsets" format="ascii">4</DataArray>
///    <DataArray type="UInt8" Name="types" format="ascii">10</DataArray>
///   </Cells>
///  </Piece></UnstructuredGrid>
/// </VTKFile>"#;
/// let mesh = vtu::read(file).unwrap();
/// assert_eq!(mesh.cell_count(), 1);
/// assert_eq!(mesh.kinds()[0], cylvol::CellKind::Tetrahedron);
/// ```
pub fn read(bytes: &[u8]) -> Result<Mesh, Error> {
    read::read(bytes)
}

/// Reads a VTU file: the mesh [`read`] gives for its bytes, errors naming the file. Raw
/// appended data (what VTK's writers write by default) is read an array at a time from
/// where the file has it, so the file is never held whole in memory (on Unix, when the XML
/// before the data lies within the first 64 KiB, as VTK's does); any other file is read
/// whole first.
///
/// ```
/// use cylvol::datasets::{generate, Dataset};
/// use cylvol::io::vtu;
/// let mesh = generate(Dataset::PumpInlet, 1000).unwrap();
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("inlet.vtu");
/// vtu::write(&mesh, &mut std::fs::File::create(&path).unwrap()).unwrap();
/// assert_eq!(vtu::read_file(&path).unwrap(), mesh);
/// ```
pub fn read_file(path: &Path) -> Result<Mesh, Error> {
    read_file_logged(path, &mut |_| {})
}

/// [`read_file`], giving `log` what was done beyond reading: empty cells (VTK type 0) dropped
/// with their cell data, ghost and blanked cells dropped (see [`crate::io::read_file_logged`]).
pub fn read_file_logged(path: &Path, log: &mut dyn FnMut(String)) -> Result<Mesh, Error> {
    let file = file_parts(path)?;
    file.notes.into_iter().for_each(&mut *log);
    read::mesh_with_active(file.parts, file.active.as_deref()).map_err(|e| e.in_file(path))
}

/// Reads a parallel VTU index file and its pieces (named relative to the index's folder),
/// each piece as [`read_file`] reads a file: the mesh [`read_parallel`] gives.
pub fn read_parallel_file(index: &Path) -> Result<Mesh, Error> {
    read_parallel_file_logged(index, &mut |_| {})
}

/// [`read_parallel_file`], giving `log` what was done beyond reading (as
/// [`read_file_logged`], for all pieces together).
pub fn read_parallel_file_logged(index: &Path, log: &mut dyn FnMut(String)) -> Result<Mesh, Error> {
    let bytes = crate::io::read_bytes(index)?;
    let folder = index.parent().unwrap_or(Path::new(""));
    parallel::read_index_with(
        &bytes,
        Indexed::UnstructuredGrid,
        |source| file_parts(&folder.join(source)),
        log,
    )
    .map_err(|e| e.in_file(index))
}

/// A VTU file's joined parts, active scalar and notes: I/O errors are [`Error::Io`] with the
/// path, the others are wrapped with it.
fn file_parts(path: &Path) -> Result<read::FileParts, Error> {
    #[cfg(unix)]
    {
        let file = std::fs::File::open(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        if let Some(parts) =
            read::read_file_parts(&file, read::HEAD_BYTES).map_err(|e| e.in_file(path))?
        {
            return Ok(parts);
        }
    }
    let bytes = crate::io::read_bytes(path)?;
    read::read_parts(&bytes).map_err(|e| e.in_file(path))
}

/// Writes a mesh as a VTU file in the default mode ([`VtuOptions::default`]: appended raw
/// data, uncompressed, 64-bit headers).
pub fn write(mesh: &Mesh, out: &mut dyn std::io::Write) -> std::io::Result<()> {
    write_with(mesh, out, &VtuOptions::default())
}

/// Writes a mesh as a VTU file with the given encoding, compression and header width.
///
/// Errors are those of `out`, or `InvalidInput` when a size does not fit a 32-bit header
/// (an uncompressed array over 4 GiB) or the block size is zero.
///
/// ```
/// use cylvol::io::vtu::{self, Encoding, VtuOptions};
/// # let file = br#"<VTKFile type="UnstructuredGrid"><UnstructuredGrid>
/// # <Piece NumberOfPoints="4" NumberOfCells="1"><Points><DataArray type="Float64"
/// # NumberOfComponents="3" format="ascii">0 0 0 1 0 0 0 1 0 0 0 1</DataArray></Points><Cells>
/// # <DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 3</DataArray>
/// # <DataArray type="Int64" Name="offsets" format="ascii">4</DataArray>
/// # <DataArray type="UInt8" Name="types" format="ascii">10</DataArray></Cells></Piece>
/// # </UnstructuredGrid></VTKFile>"#;
/// # let mesh = vtu::read(file).unwrap();
/// let options = VtuOptions { encoding: Encoding::Base64, zlib: Some(6), ..VtuOptions::default() };
/// let mut bytes = Vec::new();
/// vtu::write_with(&mesh, &mut bytes, &options).unwrap();
/// assert_eq!(vtu::read(&bytes).unwrap(), mesh);
/// ```
pub fn write_with(
    mesh: &Mesh,
    out: &mut dyn std::io::Write,
    options: &VtuOptions,
) -> std::io::Result<()> {
    write::write_with(mesh, out, options)
}
