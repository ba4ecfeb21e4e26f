//! The cast of one ray: a short loop over the parts, each with one job.
//!
//! ```text
//! for each sample position t (steps):
//!     where is it?                       locator: a cell, outside, or a stretch passed over
//!     what lies between it and the last? boundary: the exit, the entry, chords and gaps
//!     does its cell add anything?        accumulator: if not, the locator may jump on
//!     what does it emit?                 accumulator: transfer function, shading
//!     where does its segment start?      boundary: the crossing, where it follows outside
//!     composite it                       accumulator
//! at the ray's end: close the last segment at the boundary, sample the chords after it
//! ```
//!
//! A ray (see [`super::ray`]) is clipped to the mesh's padded box, to `t ≥ 0`, to the
//! clipping planes and to the opaque geometry's depth. Where a located sample follows an
//! unlocated one (or the ray's start), or an unlocated one follows it (or the ray's end), the
//! ray crossed the mesh boundary in between: the boundary sample stands for the in-mesh part
//! of the ray from the crossing to the middle between it and its located neighbour — its own
//! segment cut at the crossing, or extended to it over the outside neighbour's segment. The
//! in-mesh length of a ray is thus exact up to the crossing estimate instead of a step per
//! crossing, which makes the error of an image fall with the square of the step (midpoint
//! rule) rather than linearly. Where a clipping plane starts a ray inside the mesh, the first
//! sample stands for the ray from the plane; where one ends it inside the mesh, the last
//! sample ends at the plane, as at a boundary crossing. Where the opaque-geometry depth stops
//! a ray inside the mesh, the last sample keeps its full step.
//!
//! With a boundary surface (complete neighbours), wherever the ray may cross the boundary
//! between two positions (the fast path's exits from the mesh and entries into it, samples
//! past a possible crossing, the ray's ends; on the paper path every pair the surface's bound
//! does not rule out), every crossing in between is found exactly and sorted
//! ([`super::boundary::chords`]): the earlier sample's exit, the later one's entry, and the
//! chords between, each sampled once at its middle for its own length
//! ([`super::RenderStats::chord_samples`]; a gap's ends cut the two samples' segments,
//! [`super::RenderStats::gaps`]). A constant medium's transmittance is then exact for every
//! ray, whatever its stretches' lengths.
//!
//! The ray stops once its accumulated opacity reaches the early termination (after looking
//! whether it leaves the mesh before the next sample).

pub(crate) mod steps;

use std::ops::ControlFlow;

use glam::DVec3;

use steps::Steps;

use super::accumulate::{Accumulate, AccumulatorKind, Open, RayResult, Sample, Segment};
use super::boundary::chords::{Between, Chord};
use super::boundary::proof::ProvedExit;
use super::boundary::Stretch;
use super::frame::Frame;
use super::locate::{Locate, LocatorKind, Next};
use super::ray::{End, Ray};
use super::stats::{RenderStats, Work};

/// Casts `ray` with a locator of kind `L` and an accumulator of kind `A`, starting the
/// locator from `hint` (the previous ray's first cell, updated to this ray's).
pub(crate) fn cast<'f, L: LocatorKind, A: AccumulatorKind>(
    frame: &'f Frame<'f>,
    ray: &'f Ray<'f>,
    hint: &mut Option<u32>,
    stats: &mut RenderStats,
) -> RayResult {
    cast_into::<L, A::Accumulator<'f>>(frame, ray, hint, A::start(frame), stats)
        .0
        .finish()
}

/// Casts `ray` into `acc` (which may hold what earlier pieces of a longer ray accumulated: a
/// ray through the copies of a periodic sector is cast piece by piece, each piece in its
/// copy's frame), with a locator of kind `L` started from `hint`: the accumulator, and whether
/// the ray became opaque enough to stop.
pub(crate) fn cast_into<'f, L: LocatorKind, A: Accumulate>(
    frame: &'f Frame<'f>,
    ray: &'f Ray<'f>,
    hint: &mut Option<u32>,
    acc: A,
    stats: &mut RenderStats,
) -> (A, bool) {
    let mut work = Work::new(stats);
    let locator = <L::Locator<'f>>::start(frame, ray, *hint, &mut work);
    let cast = Cast {
        frame,
        ray,
        steps: Steps::new(ray.t_in, frame.options.step),
        locator,
        acc,
        work,
        open: None,
        was_in: false,
        jumped: false,
        first_cell: None,
    };
    let (acc, first, terminated) = cast.run();
    if first.is_some() {
        *hint = first;
    }
    (acc, terminated)
}

