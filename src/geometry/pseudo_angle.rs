//! Pseudo-angles: a monotone stand-in for the polar angle that takes one division and no
//! trigonometry, so that a point query of a sector BVH needs no `atan2`.
//!
//! The pseudo-angle of a direction `(x, y)` ([`pseudo_angle`]) is the "diamond angle": the
//! position of `(x, y) / (|x| + |y|)` along the diamond `|x| + |y| = 1`, measured so that it
//! rises from `−2` (just past `θ = −π`) through `−1, 0, 1` (`θ = −π/2, 0, π/2`) to `2`
//! (`θ = π`). It increases strictly with the angle `θ = atan2(y, x) ∈ (−π, π]`, so an arc
//! `[θ₀, θ₁]` holds a direction exactly when the arc's pseudo-angles hold the direction's.
//! A whole turn is [`TURN`] = 4; angles beyond one turn map to pseudo-angles beyond it
//! ([`pseudo_of_angle`], [`angle_of_pseudo`]), so unwrapped arcs stay unwrapped.
//!
//! Its slope is between `1/2` and `1` per radian, so an arc padded by `ε` radians is padded
//! by at least `ε/2` in pseudo-angle: far above the rounding of one division.

use std::f64::consts::{FRAC_2_PI, FRAC_PI_2, TAU};

/// One turn in pseudo-angle (`2π` radians).
pub const TURN: f64 = 4.0;

/// Angular padding (radians) of an arc's ends before they become pseudo-angles
/// ([`padded_pseudo_arc`]): far above the rounding of unwrapping an angle and of making a
/// query's pseudo-angle, far below any cell's angular size.
pub const THETA_PAD: f64 = 1e-12;

/// The pseudo-angles of the arc `[lo, hi]` (radians, unwrapped: `hi` may pass `π`), each end
/// first padded outward by [`THETA_PAD`]. A direction whose angle lies in the arc has its
/// pseudo-angle ([`pseudo_angle`], plus [`TURN`] per turn beyond `(−π, π]`) in the result:
/// the padding covers the rounding of both.
///
/// ```
/// use cylvol::geometry::pseudo_angle::{padded_pseudo_arc, pseudo_angle};
/// use std::f64::consts::{FRAC_PI_2, PI};
/// let [lo, hi] = padded_pseudo_arc(-PI, FRAC_PI_2);
/// assert!(lo < -2.0 && lo > -2.0 - 1e-11 && hi > 1.0 && hi < 1.0 + 1e-11);
/// let p = pseudo_angle(1.0, 0.0); // θ = π/2 exactly, at the arc's end
/// assert!(lo <= p && p <= hi);
/// ```
#[inline]
pub fn padded_pseudo_arc(lo: f64, hi: f64) -> [f64; 2] {
    [
        pseudo_of_angle(lo - THETA_PAD),
        pseudo_of_angle(hi + THETA_PAD),
    ]
}

/// The pseudo-angle of the direction `(x, y)`, in `(−2, 2]`: increasing with
/// `atan2(y, x)` taken in `(−π, π]` (`y = −0` with `x < 0` is `θ = π`, pseudo-angle 2), and
/// 0 for the zero vector.
///
/// ```
/// use cylvol::geometry::pseudo_angle::pseudo_angle;
/// assert_eq!(pseudo_angle(0.0, 1.0), 0.0);
/// assert_eq!(pseudo_angle(1.0, 0.0), 1.0);
/// assert_eq!(pseudo_angle(0.0, -1.0), 2.0);
/// assert_eq!(pseudo_angle(-1.0, 0.0), -1.0);
/// assert!(pseudo_angle(-1e-9, -1.0) > -2.0 && pseudo_angle(-1e-9, -1.0) < -1.999);
/// assert_eq!(pseudo_angle(2.0, 2.0), 0.5);
/// ```
#[inline]
pub fn pseudo_angle(y: f64, x: f64) -> f64 {
    let sum = x.abs() + y.abs();
    if sum == 0.0 {
        return 0.0;
    }
    let p = y / sum;
    if x >= 0.0 {
        p
    } else if y >= 0.0 {
        2.0 - p
    } else {
        -2.0 - p
    }
}

