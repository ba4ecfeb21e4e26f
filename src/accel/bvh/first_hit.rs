//! The first piece of a kept cell along a ray, in a BVH's own frame: the traversal behind
//! the structures' ray contract ([`crate::accel::skip`]).
//!
//! A closest-hit traversal of the ray against the node and piece bounds gives the smallest
//! `t ≥ t₀` at which the ray is inside the bound of a piece of a kept cell, within the nodes
//! kept. Boxes are slab-tested. Sectors are tested on `r` (a quadratic in `t`), `h` (a slab)
//! and, for arcs narrower than π, θ (two half-planes through the axis); a wider arc is tested
//! on `r` and `h` only, a lower bound of the true entry, which is all skipping needs. A
//! cylindrical BVH's nodes whose boxes in the axis frame are nearly as tight as their sectors
//! are slab-tested as those boxes instead (a quarter of the cost; the box holds the sector, so
//! the entry is again a lower bound); the others keep their sectors, with their arcs' sines
//! and cosines. Which is which is decided once per structure ([`super::NodeShapes`]).

use glam::DVec3;

use super::ray::{box_span, clip_to_slab, reciprocal};
use super::{
    arc_narrower_than_half_turn, arc_trig, ArcTrig, BoxF32, Bvh, BvhBounds, NodeShape, SectorF32,
};
use crate::accel::{Counters, RaySpan};
use crate::geometry::bounds::Aabb;
use crate::geometry::cylindrical::{CylBounds, CylFrame};

/// A ray in the structure's frame, ready for its bounds.
#[derive(Clone, Copy, Debug)]
enum LocalRay {
    /// Origin relative to the BVH's anchor, the direction's reciprocal
    /// ([`reciprocal`]).
    Boxes { o: DVec3, inv: DVec3, pad: f64 },
    /// In the cylindrical frame: `(x, y)` across the axis, `h` relative to the anchor.
    Sectors {
        o: DVec3,
        d: DVec3,
        /// The reciprocal of `d` ([`reciprocal`]), for `h` and the nodes' boxes.
        inv: DVec3,
        pad: f64,
        /// `r²` along the ray, `a t² + 2 b t + c`, with `1/a`.
        quad: [f64; 4],
    },
}

/// An entry and exit `t` of a ray into and out of a bound.
type Span = (f64, f64);

/// A ray in the cylindrical frame, for [`SectorRay::entry`]: `(x, y)` across the axis, `h`
/// relative to the anchor.
#[derive(Clone, Copy, Debug)]
struct SectorRay {
    o: DVec3,
    d: DVec3,
    /// The reciprocal of `d.z` ([`reciprocal`]).
    inv_h: f64,
    pad: f64,
    /// `r²` along the ray, `a t² + 2 b t + c`, with `1/a`.
    quad: [f64; 4],
}

