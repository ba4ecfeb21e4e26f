//! Error-bounded compositing ([`Integrate`]): the samples of a ray are placed where the field
//! and the transfer function need them to keep the pixel within the error asked for
//! ([`crate::render::RenderOptions::max_error`]) of the converged image.
//!
//! # What is integrated
//! The converged image is the one the fixed-step samples approach as the step shrinks: along
//! each ray, emission and absorption with the extinction `σ(s)` and colour `c(s)` of the
//! transfer table, linear between its entries ([`table`]), at the interpolated scalar `s`.
//! Each sample gives the scalar and its slope along the ray; between two samples of one run
//! the scalar is the cubic through both with both slopes, from a sample to a boundary
//! crossing, a clipping plane or the end of a run it is the sample's tangent ([`model`]). The
//! transfer function is integrated along that model exactly where it is linear, piece by piece,
//! so a narrow band of the transfer function crossed between two samples is not missed.
//!
//! # How the error is held
//! The error allowed per ray, `E/255`, is shared: at most [`TERMINATION_SHARE`] is left to
//! early termination (a ray stops once its transmittance is below that: the renderer raises
//! its early termination to `1 − share·E/255` where it is lower), and [`QUADRATURE_SHARE`] is
//! spread over the ray's length (its clipped span) as a tolerance per unit length. Each stretch
//! between two samples is integrated twice, with the cubic and with the straight line between
//! the two values; their difference, weighted by the light left at the stretch, estimates the
//! error of a field linear between samples — more than the cubic's own wherever the field is
//! smooth. Where it exceeds the stretch's share of the tolerance, or where the stretch is
//! longer than a cell at either end is thin and that cell is *active* ([`guard`]), the middle
//! of the stretch is located (from the cell of one end, without moving the ray's march on) and
//! each half is integrated in turn ([`crate::render::RenderStats::refined_samples`]). A tangent
//! followed from one sample whose curvature is unknown (from a run's start to its first
//! sample, or past a run's only sample) is taken to be off by a share of what it adds, falling
//! with the square of its length below the options' step; where that is too much, the sample
//! asked for lies near its far end ([`NEAR_FRACTION`]), which leaves a cubic and a short
//! tangent instead of halving it again and again. The next
//! sample is placed from the estimate of the last stretch: the step grows where it was small
//! against the tolerance, at most twofold per sample, and shrinks where it was large, within
//! [`MIN_STEP_FRACTION`] and [`MAX_STEP_FACTOR`] of the options' step, and never beyond a cap
//! of the active cell it is in.

pub(crate) mod guard;
pub(crate) mod model;
pub(crate) mod table;

use glam::DVec3;

use self::guard::Guard;
use self::model::{Crossed, Field, Knot, Light, Look, MAX_SHAPE_PIECES};
use self::table::Extinction;
use super::{Accumulate, Ask, Emission, Open, RayResult, Sample, Segment};
use crate::accel::{Accel, Counters, RaySpan};
use crate::render::accumulate::transparent::TransparentSkip;
use crate::render::cast::steps::AdaptiveSteps;
use crate::render::frame::Frame;
use crate::render::ray::Ray;
use crate::render::stats::RenderStats;

/// The share of the error allowed that the integration between samples may spend.
pub(crate) const QUADRATURE_SHARE: f64 = 0.5;

/// The share of the error allowed that early termination may leave out.
pub(crate) const TERMINATION_SHARE: f64 = 0.25;

/// A cell is active ([`guard`]) where the transfer function's variation over its range times
/// its extent exceeds this share of the error allowed.
pub(crate) const GUARD_SHARE: f64 = 0.25;

/// The shortest step, and the shortest stretch refined, as a fraction of the options' step.
pub(crate) const MIN_STEP_FRACTION: f64 = 1.0 / 64.0;

/// The longest step, as a multiple of the options' step.
pub(crate) const MAX_STEP_FACTOR: f64 = 32.0;

/// Where a stretch is longer than this many times the cap of the active cell at either end, it
/// is refined (the next step is capped at the cell's own: a neighbour may be thinner).
const CAP_SLACK: f64 = 2.0;

/// The share of a stretch's tolerance under which the straight line between two samples'
/// values stands for the field between them.
const LINE_SHARE: f64 = 0.125;

/// The share of what a stretch followed along one sample's tangent adds that is taken as
/// its error where its curvature is unknown, at the options' step (less, with the square of
/// its length, below).
const TANGENT_SHARE: f64 = 0.25;

