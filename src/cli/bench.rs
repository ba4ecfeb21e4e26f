//! `cylvol bench INPUT... [--json] [--size N] [--frames F] [--view A,E,Z] [--step S]
//! [--opacity S:A,...] [--color S:R:G:B,...] [--unit-distance D] [--grid-order cells|share]
//! [--periodic auto|N [--copies K0:K1]]`: renders every input (the wheel of a periodic
//! sector's copies with `--periodic`) with each of the four structures along both sampling paths and reports
//! the talk's per-frame figures — samples, hexahedra tested, internal and leaf nodes visited, frame time
//! — with cylindrical ÷ Cartesian ratios.
//!
//! Every structure and path renders the same `N × N` image (default 512) with the same camera
//! (`--view`, default `0,0,1`), transfer function (the default, or what `--opacity`, `--color`
//! and `--unit-distance` set: [`super::transfer`]) and step (default half the mean cell size),
//! as `cylvol render` would ([`super::scene`]). `paper` locates every sample from scratch
//! through the structure, as the talk measured; `fast` is the project's best path (previous
//! cell, face neighbours, transparent cells skipped). `frame_s` is the wall time of the
//! render alone (rays in parallel on all cores), the fastest of `--frames` renders (default
//! 1; the work counters are the same in every render, and checked to be), made in rounds that
//! render every structure and path once each, so that the machine's drifts in speed (this
//! project's 2-core machines drift by 20 % within minutes) fall on all of them alike rather
//! than on whichever renders during a slow spell; `build_s` the
//! structure's build. The face neighbours the fast path walks are built once per mesh
//! (`neighbours_s`).
//!
//! With `--json`, standard output is a JSON array with one object per input: `dataset`,
//! `cells`, `width`, `height`, `frames`, `step`, `view`, `neighbours_s`, `grid_order` (the
//! grids' candidate order, `--grid-order`), `structures` (`cart-grid`,
//! `cyl-grid`, `cart-bvh`, `cyl-bvh`, each with `build_s`, `paper` and `fast`, each of those
//! with `samples`, `hex_tests`, `internal_visits`, `leaf_visits`, `frame_s`) and `ratios`
//! (`grid` and `bvh`, each with `paper` and `fast`, each with the cyl ÷ cart quotients of
//! `hex_tests`, `internal_visits`, `leaf_visits` and `frame_s`; `null` where the Cartesian
//! figure is zero). Without it, a table. Progress goes to standard error.

use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde_json::{json, Map, Value};

use super::periodic::{self, PeriodicArgs};
use super::transfer::TransferArgs;
use super::{log, scene, InputArgs};
use cylvol::accel::{Accel, AccelParams, CandidateOrder, StructureKind};
use cylvol::axis::Axis;
use cylvol::render::{
    Camera, Copies, Image, RenderOptions, RenderPath, RenderStats, Renderer, ScalarField, Volume,
};
use cylvol::{Error, Mesh};

/// Arguments of `cylvol bench`.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// Mesh files or datasets NAME[:CELLS], e.g. pump-rotor pump-inlet:200000 mixer.vtk.
    #[arg(required = true, value_name = "INPUT")]
    inputs: Vec<String>,
    /// Print JSON on standard output (an array, one object per input).
    #[arg(long)]
    json: bool,
    /// Image side N (an N×N image).
    #[arg(long, default_value = "512", value_parser = scene::parse_side, allow_hyphen_values = true)]
    size: u32,
    /// Renders per structure and path, in rounds of one each; `frame_s` is the fastest (less
    /// noise from other work on the machine).
    #[arg(long, default_value = "1", value_parser = parse_frames, allow_hyphen_values = true)]
    frames: u32,
    /// Camera preset AZIMUTH,ELEVATION,ZOOM in degrees, degrees and a factor.
    #[arg(long, value_name = "AZIMUTH,ELEVATION,ZOOM", value_parser = scene::parse_view, allow_hyphen_values = true)]
    view: Option<[f64; 3]>,
    /// Sample spacing in world units (default: half the mean cell size). Given alone, every
    /// ray is sampled at this fixed step; with --max-error, it is the step rays start with.
    #[arg(long, value_parser = super::number::parse_step, allow_hyphen_values = true)]
    step: Option<f64>,
    /// The largest colour error allowed, in 1/255 of a pixel's premultiplied RGBA against the
    /// converged image (e.g. 2; default: none, the fixed step).
    #[arg(long, value_name = "E", value_parser = scene::parse_max_error, allow_hyphen_values = true)]
    max_error: Option<f64>,
    /// Scalar array to render (for every input).
    #[arg(long)]
    scalar: Option<String>,
    /// Machine axis instead of the detected one (for every input).
    #[arg(long, value_name = "AXIS", allow_hyphen_values = true)]
    axis: Option<Axis>,
    /// The grids' candidate order: `cells` (cell ids, the talk's grids; the default) or
    /// `share` (the cells covering most of the grid cell first).
    #[arg(long, value_name = "cells|share", default_value = "cells")]
    grid_order: CandidateOrder,
    #[command(flatten)]
    transfer: TransferArgs,
    #[command(flatten)]
    periodic: PeriodicArgs,
}

