//! Neighbourhood queries of a box BVH ([`Bvh::any_near`]): whether some piece lies near a
//! point, the piece test left to a closure.

use glam::DVec3;

use super::{Bvh, MAX_DEPTH};
use crate::geometry::bounds::Aabb;

impl Bvh<Aabb> {
    /// Whether `accept` holds for a piece whose (stored) box, padded by `r`, contains `q`:
    /// the pieces that may lie within `r` of `q` are offered to `accept` (given the piece's
    /// cell) until it returns `true`.
    ///
    /// ```
    /// use cylvol::accel::bvh::{build_bvh, BvhParams};
    /// use cylvol::accel::space::Pieces;
    /// use cylvol::geometry::bounds::Aabb;
    /// use glam::DVec3;
    /// let boxes: Vec<Aabb> = (0..10)
    ///     .map(|i| Aabb::new(DVec3::new(i as f64, 0.0, 0.0), DVec3::new(i as f64 + 0.5, 1.0, 1.0)))
    ///     .collect();
    /// let bvh = build_bvh(&Pieces { bounds: boxes, cells: (0..10).collect() }, &BvhParams::default());
    /// let q = DVec3::new(3.7, 0.5, 0.5); // 0.2 from box 3, 0.3 from box 4
    /// assert!(!bvh.any_near(q, 0.1, |_| true));
    /// assert!(bvh.any_near(q, 0.25, |c| c == 3));
    /// assert!(!bvh.any_near(q, 0.25, |c| c == 4));
    /// assert!(bvh.any_near(q, 0.35, |c| c == 4));
    /// ```
    pub fn any_near(&self, q: DVec3, r: f64, mut accept: impl FnMut(u32) -> bool) -> bool {
        let Some(root) = self.nodes.first() else {
            return false;
        };
        let q = q - self.frame.anchor;
        let extent = (0..3)
            .map(|a| (root.bounds.max[a] - root.bounds.min[a]) as f64)
            .fold(0.0, f64::max);
        let pad = r + 1e-9 * extent;
        let holds = |min: [f32; 3], max: [f32; 3]| {
            (0..3).all(|a| q[a] >= min[a] as f64 - pad && q[a] <= max[a] as f64 + pad)
        };
        let mut stack = [0u32; MAX_DEPTH];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let at = stack[top];
            let Some(node) = self.nodes.get(at as usize) else {
                continue;
            };
            if !holds(node.bounds.min, node.bounds.max) {
                continue;
            }
            if node.count == 0 {
                // Children: the next node (left) and `index` (right).
                if top + 2 <= MAX_DEPTH {
                    stack[top] = node.index;
                    stack[top + 1] = at + 1;
                    top += 2;
                }
            } else {
                let first = node.index as usize;
                let end = first + node.count as usize;
                for piece in self.refs.get(first..end).unwrap_or(&[]) {
                    if holds(piece.bounds.min, piece.bounds.max) && accept(piece.cell) {
                        return true;
                    }
                }
            }
        }
        false
    }
}
