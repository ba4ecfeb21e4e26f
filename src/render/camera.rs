//! The camera: perspective or parallel projection from an eye, a focal point, a view-up vector
//! and a view angle (or parallel scale), with VTK's conventions, and the rays through pixels.
//!
//! # Conventions (those of `vtkCamera` and `vtkRenderer::ResetCamera`)
//! - `view_angle` is the **vertical full angle** in degrees (VTK's default 30).
//! - `parallel_scale` is **half the viewport height** in world units.
//! - The default camera ([`Camera::reset`]) looks at the centre of the bounds from `+z`
//!   (direction of projection `−z`, view-up `+y`, VTK's initial camera) from the distance at
//!   which the bounding sphere fits the view: `radius / sin(angle / 2)` with `radius` half the
//!   bounds' diagonal (`1` for a point); for a window taller than wide the horizontal angle is
//!   the one that must hold the sphere, as `ResetCamera` does. Its parallel scale is `radius`
//!   (divided by the aspect for a tall window).
//! - [`Camera::azimuth`] rotates the eye about the view-up through the focal point;
//!   [`Camera::elevation`] about `view_plane_normal × view_up` (VTK's axis: the negated first
//!   row of the view transform), then re-orthogonalises the view-up (VTK's
//!   `OrthogonalizeViewUp`); [`Camera::zoom`] divides the view angle (perspective; VTK does the
//!   same through the tangent-free `ViewAngle / factor`) or the parallel scale.
//!
//! # Rays
//! Pixel `(i, j)` (row `j = 0` at the top) is sampled at its centre. A perspective ray leaves
//! the eye with a unit direction; a parallel ray leaves the eye's plane (the plane through the
//! eye normal to the direction of projection) along the direction of projection. The ray
//! parameter `t` is therefore a distance in world units from the eye (its plane).
//!
//! # Rays from matrices
//! [`MatrixRays`] makes the rays of a view matrix and a projection matrix (OpenGL's clip
//! space, as `vtkCamera` gives them, any model matrix folded into the view): the ray of a pixel
//! runs from its centre on the near plane (NDC `z = −1`) towards its centre on the far plane
//! (NDC `z = +1`), both unprojected through `(projection · view)⁻¹`, so perspective and parallel
//! projections are read from the matrix. Its `t` is the distance from the near plane's point;
//! [`MatrixRays::window_depth`] and [`MatrixRays::distance_at_depth`] convert between `t` and
//! the window depth `(z_ndc + 1)/2` of the z-buffer. Both generators implement [`RaySource`],
//! which [`crate::render::Renderer::render_rays`] renders.

use glam::{DMat4, DQuat, DVec3, DVec4};

use crate::error::{show_number, show_vector};
use crate::Error;

/// Perspective or parallel projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// A pinhole at the eye; the value is the vertical full view angle in degrees.
    Perspective(f64),
    /// Parallel rays; the value is half the viewport height in world units.
    Parallel(f64),
}

/// A camera in VTK's terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Where the camera is (VTK's `Position`).
    pub eye: DVec3,
    /// The point it looks at.
    pub focal: DVec3,
    /// The view-up vector (need not be unit or orthogonal to the view direction).
    pub up: DVec3,
    /// The projection and its view angle or parallel scale.
    pub projection: Projection,
}

/// VTK's default view angle in degrees.
pub const DEFAULT_VIEW_ANGLE: f64 = 30.0;

/// The orthonormal frame of a camera: direction of projection, right and up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraFrame {
    /// Unit direction of projection (from the eye to the focal point).
    pub forward: DVec3,
    /// Unit right vector (`forward × up`).
    pub right: DVec3,
    /// Unit up vector, orthogonal to both.
    pub up: DVec3,
}

impl Camera {
    /// A perspective camera; fails on a degenerate frame (eye on the focal point, up parallel
    /// to the view direction, non-finite values) or an angle outside `(0, 180)`.
    ///
    /// ```
    /// use cylvol::render::Camera;
    /// use glam::DVec3;
    /// let c = Camera::perspective(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y, 30.0).unwrap();
    /// assert_eq!(c.frame().unwrap().forward, -DVec3::Z);
    /// ```
    pub fn perspective(
        eye: DVec3,
        focal: DVec3,
        up: DVec3,
        view_angle: f64,
    ) -> Result<Camera, Error> {
        let c = Camera {
            eye,
            focal,
            up,
            projection: Projection::Perspective(view_angle),
        };
        c.check()?;
        Ok(c)
    }

    /// A parallel camera with the given half viewport height in world units.
    pub fn parallel(
        eye: DVec3,
        focal: DVec3,
        up: DVec3,
        parallel_scale: f64,
    ) -> Result<Camera, Error> {
        let c = Camera {
            eye,
            focal,
            up,
            projection: Projection::Parallel(parallel_scale),
        };
        c.check()?;
        Ok(c)
    }

