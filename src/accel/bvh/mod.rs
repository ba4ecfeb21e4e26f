//! Binned-SAH BVHs (stub; replaced by the BVH branch).

use glam::DVec3;

use super::Counters;

/// Build parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhParams {
    /// Largest number of pieces in a leaf.
    pub max_leaf_size: usize,
}

/// A BVH over bounds of type `B`.
#[derive(Clone, Debug)]
pub struct Bvh<B> {
    nodes: Vec<B>,
}

impl<B> Bvh<B> {
    /// Offers candidates for `q` until `accept` says yes.
    pub fn find(
        &self,
        _q: DVec3,
        _counters: &mut Counters,
        _accept: impl FnMut(u32) -> bool,
    ) -> Option<u32> {
        let _ = &self.nodes;
        None
    }
}
