//! Closest-hit ray traversal of a box BVH ([`Bvh::first_along`]), with the primitive test
//! left to a closure so the BVH never needs to know what its pieces are.

use glam::DVec3;

use super::{BoxF32, Bvh, BvhBounds, MAX_DEPTH};
use crate::accel::Counters;
use crate::geometry::bounds::Aabb;

/// The reciprocal of a ray direction for [`clip_to_slab`] and [`box_span`]: `1 / d` per
/// axis, with both zeros taken as `+0` (`-0 + 0 = +0`), so that a component of zero gives
/// `+∞`.
#[inline]
pub(crate) fn reciprocal(d: DVec3) -> DVec3 {
    DVec3::ONE / (d + DVec3::ZERO)
}

/// The part of the ray interval `span` inside the slab `[lo, hi]` along one axis, for the
/// ray's origin `o` and the [`reciprocal`] `inv` of its direction along that axis (empty,
/// start above end, where it misses).
///
/// Plain comparisons, not `f64::min` and `max` (whose `NaN` handling costs several
/// instructions each, and these run for every node a ray query visits): a `NaN` (`0 · ∞`,
/// the ray parallel to the slab and on one of its planes) fails every comparison and leaves
/// `span` as it was, which is conservative; a direction of zero keeps `span` inside the slab
/// and empties it outside, as a test of the origin against the slab would (for a finite
/// `span`: outside, the slab's ends are both `+∞` or both `−∞`, so an infinite end of `span`
/// may be left equal to the other).
#[inline(always)]
pub(crate) fn clip_to_slab(o: f64, inv: f64, lo: f64, hi: f64, span: (f64, f64)) -> (f64, f64) {
    let (s, e) = ((lo - o) * inv, (hi - o) * inv);
    let (near, far) = if e < s { (e, s) } else { (s, e) };
    (
        if near > span.0 { near } else { span.0 },
        if far < span.1 { far } else { span.1 },
    )
}

/// The ray's interval in a stored box padded by `pad`, clipped to `[t0, t1]`, for the ray's
/// origin `o` and the [`reciprocal`] `inv` of its direction; `None` where it misses, even
/// with an infinite `t0` or `t1` (see [`clip_to_slab`]): along an axis the ray is parallel
/// to and outside of, the interval is pushed to `±∞`, and the finite end from an axis it is
/// not parallel to then empties it.
#[inline(always)]
pub(crate) fn box_span(
    o: DVec3,
    inv: DVec3,
    pad: f64,
    min: [f32; 3],
    max: [f32; 3],
    t0: f64,
    t1: f64,
) -> Option<(f64, f64)> {
    let mut span = (t0, t1);
    for a in 0..3 {
        let (lo, hi) = (min[a] as f64 - pad, max[a] as f64 + pad);
        span = clip_to_slab(o[a], inv[a], lo, hi, span);
    }
    (span.0 <= span.1).then_some(span)
}

