//! What the rays of a render share ([`Frame`]): the volume, the options and the transfer
//! table, the boundary part, and what the renderer derived before its rays (the cells the
//! table makes transparent, where the structure holds the others, the nodes' scalar
//! ranges) — made once per render, read by every part of every ray.

use super::accumulate::integrate::Bounded;
use super::boundary::surface::BoundarySurface;
use super::boundary::Boundary;
use super::field::Volume;
use super::options::{RenderOptions, RenderPath};
use super::transfer::TransferTable;
use super::transparency::TransparentCells;
use crate::accel::bvh::NodeRanges;
use crate::accel::skip::CellMarks;

/// What the rays of a render share.
#[derive(Clone, Copy)]
pub(crate) struct Frame<'a> {
    /// The mesh, its structure and scalar.
    pub(crate) volume: &'a Volume<'a>,
    /// The options.
    pub(crate) options: &'a RenderOptions,
    /// The transfer table.
    pub(crate) table: &'a TransferTable,
    /// The boundary questions' part.
    pub(crate) boundary: Boundary<'a>,
    /// The fast path's boundary surface, for skipping the space outside the mesh (`None` on
    /// the paper path, or without one).
    pub(crate) surface: Option<&'a BoundarySurface>,
    /// How many cells the fast path marches before it locates a sample through the
    /// structure (the options' reach times the cells a look-up tests).
    pub(crate) march_reach: f64,
    /// The cells the table makes wholly transparent (fast path, compositing).
    pub(crate) transparent: Option<&'a TransparentCells>,
    /// Where the structure holds the cells that are not (fast path, compositing).
    pub(crate) visible: Option<&'a CellMarks>,
    /// The scalar range below each node of a BVH (fast path, projections).
    pub(crate) ranges: Option<&'a NodeRanges>,
    /// What an error-bounded render's integration reads (`None` for the others).
    pub(crate) bounded: Option<Bounded<'a>>,
    /// Each cell's scalar range over everything drawn (the volume's, or over every periodic
    /// copy where what it draws turns with them).
    pub(crate) cell_ranges: &'a [[f64; 2]],
}

impl Frame<'_> {
    /// Whether the render takes the fast path.
    #[inline]
    pub(crate) fn fast(&self) -> bool {
        self.options.path == RenderPath::Fast
    }
}
