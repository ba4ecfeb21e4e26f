//! Where a ray's samples lie: the stepping policy ([`Steps`]). Each sample stands for a segment
//! of the ray and lies in its middle (the midpoint rule).
//!
//! - [`FixedSteps`]: samples at `t_k = t_in + (k + ½)·step`, `k = 0, 1, …` while `t_k < t_out`,
//!   each standing for a segment of length `step`, so the transfer table's opacities are
//!   corrected to `step`.
//! - [`AdaptiveSteps`]: each segment starts where the one before ends and is as long as the
//!   step last set ([`Steps::set_step`]: the error-bounded integration's choice after each
//!   sample, [`crate::render::accumulate::integrate`]); a ray starts with the options' step,
//!   and the segments start anew where a stretch passed over ends (so the samples of an
//!   error-bounded render depend on where the structure's jump lands: its image is the same
//!   within the error, not bit for bit, across structures and paths).
//!
//! Positions passed over (outside the mesh, transparent space) advance by the current step
//! and are counted as samples and as skips of empty space.

use crate::render::ray::{End, Ray};
use crate::render::stats::RenderStats;

/// A kind of stepping policy, chosen once per render (its per-ray state is `Self`).
pub(crate) trait Steps: Sized {
    /// The positions from `t_in` on, starting with segments of `step`.
    fn new(t_in: f64, step: f64) -> Self;

    /// Where the next sample lies.
    fn next(&self) -> f64;

    /// The next sample is taken (counted in `samples`).
    fn take(&mut self, stats: &mut RenderStats);

    /// The segment of the last sample taken, at `t`: where it starts and ends.
    fn taken_segment(&self, t: f64) -> (f64, f64);

    /// The segments from the next sample on are `step` long (a fixed policy keeps its own).
    fn set_step(&mut self, step: f64);

    /// Whether a sample was taken before the last one taken.
    fn has_earlier(&self) -> bool;

    /// Where the sample before the last one taken lies, or the ray's start.
    fn before_last(&self) -> f64;

    /// Passes over the samples before `until` (and the ray's end), counted as samples and
    /// as skips of empty space.
    fn pass_over(&mut self, until: f64, t_out: f64, stats: &mut RenderStats);

    /// What is known of the position before the last sample taken: the ray's start for the
    /// first, else the sample before it, in the mesh (`was_in`), passed over by a jump
    /// (`after_jump`), or outside.
    fn before_taken(&self, ray: &Ray, was_in: bool, after_jump: bool) -> (f64, End);

    /// What is known of the position before the next sample: the last position of the ray.
    fn before_next(&self, ray: &Ray, was_in: bool, after_jump: bool) -> (f64, End);
}

/// What is known of the position `t_before` before a sample, `first` where there is none.
fn before(t_before: f64, first: bool, ray: &Ray, was_in: bool, after_jump: bool) -> (f64, End) {
    if first {
        (ray.t_in, ray.start)
    } else if was_in {
        (t_before, End::Sample)
    } else if after_jump {
        (t_before, End::Passed)
    } else {
        (t_before, End::Outside)
    }
}

/// Samples every `step` from `t_in` (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub(crate) struct FixedSteps {
    t_in: f64,
    step: f64,
    /// The index of the next sample.
    k: u64,
}

impl FixedSteps {
    /// Where sample `k` lies.
    #[inline]
    fn t(&self, k: u64) -> f64 {
        self.t_in + (k as f64 + 0.5) * self.step
    }
}

impl Steps for FixedSteps {
    fn new(t_in: f64, step: f64) -> FixedSteps {
        FixedSteps { t_in, step, k: 0 }
    }

    #[inline]
    fn next(&self) -> f64 {
        self.t(self.k)
    }

    #[inline]
    fn take(&mut self, stats: &mut RenderStats) {
        stats.samples += 1;
        self.k += 1;
    }

    #[inline]
    fn taken_segment(&self, t: f64) -> (f64, f64) {
        (t - 0.5 * self.step, t + 0.5 * self.step)
    }

    #[inline]
    fn set_step(&mut self, _step: f64) {}

    #[inline]
    fn has_earlier(&self) -> bool {
        self.k >= 2
    }

    fn before_last(&self) -> f64 {
        if self.k >= 2 {
            self.t(self.k - 2)
        } else {
            self.t_in
        }
    }

    fn pass_over(&mut self, until: f64, t_out: f64, stats: &mut RenderStats) {
        while self.t(self.k) < until.min(t_out) {
            stats.samples += 1;
            stats.space_skips += 1;
            self.k += 1;
        }
    }