    fn check(&self) -> Result<(), Error> {
        let ok_projection = match self.projection {
            Projection::Perspective(a) => a > 0.0 && a < 180.0,
            Projection::Parallel(s) => s > 0.0 && s.is_finite(),
        };
        if !ok_projection {
            return Err(Error::Invalid(match self.projection {
                Projection::Perspective(a) => format!(
                    "bad camera view angle {} (must be in (0, 180) degrees)",
                    show_number(a)
                ),
                Projection::Parallel(s) => format!(
                    "bad camera parallel scale {} (must be positive and finite)",
                    show_number(s)
                ),
            }));
        }
        self.frame().map(|_| ())
    }

    /// The camera's orthonormal frame, or an error when it is degenerate.
    pub fn frame(&self) -> Result<CameraFrame, Error> {
        let forward = (self.focal - self.eye).normalize_or_zero();
        let right = forward.cross(self.up).normalize_or_zero();
        if !(forward.is_finite() && right.is_finite())
            || forward == DVec3::ZERO
            || right == DVec3::ZERO
        {
            return Err(Error::Invalid(format!(
                "degenerate camera: eye {}, focal point {}, view-up {}",
                show_vector(self.eye.to_array()),
                show_vector(self.focal.to_array()),
                show_vector(self.up.to_array())
            )));
        }
        Ok(CameraFrame {
            forward,
            right,
            up: right.cross(forward),
        })
    }

    /// VTK's `ResetCamera` for the default camera (looking down `−z`, up `+y`, view angle 30°):
    /// focal point at the centre of `bounds` (`[xmin, xmax, ymin, ymax, zmin, zmax]`), distance
    /// such that the bounding sphere fits a `width × height` window. `parallel` picks the
    /// projection (parallel scale = the sphere's radius, divided by the aspect when tall).
    pub fn reset(bounds: [f64; 6], width: u32, height: u32, parallel: bool) -> Camera {
        let lo = DVec3::new(bounds[0], bounds[2], bounds[4]);
        let hi = DVec3::new(bounds[1], bounds[3], bounds[5]);
        let centre = (lo + hi) * 0.5;
        let diag = (hi - lo).length();
        let radius = if diag > 0.0 && diag.is_finite() {
            diag * 0.5
        } else {
            1.0
        };
        let aspect = width.max(1) as f64 / height.max(1) as f64;
        let mut angle = DEFAULT_VIEW_ANGLE.to_radians();
        let mut scale = radius;
        if aspect < 1.0 {
            angle = 2.0 * ((angle * 0.5).tan() * aspect).atan();
            scale /= aspect;
        }
        let distance = radius / (angle * 0.5).sin();
        Camera {
            eye: centre + DVec3::Z * distance,
            focal: centre,
            up: DVec3::Y,
            projection: if parallel {
                Projection::Parallel(scale)
            } else {
                Projection::Perspective(DEFAULT_VIEW_ANGLE)
            },
        }
    }

    /// The `--view AZIMUTH,ELEVATION,ZOOM` preset: [`Camera::reset`], then
    /// [`Camera::azimuth`], [`Camera::elevation`] and [`Camera::zoom`] in that order.
    pub fn view(
        bounds: [f64; 6],
        width: u32,
        height: u32,
        azimuth: f64,
        elevation: f64,
        zoom: f64,
    ) -> Camera {
        Camera::reset(bounds, width, height, false).turned(azimuth, elevation, zoom)
    }

    /// The camera moved as the `--view` preset moves the reset one: [`Camera::azimuth`], then
    /// [`Camera::elevation`] and [`Camera::zoom`].
    ///
    /// ```
    /// use cylvol::render::{Camera, Projection};
    /// let bounds = [0.0, 1.0, 0.0, 1.0, 0.0, 1.0];
    /// let c = Camera::reset(bounds, 64, 64, true).turned(90.0, 0.0, 2.0);
    /// let Projection::Parallel(scale) = c.projection else { unreachable!() };
    /// assert!((scale - 3f64.sqrt() / 4.0).abs() < 1e-12);
    /// assert!((c.eye.x - c.focal.x) > 0.0 && (c.eye.z - c.focal.z).abs() < 1e-9);
    /// ```
    pub fn turned(mut self, azimuth: f64, elevation: f64, zoom: f64) -> Camera {
        self.azimuth(azimuth);
        self.elevation(elevation);
        self.zoom(zoom);
        self
    }

