//! Cylindrical coordinates about a machine axis, periodic θ intervals, sector bounds, and
//! conservative cylindrical bounds of a trilinear cell.
//!
//! Conventions: `r ≥ 0` is the distance from the axis, `θ ∈ (−π, π]` is measured from the
//! frame's `e1` towards `e2`, `h` is the signed distance along the axis from its origin.
//!
//! # Conservative cell bounds
//! A trilinear cell lies in the convex hull of its corners. Project the corners onto the plane
//! orthogonal to the axis: the cell's projection lies in the 2-D convex hull `H` of the projected
//! corners. So
//! - `r_min` = distance from the axis to `H` (an edge or face may pass closer than any vertex);
//! - `r_max` = the largest corner `r` (`r` is convex, its maximum on `H` is at a vertex);
//! - `h` = the range of the corners' `h` (`h` is linear);
//! - if `H` keeps away from the axis, every point's θ lies in the smallest arc holding the
//!   corners' angles (the cone that `H` spans from the axis is narrower than π); otherwise the
//!   cell straddles (or touches) the axis and θ is the whole circle — [`straddle_sectors`]
//!   then covers it by `k` sectors `[0, r_max,i] × [2πi/k, 2π(i+1)/k] × h` instead.
//!
//! Every bound is padded by the rounding its computation can make (a few ulps of the
//! coordinates' magnitude) plus `1e-12` of the cell's extent, so the bounds stay conservative.

use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

use super::bounds::cell_bounds;

/// Angular slack of [`ThetaInterval::contains`]: the rounding of reducing an angle to the arc.
pub const ANGLE_SLACK: f64 = 8.0 * f64::EPSILON * PI;

/// A cell whose corners' hull passes within this fraction of its largest corner radius from the
/// axis counts as straddling it.
pub const AXIS_TOUCH_TOLERANCE: f64 = 1e-9;

/// Relative padding of cell bounds, in units of the cell's extent.
pub const BOUNDS_PADDING: f64 = 1e-12;

/// `a.rem_euclid(2π)`, bit for bit, without the remainder's division where `|a| < 2π` (the
/// angles of cells and arcs): there the remainder is `a` itself, exactly, so only the sign's
/// correction is left.
#[inline]
pub fn rem_tau(a: f64) -> f64 {
    let r = if a.abs() < TAU { a } else { a % TAU };
    if r < 0.0 {
        r + TAU
    } else {
        r
    }
}

/// The angle `a` reduced to `(−π, π]`.
#[inline]
pub fn normalize_angle(a: f64) -> f64 {
    if !a.is_finite() {
        return a;
    }
    let mut t = rem_tau(a); // [0, 2π]
    if t > PI {
        t -= TAU;
    }
    if t <= -PI {
        t += TAU;
    }
    t
}

/// An orthonormal frame about an axis: `origin`, the unit `axis`, and `e1`, `e2` spanning the
/// plane orthogonal to it (`e1 × e2 = axis`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CylFrame {
    /// A point on the axis, where `h = 0`.
    pub origin: DVec3,
    /// The unit direction of the axis.
    pub axis: DVec3,
    /// The direction of `θ = 0`.
    pub e1: DVec3,
    /// The direction of `θ = π/2`.
    pub e2: DVec3,
}

impl CylFrame {
    /// The frame of the axis through `origin` along `direction` (normalized here); `None` if the
    /// direction is zero or anything is not finite. `e1` is the coordinate axis least aligned
    /// with the direction, made orthogonal to it (for the z axis, `e1 = x`, `e2 = y`).
    ///
    /// ```
    /// use cylvol::geometry::cylindrical::CylFrame;
    /// use glam::DVec3;
    /// let f = CylFrame::new(DVec3::ZERO, DVec3::Z * 3.0).unwrap();
    /// let (r, theta, h) = f.to_cylindrical(DVec3::new(0.0, 2.0, 5.0));
    /// assert!((r - 2.0).abs() < 1e-15 && (theta - std::f64::consts::FRAC_PI_2).abs() < 1e-15 && h == 5.0);
    /// ```
    pub fn new(origin: DVec3, direction: DVec3) -> Option<Self> {
        if !origin.is_finite() {
            return None;
        }
        let axis = direction.try_normalize()?;
        let a = axis.abs();
        let pick = if a.x <= a.y && a.x <= a.z {
            DVec3::X
        } else if a.y <= a.z {
            DVec3::Y
        } else {
            DVec3::Z
        };
        let e1 = (pick - axis * pick.dot(axis)).try_normalize()?;
        let e2 = axis.cross(e1);
        Some(CylFrame {
            origin,
            axis,
            e1,
            e2,
        })
    }

    /// `(x, y, h)`: the point's coordinates in the frame (`x` along `e1`, `y` along `e2`).
    #[inline]
    pub fn to_local(&self, p: DVec3) -> DVec3 {
        let d = p - self.origin;
        DVec3::new(d.dot(self.e1), d.dot(self.e2), d.dot(self.axis))
    }