/// One ray being cast: its parts and what the loop knows of the position before the next
/// sample.
struct Cast<'f, 's, L, A> {
    frame: &'f Frame<'f>,
    ray: &'f Ray<'f>,
    steps: Steps,
    locator: L,
    acc: A,
    work: Work<'s>,
    /// The last composited sample, whose segment may still end at a boundary crossing.
    open: Option<Open>,
    /// Whether the previous sample position was located in a cell.
    was_in: bool,
    /// Whether a jump passed over the position before the next sample.
    jumped: bool,
    /// The first cell a sample was found in.
    first_cell: Option<u32>,
}

impl<'f, L: Locate<'f>, A: Accumulate> Cast<'f, '_, L, A> {
    /// The loop over the samples, then the ray's end: the accumulator, the ray's first cell,
    /// and whether the ray stopped opaque.
    fn run(mut self) -> (A, Option<u32>, bool) {
        let terminated = loop {
            let t = self.steps.next();
            if t >= self.ray.t_out || t.is_nan() {
                break false;
            }
            if let ControlFlow::Break(terminated) = self.sample(t) {
                break terminated;
            }
        };
        self.end(terminated);
        self.work.finish();
        (self.acc, self.first_cell, terminated)
    }

    /// The sample at `t`: located, then handled as in the mesh or outside, or passed over
    /// with the stretch the locator passes over. `Break(true)` where the ray is opaque
    /// enough to stop, `Break(false)` where nothing is left to sample.
    fn sample(&mut self, t: f64) -> ControlFlow<bool> {
        let t_out = self.ray.t_out;
        match self.locator.locate(t, &self.acc, &mut self.work) {
            Next::Inside {
                cell,
                param,
                crossed,
            } => {
                self.steps.take(self.work.stats);
                self.inside(t, (cell, param), crossed)
            }
            Next::Outside(proved) => {
                self.steps.take(self.work.stats);
                self.outside(t, proved)
            }
            Next::OutsideUntil(until) => {
                self.steps.pass_over(until, t_out, self.work.stats);
                ControlFlow::Continue(())
            }
            Next::LeftBounds(entry) => {
                self.was_in = false;
                self.close_open(t, None);
                self.steps.pass_over(entry, t_out, self.work.stats);
                ControlFlow::Continue(())
            }
            Next::NoBounds => {
                self.close_open(t, None);
                self.steps.pass_over(t_out, t_out, self.work.stats);
                ControlFlow::Break(false)
            }
        }
    }

    /// A sample located nowhere: outside the mesh, exactly. The crossings since the previous
    /// position (where the exit was not proved by parity, its crossing then the only one):
    /// its sample's exit, and the chords after it (or between two positions outside).
    fn outside(&mut self, t: f64, proved: Option<ProvedExit>) -> ControlFlow<bool> {
        let after_jump = std::mem::take(&mut self.jumped);
        let was_in = std::mem::replace(&mut self.was_in, false);
        let between = match proved {
            Some(_) => None,
            None => {
                let behind = self.steps.before_taken(self.ray, was_in, after_jump);
                let here = (t, End::Outside);
                self.frame
                    .boundary
                    .between(self.ray, behind, here, &mut self.work)
            }
        };
        let exit = proved.map(|p| p.crossing).or(between.and_then(|b| b.exit));
        self.close_open(t, exit);
        self.chords_or_stop(between.as_ref())?;
        self.locator.passed_outside(t, proved, &mut self.work);
        ControlFlow::Continue(())
    }

