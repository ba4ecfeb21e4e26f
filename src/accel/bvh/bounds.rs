//! The bounds a BVH can hold ([`BvhBounds`]): boxes ([`Aabb`]) and cylindrical sectors
//! ([`CylBounds`]), their linear build form, their true surface area, and their compact stored
//! form (`f32`, rounded outward).

use std::f64::consts::{PI, TAU};
use std::fmt::Debug;

use glam::DVec3;
use rayon::prelude::*;

use crate::geometry::bounds::Aabb;
use crate::geometry::cylindrical::{rem_tau, CylBounds, ThetaInterval, ANGLE_SLACK};
use crate::geometry::pseudo_angle::{
    angle_of_pseudo, arc_width, padded_pseudo_arc, pseudo_of_angle, THETA_PAD, TURN,
};

/// Where a BVH's linear build coordinates and stored bounds are measured from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearFrame {
    /// Subtracted from a query before it is compared with stored bounds (the root's centre for
    /// boxes; `(0, 0, h_mid)` for sectors).
    pub anchor: DVec3,
    /// Sectors: the start of the root's arc (linear θ is measured from it).
    pub theta0: f64,
    /// Sectors: the width of the root's arc (a piece's unwrapped start lies in `[0, width]`).
    pub theta_width: f64,
}

/// Bounds a [`super::Bvh`] can be built over.
///
/// The build works on *linear* boxes ([`BvhBounds::linearize`]): for boxes, the box itself;
/// for sectors, `(r, θ − θ₀, h)` with the arc unwrapped from the root's start `θ₀`. Stored
/// bounds are the compact form of linear boxes ([`BvhBounds::compact`]), which contains the
/// bound it was made from and is monotone, so nested linear boxes give nested stored bounds.
pub trait BvhBounds: Copy + Send + Sync + Debug + 'static {
    /// The stored form (24 bytes of `f32`).
    type Compact: Copy + Send + Sync + Debug + PartialEq;
    /// A query prepared for tests against stored bounds ([`BvhBounds::prepare_query`]).
    type Query: Copy + Debug;

    /// Whether the bound holds no point.
    fn is_empty_bound(&self) -> bool;
    /// The smallest bound of this kind holding all of `bounds`.
    fn union_all(bounds: &[Self]) -> Self;
    /// The frame of a BVH whose root bound is `root`.
    fn frame_of(root: &Self) -> LinearFrame;
    /// The linear box of this bound in `frame` (empty for an empty bound).
    fn linearize(&self, frame: &LinearFrame) -> Aabb;
    /// The bound a linear box stands for in `frame`.
    fn delinearize(lin: &Aabb, frame: &LinearFrame) -> Self;
    /// The surface area, in world units, of the bound a linear box stands for (equal to
    /// `delinearize(lin).surface_area()`, computed without reducing angles).
    fn linear_area(lin: &Aabb) -> f64;
    /// The surface area in world units of the bound stored corners stand for
    /// ([`BvhBounds::compact_corners`], as the build takes them): for boxes,
    /// [`BvhBounds::linear_area`]; for sectors, the same with the arc's width estimated from
    /// its pseudo-angles ([`crate::geometry::pseudo_angle::arc_width`]).
    fn corners_area(lo: [f32; 3], hi: [f32; 3]) -> f64;
    /// The true surface area in world units.
    fn surface_area(&self) -> f64;
    /// Whether the point (in the structure's coordinates) lies in the bound.
    fn contains_point(&self, q: DVec3) -> bool;
    /// The compact stored form of a linear box, rounded outward.
    fn compact(lin: &Aabb, frame: &LinearFrame) -> Self::Compact;
    /// The bound a compact form stands for (for statistics; rounding of the anchor aside).
    fn expand(c: &Self::Compact, frame: &LinearFrame) -> Self;
    /// A point in the bound's coordinates (`(x, y, z)`; `(r, θ, h)`) as the stored bounds
    /// compare it (`(x, y, z)`; `(r, φ, h)` with `φ` the pseudo-angle of `θ`).
    fn stored_coordinates(q: DVec3) -> DVec3;
    /// Whether a compact bound contains the query `q_rel = q − frame.anchor`, `q` in the
    /// stored bounds' coordinates ([`BvhBounds::stored_coordinates`]).
    fn compact_contains(c: &Self::Compact, q_rel: DVec3) -> bool;
    /// A query `q_rel` (as [`BvhBounds::compact_contains`] takes it) made ready for many
    /// [`BvhBounds::query_contains`] tests against the stored bounds of one BVH, whose root's
    /// stored bound is `root`: for boxes the query itself; for sectors, with its pseudo-angle
    /// reduced once to the root's turn, so that a node's test needs no reduction.
    fn prepare_query(q_rel: DVec3, root: &Self::Compact) -> Self::Query;
    /// [`BvhBounds::compact_contains`] for a prepared query, with the same answer for every
    /// stored bound of the BVH whose root the query was prepared with.
    fn query_contains(c: &Self::Compact, q: &Self::Query) -> bool;
    /// Whether compact `outer` contains compact `inner` (exact comparison of stored values).
    fn compact_encloses(outer: &Self::Compact, inner: &Self::Compact) -> bool;
    /// Whether the compact bound contains every point the `f64` bound `b` contains, compared
    /// as a query would be.
    fn compact_holds(c: &Self::Compact, b: &Self, frame: &LinearFrame) -> bool;
    /// The stored values' bits, to compare compact bounds exactly.
    fn compact_bits(c: &Self::Compact) -> [u32; 6];
    /// The compact bound as low and high corners in the linear coordinates' order (`x, y, z`;
    /// `r, θ, h`), the form the build takes unions of. An empty bound's corners are `+∞` and
    /// `−∞`, which unions pass over. The union of corners is exact and every coordinate of
    /// [`BvhBounds::compact`] is monotone in the linear box, so the corners' union of compact
    /// bounds is the corners of the compact union, bit for bit.
    fn compact_corners(c: &Self::Compact) -> ([f32; 3], [f32; 3]);
    /// The compact bound with these corners ([`BvhBounds::compact_corners`] undone); corners
    /// low above high (or NaN) on any axis give the empty bound.
    fn compact_from_corners(lo: [f32; 3], hi: [f32; 3]) -> Self::Compact;
}

