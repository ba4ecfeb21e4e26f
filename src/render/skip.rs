//! Empty-space skipping for the fast path: where along a ray the next sample may lie in a
//! piece's bound, so samples outside every bound (the hub's hole, the corners of the mesh's
//! box) are passed over without point location.
//!
//! - **BVHs** ([`Skipper::next_entry`]): a closest-hit traversal of the ray against the node
//!   and piece bounds gives the smallest `t ≥ t₀` at which the ray is inside a piece's bound.
//!   Boxes are slab-tested. Sectors are tested on `r` (a quadratic in `t`), `h` (a slab) and,
//!   for arcs narrower than π, θ (two half-planes through the axis); a wider arc is tested on
//!   `r` and `h` only, a lower bound of the true entry, which is all skipping needs. A
//!   cylindrical BVH's nodes whose boxes in the axis frame are nearly as tight as their sectors
//!   are slab-tested as those boxes instead (a quarter of the cost; the box holds the sector,
//!   so the entry is again a lower bound); the others keep their sectors, with their arcs'
//!   sines and cosines. Which is which is decided once per structure
//!   ([`Accel::node_ray_tests`]).
//!   [`Skipper::next_span`] also gives the exit from the piece's bound entered first, so the
//!   samples up to it (in that bound) go to point location without asking again.
//! - **Grids**: a sample is passed over when its second-level cell holds no reference (one
//!   top-cell and one leaf-cell look-up, no cell tested).
//!
//! Every answer is **conservative**: bounds are padded by `1e-9` of the root's extent before
//! the ray is intersected with them, so a sample the structure could locate is never skipped,
//! and the fast path's image keeps the paper path's samples.

use glam::DVec3;

use crate::accel::bvh::ray::{box_span, clip_to_slab, reciprocal};
use crate::accel::bvh::{
    arc_narrower_than_half_turn, arc_trig, ArcTrig, BoxF32, Bvh, BvhBounds, NodeMask, NodeRayTest,
    SectorF32,
};
use crate::accel::{Accel, Coordinates, Counters, Structure};
use crate::geometry::cylindrical::CylFrame;

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

impl LocalRay {
    /// The entry into a sector; `quad` the ray's `r²` polynomial (see [`LocalRay::Sectors`]),
    /// `trig` the arc's sines and cosines if known.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn entry_sector(
        o: DVec3,
        d: DVec3,
        inv_h: f64,
        pad: f64,
        quad: [f64; 4],
        s: &SectorF32,
        trig: Option<&ArcTrig>,
        t0: f64,
        t1: f64,
    ) -> Option<Span> {
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

/// Empty-space skipping over one structure (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct Skipper<'a> {
    accel: &'a Accel,
}

