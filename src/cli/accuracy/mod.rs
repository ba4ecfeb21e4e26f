//! `cylvol accuracy INPUT [--json] [--plot OUT.svg] [--size N] [--structure S] [--view A,E,Z]
//! [--max-error E,E,... [--repeats R]]`:
//! the price of accuracy — images at sample steps of 2, 1, ½, ¼ and ⅛ × the mean cell size,
//! each compared with a converged reference at 1/32 × and timed
//! ([`study`] defines the mean cell size, the error units and the order; [`plot`] draws the
//! error against the time as an SVG plot); with `--max-error`, the error each setting achieves
//! against the same reference instead ([`settings`]).
//!
//! The scene is `cylvol render`'s ([`super::scene`]): the default transfer function, the
//! `--view` camera (default [`DEFAULT_VIEW`], oblique), the fast path with face neighbours through `--structure`
//! (default `auto`), an `N × N` image (default 128, so that the 1/32 reference stays quick).
//! Early termination is **off** in the runs and the reference: a ray stopped at an opacity of
//! 0.99 leaves up to 1 % of its pixel uncomputed at a distance that depends on the step, an
//! error that does not fall with the step and would hide the step's own. Its price is
//! reported apart (`termination`: the default 0.99 at ½ × against the same reference, to set
//! beside the ½ × run).
//!
//! JSON: `dataset`, `cells`, `structure`, `path`, `width`, `height`, `mean_cell_size`,
//! `reference` {`step`, `factor`, `time_s`, `samples`}, `runs` [{`step`, `factor`, `time_s`,
//! `samples`, `rmse`, `max_err`}] (coarse to fine), `order` (log2 of successive rmse ratios),
//! `order_fit` (the least-squares slope), `termination` {`threshold`, `factor`, `step`,
//! `time_s`, `rmse`, `max_err`}. `--plot` writes the error (log) against the time (log), one
//! labelled point per run.
//!
//! With `--max-error E,E,...` (in 1/255, e.g. `1,2,4`) the study renders each setting and the
//! default fixed step (½ × the mean cell size, what `--step` alone renders by default), each
//! with the renderer's early termination, on an `N × N` image (default 256), and times each
//! `--repeats` times (default 3) after an untimed render: JSON `dataset`, `cells`,
//! `structure`, `path`, `width`, `height`, `mean_cell_size`, `repeats`, `reference` {`step`,
//! `factor`, `time_s`, `samples`}, `settings` [{`max_error`, `step`, `time_s`, `samples`,
//! `refined_samples`, `error` {`max`, `p999`, `mean`}}] (in the order given), `fixed_step`
//! (the same keys, `max_error` null); errors per pixel in 1/255 ([`settings`]).

mod plot;
mod settings;
mod study;

use std::path::PathBuf;

use serde_json::{json, Value};

use super::scene::StructureChoice;
use super::{log, scene, InputArgs};
use cylvol::accel::{Accel, AccelParams};
use cylvol::render::{
    Camera, Copies, RenderOptions, RenderPath, Topology, TransferFunction, Volume,
};
use cylvol::{Error, Mesh};
use plot::{Plot, Scale, Series};
use study::{
    compare, factor_label, mean_cell_size, step_study, Scene, StepStudy, REFERENCE_FACTOR,
    STEP_FACTORS,
};