/// Whether corners hold no point: low above high, or NaN, on some axis.
#[inline]
fn corners_empty(lo: &[f32; 3], hi: &[f32; 3]) -> bool {
    !(lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2])
}

/// The corners of an empty bound.
const EMPTY_CORNERS: ([f32; 3], [f32; 3]) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);

/// The corners as they are, or [`EMPTY_CORNERS`] where they hold no point.
#[inline]
fn corners_or_empty(lo: [f32; 3], hi: [f32; 3]) -> ([f32; 3], [f32; 3]) {
    if corners_empty(&lo, &hi) {
        EMPTY_CORNERS
    } else {
        (lo, hi)
    }
}

/// The largest `f32` not above `x` (NaN stays NaN).
#[inline]
pub(crate) fn f32_down(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) > x {
        next_toward_neg(f)
    } else {
        f
    }
}

/// The smallest `f32` not below `x` (NaN stays NaN).
#[inline]
pub(crate) fn f32_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x {
        -next_toward_neg(-f)
    } else {
        f
    }
}

fn next_toward_neg(f: f32) -> f32 {
    if f.is_nan() || f == f32::NEG_INFINITY {
        return f;
    }
    if f == 0.0 {
        return -f32::from_bits(1);
    }
    let b = f.to_bits();
    if f > 0.0 {
        f32::from_bits(b - 1)
    } else {
        f32::from_bits(b + 1)
    }
}

/// A query prepared for the stored sectors of one BVH ([`BvhBounds::prepare_query`]), so
/// that a node's arc is tested with comparisons only.
///
/// A stored arc `[φ₀, φ₁]` holds the query's direction, pseudo-angle `φ`, when some
/// `φ + k·TURN` lies in it. Every stored arc of a BVH starts at or after its root's start
/// `φ_r` (a node's stored bound is, bit for bit, the union of its pieces' corners), and before
/// `φ_r + TURN` but for an `f32` step (a piece's arc is unwrapped to start within the root's,
/// which is less than a turn wide unless it is the whole circle, whose arcs start in
/// `[−2, 2]` up to rounding); arcs are at most two turns long. With `φ` reduced to
/// `[φ_r, φ_r + TURN)`, the candidates are `φ`, `φ + TURN`, and — only for an arc starting
/// after `φ + TURN`, within that `f32` step of `φ_r + TURN` — `φ + 2·TURN`; no arc starts
/// after `φ + 2·TURN` or ends at `φ + 3·TURN`. On the axis every direction is the query's:
/// `φ` is then `−∞` (so are its other candidates), below every arc's start and every
/// non-empty arc's end, which makes the test of the third candidate true for every non-empty
/// arc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SectorQuery {
    /// `r`, the reduced pseudo-angle `φ` and `h` (relative to the anchor).
    pub rph: [f64; 3],
    /// `φ + TURN` and `φ + 2·TURN`.
    pub turns: [f64; 2],
}

