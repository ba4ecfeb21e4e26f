//! Clipping planes, as VTK's mappers take them (`vtkAbstractMapper::AddClippingPlane`): each
//! plane keeps the half-space its normal points into, and a ray is rendered only over the part
//! of it that every plane keeps.
//!
//! A plane is held as its equation `(a, b, c, d)`: the points with `a x + b y + c z + d ≥ 0`
//! are kept, which is what `vtkAbstractMapper3D::GetClippingPlaneInDataCoords` gives for a
//! `vtkPlane` with normal `(a, b, c)` (and the OpenGL mappers' convention). At most
//! [`MAX_CLIP_PLANES`] planes, as VTK's OpenGL mappers allow; the set is `Copy`, so that
//! [`super::RenderOptions`] stays plain data (and the C ABI a fixed-size struct).
//!
//! A clipped ray starts or ends on a plane: where that lies in the mesh, the volume ends there
//! as it would at the mesh's boundary (the ray caster cuts its first or last sample's segment at
//! the plane, see [`super::raycast`]).

use glam::DVec3;

use crate::accel::bvh::ray::clip_to_slab;
use crate::error::show_number;
use crate::Error;

/// The most clipping planes a render takes (VTK's OpenGL mappers take six).
pub const MAX_CLIP_PLANES: usize = 6;

/// Up to [`MAX_CLIP_PLANES`] clipping planes; none by default.
///
/// ```
/// use cylvol::render::ClipPlanes;
/// use glam::DVec3;
/// // Keep x ≥ 1 (the normal points into the kept side).
/// let planes = ClipPlanes::new(&[[1.0, 0.0, 0.0, -1.0]]).unwrap();
/// assert!(planes.keeps(DVec3::new(2.0, 0.0, 0.0)));
/// assert!(!planes.keeps(DVec3::new(0.5, 0.0, 0.0)));
/// // A ray along x from the origin is kept from t = 1 on.
/// assert_eq!(planes.clip_span(DVec3::ZERO, DVec3::X, (0.0, 5.0)), Some((1.0, 5.0)));
/// assert!(ClipPlanes::new(&[[0.0, 0.0, 0.0, 1.0]]).is_err()); // no normal
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClipPlanes {
    planes: [[f64; 4]; MAX_CLIP_PLANES],
    count: usize,
}

impl ClipPlanes {
    /// No plane: nothing is clipped.
    pub const NONE: ClipPlanes = ClipPlanes {
        planes: [[0.0; 4]; MAX_CLIP_PLANES],
        count: 0,
    };

    /// The planes `a x + b y + c z + d ≥ 0` (each `[a, b, c, d]`). An error names the first
    /// plane that is not finite or has no normal (`a = b = c = 0`), or more than
    /// [`MAX_CLIP_PLANES`] planes.
    pub fn new(equations: &[[f64; 4]]) -> Result<ClipPlanes, Error> {
        if equations.len() > MAX_CLIP_PLANES {
            return Err(Error::Invalid(format!(
                "{} clipping planes (at most {MAX_CLIP_PLANES})",
                equations.len()
            )));
        }
        let mut planes = ClipPlanes::NONE;
        for (i, e) in equations.iter().enumerate() {
            if !e.iter().all(|v| v.is_finite()) {
                return Err(Error::Invalid(format!(
                    "clipping plane {i}: {} is not finite",
                    show_plane(e)
                )));
            }
            if e[..3].iter().all(|&v| v == 0.0) {
                return Err(Error::Invalid(format!(
                    "clipping plane {i}: {} has no normal",
                    show_plane(e)
                )));
            }
            planes.planes[i] = *e;
        }
        planes.count = equations.len();
        Ok(planes)
    }

    /// The plane through `point` whose `normal` points into the kept side (a `vtkPlane`'s
    /// origin and normal), as an equation for [`ClipPlanes::new`].
    ///
    /// ```
    /// use cylvol::render::ClipPlanes;
    /// use glam::DVec3;
    /// let e = ClipPlanes::equation(DVec3::new(0.0, 0.0, 2.0), DVec3::new(0.0, 0.0, -1.0));
    /// assert_eq!(e, [0.0, 0.0, -1.0, 2.0]); // keeps z ≤ 2
    /// ```
    pub fn equation(point: DVec3, normal: DVec3) -> [f64; 4] {
        [normal.x, normal.y, normal.z, -normal.dot(point)]
    }

