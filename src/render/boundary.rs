//! Boundary-aware sample segments: where a ray enters or leaves the mesh between two samples,
//! the in-mesh length of the boundary sample's segment, and the opacity of a partial segment.
//!
//! A sample at `t_k` stands for `[t_k − step/2, t_k + step/2]`. Where its neighbour sample
//! (before or after) lies outside the mesh, the ray crossed the mesh boundary between the two;
//! the sample then stands for its segment cut at (or extended to) that crossing, so that the
//! in-mesh length of the ray is counted exactly rather than to a step.
//!
//! # Finding the crossing
//! With complete face neighbours the crossing is found exactly: it is the first crossing of a
//! face without a neighbour — each a bilinear patch, the trilinear map's own face, whose
//! crossing by a line is the root of a quadratic
//! ([`crate::geometry::patch::segment_crossings`]). The boundary surface offers the faces
//! whose bounds the segment meets, nearest first
//! ([`super::surface::BoundarySurface::first_face_crossing`]); where one of them cannot be
//! told, the ray is followed from the inside sample's cell across the faces it crosses until
//! it crosses one without a neighbour ([`super::march::boundary_face_crossing`]). On the fast
//! path, where the sample past an exit is proved outside by parity, the crossing of the exit
//! face is already in hand. Where neither can tell (a crossing within `1e-6` of a face's edge, a grazing ray) or without
//! neighbours, the crossing is found by [`BISECTIONS`] bisection steps on exact mesh
//! containment, then refined once by linear interpolation of the violated parametric
//! coordinate of the cell at the inside end of the bracket. Where the refinement does not land
//! inside the bracket, the bracket's midpoint is taken: the crossing is then off by at most
//! `step / 2^(BISECTIONS + 1)`.
//!
//! # Containment without the structure
//! Each bisection point is tested in the cell of the inside end of the bracket first. With
//! complete face neighbours (see [`super::Neighbours`]) a point outside that cell is followed
//! locally: across the face it lies farthest beyond (by the cell's parametric coordinates)
//! that has a neighbour, up to [`super::raycast::MAX_BOUNDARY_WALK`] cells, until a cell
//! holds it — or it lies beyond faces without a neighbour only, i.e. beyond the mesh's
//! boundary, and is outside with no structure look-up. The structure decides where the local
//! search cannot (no neighbours, a degenerate face of a collapsed cell, the budget spent). An
//! "outside" for a point that does not lie between two samples (the ray's start and end, the
//! look-ahead at early termination) is confirmed by parity along the ray from the sample
//! inside where the boundary surface allows it (see the fast path in [`super::raycast`]), by
//! the structure otherwise; so is a point the local search leaves beyond the plane of a
//! boundary face with no parameters (far beyond a thin cell).

use glam::DVec3;

/// Bisection steps of a crossing search.
pub const BISECTIONS: u32 = 6;

/// The opacity of a segment `frac` steps long made of a medium whose opacity over a full
/// step is `alpha_step`: `1 − (1 − α_step)^frac` (exactly `alpha_step` at `frac == 1`).
#[inline]
pub fn partial_opacity(alpha_step: f64, frac: f64) -> f64 {
    if frac == 1.0 {
        alpha_step
    } else if frac <= 0.0 || alpha_step <= 0.0 {
        0.0
    } else if alpha_step >= 1.0 {
        1.0
    } else {
        -(frac * (-alpha_step).ln_1p()).exp_m1()
    }
}

/// How far parametric coordinates `q` lie beyond face `f` (0–5: `u = 0`, `u = 1`, `v = 0`,
/// `v = 1`, `w = 0`, `w = 1`); negative inside.
#[inline]
pub fn face_violation(q: DVec3, f: usize) -> f64 {
    match f {
        0 => -q.x,
        1 => q.x - 1.0,
        2 => -q.y,
        3 => q.y - 1.0,
        4 => -q.z,
        _ => q.z - 1.0,
    }
}

/// The refined crossing between `t_out` (parameters `q_out`, beyond face `f`) and `t_in`
/// (parameters `q_in`, inside): the zero of face `f`'s violation interpolated linearly, if it
/// lies strictly in the bracket.
#[inline]
pub fn interpolate_crossing(
    t_out: f64,
    q_out: DVec3,
    t_in: f64,
    q_in: DVec3,
    f: usize,
) -> Option<f64> {
    let (go, gi) = (face_violation(q_out, f), face_violation(q_in, f));
    if !(go > 0.0 && gi <= 0.0) {
        return None;
    }
    let t = t_out + (t_in - t_out) * (go / (go - gi));
    let (lo, hi) = (t_out.min(t_in), t_out.max(t_in));
    (t.is_finite() && t >= lo && t <= hi).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partial_opacity_composes() {
        let a = 0.3;
        assert_eq!(partial_opacity(a, 1.0), a);
        assert_eq!(partial_opacity(a, 0.0), 0.0);
        // Two halves give one whole.
        let h = partial_opacity(a, 0.5);
        assert!(((1.0 - h) * (1.0 - h) - (1.0 - a)).abs() < 1e-15);
        assert_eq!(partial_opacity(1.0, 0.2), 1.0);
    }

    #[test]
    fn linear_crossing() {
        let t = interpolate_crossing(
            0.0,
            DVec3::new(-0.2, 0.5, 0.5),
            1.0,
            DVec3::new(0.6, 0.5, 0.5),
            0,
        );
        assert!((t.unwrap() - 0.25).abs() < 1e-15);
        assert!(interpolate_crossing(0.0, DVec3::splat(0.5), 1.0, DVec3::splat(0.6), 0).is_none());
    }
}
