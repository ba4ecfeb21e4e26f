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
//! The writer writes Float64 points and arrays, Int64 connectivity and offsets and UInt8 types
//! in the encoding [`VtuOptions`] asks for (compressed with zlib, if at all); every mode reads
//! back in VTK 9.1.

mod decode;
mod parallel;
mod read;
mod write;
mod xml;

pub use parallel::read_parallel;

pub use write::{ByteOrder, Encoding, HeaderType, VtuOptions};
/// XML attribute escaping, shared with the other VTK XML writer ([`super::vti`]).
pub(crate) use xml::escape as xml_escape;

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
