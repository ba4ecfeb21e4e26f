//! How to render: the sampling path, the interpolation, the blend mode and the options of a
//! render ([`RenderOptions`]).

use glam::DVec3;

use super::clip::ClipPlanes;
use super::shading::Shading;
use super::transfer::{GradientOpacity, DEFAULT_TABLE_SIZE};
use crate::geometry::trilinear::{index, interpolate};
use crate::Error;

/// Which sampling path.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RenderPath {
    /// Every sample located from scratch through the structure.
    Paper,
    /// Previous cell, face neighbours, then the structure; transparent cells skipped.
    Fast,
}

impl RenderPath {
    /// `paper` or `fast`.
    pub fn name(self) -> &'static str {
        match self {
            RenderPath::Paper => "paper",
            RenderPath::Fast => "fast",
        }
    }
}

impl std::str::FromStr for RenderPath {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        match s {
            "paper" => Ok(RenderPath::Paper),
            "fast" => Ok(RenderPath::Fast),
            _ => Err(Error::Invalid(format!(
                "unknown path '{s}' (expected paper or fast)"
            ))),
        }
    }
}

/// How a sample's scalar is taken from its cell's corner values (point data; a cell value is
/// the same either way).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Interpolation {
    /// Trilinear in the cell's parametric coordinates (VTK's `VTK_LINEAR_INTERPOLATION`).
    #[default]
    Linear,
    /// The value of the corner nearest in parametric coordinates (VTK's
    /// `VTK_NEAREST_INTERPOLATION`); a coordinate of exactly ½ goes to the lower corner.
    /// Gradients (shading, gradient opacity) are still those of the trilinear interpolant.
    Nearest,
}

impl Interpolation {
    /// `linear` or `nearest`.
    pub fn name(self) -> &'static str {
        match self {
            Interpolation::Linear => "linear",
            Interpolation::Nearest => "nearest",
        }
    }

    /// The scalar at parametric coordinates `p` (in `[0, 1]³`) from the corner values.
    ///
    /// ```
    /// use cylvol::render::Interpolation;
    /// use glam::DVec3;
    /// let f = [0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0]; // f = u at the corners
    /// let p = DVec3::new(0.7, 0.2, 0.9);
    /// assert!((Interpolation::Linear.sample(&f, p) - 0.7).abs() < 1e-15);
    /// assert_eq!(Interpolation::Nearest.sample(&f, p), 1.0);
    /// ```
    #[inline]
    pub fn sample(self, values: &[f64; 8], p: DVec3) -> f64 {
        match self {
            Interpolation::Linear => interpolate(values, p),
            Interpolation::Nearest => {
                let corner = index(
                    (p.x > 0.5) as usize,
                    (p.y > 0.5) as usize,
                    (p.z > 0.5) as usize,
                );
                values[corner]
            }
        }
    }
}

impl std::str::FromStr for Interpolation {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        match s {
            "linear" => Ok(Interpolation::Linear),
            "nearest" => Ok(Interpolation::Nearest),
            _ => Err(Error::Invalid(format!(
                "unknown interpolation '{s}' (expected linear or nearest)"
            ))),
        }
    }
}

/// How a ray's samples make its pixel (VTK's volume mappers' `BlendMode`).
///
/// With [`Blend::Maximum`] or [`Blend::Minimum`] a ray keeps the largest (smallest) scalar
/// interpolated at its samples in the mesh, and its pixel is that scalar's colour with that
/// scalar's opacity per unit distance ([`TransferTable::unit_opacity`], not corrected to the
/// step), premultiplied — the colour and opacity VTK's maximum- and minimum-intensity
/// projections give the extreme scalar. Shading, gradient opacity, early termination,
/// boundary segments and the fast path's skipping of transparent cells belong to compositing
/// and are not used (a transparent cell may hold the extreme); the depth output is the
/// extreme sample's `t` where its opacity reaches `depth_opacity`. Instead the fast path
/// passes over the samples in cells whose scalar range cannot beat the ray's extreme so far
/// ([`Blend::may_replace_in`]; [`RenderStats::extreme_skips`]): no inverse map where the
/// cell's face planes settle that the sample lies in it, and no interpolation; with a BVH it
/// jumps over such cells to the next that may ([`RenderStats::extreme_jumps`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Blend {
    /// Front-to-back emission-absorption compositing (VTK's `COMPOSITE_BLEND`).
    #[default]
    Composite,
    /// Maximum-intensity projection (VTK's `MAXIMUM_INTENSITY_BLEND`).
    Maximum,
    /// Minimum-intensity projection (VTK's `MINIMUM_INTENSITY_BLEND`).
    Minimum,
}