/// The pseudo-angle of the angle `theta` (radians, any value): [`pseudo_angle`] of its
/// direction, plus [`TURN`] for every whole turn `theta` lies beyond `(−π, π]`. Increasing
/// in `theta` up to rounding.
///
/// ```
/// use cylvol::geometry::pseudo_angle::pseudo_of_angle;
/// use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
/// assert!((pseudo_of_angle(FRAC_PI_4) - 0.5).abs() < 1e-15);
/// assert!((pseudo_of_angle(PI) - 2.0).abs() < 1e-15);
/// assert!((pseudo_of_angle(PI + FRAC_PI_2) - 3.0).abs() < 1e-15);
/// assert!((pseudo_of_angle(-PI - FRAC_PI_2) + 3.0).abs() < 1e-15);
/// ```
#[inline]
pub fn pseudo_of_angle(theta: f64) -> f64 {
    let (s, c) = theta.sin_cos();
    let first = pseudo_angle(s, c);
    // The turn: the pseudo-angle lies within 0.3 of 2θ/π, so the nearest whole turn is it
    // even where rounding puts the direction on the other side of ±π.
    first + TURN * ((theta * FRAC_2_PI - first) / TURN).round()
}

/// The angle (radians) whose pseudo-angle is `phi` ([`pseudo_of_angle`] undone, whole turns
/// included).
///
/// ```
/// use cylvol::geometry::pseudo_angle::{angle_of_pseudo, pseudo_of_angle};
/// for theta in [-7.0, -3.14159, -1.0, 0.0, 0.3, 3.1, 3.2, 9.0] {
///     assert!((angle_of_pseudo(pseudo_of_angle(theta)) - theta).abs() < 1e-14);
/// }
/// ```
#[inline]
pub fn angle_of_pseudo(phi: f64) -> f64 {
    let (x, y) = diamond_point(phi);
    let theta = y.atan2(x);
    theta + TAU * ((phi * FRAC_PI_2 - theta) / TAU).round()
}

/// The point `(x, y)` in the direction whose pseudo-angle is `phi` (any turn) on the diamond
/// `|x| + |y| = 1` ([`pseudo_angle`] undone).
#[inline]
fn diamond_point(phi: f64) -> (f64, f64) {
    let turns = (phi / TURN).round();
    let first = phi - TURN * turns;
    if first > 1.0 {
        let p = 2.0 - first;
        (p - 1.0, p)
    } else if first < -1.0 {
        let p = -2.0 - first;
        (-1.0 - p, p)
    } else {
        (1.0 - first.abs(), first)
    }
}

/// The unit vector `(cos θ, sin θ)` of the direction whose pseudo-angle is `phi` (any turn),
/// without trigonometry: the direction's point on the diamond, normalised. Equal to the
/// cosine and sine of [`angle_of_pseudo`] up to rounding.
///
/// ```
/// use cylvol::geometry::pseudo_angle::{direction_of_pseudo, pseudo_of_angle};
/// for theta in [-7.0, -3.14159, -1.0, 0.0, 0.3, 3.1, 3.2, 9.0] {
///     let (c, s) = direction_of_pseudo(pseudo_of_angle(theta));
///     assert!((c - theta.cos()).abs() < 1e-15 && (s - theta.sin()).abs() < 1e-15);
/// }
/// ```
#[inline]
pub fn direction_of_pseudo(phi: f64) -> (f64, f64) {
    let (x, y) = diamond_point(phi);
    let norm = (x * x + y * y).sqrt();
    (x / norm, y / norm)
}