    /// `(r, θ, h)` of a point, `θ ∈ (−π, π]` (0 on the axis).
    #[inline]
    pub fn to_cylindrical(&self, p: DVec3) -> (f64, f64, f64) {
        let l = self.to_local(p);
        let mut theta = l.y.atan2(l.x);
        if theta <= -PI {
            theta = PI;
        }
        (l.x.hypot(l.y), theta, l.z)
    }

    /// `(r, φ, h)`: [`CylFrame::to_cylindrical`] with the angle's pseudo-angle
    /// ([`crate::geometry::pseudo_angle::pseudo_angle`]) in place of the angle, made with one
    /// division instead of an `atan2`: the coordinates a sector BVH compares.
    ///
    /// ```
    /// use cylvol::geometry::cylindrical::CylFrame;
    /// use glam::DVec3;
    /// let f = CylFrame::new(DVec3::ZERO, DVec3::Z).unwrap();
    /// assert_eq!(f.to_pseudo_cylindrical(DVec3::new(0.0, 2.0, 5.0)), DVec3::new(2.0, 1.0, 5.0));
    /// ```
    #[inline]
    pub fn to_pseudo_cylindrical(&self, p: DVec3) -> DVec3 {
        let l = self.to_local(p);
        // The radius as the cell bounds measure it (the root of the squared length; `hypot`
        // guards against overflow at 1e154 and costs 1.5 % of the paper frame).
        DVec3::new(
            (l.x * l.x + l.y * l.y).sqrt(),
            crate::geometry::pseudo_angle::pseudo_angle(l.y, l.x),
            l.z,
        )
    }

    /// The point with cylindrical coordinates `(r, θ, h)`.
    #[inline]
    pub fn from_cylindrical(&self, r: f64, theta: f64, h: f64) -> DVec3 {
        let (s, c) = theta.sin_cos();
        self.origin + self.e1 * (r * c) + self.e2 * (r * s) + self.axis * h
    }
}

/// An arc of the circle of angles: from `start` counter-clockwise over `width`. Angles are
/// periodic, so an arc crossing the seam at ±π is one arc, never its complement. There are an
/// empty state (contains nothing) and a full state (`width = 2π`, contains everything).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThetaInterval {
    start: f64,
    width: f64,
}

impl ThetaInterval {
    /// The arc that contains nothing (the identity of [`ThetaInterval::union`]).
    pub const EMPTY: ThetaInterval = ThetaInterval {
        start: 0.0,
        width: -1.0,
    };
    /// The whole circle.
    pub const FULL: ThetaInterval = ThetaInterval {
        start: -PI,
        width: TAU,
    };

    /// The arc from `start` over `width` (clamped to `[0, 2π]`; a NaN width gives the whole
    /// circle, which is the conservative answer; a NaN start the empty arc).
    pub fn new(start: f64, width: f64) -> Self {
        if !start.is_finite() && width < TAU {
            return Self::EMPTY;
        }
        if width.is_nan() || width >= TAU {
            return Self::FULL;
        }
        ThetaInterval {
            start: normalize_angle(start),
            width: width.max(0.0),
        }
    }

    /// The arc from `lo` counter-clockwise to `hi` (so `from_range(3.0, -3.0)` is the short arc
    /// across the seam at π).
    pub fn from_range(lo: f64, hi: f64) -> Self {
        Self::new(lo, rem_tau(hi - lo))
    }

    /// The arc holding a single angle.
    pub fn point(theta: f64) -> Self {
        Self::new(theta, 0.0)
    }

    /// The smallest arc holding all the angles (the complement of the largest gap between them).
    ///
    /// ```
    /// use cylvol::geometry::cylindrical::ThetaInterval;
    /// let a = ThetaInterval::from_angles([3.0, -3.0, 3.1]);
    /// assert!((a.width() - (2.0 * std::f64::consts::PI - 6.0)).abs() < 1e-12);
    /// assert!(a.contains(std::f64::consts::PI) && !a.contains(0.0));
    /// ```
    pub fn from_angles(angles: impl IntoIterator<Item = f64>) -> Self {
        let mut a: Vec<f64> = angles.into_iter().collect();
        Self::from_angles_in(&mut a)
    }

    /// [`ThetaInterval::from_angles`] of the angles in `a` (reordered; no allocation).
    fn from_angles_in(a: &mut [f64]) -> Self {
        for x in a.iter_mut() {
            *x = normalize_angle(*x);
        }
        if a.iter().any(|x| x.is_nan()) {
            return Self::FULL;
        }
        if a.is_empty() {
            return Self::EMPTY;
        }
        // A stable sort: for the few angles of a cell, an insertion sort without allocation.
        a.sort_by(f64::total_cmp);
        // Largest gap, including the wrap-around gap from the last to the first.
        let n = a.len();
        let mut best_gap = a[0] + TAU - a[n - 1];
        let mut start = a[0];
        for i in 1..n {
            let gap = a[i] - a[i - 1];
            if gap > best_gap {
                best_gap = gap;
                start = a[i];
            }
        }
        Self::new(start, TAU - best_gap)
    }

    /// Whether the arc contains nothing.
    pub fn is_empty(&self) -> bool {
        self.width < 0.0
    }

    /// Whether the arc is the whole circle.
    pub fn is_full(&self) -> bool {
        self.width >= TAU
    }

    /// The start angle, in `(−π, π]`.
    pub fn start(&self) -> f64 {
        self.start
    }