/// Parses `--frames F`, 1 to 100.
fn parse_frames(s: &str) -> Result<u32, String> {
    super::number::whole_in(s, "frames", 1, 100).map(|n| n as u32)
}

/// The four structures' figures on one mesh, and the fast path's images.
pub struct BenchResult {
    /// The report object of one dataset (see the module documentation).
    pub report: Value,
    /// The fast path's image per structure.
    pub images: Vec<(StructureKind, Image)>,
}

/// What to render in a benchmark.
pub struct BenchSetup {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Renders per structure and path (at least 1): the fastest gives `frame_s`.
    pub frames: u32,
    /// Camera preset.
    pub view: Option<[f64; 3]>,
    /// Sample spacing (`None`: the default).
    pub step: Option<f64>,
    /// The error allowed, in 1/255 (`None`: the default, see [`scene::sampling`]).
    pub max_error: Option<f64>,
    /// The transfer function's options (none set: the default).
    pub transfer: TransferArgs,
}

/// One render timed: the image, counters and wall seconds.
fn timed_render(renderer: &Renderer, camera: &Camera) -> Result<(Image, RenderStats, f64), Error> {
    let started = Instant::now();
    let (image, stats) = renderer.render(camera, None)?;
    Ok((image, stats, started.elapsed().as_secs_f64()))
}

fn path_json(stats: &RenderStats, frame_s: f64) -> Value {
    json!({
        "samples": stats.samples,
        "hex_tests": stats.hex_tests,
        "internal_visits": stats.internal_visits,
        "leaf_visits": stats.leaf_visits,
        "frame_s": frame_s,
        "samples_located": stats.samples_located,
        "samples_skipped": stats.samples_skipped,
        "early_terminations": stats.early_terminations,
        "refined_samples": stats.refined_samples,
        "integrated_stretches": stats.integrated_stretches,
        "slopes": stats.slopes,
    })
}

/// The keys whose cyl ÷ cart quotients `ratios` holds.
pub const RATIO_KEYS: [&str; 4] = ["hex_tests", "internal_visits", "leaf_visits", "frame_s"];

/// `ratios` of a `structures` object: per family (`grid`, `bvh`) and path, cyl ÷ cart.
pub fn ratios(structures: &Map<String, Value>) -> Value {
    let mut out = Map::new();
    for (family, cart, cyl) in [
        ("grid", "cart-grid", "cyl-grid"),
        ("bvh", "cart-bvh", "cyl-bvh"),
    ] {
        let mut paths = Map::new();
        for path in ["paper", "fast"] {
            let mut r = Map::new();
            for key in RATIO_KEYS {
                let a = structures.get(cart).and_then(|s| s[path][key].as_f64());
                let b = structures.get(cyl).and_then(|s| s[path][key].as_f64());
                let q = match (a, b) {
                    (Some(a), Some(b)) if a > 0.0 => Some(b / a),
                    _ => None,
                };
                r.insert(key.to_string(), json!(q));
            }
            paths.insert(path.to_string(), Value::Object(r));
        }
        out.insert(family.to_string(), Value::Object(paths));
    }
    Value::Object(out)
}

