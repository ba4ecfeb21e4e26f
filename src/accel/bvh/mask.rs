//! Which nodes of a BVH hold a piece of a chosen set of cells ([`NodeMask`]), so that a
//! traversal looking only for those cells (the fast path's cells that the transfer function
//! does not make wholly transparent) never enters the subtrees that hold none of them; and the
//! range of a per-cell interval below each node ([`NodeRanges`]: the scalar range, for an
//! intensity projection's traversal looking only for cells that may beat a ray's extreme).

use rayon::prelude::*;

use super::{Bvh, BvhBounds, Node};

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

/// One interval per node of a BVH: the union of its subtree's cells' intervals (for the
/// renderer, their scalar ranges).
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
/// let ranges = bvh.node_ranges(|cell| [cell as f64, cell as f64 + 0.5]);
/// assert_eq!(ranges.get(0), Some([0.0, 99.5])); // the root's: every cell's
/// assert_eq!(ranges.len(), bvh.stats().nodes);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodeRanges {
    ranges: Vec<[f64; 2]>,
}

impl NodeRanges {
    /// Node `node`'s interval (`None` out of range).
    #[inline]
    pub fn get(&self, node: usize) -> Option<[f64; 2]> {
        self.ranges.get(node).copied()
    }

    /// The number of nodes (that of the BVH it was made for).
    pub fn len(&self) -> usize {
        self.ranges.len()
    }

    /// Whether the BVH had no node.
    pub fn is_empty(&self) -> bool {
        self.ranges.is_empty()
    }
}

/// The empty interval.
const EMPTY_RANGE: [f64; 2] = [f64::INFINITY, f64::NEG_INFINITY];

/// The union of two intervals; one with a NaN end takes in everything.
fn union(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    if a.iter().chain(&b).any(|x| x.is_nan()) {
        return [f64::NEG_INFINITY, f64::INFINITY];
    }
    [a[0].min(b[0]), a[1].max(b[1])]
}

impl<B: BvhBounds> Bvh<B> {
    /// The union of `range(cell)` over each node's subtree: the leaves in parallel, then the
    /// internal nodes from the last to the first. A node holding no piece has the empty
    /// interval `[+∞, −∞]`.
    pub fn node_ranges(&self, range: impl Fn(u32) -> [f64; 2] + Sync) -> NodeRanges {
        let leaves = self
            .nodes
            .par_iter()
            .map(|n| self.leaf_range(n, &range))
            .collect();
        self.node_ranges_from_leaves(leaves)
    }

    /// [`Bvh::node_ranges`] on the calling thread only (for ranges made lazily, as
    /// [`Bvh::nodes_holding_sequential`]).
    pub fn node_ranges_sequential(&self, range: impl Fn(u32) -> [f64; 2]) -> NodeRanges {
        let leaves = self
            .nodes
            .iter()
            .map(|n| self.leaf_range(n, &range))
            .collect();
        self.node_ranges_from_leaves(leaves)
    }

    /// The node ranges from each node's own leaf range (empty for internal nodes).
    fn node_ranges_from_leaves(&self, leaves: Vec<[f64; 2]>) -> NodeRanges {
        NodeRanges {
            ranges: self.spread_upwards(leaves, EMPTY_RANGE, union),
        }
    }

    /// A leaf's union of its pieces' cells' intervals (empty for an internal node).
    fn leaf_range(&self, n: &Node<B::Compact>, range: &impl Fn(u32) -> [f64; 2]) -> [f64; 2] {
        if n.count == 0 {
            return EMPTY_RANGE;
        }
        let first = n.index as usize;
        self.refs
            .get(first..first + n.count as usize)
            .unwrap_or(&[])
            .iter()
            .fold(EMPTY_RANGE, |acc, r| union(acc, range(r.cell)))
    }

    /// The leaves' values (one per node, the internal nodes' ignored) spread to their
    /// ancestors by `join`, from the last node to the first (both children of a node come
    /// after it in the depth-first order); `none` stands for a missing child.
    fn spread_upwards<T: Copy>(
        &self,
        mut values: Vec<T>,
        none: T,
        join: impl Fn(T, T) -> T,
    ) -> Vec<T> {
        for i in (0..self.nodes.len()).rev() {
            let node = &self.nodes[i];
            if node.count == 0 {
                let child = |c: usize| values.get(c).copied().unwrap_or(none);
                values[i] = join(child(i + 1), child(node.index as usize));
            }
        }
        values
    }