    /// The angular width, in `[0, 2π]` (negative for the empty arc).
    pub fn width(&self) -> f64 {
        self.width
    }

    /// The end angle `start + width`, reduced to `(−π, π]`.
    pub fn end(&self) -> f64 {
        normalize_angle(self.start + self.width)
    }

    /// Whether the arc holds the angle (any real; reduced mod 2π), with a slack of
    /// [`ANGLE_SLACK`] for the reduction's rounding.
    pub fn contains(&self, theta: f64) -> bool {
        if self.is_empty() || theta.is_nan() {
            return false;
        }
        if self.is_full() {
            return true;
        }
        let off = rem_tau(theta - self.start);
        off <= self.width + ANGLE_SLACK || off >= TAU - ANGLE_SLACK
    }

    /// Whether the two arcs share an angle.
    pub fn overlaps(&self, other: &ThetaInterval) -> bool {
        !self.is_empty()
            && !other.is_empty()
            && (self.contains(other.start) || other.contains(self.start))
    }

    /// The smallest arc containing both. Of the two arcs that start at one of the starts and
    /// reach the other's end, the shorter — so the gap left out is the larger of the two gaps,
    /// and an arc across the seam never turns into its complement.
    ///
    /// ```
    /// use cylvol::geometry::cylindrical::ThetaInterval;
    /// let a = ThetaInterval::from_range(3.0, -3.0); // across the seam at π
    /// let b = ThetaInterval::from_range(2.5, 2.9);
    /// let u = a.union(&b);
    /// assert!(u.contains(std::f64::consts::PI) && u.contains(2.6) && !u.contains(0.0));
    /// ```
    pub fn union(&self, other: &ThetaInterval) -> ThetaInterval {
        if self.is_empty() {
            return *other;
        }
        if other.is_empty() {
            return *self;
        }
        if self.is_full() || other.is_full() {
            return Self::FULL;
        }
        let from_self = (rem_tau(other.start - self.start) + other.width).max(self.width);
        let from_other = (rem_tau(self.start - other.start) + self.width).max(other.width);
        if from_self <= from_other {
            Self::new(self.start, from_self)
        } else {
            Self::new(other.start, from_other)
        }
    }

    /// The arc widened by `delta ≥ 0` at each end.
    pub fn padded(&self, delta: f64) -> ThetaInterval {
        if self.is_empty() || self.is_full() {
            return *self;
        }
        Self::new(self.start - delta, self.width + 2.0 * delta)
    }

    /// The arc as one or two ordinary ranges `[lo, hi]` within `[−π, π]` (two when it crosses
    /// the seam at ±π; none when empty; `[−π, π]` when full).
    ///
    /// ```
    /// use cylvol::geometry::cylindrical::ThetaInterval;
    /// let r: Vec<[f64; 2]> = ThetaInterval::from_range(3.0, -3.0).ranges().collect();
    /// assert_eq!(r.len(), 2);
    /// assert_eq!(r[0], [3.0, std::f64::consts::PI]);
    /// ```
    pub fn ranges(&self) -> impl Iterator<Item = [f64; 2]> {
        let pair = if self.is_empty() {
            [None, None]
        } else if self.is_full() {
            [Some([-PI, PI]), None]
        } else if self.start + self.width <= PI {
            [Some([self.start, self.start + self.width]), None]
        } else {
            [
                Some([self.start, PI]),
                Some([-PI, (self.start + self.width - TAU).min(PI)]),
            ]
        };
        pair.into_iter().flatten()
    }
}

/// A cylindrical sector `[r₀, r₁] × θ-arc × [h₀, h₁]`, the bounds of the cylindrical structures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CylBounds {
    /// `[r_min, r_max]`, `0 ≤ r_min`.
    pub r: [f64; 2],
    /// The arc of angles.
    pub theta: ThetaInterval,
    /// `[h_min, h_max]` along the axis.
    pub h: [f64; 2],
    /// Whether the bounded set reaches around the axis (then `theta` is the full circle and
    /// `r_min = 0`).
    pub straddles_axis: bool,
}

impl CylBounds {
    /// The empty bounds (the identity of [`CylBounds::union`]).
    pub const EMPTY: CylBounds = CylBounds {
        r: [f64::INFINITY, f64::NEG_INFINITY],
        theta: ThetaInterval::EMPTY,
        h: [f64::INFINITY, f64::NEG_INFINITY],
        straddles_axis: false,
    };

    /// Whether nothing is bounded.
    pub fn is_empty(&self) -> bool {
        !(self.r[0] <= self.r[1] && self.h[0] <= self.h[1]) || self.theta.is_empty()
    }

    /// The smallest sector holding both.
    pub fn union(&self, other: &CylBounds) -> CylBounds {
        if self.is_empty() {
            return *other;
        }
        if other.is_empty() {
            return *self;
        }
        let straddles = self.straddles_axis || other.straddles_axis;
        CylBounds {
            r: [
                if straddles {
                    0.0
                } else {
                    self.r[0].min(other.r[0])
                },
                self.r[1].max(other.r[1]),
            ],
            theta: if straddles {
                ThetaInterval::FULL
            } else {
                self.theta.union(&other.theta)
            },
            h: [self.h[0].min(other.h[0]), self.h[1].max(other.h[1])],
            straddles_axis: straddles,
        }
    }

