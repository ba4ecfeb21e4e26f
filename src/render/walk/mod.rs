//! Stepping through the mesh from cell to cell across faces: the face neighbours a step
//! follows ([`Neighbours`]), the one place a step crosses a face ([`Cells::across`]), the
//! walk of a point over the cells' face planes ([`point`]) and the march of a ray from cell
//! to cell through its exit faces ([`march`]).
//!
//! Both only *propose* cells: a cell is accepted only by the inverse map's containment test,
//! the same test the structure's point location uses, so a step never yields a point outside
//! its cell; where it gives up, the caller asks the structure.

pub(crate) mod march;
pub(crate) mod point;

use crate::mesh::topology::FaceNeighbours;
use crate::Mesh;

/// The face neighbours of a cell, for the fast path: six cell ids, `u32::MAX` for none.
/// Closures `Fn(u32) -> [u32; 6]` implement it.
///
/// A face without a neighbour is taken for the mesh's boundary by the boundary crossing
/// searches: the source must pair every shared face, θ-seam faces of coincident but separate
/// points included (as [`FaceNeighbours::build_with_tolerance`] does), or say it does not with
/// [`Neighbours::complete`].
pub trait Neighbours: Sync {
    /// The cells across the six faces of `cell` (`u32::MAX` where there is none).
    fn neighbours(&self, cell: u32) -> [u32; 6];

    /// Whether every shared face has its neighbour, so that a face with none is on the mesh's
    /// boundary (default `true`).
    fn complete(&self) -> bool {
        true
    }

    /// Starts loading the neighbours of `cell` into the cache (a hint; by default nothing).
    fn prefetch(&self, _cell: u32) {}
}

impl<F: Fn(u32) -> [u32; 6] + Sync> Neighbours for F {
    fn neighbours(&self, cell: u32) -> [u32; 6] {
        self(cell)
    }
}

impl Neighbours for FaceNeighbours {
    fn neighbours(&self, cell: u32) -> [u32; 6] {
        FaceNeighbours::neighbours(self, cell)
    }

    /// Only once [`FaceNeighbours::check_boundary`] has found no hanging face.
    fn complete(&self) -> bool {
        self.is_closed()
    }

    #[inline]
    fn prefetch(&self, cell: u32) {
        if let Some(row) = self.raw().get(cell as usize * 6) {
            crate::accel::prefetch(row);
        }
    }
}

/// No neighbours known: the fast path goes from the previous cell straight to the structure.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoNeighbours;

impl Neighbours for NoNeighbours {
    fn neighbours(&self, _cell: u32) -> [u32; 6] {
        [u32::MAX; 6]
    }

    fn complete(&self) -> bool {
        false
    }
}

/// What lies across a face of a cell ([`Cells::across`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Across {
    /// This cell.
    Cell(u32),
    /// Nothing: the face has no neighbour.
    Boundary,
    /// A neighbour that cannot be stepped into (out of range, or the cell itself).
    Invalid,
}

/// The mesh's cells with the face neighbours a step follows.
#[derive(Clone, Copy)]
pub(crate) struct Cells<'a> {
    /// The mesh.
    pub(crate) mesh: &'a Mesh,
    /// Its face neighbours.
    pub(crate) neighbours: &'a dyn Neighbours,
}

impl Cells<'_> {
    /// What lies across face `face` (0–5) of `cell`: every step from a cell to the next goes
    /// through here.
    #[inline]
    pub(crate) fn across(&self, cell: u32, face: usize) -> Across {
        let n = self.neighbours.neighbours(cell)[face];
        if n == u32::MAX {
            Across::Boundary
        } else if n as usize >= self.mesh.cell_count() || n == cell {
            Across::Invalid
        } else {
            Across::Cell(n)
        }
    }

    /// Whether face `face` of `cell` has no neighbour (out of range: not known to).
    pub(crate) fn on_boundary(&self, cell: u32, face: usize) -> bool {
        self.neighbours
            .neighbours(cell)
            .get(face)
            .is_some_and(|&n| n == u32::MAX)
    }
}