impl<B: BvhBounds> Bvh<B> {
    /// Closest-hit traversal along a ray, the bounds tests left to closures: a node is
    /// entered at `enter_node(index, bounds, hi)` (the ray's entry into it on `[t0, hi]`,
    /// `hi` the best entry so far), nearest child first; a leaf's pieces are offered to
    /// `hit(bounds, cell, hi)`, which gives the ray's `(entry, exit)` of the piece. Returns the
    /// piece with the smallest entry, as `(entry, exit, cell)`. Node visits are counted.
    pub(crate) fn closest_hit(
        &self,
        t0: f64,
        t1: f64,
        counters: &mut Counters,
        mut enter_node: impl FnMut(usize, &B::Compact, f64) -> Option<f64>,
        mut hit: impl FnMut(&B::Compact, u32, f64) -> Option<(f64, f64)>,
    ) -> Option<(f64, f64, u32)> {
        let root = self.nodes.first()?;
        enter_node(0, &root.bounds, t1)?;
        let mut best: Option<(f64, f64, u32)> = None;
        let mut hi = t1;
        let mut stack = [(0u32, t0); MAX_DEPTH];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let (at, entry) = stack[top];
            if entry > hi {
                continue;
            }
            let Some(node) = self.nodes.get(at as usize) else {
                continue;
            };
            if node.count == 0 {
                counters.internal_visits += 1;
                let mut child = |n: u32| {
                    self.nodes
                        .get(n as usize)
                        .and_then(|c| enter_node(n as usize, &c.bounds, hi))
                };
                let (l, r) = (at + 1, node.index);
                let (el, er) = (child(l), child(r));
                // The nearer child goes on top.
                let mut order = [(l, el), (r, er)];
                if matches!((el, er), (Some(a), Some(b)) if a <= b) {
                    order.swap(0, 1);
                }
                for (n, e) in order {
                    if let Some(e) = e {
                        if top < MAX_DEPTH {
                            stack[top] = (n, e);
                            top += 1;
                        }
                    }
                }
            } else {
                counters.leaf_visits += 1;
                let first = node.index as usize;
                let end = first + node.count as usize;
                for piece in self.refs.get(first..end).unwrap_or(&[]) {
                    if let Some((e, x)) = hit(&piece.bounds, piece.cell, hi) {
                        if e <= hi && best.map_or(true, |b| e < b.0) {
                            best = Some((e, x, piece.cell));
                            hi = e;
                        }
                    }
                }
            }
        }
        best
    }
}

impl Bvh<Aabb> {
    /// The padding of every stored box in queries: `1e-9` of the root's largest extent.
    pub(crate) fn query_pad(&self) -> f64 {
        self.nodes.first().map_or(0.0, |root| {
            let e = (0..3)
                .map(|a| (root.bounds.max[a] - root.bounds.min[a]) as f64)
                .fold(0.0, f64::max);
            1e-9 * e
        })
    }