impl SectorRay {
    /// The entry into a sector on `[t0, t1]`, with the arc's sines and cosines `trig` if
    /// known.
    #[inline]
    fn entry(&self, s: &SectorF32, trig: Option<&ArcTrig>, t0: f64, t1: f64) -> Option<Span> {
        let SectorRay {
            o,
            d,
            inv_h,
            pad,
            quad,
        } = *self;
        if s.r[0] > s.r[1] || s.h[0] > s.h[1] {
            return None;
        }
        // (A ray across the axis, outside the `h` slab, may leave a one-point interval at ±∞
        // with an infinite `t0` or `t1`; the `r` bound below, finite for such a ray, empties
        // it.)
        let (h0, h1) = (s.h[0] as f64 - pad, s.h[1] as f64 + pad);
        let (mut lo, mut hi) = clip_to_slab(o.z, inv_h, h0, h1, (t0, t1));
        if lo > hi {
            return None;
        }
        // r² along the ray: a t² + 2 b t + c. Inside r ≤ r1 first: one interval, and no
        // trigonometry for the many bounds it rejects.
        let [a, b, c, inv_a] = quad;
        let r1 = s.r[1] as f64 + pad;
        let r0 = s.r[0] as f64 - pad;
        let parallel = a <= 1e-300;
        if parallel {
            if c > r1 * r1 {
                return None;
            }
        } else {
            let disc1 = b * b - a * (c - r1 * r1);
            if disc1 < 0.0 {
                return None;
            }
            let sq1 = disc1.sqrt();
            lo = lo.max((-b - sq1) * inv_a);
            hi = hi.min((-b + sq1) * inv_a);
            if lo > hi {
                return None;
            }
        }
        // θ: an arc narrower than π is the intersection of two half-planes through the axis,
        // `cross(e(θ_lo), x) ≥ 0` and `cross(x, e(θ_hi)) ≥ 0` (padded by `pad`).
        if arc_narrower_than_half_turn(s, trig) {
            let [s0, c0, s1, c1] = match trig {
                Some(t) => *t,
                None => arc_trig(s),
            };
            for (f0, f1) in [
                (c0 * o.y - s0 * o.x, c0 * d.y - s0 * d.x),
                (s1 * o.x - c1 * o.y, s1 * d.x - c1 * d.y),
            ] {
                // f0 + t f1 ≥ −pad
                if f1 == 0.0 {
                    if f0 < -pad {
                        return None;
                    }
                } else {
                    let tc = (-pad - f0) / f1;
                    if f1 > 0.0 {
                        lo = lo.max(tc);
                    } else {
                        hi = hi.min(tc);
                    }
                }
            }
            if lo > hi {
                return None;
            }
        }
        // Outside r < r0: the complement of one interval.
        if parallel {
            if r0 > 0.0 && c < r0 * r0 {
                return None;
            }
            return Some((lo, hi));
        }
        if r0 > 0.0 {
            let disc0 = b * b - a * (c - r0 * r0);
            if disc0 > 0.0 {
                let sq0 = disc0.sqrt();
                let (ia, ib) = ((-b - sq0) * inv_a, (-b + sq0) * inv_a);
                if lo > ia && lo < ib {
                    lo = ib;
                } else if lo <= ia && ia < hi {
                    // In the sector up to the inner circle (an exit that is all a span needs:
                    // the ray may come back in beyond it).
                    hi = ia.max(lo);
                }
                if lo > hi {
                    return None;
                }
            }
        }
        Some((lo, hi))
    }
}

/// The ray `origin + t dir` in the frame of a sector BVH about `frame`.
fn sector_ray(frame: &CylFrame, b: &Bvh<CylBounds>, origin: DVec3, dir: DVec3) -> LocalRay {
    let o = frame.to_local(origin) - DVec3::new(0.0, 0.0, b.frame().anchor.z);
    let d = DVec3::new(dir.dot(frame.e1), dir.dot(frame.e2), dir.dot(frame.axis));
    let pad = b.nodes.first().map_or(0.0, |n| {
        1e-9 * (n.bounds.r[1] as f64).max((n.bounds.h[1] - n.bounds.h[0]) as f64)
    });
    let a = d.x * d.x + d.y * d.y;
    let quad = [a, o.x * d.x + o.y * d.y, o.x * o.x + o.y * o.y, 1.0 / a];
    LocalRay::Sectors {
        o,
        d,
        inv: reciprocal(d),
        pad,
        quad,
    }
}

/// Bounds a [`LocalRay`] can enter.
trait RayEntry {
    /// `test`: how to test a sector BVH's node, where known ([`NodeShape`]); leaf pieces
    /// and boxes have none.
    fn enter(&self, ray: &LocalRay, test: Option<&NodeShape>, t0: f64, t1: f64) -> Option<Span>;
}