    /// Whether the point `(r, θ, h)` lies in the sector. A point on the axis (`r = 0`) has no
    /// angle and lies in every sector that reaches the axis.
    pub fn contains(&self, r: f64, theta: f64, h: f64) -> bool {
        r >= self.r[0]
            && r <= self.r[1]
            && h >= self.h[0]
            && h <= self.h[1]
            && (self.theta.contains(theta) || (r == 0.0 && !self.theta.is_empty()))
    }

    /// The volume of the sector, `Δθ/2 · (r₁² − r₀²) · Δh`.
    pub fn volume(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let w = self.theta.width().min(TAU);
        0.5 * w * (self.r[1] * self.r[1] - self.r[0] * self.r[0]) * (self.h[1] - self.h[0])
    }

    /// The true surface area of the sector: two annular-sector caps `Δθ/2 · (r₁² − r₀²)`, the
    /// outer and inner curved faces `Δθ · (r₁ + r₀) · Δh`, and — unless it is the full circle —
    /// two planar sides `(r₁ − r₀) · Δh`.
    ///
    /// ```
    /// use cylvol::geometry::cylindrical::{CylBounds, ThetaInterval};
    /// let full = CylBounds { r: [0.0, 1.0], theta: ThetaInterval::FULL, h: [0.0, 1.0], straddles_axis: true };
    /// let pi = std::f64::consts::PI;
    /// assert!((full.surface_area() - 4.0 * pi).abs() < 1e-12); // 2 discs + the mantle
    /// ```
    pub fn surface_area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let w = self.theta.width().min(TAU);
        let (r0, r1) = (self.r[0], self.r[1]);
        let dh = self.h[1] - self.h[0];
        let caps = w * (r1 * r1 - r0 * r0);
        let curved = w * (r1 + r0) * dh;
        let sides = if self.theta.is_full() {
            0.0
        } else {
            2.0 * (r1 - r0) * dh
        };
        caps + curved + sides
    }

    /// Cover these bounds by `k` (at least 2) sectors `[0, r_max] × [2πi/k, 2π(i+1)/k] × h`,
    /// the simple split of a straddling cell (see [`straddle_sectors`] for a tighter one).
    pub fn split_sectors(&self, k: usize) -> Vec<CylBounds> {
        let k = k.max(2);
        let w = TAU / k as f64;
        (0..k)
            .map(|i| CylBounds {
                r: [0.0, self.r[1]],
                theta: ThetaInterval::new(w * i as f64, w).padded(ANGLE_SLACK),
                h: self.h,
                straddles_axis: false,
            })
            .collect()
    }
}

/// The corners in the frame: `(x, y)` in the plane and `h`, with the rounding pad and extent.
struct Projected {
    xy: [DVec2; 8],
    h: [f64; 8],
    pad: f64,
}

fn project(corners: &[DVec3; 8], frame: &CylFrame) -> Projected {
    project_local(corners, &corners.map(|c| frame.to_local(c)), frame)
}

/// [`project`] with the corners' [`CylFrame::to_local`] coordinates given.
fn project_local(corners: &[DVec3; 8], local: &[DVec3; 8], frame: &CylFrame) -> Projected {
    let mut xy = [DVec2::ZERO; 8];
    let mut h = [0.0; 8];
    let mut mag: f64 = 0.0;
    for (i, (c, l)) in corners.iter().zip(local).enumerate() {
        let d = *c - frame.origin;
        mag = mag.max(d.abs().max_element());
        xy[i] = DVec2::new(l.x, l.y);
        h[i] = l.z;
    }
    let extent = cell_bounds(corners).extent().max_element();
    // A dot product of 3 terms after a subtraction: a few ulps of the magnitude.
    let pad = 16.0 * f64::EPSILON * mag + BOUNDS_PADDING * extent;
    Projected { xy, h, pad }
}

/// A mesh's points in a frame, for the bounds of all its cells: each point's
/// [`CylFrame::to_local`] coordinates and the arc tangent `atan2(y, x)` of its angle, made
/// once per point rather than once for each of the (about eight) cells that share it.
/// [`FramePoints::cell_bounds`] gives, bit for bit, what [`cylindrical_bounds`] gives.
pub struct FramePoints {
    frame: CylFrame,
    local: Vec<DVec3>,
    atan2: Vec<f64>,
}

impl FramePoints {
    /// The points in `frame` (in parallel).
    pub fn new(points: &[DVec3], frame: &CylFrame) -> FramePoints {
        use rayon::prelude::*;
        let local: Vec<DVec3> = points.par_iter().map(|&p| frame.to_local(p)).collect();
        let atan2 = local.par_iter().map(|l| l.y.atan2(l.x)).collect();
        FramePoints {
            frame: *frame,
            local,
            atan2,
        }
    }

