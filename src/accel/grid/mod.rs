//! Sort-based two-level grids (stub; replaced by the grid branch).

use glam::DVec3;

use super::space::{Coordinates, Pieces};
use super::Counters;
use crate::geometry::bounds::Aabb;

/// Build parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridParams {
    /// Top-level density λ₁.
    pub top_density: f64,
    /// Second-level density λ₂.
    pub leaf_density: f64,
}

/// A two-level grid.
#[derive(Clone, Debug)]
pub struct TwoLevelGrid {
    coordinates: Coordinates,
}

/// Builds a grid over boxes given in `coordinates`.
pub fn build_grid(
    coordinates: Coordinates,
    _pieces: &Pieces<Aabb>,
    _params: &GridParams,
) -> TwoLevelGrid {
    TwoLevelGrid { coordinates }
}

impl TwoLevelGrid {
    /// Offers candidates for `q` (in the grid's coordinates) until `accept` says yes.
    pub fn find(
        &self,
        _q: DVec3,
        _counters: &mut Counters,
        _accept: impl FnMut(u32) -> bool,
    ) -> Option<u32> {
        let _ = self.coordinates;
        None
    }
}
