//! Passing over what the transfer table makes wholly transparent ([`TransparentSkip`]): the
//! part compositing accumulators share to tell the fast path which cells add nothing, and
//! where the structure holds the next cell that does.

use crate::accel::skip::CellMarks;
use crate::accel::{Accel, Counters, RaySpan};
use crate::render::frame::Frame;
use crate::render::transparency::TransparentCells;

/// The frame's transparent cells and where the structure holds the others (both `None` where
/// nothing is passed over: the paper path, a table transparent nowhere).
#[derive(Clone, Copy)]
pub(crate) struct TransparentSkip<'f> {
    transparent: Option<&'f TransparentCells>,
    visible: Option<&'f CellMarks>,
}

impl<'f> TransparentSkip<'f> {
    /// What `frame` made for passing over transparent cells.
    pub(crate) fn of(frame: &Frame<'f>) -> TransparentSkip<'f> {
        TransparentSkip {
            transparent: frame.transparent,
            visible: frame.visible,
        }
    }

    /// Whether the table makes `cell` wholly transparent.
    #[inline]
    pub(crate) fn adds_nothing(&self, cell: u32) -> bool {
        self.transparent.is_some_and(|m| m.contains(cell))
    }

    /// The next stretch of `span` the structure holds a cell that is not transparent in
    /// (the [`super::Accumulate::next_adding`] contract; `None` where nothing is marked).
    pub(crate) fn next_adding(
        &self,
        accel: &Accel,
        span: RaySpan,
        counters: &mut Counters,
    ) -> Option<Option<(f64, f64, Option<u32>)>> {
        let visible = self.visible?;
        Some(accel.next_marked(span, visible, |c| !self.adds_nothing(c), counters))
    }
}
