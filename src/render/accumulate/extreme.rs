//! Maximum- and minimum-intensity projection: a ray keeps the largest (smallest) scalar
//! interpolated at its samples in the mesh, and its pixel is that scalar's colour with that
//! scalar's opacity per unit distance, premultiplied; the depth is the extreme sample's `t`
//! where its opacity reaches the depth opacity. Nothing is composited: the ray accumulates no
//! opacity. The fast path passes over the samples in cells whose scalar range cannot beat the
//! extreme so far, and on a BVH jumps over them.

use glam::DVec3;

use super::{Accumulate, Emission, Open, RayResult, Sample, Segment};
use crate::accel::bvh::NodeRanges;
use crate::accel::{Accel, Counters, RaySpan};
use crate::render::cast::steps::FixedSteps;
use crate::render::frame::Frame;
use crate::render::options::Blend;
use crate::render::ray::Ray;
use crate::render::stats::RenderStats;

/// One ray's extreme scalar.
pub(crate) struct Extreme<'f> {
    frame: &'f Frame<'f>,
    blend: Blend,
    /// Whether the path passes over the cells that cannot beat the extreme (the fast one).
    passes: bool,
    /// The scalar range below each node of a BVH, for the jumps.
    ranges: Option<&'f NodeRanges>,
    /// The extreme scalar so far and its `t`.
    best: Option<(f64, f64)>,
}

impl<'f> Extreme<'f> {
    /// No extreme yet.
    pub(crate) fn new(frame: &'f Frame<'f>) -> Extreme<'f> {
        Extreme {
            frame,
            blend: frame.options.blend,
            passes: frame.fast(),
            ranges: frame.ranges,
            best: None,
        }
    }
}

impl Accumulate for Extreme<'_> {
    type Steps = FixedSteps;

    #[inline]
    fn adds_nothing(&self, cell: u32) -> bool {
        self.passes
            && !self.blend.may_replace_in(
                self.frame.cell_ranges[cell as usize],
                self.best.map(|e| e.0),
            )
    }

    fn chord_adds_nothing(&self, _cell: u32) -> bool {
        false
    }

    fn count_passed(stats: &mut RenderStats) {
        stats.extreme_skips += 1;
    }

    fn count_jump(stats: &mut RenderStats) {
        stats.extreme_jumps += 1;
    }

    fn next_adding(
        &self,
        accel: &Accel,
        span: RaySpan,
        counters: &mut Counters,
    ) -> Option<Option<(f64, f64, Option<u32>)>> {
        let ranges = self.ranges?;
        let best = self.best.map(|e| e.0);
        let node = |r: [f64; 2]| self.blend.may_replace_in(r, best);
        Some(accel.next_in_ranges(span, ranges, node, |c| !self.adds_nothing(c), counters))
    }

    #[inline]
    fn take(&mut self, sample: &Sample, _ray: &Ray, _stats: &mut RenderStats) -> Option<Emission> {
        if self.blend.replaces(sample.scalar, self.best.map(|e| e.0)) {
            self.best = Some((sample.scalar, sample.t));
        }
        None
    }

    fn composite(
        &mut self,
        emission: Emission,
        t: f64,
        segment: Segment,
        inside: (u32, DVec3),
    ) -> Open {
        // A projection takes no emission: nothing to composite.
        Open {
            t,
            start: segment.start,
            emission,
            inside,
            before: (1.0, [0.0; 3], f64::INFINITY),
        }
    }

    fn recomposite(&mut self, _open: Open, _end: f64) {}

    fn opacity(&self) -> f64 {
        0.0
    }

    fn finish(self) -> RayResult {
        let Some((s, t)) = self.best else {
            return RayResult::NONE;
        };
        let table = self.frame.table;
        let [r, g, b, _] = table.lookup(s);
        let a = table.unit_opacity(s).clamp(0.0, 1.0);
        RayResult {
            rgba: [r * a, g * a, b * a, a],
            depth: if a > 0.0 && a >= self.frame.options.depth_opacity {
                t
            } else {
                f64::INFINITY
            },
        }
    }
}