impl<'a> Skipper<'a> {
    /// Skipping over `accel` (a cylindrical BVH's traversals use its node tests,
    /// [`Accel::node_ray_tests`]).
    pub fn new(accel: &'a Accel) -> Skipper<'a> {
        Skipper { accel }
    }

    /// For a BVH: the smallest `t ∈ [t0, t1]` at which the ray (unit `dir`) may lie in a
    /// piece's bound, `None` if it lies in none on that interval. For a grid: `Some(t0)`
    /// (grids are skipped sample by sample, see [`Skipper::may_hold`]). Node visits are
    /// counted in `counters`.
    pub fn next_entry(
        &self,
        origin: DVec3,
        dir: DVec3,
        t0: f64,
        t1: f64,
        counters: &mut Counters,
    ) -> Option<f64> {
        self.next_span(origin, dir, t0, t1, counters).map(|s| s.0)
    }

    /// [`Skipper::next_entry`] with an exit: `(entry, exit)` such that the ray lies in one
    /// piece's bound from `entry` to `exit` (so no sample in between need ask again). For a
    /// grid: `(t0, t0)`.
    pub fn next_span(
        &self,
        origin: DVec3,
        dir: DVec3,
        t0: f64,
        t1: f64,
        counters: &mut Counters,
    ) -> Option<(f64, f64)> {
        match self.bvh_first_hit(origin, dir, t0, t1, counters, |_| true, |_| true) {
            Some(hit) => hit.map(|(e, x, _)| (e, x)),
            // A grid, or a cylindrical BVH without its frame: no bounds to traverse.
            None => Some((t0, t0)),
        }
    }

    /// For a BVH: the smallest `t ∈ [t0, t1]` at which the ray (unit `dir`) may lie in the
    /// bound of a piece of a *visible* cell, with the ray's exit from that bound and the
    /// cell: `visible_nodes` are the nodes holding such pieces (from
    /// [`Bvh::nodes_holding`] with `visible`), and `visible(cell)` says which cells are. The
    /// ray meets no visible cell before that entry, so the samples before it lie in
    /// invisible cells or outside the mesh. `None` if it meets no such bound on the interval,
    /// and for a grid or a mask of another structure (the caller then cannot skip). Node
    /// visits are counted in `counters`.
    ///
    /// [`Bvh::nodes_holding`]: crate::accel::bvh::Bvh::nodes_holding
    #[allow(clippy::too_many_arguments)]
    pub fn next_visible(
        &self,
        origin: DVec3,
        dir: DVec3,
        t0: f64,
        t1: f64,
        visible_nodes: &NodeMask,
        visible: impl Fn(u32) -> bool,
        counters: &mut Counters,
    ) -> Option<(f64, f64, u32)> {
        let node = |i: usize| visible_nodes.contains(i);
        self.next_kept(
            origin,
            dir,
            t0,
            t1,
            visible_nodes.len(),
            node,
            visible,
            counters,
        )
    }

    /// [`Skipper::next_visible`] for any choice of nodes and cells: the first bound of a piece
    /// of a cell that `cell` keeps, within nodes that `node` keeps (by their index in the
    /// BVH's depth-first order; a node must be kept wherever a kept cell's piece lies below
    /// it). `nodes` is the number of nodes the choice was made for: `None` unless it is the
    /// BVH's, and for a grid. An intensity projection keeps the nodes and cells whose scalar
    /// range may beat the ray's extreme ([`crate::accel::bvh::NodeRanges`]).
    #[allow(clippy::too_many_arguments)]
    pub fn next_kept(
        &self,
        origin: DVec3,
        dir: DVec3,
        t0: f64,
        t1: f64,
        nodes: usize,
        node: impl Fn(usize) -> bool,
        cell: impl Fn(u32) -> bool,
        counters: &mut Counters,
    ) -> Option<(f64, f64, u32)> {
        let bvh_nodes = match self.accel.structure() {
            Structure::CartBvh(b) => b.nodes.len(),
            Structure::CylBvh(b) => b.nodes.len(),
            Structure::Grid(_) => return None,
        };
        if nodes != bvh_nodes {
            return None;
        }
        self.bvh_first_hit(origin, dir, t0, t1, counters, node, cell)
            .flatten()
    }

    /// The closest-hit traversal ([`first_hit`]) of the structure's BVH in its own frame,
    /// among the nodes `node(index)` keeps and the pieces of the cells `cell(id)` keeps;
    /// `None` for a grid or a cylindrical BVH without its frame (no bounds to traverse).
    #[allow(clippy::too_many_arguments)]
    fn bvh_first_hit(
        &self,
        origin: DVec3,
        dir: DVec3,
        t0: f64,
        t1: f64,
        counters: &mut Counters,
        node: impl Fn(usize) -> bool,
        cell: impl Fn(u32) -> bool,
    ) -> Option<Option<(f64, f64, u32)>> {
        match (self.accel.structure(), self.accel.coordinates()) {
            (Structure::CartBvh(b), _) => {
                let ray = LocalRay::Boxes {
                    o: origin - b.frame().anchor,
                    inv: reciprocal(dir),
                    pad: b.query_pad(),
                };
                Some(first_hit(b, ray, &[], t0, t1, counters, node, cell))
            }
            (Structure::CylBvh(b), Coordinates::Cylindrical(frame)) => {
                let ray = sector_ray(&frame, b, origin, dir);
                let tests = Some(self.accel.node_ray_tests().tests())
                    .filter(|t| t.len() == b.nodes.len())
                    .unwrap_or(&[]);
                Some(first_hit(b, ray, tests, t0, t1, counters, node, cell))
            }
            _ => None,
        }
    }

    /// Whether the structure may hold a cell at `p`: for a grid, whether `p`'s second-level
    /// cell holds references (one top and one leaf visit counted); for a BVH, always `true`.
    pub fn may_hold(&self, p: DVec3, counters: &mut Counters) -> bool {
        match self.accel.structure() {
            Structure::Grid(g) => {
                let q = self.accel.coordinates().query(p);
                if !g.domain().contains(q) {
                    return false;
                }
                counters.internal_visits += 1;
                counters.leaf_visits += 1;
                !g.candidates(q).is_empty()
            }
            _ => true,
        }
    }
}

fn sector_ray<B: BvhBounds<Compact = SectorF32>>(
    frame: &CylFrame,
    b: &Bvh<B>,
    origin: DVec3,
    dir: DVec3,
) -> LocalRay {
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
trait Enter {
    /// `test`: how to test a sector BVH's node, where known ([`NodeRayTest`]); leaf pieces
    /// and boxes have none.
    fn enter(&self, ray: &LocalRay, test: Option<&NodeRayTest>, t0: f64, t1: f64) -> Option<Span>;
}

impl Enter for BoxF32 {
    #[inline]
    fn enter(&self, ray: &LocalRay, _: Option<&NodeRayTest>, t0: f64, t1: f64) -> Option<Span> {
        match *ray {
            LocalRay::Boxes { o, inv, pad } => box_span(o, inv, pad, self.min, self.max, t0, t1),
            LocalRay::Sectors { .. } => Some((t0, t0)),
        }
    }
}

impl Enter for SectorF32 {
    #[inline]
    fn enter(&self, ray: &LocalRay, test: Option<&NodeRayTest>, t0: f64, t1: f64) -> Option<Span> {
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
            Some(NodeRayTest::Box(b)) => return box_span(o, inv, pad, b.min, b.max, t0, t1),
            Some(NodeRayTest::Sector(trig)) => Some(trig),
            None => None,
        };
        LocalRay::entry_sector(o, d, inv.z, pad, quad, self, trig, t0, t1)
    }
}

/// Closest-hit traversal ([`Bvh::closest_hit`]) among the nodes `node(index)` keeps and the
/// pieces of the cells `cell(id)` keeps: the smallest entry `t ∈ [t0, t1]` into such a leaf
/// piece's bound, with that piece's exit and cell. `tests` holds a sector BVH's node tests
/// ([`NodeRayTest`]; empty if not known, and for boxes).
#[allow(clippy::too_many_arguments)]
fn first_hit<B: BvhBounds>(
    bvh: &Bvh<B>,
    ray: LocalRay,
    tests: &[NodeRayTest],
    t0: f64,
    t1: f64,
    counters: &mut Counters,
    node: impl Fn(usize) -> bool,
    cell: impl Fn(u32) -> bool,
) -> Option<(f64, f64, u32)>
where
    B::Compact: Enter,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{AccelParams, StructureKind};
    use crate::datasets::{generate, Dataset};
    use crate::testing::uniform;

