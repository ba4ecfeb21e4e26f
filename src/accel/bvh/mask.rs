//! Which nodes of a BVH hold a piece of a chosen set of cells ([`NodeMask`]), so that a
//! traversal looking only for those cells (the fast path's cells that the transfer function
//! does not make wholly transparent) never enters the subtrees that hold none of them.

use rayon::prelude::*;

use super::{Bvh, BvhBounds};

/// One flag per node of a BVH: whether its subtree holds a piece of a kept cell.
///
/// ```
/// use cylvol::accel::bvh::{build_bvh, BvhParams};
/// use cylvol::accel::space::Pieces;
/// use cylvol::geometry::bounds::Aabb;
/// use glam::DVec3;
/// let bounds: Vec<Aabb> = (0..100)
///     .map(|i| Aabb::new(DVec3::splat(i as f64), DVec3::splat(i as f64 + 1.0)))
///     .collect();
/// let bvh = build_bvh(&Pieces { cells: (0..100).collect(), bounds }, &BvhParams::default());
/// let mask = bvh.nodes_holding(|cell| cell == 42);
/// assert!(mask.contains(0)); // the root holds every piece
/// assert!(mask.count() < mask.len()); // subtrees without cell 42 are left out
/// assert!(!bvh.nodes_holding(|_| false).contains(0));
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct NodeMask {
    held: Vec<bool>,
}

impl NodeMask {
    /// Whether node `node` (an index into the BVH's depth-first node order) holds a kept
    /// cell; `false` out of range.
    #[inline]
    pub fn contains(&self, node: usize) -> bool {
        self.held.get(node).copied().unwrap_or(false)
    }

    /// The number of nodes (that of the BVH it was made for).
    pub fn len(&self) -> usize {
        self.held.len()
    }

    /// Whether the BVH had no node.
    pub fn is_empty(&self) -> bool {
        self.held.is_empty()
    }

    /// The number of nodes holding a kept cell.
    pub fn count(&self) -> usize {
        self.held.iter().filter(|&&h| h).count()
    }
}

impl<B: BvhBounds> Bvh<B> {
    /// The nodes whose subtrees hold a piece of a cell for which `keep(cell)`: the leaves
    /// are checked in parallel, then the internal nodes from the last to the first (both
    /// children of a node come after it in the depth-first order).
    pub fn nodes_holding(&self, keep: impl Fn(u32) -> bool + Sync) -> NodeMask {
        let leaves: Vec<bool> = self
            .nodes
            .par_iter()
            .map(|n| n.count > 0 && self.leaf_holds(n.index, n.count, &keep))
            .collect();
        self.close_upwards(leaves)
    }

    /// [`Bvh::nodes_holding`] on the calling thread only (for a mask made lazily, whose
    /// maker must not wait on work the thread pool might hand back to it).
    pub fn nodes_holding_sequential(&self, keep: impl Fn(u32) -> bool) -> NodeMask {
        let leaves: Vec<bool> = self
            .nodes
            .iter()
            .map(|n| n.count > 0 && self.leaf_holds(n.index, n.count, &keep))
            .collect();
        self.close_upwards(leaves)
    }

    fn leaf_holds(&self, first: u32, count: u32, keep: &impl Fn(u32) -> bool) -> bool {
        let first = first as usize;
        self.refs
            .get(first..first + count as usize)
            .unwrap_or(&[])
            .iter()
            .any(|r| keep(r.cell))
    }

    /// The leaves' flags spread to their ancestors.
    fn close_upwards(&self, mut held: Vec<bool>) -> NodeMask {
        for i in (0..self.nodes.len()).rev() {
            let node = &self.nodes[i];
            if node.count == 0 {
                let child = |c: usize| held.get(c).copied().unwrap_or(false);
                held[i] = child(i + 1) || child(node.index as usize);
            }
        }
        NodeMask { held }
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::super::{build_bvh, BvhParams};
    use crate::accel::space::Pieces;
    use crate::geometry::bounds::Aabb;

    /// Whether node `i`'s subtree holds a piece of a kept cell, by walking it.
    fn holds<B: super::BvhBounds>(
        bvh: &super::Bvh<B>,
        i: usize,
        keep: &impl Fn(u32) -> bool,
    ) -> bool {
        let n = &bvh.nodes[i];
        if n.count > 0 {
            let first = n.index as usize;
            bvh.refs[first..first + n.count as usize]
                .iter()
                .any(|r| keep(r.cell))
        } else {
            holds(bvh, i + 1, keep) || holds(bvh, n.index as usize, keep)
        }
    }

    #[test]
    fn the_mask_equals_a_walk_of_each_subtree_for_every_preset() {
        // Boxes scattered by a fixed sequence; two pieces per cell for some cells.
        let mut next = crate::testing::uniform(12345);
        let mut bounds = Vec::new();
        let mut cells = Vec::new();
        for c in 0..3000u32 {
            for _ in 0..1 + (c % 7 == 0) as usize {
                let lo = DVec3::new(next(), next(), next()) * 10.0;
                bounds.push(Aabb::new(lo, lo + DVec3::new(next(), next(), next())));
                cells.push(c);
            }
        }
        let pieces = Pieces { bounds, cells };
        let keeps: [&(dyn Fn(u32) -> bool + Sync); 4] =
            [&|_| false, &|_| true, &|c| c % 97 == 3, &|c| {
                (c / 100) % 2 == 0
            }];
        for (name, params) in BvhParams::PRESETS {
            let bvh = build_bvh(&pieces, &params);
            for keep in keeps {
                let parallel = bvh.nodes_holding(keep);
                let sequential = bvh.nodes_holding_sequential(keep);
                assert_eq!(parallel, sequential, "{name}");
                assert_eq!(parallel.len(), bvh.nodes.len(), "{name}");
                for i in 0..bvh.nodes.len() {
                    assert_eq!(
                        parallel.contains(i),
                        holds(&bvh, i, &keep),
                        "{name} node {i}"
                    );
                }
                assert!(!parallel.contains(bvh.nodes.len()), "{name}: out of range");
            }
        }
    }
}