/// Most samples a refinement may stack up (the halvings from the longest step to the
/// shortest, and one more).
const STACK: usize = 16;

/// Where a tangent of unknown curvature is too long, the sample asked for lies this share of
/// its length from its far end.
const NEAR_FRACTION: f64 = 1.0 / 32.0;

/// What the error-bounded integration reads, made once per render: the transfer table as
/// extinction, the active cells, the error allowed per ray, and the options' step.
#[derive(Clone, Copy)]
pub(crate) struct Bounded<'a> {
    /// The transfer table as extinction.
    pub(crate) table: &'a Extinction,
    /// The caps of the active cells.
    pub(crate) guard: &'a Guard,
    /// The error allowed per ray, in `[0, 1]` RGBA units.
    pub(crate) error: f64,
    /// The options' step: a ray's first.
    pub(crate) step: f64,
}

/// A sample of the ray that the integration holds: its knot, its cell, where its run starts if
/// it starts one, and where its segment ends by default.
#[derive(Clone, Copy, Debug)]
struct Node {
    knot: Knot,
    cell: u32,
    /// Where the run of samples it belongs to starts, if it is the first of one.
    from: Option<f64>,
    /// Where its run ends if it is the last (the next sample's segment start).
    end: f64,
    /// Whether `from` is only known to lie between it and the position before, which was in
    /// a cell that adds nothing.
    loose_from: bool,
}

/// Which stretch of a run is integrated: between two samples, or from a run's end known only
/// to lie in it (the position beyond was in a cell that adds nothing, or outside the mesh)
/// to its nearest sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Part {
    /// Between two samples, or to a crossing or a plane.
    Known,
    /// From a loose start to the run's first sample.
    LooseStart,
    /// From the run's last sample to a loose end.
    LooseEnd,
}

/// Error-bounded compositing along one ray (see the module documentation).
pub(crate) struct Integrate<'f> {
    frame: &'f Frame<'f>,
    bounded: Bounded<'f>,
    /// The cells the fast path passes over, and where the structure holds the others.
    skip: TransparentSkip<'f>,
    light: Light,
    depth: f64,
    /// The error allowed per unit length of the ray (set at its first sample).
    tolerance: f64,
    /// Light below which nothing more is gathered.
    negligible: f64,
    /// Where the integration stands, and the sample there, if it stands at one.
    at: f64,
    behind: Option<Node>,
    /// The samples still to reach, the nearest last.
    ahead: [Option<Node>; STACK],
    ahead_len: usize,
    /// Where the ray (the piece of it being cast) ends.
    t_out: f64,
    /// Where the run ends once every sample ahead is reached.
    close: Option<f64>,
    /// The sample taken and not yet composited.
    taken: Option<Node>,
    /// The stretch whose middle was asked for, and whether it ends a run, and which part.
    asked: Option<(Ask, bool, Part)>,
    /// Whether the run's end (`close`) is loose (see [`Part`]).
    loose_close: bool,
    /// Whether the run being started has a loose start (see [`Part`]).
    loose_start: bool,
    /// The stretch being integrated is taken as it is (its middle was not found).
    as_is: bool,
    /// The sample asked for lies near the far end of a tangent (see [`NEAR_FRACTION`]).
    near: bool,
    /// The curvature of the scalar along the ray at the last sample, where known.
    curvature: f64,
    /// The step the last stretch suggests.
    suggested: f64,
    /// The stretches integrated.
    stretches: u64,
}