    fn before_taken(&self, ray: &Ray, was_in: bool, after_jump: bool) -> (f64, End) {
        let j = self.k - 1;
        let t_before = if j == 0 { ray.t_in } else { self.t(j - 1) };
        before(t_before, j == 0, ray, was_in, after_jump)
    }

    fn before_next(&self, ray: &Ray, was_in: bool, after_jump: bool) -> (f64, End) {
        let j = self.k;
        let t_before = if j == 0 { ray.t_in } else { self.t(j - 1) };
        before(t_before, j == 0, ray, was_in, after_jump)
    }
}

/// Segments that follow one another, each as long as the step last set (see the module
/// documentation).
#[derive(Clone, Copy, Debug)]
pub(crate) struct AdaptiveSteps {
    t_in: f64,
    /// Where the next sample's segment starts.
    start: f64,
    /// The next sample's segment length.
    step: f64,
    /// The last two positions taken or passed over, the last first (NaN: none).
    behind: [f64; 2],
    /// The positions taken or passed over so far.
    k: u64,
}

impl AdaptiveSteps {
    /// Moves on past the next position.
    #[inline]
    fn advance(&mut self) {
        self.behind = [self.next(), self.behind[0]];
        self.start += self.step;
        self.k += 1;
    }
}

impl Steps for AdaptiveSteps {
    fn new(t_in: f64, step: f64) -> AdaptiveSteps {
        AdaptiveSteps {
            t_in,
            start: t_in,
            step,
            behind: [f64::NAN; 2],
            k: 0,
        }
    }

    #[inline]
    fn next(&self) -> f64 {
        self.start + 0.5 * self.step
    }

    #[inline]
    fn take(&mut self, stats: &mut RenderStats) {
        stats.samples += 1;
        self.advance();
    }

    #[inline]
    fn taken_segment(&self, _t: f64) -> (f64, f64) {
        (self.start - self.step, self.start)
    }

    #[inline]
    fn set_step(&mut self, step: f64) {
        self.step = step;
    }

    #[inline]
    fn has_earlier(&self) -> bool {
        self.k >= 2
    }

    fn before_last(&self) -> f64 {
        if self.k >= 2 {
            self.behind[1]
        } else {
            self.t_in
        }
    }

    fn pass_over(&mut self, until: f64, t_out: f64, stats: &mut RenderStats) {
        let until = until.min(t_out);
        let next = self.next();
        if next.is_nan() || next >= until {
            return;
        }
        // The positions before `until`, counted at once: `n` of them, the last `n − 1` steps on.
        let n = ((until - self.next()) / self.step).ceil().max(1.0);
        let last = self.next() + (n - 1.0) * self.step;
        self.behind = [
            last,
            if n >= 2.0 {
                last - self.step
            } else {
                self.behind[0]
            },
        ];
        // The segments start anew where the stretch passed over ends.
        self.start = until;
        self.k += n as u64;
        stats.samples += n as u64;
        stats.space_skips += n as u64;
    }

    fn before_taken(&self, ray: &Ray, was_in: bool, after_jump: bool) -> (f64, End) {
        before(self.behind[1], self.k <= 1, ray, was_in, after_jump)
    }

    fn before_next(&self, ray: &Ray, was_in: bool, after_jump: bool) -> (f64, End) {
        before(self.behind[0], self.k == 0, ray, was_in, after_jump)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adaptive_segments_follow_one_another() {
        let mut stats = RenderStats::default();
        let mut s = AdaptiveSteps::new(1.0, 0.5);
        assert_eq!(s.next(), 1.25);
        s.take(&mut stats);
        assert_eq!(s.taken_segment(1.25), (1.0, 1.5));
        s.set_step(0.25);
        assert_eq!(s.next(), 1.625);
        s.take(&mut stats);
        assert_eq!(s.taken_segment(1.625), (1.5, 1.75));
        assert_eq!(s.before_last(), 1.25);
        s.pass_over(2.3, 10.0, &mut stats);
        // 1.875, 2.125 passed; the segments start anew at 2.3.
        assert_eq!(s.next(), 2.425);
        assert_eq!(s.before_last(), 1.875);
        assert_eq!((stats.samples, stats.space_skips), (4, 2));
    }

    #[test]
    fn fixed_steps_are_the_grid() {
        let mut stats = RenderStats::default();
        let mut s = FixedSteps::new(0.0, 0.1);
        s.pass_over(0.31, 1.0, &mut stats);
        assert_eq!(s.next(), 0.0 + 3.5 * 0.1);
        assert_eq!(stats.space_skips, 3);
        s.set_step(5.0);
        assert_eq!(s.next(), 0.35000000000000003);
    }
}
