//! The synthetic pump datasets (stub: replaced by the datasets branch).

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

impl Dataset {
    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Dataset::PumpInlet => "pump-inlet",
            Dataset::PumpRotor => "pump-rotor",
            Dataset::PumpDiffuser => "pump-diffuser",
        }
    }
}

/// Parses `NAME[:CELLS]`.
pub fn parse_spec(_spec: &str) -> Result<Option<(Dataset, usize)>, Error> {
    Ok(None)
}

/// Generates a dataset with about `cells` cells.
pub fn generate(_dataset: Dataset, _cells: usize) -> Result<Mesh, Error> {
    Err(Error::Invalid("datasets not yet written".into()))
}