impl Blend {
    /// All three, in the order of their names.
    pub const ALL: [Blend; 3] = [Blend::Composite, Blend::Maximum, Blend::Minimum];

    /// `composite`, `max` or `min` (what [`str::parse`] reads).
    pub fn name(self) -> &'static str {
        match self {
            Blend::Composite => "composite",
            Blend::Maximum => "max",
            Blend::Minimum => "min",
        }
    }

    /// Whether `s` replaces `best` as the ray's extreme (never for compositing or a NaN `s`).
    ///
    /// ```
    /// use cylvol::render::Blend;
    /// assert!(Blend::Maximum.replaces(2.0, Some(1.0)));
    /// assert!(!Blend::Minimum.replaces(2.0, Some(1.0)));
    /// assert!(Blend::Minimum.replaces(2.0, None));
    /// assert!(!Blend::Maximum.replaces(f64::NAN, None));
    /// ```
    #[inline]
    pub fn replaces(self, s: f64, best: Option<f64>) -> bool {
        match (self, best) {
            (Blend::Composite, _) => false,
            (_, None) => !s.is_nan(),
            (Blend::Maximum, Some(b)) => s > b,
            (Blend::Minimum, Some(b)) => s < b,
        }
    }

    /// Whether a cell whose scalar lies in `range` (`[min, max]`) may hold a sample that
    /// replaces `best` as the ray's extreme: an interpolated scalar lies within its cell's
    /// corner values, so a cell whose maximum is not above the ray's maximum (whose minimum
    /// is not below its minimum) holds none. `true` for compositing, with no extreme yet, and
    /// for a NaN bound.
    ///
    /// ```
    /// use cylvol::render::Blend;
    /// assert!(!Blend::Maximum.may_replace_in([0.0, 1.0], Some(1.0)));
    /// assert!(Blend::Maximum.may_replace_in([0.0, 1.5], Some(1.0)));
    /// assert!(!Blend::Minimum.may_replace_in([0.5, 1.5], Some(0.5)));
    /// assert!(Blend::Minimum.may_replace_in([0.5, 1.5], None));
    /// ```
    #[inline]
    pub fn may_replace_in(self, range: [f64; 2], best: Option<f64>) -> bool {
        match (self, best) {
            (Blend::Composite, _) | (_, None) => true,
            (Blend::Maximum, Some(b)) => range[1] > b || range[1].is_nan(),
            (Blend::Minimum, Some(b)) => range[0] < b || range[0].is_nan(),
        }
    }
}

