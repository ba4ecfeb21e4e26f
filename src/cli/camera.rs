//! The camera options of `cylvol render`: the `--view AZIMUTH,ELEVATION,ZOOM` preset around
//! the data, or a camera set as VTK sets one (`--camera POSITION:FOCAL_POINT:VIEW_UP`,
//! `vtkCamera::SetPosition`, `SetFocalPoint`, `SetViewUp`), with `--view-angle`
//! (`SetViewAngle`), `--parallel` (`ParallelProjectionOn`) and `--parallel-scale`
//! (`SetParallelScale`).
//!
//! Without `--camera` the preset places the camera ([`cylvol::render::Camera::reset`], then
//! azimuth, elevation and zoom), in parallel projection with `--parallel` (the reset's parallel
//! scale is the bounding sphere's radius, which the zoom divides); `--view-angle` and
//! `--parallel-scale` then replace what the preset made, as the `vtkCamera` calls would after
//! `ResetCamera`. With `--camera` the view angle defaults to VTK's 30° and the parallel scale
//! to the reset's ([`cylvol::render::Camera::reset`]).

use glam::DVec3;

use super::number::show;
use super::scene;
use cylvol::render::{Camera, Projection, DEFAULT_VIEW_ANGLE};
use cylvol::Error;

/// The camera options.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct CameraArgs {
    /// Camera preset AZIMUTH,ELEVATION,ZOOM in degrees, degrees and a factor.
    #[arg(long, value_name = "AZIMUTH,ELEVATION,ZOOM", value_parser = scene::parse_view, allow_hyphen_values = true)]
    pub view: Option<[f64; 3]>,
    /// The camera as VTK sets it, instead of `--view`: its position, focal point and view-up
    /// vector, each `X,Y,Z` in world units, e.g. `0,0,50:0,0,0:0,1,0`.
    #[arg(long, value_name = "X,Y,Z:X,Y,Z:X,Y,Z", value_parser = parse_camera, allow_hyphen_values = true, conflicts_with = "view")]
    pub camera: Option<[DVec3; 3]>,
    /// The perspective camera's full vertical view angle in degrees, in (0, 180) (VTK's
    /// `ViewAngle`; default 30, which `--view`'s zoom divides).
    #[arg(long, value_name = "DEGREES", value_parser = parse_view_angle, conflicts_with = "parallel", allow_hyphen_values = true)]
    pub view_angle: Option<f64>,
    /// Parallel projection (VTK's `ParallelProjection`) instead of perspective.
    #[arg(long)]
    pub parallel: bool,
    /// With `--parallel`: half the viewport height in world units (VTK's `ParallelScale`;
    /// default as `ResetCamera` sets it, the bounding sphere's radius, over the aspect ratio
    /// when the image is taller than wide; `--view`'s zoom divides it).
    #[arg(long, value_name = "S", value_parser = parse_parallel_scale, requires = "parallel", allow_hyphen_values = true)]
    pub parallel_scale: Option<f64>,
}

/// Parses `--camera X,Y,Z:X,Y,Z:X,Y,Z` (position, focal point, view-up; finite numbers),
/// refusing, in the option's terms, a camera that sets no direction: the position on the focal
/// point, or the view-up along the line of sight (or zero).
pub fn parse_camera(s: &str) -> Result<[DVec3; 3], String> {
    let [eye, focal, up] = parse_vectors(s)
        .ok_or_else(|| format!("camera '{s}' is not POSITION:FOCAL_POINT:VIEW_UP, each X,Y,Z"))?;
    let sight = focal - eye;
    let why = if sight == DVec3::ZERO {
        "the position is the focal point, so there is no direction of view"
    } else if !sight.is_finite() || !sight.normalize_or_zero().is_finite() {
        "the position and the focal point are too far apart to give a direction of view"
    } else if up == DVec3::ZERO {
        "the view-up is zero"
    } else if sight.normalize().cross(up).normalize_or_zero() == DVec3::ZERO {
        "the view-up is along the line of sight, so it sets no up in the image"
    } else {
        return Ok([eye, focal, up]);
    };
    Err(format!("degenerate camera '{s}': {why}"))
}

/// `N` vectors `X,Y,Z` of finite numbers separated by `:`, if `s` is that.
pub fn parse_vectors<const N: usize>(s: &str) -> Option<[DVec3; N]> {
    let vectors: Vec<DVec3> = s
        .split(':')
        .map(|part| {
            let v: Vec<f64> = part
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .ok()?;
            match v[..] {
                [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => {
                    Some(DVec3::new(x, y, z))
                }
                _ => None,
            }
        })
        .collect::<Option<_>>()?;
    <[DVec3; N]>::try_from(vectors).ok()
}

/// Parses `--view-angle DEGREES`, in (0, 180).
pub fn parse_view_angle(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(a) if a > 0.0 && a < 180.0 => Ok(a),
        _ => Err(format!(
            "view angle '{s}' must be a number of degrees in (0, 180)"
        )),
    }
}

