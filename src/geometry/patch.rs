//! Bilinear patches, the faces of a trilinear cell: how many times a segment of a line
//! crosses one.
//!
//! A face with corners `a, b, c, e` in cyclic order (as [`crate::mesh::topology::FACES`]
//! lists them) is the patch `P(s, r) = a (1−s)(1−r) + b s (1−r) + c s r + e (1−s) r` on
//! `[0, 1]²`: the trilinear map restricted to that face. A line meets it where two planes
//! through the line both do; each plane cuts the patch along a curve `A s r + B s + C r + D =
//! 0`, and eliminating `r` leaves a quadratic in `s` — at most two crossings, unless the line
//! lies in the patch (a hyperbolic paraboloid holds two families of lines).
//!
//! [`segment_crossings`] answers only where the count is robust: a crossing near an edge of
//! the patch, within a given distance of an end of the segment (measured across the patch), or
//! a line nearly tangent to the patch (two roots close together, or none) gives no answer, for
//! the caller to decide another way.

use glam::DVec3;

/// Parametric distance from the edges of the patch within which a crossing is too close to
/// call inside or outside.
pub const EDGE_BAND: f64 = 1e-6;

/// Where a segment crosses a patch: the crossings' `t`, in increasing order (at most two).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Crossings {
    ts: [f64; 2],
    n: usize,
}

impl Crossings {
    /// How many times the segment crosses the patch.
    pub fn count(&self) -> u32 {
        self.n as u32
    }

    /// The crossings' `t`, in increasing order.
    pub fn ts(&self) -> &[f64] {
        &self.ts[..self.n]
    }

    fn push(&mut self, t: f64) {
        self.ts[self.n] = t;
        self.n += 1;
        if self.n == 2 && self.ts[1] < self.ts[0] {
            self.ts.swap(0, 1);
        }
    }
}