/// Renders the same view of `mesh` (or of the wheel of its `copies`) with each structure in
/// `built` (the four, built over `mesh`), along each of `paths`.
pub fn bench_mesh(
    mesh: &Mesh,
    built: &[Accel],
    label: &str,
    setup: &BenchSetup,
    (paths, copies): (&[RenderPath], Option<&Copies>),
) -> Result<BenchResult, Error> {
    let (width, height) = (setup.width, setup.height);
    let (step, max_error) = scene::sampling(mesh, setup.step, setup.max_error)?;
    let bounds = copies.map_or(mesh.bounds(), |c| c.bounds());
    let [az, el, zoom] = setup.view.unwrap_or(scene::DEFAULT_VIEW);
    let camera = Camera::view(bounds, width, height, az, el, zoom);
    let diagonal = scene::diagonal_of(bounds);
    if built.is_empty() {
        return Err(Error::Invalid("bench: no structure to render with".into()));
    }
    let started = Instant::now();
    let neighbours = paths
        .contains(&RenderPath::Fast)
        .then(|| periodic::wheel_topology(scene::neighbours(mesh, &built[0]), mesh, copies));
    let neighbours_s = started.elapsed().as_secs_f64();
    let bar = progress_bar(
        (built.len() * paths.len()) as u64 * setup.frames.max(1) as u64,
        label,
    );
    // Gathered once for the four structures.
    let field = ScalarField::gather(mesh)?;
    let volumes = built
        .iter()
        .map(|accel| Volume::with_field(mesh, accel, &field))
        .collect::<Result<Vec<_>, Error>>()?;
    // Every structure and path's renderer, made before any frame is timed.
    let mut runs = Vec::new();
    for volume in &volumes {
        let drawn_range = match copies {
            Some(c) => c.scalar_range(volume)?,
            None => volume.scalar_range(),
        };
        let range = scene::transfer_range(drawn_range);
        let transfer =
            setup
                .transfer
                .apply(scene::transfer_over(diagonal, range), range, diagonal)?;
        for &path in paths {
            let mut options = RenderOptions::new(width, height, step);
            options.path = path;
            options.max_error = max_error;
            let mut renderer = Renderer::new(volume, &transfer, &options)?;
            if let (RenderPath::Fast, Some(n)) = (path, &neighbours) {
                renderer = renderer.with_topology(n);
            }
            if let Some(c) = copies {
                renderer = renderer.with_copies(*c)?;
            }
            let accel = volume.accel();
            runs.push((accel.kind(), accel.stats().build_s(), path, renderer));
        }
    }
    // Rounds of one render each, so that the machine's drifts in speed fall on every
    // structure and path alike; the first round's images and counters are kept, and every
    // later render must count the same work (the render is deterministic).
    let mut first: Vec<(Image, RenderStats, f64)> = Vec::with_capacity(runs.len());
    for round in 0..setup.frames.max(1) {
        for (i, (kind, _, path, renderer)) in runs.iter().enumerate() {
            let (image, stats, frame_s) = timed_render(renderer, &camera)?;
            bar.inc(1);
            if round == 0 {
                first.push((image, stats, frame_s));
                continue;
            }
            let kept = &mut first[i];
            if stats != kept.1 {
                return Err(Error::Invalid(format!(
                    "bench: {kind} {} path: a second render counted different work ({stats:?} after {:?})",
                    path.name(),
                    kept.1
                )));
            }
            kept.2 = kept.2.min(frame_s);
        }
    }
    let mut structures = Map::new();
    let mut images = Vec::new();
    for ((kind, build_s, path, _), (image, stats, frame_s)) in runs.iter().zip(first) {
        bar.suspend(|| {
            log(format_args!(
                "{label}: {kind} built in {build_s:.2} s, {} path {frame_s:.3} s: {} samples, {} hexahedra tested, {} internal / {} leaf visits",
                path.name(),
                stats.samples,
                stats.hex_tests,
                stats.internal_visits,
                stats.leaf_visits
            ))
        });
        let entry = structures
            .entry(kind.name())
            .or_insert_with(|| json!({ "build_s": build_s }));
        entry[path.name()] = path_json(&stats, frame_s);
        if *path == RenderPath::Fast {
            images.push((*kind, image));
        }
    }
    bar.finish_and_clear();
    let ratios = ratios(&structures);
    let report = json!({
        "dataset": label,
        "cells": mesh.cell_count(),
        "width": width,
        "height": height,
        "frames": setup.frames.max(1),
        "step": step,
        "max_error": max_error,
        "view": setup.view.unwrap_or(scene::DEFAULT_VIEW),
        "neighbours_s": neighbours.as_ref().map(|_| neighbours_s),
        "periodic": periodic::json(copies),
        "structures": structures,
        "ratios": ratios,
    });
    Ok(BenchResult { report, images })
}

