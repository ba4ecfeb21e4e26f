//! VTK XML unstructured grid files (`.vtu`).

use crate::{Error, Mesh};

/// Reads a VTU file's bytes.
pub fn read(_bytes: &[u8]) -> Result<Mesh, Error> {
    Err(Error::Invalid("VTU reader not yet written".into()))
}

/// Writes a mesh as a VTU file.
pub fn write(_mesh: &Mesh, _out: &mut dyn std::io::Write) -> std::io::Result<()> {
    Err(std::io::Error::other("VTU writer not yet written"))
}