impl<'f> Integrate<'f> {
    /// Nothing gathered yet.
    pub(crate) fn new(frame: &'f Frame<'f>) -> Integrate<'f> {
        let bounded = frame
            .bounded
            .expect("an error-bounded render derives its tables before its rays");
        Integrate {
            frame,
            bounded,
            skip: TransparentSkip::of(frame),
            light: Light::CLEAR,
            depth: f64::INFINITY,
            tolerance: f64::NAN,
            negligible: 1e-3 * bounded.error,
            at: f64::NAN,
            behind: None,
            ahead: [None; STACK],
            ahead_len: 0,
            close: None,
            taken: None,
            asked: None,
            t_out: f64::INFINITY,
            loose_close: false,
            loose_start: false,
            as_is: false,
            near: false,
            curvature: f64::NAN,
            suggested: bounded.step,
            stretches: 0,
        }
    }

    fn push(&mut self, node: Node) {
        if self.ahead_len < STACK {
            self.ahead[self.ahead_len] = Some(node);
            self.ahead_len += 1;
        }
    }

    fn top(&self) -> Option<Node> {
        self.ahead_len.checked_sub(1).and_then(|k| self.ahead[k])
    }

    fn pop(&mut self) -> Option<Node> {
        let top = self.top();
        if top.is_some() {
            self.ahead_len -= 1;
        }
        top
    }

    /// The shortest step and stretch refined, and the longest step.
    fn step_limits(&self) -> (f64, f64) {
        let step = self.bounded.step;
        (step * MIN_STEP_FRACTION, step * MAX_STEP_FACTOR)
    }

    /// The knot of `sample`: its scalar, slope and look.
    fn knot(&self, sample: &Sample, ray: &Ray) -> Knot {
        let opts = self.frame.options;
        let mut look = Look::PLAIN;
        if let Some(shading) = &opts.shading {
            let (gain, specular) = shading.terms(sample.gradient, ray.dir);
            look.gain = gain;
            look.specular = specular;
        }
        if let Some(go) = &opts.gradient_opacity {
            look.opacity = go.at(sample.gradient.map_or(0.0, |g| g.length()));
        }
        Knot {
            t: sample.t,
            s: sample.scalar,
            slope: sample.slope,
            look,
        }
    }

    /// Integrates `[t0, t1]` along `field` where the error estimate and the active cells at
    /// its ends (`cells`) allow it; else the stretch whose middle to locate first (from
    /// `cells.0`).
    fn stretch(
        &mut self,
        field: Field,
        (t0, t1): (f64, f64),
        cells: (u32, u32),
        part: Part,
    ) -> Option<Ask> {
        let ends_run = matches!(field, Field::Tangent(..));
        let len = t1 - t0;
        if len.is_nan() || len <= 0.0 || self.light.transmittance <= self.negligible {
            return None;
        }
        let (crossed, mut estimate) = self.cross(&field, (t0, t1));
        if part != Part::Known {
            // Where the run really ends within it is unknown: all it adds may be wrong.
            estimate = estimate.max(crossed.light.difference(&self.light));
        } else if let Field::Tangent(_, curvature) = field {
            if curvature == 0.0 {
                // A tangent followed from one sample, its curvature unknown: what it adds may
                // be off by a share of it, falling with the square of its length from the
                // options' step (which resolves the field) down.
                let reach = (len / self.bounded.step).min(1.0);
                let whole = crossed.light.difference(&self.light);
                estimate = estimate.max(TANGENT_SHARE * reach * reach * whole);
            }
        }
        let allowed = self.tolerance * len;
        let guard = self.bounded.guard;
        let cap = guard.cap(cells.0).min(guard.cap(cells.1));
        let (min_step, _) = self.step_limits();
        let too_long = len > CAP_SLACK * cap;
        if !self.as_is && len > 2.0 * min_step && (estimate > allowed || too_long) {
            let ask = match field {
                Field::Tangent(knot, 0.0) if part == Part::Known && !too_long => {
                    // Its curvature unknown: a sample near its far end makes the stretch a
                    // cubic and leaves a short tangent.
                    let near = NEAR_FRACTION * len;
                    let (from, to) = if knot.t >= t1 {
                        (t0, t0 + 2.0 * near)
                    } else {
                        (t1 - 2.0 * near, t1)
                    };
                    self.near = true;
                    Ask {
                        from,
                        to,
                        cell: cells.0,
                    }
                }
                _ => Ask {
                    from: t0,
                    to: t1,
                    cell: cells.0,
                },
            };
            self.asked = Some((ask, ends_run, part));
            return Some(ask);
        }
        self.as_is = false;
        self.stretches += 1;
        self.light = crossed.light;
        if self.depth.is_infinite() {
            if let Some(t) = crossed.reached {
                self.depth = t;
            }
        }
        if let Field::Cubic(..) = field {
            let ratio = estimate / allowed;
            let grow = if ratio > 0.0 {
                (0.8 / ratio.sqrt()).clamp(0.25, 2.0)
            } else {
                2.0
            };
            self.suggested = len * grow;
        }
        None
    }

    /// The light after `[t0, t1]` along `field`, and the estimate of its error: where the
    /// field strays from the straight line between its ends by little against how steeply
    /// the transfer function varies there, the line's light and the bound of that difference;
    /// else the field's light, cut into pieces enough for its shape, and its difference from
    /// the line's.
    fn cross(&self, field: &Field, span: (f64, f64)) -> (Crossed, f64) {
        let table = self.bounded.table;
        let limits = (self.frame.options.depth_opacity, self.negligible);
        let line = field.chord();
        let rough = self.light.cross(table, &line, span, 1, limits);
        let deviation = field.deviation(span);
        if deviation == 0.0 {
            return (rough, 0.0);
        }
        let (s0, s1) = field.ends(span);
        let (lo, hi) = (s0.min(s1) - deviation, s0.max(s1) + deviation);
        let len = span.1 - span.0;
        let bound = 2.0 * self.light.transmittance * len * table.steepest(lo, hi) * deviation;
        let allowed = self.tolerance * len;
        if bound <= LINE_SHARE * allowed {
            return (rough, bound);
        }
        let pieces = (bound / (LINE_SHARE * allowed)).sqrt().ceil();
        let pieces = if pieces.is_finite() {
            (pieces as usize).clamp(2, MAX_SHAPE_PIECES)
        } else {
            MAX_SHAPE_PIECES
        };
        let fine = self.light.cross(table, field, span, pieces, limits);
        let estimate = fine.light.difference(&rough.light);
        (fine, estimate)
    }

    /// Ends the run at `e` from the sample `b` the integration stands at (its tangent, bent
    /// by the last curvature known); the stretch to refine first, if any.
    fn end_run(&mut self, b: Node, e: f64) -> Option<Ask> {
        let curvature = if self.curvature.is_finite() {
            self.curvature
        } else {
            0.0
        };
        let field = Field::Tangent(b.knot, curvature);
        let part = if self.loose_close {
            Part::LooseEnd
        } else {
            Part::Known
        };
        if let Some(ask) = self.stretch(field, (self.at, e), (b.cell, b.cell), part) {
            return Some(ask);
        }
        self.loose_close = false;
        self.at = e;
        self.behind = None;
        self.curvature = f64::NAN;
        None
    }

    /// Reaches the nearest sample ahead (after ending the run before it where it starts one);
    /// the stretch to refine first, if any.
    fn reach(&mut self, top: Node) -> Option<Ask> {
        if let Some(a) = top.from {
            if let Some(b) = self.behind {
                let end = *self.close.get_or_insert(b.end.max(self.at));
                if let Some(ask) = self.end_run(b, end) {
                    return Some(ask);
                }
                self.close = None;
                return None;
            }
            self.at = a;
            self.loose_start = top.loose_from;
            self.curvature = f64::NAN;
            if let Some(slot) = self.ahead_len.checked_sub(1) {
                if let Some(node) = self.ahead[slot].as_mut() {
                    node.from = None;
                }
            }
        }
        let (field, cells, part) = match self.behind {
            Some(b) => (
                Field::Cubic(b.knot, top.knot),
                (b.cell, top.cell),
                Part::Known,
            ),
            None if self.loose_start => (
                Field::Tangent(top.knot, 0.0),
                (top.cell, top.cell),
                Part::LooseStart,
            ),
            None => (
                Field::Tangent(top.knot, 0.0),
                (top.cell, top.cell),
                Part::Known,
            ),
        };
        if let Some(ask) = self.stretch(field, (self.at, top.knot.t), cells, part) {
            return Some(ask);
        }
        self.loose_start = false;
        if let Some(b) = self.behind {
            let dt = top.knot.t - b.knot.t;
            if dt > 0.0 {
                self.curvature = (top.knot.slope - b.knot.slope) / dt;
            }
        }
        self.at = top.knot.t;
        self.behind = self.pop();
        None
    }
}