    /// Rotates the eye about the view-up vector through the focal point by `degrees`.
    pub fn azimuth(&mut self, degrees: f64) {
        let axis = self.up.normalize_or_zero();
        if axis == DVec3::ZERO || !degrees.is_finite() {
            return;
        }
        let q = DQuat::from_axis_angle(axis, degrees.to_radians());
        self.eye = self.focal + q * (self.eye - self.focal);
    }

    /// Rotates the eye about `view_plane_normal × view_up` through the focal point by
    /// `degrees` (positive moves the eye up), rotating the view-up with it.
    pub fn elevation(&mut self, degrees: f64) {
        let vpn = (self.eye - self.focal).normalize_or_zero();
        let axis = vpn.cross(self.up).normalize_or_zero();
        if axis == DVec3::ZERO || !degrees.is_finite() {
            return;
        }
        let q = DQuat::from_axis_angle(axis, degrees.to_radians());
        self.eye = self.focal + q * (self.eye - self.focal);
        // The rotated up is the old up orthogonalised against the new view plane normal.
        let up = q * self.up;
        let new_vpn = (self.eye - self.focal).normalize_or_zero();
        self.up = (up - new_vpn * up.dot(new_vpn)).normalize_or_zero();
    }

    /// Divides the view angle (perspective) or the parallel scale by `factor` (> 1 zooms in).
    pub fn zoom(&mut self, factor: f64) {
        if !(factor > 0.0 && factor.is_finite()) {
            return;
        }
        self.projection = match self.projection {
            Projection::Perspective(a) => Projection::Perspective(a / factor),
            Projection::Parallel(s) => Projection::Parallel(s / factor),
        };
    }
}

/// Generates the rays of a `width × height` image for a camera.
#[derive(Clone, Copy, Debug)]
pub struct RayGenerator {
    eye: DVec3,
    frame: CameraFrame,
    parallel: bool,
    /// Half extents of the image plane at unit distance (perspective) or in world units.
    half_w: f64,
    half_h: f64,
    width: u32,
    height: u32,
}

impl RayGenerator {
    /// Prepares ray generation; fails for a degenerate camera or an empty image.
    pub fn new(camera: &Camera, width: u32, height: u32) -> Result<RayGenerator, Error> {
        camera.check()?;
        if width == 0 || height == 0 {
            return Err(Error::Invalid(format!("empty image {width}x{height}")));
        }
        let frame = camera.frame()?;
        let aspect = width as f64 / height as f64;
        let (parallel, half_h) = match camera.projection {
            Projection::Perspective(a) => (false, (a.to_radians() * 0.5).tan()),
            Projection::Parallel(s) => (true, s),
        };
        Ok(RayGenerator {
            eye: camera.eye,
            frame,
            parallel,
            half_w: half_h * aspect,
            half_h,
            width,
            height,
        })
    }

    /// The ray through the centre of pixel `(i, j)` (row 0 at the top): origin and unit
    /// direction.
    #[inline]
    pub fn ray(&self, i: u32, j: u32) -> (DVec3, DVec3) {
        let x = ((i as f64 + 0.5) / self.width as f64) * 2.0 - 1.0;
        let y = 1.0 - ((j as f64 + 0.5) / self.height as f64) * 2.0;
        let f = &self.frame;
        if self.parallel {
            (
                self.eye + f.right * (x * self.half_w) + f.up * (y * self.half_h),
                f.forward,
            )
        } else {
            let d = f.forward + f.right * (x * self.half_w) + f.up * (y * self.half_h);
            (self.eye, d.normalize())
        }
    }
}

/// Anything that gives the ray of each pixel of an image: its size and, for pixel `(i, j)`
/// (row 0 at the top), an origin and a unit direction.
pub trait RaySource: Sync {
    /// The image size `(width, height)` the rays are for.
    fn size(&self) -> (u32, u32);
    /// The ray through the centre of pixel `(i, j)`: origin and unit direction.
    fn ray(&self, i: u32, j: u32) -> (DVec3, DVec3);

    /// Where `p` lies in the image, in pixels (the centre of pixel `(i, j)` at `(i, j)`), for
    /// a projection by which every point of the ray of a pixel (at `t ≥ 0`) projects to that
    /// pixel's centre and the image of a segment is a segment; `None` for a point that cannot
    /// be projected so (at or behind a perspective eye) or rays with no such projection (the
    /// default). [`crate::render::ray_faces`] sorts the boundary faces to the image with it.
    fn project(&self, _p: DVec3) -> Option<(f64, f64)> {
        None
    }

