//! The price of accuracy: images rendered at several sample steps compared with a converged
//! reference, their errors, their times, and the observed order of convergence.
//!
//! # Steps
//! Steps are multiples of the **mean cell size** ([`mean_cell_size`]): the mean over the
//! mesh's cells of each cell's axis-aligned bounding-box diagonal divided by `√3` (the edge of
//! the cube with that diagonal). [`crate::render::default_step`] is half of it. A study
//! renders at [`STEP_FACTORS`] × that size (2, 1, ½, ¼, ⅛) and compares each image with a
//! reference rendered at [`REFERENCE_FACTOR`] (1/32) × the size, everything else equal.
//!
//! # Images and errors
//! Every image here is composited in `f64`: [`render_f64`] casts the rays through
//! [`Renderer::cast`] — the routine [`Renderer::render`] runs per pixel — and keeps its `f64`
//! premultiplied RGBA, where [`crate::render::Image`] would round to `f32` (a relative
//! `6e-8`, far below the errors measured, but needless for a reference). Errors are in
//! `[0, 1]` RGBA units: the premultiplied `[r, g, b, a]` of the image composited over a black
//! background (which leaves premultiplied colour unchanged), per channel. `rmse` is the root
//! mean square over all pixels and all four channels; `max_err` is the largest absolute
//! difference of any channel of any pixel ([`compare`]).
//!
//! # Order
//! With the steps halving, the observed order between two successive runs is
//! `log2(rmse_i / rmse_{i+1})` ([`observed_orders`]); [`fitted_order`] is the least-squares
//! slope of `log rmse` against `log step` over all runs. The midpoint rule on a smooth
//! integrand is second order; the integrand along a ray jumps where the ray enters or leaves
//! the mesh (and has kinks at cell faces and transfer-function breakpoints), which makes the
//! image error first order in the step, so an order near 1 is what to expect. The reference
//! itself is off by its own `(1/32)^p` share: with `p = 1`, the ⅛ run's measured error is
//! about ¾ of its true error, which raises the last observed order slightly.

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use cylvol::error::show_number;
use cylvol::render::{
    default_step, Camera, Copies, RayGenerator, RenderOptions, RenderStats, Renderer, Topology,
    TransferFunction, Volume,
};
use cylvol::{Error, Mesh};

/// The study's steps as multiples of the mean cell size, coarse to fine.
pub const STEP_FACTORS: [f64; 5] = [2.0, 1.0, 0.5, 0.25, 0.125];

/// The reference's step as a multiple of the mean cell size.
pub const REFERENCE_FACTOR: f64 = 1.0 / 32.0;

/// The mean cell size: the mean over cells of the bounding-box diagonal ÷ `√3`, i.e. twice
/// [`default_step`] (including its fallback for meshes of flat cells).
pub fn mean_cell_size(mesh: &Mesh) -> f64 {
    2.0 * default_step(mesh)
}

/// An image's premultiplied `f64` RGBA, rows top to bottom.
pub type Rgba64 = Vec<[f64; 4]>;

/// Renders the image seen by `camera` with `f64` pixels (rows in parallel) and the work done.
pub fn render_f64(
    renderer: &Renderer<'_>,
    camera: &Camera,
) -> Result<(Rgba64, RenderStats), Error> {
    let (w, h) = (renderer.options().width, renderer.options().height);
    let rays = RayGenerator::new(camera, w, h)?;
    let rows: Vec<(Rgba64, RenderStats)> = (0..h)
        .into_par_iter()
        .map(|j| {
            let mut stats = RenderStats::default();
            let row = (0..w)
                .map(|i| {
                    let (o, d) = rays.ray(i, j);
                    renderer.cast(o, d, f64::INFINITY, &mut stats).rgba
                })
                .collect();
            (row, stats)
        })
        .collect();
    let mut image = Vec::with_capacity(w as usize * h as usize);
    let mut stats = RenderStats::default();
    for (row, s) in rows {
        image.extend(row);
        stats += s;
    }
    Ok((image, stats))
}

/// The error of an image against a reference, in `[0, 1]` RGBA units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ImageError {
    /// Root mean square over all pixels and channels.
    pub rmse: f64,
    /// Largest absolute difference of any channel of any pixel.
    pub max_err: f64,
}

