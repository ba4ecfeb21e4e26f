//! Size and quality figures of a built BVH ([`BvhStats`]).

use serde::Serialize;

use super::bounds::BvhBounds;
use super::{Bvh, Node, Ref};

/// Figures of a built BVH (the `cylvol stats` keys of a BVH).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct BvhStats {
    /// Nodes, internal and leaves.
    pub nodes: usize,
    /// Leaves.
    pub leaves: usize,
    /// Pieces referenced by the leaves (one per cell, more for cells cut at the axis).
    pub references: usize,
    /// Heap bytes held (nodes and leaf pieces, by capacity).
    pub bytes: usize,
    /// Sum of every node's bounding area in world units ([`crate::geometry::Aabb::surface_area`]
    /// or [`crate::geometry::CylBounds::surface_area`] of its stored bound).
    pub surface_area: f64,
    /// Wall time of the build, in seconds.
    pub build_s: f64,
}

impl<B: BvhBounds> Bvh<B> {
    /// Its figures.
    pub fn stats(&self) -> BvhStats {
        BvhStats {
            nodes: self.nodes.len(),
            leaves: self.nodes.iter().filter(|n| n.count > 0).count(),
            references: self.refs.len(),
            bytes: self.nodes.capacity() * std::mem::size_of::<Node<B::Compact>>()
                + self.refs.capacity() * std::mem::size_of::<Ref<B::Compact>>(),
            surface_area: self
                .nodes
                .iter()
                .map(|n| B::expand(&n.bounds, &self.frame).surface_area())
                .sum(),
            build_s: self.build_s,
        }
    }

    /// The depth of the deepest node (the root has depth 0; 0 for an empty BVH).
    pub fn depth(&self) -> usize {
        let mut deepest = 0;
        let mut stack = vec![(0usize, 0usize)];
        while let Some((i, d)) = stack.pop() {
            let Some(n) = self.nodes.get(i) else { continue };
            deepest = deepest.max(d);
            if n.count == 0 {
                stack.push((i + 1, d + 1));
                stack.push((n.index as usize, d + 1));
            }
        }
        deepest
    }
}

#[cfg(test)]
mod tests {
    use super::super::{BoxF32, SectorF32};
    use super::*;

    #[test]
    fn records_are_compact() {
        assert_eq!(std::mem::size_of::<Node<BoxF32>>(), 32);
        assert_eq!(std::mem::size_of::<Node<SectorF32>>(), 32);
        assert_eq!(std::mem::size_of::<Ref<BoxF32>>(), 28);
        assert_eq!(std::mem::size_of::<Ref<SectorF32>>(), 28);
    }
}