    /// Skipping never passes a sample the structure locates: along rays from all round the
    /// mesh, through points of its box, the entry [`Skipper::next_entry`] gives is at or before
    /// the first of 1,000 samples the structure's point location finds in a cell, and `None`
    /// only where it finds none. For both BVHs over a ring (the rotor) and an O-grid with cells
    /// on the axis (the inlet); the cylindrical BVHs test nodes both as boxes and as sectors.
    /// The entries are also close, so that the skipping is seen to skip: the median distance
    /// from an entry to that first sample is within 2 % of the box's diagonal (entering at the
    /// rays' start, as a skipping that skipped nothing would, the median is about half).
    #[test]
    fn skipping_never_passes_a_located_sample() {
        for dataset in [Dataset::PumpRotor, Dataset::PumpInlet] {
            let mesh = generate(dataset, 3000).expect("mesh");
            let axis = crate::axis::detect(&mesh);
            let [x0, x1, y0, y1, z0, z1] = mesh.bounds();
            let (lo, hi) = (DVec3::new(x0, y0, z0), DVec3::new(x1, y1, z1));
            let (centre, diagonal) = ((lo + hi) * 0.5, (hi - lo).length());
            for kind in [StructureKind::CylBvh, StructureKind::CartBvh] {
                let accel =
                    Accel::build(&mesh, kind, &axis, &AccelParams::default()).expect("structure");
                if kind == StructureKind::CylBvh {
                    let tests = accel.node_ray_tests().tests();
                    let boxes = tests
                        .iter()
                        .filter(|t| matches!(t, NodeRayTest::Box(_)))
                        .count();
                    assert!(0 < boxes && boxes < tests.len(), "{dataset:?}: {boxes}");
                }
                let skipper = Skipper::new(&accel);
                let mut next = uniform(7);
                let mut gaps = Vec::new();
                for _ in 0..150 {
                    let (u, v) = (2.0 * next() - 1.0, std::f64::consts::TAU * next());
                    let w = (1.0 - u * u).sqrt();
                    let origin = centre + DVec3::new(w * v.cos(), w * v.sin(), u) * diagonal;
                    let target = lo + (hi - lo) * DVec3::new(next(), next(), next());
                    let dir = (target - origin).normalize();
                    let t1 = 2.0 * diagonal;
                    let mut counters = Counters::default();
                    let entry = skipper.next_entry(origin, dir, 0.0, t1, &mut counters);
                    let first = (0..1000).map(|k| t1 * k as f64 / 1000.0).find(|&t| {
                        accel
                            .locate(&mesh, origin + dir * t, &mut counters)
                            .is_some()
                    });
                    match (entry, first) {
                        (Some(e), Some(t)) => {
                            assert!(e <= t, "{dataset:?} {kind:?}: entry {e} after {t}");
                            gaps.push((t - e) / diagonal);
                        }
                        (None, Some(t)) => panic!("{dataset:?} {kind:?}: no entry, cell at {t}"),
                        _ => {}
                    }
                }
                assert!(
                    gaps.len() >= 50,
                    "{dataset:?} {kind:?}: {} met the mesh",
                    gaps.len()
                );
                gaps.sort_by(f64::total_cmp);
                let median = gaps[gaps.len() / 2];
                assert!(median <= 0.02, "{dataset:?} {kind:?}: median gap {median}");
            }
        }
    }
}