    /// A sample in `cell` at the (unclamped) parameters `param`. The crossings since the
    /// previous position where the ray may have crossed the boundary — from outside (the
    /// entry, and chords before it), or from a sample in the mesh where the locator says it
    /// may have left it (a gap): the previous sample's exit closes it, the entry starts
    /// this one. Then the sample is passed over, or taken and composited.
    fn inside(&mut self, t: f64, (cell, param): (u32, DVec3), crossed: bool) -> ControlFlow<bool> {
        let after_jump = std::mem::take(&mut self.jumped);
        let was_in = std::mem::replace(&mut self.was_in, true);
        let between = if !was_in || crossed {
            let behind = self.steps.before_taken(self.ray, was_in, after_jump);
            let here = (t, End::Sample);
            self.frame
                .boundary
                .between(self.ray, behind, here, &mut self.work)
        } else {
            None
        };
        if let Some(b) = &between {
            if b.exit.is_some() && b.entry.is_some() {
                self.work.stats.gaps += 1;
            }
            if let (Some(e), Some(open)) = (b.exit, self.open.take()) {
                self.acc.recomposite(open, e);
            }
        }
        self.chords_or_stop(between.as_ref())?;
        // The previous composited sample (if any) keeps its full end (or the exit just
        // found): this one is inside.
        self.open = None;
        self.work.stats.samples_located += 1;
        self.first_cell = self.first_cell.or(Some(cell));
        if self.acc.adds_nothing(cell) {
            self.pass_over();
            return ControlFlow::Continue(());
        }
        let sample = self.sample_at(t, cell, param);
        let Some(emission) = self.acc.take(&sample, self.ray, self.work.stats) else {
            return ControlFlow::Continue(());
        };
        let start = match between {
            Some(b) => b.entry,
            None => self.segment_start(t, (cell, param), was_in, after_jump),
        };
        let end = t + 0.5 * self.frame.options.step;
        let segment = Segment { start, end };
        let open = self.acc.composite(emission, t, segment, (cell, param));
        // Without boundary segments no sample is ever cut at an exit crossing.
        self.open = self.frame.options.boundary_segments.then_some(open);
        self.stop_if_opaque(t, (cell, param))
    }

    /// A sample in a cell that adds nothing: counted, and where the locator can, the ray
    /// jumps over the samples up to the next that may add something.
    fn pass_over(&mut self) {
        A::count_passed(self.work.stats);
        let t_next = self.steps.next();
        if let Some(until) = self.locator.jump(t_next, &self.acc, &mut self.work) {
            A::count_jump(self.work.stats);
            self.steps.pass_over(until, self.ray.t_out, self.work.stats);
            self.was_in = false;
            self.jumped = true;
        }
    }

    /// Where the segment of the sample at `t` in `inside` starts where the position before it
    /// was outside the mesh: at the crossing (the ray's start counts as outside unless it is
    /// in the mesh); `None` for its step's own start.
    fn segment_start(
        &mut self,
        t: f64,
        inside: (u32, DVec3),
        was_in: bool,
        after_jump: bool,
    ) -> Option<f64> {
        if was_in || !self.frame.options.boundary_segments {
            return None;
        }
        let boundary = &self.frame.boundary;
        let t_prev = self.steps.before_last();
        // An earlier sample not located is outside; one jumped over or the ray's start may be
        // either.
        let stretch = Stretch {
            ray: self.ray,
            t_inside: t,
            t: t_prev,
            inside_cell: inside.0,
        };
        let outside = (self.steps.has_earlier() && !after_jump)
            || boundary
                .locate(stretch, inside.0, inside.1, &mut self.work)
                .is_none();
        outside.then(|| boundary.crossing(self.ray, t_prev, t, inside, &mut self.work))
    }

    /// Stops the ray where it is opaque enough, after seeing whether it leaves the mesh before
    /// the next sample (the last sample's segment then ends at the crossing).
    fn stop_if_opaque(&mut self, t: f64, inside: (u32, DVec3)) -> ControlFlow<bool> {
        let early_termination = self.frame.options.early_termination;
        if self.acc.opacity() < early_termination {
            return ControlFlow::Continue(());
        }
        if let Some(open) = self.open.take() {
            let boundary = &self.frame.boundary;
            let t_next = self.steps.next().min(self.ray.t_out);
            let stretch = Stretch {
                ray: self.ray,
                t_inside: t,
                t: t_next,
                inside_cell: inside.0,
            };
            if boundary
                .locate(stretch, inside.0, inside.1, &mut self.work)
                .is_none()
            {
                let e = boundary.crossing(self.ray, t_next, t, open.inside, &mut self.work);
                self.acc.recomposite(open, e);
            }
        }
        if self.acc.opacity() >= early_termination {
            self.work.stats.early_terminations += 1;
            return ControlFlow::Break(true);
        }
        ControlFlow::Continue(())
    }

