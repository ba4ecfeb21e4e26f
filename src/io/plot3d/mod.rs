//! PLOT3D whole single-grid files.

use crate::{Error, Mesh};

/// Reads a PLOT3D grid and, optionally, its Q file.
pub fn read(_xyz: &[u8], _q: Option<&[u8]>) -> Result<Mesh, Error> {
    Err(Error::Invalid("PLOT3D reader not yet written".into()))
}
