//! Binned-SAH bounding volume hierarchies over bounded pieces of cells, in Cartesian space
//! (boxes, [`Aabb`]) or in cylindrical coordinates (sectors, [`CylBounds`]).
//!
//! # Method
//! - **Build** ([`build_bvh`]): top-down, binned surface-area heuristic. Each node bins its
//!   pieces' centroids along each of its three coordinates into [`BvhParams::bins`] bins and
//!   takes the split plane of least cost `C_t · A(P) + A(L) · N(L) + A(R) · N(R)` (or makes a
//!   leaf when that is cheaper than `A(P) · N(P)` and the node holds at most
//!   [`BvhParams::max_leaf_size`] pieces). `A` is the true surface area of the bound in world
//!   units: [`Aabb::surface_area`] for boxes, [`CylBounds::surface_area`] for sectors (two
//!   annular caps, the inner and outer curved faces and two planar sides). Subtrees above a
//!   size threshold are built in parallel with `rayon::join`.
//! - **Build passes in `f32`.** The binning and partitioning passes, which stream over every
//!   piece at every level, work on each piece's *stored* bound (below: `f32`, rounded outward)
//!   as two corners, 32 bytes with the piece's index, with SIMD unions. Unions of stored corners
//!   are exact and the stored form is monotone in the bound, so each node's stored bound is,
//!   bit for bit, the stored form of the union of its pieces' `f64` bounds; only the choice of
//!   split reads the `f32` rounding (centroids and areas).
//! - **Cylindrical bounds.** θ is periodic. The build works in *linear* coordinates
//!   `(r, θ − θ₀, h)`, where `θ₀` is the start of the root's arc and every piece's arc is
//!   unwrapped relative to it; unions and centroids are then ordinary, a node's arc is the
//!   interval it spans from `θ₀` (never the complement of an arc across the seam), and a node
//!   spanning `2π` or more is the whole circle.
//! - **Layout.** Nodes are flattened depth-first into 32-byte records: 24 bytes of `f32`
//!   bounds and two `u32`s (a leaf's piece range, or an internal node's right child; the left
//!   child is the next node). Leaf pieces are 28-byte records (`f32` bounds and the cell id).
//!   All `f32` bounds are rounded **outward** from the `f64` bounds, relative to an anchor
//!   (the root's centre; for sectors only `h` is shifted), so a mesh far from the origin keeps
//!   tight bounds and every stored bound still contains its `f64` bound exactly. θ is stored
//!   as an unwrapped `[θ₀ + lo, θ₀ + hi]`, padded by
//!   [`THETA_PAD`](crate::geometry::pseudo_angle::THETA_PAD), so a parent's stored arc
//!   contains its children's bit for bit.
//! - **Traversal** ([`Bvh::find`]): a small fixed stack; each node popped is tested against the
//!   query and counted (`internal_visits` or `leaf_visits`); in a leaf, each piece whose stored
//!   bound contains the query offers its cell to the caller's closure until it accepts one. A
//!   query is prepared once ([`BvhBounds::prepare_query`]): for sectors its pseudo-angle is
//!   reduced to the root's turn ([`SectorQuery`]), so a node's arc is tested by comparisons
//!   alone, with no reduction of the angle per node.
//!
//! # Example
//! ```
//! use cylvol::accel::bvh::{build_bvh, BvhParams};
//! use cylvol::accel::{space, Counters};
//! use cylvol::datasets::{generate, Dataset};
//!
//! let mesh = generate(Dataset::PumpRotor, 5_000).unwrap();
//! let pieces = space::cartesian_pieces(&mesh);
//! let bvh = build_bvh(&pieces, &BvhParams::default());
//! bvh.assert_well_formed(&pieces);
//! let p = mesh.points()[mesh.cells()[42][0] as usize];
//! let mut counters = Counters::default();
//! let found = bvh.find(p, &mut counters, |c| {
//!     cylvol::geometry::containment::contains(&mesh.cell_corners(c as usize), p)
//! });
//! assert!(found.is_some());
//! assert!(counters.leaf_visits >= 1);
//! ```

mod binned_build;
mod bounds;
mod first_hit;
mod mask;
mod near;
mod node_shapes;
pub(crate) mod ray;
mod stats;
mod traverse;
mod validation;

use std::marker::PhantomData;