    /// The bounds `(min, max)`, in pixels as [`RaySource::project`] gives them, of the
    /// projections of the eight corners of the box `lo`–`hi` (which hold the projection of
    /// the whole box); `None` where a corner cannot be projected.
    fn project_box(&self, lo: DVec3, hi: DVec3) -> Option<([f64; 2], [f64; 2])> {
        let (mut a, mut b) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for k in 0..8 {
            let (i, j) = self.project(box_corner(lo, hi, k))?;
            a = [a[0].min(i), a[1].min(j)];
            b = [b[0].max(i), b[1].max(j)];
        }
        Some((a, b))
    }
}

/// Corner `k` (0–7: bit 0 x, bit 1 y, bit 2 z at `hi`) of the box `lo`–`hi`.
#[inline]
fn box_corner(lo: DVec3, hi: DVec3, k: usize) -> DVec3 {
    DVec3::new(
        if k & 1 == 0 { lo.x } else { hi.x },
        if k & 2 == 0 { lo.y } else { hi.y },
        if k & 4 == 0 { lo.z } else { hi.z },
    )
}

/// [`RaySource::project_box`] for a projection to NDC `(X(p) / W(p), Y(p) / W(p))`, `X`, `Y`
/// and `W` affine (`rows`: each the gradient and the constant, `r · (p, 1)`), points with
/// `W ≤ 0` unprojectable: the corners' values from one corner and the three edges, with no
/// product per corner.
fn project_box_affine(
    rows: [DVec4; 3],
    (lo, hi): (DVec3, DVec3),
    width: u32,
    height: u32,
) -> Option<([f64; 2], [f64; 2])> {
    let at = |p: DVec4| DVec3::new(rows[0].dot(p), rows[1].dot(p), rows[2].dot(p));
    let base = at(lo.extend(1.0));
    let e = hi - lo;
    let edges = [
        at(DVec4::new(e.x, 0.0, 0.0, 0.0)),
        at(DVec4::new(0.0, e.y, 0.0, 0.0)),
        at(DVec4::new(0.0, 0.0, e.z, 0.0)),
    ];
    let (mut x, mut y) = (
        [f64::INFINITY, f64::NEG_INFINITY],
        [f64::INFINITY, f64::NEG_INFINITY],
    );
    for k in 0..8 {
        let mut v = base;
        for (bit, edge) in edges.iter().enumerate() {
            if k & (1 << bit) != 0 {
                v += *edge;
            }
        }
        if v.z.is_nan() || v.z <= 0.0 {
            return None;
        }
        let (nx, ny) = (v.x / v.z, v.y / v.z);
        x = [x[0].min(nx), x[1].max(nx)];
        y = [y[0].min(ny), y[1].max(ny)];
    }
    // Pixel columns grow with x, rows fall with y.
    let (i0, j1) = ndc_to_pixel(x[0], y[0], width, height)?;
    let (i1, j0) = ndc_to_pixel(x[1], y[1], width, height)?;
    Some(([i0, j0], [i1, j1]))
}

/// Pixel coordinates (the centre of pixel `(i, j)` at `(i, j)`, row 0 at the top) of the
/// normalized device coordinates `(x, y)` of a `width × height` image: the inverse of the
/// pixel centres' NDC that both ray sources use.
fn ndc_to_pixel(x: f64, y: f64, width: u32, height: u32) -> Option<(f64, f64)> {
    let i = (x + 1.0) * 0.5 * width as f64 - 0.5;
    let j = (1.0 - y) * 0.5 * height as f64 - 0.5;
    (i.is_finite() && j.is_finite()).then_some((i, j))
}

impl RaySource for RayGenerator {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    #[inline]
    fn ray(&self, i: u32, j: u32) -> (DVec3, DVec3) {
        RayGenerator::ray(self, i, j)
    }

    fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        let rel = p - self.eye;
        let f = &self.frame;
        let (x, y) = if self.parallel {
            (rel.dot(f.right) / self.half_w, rel.dot(f.up) / self.half_h)
        } else {
            let z = rel.dot(f.forward);
            if z.is_nan() || z <= 0.0 {
                return None;
            }
            (
                rel.dot(f.right) / (z * self.half_w),
                rel.dot(f.up) / (z * self.half_h),
            )
        };
        ndc_to_pixel(x, y, self.width, self.height)
    }

    fn project_box(&self, lo: DVec3, hi: DVec3) -> Option<([f64; 2], [f64; 2])> {
        let f = &self.frame;
        let row = |v: DVec3, scale: f64| (v / scale).extend(-(v / scale).dot(self.eye));
        let w = if self.parallel {
            DVec4::W
        } else {
            row(f.forward, 1.0)
        };
        let rows = [row(f.right, self.half_w), row(f.up, self.half_h), w];
        project_box_affine(rows, (lo, hi), self.width, self.height)
    }
}

