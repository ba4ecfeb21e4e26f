//! What a ray's samples make of its pixel, chosen once per render ([`Accumulate`]):
//! front-to-back compositing of emission and absorption at a fixed step ([`composite`]) or
//! bounded by an error ([`integrate`]), or a maximum- or minimum-intensity projection
//! ([`extreme`]), with the transfer function and shading behind them ([`shade`]).
//!
//! The cast loop hands an accumulator each sample ([`Sample`]: the scalar at a point of a
//! cell) with the stretch of the ray it stands for ([`Segment`]); compositing turns it into
//! an [`Emission`] and absorbs it over the segment, keeping the state before it so that the
//! segment can be cut later at a boundary crossing ([`Open`]). An accumulator also says which
//! cells add nothing (the fast path passes over their samples) and where along the ray the
//! structure may hold one that adds something.
//!
//! An error-bounded accumulator also says where the next sample goes ([`Accumulate::next_step`])
//! and asks for samples between those it was given ([`Accumulate::ask`]), which the cast loop
//! locates and hands back ([`Accumulate::answer`]); the others keep the defaults, which do
//! nothing.

pub(crate) mod composite;
pub(crate) mod extreme;
pub(crate) mod integrate;
pub(crate) mod shade;
pub(crate) mod transparent;

use glam::DVec3;

use super::cast::steps::Steps;
use super::frame::Frame;
use super::ray::Ray;
use super::stats::RenderStats;
use crate::accel::{Accel, Counters, RaySpan};

/// The scalar at a point of a cell.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sample {
    /// Where along the ray.
    pub(crate) t: f64,
    /// The cell.
    pub(crate) cell: u32,
    /// The parametric coordinates in the cell, clamped to its cube.
    pub(crate) param: DVec3,
    /// The scalar.
    pub(crate) scalar: f64,
    /// The cell's corner values (point data), for the gradient.
    pub(crate) values: Option<[f64; 8]>,
    /// The scalar's gradient there, where the accumulator asks for slopes
    /// ([`Accumulate::SLOPES`]; `None` else, for cell data, or where the cell is degenerate).
    pub(crate) gradient: Option<DVec3>,
    /// The scalar's derivative along the ray there (0 where no gradient is taken, and with
    /// nearest interpolation).
    pub(crate) slope: f64,
}

/// What a sample emits: its (shaded) colour and its opacity over a whole step.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Emission {
    /// The colour.
    pub(crate) rgb: [f64; 3],
    /// The opacity of a step of it.
    pub(crate) alpha_step: f64,
}

/// The stretch of the ray a sample stands for: from `start` (`None`: its step's own start, for
/// a whole step) to `end`; where the sample starts a run of samples after positions in cells
/// that add nothing (or the ray's start), the run starts at the last of them, `own_start`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Segment {
    /// Where it starts, if not where its step starts.
    pub(crate) start: Option<f64>,
    /// Where it ends.
    pub(crate) end: f64,
    /// The position before it (where a run it starts starts).
    pub(crate) own_start: f64,
}

/// A sample an accumulator asks for: the middle of the stretch `[from, to]` of the ray, which
/// lies in the mesh, located from `cell`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Ask {
    /// Where the stretch starts.
    pub(crate) from: f64,
    /// Where it ends.
    pub(crate) to: f64,
    /// A cell at one of its ends.
    pub(crate) cell: u32,
}

/// A composited sample whose segment may still be cut at a boundary crossing
/// ([`Accumulate::recomposite`]): the sample, its emission and the accumulated state before it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Open {
    /// Where the sample lies.
    pub(crate) t: f64,
    /// Its segment's start, if not its step's.
    pub(crate) start: Option<f64>,
    /// What it emits.
    pub(crate) emission: Emission,
    /// Its cell and (unclamped) parameters: where a crossing search starts.
    pub(crate) inside: (u32, DVec3),
    /// The transmittance, colour and depth before it.
    pub(crate) before: (f64, [f64; 3], f64),
}

/// A ray's accumulated pixel: premultiplied colour and opacity, and the depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayResult {
    /// Premultiplied colour and accumulated opacity.
    pub rgba: [f64; 4],
    /// The depth sample's `t` (see the renderer's documentation), `+∞` if none.
    pub depth: f64,
}

impl RayResult {
    /// Nothing: transparent black at infinite depth.
    pub(crate) const NONE: RayResult = RayResult {
        rgba: [0.0; 4],
        depth: f64::INFINITY,
    };
}

/// What a ray's samples make of its pixel.
pub(crate) trait Accumulate {
    /// Where its samples go: every step of the options, or where it says
    /// ([`Accumulate::next_step`]).
    type Steps: Steps;

