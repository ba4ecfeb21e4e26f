//! Structural checks of a built BVH ([`Bvh::assert_well_formed`]), for tests.

use super::bounds::BvhBounds;
use super::{Bvh, MAX_DEPTH};
use crate::accel::space::Pieces;

impl<B: BvhBounds> Bvh<B> {
    /// Panics, saying what is wrong, unless the BVH is well formed for `pieces` (those it was
    /// built from):
    /// - the nodes form one tree from the root, depth-first (left child next), no deeper
    ///   than [`super::MAX_DEPTH`] allows for the traversal stack;
    /// - every node's stored bound contains its children's, and every leaf's contains its
    ///   pieces' stored bounds;
    /// - every piece is in exactly one leaf, with its own cell and a stored bound that contains
    ///   its `f64` bound as a query compares it;
    /// - leaves hold between 1 and `max_leaf_size` pieces, and together all of them in order.
    pub fn assert_well_formed(&self, pieces: &Pieces<B>) {
        let n = pieces.bounds.len().min(pieces.cells.len());
        assert_eq!(
            self.refs.len(),
            n,
            "BVH holds {} pieces, expected {n}",
            self.refs.len()
        );
        if n == 0 {
            assert!(self.nodes.is_empty(), "an empty BVH has nodes");
            return;
        }
        assert!(!self.nodes.is_empty(), "a BVH of {n} pieces has no node");
        // Tree shape, nesting, leaf ranges.
        let mut seen = vec![false; self.nodes.len()];
        let mut next_ref = 0usize;
        let mut stack = vec![(0usize, 0usize)];
        while let Some((i, depth)) = stack.pop() {
            let node = self
                .nodes
                .get(i)
                .unwrap_or_else(|| panic!("node {i} is out of range"));
            assert!(!seen[i], "node {i} is reached twice");
            seen[i] = true;
            assert!(depth < MAX_DEPTH - 1, "node {i} is too deep ({depth})");
            if node.count == 0 {
                let (l, r) = (i + 1, node.index as usize);
                assert!(
                    l < r && r < self.nodes.len(),
                    "internal node {i}: bad children {l}, {r} of {}",
                    self.nodes.len()
                );
                for c in [l, r] {
                    assert!(
                        B::compact_encloses(&node.bounds, &self.nodes[c].bounds),
                        "node {i} {:?} does not contain its child {c} {:?}",
                        node.bounds,
                        self.nodes[c].bounds
                    );
                }
                stack.push((r, depth + 1));
                stack.push((l, depth + 1));
            } else {
                let (first, count) = (node.index as usize, node.count as usize);
                assert!(
                    count <= self.params.max_leaf_size,
                    "leaf {i} holds {count} pieces, more than {}",
                    self.params.max_leaf_size
                );
                assert_eq!(
                    first, next_ref,
                    "leaf {i} does not continue the pieces in order"
                );
                next_ref = first + count;
                assert!(next_ref <= n, "leaf {i} runs past the pieces");
                for (k, r) in self.refs[first..next_ref].iter().enumerate() {
                    assert!(
                        B::compact_encloses(&node.bounds, &r.bounds),
                        "leaf {i} {:?} does not contain its piece {} {:?}",
                        node.bounds,
                        first + k,
                        r.bounds
                    );
                }
            }
        }
        assert_eq!(next_ref, n, "the leaves hold {next_ref} of {n} pieces");
        if let Some(i) = seen.iter().position(|s| !s) {
            panic!("node {i} is not in the tree");
        }
        // Every piece exactly once: compare the multisets of (cell, stored bound).
        let mut stored: Vec<(u32, [u32; 6])> = self
            .refs
            .iter()
            .map(|r| (r.cell, B::compact_bits(&r.bounds)))
            .collect();
        let mut expected: Vec<(u32, [u32; 6])> = Vec::with_capacity(n);
        for (i, (b, &cell)) in pieces.bounds.iter().zip(&pieces.cells).enumerate() {
            let c = B::compact(&b.linearize(&self.frame), &self.frame);
            assert!(
                B::compact_holds(&c, b, &self.frame),
                "piece {i} {b:?} of cell {cell} is not contained in its stored bound {c:?}"
            );
            expected.push((cell, B::compact_bits(&c)));
        }
        stored.sort_unstable();
        expected.sort_unstable();
        if stored != expected {
            let bad = stored
                .iter()
                .zip(&expected)
                .position(|(a, b)| a != b)
                .unwrap_or(n.saturating_sub(1));
            panic!(
                "the leaves do not hold each piece exactly once (first difference at sorted \
                 position {bad}: stored {:?}, expected {:?})",
                stored.get(bad),
                expected.get(bad)
            );
        }
    }
}