impl RayEntry for BoxF32 {
    #[inline]
    fn enter(&self, ray: &LocalRay, _: Option<&NodeShape>, t0: f64, t1: f64) -> Option<Span> {
        match *ray {
            LocalRay::Boxes { o, inv, pad } => box_span(o, inv, pad, self.min, self.max, t0, t1),
            LocalRay::Sectors { .. } => Some((t0, t0)),
        }
    }
}

impl RayEntry for SectorF32 {
    #[inline]
    fn enter(&self, ray: &LocalRay, test: Option<&NodeShape>, t0: f64, t1: f64) -> Option<Span> {
        let LocalRay::Sectors {
            o,
            d,
            inv,
            pad,
            quad,
        } = *ray
        else {
            return Some((t0, t0));
        };
        let trig = match test {
            // The box holds the sector (in the same frame, `h` as stored).
            Some(NodeShape::Box(b)) => return box_span(o, inv, pad, b.min, b.max, t0, t1),
            Some(NodeShape::Sector(trig)) => Some(trig),
            None => None,
        };
        let ray = SectorRay {
            o,
            d,
            inv_h: inv.z,
            pad,
            quad,
        };
        ray.entry(self, trig, t0, t1)
    }
}

/// Closest-hit traversal ([`Bvh::closest_hit`]) of `ray` (with a sector BVH's node tests,
/// [`NodeShape`]; empty if not known, and for boxes) among the nodes `node(index)` keeps
/// and the pieces of the cells `cell(id)` keeps: the smallest entry `t ∈ [t0, t1]` into such
/// a leaf piece's bound, with that piece's exit and cell.
fn first_hit<B: BvhBounds>(
    bvh: &Bvh<B>,
    (ray, tests): (LocalRay, &[NodeShape]),
    (t0, t1): (f64, f64),
    counters: &mut Counters,
    node: impl Fn(usize) -> bool,
    cell: impl Fn(u32) -> bool,
) -> Option<(f64, f64, u32)>
where
    B::Compact: RayEntry,
{
    bvh.closest_hit(
        t0,
        t1,
        counters,
        |i, b, hi| {
            if node(i) {
                b.enter(&ray, tests.get(i), t0, hi).map(|s| s.0)
            } else {
                None
            }
        },
        // Against the whole interval, for the piece's own exit.
        |b, c, _| {
            if cell(c) {
                b.enter(&ray, None, t0, t1)
            } else {
                None
            }
        },
    )
}

impl Bvh<Aabb> {
    /// The smallest `t` of `span` at which the ray may lie in the bound of a piece of a cell
    /// that `cell` keeps, within the nodes that `node` keeps (by their index in depth-first
    /// order), with the ray's exit from that bound and the cell; `None` if there is none.
    /// Node visits are counted in `counters`.
    pub(crate) fn first_kept(
        &self,
        span: RaySpan,
        node: impl Fn(usize) -> bool,
        cell: impl Fn(u32) -> bool,
        counters: &mut Counters,
    ) -> Option<(f64, f64, u32)> {
        let ray = LocalRay::Boxes {
            o: span.origin - self.frame().anchor,
            inv: reciprocal(span.dir),
            pad: self.query_pad(),
        };
        first_hit(self, (ray, &[]), (span.t0, span.t1), counters, node, cell)
    }
}

impl Bvh<CylBounds> {
    /// [`Bvh::first_kept`] for a BVH of sectors about `frame`, its nodes tested as `tests`
    /// says (ignored unless it has one test a node).
    pub(crate) fn first_kept_sector(
        &self,
        (frame, tests): (&CylFrame, &[NodeShape]),
        span: RaySpan,
        node: impl Fn(usize) -> bool,
        cell: impl Fn(u32) -> bool,
        counters: &mut Counters,
    ) -> Option<(f64, f64, u32)> {
        let ray = sector_ray(frame, self, span.origin, span.dir);
        let tests = Some(tests)
            .filter(|t| t.len() == self.nodes.len())
            .unwrap_or(&[]);
        first_hit(self, (ray, tests), (span.t0, span.t1), counters, node, cell)
    }
}