/// `projection` (row-major, OpenGL conventions) narrowed to the rows `[r0, r1)` of a
/// `height`-row image counted from the bottom: NDC `y` of the band mapped onto `[-1, 1]`, so
/// that [`MatrixRays`] of the band (`r1 - r0` rows) are exactly the full image's rays of those
/// rows. vtkCylVolMapper renders a frame in such bands.
///
/// ```
/// use cylvol::render::{band_projection, MatrixRays, RaySource};
/// let view = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, -5.0, 0.0, 0.0, 0.0, 1.0];
/// // A perspective with near 1 and far 10.
/// let (a, b) = (-11.0 / 9.0, -20.0 / 9.0);
/// let proj = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, a, b, 0.0, 0.0, -1.0, 0.0];
/// let whole = MatrixRays::new(&view, &proj, 8, 8).unwrap();
/// let band = MatrixRays::new(&view, &band_projection(&proj, 2, 4, 8), 8, 2).unwrap();
/// // Rows 2 and 3 from the bottom are rows 5 and 4 from the top, the band's rows 1 and 0.
/// let ((o, d), (o2, d2)) = (whole.ray(3, 4), band.ray(3, 0));
/// assert!((o - o2).length() < 1e-12 && (d - d2).length() < 1e-12);
/// ```
pub fn band_projection(projection: &[f64; 16], r0: u32, r1: u32, height: u32) -> [f64; 16] {
    let lo = -1.0 + 2.0 * f64::from(r0) / f64::from(height);
    let hi = -1.0 + 2.0 * f64::from(r1) / f64::from(height);
    let (scale, centre) = (2.0 / (hi - lo), 0.5 * (lo + hi));
    let mut band = *projection;
    for k in 0..4 {
        band[4 + k] = scale * (projection[4 + k] - centre * projection[12 + k]);
    }
    band
}

/// The rays of a view and a projection matrix (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct MatrixRays {
    /// `projection · view`: world to clip space.
    clip: DMat4,
    /// Its inverse: clip space to world.
    unproject: DMat4,
    width: u32,
    height: u32,
}

impl MatrixRays {
    /// Rays for a `width × height` image from `view` (world to eye; any model matrix folded
    /// in) and `projection` (eye to clip space, OpenGL conventions). Both are row-major
    /// (`m[4 r + c]`, as `vtkMatrix4x4::DeepCopy(double[16])` gives them). Fails on non-finite
    /// entries, a singular `projection · view`, or an empty image.
    ///
    /// ```
    /// use cylvol::render::{MatrixRays, RaySource};
    /// let identity = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    /// // Identity matrices: clip space is world space, the near plane z = −1, the far z = +1.
    /// let rays = MatrixRays::new(&identity, &identity, 1, 1).unwrap();
    /// let (o, d) = rays.ray(0, 0);
    /// assert_eq!((o.to_array(), d.to_array()), ([0.0, 0.0, -1.0], [0.0, 0.0, 1.0]));
    /// ```
    pub fn new(
        view: &[f64; 16],
        projection: &[f64; 16],
        width: u32,
        height: u32,
    ) -> Result<MatrixRays, Error> {
        if width == 0 || height == 0 {
            return Err(Error::Invalid(format!("empty image {width}x{height}")));
        }
        if !view.iter().chain(projection).all(|v| v.is_finite()) {
            return Err(Error::Invalid(
                "the view or projection matrix has a non-finite entry".into(),
            ));
        }
        let row_major = |m: &[f64; 16]| DMat4::from_cols_array(m).transpose();
        let clip = row_major(projection) * row_major(view);
        let unproject = clip.inverse();
        let det = clip.determinant();
        if det == 0.0 || !det.is_finite() || !unproject.is_finite() {
            return Err(Error::Invalid(
                "projection · view is singular: no rays can be made from it".into(),
            ));
        }
        let rays = MatrixRays {
            clip,
            unproject,
            width,
            height,
        };
        // Every pixel's near and far points must be proper points: their homogeneous w is
        // linear in the pixel centre's (x, y), so w of one sign at the four corner pixels
        // means w of that sign at every pixel.
        let corners = [
            (0, 0),
            (width - 1, 0),
            (0, height - 1),
            (width - 1, height - 1),
        ];
        for z in [-1.0, 1.0] {
            let w: Vec<f64> = corners
                .iter()
                .map(|&(i, j)| {
                    let (x, y) = rays.ndc(i, j);
                    (rays.unproject * DVec4::new(x, y, z, 1.0)).w
                })
                .collect();
            if !(w.iter().all(|&w| w > 0.0) || w.iter().all(|&w| w < 0.0)) {
                return Err(Error::Invalid(
                    "the matrices put a pixel's near or far point at infinity".into(),
                ));
            }
        }
        for (i, j) in corners {
            let (o, d) = rays.ray(i, j);
            if !(o.is_finite() && d.is_finite() && d != DVec3::ZERO) {
                return Err(Error::Invalid(format!(
                    "the matrices give no ray at pixel ({i}, {j}) (a near or far point at infinity)"
                )));
            }
        }
        Ok(rays)
    }

