//! Where a ray's samples lie: the stepping policy. Samples lie at
//! `t_k = t_in + (k + ½)·step`, `k = 0, 1, …` while `t_k < t_out`; each stands for a segment
//! of length `step` (the midpoint rule), so the transfer table's opacities are corrected to
//! `step`.

use crate::render::ray::{End, Ray};
use crate::render::stats::RenderStats;

/// The sample positions along one ray, and which is next.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Steps {
    t_in: f64,
    step: f64,
    /// The index of the next sample.
    k: u64,
}

impl Steps {
    /// The positions from `t_in` on, `step` apart.
    pub(crate) fn new(t_in: f64, step: f64) -> Steps {
        Steps { t_in, step, k: 0 }
    }

    /// Where sample `k` lies.
    #[inline]
    fn t(&self, k: u64) -> f64 {
        self.t_in + (k as f64 + 0.5) * self.step
    }

    /// Where the next sample lies.
    #[inline]
    pub(crate) fn next(&self) -> f64 {
        self.t(self.k)
    }

    /// The next sample is taken (counted in `samples`).
    #[inline]
    pub(crate) fn take(&mut self, stats: &mut RenderStats) {
        stats.samples += 1;
        self.k += 1;
    }

    /// Whether a sample was taken before the last one taken.
    #[inline]
    pub(crate) fn has_earlier(&self) -> bool {
        self.k >= 2
    }

    /// Where the sample before the last one taken lies, or the ray's start.
    pub(crate) fn before_last(&self) -> f64 {
        if self.k >= 2 {
            self.t(self.k - 2)
        } else {
            self.t_in
        }
    }

    /// Passes over the samples before `until` (and the ray's end), counted as samples and
    /// as skips of empty space.
    pub(crate) fn pass_over(&mut self, until: f64, t_out: f64, stats: &mut RenderStats) {
        while self.t(self.k) < until.min(t_out) {
            stats.samples += 1;
            stats.space_skips += 1;
            self.k += 1;
        }
    }

    /// What is known of the position before sample `j`: the ray's start for the first, else
    /// the sample before it, in the mesh (`was_in`), passed over by a jump (`after_jump`), or
    /// outside.
    fn before(&self, j: u64, ray: &Ray, was_in: bool, after_jump: bool) -> (f64, End) {
        if j == 0 {
            (ray.t_in, ray.start)
        } else if was_in {
            (self.t(j - 1), End::Sample)
        } else if after_jump {
            (self.t(j - 1), End::Passed)
        } else {
            (self.t(j - 1), End::Outside)
        }
    }

    /// [`Steps::before`] the last sample taken.
    pub(crate) fn before_taken(&self, ray: &Ray, was_in: bool, after_jump: bool) -> (f64, End) {
        self.before(self.k - 1, ray, was_in, after_jump)
    }

    /// [`Steps::before`] the next sample: the last position of the ray.
    pub(crate) fn before_next(&self, ray: &Ray, was_in: bool, after_jump: bool) -> (f64, End) {
        self.before(self.k, ray, was_in, after_jump)
    }
}
