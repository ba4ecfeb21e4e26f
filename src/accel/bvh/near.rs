//! Neighbourhood queries of a box BVH: whether some piece lies near a point
//! ([`Bvh::any_near`]), and which pieces lie near a box ([`Bvh::each_near_box`]), the piece
//! test left to a closure.

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

    /// Offers to `visit` (given the piece's cell) every piece whose stored box, padded by `r`,
    /// meets the box `b`, until `visit` returns `true`; returns whether it did. One traversal
    /// for what [`Bvh::any_near`] would ask point by point of points spread over `b`.
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
    /// // From x = 3.7 to 5.2: boxes 4 and 5; padded by 0.25, box 3 too.
    /// let b = Aabb::new(DVec3::new(3.7, 0.5, 0.5), DVec3::new(5.2, 0.5, 0.5));
    /// let mut met = Vec::new();
    /// assert!(!bvh.each_near_box(&b, 0.0, |c| { met.push(c); false }));
    /// met.sort();
    /// assert_eq!(met, [4, 5]);
    /// met.clear();
    /// bvh.each_near_box(&b, 0.25, |c| { met.push(c); false });
    /// met.sort();
    /// assert_eq!(met, [3, 4, 5]);
    /// assert!(bvh.each_near_box(&b, 0.0, |c| c == 5));
    /// ```
    pub fn each_near_box(&self, b: &Aabb, r: f64, visit: impl FnMut(u32) -> bool) -> bool {
        let (lo, hi) = (b.min - self.frame.anchor, b.max - self.frame.anchor);
        let pad = r + self.query_pad();
        let meets = |c: &BoxF32| {
            (0..3).all(|a| hi[a] >= c.min[a] as f64 - pad && lo[a] <= c.max[a] as f64 + pad)
        };
        self.find_where(meets, &mut Counters::default(), visit)
            .is_some()
    }
}