impl SectorQuery {
    /// The query `(r, φ, h)` (`h` relative to the anchor) prepared for a BVH whose root's
    /// arc starts at pseudo-angle `root_start`.
    #[inline]
    pub fn new(q: DVec3, root_start: f32) -> Self {
        let base = if root_start.is_finite() {
            root_start as f64
        } else {
            0.0
        };
        let mut phi = q.y;
        if !(phi >= base && phi < base + TURN) {
            // Whole turns away (a query's pseudo-angle in (−2, 2] is at most one); NaN stays.
            phi -= TURN * ((phi - base) / TURN).floor();
        }
        if q.x == 0.0 {
            // On the axis: every candidate −∞, so the third's test holds for any arc.
            phi = f64::NEG_INFINITY;
        }
        SectorQuery {
            rph: [q.x, phi, q.z],
            turns: [phi + TURN, phi + 2.0 * TURN],
        }
    }
}

/// A box stored as `f32`, relative to the BVH's anchor.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[repr(C)]
pub struct BoxF32 {
    /// Low corner (rounded down).
    pub min: [f32; 3],
    /// High corner (rounded up).
    pub max: [f32; 3],
}

impl BoxF32 {
    /// The empty box: low corner `+∞`, high `−∞` (what an empty bound is stored as).
    pub const EMPTY: BoxF32 = BoxF32 {
        min: [f32::INFINITY; 3],
        max: [f32::NEG_INFINITY; 3],
    };
}

/// A sector stored as `f32`: `r`, the unwrapped arc as pseudo-angles `[φ_lo, φ_hi]`
/// ([`crate::geometry::pseudo_angle`]: absolute, a turn is 4, `φ_lo ∈ [−2, 6]`,
/// `φ_hi − φ_lo ≥ 4` for the whole circle) and `h` relative to the anchor. A query compares
/// its own pseudo-angle with them, so it needs no `atan2`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[repr(C)]
pub struct SectorF32 {
    /// `[r_min, r_max]` (rounded outward).
    pub r: [f32; 2],
    /// `[φ_lo, φ_hi]`: the pseudo-angles of the arc's ends padded by [`THETA_PAD`] radians,
    /// rounded outward.
    pub theta: [f32; 2],
    /// `[h_min, h_max]` relative to the anchor (rounded outward).
    pub h: [f32; 2],
}

fn aabb_union_all(bounds: &[Aabb]) -> Aabb {
    bounds
        .par_iter()
        .fold(|| Aabb::EMPTY, |a, b| a.union(b))
        .reduce(|| Aabb::EMPTY, |a, b| a.union(&b))
}

impl BvhBounds for Aabb {
    type Compact = BoxF32;
    type Query = DVec3;

    fn is_empty_bound(&self) -> bool {
        self.is_empty()
    }

    fn union_all(bounds: &[Self]) -> Self {
        aabb_union_all(bounds)
    }

    fn frame_of(root: &Self) -> LinearFrame {
        let anchor = if root.is_empty() || !root.center().is_finite() {
            DVec3::ZERO
        } else {
            root.center()
        };
        LinearFrame {
            anchor,
            theta0: 0.0,
            theta_width: 0.0,
        }
    }

    fn linearize(&self, _frame: &LinearFrame) -> Aabb {
        if self.is_empty() {
            Aabb::EMPTY
        } else {
            *self
        }
    }

    fn delinearize(lin: &Aabb, _frame: &LinearFrame) -> Self {
        *lin
    }

    #[inline]
    fn linear_area(lin: &Aabb) -> f64 {
        lin.surface_area()
    }