/// Parses `--parallel-scale S`, positive and finite.
pub fn parse_parallel_scale(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!(
            "parallel scale '{s}' must be a positive, finite length"
        )),
    }
}

impl CameraArgs {
    /// The camera these options describe for a `width × height` image of what `bounds`
    /// (`[xmin, xmax, ymin, ymax, zmin, zmax]`: a mesh's, or the wheel of a periodic sector's
    /// copies) holds, checked: a degenerate one (the position on the focal point, the view-up
    /// along the view) is an error.
    pub fn camera_for(&self, bounds: [f64; 6], width: u32, height: u32) -> Result<Camera, Error> {
        let mut camera = match self.camera {
            Some([eye, focal, up]) => {
                let reset = Camera::reset(bounds, width, height, self.parallel);
                Camera {
                    eye,
                    focal,
                    up,
                    projection: reset.projection,
                }
            }
            None => {
                let [azimuth, elevation, zoom] = self.view.unwrap_or(scene::DEFAULT_VIEW);
                Camera::reset(bounds, width, height, self.parallel).turned(azimuth, elevation, zoom)
            }
        };
        if let Some(angle) = self.view_angle {
            camera.projection = Projection::Perspective(angle);
        }
        if let Some(scale) = self.parallel_scale {
            camera.projection = Projection::Parallel(scale);
        }
        // Only a zoom can make the projection unusable here: the view angle and the parallel
        // scale given were checked when parsed.
        if let (None, Some([_, _, zoom])) = (self.camera, self.view) {
            let given = self.view_text();
            match camera.projection {
                Projection::Perspective(a) if !(a > 0.0 && a < 180.0) => {
                    return Err(zoom_error(&given, zoom));
                }
                Projection::Parallel(s) if !(s > 0.0 && s.is_finite()) => {
                    return Err(Error::Invalid(format!(
                        "--view {given}: a zoom of {} makes the parallel scale (half the \
                         image's height) {}, not a positive, finite length",
                        show(zoom),
                        show(s)
                    )));
                }
                _ => {}
            }
        }
        let checked = match camera.projection {
            Projection::Perspective(a) => {
                Camera::perspective(camera.eye, camera.focal, camera.up, a)
            }
            Projection::Parallel(s) => Camera::parallel(camera.eye, camera.focal, camera.up, s),
        };
        let option = if self.camera.is_some() {
            "--camera"
        } else {
            "--view"
        };
        checked.map_err(|e| Error::Invalid(format!("{option}: {e}")))
    }

    /// Refuses, before any work, a `--view` whose zoom widens the perspective camera's view
    /// angle to 180° or more (the zoom divides VTK's 30°); [`CameraArgs::camera`] checks the
    /// rest, which needs the mesh.
    pub fn check(&self) -> Result<(), Error> {
        match self.view {
            Some(view) if self.camera.is_none() && !self.parallel && self.view_angle.is_none() => {
                check_zoom(view)
            }
            _ => Ok(()),
        }
    }

    /// `--view` as given, its numbers shown readably.
    fn view_text(&self) -> String {
        self.view.map(|v| v.map(show).join(",")).unwrap_or_default()
    }
}

/// Refuses a `--view AZIMUTH,ELEVATION,ZOOM` whose zoom would widen a perspective camera's
/// default view angle ([`DEFAULT_VIEW_ANGLE`]) to 180° or more.
pub fn check_zoom(view: [f64; 3]) -> Result<(), Error> {
    let zoom = view[2];
    if DEFAULT_VIEW_ANGLE / zoom < 180.0 {
        return Ok(());
    }
    Err(zoom_error(&view.map(show).join(","), zoom))
}

/// The error of a zoom that leaves no perspective view angle below 180°.
fn zoom_error(given: &str, zoom: f64) -> Error {
    Error::Invalid(format!(
        "--view {given}: a zoom of {} would widen the {DEFAULT_VIEW_ANGLE}° view angle to {}°; \
         the zoom divides the view angle, which must stay below 180°, so the zoom must be more \
         than {DEFAULT_VIEW_ANGLE}/180 (about {:.4}) (or use --parallel)",
        show(zoom),
        show(DEFAULT_VIEW_ANGLE / zoom),
        DEFAULT_VIEW_ANGLE / 180.0,
    ))
}
