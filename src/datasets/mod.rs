//! The synthetic pump datasets.

use crate::{Error, Mesh};

/// A built-in synthetic dataset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dataset {
    /// An O-grid pipe.
    PumpInlet,
    /// An impeller passage ring.
    PumpRotor,
    /// A widening annulus with vanes.
    PumpDiffuser,
}

/// Generates a dataset with about `cells` cells.
pub fn generate(_dataset: Dataset, _cells: usize) -> Result<Mesh, Error> {
    Err(Error::Invalid("datasets not yet written".into()))
}