    #[inline]
    fn corners_area(lo: [f32; 3], hi: [f32; 3]) -> f64 {
        Self::linear_area(&Aabb::new(
            DVec3::from_array(lo.map(f64::from)),
            DVec3::from_array(hi.map(f64::from)),
        ))
    }

    fn surface_area(&self) -> f64 {
        Aabb::surface_area(self)
    }

    fn contains_point(&self, q: DVec3) -> bool {
        self.contains(q)
    }

    fn compact(lin: &Aabb, frame: &LinearFrame) -> BoxF32 {
        if lin.is_empty() {
            return BoxF32::EMPTY;
        }
        let lo = lin.min - frame.anchor;
        let hi = lin.max - frame.anchor;
        BoxF32 {
            min: [f32_down(lo.x), f32_down(lo.y), f32_down(lo.z)],
            max: [f32_up(hi.x), f32_up(hi.y), f32_up(hi.z)],
        }
    }

    fn expand(c: &BoxF32, frame: &LinearFrame) -> Self {
        Aabb::new(
            DVec3::new(c.min[0] as f64, c.min[1] as f64, c.min[2] as f64) + frame.anchor,
            DVec3::new(c.max[0] as f64, c.max[1] as f64, c.max[2] as f64) + frame.anchor,
        )
    }

    #[inline(always)]
    fn stored_coordinates(q: DVec3) -> DVec3 {
        q
    }

    #[inline(always)]
    fn compact_contains(c: &BoxF32, q: DVec3) -> bool {
        q.x >= c.min[0] as f64
            && q.x <= c.max[0] as f64
            && q.y >= c.min[1] as f64
            && q.y <= c.max[1] as f64
            && q.z >= c.min[2] as f64
            && q.z <= c.max[2] as f64
    }

    #[inline]
    fn prepare_query(q: DVec3, _root: &BoxF32) -> DVec3 {
        q
    }

    #[inline(always)]
    fn query_contains(c: &BoxF32, q: &DVec3) -> bool {
        Self::compact_contains(c, *q)
    }

    fn compact_encloses(outer: &BoxF32, inner: &BoxF32) -> bool {
        (0..3).all(|a| outer.min[a] <= inner.min[a] && outer.max[a] >= inner.max[a])
    }

    fn compact_holds(c: &BoxF32, b: &Self, frame: &LinearFrame) -> bool {
        if b.is_empty() {
            return true;
        }
        // A query is shifted by the anchor with the same rounding, which is monotone.
        let lo = b.min - frame.anchor;
        let hi = b.max - frame.anchor;
        (0..3).all(|a| lo[a] >= c.min[a] as f64 && hi[a] <= c.max[a] as f64)
    }

    fn compact_bits(c: &BoxF32) -> [u32; 6] {
        [
            c.min[0].to_bits(),
            c.min[1].to_bits(),
            c.min[2].to_bits(),
            c.max[0].to_bits(),
            c.max[1].to_bits(),
            c.max[2].to_bits(),
        ]
    }

    fn compact_corners(c: &BoxF32) -> ([f32; 3], [f32; 3]) {
        corners_or_empty(c.min, c.max)
    }

    fn compact_from_corners(lo: [f32; 3], hi: [f32; 3]) -> BoxF32 {
        let (min, max) = corners_or_empty(lo, hi);
        BoxF32 { min, max }
    }
}

/// The sector area of a linear box `(r, θ − θ₀, h)`: the formula of
/// [`CylBounds::surface_area`] with the width `min(Δθ, 2π)`.
#[inline]
fn sector_area(lin: &Aabb) -> f64 {
    if lin.is_empty() {
        return 0.0;
    }
    let (r0, r1) = (lin.min.x.max(0.0), lin.max.x);
    let span = lin.max.y - lin.min.y;
    let w = span.min(TAU);
    let dh = lin.max.z - lin.min.z;
    let caps = w * (r1 * r1 - r0 * r0);
    let curved = w * (r1 + r0) * dh;
    let sides = if span >= TAU {
        0.0
    } else {
        2.0 * (r1 - r0) * dh
    };
    caps + curved + sides
}

impl BvhBounds for CylBounds {
    type Compact = SectorF32;
    type Query = SectorQuery;