/// Arguments of `cylvol accuracy`.
#[derive(clap::Args, Debug)]
pub struct AccuracyArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Print JSON on standard output.
    #[arg(long)]
    json: bool,
    /// Write the error-against-time plot to this SVG file.
    #[arg(long, value_name = "OUT.svg")]
    plot: Option<PathBuf>,
    /// Image side N (an N×N image) [default: 128, 256 with --max-error].
    #[arg(long, value_parser = scene::parse_side, allow_hyphen_values = true)]
    size: Option<u32>,
    /// cart-grid, cyl-grid, cart-bvh, cyl-bvh or auto.
    #[arg(long, default_value = "auto")]
    structure: StructureChoice,
    /// Camera preset AZIMUTH,ELEVATION,ZOOM in degrees, degrees and a factor.
    #[arg(long, value_name = "AZIMUTH,ELEVATION,ZOOM", value_parser = scene::parse_view, allow_hyphen_values = true)]
    view: Option<[f64; 3]>,
    /// paper or fast sampling path.
    #[arg(long, default_value = "fast")]
    path: RenderPath,
    /// Every sample stands for a whole step, even where the ray crosses the mesh boundary
    /// (faster, first order in the step); by default boundary samples are cut at the crossing.
    #[arg(long)]
    whole_steps: bool,
    /// Measure these error settings (in 1/255 of a pixel's premultiplied RGBA) against the
    /// converged reference instead of the step study.
    #[arg(long, value_name = "E,E,...", value_delimiter = ',', value_parser = scene::parse_max_error, allow_hyphen_values = true)]
    max_error: Vec<f64>,
    /// The wheel of a periodic sector (see `render --periodic`).
    #[command(flatten)]
    periodic: super::periodic::PeriodicArgs,
    /// Timed renders per setting (the least time is reported).
    #[arg(long, default_value = "3", value_parser = clap::value_parser!(u32).range(1..=100), requires = "max_error")]
    repeats: u32,
}

/// The image side of the step study.
const STUDY_SIDE: u32 = 128;

/// The reference's step of a settings study as a multiple of the mean cell size: finer than
/// the step study's, so that its own error (second order in the step with boundary segments)
/// stays well below the smallest setting measured.
const SETTINGS_REFERENCE_FACTOR: f64 = 1.0 / 128.0;

/// The image side of a settings study: large enough that a render's time is mostly its rays.
const SETTINGS_SIDE: u32 = 256;

/// The default `--view` of the study: oblique (azimuth 30°, elevation 20°). Seen down the axis
/// (`cylvol render`'s default) a rotor is nearly symmetric about the line of sight and its top
/// face lies in the box face where rays start, so the pixels at one radius share one sampling
/// error: the image error then jumps about with the step instead of averaging (measured on
/// `pump-rotor:5000` at 64², successive rmse ratios 4.3, 2.0, 1.1, 2.0; oblique 3.3, 1.9,
/// 1.8, 1.9).
pub const DEFAULT_VIEW: [f64; 3] = [30.0, 20.0, 1.0];

/// Early termination threshold whose price `termination` reports (the renderer's default).
const TERMINATION: f64 = 0.99;

/// A study's report and the numbers behind it.
pub struct AccuracyResult {
    /// The JSON report (see the module documentation).
    pub report: Value,
    /// The study.
    pub study: StepStudy,
}

/// How the study samples rays.
#[derive(Clone, Copy, Debug)]
pub struct Sampling {
    /// Paper or fast path.
    pub path: RenderPath,
    /// Boundary samples cut at the crossing (see [`RenderOptions::boundary_segments`]).
    pub boundary_segments: bool,
}

