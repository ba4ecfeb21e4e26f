//! Point location through a BVH ([`Bvh::find`]), and the leaf pieces within nodes that pass a
//! test ([`Bvh::collect_where`]).

use glam::DVec3;

use rayon::prelude::*;

use super::bounds::BvhBounds;
use super::Node;
use super::{Bvh, MAX_DEPTH};
use crate::accel::Counters;

/// What [`Bvh::collect_where`] does with a node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Enter {
    /// Pass over its subtree.
    Skip,
    /// Test its children.
    Test,
    /// Take every piece below it, with no more tests.
    All,
}

impl Enter {
    /// What to do with a node reached this way: ask `enter` of its bound when it is to be
    /// tested, else what its parent decided.
    #[inline]
    fn at<C>(self, bounds: &C, enter: &impl Fn(&C) -> Enter) -> Enter {
        match self {
            Enter::Test => enter(bounds),
            decided => decided,
        }
    }
}

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
        let root = self.nodes.first()?;
        let q = B::prepare_query(q - self.frame.anchor, &root.bounds);
        self.find_where(|b| B::query_contains(b, &q), counters, accept)
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
                    // Right child below, left child (the next node) on top; the right child,
                    // far in memory, starts loading while the left one's subtree is searched.
                    if let Some(right) = self.nodes.get(node.index as usize) {
                        crate::accel::prefetch(right);
                    }
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

    /// Every leaf piece reached from the root through nodes that `enter` lets in, mapped by
    /// `piece` (given the piece's stored bound and cell; `None` leaves it out), in depth-first
    /// order; the subtrees below the top levels are walked in parallel.
    ///
    /// `enter` answers for a node's stored bound: [`Enter::Skip`] passes over its subtree,
    /// [`Enter::Test`] tests its children, [`Enter::All`] takes every piece below it with no
    /// more tests. It may skip a node only where no stored bound within the node's would be
    /// let in (a parent's stored bound contains its children's and its pieces', bit for bit):
    /// then the answer is that of `piece` over every piece the test does not rule out.
    pub(crate) fn collect_where<T: Send>(
        &self,
        enter: impl Fn(&B::Compact) -> Enter + Sync,
        piece: impl Fn(&B::Compact, u32) -> Option<T> + Sync,
    ) -> Vec<T> {
        /// Depth of the subtrees walked as parallel tasks (up to 2⁶ of them).
        const TASK_DEPTH: usize = 6;
        // The roots of the tasks: the nodes at that depth (or leaves above it) reached
        // through nodes that pass.
        let mut tasks = Vec::new();
        let mut stack = vec![(0u32, 0usize, Enter::Test)];
        while let Some((at, depth, how)) = stack.pop() {
            let Some(node) = self.nodes.get(at as usize) else {
                continue;
            };
            if depth == TASK_DEPTH || node.count > 0 {
                tasks.push((at, how));
                continue;
            }
            let how = how.at(&node.bounds, &enter);
            if how != Enter::Skip {
                stack.push((node.index, depth + 1, how));
                stack.push((at + 1, depth + 1, how));
            }
        }
        tasks
            .par_iter()
            .flat_map_iter(|&(at, how)| {
                let mut out = Vec::new();
                self.collect_subtree(at, how, &enter, &piece, &mut out);
                out
            })
            .collect()
    }

    /// [`Bvh::collect_where`] below node `at` (tested unless `how` is [`Enter::All`]), into
    /// `out`.
    fn collect_subtree<T>(
        &self,
        at: u32,
        how: Enter,
        enter: &impl Fn(&B::Compact) -> Enter,
        piece: &impl Fn(&B::Compact, u32) -> Option<T>,
        out: &mut Vec<T>,
    ) {
        let Some(node): Option<&Node<B::Compact>> = self.nodes.get(at as usize) else {
            return;
        };
        let how = how.at(&node.bounds, enter);
        if how == Enter::Skip {
            return;
        }
        if node.count > 0 {
            let first = node.index as usize;
            let end = first + node.count as usize;
            let refs = self.refs.get(first..end).unwrap_or(&[]);
            out.extend(refs.iter().filter_map(|r| piece(&r.bounds, r.cell)));
        } else {
            self.collect_subtree(at + 1, how, enter, piece, out);
            self.collect_subtree(node.index, how, enter, piece, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::{AtomicUsize, Ordering};

    use glam::DVec3;

    use super::Enter;
    use crate::accel::bvh::{build_bvh, BoxF32, BvhParams};
    use crate::accel::space::Pieces;
    use crate::geometry::bounds::Aabb;

    /// Whether `a` lies within `b`.
    fn within(a: &BoxF32, b: &BoxF32) -> bool {
        (0..3).all(|k| b.min[k] <= a.min[k] && a.max[k] <= b.max[k])
    }

    /// Whether two stored boxes overlap (closed).
    fn overlap(a: &BoxF32, b: &BoxF32) -> bool {
        (0..3).all(|k| a.min[k] <= b.max[k] && b.min[k] <= a.max[k])
    }

    #[test]
    fn collect_where_finds_every_piece_that_passes_and_skips_subtrees_for_every_preset() {
        // Boxes scattered along a line by a fixed sequence, so a query box meets few subtrees.
        let mut next = crate::testing::uniform(777);
        let bounds: Vec<Aabb> = (0..4000)
            .map(|_| {
                let lo = DVec3::new(100.0 * next(), next(), next());
                Aabb::new(lo, lo + DVec3::splat(0.5 * next()))
            })
            .collect();
        let pieces = Pieces {
            cells: (0..bounds.len() as u32).collect(),
            bounds,
        };
        for (name, params) in BvhParams::PRESETS {
            let bvh = build_bvh(&pieces, &params);
            let root = bvh.nodes[0].bounds;
            for (k, span) in [(0.0, 0.0), (0.2, 0.3), (0.45, 0.5), (0.0, 1.0)]
                .into_iter()
                .enumerate()
            {
                // A slab of the root's box along x.
                let mut query = root;
                let len = root.max[0] - root.min[0];
                query.min[0] = root.min[0] + span.0 as f32 * len;
                query.max[0] = root.min[0] + span.1 as f32 * len;
                let offered = AtomicUsize::new(0);
                let tested = AtomicUsize::new(0);
                let mut found = bvh.collect_where(
                    |b| match (tested.fetch_add(1, Ordering::Relaxed), overlap(b, &query)).1 {
                        false => Enter::Skip,
                        true if within(b, &query) => Enter::All,
                        true => Enter::Test,
                    },
                    |b, cell| {
                        offered.fetch_add(1, Ordering::Relaxed);
                        overlap(b, &query).then_some(cell)
                    },
                );
                let n = found.len();
                found.sort_unstable();
                found.dedup();
                assert_eq!(found.len(), n, "{name} query {k}: a piece twice");
                let mut brute: Vec<u32> = bvh
                    .refs
                    .iter()
                    .filter(|r| overlap(&r.bounds, &query))
                    .map(|r| r.cell)
                    .collect();
                brute.sort_unstable();
                assert_eq!(found, brute, "{name} query {k}");
                let offered = offered.into_inner();
                if k < 3 {
                    assert!(
                        offered < bvh.refs.len() / 2,
                        "{name} query {k}: {offered} of {} pieces offered",
                        bvh.refs.len()
                    );
                } else {
                    assert_eq!(offered, bvh.refs.len(), "{name}: the whole root");
                    // The root lies within the query: no node below it is tested.
                    assert_eq!(tested.into_inner(), 1, "{name}");
                }
            }
        }
    }
}