    fn is_empty_bound(&self) -> bool {
        self.is_empty()
    }

    fn union_all(bounds: &[Self]) -> Self {
        bounds
            .par_iter()
            .fold(|| CylBounds::EMPTY, |a, b| a.union(b))
            .reduce(|| CylBounds::EMPTY, |a, b| a.union(&b))
    }

    fn frame_of(root: &Self) -> LinearFrame {
        let h_mid = 0.5 * (root.h[0] + root.h[1]);
        let ok = !root.is_empty() && h_mid.is_finite();
        let (theta0, theta_width) = if !ok || root.theta.is_full() {
            (-PI, TAU)
        } else {
            (root.theta.start(), root.theta.width())
        };
        LinearFrame {
            anchor: DVec3::new(0.0, 0.0, if ok { h_mid } else { 0.0 }),
            theta0,
            theta_width,
        }
    }

    fn linearize(&self, frame: &LinearFrame) -> Aabb {
        if self.is_empty() {
            return Aabb::EMPTY;
        }
        let (lo, width) = if self.theta.is_full() {
            (0.0, TAU)
        } else {
            let mut lo = rem_tau(self.theta.start() - frame.theta0);
            // Rounding may put a start just before θ₀ at the far end: bring it back.
            if lo > frame.theta_width {
                lo -= TAU;
            }
            (lo, self.theta.width())
        };
        let r0 = if self.straddles_axis { 0.0 } else { self.r[0] };
        Aabb::new(
            DVec3::new(r0, lo, self.h[0]),
            DVec3::new(self.r[1], lo + width, self.h[1]),
        )
    }

    fn delinearize(lin: &Aabb, frame: &LinearFrame) -> Self {
        if lin.is_empty() {
            return CylBounds::EMPTY;
        }
        let span = lin.max.y - lin.min.y;
        let full = span >= TAU;
        let theta = if full {
            ThetaInterval::FULL
        } else {
            ThetaInterval::new(frame.theta0 + lin.min.y, span).padded(THETA_PAD)
        };
        CylBounds {
            r: [lin.min.x.max(0.0), lin.max.x],
            theta,
            h: [lin.min.z, lin.max.z],
            straddles_axis: full && lin.min.x <= 0.0,
        }
    }

    #[inline]
    fn linear_area(lin: &Aabb) -> f64 {
        sector_area(lin)
    }

    #[inline]
    fn corners_area(lo: [f32; 3], hi: [f32; 3]) -> f64 {
        // A whole turn's width is 2π, so that the area leaves out the planar sides.
        let span = arc_width(lo[1] as f64, hi[1] as f64);
        sector_area(&Aabb::new(
            DVec3::new(lo[0] as f64, 0.0, lo[2] as f64),
            DVec3::new(hi[0] as f64, span, hi[2] as f64),
        ))
    }

    fn surface_area(&self) -> f64 {
        CylBounds::surface_area(self)
    }

    fn contains_point(&self, q: DVec3) -> bool {
        self.contains(q.x, q.y, q.z)
    }

    fn compact(lin: &Aabb, frame: &LinearFrame) -> SectorF32 {
        if lin.is_empty() {
            return EMPTY_SECTOR;
        }
        // Unwrapped, not reduced (nodes' bounds are unions of their children's stored
        // bounds, so they nest bit for bit).
        let [lo, hi] = padded_pseudo_arc(frame.theta0 + lin.min.y, frame.theta0 + lin.max.y);
        SectorF32 {
            r: [f32_down(lin.min.x.max(0.0)), f32_up(lin.max.x)],
            theta: [f32_down(lo), f32_up(hi)],
            h: [
                f32_down(lin.min.z - frame.anchor.z),
                f32_up(lin.max.z - frame.anchor.z),
            ],
        }
    }

    fn expand(c: &SectorF32, frame: &LinearFrame) -> Self {
        if c.r[0] > c.r[1] || c.h[0] > c.h[1] || c.theta[0] > c.theta[1] {
            return CylBounds::EMPTY;
        }
        let lo = angle_of_pseudo(c.theta[0] as f64);
        let span = angle_of_pseudo(c.theta[1] as f64) - lo;
        let full = c.theta[1] as f64 - c.theta[0] as f64 >= TURN || span >= TAU;
        CylBounds {
            r: [c.r[0] as f64, c.r[1] as f64],
            theta: if full {
                ThetaInterval::FULL
            } else {
                ThetaInterval::new(lo, span)
            },
            h: [
                c.h[0] as f64 + frame.anchor.z,
                c.h[1] as f64 + frame.anchor.z,
            ],
            straddles_axis: full && c.r[0] <= 0.0,
        }
    }