    /// The ray's end: where it is outside the mesh, the last sample ends at the crossing;
    /// where it is in the mesh on a clipping plane, at the plane. Where the boundary surface
    /// tells the crossings since the last position, the pieces of the ray in the mesh after it
    /// are chords (the whole ray's, where it is too short for a sample); on the fast path, not
    /// where the surface proved the ray outside up to its end.
    fn end(&mut self, terminated: bool) {
        let ray = self.ray;
        let t_out = ray.t_out;
        let (t_last, last_end) = self.steps.before_next(ray, self.was_in, self.jumped);
        let may_cross = !(last_end == End::Outside && self.locator.outside_through(t_out));
        let between = if !terminated && may_cross && t_out.is_finite() && t_last < t_out {
            let (from, to) = ((t_last, last_end), (t_out, ray.end));
            self.frame.boundary.between(ray, from, to, &mut self.work)
        } else {
            None
        };
        if let Some(b) = between {
            if let Some(open) = self.open.take() {
                match b.exit {
                    Some(e) => self.acc.recomposite(open, e),
                    None if ray.ends_on_plane => self.acc.recomposite(open, t_out),
                    None => {}
                }
            }
            // The ray ends here, so whether the chords make it opaque changes nothing.
            self.composite_chords(b.chords());
        } else if let Some(open) = self.open.take() {
            if t_out.is_finite() {
                let boundary = &self.frame.boundary;
                let stretch = Stretch {
                    ray,
                    t_inside: open.t,
                    t: t_out,
                    inside_cell: open.inside.0,
                };
                if boundary
                    .locate(stretch, open.inside.0, open.inside.1, &mut self.work)
                    .is_none()
                {
                    let e = boundary.crossing(ray, t_out, open.t, open.inside, &mut self.work);
                    self.acc.recomposite(open, e);
                } else if ray.ends_on_plane {
                    self.acc.recomposite(open, t_out);
                }
            }
        }
    }

    /// The ray left the mesh before `t_outside`: the open segment ends at the crossing, where
    /// it is `known` (an exit proved by parity) or found.
    fn close_open(&mut self, t_outside: f64, known: Option<f64>) {
        if let Some(open) = self.open.take() {
            let e = known.unwrap_or_else(|| {
                self.frame.boundary.crossing(
                    self.ray,
                    t_outside,
                    open.t,
                    open.inside,
                    &mut self.work,
                )
            });
            self.acc.recomposite(open, e);
        }
    }

    /// Composites the chords between two positions; `Break(true)` where they make the ray
    /// opaque enough to stop (counted as an early termination).
    fn chords_or_stop(&mut self, between: Option<&Between>) -> ControlFlow<bool> {
        let chords = between.map_or(&[][..], |b| b.chords());
        if !chords.is_empty() && self.composite_chords(chords) {
            self.work.stats.early_terminations += 1;
            return ControlFlow::Break(true);
        }
        ControlFlow::Continue(())
    }

    /// Samples each of `chords` (pieces of the ray in the mesh that hold no sample, front to
    /// back) once at its middle, standing for its own length, and accumulates it. A middle
    /// located nowhere (a chord too thin for the inverse map's tolerance) or in a cell that
    /// adds nothing adds nothing. Returns whether the ray is now opaque enough to stop.
    fn composite_chords(&mut self, chords: &[Chord]) -> bool {
        for chord in chords {
            if chord.length().partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                continue;
            }
            let before = self.work.counters.hex_tests;
            let found = self.locator.locate_chord(chord, &mut self.work);
            self.work.stats.boundary_refinements += self.work.counters.hex_tests - before;
            let Some((cell, q)) = found else {
                continue;
            };
            self.work.stats.chord_samples += 1;
            if self.acc.chord_adds_nothing(cell) {
                continue;
            }
            let sample = self.sample_at(chord.middle(), cell, q);
            let Some(emission) = self.acc.take(&sample, self.ray, self.work.stats) else {
                continue;
            };
            let segment = Segment {
                start: Some(chord.start),
                end: chord.end,
            };
            self.acc
                .composite(emission, sample.t, segment, (cell, sample.param));
        }
        self.acc.opacity() >= self.frame.options.early_termination
    }

    /// The scalar at parameters `param` of `cell` (clamped to its cube), for the sample at `t`.
    fn sample_at(&self, t: f64, cell: u32, param: DVec3) -> Sample {
        let param = param.clamp(DVec3::ZERO, DVec3::ONE);
        let interpolation = self.frame.options.interpolation;
        let (scalar, values) = self.frame.volume.scalar_at(cell, param, interpolation);
        Sample {
            t,
            cell,
            param,
            scalar,
            values,
        }
    }
}