/// Where the segment `o + t d`, `t ∈ (t0, t1)`, crosses the bilinear patch with corners
/// `corners` (cyclic order), or `None` where that cannot be told robustly (see the
/// module documentation): a crossing within [`EDGE_BAND`] of the patch's edges, or one whose
/// distance from either end of the segment, along the patch's normal there, is at most
/// `margin`, is not told.
///
/// ```
/// use cylvol::geometry::patch::segment_crossings;
/// use glam::DVec3;
/// let square = [
///     DVec3::new(0.0, 0.0, 1.0),
///     DVec3::new(1.0, 0.0, 1.0),
///     DVec3::new(1.0, 1.0, 1.0),
///     DVec3::new(0.0, 1.0, 1.0),
/// ];
/// let (o, d) = (DVec3::new(0.3, 0.6, 0.0), DVec3::Z);
/// let crossings = segment_crossings(&square, o, d, 0.0, 2.0, 0.0).unwrap();
/// assert_eq!(crossings.count(), 1);
/// assert!((crossings.ts()[0] - 1.0).abs() < 1e-12);
/// assert_eq!(segment_crossings(&square, o, d, 1.5, 2.0, 0.0).unwrap().count(), 0);
/// // Through an edge, or within the margin of an end: undecided.
/// assert_eq!(segment_crossings(&square, DVec3::new(1.0, 0.6, 0.0), d, 0.0, 2.0, 0.0), None);
/// assert_eq!(segment_crossings(&square, o, d, 0.0, 1.05, 0.1), None);
/// ```
pub fn segment_crossings(
    corners: &[DVec3; 4],
    o: DVec3,
    d: DVec3,
    t0: f64,
    t1: f64,
    margin: f64,
) -> Option<Crossings> {
    let dd = d.length_squared();
    if !(dd > 0.0 && dd.is_finite() && t0.is_finite() && t1.is_finite() && t0 <= t1) {
        return None;
    }
    let [a, b, c, e] = *corners;
    // The patch as a + s eb + r ee + s r etw, relative to a.
    let (eb, ee, etw) = (b - a, e - a, a - b + c - e);
    let size = eb.length().max(ee.length()).max((c - a).length());
    if !(size > 0.0 && size.is_finite()) {
        return None;
    }
    let unit = d / dd.sqrt();
    let (n1, n2) = unit.any_orthonormal_pair();
    let q = a - o;
    // Each plane n·(x − o) = 0 cuts the patch along A s r + B s + C r + D = 0.
    let coeffs = |n: DVec3| [n.dot(etw), n.dot(eb), n.dot(ee), n.dot(q)];
    let [a1, b1, c1, d1] = coeffs(n1);
    let [a2, b2, c2, d2] = coeffs(n2);
    // r = −(B s + D)/(A s + C) from either plane; equal where both hold.
    let alpha = a1 * b2 - a2 * b1;
    let beta = a1 * d2 + c1 * b2 - a2 * d1 - c2 * b1;
    let gamma = c1 * d2 - c2 * d1;
    let scale = alpha.abs() + beta.abs() + gamma.abs();
    if !(scale > 0.0 && scale.is_finite()) {
        // The line lies in the patch, or no answer in floating point.
        return None;
    }
    let roots: [Option<f64>; 2] = if alpha.abs() <= 1e-12 * scale {
        // Nearly linear: one root (the other far off, or none).
        if beta.abs() <= 1e-9 * scale {
            return None;
        }
        [Some(-gamma / beta), None]
    } else {
        let disc = beta * beta - 4.0 * alpha * gamma;
        let tol = 1e-10 * (beta * beta + (4.0 * alpha * gamma).abs());
        if disc.abs() <= tol {
            // Nearly tangent: two roots or none, too close to tell.
            return None;
        }
        if disc < 0.0 {
            [None, None]
        } else {
            // The stable pair: q = −(β + sign(β)√disc)/2, roots q/α and γ/q.
            let sq = disc.sqrt();
            let qq = -0.5 * (beta + beta.signum() * sq);
            [Some(qq / alpha), (qq != 0.0).then(|| gamma / qq)]
        }
    };
    let in_band = |x: f64| x.abs() <= EDGE_BAND || (x - 1.0).abs() <= EDGE_BAND;
    let t_pad = 1e-9 * ((t1 - t0).abs() + size / dd.sqrt());
    let len = dd.sqrt();
    let mut found = Crossings::default();
    for s in roots.into_iter().flatten() {
        if !s.is_finite() {
            return None;
        }
        if in_band(s) {
            return None;
        }
        if !(0.0..=1.0).contains(&s) {
            continue;
        }
        // r from the plane whose denominator is larger.
        let (den1, den2) = (a1 * s + c1, a2 * s + c2);
        let r = if den1.abs() >= den2.abs() {
            -(b1 * s + d1) / den1
        } else {
            -(b2 * s + d2) / den2
        };
        if !r.is_finite() || den1.abs().max(den2.abs()) <= 1e-12 * size {
            return None;
        }
        if in_band(r) {
            return None;
        }
        if !(0.0..=1.0).contains(&r) {
            continue;
        }
        let x = a + eb * s + ee * r + etw * (s * r);
        let t = (x - o).dot(d) / dd;
        // The ends' distances from the crossing along the patch's normal there.
        let normal = (eb + etw * r).cross(ee + etw * s);
        let nn = normal.length();
        if !(nn > 0.0 && nn.is_finite()) {
            return None;
        }
        let across = (normal.dot(d) / (nn * len)).abs() * len;
        let near = |t_end: f64| {
            let dt = (t - t_end).abs();
            dt <= t_pad || dt * across <= margin
        };
        if near(t0) || near(t1) {
            return None;
        }
        if t > t0 && t < t1 {
            found.push(t);
        }
    }
    Some(found)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(p: &[DVec3; 4], s: f64, r: f64) -> DVec3 {
        p[0] * (1.0 - s) * (1.0 - r) + p[1] * s * (1.0 - r) + p[2] * s * r + p[3] * (1.0 - s) * r
    }

    const TWISTED: [DVec3; 4] = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(0.0, 1.0, 1.0),
    ];

    #[test]
    fn a_line_through_two_points_of_a_twisted_patch_crosses_it_twice() {
        let (x, y) = (at(&TWISTED, 0.2, 0.3), at(&TWISTED, 0.8, 0.6));
        let d = y - x;
        assert_eq!(
            segment_crossings(&TWISTED, x - d, d, 0.0, 3.0, 0.0).map(|c| c.count()),
            Some(2)
        );
        // Each end of the segment between them counts one.
        assert_eq!(
            segment_crossings(&TWISTED, x - d, d, 0.0, 1.5, 0.0).map(|c| c.count()),
            Some(1)
        );
        assert_eq!(
            segment_crossings(&TWISTED, x - d, d, 1.5, 3.0, 0.0).map(|c| c.count()),
            Some(1)
        );
        assert_eq!(
            segment_crossings(&TWISTED, x - d, d, 1.2, 1.8, 0.0).map(|c| c.count()),
            Some(0)
        );
        // A segment ending on a crossing is undecided.
        assert_eq!(segment_crossings(&TWISTED, x - d, d, 0.0, 1.0, 0.0), None);
    }

    #[test]
    fn a_line_through_the_extension_only_misses() {
        // Points of the extended patch outside [0, 1]²: no crossing.
        let (x, y) = (at(&TWISTED, 1.4, 0.3), at(&TWISTED, -0.5, 0.6));
        let d = y - x;
        assert_eq!(
            segment_crossings(&TWISTED, x - d, d, 0.0, 3.0, 0.0).map(|c| c.count()),
            Some(0)
        );
        // One inside, one outside: one crossing.
        let (x, y) = (at(&TWISTED, 0.4, 0.3), at(&TWISTED, -0.5, 0.6));
        let d = y - x;
        assert_eq!(
            segment_crossings(&TWISTED, x - d, d, 0.0, 3.0, 0.0).map(|c| c.count()),
            Some(1)
        );
    }

    #[test]
    fn a_line_in_the_patch_or_degenerate_input_is_undecided() {
        // The ruling s = 0.5 lies in the patch.
        let (x, y) = (at(&TWISTED, 0.5, 0.0), at(&TWISTED, 0.5, 1.0));
        assert_eq!(segment_crossings(&TWISTED, x, y - x, -1.0, 2.0, 0.0), None);
        assert_eq!(
            segment_crossings(&TWISTED, x, DVec3::ZERO, 0.0, 1.0, 0.0),
            None
        );
        assert_eq!(
            segment_crossings(&TWISTED, x, DVec3::X, 0.0, f64::NAN, 0.0),
            None
        );
        assert_eq!(
            segment_crossings(&[DVec3::ONE; 4], x, DVec3::X, 0.0, 1.0, 0.0),
            None
        );
    }

    #[test]
    fn far_from_the_origin_the_count_holds() {
        let shift = DVec3::splat(1e6);
        let small = TWISTED.map(|p| p * 1e-3 + shift);
        let (x, y) = (at(&small, 0.2, 0.3), at(&small, 0.7, 0.9));
        let d = (y - x).normalize();
        let o = x - d * 1e3;
        let len = (y - x).length();
        assert_eq!(
            segment_crossings(&small, o, d, 0.0, 1e3 + 2.0 * len, 1e-9).map(|c| c.count()),
            Some(2)
        );
        assert_eq!(
            segment_crossings(&small, o, d, 0.0, 1e3 + 0.5 * len, 1e-9).map(|c| c.count()),
            Some(1)
        );
    }
}