/// Runs the step study of the scene `of` on an `size × size` image.
pub fn study(of: &SceneOf<'_>, label: &str, size: u32) -> Result<AccuracyResult, Error> {
    let SceneOf {
        mesh,
        accel,
        neighbours,
        view,
        sampling,
        copies,
    } = *of;
    let kind = accel.kind();
    let volume = Volume::new(mesh, accel)?;
    let (transfer, camera) = scene_of(mesh, &volume, copies.as_ref(), size, view)?;
    let base = mean_cell_size(mesh);
    let mut options = RenderOptions::new(size, size, base);
    options.path = sampling.path;
    options.early_termination = f64::INFINITY;
    options.boundary_segments = sampling.boundary_segments;
    let setup = Scene {
        volume: &volume,
        transfer: &transfer,
        options,
        neighbours,
        camera: &camera,
        copies,
    };
    // One tick per image: the reference, each step, and the early-terminated run.
    let bar = super::bench::progress_bar(STEP_FACTORS.len() as u64 + 2, label);
    let (study, reference) = step_study(&setup, base, &STEP_FACTORS, REFERENCE_FACTOR, |line| {
        bar.suspend(|| log(format_args!("{label}: {line}")));
        bar.inc(1);
    })?;
    let terminated = Scene {
        options: RenderOptions {
            early_termination: TERMINATION,
            ..options
        },
        ..setup
    };
    let (image, stats, time_s) = terminated.render_at(base * 0.5)?;
    bar.inc(1);
    let e = compare(&image, &reference)?;
    bar.finish_and_clear();
    log(format_args!(
        "{label}: early termination at {TERMINATION}, 1/2× step: {time_s:.3} s, {} rays stopped, rmse {:.3e}, max {:.3e}",
        stats.early_terminations, e.rmse, e.max_err
    ));
    let report = json!({
        "dataset": label,
        "cells": mesh.cell_count(),
        "structure": kind.name(),
        "path": sampling.path.name(),
        "boundary_segments": sampling.boundary_segments,
        "periodic": super::periodic::json(copies.as_ref()),
        "width": size,
        "height": size,
        "mean_cell_size": study.mean_cell_size,
        "reference": study.reference,
        "runs": study.runs,
        "order": study.order,
        "order_fit": study.order_fit,
        "termination": {
            "threshold": TERMINATION,
            "factor": 0.5,
            "step": base * 0.5,
            "time_s": time_s,
            "rays_stopped": stats.early_terminations,
            "rmse": e.rmse,
            "max_err": e.max_err,
        },
    });
    Ok(AccuracyResult { report, study })
}

/// The default transfer function and the `size × size` camera of `view` for the mesh, or for
/// the wheel of its `copies` (their bounds, and the range of what they draw).
fn scene_of(
    mesh: &Mesh,
    volume: &Volume,
    copies: Option<&Copies>,
    size: u32,
    view: Option<[f64; 3]>,
) -> Result<(TransferFunction, Camera), Error> {
    let (bounds, range) = match copies {
        Some(c) => (c.bounds(), c.scalar_range(volume)?),
        None => (mesh.bounds(), volume.scalar_range()),
    };
    let transfer = scene::transfer_over(scene::diagonal_of(bounds), scene::transfer_range(range));
    let [az, el, zoom] = view.unwrap_or(scene::DEFAULT_VIEW);
    Ok((transfer, Camera::view(bounds, size, size, az, el, zoom)))
}

/// The error-against-time plot of a study: rmse and max error, one labelled point per run.
pub fn plot(study: &StepStudy, title: &str) -> Plot {
    let labels: Vec<String> = study.runs.iter().map(|r| factor_label(r.factor)).collect();
    Plot {
        title: title.to_string(),
        x_label: "render time (s)".into(),
        y_label: "error against the 1/32× reference ([0, 1] RGBA)".into(),
        x_scale: Scale::Log,
        y_scale: Scale::Log,
        series: vec![
            Series {
                name: "rmse".into(),
                points: study.runs.iter().map(|r| (r.time_s, r.rmse)).collect(),
                labels: labels.clone(),
            },
            Series {
                name: "max error".into(),
                points: study.runs.iter().map(|r| (r.time_s, r.max_err)).collect(),
                labels,
            },
        ],
        ..Plot::default()
    }
}

