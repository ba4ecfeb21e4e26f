//! The camera of a render as C gives it — a look-at camera in `vtkCamera`'s terms or a pair of
//! matrices — and its conversion to the renderer's rays and depth conventions.

use glam::DVec3;

use super::codes::{CameraModeCode, Code, CylvolCameraMode};
use super::status::Failure;
use crate::error::show_number;
use crate::render::Camera;
use crate::render::{MatrixRays, RayGenerator, RaySource};

/// A camera: `mode` says which fields are read.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CylvolCamera {
    /// LOOK_AT or MATRICES.
    pub mode: CameraModeCode,
    /// LOOK_AT (`vtkCamera`'s conventions): the eye position.
    pub eye: [f64; 3],
    /// LOOK_AT: the point looked at.
    pub focal_point: [f64; 3],
    /// LOOK_AT: the view-up vector (need not be unit or orthogonal to the view direction).
    pub view_up: [f64; 3],
    /// LOOK_AT: the vertical full view angle in degrees, in (0, 180) (perspective).
    pub view_angle: f64,
    /// LOOK_AT: nonzero for a parallel projection.
    pub parallel: i32,
    /// LOOK_AT: half the viewport height in world units (parallel), > 0.
    pub parallel_scale: f64,
    /// MATRICES: world (data) space to eye space, row-major (as
    /// `vtkMatrix4x4::DeepCopy(double[16])` gives it), the model (volume) matrix folded in.
    pub view: [f64; 16],
    /// MATRICES: eye space to OpenGL clip space, row-major; perspective or parallel is read
    /// from the matrix.
    pub projection: [f64; 16],
}

/// The identity matrix, row-major.
const IDENTITY: [f64; 16] = [
    1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
];

impl Default for CylvolCamera {
    /// LOOK_AT from `(0, 0, 1)` at the origin, view-up `+y`, perspective with VTK's 30°, parallel
    /// scale 1, identity matrices.
    fn default() -> Self {
        CylvolCamera {
            mode: CylvolCameraMode::LOOK_AT.into(),
            eye: [0.0, 0.0, 1.0],
            focal_point: [0.0; 3],
            view_up: [0.0, 1.0, 0.0],
            view_angle: crate::render::DEFAULT_VIEW_ANGLE,
            parallel: 0,
            parallel_scale: 1.0,
            view: IDENTITY,
            projection: IDENTITY,
        }
    }
}

/// The rays of a camera, and how its depth values relate to ray distances.
pub enum Rays {
    /// A look-at camera: depth is the distance along the ray.
    LookAt(RayGenerator),
    /// Matrices: depth is the window depth in `[0, 1]`.
    Matrices(MatrixRays),
}

impl Rays {
    /// The ray source.
    pub fn source(&self) -> &dyn RaySource {
        match self {
            Rays::LookAt(g) => g,
            Rays::Matrices(m) => m,
        }
    }

    /// The ray distance of an input depth value at pixel `(i, j)` (row 0 at the top).
    pub fn distance(&self, i: u32, j: u32, depth: f32) -> f64 {
        match self {
            Rays::LookAt(_) => depth as f64,
            Rays::Matrices(m) => {
                if depth >= 1.0 {
                    // The far plane or beyond: nothing opaque in front of the volume.
                    f64::INFINITY
                } else {
                    m.distance_at_depth(i, j, depth as f64)
                }
            }
        }
    }

    /// The output depth value of a ray distance at pixel `(i, j)` (`+∞`: none).
    pub fn depth(&self, i: u32, j: u32, t: f32) -> f32 {
        match self {
            Rays::LookAt(_) => t,
            Rays::Matrices(m) => m.window_depth(i, j, t as f64).clamp(0.0, 1.0) as f32,
        }
    }

    /// Whether depth values are window depths (MATRICES) rather than distances.
    pub fn window_depths(&self) -> bool {
        matches!(self, Rays::Matrices(_))
    }
}

fn finite(what: &str, values: &[f64]) -> Result<(), Failure> {
    super::arrays::finite(values, what)
}

impl CylvolCamera {
    /// The rays of a `width × height` image.
    pub fn rays(&self, width: u32, height: u32) -> Result<Rays, Failure> {
        match self.mode.decode("camera->mode")? {
            CylvolCameraMode::LOOK_AT => {
                finite("camera->eye", &self.eye)?;
                finite("camera->focal_point", &self.focal_point)?;
                finite("camera->view_up", &self.view_up)?;
                let (eye, focal, up) = (
                    DVec3::from_array(self.eye),
                    DVec3::from_array(self.focal_point),
                    DVec3::from_array(self.view_up),
                );
                let camera = if self.parallel != 0 {
                    if !(self.parallel_scale > 0.0 && self.parallel_scale.is_finite()) {
                        return Err(Failure::invalid(format!(
                            "camera->parallel_scale = {} (must be positive and finite)",
                            show_number(self.parallel_scale)
                        )));
                    }
                    Camera::parallel(eye, focal, up, self.parallel_scale)
                } else {
                    if !(self.view_angle > 0.0 && self.view_angle < 180.0) {
                        return Err(Failure::invalid(format!(
                            "camera->view_angle = {} (must be in (0, 180) degrees)",
                            show_number(self.view_angle)
                        )));
                    }
                    Camera::perspective(eye, focal, up, self.view_angle)
                }
                .map_err(|e| Failure::invalid(format!("camera: {e}")))?;
                let g = RayGenerator::new(&camera, width, height)
                    .map_err(|e| Failure::invalid(format!("camera: {e}")))?;
                Ok(Rays::LookAt(g))
            }
            CylvolCameraMode::MATRICES => {
                finite("camera->view", &self.view)?;
                finite("camera->projection", &self.projection)?;
                let m = MatrixRays::new(&self.view, &self.projection, width, height)
                    .map_err(|e| Failure::invalid(format!("camera: {e}")))?;
                Ok(Rays::Matrices(m))
            }
        }
    }
}

/// Fills `camera` with the defaults: LOOK_AT from `(0, 0, 1)` at the origin, view-up `+y`,
/// view angle 30°, perspective, parallel scale 1, identity matrices.
///
/// # Safety
/// `camera` NULL (nothing happens) or valid for writing a `CylvolCamera`.
#[no_mangle]
pub unsafe extern "C" fn cylvol_camera_default(camera: *mut CylvolCamera) {
    let _ = super::status::guard("cylvol_camera_default", || {
        // SAFETY: the caller vouches for the pointer.
        unsafe { super::arrays::write(camera, CylvolCamera::default(), "camera") }
    });
}
