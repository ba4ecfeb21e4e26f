//! Front-to-back compositing: `C += T α c`, `T *= 1 − α`, with `α` the opacity of the sample's
//! segment and `c` its (shaded) colour. A segment of `frac` steps made of a medium whose
//! opacity over a step is `α_step` has the opacity `1 − (1 − α_step)^frac` (exactly `α_step`
//! for a whole step). The depth is the `t` of the first sample at which the accumulated
//! opacity `1 − T` reaches the options' depth opacity.

use glam::DVec3;

use super::shade::emission;
use super::transparent::TransparentSkip;
use super::{Accumulate, Emission, Open, RayResult, Sample, Segment};
use crate::accel::{Accel, Counters, RaySpan};
use crate::render::cast::steps::FixedSteps;
use crate::render::frame::Frame;
use crate::render::ray::Ray;
use crate::render::stats::RenderStats;

/// The opacity of a segment `frac` steps long made of a medium whose opacity over a full
/// step is `alpha_step`: `1 − (1 − α_step)^frac` (exactly `alpha_step` at `frac == 1`).
#[inline]
pub(crate) fn partial_opacity(alpha_step: f64, frac: f64) -> f64 {
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

/// Front-to-back accumulation along one ray.
pub(crate) struct Composite<'f> {
    frame: &'f Frame<'f>,
    /// The cells the fast path passes over, and where the structure holds the others.
    skip: TransparentSkip<'f>,
    transmittance: f64,
    color: [f64; 3],
    depth: f64,
}

impl<'f> Composite<'f> {
    /// Nothing accumulated yet.
    pub(crate) fn new(frame: &'f Frame<'f>) -> Composite<'f> {
        Composite {
            frame,
            skip: TransparentSkip::of(frame),
            transmittance: 1.0,
            color: [0.0; 3],
            depth: f64::INFINITY,
        }
    }

    /// Composites `open` over the segment from its start to `end`, from the state before it.
    fn apply(&mut self, open: &Open, end: f64) {
        let step = self.frame.options.step;
        let a = match open.start {
            None => partial_opacity(open.emission.alpha_step, 1.0),
            Some(s) => partial_opacity(open.emission.alpha_step, ((end - s) / step).max(0.0)),
        };
        (self.transmittance, self.color, self.depth) = open.before;
        let w = self.transmittance * a;
        for ch in 0..3 {
            self.color[ch] += w * open.emission.rgb[ch];
        }
        self.transmittance *= 1.0 - a;
        if self.depth.is_infinite() && 1.0 - self.transmittance >= self.frame.options.depth_opacity
        {
            self.depth = open.t;
        }
    }
}

impl Accumulate for Composite<'_> {
    type Steps = FixedSteps;

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

    #[inline]
    fn take(&mut self, sample: &Sample, ray: &Ray, stats: &mut RenderStats) -> Option<Emission> {
        emission(self.frame, sample, ray.dir, stats)
    }

    fn composite(
        &mut self,
        emission: Emission,
        t: f64,
        segment: Segment,
        inside: (u32, DVec3),
    ) -> Open {
        let open = Open {
            t,
            start: segment.start,
            emission,
            inside,
            before: (self.transmittance, self.color, self.depth),
        };
        self.apply(&open, segment.end);
        open
    }

    fn recomposite(&mut self, mut open: Open, end: f64) {
        let start = open.start.unwrap_or(open.t - 0.5 * self.frame.options.step);
        open.start = Some(start);
        self.apply(&open, end);
    }

    #[inline]
    fn opacity(&self) -> f64 {
        1.0 - self.transmittance
    }

    fn finish(self) -> RayResult {
        RayResult {
            rgba: [
                self.color[0],
                self.color[1],
                self.color[2],
                1.0 - self.transmittance,
            ],
            depth: self.depth,
        }
    }
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
}
