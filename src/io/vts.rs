//! VTK XML structured grid files (`.vts`), as VTK's `vtkXMLStructuredGridWriter` and ParaView
//! write them: one or several `<Piece>`s, each an `Extent` of points (i fastest) whose
//! hexahedra are its cells, read by the same walker and decoders as VTU files (every
//! encoding, compressor and header width they take).
//!
//! - Cells are each piece's `(ni−1)(nj−1)(nk−1)` hexahedra ([`super::structured::hexahedra`],
//!   which orients left-handed grids); pieces are joined as VTU pieces are, the points on the
//!   faces two pieces share kept in each (coincident, as a duplicated seam is).
//! - Blanking as VTK's structured grids have it: a cell flagged hidden or as another piece's
//!   ghost in `vtkGhostType` is dropped, and so is every cell with a corner point flagged
//!   hidden (`vtkStructuredGrid::IsCellVisible`); the ghost arrays are not kept.
//! - A piece flat along an axis (a 2-D grid) has no volume cells: an error saying so. An empty
//!   piece (an extent with nothing in it) is skipped.
//!
//! Errors are [`crate::ReadError`]s of format `VTS` with the byte offset, as for VTU files.
//!
//! A parallel index (`.pvts`) and its `.vts` pieces are read by [`read_parallel_file`].

use std::path::Path;

use crate::{Error, Mesh};

/// The format name in read errors.
const FORMAT: &str = "VTS";

/// Reads a `.vts` file's bytes into a validated mesh.
///
/// ```
/// let file = br#"<VTKFile type="StructuredGrid" version="1.0">
///  <StructuredGrid WholeExtent="0 1 0 1 0 2"><Piece Extent="0 1 0 1 0 2">
///   <PointData Scalars="h"><DataArray type="Float32" Name="h" format="ascii">
///     0 0 0 0  1 1 1 1  2 2 2 2</DataArray></PointData>
///   <Points><DataArray type="Float32" NumberOfComponents="3" format="ascii">
///     0 0 0  1 0 0  0 1 0  1 1 0   0 0 1  1 0 1  0 1 1  1 1 1   0 0 2  1 0 2  0 1 2  1 1 2
///   </DataArray></Points>
///  </Piece></StructuredGrid>
/// </VTKFile>"#;
/// let mesh = cylvol::io::vts::read(file).unwrap();
/// assert_eq!((mesh.point_count(), mesh.cell_count()), (12, 2));
/// assert_eq!(mesh.scalar_range(), Some([0.0, 2.0]));
/// ```
pub fn read(bytes: &[u8]) -> Result<Mesh, Error> {
    read_logged(bytes, &mut |_| {})
}

/// [`read`], giving `log` what was done beyond reading: ghost and blanked cells dropped.
pub fn read_logged(bytes: &[u8], log: &mut dyn FnMut(String)) -> Result<Mesh, Error> {
    let file = super::vtu::read_structured_parts(bytes).map_err(as_vts)?;
    file.notes.into_iter().for_each(&mut *log);
    super::vtu::mesh_with_active(file.parts, file.active.as_deref())
}

/// Reads a `.vts` file: the mesh [`read`] gives for its bytes, errors naming the file.
pub fn read_file(path: &Path) -> Result<Mesh, Error> {
    read_file_logged(path, &mut |_| {})
}

/// [`read_file`], giving `log` what was done beyond reading ([`read_logged`]).
pub fn read_file_logged(path: &Path, log: &mut dyn FnMut(String)) -> Result<Mesh, Error> {
    let bytes = super::read_bytes(path)?;
    read_logged(&bytes, log).map_err(|e| e.in_file(path))
}

/// Reads a parallel structured grid index (`.pvts`, `vtkXMLPStructuredGridWriter`'s) and its
/// pieces, named relative to the index's folder, each as [`read_file`] reads a `.vts` file
/// (its ghost and blanked cells dropped), joined in index order; errors name the file.
pub fn read_parallel_file(index: &Path) -> Result<Mesh, Error> {
    read_parallel_file_logged(index, &mut |_| {})
}

/// [`read_parallel_file`], giving `log` what was done beyond reading ([`read_logged`], for
/// every piece, each note naming its piece).
pub fn read_parallel_file_logged(index: &Path, log: &mut dyn FnMut(String)) -> Result<Mesh, Error> {
    let bytes = super::read_bytes(index)?;
    let folder = index.parent().unwrap_or(Path::new(""));
    let read_piece = |source: &str| {
        let path = folder.join(source);
        let piece = super::read_bytes(&path)?;
        super::vtu::read_structured_parts(&piece)
            .map_err(as_vts)
            .map_err(|e| e.in_file(&path))
    };
    super::vtu::read_index_with(&bytes, super::vtu::Indexed::StructuredGrid, read_piece, log)
        .map_err(|e| e.in_file(index))
}

/// A read error of the shared XML reader, named as this format's.
fn as_vts(e: Error) -> Error {
    match e {
        Error::Read(mut r) => {
            r.format = FORMAT;
            Error::Read(r)
        }
        e => e,
    }
}