/// Prints a study as a table.
pub fn print_table(report: &Value, study: &StepStudy) -> Result<(), Error> {
    outln!(
        "{} — {} cells, {}, {}×{} image, mean cell size {:.4e}",
        report["dataset"].as_str().unwrap_or(""),
        report["cells"],
        report["structure"].as_str().unwrap_or(""),
        report["width"],
        report["height"],
        study.mean_cell_size
    );
    outln!(
        "reference: {} mean cell size, step {:.4e}, {:.3} s",
        factor_label(study.reference.factor),
        study.reference.step,
        study.reference.time_s
    );
    outln!(
        "{:>7} {:>11} {:>9} {:>11} {:>11} {:>7}",
        "step",
        "(world)",
        "time s",
        "rmse",
        "max err",
        "order"
    );
    for (k, r) in study.runs.iter().enumerate() {
        let order = k
            .checked_sub(1)
            .and_then(|i| study.order.get(i).copied().flatten())
            .map(|o| format!("{o:.2}"))
            .unwrap_or_default();
        outln!(
            "{:>7} {:>11.4e} {:>9.3} {:>11.3e} {:>11.3e} {:>7}",
            factor_label(r.factor),
            r.step,
            r.time_s,
            r.rmse,
            r.max_err,
            order
        );
    }
    if let Some(o) = study.order_fit {
        outln!("fitted order: {o:.2}");
    }
    let t = &report["termination"];
    outln!(
        "early termination at {} ({} rays stopped): at 1/2× rmse {:.3e}, max {:.3e} in {:.3} s (without it: see 1/2× above)",
        t["threshold"],
        t["rays_stopped"],
        t["rmse"].as_f64().unwrap_or(0.0),
        t["max_err"].as_f64().unwrap_or(0.0),
        t["time_s"].as_f64().unwrap_or(0.0)
    );
    Ok(())
}

pub fn run(args: &AccuracyArgs) -> Result<(), Error> {
    // Checked before any work.
    if let Some(plot) = &args.plot {
        super::output::check("--plot", plot, "an SVG plot", &["svg"])?;
    }
    super::camera::check_zoom(args.view.unwrap_or(DEFAULT_VIEW))?;
    let path = args.path;
    let mesh = scene::renderable(args.input.load()?)?;
    let (axis, _) = args.input.axis(&mesh);
    let kind = scene::structure(args.structure, &mesh, &axis);
    let label = cylvol::input::Input::parse(&args.input.input)?.label();
    let accel = super::build_logged(&mesh, kind, &axis, &AccelParams::default())?;
    let copies = args.periodic.copies(&mesh, &axis)?;
    let neighbours =
        super::periodic::wheel_topology(scene::neighbours(&mesh, &accel), &mesh, copies.as_ref());
    let view = Some(args.view.unwrap_or(DEFAULT_VIEW));
    if !args.max_error.is_empty() {
        let scene = SceneOf {
            mesh: &mesh,
            accel: &accel,
            neighbours: &neighbours,
            view,
            sampling: Sampling {
                path,
                boundary_segments: !args.whole_steps,
            },
            copies,
        };
        let size = args.size.unwrap_or(SETTINGS_SIDE);
        let report = settings_study(&scene, &label, size, &args.max_error, args.repeats)?;
        return print_settings(&report, args.json);
    }
    let of = SceneOf {
        mesh: &mesh,
        accel: &accel,
        neighbours: &neighbours,
        view,
        sampling: Sampling {
            path,
            boundary_segments: !args.whole_steps,
        },
        copies,
    };
    let result = study(&of, &label, args.size.unwrap_or(STUDY_SIDE))?;
    if let Some(path) = &args.plot {
        let title = format!(
            "{label} ({} cells): error against time as the step shrinks",
            mesh.cell_count()
        );
        let svg = plot(&result.study, &title);
        super::output::write_replacing(path, |partial| svg.write(partial))?;
        log(format_args!("wrote {}", path.display()));
    }
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&result.report)
                .map_err(|e| Error::Invalid(e.to_string()))?
        );
    } else {
        print_table(&result.report, &result.study)?;
    }
    Ok(())
}

/// What a study renders: the mesh, its structure and neighbours, the view, the sampling and
/// the periodic copies.
#[derive(Clone, Copy)]
pub struct SceneOf<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// Its structure.
    pub accel: &'a Accel,
    /// Its face neighbours (fast path).
    pub neighbours: &'a Topology,
    /// The camera preset.
    pub view: Option<[f64; 3]>,
    /// How rays are sampled.
    pub sampling: Sampling,
    /// The periodic copies drawn instead of the mesh alone, if any.
    pub copies: Option<Copies>,
}