    #[inline(always)]
    fn stored_coordinates(q: DVec3) -> DVec3 {
        DVec3::new(q.x, pseudo_of_angle(q.y), q.z)
    }

    #[inline(always)]
    fn compact_contains(c: &SectorF32, q: DVec3) -> bool {
        if !(q.x >= c.r[0] as f64
            && q.x <= c.r[1] as f64
            && q.z >= c.h[0] as f64
            && q.z <= c.h[1] as f64)
        {
            return false;
        }
        if q.x == 0.0 {
            // On the axis every angle is the point's.
            return c.theta[0] <= c.theta[1];
        }
        let t0 = c.theta[0] as f64;
        let mut d = q.y - t0;
        if d < 0.0 {
            d += TURN;
            if d < 0.0 {
                d += TURN;
            }
        } else if d >= TURN {
            d -= TURN;
        }
        if !(0.0..TURN).contains(&d) {
            d = d.rem_euclid(TURN);
        }
        d <= c.theta[1] as f64 - t0
    }

    #[inline]
    fn prepare_query(q: DVec3, root: &SectorF32) -> SectorQuery {
        SectorQuery::new(q, root.theta[0])
    }

    #[inline(always)]
    fn query_contains(c: &SectorF32, q: &SectorQuery) -> bool {
        let (t0, t1) = (c.theta[0] as f64, c.theta[1] as f64);
        let [r, phi, h] = q.rph;
        let [phi1, phi2] = q.turns;
        r >= c.r[0] as f64
            && r <= c.r[1] as f64
            && h >= c.h[0] as f64
            && h <= c.h[1] as f64
            && ((t0 <= phi && phi <= t1) || (phi1 <= t1 && (t0 <= phi1 || phi2 <= t1)))
    }

    fn compact_encloses(outer: &SectorF32, inner: &SectorF32) -> bool {
        outer.r[0] <= inner.r[0]
            && outer.r[1] >= inner.r[1]
            && outer.h[0] <= inner.h[0]
            && outer.h[1] >= inner.h[1]
            && ((outer.theta[0] <= inner.theta[0] && outer.theta[1] >= inner.theta[1])
                || outer.theta[1] as f64 - outer.theta[0] as f64 >= TURN)
    }

    fn compact_holds(c: &SectorF32, b: &Self, frame: &LinearFrame) -> bool {
        if b.is_empty() {
            return true;
        }
        let rz = b.r[0] >= c.r[0] as f64
            && b.r[1] <= c.r[1] as f64
            && b.h[0] - frame.anchor.z >= c.h[0] as f64
            && b.h[1] - frame.anchor.z <= c.h[1] as f64;
        let t0 = c.theta[0] as f64;
        let span = c.theta[1] as f64 - t0;
        let theta = if span >= TURN {
            true
        } else if b.theta.is_full() {
            false
        } else {
            // The arc and the slack `ThetaInterval::contains` allows on either side, in
            // pseudo-angle.
            let start = b.theta.start() - ANGLE_SLACK;
            let (lo, hi) = (
                pseudo_of_angle(start),
                pseudo_of_angle(start + b.theta.width() + 2.0 * ANGLE_SLACK),
            );
            let off = (lo - t0).rem_euclid(TURN);
            off + (hi - lo) <= span
        };
        rz && theta
    }

    fn compact_bits(c: &SectorF32) -> [u32; 6] {
        [
            c.r[0].to_bits(),
            c.r[1].to_bits(),
            c.theta[0].to_bits(),
            c.theta[1].to_bits(),
            c.h[0].to_bits(),
            c.h[1].to_bits(),
        ]
    }

    fn compact_corners(c: &SectorF32) -> ([f32; 3], [f32; 3]) {
        corners_or_empty([c.r[0], c.theta[0], c.h[0]], [c.r[1], c.theta[1], c.h[1]])
    }

