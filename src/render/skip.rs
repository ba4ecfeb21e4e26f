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
//!   top-cell and one leaf-cell look-up, no cell tested). Jumps over transparent space
//!   ([`Skipper::next_kept_in_grid`]) walk from grid cell to grid cell along the ray — a
//!   whole top cell at a time where it references no kept cell — each step locating the
//!   point past the last cell's exit as point location would, so the walk's notion of a cell
//!   is the grid's own; exits are computed never later than the true ones (slabs; for a
//!   cylindrical grid also the circles `r = r₀, r₁` and the half-planes at the arc's ends).
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
use crate::accel::grid::{GridMask, MaskedCell};
use crate::accel::{Accel, Coordinates, Counters, Structure};
use crate::geometry::bounds::Aabb;
use crate::geometry::cylindrical::CylFrame;
use crate::geometry::pseudo_angle::direction_of_pseudo;

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

    /// For a grid: the first `t ∈ [t0, t1]` from which the ray (unit `dir`) may lie in a grid
    /// cell that references a kept cell (`mask`, from
    /// [`crate::accel::grid::TwoLevelGrid::cells_holding`] with `keep`), with the ray's exit
    /// from that grid cell and a kept cell it references (a hint for locating the sample
    /// there); `None` if no such grid cell lies on `[t0, t1]`.
    /// Every point of the ray before the answer lies in grid cells that reference no kept
    /// cell, so no kept cell holds it: the grids' counterpart of [`Skipper::next_kept`]. The
    /// walk goes from grid cell to grid cell along the ray, a whole top cell at a time where
    /// the top cell references no kept cell. Where it cannot go on — the ray leaves the
    /// grid's domain (the space outside the mesh, which the fast path crosses by the boundary
    /// surface), a step would not leave its cell, or after [`MAX_GRID_WALK`] cells — it stops
    /// there, with no hint: the caller then samples from there as it would without jumping.
    /// `None` for a BVH or a mask made for another grid. Top and leaf cells visited are
    /// counted in `counters`.
    #[allow(clippy::too_many_arguments)]
    pub fn next_kept_in_grid(
        &self,
        origin: DVec3,
        dir: DVec3,
        t0: f64,
        t1: f64,
        mask: &GridMask,
        keep: impl Fn(u32) -> bool,
        counters: &mut Counters,
    ) -> Option<(f64, f64, Option<u32>)> {
        let Structure::Grid(grid) = self.accel.structure() else {
            return None;
        };
        let stats = grid.stats();
        if !mask.fits(stats.top_cells, stats.leaf_cells) {
            return None;
        }
        let coordinates = self.accel.coordinates();
        let ray = GridRay::new(coordinates, origin, dir);
        let at = |t: f64, counters: &mut Counters| {
            grid.masked_cell_at(coordinates.query(origin + dir * t), mask, counters)
        };
        let mut t = t0;
        let mut here = at(t, counters);
        for _ in 0..MAX_GRID_WALK {
            let region = match here {
                MaskedCell::Outside => return Some((t, t, None)),
                MaskedCell::Kept(leaf, region) => {
                    let hint = grid.leaf_refs(leaf).iter().copied().find(|&c| keep(c));
                    return Some((t, ray.exit(&region, t), hint));
                }
                MaskedCell::Empty(region) => region,
            };
            let exit = ray.exit(&region, t);
            if exit > t1 {
                return None;
            }
            // The exit's point lies on the region's face up to rounding, so it may be
            // classified into the region again: step past it by the least amount that leaves
            // it, far below the pieces' padding, or stop.
            let limit = GRID_STEP_LIMIT * ray.least_extent(&region);
            let mut step = f64::EPSILON * exit.abs().max(ray.scale);
            loop {
                if step > limit || limit.is_nan() {
                    return Some((exit, exit, None));
                }
                let next = at(exit + step, counters);
                if next != here {
                    (t, here) = (exit + step, next);
                    break;
                }
                step *= 2.0;
            }
        }
        Some((t, t, None))
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

/// The most grid cells [`Skipper::next_kept_in_grid`] walks through before it stops.
pub const MAX_GRID_WALK: usize = 1 << 16;

/// The largest step, relative to the grid cell's least extent, that
/// [`Skipper::next_kept_in_grid`] takes past a grid cell's exit to leave the cell: thousands
/// of times below the padding of the pieces the grid references (`4e-9` of a mesh cell's
/// diagonal and more; grid cells are shaped like the pieces they hold), so that no point of a
/// kept piece in the next grid cell lies within the step.
const GRID_STEP_LIMIT: f64 = 1e-12;

/// A ray in a grid's coordinates, for the exits from grid cells.
#[derive(Clone, Copy, Debug)]
struct GridRay {
    /// In the cylindrical frame (`(x, y)` across the axis, `h` along it) for a cylindrical
    /// grid, else as given.
    o: DVec3,
    d: DVec3,
    /// Cylindrical or not.
    cylindrical: bool,
    /// The magnitude of the ray's origin (at least 1): what rounding is relative to.
    scale: f64,
}

impl GridRay {
    fn new(coordinates: Coordinates, origin: DVec3, dir: DVec3) -> GridRay {
        let scale = origin.abs().max_element().max(1.0);
        match coordinates {
            Coordinates::Cartesian => GridRay {
                o: origin,
                d: dir,
                cylindrical: false,
                scale,
            },
            Coordinates::Cylindrical(frame) => GridRay {
                o: frame.to_local(origin),
                d: DVec3::new(dir.dot(frame.e1), dir.dot(frame.e2), dir.dot(frame.axis)),
                cylindrical: true,
                scale,
            },
        }
    }

    /// The least extent of `region`, in world units: its box's shortest side, or for a
    /// cylindrical region its radial and axial sides (its arc is as long as its angle times
    /// its radius, which may be anything near the axis).
    fn least_extent(&self, region: &Aabb) -> f64 {
        let e = region.max - region.min;
        if self.cylindrical {
            e.x.min(e.z)
        } else {
            e.min_element()
        }
    }

    /// Where the ray leaves `region` (a box in the grid's coordinates holding the point at
    /// `t`, as the grid classifies it) after `t`: never later than the true exit, and `t`
    /// itself where the point lies on the face it leaves by, or (by rounding) just beyond it.
    /// The slabs (every axis of a Cartesian box, `h` of a cylindrical one) are convex, so
    /// their exit is the nearest face ahead. A cylindrical region is also left through its
    /// outer circle (the later root of `r² = r₁²`), through its inner circle where the ray
    /// reaches it (the earlier root of `r² = r₀²`), and through the half-plane at the end of
    /// its arc that the ray turns towards; any of those crossings a little behind `t` counts
    /// as one at `t` (rounding), and any doubtful one counts (an earlier exit only costs a
    /// step of the walk).
    fn exit(&self, region: &Aabb, t: f64) -> f64 {
        let (o, d) = (self.o, self.d);
        let (lo, hi) = (region.min, region.max);
        let mut exit = f64::INFINITY;
        let slabs = if self.cylindrical { 2..3 } else { 0..3 };
        for a in slabs {
            if d[a] != 0.0 {
                let face = if d[a] > 0.0 { hi[a] } else { lo[a] };
                exit = exit.min((face - o[a]) / d[a]);
            }
        }
        if self.cylindrical {
            let behind = t - 1e-9 * (t.abs() + self.scale);
            // r² along the ray: a t² + 2 b t + c.
            let a = d.x * d.x + d.y * d.y;
            let b = o.x * d.x + o.y * d.y;
            let c = o.x * o.x + o.y * o.y;
            if a > 0.0 {
                let outer = b * b - a * (c - hi.x * hi.x);
                exit = exit.min(if outer >= 0.0 {
                    (-b + outer.sqrt()) / a
                } else {
                    t
                });
                // Inwards through the inner circle at the earlier root (where the ray came
                // out of the hole, at the later one, is an entry).
                let inner = b * b - a * (c - lo.x * lo.x);
                if lo.x > 0.0 && inner > 0.0 {
                    let reach = (-b - inner.sqrt()) / a;
                    if reach >= behind {
                        exit = exit.min(reach);
                    }
                }
            }
            // The half-planes through the axis at the arc's ends (none for a whole turn):
            // where the ray meets the line through the axis along `u`, on `u`'s side. A line
            // turns about the axis one way all along (`ω`, the sign of `o × d` across it), so
            // it leaves by the end it turns towards; through the axis (`ω = 0`) by either.
            if hi.y - lo.y < 4.0 {
                let near = -1e-9 * self.scale;
                let omega = o.x * d.y - o.y * d.x;
                let ends = match omega.partial_cmp(&0.0) {
                    Some(std::cmp::Ordering::Greater) => [None, Some(hi.y)],
                    Some(std::cmp::Ordering::Less) => [Some(lo.y), None],
                    _ => [Some(lo.y), Some(hi.y)],
                };
                for phi in ends.into_iter().flatten() {
                    let (ux, uy) = direction_of_pseudo(phi);
                    let f1 = ux * d.y - uy * d.x;
                    if f1 != 0.0 {
                        let tc = (uy * o.x - ux * o.y) / f1;
                        let along = ux * (o.x + tc * d.x) + uy * (o.y + tc * d.y);
                        if tc >= behind && along >= near {
                            exit = exit.min(tc);
                        }
                    }
                }
            }
        }
        // (NaN, from a degenerate ray, stays at `t`.)
        if exit > t {
            exit
        } else {
            t
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

    /// Rays from a sphere around a box, one diagonal from its centre, through random points of
    /// the box.
    struct RaysThroughBox {
        lo: DVec3,
        hi: DVec3,
    }

    impl RaysThroughBox {
        /// Around the mesh's box.
        fn of(mesh: &crate::Mesh) -> RaysThroughBox {
            let [x0, x1, y0, y1, z0, z1] = mesh.bounds();
            RaysThroughBox {
                lo: DVec3::new(x0, y0, z0),
                hi: DVec3::new(x1, y1, z1),
            }
        }

        fn centre(&self) -> DVec3 {
            (self.lo + self.hi) * 0.5
        }

        fn diagonal(&self) -> f64 {
            (self.hi - self.lo).length()
        }

        /// A ray's origin and unit direction, from `next`'s uniform numbers.
        fn next(&self, next: &mut impl FnMut() -> f64) -> (DVec3, DVec3) {
            let (u, v) = (2.0 * next() - 1.0, std::f64::consts::TAU * next());
            let w = (1.0 - u * u).sqrt();
            let origin = self.centre() + DVec3::new(w * v.cos(), w * v.sin(), u) * self.diagonal();
            let target = self.lo + (self.hi - self.lo) * DVec3::new(next(), next(), next());
            (origin, (target - origin).normalize())
        }
    }

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
            let rays = RaysThroughBox::of(&mesh);
            let diagonal = rays.diagonal();
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
                    let (origin, dir) = rays.next(&mut next);
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

    /// A grid's walk never passes a point where the grid offers a kept cell: along rays from
    /// all round the mesh, through points of its box, the answer of
    /// [`Skipper::next_kept_in_grid`] is at or before the first of 2,000 samples whose grid
    /// cell references a kept cell (one in 13 cells kept), and `None` only where no sample's
    /// does. For both grids over a ring (the rotor) and an O-grid with cells on the axis (the
    /// inlet). The walk is seen to walk: on nine rays in ten that meet a kept grid cell it
    /// reaches one (an answer with a hint, a kept cell of that grid cell), within 1 % of the
    /// box's diagonal of the
    /// first such sample at the median; and with nothing kept it answers `None` or stops at
    /// the grid's edge (no hint).
    #[test]
    fn grid_walks_never_pass_a_kept_cell() {
        for dataset in [Dataset::PumpRotor, Dataset::PumpInlet] {
            let mesh = generate(dataset, 3000).expect("mesh");
            let axis = crate::axis::detect(&mesh);
            let rays = RaysThroughBox::of(&mesh);
            let (centre, diagonal) = (rays.centre(), rays.diagonal());
            for kind in [StructureKind::CylGrid, StructureKind::CartGrid] {
                let accel =
                    Accel::build(&mesh, kind, &axis, &AccelParams::default()).expect("structure");
                let Structure::Grid(grid) = accel.structure() else {
                    panic!("{kind:?} is not a grid");
                };
                let keep = |c: u32| c % 13 == 5;
                let mask = grid.cells_holding(keep);
                let none = grid.cells_holding(|_| false);
                let skipper = Skipper::new(&accel);
                let offered = |p: DVec3| {
                    let q = accel.coordinates().query(p);
                    grid.candidates(q).iter().any(|&c| keep(c))
                };
                let mut next = uniform(11);
                let (mut gaps, mut reached, mut met) = (Vec::new(), 0, 0);
                for _ in 0..150 {
                    let (origin, dir) = rays.next(&mut next);
                    let t1 = 2.0 * diagonal;
                    let mut counters = Counters::default();
                    // From where the ray meets the grid's domain (the walk stops outside it).
                    let t0 = (0..2000)
                        .map(|k| t1 * k as f64 / 2000.0)
                        .find(|&t| {
                            grid.domain()
                                .contains(accel.coordinates().query(origin + dir * t))
                        })
                        .unwrap_or(t1);
                    let answer =
                        skipper.next_kept_in_grid(origin, dir, t0, t1, &mask, keep, &mut counters);
                    let first = (0..2000)
                        .map(|k| t0 + (t1 - t0) * k as f64 / 2000.0)
                        .find(|&t| offered(origin + dir * t));
                    match (answer, first) {
                        (Some((e, x, hint)), Some(t)) => {
                            met += 1;
                            assert!(e <= t, "{dataset:?} {kind:?}: answer {e} after {t}");
                            assert!(e <= x, "{dataset:?} {kind:?}: exit {x} before {e}");
                            if let Some(c) = hint {
                                assert!(keep(c), "{dataset:?} {kind:?}: hint {c}");
                                reached += 1;
                                gaps.push((t - e) / diagonal);
                            }
                        }
                        (None, Some(t)) => {
                            panic!("{dataset:?} {kind:?}: no answer, kept cell offered at {t}")
                        }
                        _ => {}
                    }
                    let empty = skipper.next_kept_in_grid(
                        origin,
                        dir,
                        t0,
                        t1,
                        &none,
                        |_| false,
                        &mut counters,
                    );
                    assert!(
                        matches!(empty, None | Some((_, _, None))),
                        "{dataset:?} {kind:?}: {empty:?}"
                    );
                }
                // A walk that stalled at a cell's face (an exit computed at the point
                // itself) would stop there, with no hint.
                assert!(
                    reached >= 50 && 10 * reached >= 9 * met,
                    "{dataset:?} {kind:?}: {reached} reached of {met}"
                );
                gaps.sort_by(f64::total_cmp);
                let median = gaps[gaps.len() / 2];
                assert!(median <= 0.01, "{dataset:?} {kind:?}: median gap {median}");
                // A mask of another grid is refused.
                let other = GridMask::default();
                let refused = skipper.next_kept_in_grid(
                    centre,
                    DVec3::X,
                    0.0,
                    1.0,
                    &other,
                    keep,
                    &mut Counters::default(),
                );
                assert_eq!(refused, None);
            }
        }
    }
}