/// The width in radians of the arc of pseudo-angles `[lo, hi]`, estimated without
/// trigonometry (for the build's surface-area heuristic, which measures millions of arcs): a
/// whole turn or more is `2π`; an arc narrower than [`NARROW_ARC`] is its width times the
/// angle's slope at its middle (`dθ/dφ = 1 / ((1 − u)² + u²)`, `u` the place within the
/// quarter turn), each side of a quarter turn's end apart where it spans one (the slope is
/// continuous there but has a corner, where one slope for the whole arc would be off by up to
/// half the arc's width, relatively); a wider one is the difference of its ends' angles,
/// interpolated linearly in a table of the angle over a quarter turn. Within a part in a
/// thousand of the width for every arc, and within `1e-6` radians for the wide ones.
///
/// ```
/// use cylvol::geometry::pseudo_angle::{arc_width, pseudo_of_angle};
/// let w = arc_width(pseudo_of_angle(0.70), pseudo_of_angle(0.80));
/// assert!((w - 0.1).abs() < 1e-6);
/// let w = arc_width(pseudo_of_angle(-3.0), pseudo_of_angle(2.0));
/// assert!((w - 5.0).abs() < 1e-6);
/// assert_eq!(arc_width(-2.0, 2.5), std::f64::consts::TAU);
/// ```
#[inline]
pub fn arc_width(lo: f64, hi: f64) -> f64 {
    let w = hi - lo;
    if w >= TURN || w.is_nan() {
        return TAU;
    }
    if w < NARROW_ARC {
        let end = hi.floor();
        return if lo < end {
            narrow_arc_width(lo, end) + narrow_arc_width(end, hi)
        } else {
            narrow_arc_width(lo, hi)
        };
    }
    unwrapped_angle(hi) - unwrapped_angle(lo)
}

/// [`arc_width`] of a narrow arc within one quarter turn: its width times the slope at its
/// middle.
#[inline]
fn narrow_arc_width(lo: f64, hi: f64) -> f64 {
    let mid = 0.5 * (lo + hi);
    let u = mid - mid.floor();
    let v = 1.0 - u;
    (hi - lo) / (u * u + v * v)
}

/// Arcs narrower than this (in pseudo-angle, about 1.4°–2.8°) are measured by
/// [`arc_width`] with the slope at their middle (relative error below `w²/8` of the slope's
/// largest second derivative, about `1e-4` here); wider ones from the table.
pub const NARROW_ARC: f64 = 1.0 / 64.0;

/// Intervals of the table of the angle over a quarter turn.
const ANGLE_TABLE_STEPS: usize = 1024;

/// The angle at `ANGLE_TABLE_STEPS + 1` evenly spaced places `u` of the first quarter turn:
/// `atan(u / (1 − u))`, from 0 to `π/2`.
fn quarter_angles() -> &'static [f64] {
    static TABLE: std::sync::OnceLock<Vec<f64>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        (0..=ANGLE_TABLE_STEPS)
            .map(|i| {
                let u = i as f64 / ANGLE_TABLE_STEPS as f64;
                u.atan2(1.0 - u)
            })
            .collect()
    })
}