impl Accumulate for Integrate<'_> {
    type Steps = AdaptiveSteps;

    const SLOPES: bool = true;

    #[inline]
    fn adds_nothing(&self, cell: u32) -> bool {
        self.skip.adds_nothing(cell)
    }

    fn chord_adds_nothing(&self, cell: u32) -> bool {
        self.adds_nothing(cell)
    }

    fn count_passed(stats: &mut RenderStats) {
        stats.samples_skipped += 1;
    }

    fn count_jump(stats: &mut RenderStats) {
        stats.transparent_jumps += 1;
    }

    fn next_adding(
        &self,
        accel: &Accel,
        span: RaySpan,
        counters: &mut Counters,
    ) -> Option<Option<(f64, f64, Option<u32>)>> {
        self.skip.next_adding(accel, span, counters)
    }

    fn take(&mut self, sample: &Sample, ray: &Ray, _stats: &mut RenderStats) -> Option<Emission> {
        self.t_out = ray.t_out;
        self.taken = Some(Node {
            knot: self.knot(sample, ray),
            cell: sample.cell,
            from: None,
            end: f64::NAN,
            loose_from: false,
        });
        // What the sample emits is integrated with its neighbours: nothing to report here.
        Some(Emission {
            rgb: [0.0; 3],
            alpha_step: 0.0,
        })
    }

    fn composite(
        &mut self,
        emission: Emission,
        t: f64,
        segment: Segment,
        inside: (u32, DVec3),
    ) -> Open {
        if let Some(mut node) = self.taken.take() {
            node.end = segment.end;
            node.from = match segment.start {
                Some(a) => Some(a),
                None if self.behind.is_none() => {
                    node.loose_from = true;
                    Some(segment.own_start)
                }
                None => None,
            };
            self.push(node);
        }
        Open {
            t,
            start: segment.start,
            emission,
            inside,
            before: (self.light.transmittance, self.light.color, self.depth),
        }
    }

    fn recomposite(&mut self, _open: Open, end: f64) {
        if self.behind.is_some() || self.ahead_len > 0 {
            self.close = Some(end);
            self.loose_close = false;
        }
    }

    fn span(&mut self, len: f64) {
        self.tolerance = QUADRATURE_SHARE * self.bounded.error / len.max(f64::MIN_POSITIVE);
    }

    fn outside(&mut self) {
        // The run ends no later than its last sample's own segment (or the crossing the cast
        // loop cut it at, which is exact).
        if self.close.is_none() && self.behind.is_some() && self.ahead_len == 0 {
            self.interrupt(None);
            self.loose_close = true;
        }
    }

    fn interrupt(&mut self, at: Option<f64>) {
        if self.close.is_none() {
            if let Some(b) = self.behind {
                if self.ahead_len == 0 {
                    // Not past the ray's end (a depth image's stop, a plane).
                    self.close = Some(at.unwrap_or(b.end.min(self.t_out)));
                    self.loose_close = at.is_some();
                }
            }
        }
    }

    fn ask(&mut self) -> Option<Ask> {
        loop {
            if let Some(top) = self.top() {
                if let Some(ask) = self.reach(top) {
                    return Some(ask);
                }
            } else if let Some(e) = self.close {
                let Some(b) = self.behind else {
                    self.close = None;
                    continue;
                };
                if let Some(ask) = self.end_run(b, e) {
                    return Some(ask);
                }
                self.close = None;
            } else {
                return None;
            }
        }
    }

    fn answer(&mut self, sample: Option<&Sample>, ray: &Ray, stats: &mut RenderStats) {
        let Some((ask, ends_run, part)) = self.asked.take() else {
            return;
        };
        let middle = 0.5 * (ask.from + ask.to);
        if std::mem::take(&mut self.near) && sample.is_none() {
            self.as_is = true;
            return;
        }
        // A loose end's middle in a cell that adds nothing, or outside the mesh: the run ends
        // (starts) before (after) it.
        let adds_nothing = sample.map_or(true, |s| self.adds_nothing(s.cell));
        match part {
            Part::LooseEnd if adds_nothing => {
                self.close = Some(middle);
                return;
            }
            Part::LooseStart if adds_nothing => {
                self.at = middle;
                return;
            }
            _ => {}
        }
        match sample {
            Some(sample) if self.ahead_len < STACK => {
                stats.refined_samples += 1;
                let node = Node {
                    knot: self.knot(sample, ray),
                    cell: sample.cell,
                    from: None,
                    end: ask.to,
                    loose_from: false,
                };
                self.push(node);
            }
            // The middle of a run's last stretch lies outside the mesh: the run ends before
            // it (the next ask halves what is left).
            None if ends_run && self.close.is_some() => {
                self.close = Some(0.5 * (ask.from + ask.to));
            }
            _ => self.as_is = true,
        }
    }

    fn next_step(&self, cell: u32) -> Option<f64> {
        let (min_step, max_step) = self.step_limits();
        let cap = self.bounded.guard.cap(cell);
        Some(self.suggested.min(cap).clamp(min_step, max_step))
    }

    #[inline]
    fn opacity(&self) -> f64 {
        1.0 - self.light.transmittance
    }

    fn count(&self, stats: &mut RenderStats) {
        stats.integrated_stretches += self.stretches;
    }

    fn finish(self) -> RayResult {
        RayResult {
            rgba: self.light.rgba(),
            depth: self.depth,
        }
    }
}