/// Compares two images of the same size channel by channel.
pub fn compare(image: &[[f64; 4]], reference: &[[f64; 4]]) -> Result<ImageError, Error> {
    if image.len() != reference.len() {
        return Err(Error::Invalid(format!(
            "cannot compare an image of {} pixels with one of {}",
            image.len(),
            reference.len()
        )));
    }
    let (sum, max) = image
        .par_iter()
        .zip(reference)
        .map(|(a, b)| {
            let mut sum = 0.0f64;
            let mut max = 0.0f64;
            for k in 0..4 {
                let d = (a[k] - b[k]).abs();
                sum += d * d;
                max = max.max(d);
            }
            (sum, max)
        })
        .reduce(|| (0.0, 0.0), |x, y| (x.0 + y.0, x.1.max(y.1)));
    let n = (image.len() * 4).max(1) as f64;
    Ok(ImageError {
        rmse: (sum / n).sqrt(),
        max_err: max,
    })
}

/// One image of a study.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Run {
    /// Sample spacing in world units.
    pub step: f64,
    /// The step as a multiple of the mean cell size.
    pub factor: f64,
    /// Wall time of the render (the rays only; no structure, table or comparison).
    pub time_s: f64,
    /// Samples taken.
    pub samples: u64,
    /// Root-mean-square error against the reference.
    pub rmse: f64,
    /// Largest error against the reference.
    pub max_err: f64,
}

/// The reference of a study.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Reference {
    /// Sample spacing in world units.
    pub step: f64,
    /// The step as a multiple of the mean cell size.
    pub factor: f64,
    /// Wall time of the render.
    pub time_s: f64,
    /// Samples taken.
    pub samples: u64,
}

/// What a study renders: a volume, its transfer function, the options (their `step` is
/// replaced by each run's), the fast path's neighbours and the camera.
#[derive(Clone, Copy)]
pub struct Scene<'a> {
    /// The mesh, structure and scalars.
    pub volume: &'a Volume<'a>,
    /// The transfer function.
    pub transfer: &'a TransferFunction,
    /// Everything but the step.
    pub options: RenderOptions,
    /// Face neighbours for the fast path.
    pub neighbours: &'a Topology,
    /// The view.
    pub camera: &'a Camera,
    /// The periodic copies drawn instead of the mesh alone, if any.
    pub copies: Option<Copies>,
}

impl Scene<'_> {
    /// The renderer of this scene with `options` (its copies, if any).
    pub fn renderer(&self, options: &RenderOptions) -> Result<Renderer<'_>, Error> {
        let renderer =
            Renderer::new(self.volume, self.transfer, options)?.with_topology(self.neighbours);
        match self.copies {
            Some(c) => renderer.with_copies(c),
            None => Ok(renderer),
        }
    }

    /// Renders at `step` in `f64`, timed.
    pub fn render_at(&self, step: f64) -> Result<(Rgba64, RenderStats, f64), Error> {
        let options = RenderOptions {
            step,
            ..self.options
        };
        let renderer = self.renderer(&options)?;
        let started = Instant::now();
        let (image, stats) = render_f64(&renderer, self.camera)?;
        Ok((image, stats, started.elapsed().as_secs_f64()))
    }

    /// Renders at `base × factor` and measures it against `reference`.
    pub fn run(&self, base: f64, factor: f64, reference: &[[f64; 4]]) -> Result<Run, Error> {
        let step = base * factor;
        let (image, stats, time_s) = self.render_at(step)?;
        let e = compare(&image, reference)?;
        Ok(Run {
            step,
            factor,
            time_s,
            samples: stats.samples,
            rmse: e.rmse,
            max_err: e.max_err,
        })
    }
}

/// A step study: the reference, the runs (coarse to fine) and the observed orders.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StepStudy {
    /// The mean cell size the factors multiply.
    pub mean_cell_size: f64,
    /// The converged reference.
    pub reference: Reference,
    /// One run per factor, in the order given.
    pub runs: Vec<Run>,
    /// [`observed_orders`] of the runs.
    pub order: Vec<Option<f64>>,
    /// [`fitted_order`] of the runs.
    pub order_fit: Option<f64>,
}