/// The unwrapped angle of a pseudo-angle, interpolated linearly in [`quarter_angles`]: each
/// quarter turn adds `π/2` (the pseudo-angle is the same function of the place in every
/// quarter). Within `2.5e-7` radians (`h²/8` times the largest second derivative, 2). It is
/// [`angle_of_pseudo`] without that function's `atan2`, for the millions of widths a build
/// measures; anything that needs the angle to the last bit calls `angle_of_pseudo`.
#[inline]
fn unwrapped_angle(phi: f64) -> f64 {
    let quarter = phi.floor();
    let x = (phi - quarter) * ANGLE_TABLE_STEPS as f64;
    let table = quarter_angles();
    let i = (x as usize).min(ANGLE_TABLE_STEPS - 1);
    let (a, b) = (table[i], table[i + 1]);
    quarter * FRAC_PI_2 + a + (b - a) * (x - i as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    proptest! {
        /// The pseudo-angle orders directions as `atan2` does.
        #[test]
        fn pseudo_angle_orders_as_the_angle(
            a in -PI..PI, b in -PI..PI, r in 1e-6f64..1e6, s in 1e-6f64..1e6,
        ) {
            let (pa, pb) = (
                pseudo_angle(r * a.sin(), r * a.cos()),
                pseudo_angle(s * b.sin(), s * b.cos()),
            );
            let (ta, tb) = ((r * a.sin()).atan2(r * a.cos()), (s * b.sin()).atan2(s * b.cos()));
            if ta < tb - 1e-12 {
                prop_assert!(pa < pb, "{ta} {tb}: {pa} {pb}");
            }
            if ta > tb + 1e-12 {
                prop_assert!(pa > pb, "{ta} {tb}: {pa} {pb}");
            }
            prop_assert!(pa > -2.0 && pa <= 2.0);
        }

        /// The estimated width of an arc is within a part in a thousand, narrow (the slope at
        /// the middle) or wide (the table), and within `1e-6` radians when wide (an arc of
        /// 0.05 radians is at least 0.025 in pseudo-angle, above `NARROW_ARC`).
        #[test]
        fn arc_widths_are_close(a in -10.0f64..10.0, w in prop_oneof![1e-9f64..0.05, 0.05f64..6.2]) {
            let got = arc_width(pseudo_of_angle(a), pseudo_of_angle(a + w));
            prop_assert!((got - w).abs() <= 1e-3 * w, "{a} {w}: {got}");
            if w >= 0.05 {
                prop_assert!((got - w).abs() <= 1e-6, "{a} {w}: {got}");
            }
        }

        /// Narrow arcs across the end of a quarter turn (where the slope has a corner) are
        /// measured as closely as those within one.
        #[test]
        fn narrow_arcs_across_a_quarter_turn_are_close(
            quarter in -8i32..8, before in 0.0f64..1.0, w in 1e-9f64..0.015,
        ) {
            let a = f64::from(quarter) * FRAC_PI_2 - before * w;
            let got = arc_width(pseudo_of_angle(a), pseudo_of_angle(a + w));
            prop_assert!((got - w).abs() <= 1e-4 * w, "{a} {w}: {got}");
        }

        /// A pseudo-angle's unit vector is the angle's cosine and sine, in every turn (the
        /// skipping rays' half-planes through the axis are made from it).
        #[test]
        fn directions_of_pseudo_angles_are_the_cosines_and_sines(a in -20.0f64..20.0) {
            let (c, s) = direction_of_pseudo(pseudo_of_angle(a));
            // The pseudo-angle of an angle several turns out carries the rounding of its turns.
            let tol = 4e-16 * a.abs().max(1.0);
            prop_assert!((c - a.cos()).abs() <= tol && (s - a.sin()).abs() <= tol, "{a}: {c} {s}");
            prop_assert!((c.hypot(s) - 1.0).abs() <= 4e-16);
        }

        /// Unwrapped angles keep their order and turns, and come back.
        #[test]
        fn unwrapped_angles_keep_order_and_turns(a in -20.0f64..20.0, d in 1e-9f64..1.0) {
            let (pa, pb) = (pseudo_of_angle(a), pseudo_of_angle(a + d));
            prop_assert!(pa < pb, "{a} {d}: {pa} {pb}");
            prop_assert!((pseudo_of_angle(a + TAU) - (pa + TURN)).abs() < 1e-12);
            prop_assert!((angle_of_pseudo(pa) - a).abs() < 1e-12 * a.abs().max(1.0));
            // The slope is between 1/2 and 1 per radian.
            prop_assert!(pb - pa >= 0.5 * d * (1.0 - 1e-6) - 1e-15 && pb - pa <= d * (1.0 + 1e-6) + 1e-15);
        }
    }

    /// The arc `arc_widths_are_close` once drew, across the quarter turn at `3π`: measured with
    /// one slope it was 0.17 % short.
    #[test]
    fn an_arc_across_a_quarter_turn_found_by_the_proptest() {
        let (a, w) = (9.4216639013351, 0.011841188019231024);
        let got = arc_width(pseudo_of_angle(a), pseudo_of_angle(a + w));
        assert!((got - w).abs() <= 1e-4 * w, "{got}");
    }

    #[test]
    fn the_seam_and_the_axes() {
        assert_eq!(pseudo_angle(-0.0, -1.0), 2.0);
        assert_eq!(pseudo_angle(0.0, 0.0), 0.0);
        assert_eq!(pseudo_angle(-1.0, -1.0), -1.5);
        assert_eq!(pseudo_angle(1.0, -1.0), 1.5);
        assert!((pseudo_of_angle(-PI) - (-2.0)).abs() < 1e-15);
        assert!(pseudo_of_angle(f64::NAN).is_nan());
    }
}