/// Renders the reference, then each of `errors` and the default fixed step, each timed over
/// `repeats` (see the module documentation): the JSON report.
pub fn settings_study(
    of: &SceneOf<'_>,
    label: &str,
    size: u32,
    errors: &[f64],
    repeats: u32,
) -> Result<Value, Error> {
    let mesh = of.mesh;
    let volume = Volume::new(mesh, of.accel)?;
    let (transfer, camera) = scene_of(mesh, &volume, of.copies.as_ref(), size, of.view)?;
    let base = mean_cell_size(mesh);
    let mut options = RenderOptions::new(size, size, base);
    options.path = of.sampling.path;
    options.boundary_segments = of.sampling.boundary_segments;
    let scene = Scene {
        volume: &volume,
        transfer: &transfer,
        options: RenderOptions {
            early_termination: f64::INFINITY,
            ..options
        },
        neighbours: of.neighbours,
        camera: &camera,
        copies: of.copies,
    };
    let bar = super::bench::progress_bar(errors.len() as u64 + 2, label);
    let step = base * SETTINGS_REFERENCE_FACTOR;
    let (reference, stats, time_s) = scene.render_at(step)?;
    bar.inc(1);
    let rendered = Scene { options, ..scene };
    let default_step = 0.5 * base;
    let mut runs = Vec::with_capacity(errors.len());
    for &e in errors {
        let run = settings::run_setting(&rendered, default_step, Some(e), repeats, &reference)?;
        bar.suspend(|| {
            log(format_args!(
                "{label}: --max-error {e}: {:.4} s, {} samples ({} refined), error max {:.3} p99.9 {:.3} mean {:.4} /255",
                run.time_s, run.samples, run.refined_samples, run.error.max, run.error.p999, run.error.mean
            ))
        });
        bar.inc(1);
        runs.push(run);
    }
    let fixed = settings::run_setting(&rendered, default_step, None, repeats, &reference)?;
    bar.finish_and_clear();
    Ok(json!({
        "dataset": label,
        "cells": mesh.cell_count(),
        "structure": of.accel.kind().name(),
        "path": of.sampling.path.name(),
        "boundary_segments": of.sampling.boundary_segments,
        "periodic": super::periodic::json(of.copies.as_ref()),
        "width": size,
        "height": size,
        "mean_cell_size": base,
        "repeats": repeats,
        "reference": {
            "step": step,
            "factor": SETTINGS_REFERENCE_FACTOR,
            "time_s": time_s,
            "samples": stats.samples,
        },
        "settings": runs,
        "fixed_step": fixed,
    }))
}

/// Prints a settings study as JSON or as a table.
fn print_settings(report: &Value, as_json: bool) -> Result<(), Error> {
    if as_json {
        outln!(
            "{}",
            serde_json::to_string_pretty(report).map_err(|e| Error::Invalid(e.to_string()))?
        );
        return Ok(());
    }
    outln!(
        "{} — {} cells, {}, {}×{} image, best of {} renders; errors per pixel in 1/255 against the reference (step {:.4e})",
        report["dataset"].as_str().unwrap_or(""),
        report["cells"],
        report["structure"].as_str().unwrap_or(""),
        report["width"],
        report["height"],
        report["repeats"],
        report["reference"]["step"].as_f64().unwrap_or(0.0)
    );
    outln!(
        "{:>14} {:>9} {:>11} {:>9} {:>9} {:>9} {:>9}",
        "setting",
        "time s",
        "samples",
        "refined",
        "max",
        "p99.9",
        "mean"
    );
    let rows = report["settings"].as_array().into_iter().flatten();
    for run in rows.chain(std::iter::once(&report["fixed_step"])) {
        let setting = match run["max_error"].as_f64() {
            Some(e) => format!("max-error {e}"),
            None => format!("step {:.3e}", run["step"].as_f64().unwrap_or(0.0)),
        };
        let e = &run["error"];
        let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
        outln!(
            "{:>14} {:>9.4} {:>11} {:>9} {:>9.3} {:>9.3} {:>9.4}",
            setting,
            f(&run["time_s"]),
            run["samples"],
            run["refined_samples"],
            f(&e["max"]),
            f(&e["p999"]),
            f(&e["mean"])
        );
    }
    Ok(())
}