/// A progress bar of `len` ticks on standard error, labelled `label`; indicatif draws nothing
/// when standard error is not a terminal (a pipe, a file, a test), so logs and JSON stay clean.
pub fn progress_bar(len: u64, label: &str) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} {elapsed}") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_prefix(label.to_string());
    bar
}

/// Prints one dataset's report as a table.
pub fn print_table(report: &Value) -> Result<(), Error> {
    outln!(
        "{} — {} cells, {}×{} image, step {:.4e}",
        report["dataset"].as_str().unwrap_or(""),
        report["cells"],
        report["width"],
        report["height"],
        report["step"].as_f64().unwrap_or(0.0)
    );
    outln!(
        "{:<10} {:>8} {:<6} {:>12} {:>9} {:>10} {:>9} {:>9}",
        "structure",
        "build s",
        "path",
        "samples",
        "hex/smp",
        "inner/smp",
        "leaf/smp",
        "frame s"
    );
    for kind in StructureKind::ALL {
        let s = &report["structures"][kind.name()];
        for path in ["paper", "fast"] {
            let p = &s[path];
            if p.is_null() {
                continue;
            }
            let samples = p["samples"].as_f64().unwrap_or(0.0);
            let per = |k: &str| {
                if samples > 0.0 {
                    format!("{:.3}", p[k].as_f64().unwrap_or(0.0) / samples)
                } else {
                    "-".into()
                }
            };
            outln!(
                "{:<10} {:>8.3} {:<6} {:>12} {:>9} {:>10} {:>9} {:>9.3}",
                kind.name(),
                s["build_s"].as_f64().unwrap_or(0.0),
                path,
                p["samples"],
                per("hex_tests"),
                per("internal_visits"),
                per("leaf_visits"),
                p["frame_s"].as_f64().unwrap_or(0.0)
            );
        }
    }
    for family in ["grid", "bvh"] {
        for path in ["paper", "fast"] {
            let r = &report["ratios"][family][path];
            let parts: Vec<String> = RATIO_KEYS
                .iter()
                .filter_map(|k| r[*k].as_f64().map(|v| format!("{k} {v:.2}")))
                .collect();
            if !parts.is_empty() {
                outln!("cyl ÷ cart {family} {path}: {}", parts.join(", "));
            }
        }
    }
    Ok(())
}

pub fn run(args: &BenchArgs) -> Result<(), Error> {
    super::camera::check_zoom(args.view.unwrap_or(scene::DEFAULT_VIEW))?;
    // Refuse a missing file before spending minutes on the inputs before it.
    for spec in &args.inputs {
        if let cylvol::input::Input::File(p) = cylvol::input::Input::parse(spec)? {
            if !p.exists() {
                return Err(Error::Invalid(format!(
                    "{}: no such file, and not a dataset name (pump-inlet, pump-rotor, pump-diffuser)",
                    p.display()
                )));
            }
        }
    }
    let setup = BenchSetup {
        width: args.size,
        height: args.size,
        frames: args.frames,
        view: args.view,
        step: args.step,
        max_error: args.max_error,
        transfer: args.transfer.clone(),
    };
    let mut reports = Vec::new();
    for (k, spec) in args.inputs.iter().enumerate() {
        log(format_args!(
            "bench {}/{}: {spec}",
            k + 1,
            args.inputs.len()
        ));
        let input = InputArgs {
            input: spec.clone(),
            q_file: None,
            scalar: args.scalar.clone(),
            axis: args.axis,
        };
        let mesh = scene::renderable(input.load()?)?;
        let (axis, _) = input.axis(&mesh);
        let copies = args.periodic.copies(&mesh, &axis)?;
        let label = cylvol::input::Input::parse(spec)?.label();
        let mut params = AccelParams::default();
        params.grid.order = args.grid_order;
        let built = super::stats::build_all(&mesh, &axis, &params)?;
        let mut result = bench_mesh(
            &mesh,
            &built,
            &label,
            &setup,
            (&[RenderPath::Paper, RenderPath::Fast], copies.as_ref()),
        )?;
        result.report["grid_order"] = json!(args.grid_order.name());
        if !args.json {
            if k > 0 {
                outln!();
            }
            print_table(&result.report)?;
        }
        reports.push(result.report);
    }
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&Value::Array(reports))
                .map_err(|e| Error::Invalid(e.to_string()))?
        );
    }
    Ok(())
}