    /// The first piece along the ray `origin + t dir` on `[t0, t1]`: among the pieces whose
    /// (padded) boxes the ray meets, `hit(cell, lo, hi)` — given the piece's cell and the
    /// ray's interval in its box — says where the ray meets the piece itself (`None`: not
    /// at all); the piece with the smallest such entry wins. Returns its `(entry, exit,
    /// cell)`. Nodes are visited nearest first, and those entered beyond the best entry so
    /// far are skipped; every node tested is counted in `counters`.
    ///
    /// ```
    /// use cylvol::accel::bvh::{build_bvh, BvhParams};
    /// use cylvol::accel::space::Pieces;
    /// use cylvol::accel::Counters;
    /// use cylvol::geometry::bounds::Aabb;
    /// use glam::DVec3;
    /// let boxes: Vec<Aabb> = (0..10)
    ///     .map(|i| Aabb::new(DVec3::new(i as f64, 0.0, 0.0), DVec3::new(i as f64 + 0.5, 1.0, 1.0)))
    ///     .collect();
    /// let cells = (0..10).collect();
    /// let bvh = build_bvh(&Pieces { bounds: boxes, cells }, &BvhParams::default());
    /// let mut counters = Counters::default();
    /// let o = DVec3::new(-1.0, 0.5, 0.5);
    /// // Every box is a hit: the first is box 0, entered at t = 1.
    /// let (entry, _, cell) = bvh.first_along(o, DVec3::X, 0.0, 100.0, &mut counters, |_, lo, hi| Some((lo, hi))).unwrap();
    /// assert_eq!(cell, 0);
    /// assert!((entry - 1.0).abs() < 1e-6);
    /// // Only odd boxes are hits, from t = 2.7 (x = 1.7) on: box 3.
    /// let first = bvh.first_along(o, DVec3::X, 2.7, 100.0, &mut counters, |c, lo, hi| (c % 2 == 1).then_some((lo, hi)));
    /// assert_eq!(first.unwrap().2, 3);
    /// ```
    pub fn first_along(
        &self,
        origin: DVec3,
        dir: DVec3,
        t0: f64,
        t1: f64,
        counters: &mut Counters,
        mut hit: impl FnMut(u32, f64, f64) -> Option<(f64, f64)>,
    ) -> Option<(f64, f64, u32)> {
        let o = origin - self.frame.anchor;
        let pad = self.query_pad();
        let inv = reciprocal(dir);
        let span = |b: &BoxF32, hi: f64| box_span(o, inv, pad, b.min, b.max, t0, hi);
        self.closest_hit(
            t0,
            t1,
            counters,
            |_, b, hi| span(b, hi).map(|s| s.0),
            |b, cell, hi| span(b, hi).and_then(|(lo, x)| hit(cell, lo, x)),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The textbook slab: a division per plane, `f64::min` and `max`, and a zero direction
    /// tested by the origin.
    fn textbook(o: f64, d: f64, lo: f64, hi: f64, span: (f64, f64)) -> (f64, f64) {
        if d == 0.0 {
            return if o >= lo && o <= hi {
                span
            } else {
                (f64::INFINITY, f64::NEG_INFINITY)
            };
        }
        let (s, e) = ((lo - o) / d, (hi - o) / d);
        (span.0.max(s.min(e)), span.1.min(s.max(e)))
    }

    #[test]
    fn a_zero_direction_tests_the_origin_either_sign() {
        let within = |(s, e): (f64, f64)| s <= e;
        for zero in [0.0, -0.0] {
            let inv = reciprocal(DVec3::new(zero, 1.0, 1.0)).x;
            assert_eq!(inv, f64::INFINITY);
            assert_eq!(clip_to_slab(0.5, inv, 0.0, 1.0, (0.0, 2.0)), (0.0, 2.0));
            assert!(!within(clip_to_slab(-0.5, inv, 0.0, 1.0, (-3.0, 2.0))));
            assert!(!within(clip_to_slab(1.5, inv, 0.0, 1.0, (-3.0, 2.0))));
            // On either plane (0 · ∞ is NaN): the interval is kept, never lost.
            assert_eq!(clip_to_slab(0.0, inv, 0.0, 1.0, (0.0, 2.0)), (0.0, 2.0));
            assert_eq!(clip_to_slab(1.0, inv, 0.0, 1.0, (0.0, 2.0)), (0.0, 2.0));
        }
    }

    #[test]
    fn a_box_beside_a_parallel_ray_is_missed_over_the_whole_line() {
        let all = (f64::NEG_INFINITY, f64::INFINITY);
        let (min, max) = ([0.0f32; 3], [1.0f32; 3]);
        for zero in [0.0, -0.0] {
            let inv = reciprocal(DVec3::new(1.0, zero, -zero));
            for y in [-0.5, 1.5] {
                let o = DVec3::new(-2.0, y, 0.5);
                assert_eq!(box_span(o, inv, 1e-9, min, max, all.0, all.1), None);
                assert_eq!(box_span(o, inv, 1e-9, min, max, 0.0, all.1), None);
            }
            let o = DVec3::new(-2.0, 0.5, 0.5);
            let (s, e) = box_span(o, inv, 0.0, min, max, all.0, all.1).unwrap();
            assert!(
                (s - 2.0).abs() < 1e-15 && (e - 3.0).abs() < 1e-15,
                "{s} {e}"
            );
        }
    }

    proptest! {
        #[test]
        fn clip_to_slab_is_the_textbook_slab(
            o in -10.0f64..10.0,
            d in prop_oneof![-2.0f64..2.0, Just(0.0), Just(-0.0), Just(1e-300)],
            lo in -5.0f64..5.0,
            width in prop_oneof![0.0f64..4.0, Just(0.0)],
            span in (-20.0f64..20.0, 0.0f64..40.0),
        ) {
            let (hi, span) = (lo + width, (span.0, span.0 + span.1));
            let got = clip_to_slab(o, 1.0 / (d + 0.0), lo, hi, span);
            let want = textbook(o, d, lo, hi, span);
            // Multiplying by the reciprocal rounds twice: within a few ulps of the quotient.
            let close = |a: f64, b: f64| a == b || (a - b).abs() <= 1e-12 * a.abs().max(b.abs());
            if want.0 <= want.1 {
                prop_assert!(close(got.0, want.0) && close(got.1, want.1), "{got:?} {want:?}");
            } else {
                // Missed, or met only within rounding of one end.
                prop_assert!(got.0 > got.1 || close(got.0, got.1), "{got:?} {want:?}");
            }
        }
    }
}
