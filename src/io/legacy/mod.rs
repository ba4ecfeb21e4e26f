//! Legacy VTK files (`.vtk`).

use crate::{Error, Mesh};

/// Reads a legacy VTK file's bytes.
pub fn read(_bytes: &[u8]) -> Result<Mesh, Error> {
    Err(Error::Invalid("legacy VTK reader not yet written".into()))
}

/// Writes a mesh as a BINARY legacy VTK unstructured grid.
pub fn write(_mesh: &Mesh, _out: &mut dyn std::io::Write) -> std::io::Result<()> {
    Err(std::io::Error::other("legacy VTK writer not yet written"))
}