impl std::str::FromStr for Blend {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        crate::error::by_name(&Blend::ALL, Blend::name, s, "blend mode")
    }
}

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Distance between samples along a ray, in world units.
    pub step: f64,
    /// Paper or fast path.
    pub path: RenderPath,
    /// Shading, or `None` for none (then no gradient is evaluated).
    pub shading: Option<Shading>,
    /// Rays stop once their accumulated opacity reaches this (default 0.99; 1 or more never).
    pub early_termination: f64,
    /// The depth output is where the accumulated opacity first reaches this (default 0.5).
    pub depth_opacity: f64,
    /// Tile side in pixels for the parallel loop (default 16).
    pub tile: u32,
    /// Entries of the transfer-function table (default 1024).
    pub table_size: usize,
    /// Whether a sample next to a boundary crossing stands for the in-mesh part of its segment
    /// only, the crossing found by bisection (default: on). Off, every sample stands for a whole
    /// step: cheaper, but the error is then first order in the step (see `cylvol accuracy`).
    pub boundary_segments: bool,
    /// How the scalar is interpolated in a cell (default linear).
    pub interpolation: Interpolation,
    /// Gradient opacity (VTK's): a factor of the gradient magnitude on the scalar opacity per
    /// unit distance; `None` (the default) for none, and then no gradient is evaluated unless
    /// shading is on.
    pub gradient_opacity: Option<GradientOpacity>,
    /// How the samples make the pixel (default compositing; see [`Blend`]).
    pub blend: Blend,
    /// Clipping planes (default none): each ray is rendered only where every plane keeps it
    /// (see [`super::clip`]); where a plane cuts the mesh the volume ends there, as at its
    /// boundary.
    pub clip_planes: ClipPlanes,
    /// The fast path's reach by marching (default [`DEFAULT_MARCH_REACH`]): a sample about
    /// more than this many cells ahead of the previous one ([`super::march::March::cells_ahead`]),
    /// times the cells a look-up through the structure tests on average
    /// ([`Accel::lookup_tests`]: about 1 on a BVH of well-shaped cells, 7–19 on a grid), is
    /// located through the structure instead of by crossing every cell on the way, where
    /// the boundary surface proves the ray stays in the mesh up to it (so no exit and
    /// re-entry between the two is passed over; counted in [`RenderStats::far_locates`]).
    /// The image is the same either way: both find the cell holding the sample.
    /// `f64::INFINITY` always marches.
    pub march_reach: f64,
    /// The largest colour error allowed, in 1/255 of a pixel's premultiplied RGBA against
    /// the converged image (what the samples approach as they get denser), or `None` (the
    /// default of [`RenderOptions::new`]) for samples every [`RenderOptions::step`].
    ///
    /// With an error set, compositing places its samples along each ray where the field and
    /// the transfer function need them ([`super::accumulate::integrate`]): `step` is then the
    /// step a ray starts with, the integration between samples is exact for a field that is
    /// linear between them, and early termination stops a ray no earlier than its share of
    /// the error allows (the stricter of that and [`RenderOptions::early_termination`]).
    /// [`DEFAULT_MAX_ERROR`] is a setting measured at least as accurate as VTK's ray caster.
    /// Intensity projections and whole steps ([`RenderOptions::boundary_segments`] off) keep
    /// the fixed step.
    pub max_error: Option<f64>,
}

/// The default [`RenderOptions::march_reach`]: a look-up that tests one cell costs about as
/// much as crossing this many cells by their planes (measured on the refined mixer, whose
/// cylindrical BVH's look-ups test 1.02 cells, `cargo bench --bench render -- MESH 512 3
/// cyl-bvh fast --vtk-scene --step-factor=F --march-reach=R`).
pub const DEFAULT_MARCH_REACH: f64 = 6.0;

impl RenderOptions {
    /// Defaults for a `width × height` image with the given step: fast path, no shading,
    /// early termination at 0.99, depth at 0.5, 16-pixel tiles, 1024 table entries, boundary
    /// segments on, linear interpolation, no gradient opacity, compositing, no clipping plane.
    pub fn new(width: u32, height: u32, step: f64) -> RenderOptions {
        RenderOptions {
            width,
            height,
            step,
            path: RenderPath::Fast,
            shading: None,
            early_termination: 0.99,
            depth_opacity: 0.5,
            tile: 16,
            table_size: DEFAULT_TABLE_SIZE,
            boundary_segments: true,
            interpolation: Interpolation::Linear,
            gradient_opacity: None,
            blend: Blend::Composite,
            clip_planes: ClipPlanes::NONE,
            march_reach: DEFAULT_MARCH_REACH,
            max_error: None,
        }
    }

    /// Whether the render places its samples for [`RenderOptions::max_error`]: an error is
    /// set, the samples are composited and boundary segments are on.
    pub fn error_bounded(&self) -> bool {
        self.max_error.is_some() && self.blend == Blend::Composite && self.boundary_segments
    }
}

/// An error setting of 2/255 of a pixel's premultiplied RGBA (see [`RenderOptions::max_error`]),
/// measured at least as accurate as VTK's ray caster on every mesh the tests carry. Renders ask
/// for an error only when one is given (`--max-error`); the default is the fixed step.
pub const DEFAULT_MAX_ERROR: f64 = 2.0;

/// Samples per ray beyond which a render is refused (a step far too small for the mesh).
pub const MAX_SAMPLES_PER_RAY: f64 = 1e7;