    /// [`cylindrical_bounds`] of the cell with these corners, whose point ids are `ids`
    /// (indices into the points this was made of).
    pub fn cell_bounds(&self, corners: &[DVec3; 8], ids: &[u32; 8]) -> CylBounds {
        let local = ids.map(|i| self.local[i as usize]);
        let pr = project_local(corners, &local, &self.frame);
        bounds_of_projected(&pr, |k| self.atan2[ids[k] as usize])
    }
}
fn cross(a: DVec2, b: DVec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Most points [`convex_hull`] takes (a cell's corners).
const HULL_INPUT: usize = 8;

/// A convex polygon of at most `2 · HULL_INPUT` vertices, held without allocation.
struct Hull {
    points: [DVec2; 2 * HULL_INPUT],
    len: usize,
}

impl Hull {
    fn as_slice(&self) -> &[DVec2] {
        &self.points[..self.len]
    }
}

/// The convex hull of the points (at most [`HULL_INPUT`]; the rest are ignored),
/// counter-clockwise, without collinear points (1 or 2 points when degenerate). Andrew's
/// monotone chain, on the stack.
fn convex_hull(points: &[DVec2]) -> Hull {
    let mut p = [DVec2::ZERO; HULL_INPUT];
    let m = points.len().min(HULL_INPUT);
    p[..m].copy_from_slice(&points[..m]);
    // A stable sort; for 8 points an insertion sort without allocation.
    p[..m].sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    // Drop consecutive duplicates.
    let mut n = 0;
    for i in 0..m {
        if n == 0 || p[i] != p[n - 1] {
            p[n] = p[i];
            n += 1;
        }
    }
    let mut hull = Hull {
        points: [DVec2::ZERO; 2 * HULL_INPUT],
        len: 0,
    };
    if n <= 2 {
        hull.points[..n].copy_from_slice(&p[..n]);
        hull.len = n;
        return hull;
    }
    let h = &mut hull.points;
    let mut len = 0usize;
    for pass in 0..2 {
        let start = len;
        for j in 0..n {
            let q = if pass == 0 { p[j] } else { p[n - 1 - j] };
            while len >= start + 2 && cross(h[len - 1] - h[len - 2], q - h[len - 2]) <= 0.0 {
                len -= 1;
            }
            h[len] = q;
            len += 1;
        }
        len -= 1;
    }
    hull.len = len;
    hull
}

/// The squared distance from the origin to the segment (its root is the distance).
fn segment_distance_squared(a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        (-a.dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t).length_squared()
}

fn segment_distance(a: DVec2, b: DVec2) -> f64 {
    segment_distance_squared(a, b).sqrt()
}

/// Distance from the origin to the convex polygon (0 when inside or on it).
fn hull_distance(hull: &[DVec2]) -> f64 {
    match hull.len() {
        0 => f64::INFINITY,
        1 => hull[0].length(),
        2 => segment_distance(hull[0], hull[1]),
        n => {
            let inside = (0..n).all(|i| cross(hull[(i + 1) % n] - hull[i], -hull[i]) >= 0.0);
            if inside {
                0.0
            } else {
                // The least root is the root of the least square (monotone, correctly rounded).
                (0..n)
                    .map(|i| segment_distance_squared(hull[i], hull[(i + 1) % n]))
                    .fold(f64::INFINITY, f64::min)
                    .sqrt()
            }
        }
    }
}

/// Conservative cylindrical bounds of a trilinear cell (see the module documentation). A cell
/// whose corners' hull contains or touches the axis (within [`AXIS_TOUCH_TOLERANCE`] of its
/// largest radius) gets `straddles_axis = true`, `r_min = 0` and the full circle.
///
/// ```
/// use cylvol::geometry::cylindrical::{cylindrical_bounds, CylFrame};
/// use cylvol::geometry::trilinear::CORNER_PARAMETERS;
/// use glam::DVec3;
/// let frame = CylFrame::new(DVec3::ZERO, DVec3::Z).unwrap();
/// // A unit cube from (1, -0.5, 0): its face x = 1 passes at r = 1 although no corner does.
/// let cell = CORNER_PARAMETERS.map(|c| DVec3::from_array(c) + DVec3::new(1.0, -0.5, 0.0));
/// let b = cylindrical_bounds(&cell, &frame);
/// assert!(b.r[0] <= 1.0 && b.r[0] > 1.0 - 1e-9);
/// assert!(!b.straddles_axis && b.theta.contains(0.0) && !b.theta.contains(1.0));
/// ```
pub fn cylindrical_bounds(corners: &[DVec3; 8], frame: &CylFrame) -> CylBounds {
    let pr = project(corners, frame);
    bounds_of_projected(&pr, |k| pr.xy[k].y.atan2(pr.xy[k].x))
}

/// [`cylindrical_bounds`] of projected corners; `atan2(k)` is `atan2(y, x)` of corner `k`.
fn bounds_of_projected(pr: &Projected, atan2: impl Fn(usize) -> f64) -> CylBounds {
    // Squared radii: the extreme radii are the roots of the extreme squares (the square root
    // is monotone and correctly rounded), so one root each instead of eight.
    let r2 = pr.xy.map(|p| p.length_squared());
    let r_max = r2.iter().copied().fold(0.0, f64::max).sqrt();
    let (h_lo, h_hi) =
        pr.h.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &h| {
                (a.min(h), b.max(h))
            });
    let h = [h_lo - pr.pad, h_hi + pr.pad];
    let r_hi = r_max + pr.pad;
    if !(r_max.is_finite() && h_lo.is_finite() && h_hi.is_finite()) {
        // Conservative for garbage input: everything.
        return CylBounds {
            r: [0.0, f64::INFINITY],
            theta: ThetaInterval::FULL,
            h: [f64::NEG_INFINITY, f64::INFINITY],
            straddles_axis: true,
        };
    }
    let hull = convex_hull(&pr.xy);
    let dist = hull_distance(hull.as_slice());
    let touch = (AXIS_TOUCH_TOLERANCE * r_max).max(2.0 * pr.pad);
    if dist <= touch {
        return CylBounds {
            r: [0.0, r_hi],
            theta: ThetaInterval::FULL,
            h,
            straddles_axis: true,
        };
    }
    // Each corner's angle is uncertain by about pad / r.
    // max over corners of pad / r is pad over the least r (division is monotone too).
    let r_min = r2.iter().copied().fold(f64::INFINITY, f64::min).sqrt();
    let dtheta = 0.0f64.max(pr.pad / r_min) + ANGLE_SLACK;
    let theta = corner_arc(&pr.xy, atan2).padded(dtheta);
    CylBounds {
        r: [(dist - pr.pad).max(0.0), r_hi],
        theta,
        h,
        straddles_axis: false,
    }
}

/// [`ThetaInterval::from_angles`] of the corners' angles `atan2(y, x)`, exactly, with fewer
/// arc tangents: when every corner lies within a quarter turn of the first one, the corners
/// are ordered by the tangent of their angle from it, and only those that may be the arc's
/// ends (within a generous tolerance of the extreme tangents) get their `atan2`. The arc's
/// start and end are then the same angles as the sorted list's, and its width is computed by
/// the same expression. Anything unusual (a corner a quarter turn away or more, NaN, ends
/// that straddle the seam, an arc near half a turn) takes the full path.
/// `atan2(k)` is `atan2(y, x)` of `xy[k]`.
fn corner_arc(xy: &[DVec2; 8], atan2: impl Fn(usize) -> f64) -> ThetaInterval {
    corner_arc_fast(xy, &atan2).unwrap_or_else(|| {
        let mut angles: [f64; 8] = std::array::from_fn(atan2);
        ThetaInterval::from_angles_in(&mut angles)
    })
}

/// [`corner_arc`]'s quick path; `None` where it must sort all the angles.
fn corner_arc_fast(xy: &[DVec2; 8], atan2: impl Fn(usize) -> f64) -> Option<ThetaInterval> {
    let u = xy[0];
    let mut t = [0.0f64; 8];
    for (t, p) in t.iter_mut().zip(xy) {
        let d = u.dot(*p);
        // NaN fails this test too.
        if d.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        *t = cross(u, *p) / d;
    }
    let lo = t.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = t.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    // Rounding moves a tangent by a few ulps of 1 + t²; the tolerance is far wider.
    let (tol_lo, tol_hi) = (1e-7 * (1.0 + lo * lo), 1e-7 * (1.0 + hi * hi));
    let (mut start, mut end) = (f64::NAN, f64::NAN);
    let (mut start_span, mut end_span) = (
        [f64::INFINITY, f64::NEG_INFINITY],
        [f64::INFINITY, f64::NEG_INFINITY],
    );
    for (k, &tj) in t.iter().enumerate() {
        let near_lo = tj <= lo + tol_lo;
        let near_hi = tj >= hi - tol_hi;
        if !(near_lo || near_hi) {
            continue;
        }
        let a = normalize_angle(atan2(k));
        if near_lo {
            if start.is_nan() || a.total_cmp(&start).is_lt() {
                start = a;
            }
            start_span = [start_span[0].min(a), start_span[1].max(a)];
        }
        if near_hi {
            if end.is_nan() || a.total_cmp(&end).is_gt() {
                end = a;
            }
            end_span = [end_span[0].min(a), end_span[1].max(a)];
        }
    }
    // Candidates for one end on both sides of the seam: the ordering there is unclear.
    if start_span[1] - start_span[0] > FRAC_PI_2 || end_span[1] - end_span[0] > FRAC_PI_2 {
        return None;
    }
    // The sorted angles' largest gap: across the seam (from the last to the first) when the
    // arc does not cross it, else between the arc's end and its start.
    let gap = if start.total_cmp(&end).is_le() {
        start + TAU - end
    } else {
        start - end
    };
    // Every other gap is then at most the arc's width, far below this one.
    if gap.partial_cmp(&(PI + 1e-6)) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    Some(ThetaInterval::new(start, TAU - gap))
}

/// Clip a convex polygon by the half-plane `n · p ≥ −pad`.
fn clip(poly: &[DVec2], n: DVec2, pad: f64) -> Vec<DVec2> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    let m = poly.len();
    for i in 0..m {
        let a = poly[i];
        let b = poly[(i + 1) % m];
        let da = n.dot(a) + pad;
        let db = n.dot(b) + pad;
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            let t = da / (da - db);
            out.push(a + (b - a) * t);
        }
    }
    out
}

