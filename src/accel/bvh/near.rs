//! Neighbourhood queries of a box BVH ([`Bvh::any_near`]): whether some piece lies near a
//! point, the piece test left to a closure.

use glam::DVec3;

use super::{BoxF32, Bvh};
use crate::accel::Counters;
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
    pub fn any_near(&self, q: DVec3, r: f64, accept: impl FnMut(u32) -> bool) -> bool {
        let q = q - self.frame.anchor;
        let pad = r + self.query_pad();
        let holds = |b: &BoxF32| {
            (0..3).all(|a| q[a] >= b.min[a] as f64 - pad && q[a] <= b.max[a] as f64 + pad)
        };
        self.find_where(holds, &mut Counters::default(), accept)
            .is_some()
    }
}