    /// The NDC `(x, y)` of the centre of pixel `(i, j)` (row 0 at the top).
    #[inline]
    fn ndc(&self, i: u32, j: u32) -> (f64, f64) {
        (
            (i as f64 + 0.5) / self.width as f64 * 2.0 - 1.0,
            1.0 - (j as f64 + 0.5) / self.height as f64 * 2.0,
        )
    }

    /// The world point with NDC `(x, y, z)`.
    #[inline]
    fn point(&self, x: f64, y: f64, z: f64) -> DVec3 {
        let h = self.unproject * DVec4::new(x, y, z, 1.0);
        h.truncate() / h.w
    }

    /// The window depth `(z_ndc + 1)/2` of the point at distance `t` along the ray of pixel
    /// `(i, j)` (`1` for `t = +∞`).
    pub fn window_depth(&self, i: u32, j: u32, t: f64) -> f64 {
        if t == f64::INFINITY {
            return 1.0;
        }
        let (o, d) = self.ray(i, j);
        let c = self.clip * (o + d * t).extend(1.0);
        (c.z / c.w + 1.0) * 0.5
    }

    /// The distance along the ray of pixel `(i, j)` of the point at window depth `depth`
    /// (the inverse of [`MatrixRays::window_depth`]).
    pub fn distance_at_depth(&self, i: u32, j: u32, depth: f64) -> f64 {
        let (x, y) = self.ndc(i, j);
        let (o, d) = self.ray(i, j);
        (self.point(x, y, 2.0 * depth - 1.0) - o).dot(d)
    }
}