pub use binned_build::build_bvh;
pub use bounds::{BoxF32, BvhBounds, LinearFrame, SectorF32, SectorQuery};
pub use mask::{NodeMask, NodeRanges};
pub use node_shapes::{
    arc_narrower_than_half_turn, arc_trig, sector_box, ArcTrig, NodeShape, NodeShapes,
    BOX_AREA_LIMIT,
};
pub use stats::BvhStats;
pub(crate) use traverse::Enter;

#[cfg(doc)]
use crate::geometry::{bounds::Aabb, cylindrical::CylBounds};

/// Deepest a node can be (the root has depth 0); the build switches to median splits before
/// reaching it, so [`Bvh::find`]'s fixed stack never overflows.
pub const MAX_DEPTH: usize = 96;

/// Build parameters of [`build_bvh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhParams {
    /// Largest number of pieces in a leaf (clamped to `1..=255`).
    pub max_leaf_size: usize,
    /// Number of SAH bins per axis (clamped to `2..=32`).
    pub bins: usize,
    /// Cost of visiting a node relative to testing one piece's bound, in the SAH.
    pub traversal_cost: f64,
}

impl Default for BvhParams {
    /// The measured defaults ([`BvhParams::BALANCED`]).
    fn default() -> Self {
        Self::BALANCED
    }
}

impl BvhParams {
    /// The default: leaves of up to 16 pieces, 16 bins, a node visit costing 4 piece tests.
    /// Measured on pump-rotor (0.3 M and 2.1 M cells) and the LOX post: the fewest internal and
    /// leaf nodes visited per lookup of the settings tried, and about 36 bytes per cell; the
    /// hexahedra tested per lookup do not depend on the settings (leaf pieces keep their own
    /// bounds).
    pub const BALANCED: BvhParams = BvhParams {
        max_leaf_size: 16,
        bins: 16,
        traversal_cost: 4.0,
    };
    /// The quickest build: as [`BvhParams::BALANCED`] with 8 bins.
    pub const FAST_BUILD: BvhParams = BvhParams {
        max_leaf_size: 16,
        bins: 8,
        traversal_cost: 4.0,
    };
    /// Small leaves (up to 4 pieces), 32 bins, a node visit costing 2 piece tests: fewer
    /// pieces tested in each leaf, more nodes (about 48 bytes per cell).
    pub const FINE: BvhParams = BvhParams {
        max_leaf_size: 4,
        bins: 32,
        traversal_cost: 2.0,
    };
    /// Every preset, by name.
    pub const PRESETS: [(&'static str, BvhParams); 3] = [
        ("balanced", Self::BALANCED),
        ("fast-build", Self::FAST_BUILD),
        ("fine", Self::FINE),
    ];

    /// The parameters with every field clamped to its valid range (NaN or negative traversal
    /// costs become 0).
    pub fn sanitized(&self) -> BvhParams {
        BvhParams {
            max_leaf_size: self.max_leaf_size.clamp(1, 255),
            bins: self.bins.clamp(2, binned_build::MAX_BINS),
            traversal_cost: if self.traversal_cost > 0.0 {
                self.traversal_cost.min(1e6)
            } else {
                0.0
            },
        }
    }
}

/// A flattened node: `count == 0` for an internal node (left child next, right child at
/// `index`), else a leaf holding pieces `index .. index + count`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub(crate) struct Node<C> {
    pub(crate) bounds: C,
    pub(crate) count: u32,
    pub(crate) index: u32,
}

/// A piece in a leaf: its stored bound and its cell.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub(crate) struct Ref<C> {
    pub(crate) bounds: C,
    pub(crate) cell: u32,
}

/// A BVH over pieces bounded by `B` ([`Aabb`] or [`CylBounds`]); build with [`build_bvh`].
#[derive(Clone, Debug)]
pub struct Bvh<B: BvhBounds> {
    pub(crate) nodes: Vec<Node<B::Compact>>,
    pub(crate) refs: Vec<Ref<B::Compact>>,
    pub(crate) frame: LinearFrame,
    pub(crate) params: BvhParams,
    pub(crate) build_s: f64,
    pub(crate) _bounds: PhantomData<B>,
}

impl<B: BvhBounds> Bvh<B> {
    /// The parameters it was built with (sanitized).
    pub fn params(&self) -> &BvhParams {
        &self.params
    }

    /// Whether it holds no piece.
    pub fn is_empty(&self) -> bool {
        self.refs.is_empty()
    }

    /// The frame its stored bounds are relative to.
    pub fn frame(&self) -> &LinearFrame {
        &self.frame
    }
}
