//! The error a setting achieves: images rendered with `--max-error` settings (and at the
//! default fixed step, for comparison) measured against a converged reference per pixel, and
//! timed over repeats.
//!
//! # Per-pixel error
//! A pixel's error is the largest absolute difference of its four premultiplied RGBA channels
//! (over a black background, as [`super::study`] composites them) from the reference's, in
//! 1/255 — the unit of [`cylvol::render::RenderOptions::max_error`]. A setting reports the
//! largest over the image (`max`), the 99.9th percentile (`p999`: the error that all but one
//! pixel in a thousand stay within) and the mean (`mean`).
//!
//! # Reference
//! The fixed step at [`super::study::REFERENCE_FACTOR`] × the mean cell size, with boundary
//! segments and without early termination ([`super::study`]): what every render converges to.
//!
//! # Time
//! Each image is rendered `repeats` times after one untimed render (which makes what a
//! renderer derives once: the transparent and active cells, the tables); the time reported is
//! the least of the repeats (the rays only), the one least disturbed by the machine.

use std::time::Instant;

use serde::Serialize;

use super::study::{render_f64, Rgba64, Scene};
use cylvol::render::{RenderOptions, RenderStats};
use cylvol::Error;

/// The errors of an image against the reference, per pixel, in 1/255.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PixelErrors {
    /// The largest.
    pub max: f64,
    /// The 99.9th percentile.
    pub p999: f64,
    /// The mean.
    pub mean: f64,
}

/// One image of a settings study: what was asked, what it cost, what it achieved.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SettingRun {
    /// The error asked for, in 1/255 (`None`: the fixed step).
    pub max_error: Option<f64>,
    /// The step (the first of each ray where an error is asked for).
    pub step: f64,
    /// The least render time over the repeats, in seconds.
    pub time_s: f64,
    /// Samples taken.
    pub samples: u64,
    /// Samples an error-bounded render added between others.
    pub refined_samples: u64,
    /// Its errors against the reference.
    pub error: PixelErrors,
}

/// Each pixel's error: the largest channel difference, in 1/255.
pub fn pixel_errors(image: &[[f64; 4]], reference: &[[f64; 4]]) -> Vec<f64> {
    image
        .iter()
        .zip(reference)
        .map(|(a, b)| {
            (0..4)
                .map(|k| (a[k] - b[k]).abs() * 255.0)
                .fold(0.0, f64::max)
        })
        .collect()
}

/// The largest, 99.9th percentile and mean of per-pixel errors (all 0 for none).
pub fn summarize(errors: &[f64]) -> PixelErrors {
    if errors.is_empty() {
        return PixelErrors {
            max: 0.0,
            p999: 0.0,
            mean: 0.0,
        };
    }
    let mut sorted = errors.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    // The smallest error that at least 99.9 % of the pixels stay within.
    let rank = ((0.999 * n as f64).ceil() as usize).clamp(1, n);
    PixelErrors {
        max: sorted[n - 1],
        p999: sorted[rank - 1],
        mean: sorted.iter().sum::<f64>() / n as f64,
    }
}

/// Renders `scene` with `options` once untimed, then `repeats` times timed: the image, its
/// counters and the least time.
pub fn timed(
    scene: &Scene<'_>,
    options: &RenderOptions,
    repeats: u32,
) -> Result<(Rgba64, RenderStats, f64), Error> {
    let renderer = scene.renderer(options)?;
    let (image, stats) = render_f64(&renderer, scene.camera)?;
    let mut best = f64::INFINITY;
    for _ in 0..repeats.max(1) {
        let started = Instant::now();
        render_f64(&renderer, scene.camera)?;
        best = best.min(started.elapsed().as_secs_f64());
    }
    Ok((image, stats, best))
}

/// Renders `scene` at `step` with the error `max_error` (`None`: the fixed step) and measures
/// it against `reference`.
pub fn run_setting(
    scene: &Scene<'_>,
    step: f64,
    max_error: Option<f64>,
    repeats: u32,
    reference: &[[f64; 4]],
) -> Result<SettingRun, Error> {
    let options = RenderOptions {
        step,
        max_error,
        ..scene.options
    };
    let (image, stats, time_s) = timed(scene, &options, repeats)?;
    Ok(SettingRun {
        max_error,
        step,
        time_s,
        samples: stats.samples,
        refined_samples: stats.refined_samples,
        error: summarize(&pixel_errors(&image, reference)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_of_pixel_errors() {
        let mut errors: Vec<f64> = (0..2000).map(|k| k as f64 / 1000.0).collect();
        errors.reverse();
        let s = summarize(&errors);
        assert_eq!(s.max, 1.999);
        // 1998 of 2000 pixels are within 1.997.
        assert_eq!(s.p999, 1.997);
        assert!((s.mean - 0.9995).abs() < 1e-12);
        assert_eq!(summarize(&[]).max, 0.0);
        let e = pixel_errors(&[[0.0, 0.1, 0.0, 0.5]], &[[0.0, 0.0, 0.0, 0.48]]);
        assert!((e[0] - 25.5).abs() < 1e-9);
    }
}