/// Renders the reference at `reference_factor × base`, then one run per factor, calling
/// `progress` with a line after each image.
pub fn step_study(
    scene: &Scene<'_>,
    base: f64,
    factors: &[f64],
    reference_factor: f64,
    mut progress: impl FnMut(&str),
) -> Result<(StepStudy, Rgba64), Error> {
    if !(base > 0.0 && base.is_finite()) {
        return Err(Error::Invalid(format!(
            "bad mean cell size {}",
            show_number(base)
        )));
    }
    let step = base * reference_factor;
    let (reference_image, stats, time_s) = scene.render_at(step)?;
    progress(&format!(
        "reference at {reference_factor} × mean cell size (step {step:.4e}): {} samples, {time_s:.2} s",
        stats.samples
    ));
    let reference = Reference {
        step,
        factor: reference_factor,
        time_s,
        samples: stats.samples,
    };
    let mut runs = Vec::with_capacity(factors.len());
    for &factor in factors {
        let run = scene.run(base, factor, &reference_image)?;
        progress(&format!(
            "step {factor} × mean cell size ({:.4e}): {:.3} s, rmse {:.3e}, max {:.3e}",
            run.step, run.time_s, run.rmse, run.max_err
        ));
        runs.push(run);
    }
    let order = observed_orders(&runs);
    let order_fit = fitted_order(&runs);
    Ok((
        StepStudy {
            mean_cell_size: base,
            reference,
            runs,
            order,
            order_fit,
        },
        reference_image,
    ))
}

/// The order observed between successive runs: `ln(rmse_i / rmse_{i+1}) / ln(step_i /
/// step_{i+1})` (`log2` of the rmse ratio when the step halves); `None` where an error is zero
/// or the steps are equal.
pub fn observed_orders(runs: &[Run]) -> Vec<Option<f64>> {
    runs.windows(2)
        .map(|w| {
            let (a, b) = (&w[0], &w[1]);
            let den = (a.step / b.step).ln();
            let num = (a.rmse / b.rmse).ln();
            (num.is_finite() && den.is_finite() && den != 0.0).then_some(num / den)
        })
        .collect()
}

/// The least-squares slope of `ln rmse` against `ln step` over the runs with a positive
/// error; `None` with fewer than two such runs of different steps.
pub fn fitted_order(runs: &[Run]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = runs
        .iter()
        .filter(|r| r.rmse > 0.0 && r.step > 0.0)
        .map(|r| (r.step.ln(), r.rmse.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// A factor as a short label: `2×`, `1×`, `1/2×`, `1/8×`.
pub fn factor_label(factor: f64) -> String {
    if factor >= 1.0 {
        format!("{factor}×")
    } else {
        let inv = 1.0 / factor;
        if (inv - inv.round()).abs() < 1e-9 {
            format!("1/{}×", inv.round())
        } else {
            format!("{factor}×")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(step: f64, rmse: f64) -> Run {
        Run {
            step,
            factor: step,
            time_s: 0.0,
            samples: 0,
            rmse,
            max_err: rmse,
        }
    }

    #[test]
    fn compare_rejects_different_sizes_and_measures_channels() {
        assert!(compare(&[[0.0; 4]], &[]).is_err());
        let e = compare(&[[0.1, 0.0, 0.0, 0.0]], &[[0.0, 0.0, 0.0, 0.3]]).unwrap();
        assert!((e.max_err - 0.3).abs() < 1e-15);
        assert!((e.rmse - ((0.01 + 0.09) / 4.0f64).sqrt()).abs() < 1e-15);
        assert_eq!(compare(&[], &[]).unwrap().rmse, 0.0);
    }

    #[test]
    fn orders_of_power_laws() {
        let runs: Vec<Run> = [1.0, 0.5, 0.25, 0.125]
            .iter()
            .map(|&h| run(h, 3.0 * h * h))
            .collect();
        for o in observed_orders(&runs) {
            assert!((o.unwrap() - 2.0).abs() < 1e-12);
        }
        assert!((fitted_order(&runs).unwrap() - 2.0).abs() < 1e-12);
        assert_eq!(observed_orders(&[run(1.0, 0.0), run(0.5, 0.0)]), vec![None]);
        assert_eq!(fitted_order(&[run(1.0, 0.1)]), None);
    }

    #[test]
    fn compare_and_order_of_two_images() {
        let a = vec![[0.0, 0.0, 0.0, 0.0], [0.5, 0.5, 0.5, 1.0]];
        let b = vec![[0.0, 0.0, 0.0, 0.0], [0.5, 0.5, 0.5, 0.5]];
        let e = compare(&a, &b).unwrap();
        assert_eq!(e.max_err, 0.5);
        assert!((e.rmse - (0.25f64 / 8.0).sqrt()).abs() < 1e-15);
        assert_eq!(
            observed_orders(&[run(1.0, 0.4), run(0.5, 0.1)]),
            vec![Some(2.0)]
        );
    }

    #[test]
    fn factor_labels() {
        assert_eq!(factor_label(2.0), "2×");
        assert_eq!(factor_label(1.0), "1×");
        assert_eq!(factor_label(0.125), "1/8×");
        assert_eq!(factor_label(0.3), "0.3×");
    }
}