    /// The planes' equations.
    pub fn equations(&self) -> &[[f64; 4]] {
        &self.planes[..self.count]
    }

    /// Whether there is no plane.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Whether every plane keeps `p`.
    pub fn keeps(&self, p: DVec3) -> bool {
        self.equations().iter().all(|e| value(e, p) >= 0.0)
    }

    /// The part of the span `(t0, t1)` of the ray `o + t d` that every plane keeps, `None` if
    /// it is empty. A ray parallel to a plane is kept whole where its origin is kept and not at
    /// all otherwise.
    pub fn clip_span(&self, o: DVec3, d: DVec3, span: (f64, f64)) -> Option<(f64, f64)> {
        // Along the ray a plane's value is `value(o) + t n·d`: the kept half-space is the slab
        // `[0, +∞)` of that value, clipped as the BVH's ray queries clip a box's slabs.
        let span = self.equations().iter().fold(span, |span, e| {
            let rate = e[0] * d.x + e[1] * d.y + e[2] * d.z;
            clip_to_slab(value(e, o), 1.0 / (rate + 0.0), 0.0, f64::INFINITY, span)
        });
        (span.0 < span.1).then_some(span)
    }
}

/// The plane's function `a x + b y + c z + d` at `p`.
fn value(e: &[f64; 4], p: DVec3) -> f64 {
    e[0] * p.x + e[1] * p.y + e[2] * p.z + e[3]
}

/// A plane's `[a, b, c, d]` as a message shows it.
fn show_plane(e: &[f64; 4]) -> String {
    format!("[{}]", e.map(show_number).join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slab_between_two_planes() {
        // Keep 1 ≤ z ≤ 3.
        let planes = ClipPlanes::new(&[
            ClipPlanes::equation(DVec3::new(0.0, 0.0, 1.0), DVec3::Z),
            ClipPlanes::equation(DVec3::new(0.0, 0.0, 3.0), -DVec3::Z),
        ])
        .unwrap();
        assert_eq!(planes.equations().len(), 2);
        let o = DVec3::new(0.3, -0.2, 0.0);
        assert_eq!(planes.clip_span(o, DVec3::Z, (0.0, 10.0)), Some((1.0, 3.0)));
        // Backwards along z: kept between t = -3 and -1, not for t ≥ 0.
        assert_eq!(planes.clip_span(o, -DVec3::Z, (0.0, 10.0)), None);
        // A slanted ray: z = t / 2 is kept for t in [2, 6].
        let d = DVec3::new(3f64.sqrt() / 2.0, 0.0, 0.5);
        let (a, b) = planes.clip_span(o, d, (0.0, 100.0)).unwrap();
        assert!(
            (a - 2.0).abs() < 1e-12 && (b - 6.0).abs() < 1e-12,
            "{a} {b}"
        );
        // Parallel to the planes: whole inside the slab, nothing outside it.
        let inside = DVec3::new(0.0, 0.0, 2.0);
        assert_eq!(
            planes.clip_span(inside, DVec3::X, (0.5, 4.0)),
            Some((0.5, 4.0))
        );
        assert_eq!(planes.clip_span(o, DVec3::X, (0.5, 4.0)), None);
        assert!(planes.keeps(inside) && !planes.keeps(o));
    }

    #[test]
    fn no_plane_keeps_everything() {
        let none = ClipPlanes::default();
        assert!(none.is_empty() && none == ClipPlanes::NONE);
        assert_eq!(
            none.clip_span(DVec3::ONE, DVec3::X, (0.0, 1.0)),
            Some((0.0, 1.0))
        );
        assert_eq!(none.clip_span(DVec3::ONE, DVec3::X, (1.0, 1.0)), None);
    }

    #[test]
    fn bad_planes_are_refused_by_name() {
        let msg = |e: &[[f64; 4]]| ClipPlanes::new(e).unwrap_err().to_string();
        assert!(msg(&[[1.0, 0.0, 0.0, 0.0], [0.0, f64::NAN, 1.0, 0.0]])
            .starts_with("clipping plane 1:"));
        assert!(msg(&[[0.0, 0.0, 0.0, 1.0]]).contains("no normal"));
        assert!(msg(&[[0.0, 0.0, 1.0, f64::INFINITY]]).contains("not finite"));
        assert!(msg(&[[1.0, 0.0, 0.0, 0.0]; 7]).contains("at most 6"));
        assert!(ClipPlanes::new(&[[1.0, 0.0, 0.0, 0.0]; 6]).is_ok());
    }
}
