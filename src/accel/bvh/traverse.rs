//! Point location through a BVH ([`Bvh::find`]).

use glam::DVec3;

use super::bounds::BvhBounds;
use super::{Bvh, MAX_DEPTH};
use crate::accel::Counters;

impl<B: BvhBounds> Bvh<B> {
    /// Offers the cells of the leaf pieces whose bounds contain `q` to `accept`, until it
    /// returns `true`; returns that cell, or `None` when none is accepted.
    ///
    /// `q` is in the structure's coordinates ([`crate::accel::Coordinates::of`]): `(x, y, z)`
    /// for boxes, `(r, θ, h)` with `θ ∈ (−π, π]` for sectors. Every node popped from the
    /// traversal stack is tested and counted, in `counters.internal_visits` or
    /// `counters.leaf_visits`; `accept` does its own counting of the cells it tests. A cell
    /// cut into several pieces may be offered once for each piece that contains `q`.
    #[inline]
    pub fn find(
        &self,
        q: DVec3,
        counters: &mut Counters,
        accept: impl FnMut(u32) -> bool,
    ) -> Option<u32> {
        self.find_stored(B::stored_coordinates(q), counters, accept)
    }

    /// [`Bvh::find`] for a point already in the stored bounds' coordinates
    /// ([`BvhBounds::stored_coordinates`]): `(x, y, z)` for boxes, `(r, φ, h)` for sectors,
    /// `φ` the pseudo-angle ([`crate::geometry::cylindrical::CylFrame::to_pseudo_cylindrical`]
    /// makes it without trigonometry).
    #[inline]
    pub fn find_stored(
        &self,
        q: DVec3,
        counters: &mut Counters,
        accept: impl FnMut(u32) -> bool,
    ) -> Option<u32> {
        let q = q - self.frame.anchor;
        self.find_where(|b| B::compact_contains(b, q), counters, accept)
    }

    /// The traversal of [`Bvh::find`] for any test of stored bounds: the cells of the leaf
    /// pieces whose bounds pass `holds` (within nodes that pass it) are offered to `accept`
    /// until it returns `true`. Nodes visited are counted in `counters`.
    #[inline]
    pub(crate) fn find_where(
        &self,
        holds: impl Fn(&B::Compact) -> bool,
        counters: &mut Counters,
        mut accept: impl FnMut(u32) -> bool,
    ) -> Option<u32> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut stack = [0u32; MAX_DEPTH];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let at = stack[top];
            let Some(node) = self.nodes.get(at as usize) else {
                continue;
            };
            let inside = holds(&node.bounds);
            if node.count == 0 {
                counters.internal_visits += 1;
                if inside && top + 2 <= MAX_DEPTH {
                    // Right child below, left child (the next node) on top.
                    stack[top] = node.index;
                    stack[top + 1] = at + 1;
                    top += 2;
                }
            } else {
                counters.leaf_visits += 1;
                if inside {
                    let first = node.index as usize;
                    let end = first + node.count as usize;
                    for r in self.refs.get(first..end).unwrap_or(&[]) {
                        if holds(&r.bounds) && accept(r.cell) {
                            return Some(r.cell);
                        }
                    }
                }
            }
        }
        None
    }
}