impl RaySource for MatrixRays {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    #[inline]
    fn ray(&self, i: u32, j: u32) -> (DVec3, DVec3) {
        let (x, y) = self.ndc(i, j);
        let near = self.point(x, y, -1.0);
        let far = self.point(x, y, 1.0);
        (near, (far - near).normalize_or_zero())
    }
    fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        let c = self.clip * p.extend(1.0);
        if c.w.is_nan() || c.w <= 0.0 {
            return None;
        }
        ndc_to_pixel(c.x / c.w, c.y / c.w, self.width, self.height)
    }

    fn project_box(&self, lo: DVec3, hi: DVec3) -> Option<([f64; 2], [f64; 2])> {
        let rows = [self.clip.row(0), self.clip.row(1), self.clip.row(3)];
        project_box_affine(rows, (lo, hi), self.width, self.height)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `vtkCamera`'s view transform (row-major): rows right, up, −forward; the eye to the
    /// origin.
    fn vtk_view(eye: DVec3, focal: DVec3, up: DVec3) -> [f64; 16] {
        let f = (focal - eye).normalize();
        let r = f.cross(up).normalize();
        let u = r.cross(f);
        [
            r.x,
            r.y,
            r.z,
            -r.dot(eye), //
            u.x,
            u.y,
            u.z,
            -u.dot(eye), //
            -f.x,
            -f.y,
            -f.z,
            f.dot(eye), //
            0.0,
            0.0,
            0.0,
            1.0,
        ]
    }

    /// `vtkPerspectiveTransform::SetupCamera`'s perspective (row-major, OpenGL's clip space):
    /// vertical full angle `angle` (degrees), `aspect` = width ÷ height, near and far distances.
    fn vtk_perspective(angle: f64, aspect: f64, near: f64, far: f64) -> [f64; 16] {
        let h = 1.0 / (angle.to_radians() * 0.5).tan();
        [
            h / aspect,
            0.0,
            0.0,
            0.0, //
            0.0,
            h,
            0.0,
            0.0, //
            0.0,
            0.0,
            -(far + near) / (far - near),
            -2.0 * far * near / (far - near), //
            0.0,
            0.0,
            -1.0,
            0.0,
        ]
    }

    /// VTK's parallel projection (`vtkPerspectiveTransform::Ortho`) of half height `scale`.
    fn vtk_ortho(scale: f64, aspect: f64, near: f64, far: f64) -> [f64; 16] {
        [
            1.0 / (scale * aspect),
            0.0,
            0.0,
            0.0, //
            0.0,
            1.0 / scale,
            0.0,
            0.0, //
            0.0,
            0.0,
            -2.0 / (far - near),
            -(far + near) / (far - near), //
            0.0,
            0.0,
            0.0,
            1.0,
        ]
    }

    #[test]
    fn matrix_rays_equal_look_at_rays_with_vtk_matrices() {
        let eye = DVec3::new(3.0, -2.0, 7.5);
        let focal = DVec3::new(0.5, 0.25, -1.0);
        let up = DVec3::new(0.1, 1.0, 0.3);
        let (w, h) = (13, 7);
        for parallel in [false, true] {
            let camera = if parallel {
                Camera::parallel(eye, focal, up, 2.5).unwrap()
            } else {
                Camera::perspective(eye, focal, up, 40.0).unwrap()
            };
            let look = RayGenerator::new(&camera, w, h).unwrap();
            let aspect = w as f64 / h as f64;
            let (near, far) = (0.5, 40.0);
            let projection = if parallel {
                vtk_ortho(2.5, aspect, near, far)
            } else {
                vtk_perspective(40.0, aspect, near, far)
            };
            let m = MatrixRays::new(&vtk_view(eye, focal, up), &projection, w, h).unwrap();
            let forward = (focal - eye).normalize();
            for j in 0..h {
                for i in 0..w {
                    let (o1, d1) = look.ray(i, j);
                    let (o2, d2) = m.ray(i, j);
                    assert!((d1 - d2).length() < 1e-9, "{i},{j}: {d1} vs {d2}");
                    // The matrix ray starts on the near plane, on the look-at ray.
                    let t = (o2 - o1).dot(d1);
                    assert!((o1 + d1 * t - o2).length() < 1e-9);
                    assert!(((o2 - eye).dot(forward) - near).abs() < 1e-9);
                }
            }
        }
    }

    /// [`RaySource::project_box`]'s default: the eight corners' [`RaySource::project`].
    struct CornerByCorner<'a>(&'a dyn RaySource);

    impl RaySource for CornerByCorner<'_> {
        fn size(&self) -> (u32, u32) {
            self.0.size()
        }
        fn ray(&self, i: u32, j: u32) -> (DVec3, DVec3) {
            self.0.ray(i, j)
        }
        fn project(&self, p: DVec3) -> Option<(f64, f64)> {
            self.0.project(p)
        }
    }

    #[test]
    fn a_box_projects_as_its_eight_corners_do() {
        let eye = DVec3::new(3.0, -2.0, 7.5);
        let focal = DVec3::new(0.5, 0.25, -1.0);
        let up = DVec3::new(0.1, 1.0, 0.3);
        let (w, h) = (64, 48);
        let aspect = w as f64 / h as f64;
        let look = RayGenerator::new(&Camera::perspective(eye, focal, up, 40.0).unwrap(), w, h);
        let flat = RayGenerator::new(&Camera::parallel(eye, focal, up, 2.5).unwrap(), w, h);
        let view = vtk_view(eye, focal, up);
        let persp = MatrixRays::new(&view, &vtk_perspective(40.0, aspect, 0.5, 40.0), w, h);
        let ortho = MatrixRays::new(&view, &vtk_ortho(2.5, aspect, 0.5, 40.0), w, h);
        let sources: [&dyn RaySource; 4] = [
            &look.unwrap(),
            &flat.unwrap(),
            &persp.unwrap(),
            &ortho.unwrap(),
        ];
        // Boxes scattered around the focal point, some reaching behind the eye.
        let mut next = crate::testing::uniform(99);
        for (k, rays) in sources.into_iter().enumerate() {
            let (mut projected, mut behind) = (0, 0);
            for _ in 0..2000 {
                let lo = focal + DVec3::new(next(), next(), next()) * 16.0 - 8.0;
                let hi = lo + DVec3::new(next(), next(), next()) * 3.0;
                let fast = rays.project_box(lo, hi);
                let slow = CornerByCorner(rays).project_box(lo, hi);
                match (fast, slow) {
                    (Some((a, b)), Some((c, d))) => {
                        for (u, v) in [a, b].iter().flatten().zip([c, d].iter().flatten()) {
                            assert!((u - v).abs() < 1e-9 * (1.0 + v.abs()), "{k}: {u} vs {v}");
                        }
                        projected += 1;
                    }
                    (None, None) => behind += 1,
                    other => panic!("source {k}, box {lo}-{hi}: {other:?}"),
                }
            }
            assert!(projected > 100, "source {k}: {projected} projected");
            assert!(
                k % 2 == 1 || behind > 50,
                "source {k}: {behind} behind the eye"
            );
        }
    }

    #[test]
    fn window_depth_and_distance_are_inverse_and_match_the_z_buffer() {
        let eye = DVec3::new(0.0, 0.0, 10.0);
        let (near, far) = (2.0, 20.0);
        for projection in [
            vtk_perspective(30.0, 1.5, near, far),
            vtk_ortho(3.0, 1.5, near, far),
        ] {
            let m =
                MatrixRays::new(&vtk_view(eye, DVec3::ZERO, DVec3::Y), &projection, 6, 4).unwrap();
            let (i, j) = (4, 1);
            let (o, d) = m.ray(i, j);
            // The near plane is depth 0, the far plane depth 1.
            assert!(m.window_depth(i, j, 0.0).abs() < 1e-12);
            let t_far = (far - near) / d.dot(-DVec3::Z);
            assert!((m.window_depth(i, j, t_far) - 1.0).abs() < 1e-12);
            assert_eq!(m.window_depth(i, j, f64::INFINITY), 1.0);
            for t in [0.3, 1.0, 5.0, 11.0] {
                let z = m.window_depth(i, j, t);
                assert!((0.0..=1.0).contains(&z));
                assert!((m.distance_at_depth(i, j, z) - t).abs() < 1e-9 * t.max(1.0));
                // Against the z-buffer formula of an eye-space depth e (distance along −z):
                // perspective: z_ndc = (f + n)/(f − n) − 2 f n / ((f − n) e).
                let e = (eye - (o + d * t)).dot(DVec3::Z);
                let expected = if projection[14] == -1.0 {
                    ((far + near) / (far - near) - 2.0 * far * near / ((far - near) * e) + 1.0)
                        * 0.5
                } else {
                    (e - near) / (far - near)
                };
                assert!((z - expected).abs() < 1e-12, "{z} vs {expected}");
            }
        }
    }

    #[test]
    fn singular_or_non_finite_matrices_are_refused() {
        let zero = [0.0; 16];
        let id = vtk_view(DVec3::Z, DVec3::ZERO, DVec3::Y);
        assert!(MatrixRays::new(&id, &zero, 4, 4).is_err());
        let mut nan = id;
        nan[5] = f64::NAN;
        assert!(MatrixRays::new(&nan, &vtk_ortho(1.0, 1.0, 0.1, 10.0), 4, 4).is_err());
        assert!(MatrixRays::new(&id, &vtk_ortho(1.0, 1.0, 0.1, 10.0), 0, 4).is_err());
        // Unprojection whose w is x_ndc + ½: the near point of a left pixel is behind infinity.
        let unproject = DMat4::from_cols_array(&[
            1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.5,
        ])
        .transpose();
        let clip = unproject.inverse().transpose().to_cols_array();
        let identity = DMat4::IDENTITY.to_cols_array();
        let e = MatrixRays::new(&identity, &clip, 4, 4).unwrap_err();
        assert!(e.to_string().contains("at infinity"), "{e}");
    }

    #[test]
    fn reset_fits_the_bounding_sphere() {
        let b = [-1.0, 1.0, -2.0, 2.0, 0.0, 4.0];
        let c = Camera::reset(b, 100, 100, false);
        assert_eq!(c.focal, DVec3::new(0.0, 0.0, 2.0));
        let radius = (2.0f64 * 2.0 + 4.0 * 4.0 + 4.0 * 4.0).sqrt() * 0.5;
        let d = (c.eye - c.focal).length();
        // The sphere's tangent cone from the eye has half angle 15°.
        assert!(((radius / d).asin().to_degrees() - 15.0).abs() < 1e-12);
    }

    #[test]
    fn azimuth_and_elevation_move_the_eye_as_vtk_does() {
        let b = [-1.0, 1.0, -1.0, 1.0, -1.0, 1.0];
        let mut c = Camera::reset(b, 10, 10, false);
        let d = c.eye.z;
        c.azimuth(90.0);
        // About +y by +90°: +z goes to +x.
        assert!((c.eye - DVec3::new(d, 0.0, 0.0)).length() < 1e-12);
        let mut c = Camera::reset(b, 10, 10, false);
        c.elevation(90.0);
        assert!((c.eye - DVec3::new(0.0, d, 0.0)).length() < 1e-12);
        assert!((c.up - -DVec3::Z).length() < 1e-12);
        c.zoom(2.0);
        assert_eq!(c.projection, Projection::Perspective(15.0));
    }

    #[test]
    fn centre_ray_goes_to_the_focal_point() {
        let c =
            Camera::perspective(DVec3::new(1.0, 2.0, 3.0), DVec3::ZERO, DVec3::Y, 30.0).unwrap();
        let g = RayGenerator::new(&c, 3, 3).unwrap();
        let (o, d) = g.ray(1, 1);
        assert_eq!(o, c.eye);
        assert!((d - (-c.eye).normalize()).length() < 1e-15);
        assert!(Camera::perspective(DVec3::ZERO, DVec3::ZERO, DVec3::Y, 30.0).is_err());
        assert!(Camera::perspective(DVec3::Z, DVec3::ZERO, DVec3::Z, 30.0).is_err());
    }
}