    /// The nodes whose subtrees hold a piece of a cell for which `keep(cell)`: the leaves
    /// are checked in parallel, then the internal nodes from the last to the first (both
    /// children of a node come after it in the depth-first order).
    pub fn nodes_holding(&self, keep: impl Fn(u32) -> bool + Sync) -> NodeMask {
        let leaves: Vec<bool> = self
            .nodes
            .par_iter()
            .map(|n| n.count > 0 && self.leaf_holds(n.index, n.count, &keep))
            .collect();
        NodeMask {
            held: self.spread_upwards(leaves, false, |a, b| a || b),
        }
    }

    /// [`Bvh::nodes_holding`] on the calling thread only (for a mask made lazily, whose
    /// maker must not wait on work the thread pool might hand back to it).
    pub fn nodes_holding_sequential(&self, keep: impl Fn(u32) -> bool) -> NodeMask {
        let leaves: Vec<bool> = self
            .nodes
            .iter()
            .map(|n| n.count > 0 && self.leaf_holds(n.index, n.count, &keep))
            .collect();
        NodeMask {
            held: self.spread_upwards(leaves, false, |a, b| a || b),
        }
    }

    fn leaf_holds(&self, first: u32, count: u32, keep: &impl Fn(u32) -> bool) -> bool {
        let first = first as usize;
        self.refs
            .get(first..first + count as usize)
            .unwrap_or(&[])
            .iter()
            .any(|r| keep(r.cell))
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

    /// `cells` cells' boxes scattered by `next` in a 10-unit cube, every `split`-th cell in
    /// two pieces.
    fn scattered(next: &mut impl FnMut() -> f64, cells: u32, split: u32) -> Pieces<Aabb> {
        let mut pieces = Pieces {
            bounds: Vec::new(),
            cells: Vec::new(),
        };
        for c in 0..cells {
            for _ in 0..1 + (c % split == 0) as usize {
                let lo = DVec3::new(next(), next(), next()) * 10.0;
                let size = DVec3::new(next(), next(), next());
                pieces.bounds.push(Aabb::new(lo, lo + size));
                pieces.cells.push(c);
            }
        }
        pieces
    }

    /// The union of `range` over node `i`'s subtree, by walking it.
    fn range_below<B: super::BvhBounds>(
        bvh: &super::Bvh<B>,
        i: usize,
        range: &impl Fn(u32) -> [f64; 2],
    ) -> [f64; 2] {
        let n = &bvh.nodes[i];
        let mut out = [f64::INFINITY, f64::NEG_INFINITY];
        let mut take = |r: [f64; 2]| out = [out[0].min(r[0]), out[1].max(r[1])];
        if n.count > 0 {
            let first = n.index as usize;
            for r in &bvh.refs[first..first + n.count as usize] {
                take(range(r.cell));
            }
        } else {
            take(range_below(bvh, i + 1, range));
            take(range_below(bvh, n.index as usize, range));
        }
        out
    }

    #[test]
    fn node_ranges_equal_a_walk_of_each_subtree_for_every_preset() {
        let mut next = crate::testing::uniform(54321);
        let pieces = scattered(&mut next, 2000, 5);
        let values: Vec<f64> = (0..2000).map(|_| next() * 100.0 - 50.0).collect();
        let range = |c: u32| {
            let v = values[c as usize];
            [v, v + (c % 3) as f64]
        };
        for (name, params) in BvhParams::PRESETS {
            let bvh = build_bvh(&pieces, &params);
            let ranges = bvh.node_ranges(range);
            assert_eq!(ranges, bvh.node_ranges_sequential(range), "{name}");
            assert_eq!(ranges.len(), bvh.nodes.len(), "{name}");
            for i in 0..bvh.nodes.len() {
                assert_eq!(
                    ranges.get(i),
                    Some(range_below(&bvh, i, &range)),
                    "{name} {i}"
                );
            }
            assert_eq!(ranges.get(bvh.nodes.len()), None);
            // A NaN end widens its ancestors to everything, the root included.
            let nan = bvh.node_ranges(|c| if c == 7 { [f64::NAN, 0.0] } else { range(c) });
            assert_eq!(
                nan.get(0),
                Some([f64::NEG_INFINITY, f64::INFINITY]),
                "{name}"
            );
        }
    }

    #[test]
    fn the_mask_equals_a_walk_of_each_subtree_for_every_preset() {
        let pieces = scattered(&mut crate::testing::uniform(12345), 3000, 7);
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
