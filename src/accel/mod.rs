//! The four acceleration structures — Cartesian and cylindrical two-level grids and BVHs —
//! behind one point-location interface.
//!
//! A structure knows nothing of hexahedra: it indexes bounded [`space::Pieces`] of cells and,
//! for a query point, offers candidate cells to a closure until the closure accepts one
//! ([`Structure::find`]). [`Accel::locate`] supplies the closure that tests a cell with the
//! inverse trilinear map. Counters record the work: hexahedra tested, internal and leaf nodes
//! visited (for grids: top-level cells and second-level cells visited).
//!
//! The structures also share one ray contract, for the renderer's skipping: the stretches of
//! a ray that may hold the cells it looks for, each structure by its own traversal (`skip.rs`:
//! a BVH's closest-hit traversal of its nodes, a grid's walk from grid cell to grid cell).

mod build;
pub mod bvh;
pub mod choose;
pub mod grid;
pub mod probe;
pub(crate) mod skip;
pub mod space;

use std::fmt;
use std::ops::AddAssign;
use std::str::FromStr;

use glam::DVec3;

use crate::geometry::bounds::Aabb;
use crate::geometry::cylindrical::CylBounds;

pub use build::{Accel, AccelParams, StructureStats, LOOKUP_PROBES};
pub use bvh::{Bvh, BvhParams};
pub use grid::{CandidateOrder, GridParams, TwoLevelGrid};
pub use space::{Coordinates, Pieces};

/// Which structure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum StructureKind {
    /// Two-level grid in `(x, y, z)`.
    CartGrid,
    /// Two-level grid in `(r, θ, h)` about the machine axis.
    CylGrid,
    /// Binned-SAH BVH of boxes.
    CartBvh,
    /// Binned-SAH BVH of cylindrical sectors.
    CylBvh,
}

impl StructureKind {
    /// All four, in report order.
    pub const ALL: [StructureKind; 4] = [
        StructureKind::CartGrid,
        StructureKind::CylGrid,
        StructureKind::CartBvh,
        StructureKind::CylBvh,
    ];

    /// `cart-grid`, `cyl-grid`, `cart-bvh`, `cyl-bvh`.
    pub fn name(self) -> &'static str {
        match self {
            StructureKind::CartGrid => "cart-grid",
            StructureKind::CylGrid => "cyl-grid",
            StructureKind::CartBvh => "cart-bvh",
            StructureKind::CylBvh => "cyl-bvh",
        }
    }

    /// Whether it works in cylindrical coordinates.
    pub fn is_cylindrical(self) -> bool {
        matches!(self, StructureKind::CylGrid | StructureKind::CylBvh)
    }

    /// Whether it is a grid (else a BVH).
    pub fn is_grid(self) -> bool {
        matches!(self, StructureKind::CartGrid | StructureKind::CylGrid)
    }
}

impl fmt::Display for StructureKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for StructureKind {
    type Err = crate::Error;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        crate::error::by_name(&StructureKind::ALL, StructureKind::name, s, "structure")
    }
}

/// Work done by point location.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Cells tested with the inverse map (the talk's "hexahedra visited").
    pub hex_tests: u64,
    /// Internal nodes visited (grids: top-level cells visited).
    pub internal_visits: u64,
    /// Leaf nodes visited (grids: second-level cells visited).
    pub leaf_visits: u64,
}

impl AddAssign for Counters {
    fn add_assign(&mut self, o: Counters) {
        self.hex_tests += o.hex_tests;
        self.internal_visits += o.internal_visits;
        self.leaf_visits += o.leaf_visits;
    }
}

/// A ray as the structures take it for skipping ([`skip`]): the points `origin + t dir`
/// (`dir` a unit vector) for `t` in `[t0, t1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct RaySpan {
    /// Where the ray starts.
    pub(crate) origin: DVec3,
    /// Its unit direction.
    pub(crate) dir: DVec3,
    /// The start of the span.
    pub(crate) t0: f64,
    /// Its end.
    pub(crate) t1: f64,
}

/// One of the four structures, built.
#[derive(Clone, Debug)]
pub enum Structure {
    /// A grid over boxes in `(x, y, z)` or `(r, φ, h)`.
    Grid(TwoLevelGrid),
    /// A BVH of boxes.
    CartBvh(Bvh<Aabb>),
    /// A BVH of sectors.
    CylBvh(Bvh<CylBounds>),
}

impl Structure {
    /// Offers the cells whose pieces contain `q` (a point as the structure compares it,
    /// [`Coordinates::query`]) to `accept` until it returns `true`; returns that cell.
    #[inline]
    pub fn find(
        &self,
        q: DVec3,
        counters: &mut Counters,
        accept: impl FnMut(u32) -> bool,
    ) -> Option<u32> {
        match self {
            Structure::Grid(g) => g.find(q, counters, accept),
            Structure::CartBvh(b) => b.find_stored(q, counters, accept),
            Structure::CylBvh(b) => b.find_stored(q, counters, accept),
        }
    }
}

/// Asks the processor to start loading the cache line of `x` (nothing elsewhere).
#[inline(always)]
pub(crate) fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is a hint; it reads nothing and faults on no address.
    unsafe {
        core::arch::x86_64::_mm_prefetch(
            x as *const T as *const i8,
            core::arch::x86_64::_MM_HINT_T0,
        );
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}