    fn compact_from_corners(lo: [f32; 3], hi: [f32; 3]) -> SectorF32 {
        if corners_empty(&lo, &hi) {
            return EMPTY_SECTOR;
        }
        SectorF32 {
            r: [lo[0], hi[0]],
            theta: [lo[1], hi[1]],
            h: [lo[2], hi[2]],
        }
    }
}

/// The stored form of an empty sector.
const EMPTY_SECTOR: SectorF32 = SectorF32 {
    r: [f32::INFINITY, f32::NEG_INFINITY],
    theta: [0.0, -1.0],
    h: [f32::INFINITY, f32::NEG_INFINITY],
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh::{build_bvh, BvhParams};
    use crate::accel::space::Pieces;
    use proptest::prelude::*;

    /// Sectors of every kind: narrow and wide arcs anywhere (across ±π and 0), whole circles
    /// straddling the axis, pieces touching the axis; and, with `near_full`, arcs that together
    /// come within `1e-9` of the whole circle without closing it (a root just short of a turn).
    fn sectors(seed: u64, n: usize, near_full: bool) -> Vec<CylBounds> {
        let mut next = crate::testing::uniform(seed);
        let start = -PI + TAU * next();
        (0..n)
            .map(|i| {
                let (r0, dr, h0, dh) = (2.0 * next(), next(), 4.0 * next() - 2.0, next());
                let kind = (8.0 * next()) as u32;
                let theta = if near_full {
                    // Two halves: [start, start + π] and [start + π, start + 2π − 1e-9].
                    let half = (i % 2) as f64;
                    ThetaInterval::new(start + PI * half, PI - 1e-9 * half)
                } else {
                    match kind {
                        0 => ThetaInterval::FULL,
                        1 | 2 => ThetaInterval::new(-PI + TAU * next(), TAU * next()),
                        _ => ThetaInterval::new(-PI + TAU * next(), 0.6 * next()),
                    }
                };
                CylBounds {
                    r: [if kind == 0 || kind == 3 { 0.0 } else { r0 }, r0 + dr],
                    theta,
                    h: [h0, h0 + dh],
                    straddles_axis: kind == 0 && !near_full,
                }
            })
            .collect()
    }

    /// Queries as a BVH gets them (`(r, φ, h)`, `φ ∈ (−2, 2]`): anywhere, on the axis, and at
    /// every stored arc end and one `f32` step either side (reduced to `(−2, 2]`).
    fn queries(seed: u64, arcs: &[[f32; 2]]) -> Vec<DVec3> {
        let mut next = crate::testing::uniform(seed);
        let mut qs: Vec<DVec3> = (0..200)
            .map(|i| {
                let r = if i % 10 == 0 { 0.0 } else { 3.2 * next() };
                DVec3::new(r, 4.0 * next() - 2.0, 4.4 * next() - 2.2)
            })
            .collect();
        for &t in arcs.iter().flatten() {
            for t in [t, next_up(t), next_toward_neg(t)] {
                qs.push(DVec3::new(1.0, first_turn(t as f64), 0.0));
            }
        }
        qs
    }

    /// The next `f32` towards `+∞`.
    fn next_up(t: f32) -> f32 {
        -next_toward_neg(-t)
    }

    /// The pseudo-angle `phi` moved by whole turns into `(−2, 2]`, as a query's is.
    fn first_turn(phi: f64) -> f64 {
        phi - TURN * ((phi + 2.0) / TURN).ceil() + TURN
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// A prepared query's test agrees with `compact_contains` for every stored bound of the
        /// BVH it was prepared for, on every preset.
        #[test]
        fn prepared_sector_queries_agree_with_compact_contains(
            seed in any::<u64>(),
            n in 1usize..200,
            near_full in any::<bool>(),
        ) {
            let bounds = sectors(seed, n, near_full);
            let pieces = Pieces { cells: (0..n as u32).collect(), bounds };
            for (_, params) in BvhParams::PRESETS {
                let bvh = build_bvh(&pieces, &params);
                let stored: Vec<SectorF32> = bvh
                    .nodes
                    .iter()
                    .map(|n| n.bounds)
                    .chain(bvh.refs.iter().map(|r| r.bounds))
                    .collect();
                let arcs: Vec<[f32; 2]> = stored.iter().map(|c| c.theta).collect();
                let root = &bvh.nodes[0].bounds;
                for q in queries(seed ^ 1, &arcs) {
                    let prepared = CylBounds::prepare_query(q, root);
                    for c in &stored {
                        prop_assert_eq!(
                            CylBounds::query_contains(c, &prepared),
                            CylBounds::compact_contains(c, q),
                            "{:?} in {:?} (root {:?})", q, c, root
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn prepared_sector_queries_take_a_third_turn_for_arcs_starting_past_the_roots_turn() {
        // An arc may start up to an f32 step after the root's start plus a turn; a query just
        // after the root's start then meets it only at φ + 2·TURN.
        for root_start in [-2.0f32, -1.3, 0.0, 0.7, 2.0, 5.5] {
            let root = SectorF32 {
                r: [0.0, 2.0],
                theta: [root_start, root_start + 8.0],
                h: [-1.0, 1.0],
            };
            let t0 = next_up(root_start + 4.0);
            for (width, phi_offset) in [
                (3.9f32, 0.0f64),
                (4.5, 0.0),
                (4.5, 1e-9),
                (0.5, 0.0),
                (0.5, 1e-9),
            ] {
                let c = SectorF32 {
                    theta: [t0, t0 + width],
                    ..root
                };
                let phi = first_turn(root_start as f64 + phi_offset);
                let q = DVec3::new(1.0, phi, 0.0);
                assert_eq!(
                    CylBounds::query_contains(&c, &CylBounds::prepare_query(q, &root)),
                    CylBounds::compact_contains(&c, q),
                    "root {root_start}, arc {:?}, φ {phi}",
                    c.theta
                );
            }
        }
    }

    #[test]
    fn f32_rounding_is_outward() {
        for &x in &[0.1, -0.1, 1e6 + 0.3, -PI, 1e-300, -1e-300, 0.0, 1e40] {
            assert!((f32_down(x) as f64) <= x, "{x}");
            assert!((f32_up(x) as f64) >= x, "{x}");
            if x.abs() < 1e38 {
                let gap = (f32_up(x) as f64) - (f32_down(x) as f64);
                assert!(gap <= (x.abs() * 1.2e-7).max(1e-44), "{x}");
            }
        }
        assert!(f32_down(f64::NAN).is_nan());
    }

    #[test]
    fn sector_area_matches_cylbounds() {
        let frame = LinearFrame {
            anchor: DVec3::ZERO,
            theta0: 2.5,
            theta_width: 3.0,
        };
        for (r0, r1, lo, hi) in [
            (0.2, 0.9, 0.1, 1.3),
            (0.0, 1.0, 0.0, TAU),
            (0.5, 0.6, 2.0, 2.9),
        ] {
            let lin = Aabb::new(DVec3::new(r0, lo, -1.0), DVec3::new(r1, hi, 2.0));
            let b = CylBounds::delinearize(&lin, &frame);
            let exact = CylBounds {
                theta: ThetaInterval::new(frame.theta0 + lo, hi - lo),
                ..b
            };
            let a = sector_area(&lin);
            assert!((a - exact.surface_area()).abs() <= 1e-12 * a, "{a}");
        }
    }

    #[test]
    fn sector_compact_holds_seam_arcs() {
        // An arc across ±π in a frame starting just before it.
        let b = CylBounds {
            r: [1.0, 2.0],
            theta: ThetaInterval::from_range(3.0, -3.0),
            h: [0.0, 1.0],
            straddles_axis: false,
        };
        let frame = CylBounds::frame_of(&b);
        let lin = b.linearize(&frame);
        assert!(lin.min.y.abs() < 1e-15 && (lin.max.y - (TAU - 6.0)).abs() < 1e-12);
        let c = CylBounds::compact(&lin, &frame);
        assert!(CylBounds::compact_holds(&c, &b, &frame));
        let q = |t: f64| CylBounds::stored_coordinates(DVec3::new(1.5, t, 0.5 - frame.anchor.z));
        assert!(CylBounds::compact_contains(&c, q(PI)));
        assert!(CylBounds::compact_contains(&c, q(-3.05)));
        assert!(!CylBounds::compact_contains(&c, q(0.0)));
        assert!(!CylBounds::compact_contains(&c, q(2.9)));
    }
}
