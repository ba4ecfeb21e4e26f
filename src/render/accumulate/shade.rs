//! What a sample emits: the transfer function's colour and step-corrected opacity of its
//! scalar, the opacity scaled by the gradient opacity where it is on, the colour shaded where
//! shading is on. The gradient (of the trilinear interpolant) is evaluated only when shading
//! or gradient opacity needs it, and only for samples the transfer function does not make
//! transparent ([`crate::render::RenderStats::gradient_evaluations`]).

use glam::DVec3;

use super::{Emission, Sample};
use crate::geometry::trilinear::physical_gradient;
use crate::render::frame::Frame;
use crate::render::stats::RenderStats;

/// The colour (shaded where shading is on) and the opacity over a step of `sample`, seen
/// along `dir`; `None` where it adds nothing. A cell scalar has no gradient to evaluate.
#[inline]
pub(crate) fn emission(
    frame: &Frame,
    sample: &Sample,
    dir: DVec3,
    stats: &mut RenderStats,
) -> Option<Emission> {
    let opts = frame.options;
    let table = frame.table;
    let s = sample.scalar;
    let [r, g, b, mut a] = table.lookup(s);
    if a <= 0.0 || a.is_nan() {
        return None;
    }
    let grad = match sample.values {
        Some(values) if opts.shading.is_some() || opts.gradient_opacity.is_some() => {
            stats.gradient_evaluations += 1;
            physical_gradient(
                &frame.volume.mesh().cell_corners(sample.cell as usize),
                &values,
                sample.param,
            )
        }
        _ => None,
    };
    if let Some(go) = &opts.gradient_opacity {
        let f = go.at(grad.map_or(0.0, |g| g.length()));
        if f != 1.0 {
            a = table.step_opacity(table.unit_opacity(s) * f);
            if a <= 0.0 || a.is_nan() {
                return None;
            }
        }
    }
    let rgb = match &opts.shading {
        Some(shading) => shading.shade([r, g, b], grad, dir),
        None => [r, g, b],
    };
    Some(Emission { rgb, alpha_step: a })
}