/// Sector bounds covering a cell. A cell that does not straddle the axis gets its
/// [`cylindrical_bounds`] alone. A straddling one is cut into `k` (at least 3) sectors
/// `[2πi/k, 2π(i+1)/k]`: for each, the corners' hull is clipped to the sector's wedge (slightly
/// widened for rounding); sectors the hull misses are left out, and the others get
/// `r ∈ [0, r_max,i]` with `r_max,i` the largest radius of the clipped polygon, and the cell's
/// `h` range.
pub fn straddle_sectors(corners: &[DVec3; 8], frame: &CylFrame, k: usize) -> Vec<CylBounds> {
    let whole = cylindrical_bounds(corners, frame);
    if !whole.straddles_axis || !whole.r[1].is_finite() {
        return vec![whole];
    }
    let k = k.max(3);
    let pr = project(corners, frame);
    let mut hull = convex_hull(&pr.xy).as_slice().to_vec();
    if hull.len() < 3 {
        // A segment or a point: thicken into a polygon for clipping.
        let a = hull.first().copied().unwrap_or(DVec2::ZERO);
        let b = hull.last().copied().unwrap_or(DVec2::ZERO);
        hull = vec![a, b, b, a];
    }
    let w = TAU / k as f64;
    let mut out = Vec::with_capacity(k);
    for i in 0..k {
        let a0 = w * i as f64;
        let a1 = w * (i + 1) as f64;
        let (s0, c0) = a0.sin_cos();
        let (s1, c1) = a1.sin_cos();
        // Wedge: cross(dir0, p) ≥ 0 and cross(p, dir1) ≥ 0, widened by the pad.
        let n0 = DVec2::new(-s0, c0);
        let n1 = DVec2::new(s1, -c1);
        let poly = clip(&clip(&hull, n0, pr.pad), n1, pr.pad);
        if poly.is_empty() {
            continue;
        }
        let r_max = poly.iter().map(|p| p.length()).fold(0.0, f64::max);
        out.push(CylBounds {
            r: [0.0, r_max + pr.pad],
            theta: ThetaInterval::new(a0, w).padded(ANGLE_SLACK),
            h: whole.h,
            straddles_axis: false,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_round_trip_and_seam() {
        let f = CylFrame::new(DVec3::new(1.0, 2.0, 3.0), DVec3::new(1.0, 1.0, 0.5)).unwrap();
        assert!((f.e1.cross(f.e2) - f.axis).length() < 1e-15);
        for (r, t, h) in [(2.0, 0.3, -1.0), (0.5, PI, 4.0), (1.0, -2.0, 0.0)] {
            let p = f.from_cylindrical(r, t, h);
            let (r2, t2, h2) = f.to_cylindrical(p);
            assert!((r - r2).abs() < 1e-14 && (t - t2).abs() < 1e-14 && (h - h2).abs() < 1e-14);
        }
        let z = CylFrame::new(DVec3::ZERO, DVec3::Z).unwrap();
        assert_eq!(z.to_cylindrical(DVec3::new(-1.0, -0.0, 0.0)).1, PI);
        assert!(CylFrame::new(DVec3::ZERO, DVec3::ZERO).is_none());
        assert!(CylFrame::new(DVec3::NAN, DVec3::Z).is_none());
    }

    #[test]
    fn rem_tau_is_rem_euclid_bit_for_bit() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut values = vec![0.0, -0.0, PI, -PI, TAU, -TAU, 1e-300, -1e-300, 7.0, -7.0];
        values.extend([
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
        ]);
        let step = |x: f64, by: i64| f64::from_bits((x.to_bits() as i64 + by) as u64);
        values.extend([step(TAU, 1), step(TAU, -1), step(-TAU, 1), step(-TAU, -1)]);
        for _ in 0..100_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let unit = (state >> 11) as f64 / (1u64 << 53) as f64;
            values.push((unit - 0.5) * [1e-9, 1.0, 7.0, 13.0, 1e6][(state % 5) as usize]);
        }
        for a in values {
            assert_eq!(rem_tau(a).to_bits(), a.rem_euclid(TAU).to_bits(), "{a:e}");
        }
    }

    #[test]
    fn theta_interval_basics() {
        let a = ThetaInterval::from_range(3.0, -3.0);
        assert!(a.contains(PI) && a.contains(-PI) && a.contains(-3.05) && !a.contains(0.0));
        assert!((a.width() - (TAU - 6.0)).abs() < 1e-15);
        let b = ThetaInterval::from_range(-0.1, 0.1); // across 0
        assert!(b.contains(0.0) && !b.contains(PI));
        assert!(!a.overlaps(&b));
        let u = a.union(&b);
        assert!(u.contains(PI) && u.contains(0.0));
        assert!(u.width() < TAU);
        assert!(ThetaInterval::EMPTY.union(&a) == a);
        assert!(ThetaInterval::FULL.contains(1.234));
        let two: Vec<_> = a.ranges().collect();
        assert_eq!(two.len(), 2);
        assert!((two[1][1] + 3.0).abs() < 1e-15);
    }

    #[test]
    fn sector_area_and_volume_of_quarter_annulus() {
        let b = CylBounds {
            r: [1.0, 2.0],
            theta: ThetaInterval::new(0.0, PI / 2.0),
            h: [0.0, 3.0],
            straddles_axis: false,
        };
        let caps = 2.0 * (PI / 4.0) * (4.0 - 1.0);
        let curved = (PI / 2.0) * 3.0 * (1.0 + 2.0);
        let sides = 2.0 * 1.0 * 3.0;
        assert!((b.surface_area() - (caps + curved + sides)).abs() < 1e-12);
        assert!((b.volume() - PI / 4.0 * 3.0 * 3.0).abs() < 1e-12);
    }

    #[test]
    fn corner_arc_is_bit_identical_to_sorting_all_angles() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut fast_paths = 0;
        for case in 0..200_000 {
            // Centres anywhere, often right at the seam or at 0; spreads from none to wide.
            let centre = match case % 4 {
                0 => PI,
                1 => PI * (1.0 - 1e-12 * next()),
                2 => 0.0,
                _ => (2.0 * next() - 1.0) * PI,
            };
            let spread = [0.0, 1e-9, 0.05, 1.0, 2.9, 3.2][case % 6] * next();
            let mut xy = [DVec2::ZERO; 8];
            for i in 0..8 {
                // Half the corners share another corner's angle at another radius (radial
                // edges), where the angles of the two may round apart.
                let theta = if i >= 4 && case % 3 == 0 {
                    xy[i - 4].y.atan2(xy[i - 4].x)
                } else {
                    centre + spread * (next() - 0.5)
                };
                let r = [1.0, 1e-6, 1e6][case % 5 % 3] * (0.5 + next());
                xy[i] = DVec2::new(r * theta.cos(), r * theta.sin());
            }
            if case % 7 == 0 {
                xy[3] = xy[1] * 2.0; // exactly radial
            }
            let fast = corner_arc(&xy, |k| xy[k].y.atan2(xy[k].x));
            let mut angles = xy.map(|p| p.y.atan2(p.x));
            let full = ThetaInterval::from_angles_in(&mut angles);
            assert_eq!(
                (fast.start().to_bits(), fast.width().to_bits()),
                (full.start().to_bits(), full.width().to_bits()),
                "case {case}: {xy:?}"
            );
            fast_paths += usize::from(corner_arc_fast(&xy, |k| xy[k].y.atan2(xy[k].x)).is_some());
        }
        assert!(fast_paths > 50_000);
    }

    #[test]
    fn frame_points_give_cylindrical_bounds_bit_for_bit() {
        let mut state = 0x853c_49e6_748f_ea9bu64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let unit = |x: u64| (x >> 11) as f64 / (1u64 << 53) as f64;
        // Points on a ring and near the axis, shared by cells of random corners (some
        // repeated, as collapsed cells repeat them), about a tilted axis.
        let points: Vec<DVec3> = (0..500)
            .map(|i| {
                let r = if i % 10 == 0 {
                    1e-3 * unit(next())
                } else {
                    1.0 + unit(next())
                };
                let t = TAU * unit(next());
                DVec3::new(r * t.cos(), r * t.sin(), unit(next()) - 0.5)
            })
            .collect();
        let frame = CylFrame::new(DVec3::new(0.0, 0.0, 0.1), DVec3::new(0.01, 0.0, 1.0)).unwrap();
        let shared = FramePoints::new(&points, &frame);
        let bits = |b: CylBounds| {
            let [r0, r1, h0, h1] = [b.r[0], b.r[1], b.h[0], b.h[1]].map(f64::to_bits);
            let t = [b.theta.start(), b.theta.width()].map(f64::to_bits);
            (r0, r1, h0, h1, t, b.straddles_axis)
        };
        for _ in 0..20_000 {
            let first = (next() % 500) as u32;
            let ids: [u32; 8] = std::array::from_fn(|_| match next() % 4 {
                0 => first,
                _ => ((first as u64 + next() % 40) % 500) as u32,
            });
            let corners = ids.map(|i| points[i as usize]);
            assert_eq!(
                bits(shared.cell_bounds(&corners, &ids)),
                bits(cylindrical_bounds(&corners, &frame)),
                "{ids:?}"
            );
        }
    }

    #[test]
    fn edge_passing_near_axis_lowers_r_min() {
        let f = CylFrame::new(DVec3::ZERO, DVec3::Z).unwrap();
        // A thin cell whose bottom edge goes from (-1, 0.1) to (1, 0.1): vertices at r ≈ 1,
        // but the edge passes at r = 0.1.
        let c = [
            DVec3::new(-1.0, 0.1, 0.0),
            DVec3::new(1.0, 0.1, 0.0),
            DVec3::new(1.0, 0.3, 0.0),
            DVec3::new(-1.0, 0.3, 0.0),
            DVec3::new(-1.0, 0.1, 1.0),
            DVec3::new(1.0, 0.1, 1.0),
            DVec3::new(1.0, 0.3, 1.0),
            DVec3::new(-1.0, 0.3, 1.0),
        ];
        let b = cylindrical_bounds(&c, &f);
        assert!(!b.straddles_axis);
        assert!(b.r[0] <= 0.1 && b.r[0] > 0.1 - 1e-9);
        assert!(b.theta.contains(PI / 2.0) && !b.theta.contains(-PI / 2.0));
    }
}