    /// Whether its samples carry the scalar's gradient and slope along the ray.
    const SLOPES: bool = false;

    /// Whether a sample in `cell` adds nothing whatever its scalar, so that the fast path may
    /// pass over it: a cell the transfer function makes transparent (compositing), or one
    /// whose scalar range cannot beat the ray's extreme so far (a projection). Always `false`
    /// on the paper path.
    fn adds_nothing(&self, cell: u32) -> bool;

    /// Whether a chord's middle in `cell` adds nothing (and is not interpolated).
    fn chord_adds_nothing(&self, cell: u32) -> bool;

    /// Counts a sample passed over because its cell adds nothing.
    fn count_passed(stats: &mut RenderStats);

    /// Counts a jump over cells that add nothing.
    fn count_jump(stats: &mut RenderStats);

    /// The first stretch of `span` where the structure may hold a cell that adds something
    /// (its entry, exit and such a cell where known); `None` where the structure keeps
    /// nothing to tell it by (no jump), `Some(None)` where there is none on the span.
    fn next_adding(
        &self,
        accel: &Accel,
        span: RaySpan,
        counters: &mut Counters,
    ) -> Option<Option<(f64, f64, Option<u32>)>>;

    /// Takes a sample: its emission where it is to be composited over its segment, `None`
    /// where it adds nothing to composite (transparent, or kept as the ray's extreme).
    fn take(&mut self, sample: &Sample, ray: &Ray, stats: &mut RenderStats) -> Option<Emission>;

    /// Composites what the sample at `t` emits over its segment; returns it open, for a
    /// later cut of the segment at a crossing.
    fn composite(
        &mut self,
        emission: Emission,
        t: f64,
        segment: Segment,
        inside: (u32, DVec3),
    ) -> Open;

    /// Composites `open` again from the state before it, its segment ending at `end` (a
    /// boundary crossing, or a clipping plane).
    fn recomposite(&mut self, open: Open, end: f64);

    /// The opacity accumulated so far.
    fn opacity(&self) -> f64;

    /// The whole ray it gathers over is `len` long (its pieces' total, for a ray cast piece
    /// by piece), said before its first sample.
    fn span(&mut self, _len: f64) {}

    /// A position of the ray was found outside the mesh (or passed over as such).
    fn outside(&mut self) {}

    /// The run of samples stops: at `at` (a position in a cell that adds nothing), or where
    /// `None` (the ray's end), at the last sample's own segment end.
    fn interrupt(&mut self, _at: Option<f64>) {}

    /// A sample needed before the accumulator can go on, if any (see [`Ask`]).
    fn ask(&mut self) -> Option<Ask> {
        None
    }

    /// The sample asked for, `None` where it could not be located.
    fn answer(&mut self, _sample: Option<&Sample>, _ray: &Ray, _stats: &mut RenderStats) {}

    /// The step of the sample after the one just composited, in `cell`; `None` for the
    /// options' fixed step.
    fn next_step(&self, _cell: u32) -> Option<f64> {
        None
    }

    /// Adds its own counters to `stats`, at the ray's end.
    fn count(&self, _stats: &mut RenderStats) {}

    /// The pixel.
    fn finish(self) -> RayResult;
}

/// A kind of accumulator, chosen once per render (its per-ray state is `Accumulator<'f>`).
pub(crate) trait AccumulatorKind {
    /// The accumulator of one ray.
    type Accumulator<'f>: Accumulate;
    /// A ray's accumulator, with nothing accumulated.
    fn start<'f>(frame: &'f Frame<'f>) -> Self::Accumulator<'f>;
}

/// Front-to-back compositing.
pub(crate) enum FrontToBack {}

impl AccumulatorKind for FrontToBack {
    type Accumulator<'f> = composite::Composite<'f>;
    fn start<'f>(frame: &'f Frame<'f>) -> composite::Composite<'f> {
        composite::Composite::new(frame)
    }
}

/// Front-to-back compositing bounded by an error.
pub(crate) enum Integrating {}

impl AccumulatorKind for Integrating {
    type Accumulator<'f> = integrate::Integrate<'f>;
    fn start<'f>(frame: &'f Frame<'f>) -> integrate::Integrate<'f> {
        integrate::Integrate::new(frame)
    }
}

/// A maximum- or minimum-intensity projection.
pub(crate) enum Projection {}

impl AccumulatorKind for Projection {
    type Accumulator<'f> = extreme::Extreme<'f>;
    fn start<'f>(frame: &'f Frame<'f>) -> extreme::Extreme<'f> {
        extreme::Extreme::new(frame)
    }
}
