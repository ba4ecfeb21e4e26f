//! A ray as the renderer casts it ([`Ray`]): its origin and unit direction, the part of it
//! that is rendered (within the mesh's padded box, from the eye on, within the clipping
//! planes, up to the opaque geometry's depth), what is known of the mesh at the two ends of
//! that part, and the boundary faces its line meets where a list was made for it.

use glam::DVec3;

use super::clip::ClipPlanes;
use crate::geometry::bounds::Aabb;

/// What is known of one end of a stretch of a ray between two positions (the ray's ends, or
/// two sample positions): whether the mesh holds it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum End {
    /// A sample found in the mesh, whose segment ends (or starts) at the crossing nearest it.
    Sample,
    /// A position found outside the mesh.
    Outside,
    /// The ray's start or end found in the mesh (no sample there): the piece from it to the
    /// nearest crossing is a chord.
    In,
    /// The ray's start or end, on either side (the eye, a clipping plane, opaque geometry):
    /// where the parity puts it in the mesh, the piece from it to the nearest crossing is a
    /// chord.
    Unknown,
    /// A sample position passed over (by a jump over transparent space), on either side:
    /// where the parity puts it in the mesh it is a sample there (in a transparent cell),
    /// whose segment ends at the nearest crossing.
    Passed,
}

/// A boundary face whose stored box a ray's line meets: the ray's interval in the box and the
/// face's index in the boundary surface's faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct RayFace {
    /// Where the ray's line enters the face's box.
    pub(crate) entry: f64,
    /// Where it leaves it.
    pub(crate) exit: f64,
    /// The face.
    pub(crate) face: u32,
}

/// A ray and the part of it that is rendered.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ray<'f> {
    /// Where it starts (the eye, or a point of the eye's plane).
    pub(crate) origin: DVec3,
    /// Its unit direction.
    pub(crate) dir: DVec3,
    /// The boundary faces whose boxes the ray's line meets, by increasing entry, where a list
    /// was made for it (the surface's queries then scan it instead of the surface's BVH).
    pub(crate) faces: Option<&'f [RayFace]>,
    /// Where the rendered part starts: on the mesh's padded box, at the eye, or on a
    /// clipping plane.
    pub(crate) t_in: f64,
    /// Where it ends: on the box, on a clipping plane, or at the opaque geometry's depth.
    pub(crate) t_out: f64,
    /// What is known of the mesh at `t_in`: outside on the box; either side at the eye or on a
    /// plane.
    pub(crate) start: End,
    /// What is known of the mesh at `t_out`: outside on the box; either side on a plane or at
    /// opaque geometry.
    pub(crate) end: End,
    /// Whether a clipping plane ends it (where that lies in the mesh, the last sample's
    /// segment ends on the plane).
    pub(crate) ends_on_plane: bool,
}

impl<'f> Ray<'f> {
    /// The ray `origin + t dir` rendered within `clip_box` and `t ≥ 0`, then within the
    /// clipping `planes`, then up to `t_stop` (opaque geometry; `+∞` or NaN for none); `None`
    /// where nothing is left.
    pub(crate) fn clipped(
        origin: DVec3,
        dir: DVec3,
        clip_box: &Aabb,
        planes: &ClipPlanes,
        t_stop: f64,
    ) -> Option<Ray<'f>> {
        let in_box = box_span(clip_box, origin, dir)?;
        let (t_in, t_out) = planes.clip_span(origin, dir, in_box)?;
        // Whether a clipping plane moved the ray's start (which may then lie in the mesh) or
        // its end (where, in the mesh, the last sample's segment ends).
        let starts_on_plane = t_in > in_box.0;
        let (t_out, ends_on_plane) = if t_stop.is_nan() || t_stop >= t_out {
            (t_out, t_out < in_box.1)
        } else {
            (t_stop, false)
        };
        // On the mesh's padded box the ends are outside; at the eye, on a clipping plane or
        // at opaque geometry, either side.
        let start = if t_in > 0.0 && !starts_on_plane {
            End::Outside
        } else {
            End::Unknown
        };
        let end = if t_out < in_box.1 {
            End::Unknown
        } else {
            End::Outside
        };
        Some(Ray {
            origin,
            dir,
            faces: None,
            t_in,
            t_out,
            start,
            end,
            ends_on_plane,
        })
    }

    /// The same ray with the list of the boundary faces its line meets.
    pub(crate) fn with_faces(self, faces: Option<&'f [RayFace]>) -> Ray<'f> {
        Ray { faces, ..self }
    }

    /// The whole line `origin + t dir`, rendered over no particular part (for the queries
    /// that take their own interval).
    #[cfg(test)]
    pub(crate) fn line(origin: DVec3, dir: DVec3) -> Ray<'f> {
        Ray {
            origin,
            dir,
            faces: None,
            t_in: f64::NEG_INFINITY,
            t_out: f64::INFINITY,
            start: End::Unknown,
            end: End::Unknown,
            ends_on_plane: false,
        }
    }

    /// The point at `t`.
    #[inline]
    pub(crate) fn at(&self, t: f64) -> DVec3 {
        self.origin + self.dir * t
    }
}

/// The ray's `[t_in, t_out]` within `clip_box` and `t ≥ 0`, if not empty.
pub(crate) fn box_span(clip_box: &Aabb, origin: DVec3, dir: DVec3) -> Option<(f64, f64)> {
    let (mut t_in, mut t_out) = (0.0f64, f64::INFINITY);
    for a in 0..3 {
        let (o, d) = (origin[a], dir[a]);
        let (lo, hi) = (clip_box.min[a], clip_box.max[a]);
        if d == 0.0 {
            // Parallel to this slab: inside it or missing the box.
            if !(o >= lo && o <= hi) {
                return None;
            }
            continue;
        }
        let (t0, t1) = ((lo - o) / d, (hi - o) / d);
        t_in = t_in.max(t0.min(t1));
        t_out = t_out.min(t0.max(t1));
    }
    if !(t_in.is_finite() && t_out.is_finite()) {
        return None;
    }
    (t_in < t_out).then_some((t_in, t_out))
}
