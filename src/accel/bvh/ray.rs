//! Closest-hit ray traversal of a box BVH ([`Bvh::first_along`]), with the primitive test
//! left to a closure so the BVH never needs to know what its pieces are.

use glam::DVec3;

use super::{BoxF32, Bvh, BvhBounds, MAX_DEPTH};
use crate::accel::Counters;
use crate::geometry::bounds::Aabb;

/// The ray's `t`-interval inside `[lo, hi]` along one axis (origin `o`, direction `d`);
/// empty (`lo > hi`) where it misses.
#[inline]
pub(crate) fn slab(o: f64, d: f64, lo: f64, hi: f64) -> (f64, f64) {
    if d == 0.0 {
        if o >= lo && o <= hi {
            (f64::NEG_INFINITY, f64::INFINITY)
        } else {
            (f64::INFINITY, f64::NEG_INFINITY)
        }
    } else {
        let inv = 1.0 / d;
        let (a, b) = ((lo - o) * inv, (hi - o) * inv);
        (a.min(b), a.max(b))
    }
}

/// The ray's interval in a stored box padded by `pad`, clipped to `[t0, t1]`.
#[inline]
fn box_span(
    o: DVec3,
    d: DVec3,
    pad: f64,
    min: [f32; 3],
    max: [f32; 3],
    t0: f64,
    t1: f64,
) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (t0, t1);
    for a in 0..3 {
        let (s, e) = slab(o[a], d[a], min[a] as f64 - pad, max[a] as f64 + pad);
        lo = lo.max(s);
        hi = hi.min(e);
    }
    (lo <= hi).then_some((lo, hi))
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
        let span = |b: &BoxF32, hi: f64| box_span(o, dir, pad, b.min, b.max, t0, hi);
        self.closest_hit(
            t0,
            t1,
            counters,
            |_, b, hi| span(b, hi).map(|s| s.0),
            |b, cell, hi| span(b, hi).and_then(|(lo, x)| hit(cell, lo, x)),
        )
    }
}
