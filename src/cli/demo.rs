//! `cylvol demo [--out DIR]`: the main job on the built-in default dataset.
//!
//! It generates the default dataset (`pump-rotor` at a demo size), describes it, builds the
//! four acceleration structures, measures point location through each, renders the same
//! view with each structure along both paths (as `cylvol bench`), and prints the talk's
//! cylindrical ÷ Cartesian ratios for the rotor beside ours. It writes into `DIR`: the mesh
//! (VTU), the fast path's image per structure (`cart-grid.png`, `cyl-grid.png`,
//! `cart-bvh.png`, `cyl-bvh.png`, [`DEMO_IMAGE`]² from [`DEMO_VIEW`]), the price of accuracy
//! (`accuracy.svg`, the `cylvol accuracy` study through the cylindrical BVH at
//! [`DEMO_ACCURACY_IMAGE`]²) and all the figures (`demo.json`).
//!
//! The sizes are chosen so that the whole demo, builds included, takes well under a minute on
//! a 2-core machine.

use std::path::PathBuf;
use std::time::Instant;

use serde_json::{json, Value};

use super::log;
use cylvol::accel::probe::{lookup_cost, points_in_cells};
use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::datasets::Dataset;
use cylvol::render::RenderPath;
use cylvol::{Error, Mesh};

/// The dataset and size the demo uses.
pub const DEMO_DATASET: Dataset = Dataset::PumpRotor;
/// Cells in the demo's dataset: large enough to be a real mesh, small enough for seconds.
pub const DEMO_CELLS: usize = 400_000;

/// Side of the demo's rendered images.
pub const DEMO_IMAGE: u32 = 256;
/// Side of the images of the demo's accuracy study.
pub const DEMO_ACCURACY_IMAGE: u32 = 96;
/// The demo's camera: azimuth 30°, elevation 20°, no zoom.
pub const DEMO_VIEW: [f64; 3] = [30.0, 20.0, 1.0];

/// The talk's per-frame cylindrical ÷ Cartesian ratios on its rotor, beside the bench's:
/// (family, key in the bench's `ratios`, label, talk). `fps` is the inverse of the
/// `frame_s` ratio (cart frame time ÷ cyl frame time).
const TALK_ROTOR_FRAME: [(&str, &str, &str, f64); 5] = [
    ("grid", "hex_tests", "grid: hexahedra visited", 0.89),
    ("grid", "fps", "grid: frames per second", 1.09),
    (
        "bvh",
        "internal_visits",
        "BVH: internal nodes visited",
        0.88,
    ),
    ("bvh", "leaf_visits", "BVH: leaf nodes visited", 0.86),
    ("bvh", "fps", "BVH: frames per second", 1.14),
];

/// The talk's cylindrical ÷ Cartesian ratios on its rotor (2.1 M hexahedra), for comparison.
const TALK_ROTOR: [(&str, &str, &str, f64); 7] = [
    ("grid", "grid_cells", "grid: cells", 0.94),
    ("grid", "references", "grid: references", 0.64),
    ("grid", "bytes", "grid: memory", 0.69),
    ("grid", "hex_tests", "grid: hexahedra tested", 0.89),
    ("bvh", "surface_area", "BVH: surface area", 0.80),
    (
        "bvh",
        "internal_visits",
        "BVH: internal nodes visited",
        0.88,
    ),
    ("bvh", "leaf_visits", "BVH: leaf nodes visited", 0.86),
];

/// Arguments of `cylvol demo`.
#[derive(clap::Args, Debug)]
pub struct DemoArgs {
    /// Folder for the demo's outputs (created if missing).
    #[arg(long, value_name = "DIR", default_value = "cylvol-demo")]
    out: PathBuf,
    /// Cells of the demo dataset (for a quicker look; the default is the demo size).
    #[arg(long, default_value_t = DEMO_CELLS, value_parser = parse_cells, allow_hyphen_values = true)]
    cells: usize,
}

/// Parses `--cells N`, within what the datasets make ([`cylvol::datasets::MIN_CELLS`] to
/// [`cylvol::datasets::MAX_CELLS`]).
fn parse_cells(s: &str) -> Result<usize, String> {
    use cylvol::datasets::{MAX_CELLS, MIN_CELLS};
    super::number::whole_in(s, "cells", MIN_CELLS as u64, MAX_CELLS as u64).map(|n| n as usize)
}

fn io_error(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |source| Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

pub fn run(args: &DemoArgs) -> Result<(), Error> {
    if args.out.exists() && !args.out.is_dir() {
        return Err(Error::Invalid(format!(
            "--out {}: is a file; give a folder",
            args.out.display()
        )));
    }
    std::fs::create_dir_all(&args.out).map_err(io_error(&args.out))?;
    // A folder that takes no file is refused before the work.
    super::output::check_folder("--out", &args.out.join("demo.json"))?;
    let started = Instant::now();
    let mesh = cylvol::datasets::generate(DEMO_DATASET, args.cells)?;
    log(format_args!(
        "generated {}:{}: {} cells in {:.2} s",
        DEMO_DATASET.name(),
        args.cells,
        mesh.cell_count(),
        started.elapsed().as_secs_f64()
    ));
    let detection = cylvol::axis::detect_with_report(&mesh);
    let info = super::info::describe(&mesh, detection.axis, Some(detection.clear));
    let built = super::stats::build_all(&mesh, &detection.axis, &AccelParams::default())?;
    let structures = measure_structures(&mesh, &built);
    outln!(
        "{} — {} cells, {} points, scalar '{}', axis {:?}",
        DEMO_DATASET.name(),
        info_field(&info, "cells"),
        info_field(&info, "points"),
        mesh.active_scalar()
            .map(|a| a.selector(mesh.point_data(), mesh.cell_data()))
            .unwrap_or_else(|| "none".into()),
        detection.axis.direction.to_array()
    );
    let comparison = compare_structures(&structures)?;
    let (bench, images) = render_views(&mesh, &built, &args.out)?;
    let frame_comparison = compare_frames(&bench.report)?;
    let (accuracy, plot_path) = price_of_accuracy(&mesh, &built, &args.out)?;

    let mesh_path = args.out.join(format!("{}.vtu", DEMO_DATASET.name()));
    cylvol::io::write_file(&mesh, &mesh_path)?;
    let report = json!({
        "dataset": DEMO_DATASET.name(),
        "info": serde_json::to_value(&info).map_err(|e| Error::Invalid(e.to_string()))?,
        "structures": structures,
        "comparison": comparison,
        "bench": bench.report,
        "frame_comparison": frame_comparison,
        "images": images,
        "accuracy": accuracy.report,
    });
    let report_path = args.out.join("demo.json");
    let text = serde_json::to_string_pretty(&report).map_err(|e| Error::Invalid(e.to_string()))?;
    super::output::write_replacing(&report_path, |p| {
        std::fs::write(p, &text).map_err(io_error(p))
    })?;
    log(format_args!(
        "wrote {}, {}, {} and the images ({:.2} s in all)",
        mesh_path.display(),
        report_path.display(),
        plot_path.display(),
        started.elapsed().as_secs_f64()
    ));
    Ok(())
}

/// Each structure's figures with the cost of point location through it (per point, over
/// 100,000 points inside cells), by name.
fn measure_structures(mesh: &Mesh, built: &[Accel]) -> serde_json::Map<String, Value> {
    let points = points_in_cells(mesh, 100_000, 0x00C7_1D0F);
    let mut structures = serde_json::Map::new();
    for accel in built {
        let mut entry = super::stats::stats_json(&accel.stats());
        let cost = lookup_cost(accel, mesh, &points);
        entry["hex_tests"] = json!(cost.hex_tests);
        entry["internal_visits"] = json!(cost.internal_visits);
        entry["leaf_visits"] = json!(cost.leaf_visits);
        structures.insert(accel.kind().name().to_string(), entry);
    }
    structures
}

/// Prints the talk's cylindrical ÷ Cartesian ratios for the rotor beside the structures'
/// (`structures`, from [`measure_structures`]); returns them for the report.
fn compare_structures(structures: &serde_json::Map<String, Value>) -> Result<Vec<Value>, Error> {
    let ratio = |family: &str, key: &str| -> Option<f64> {
        let (cart, cyl) = match family {
            "grid" => ("cart-grid", "cyl-grid"),
            _ => ("cart-bvh", "cyl-bvh"),
        };
        let a = structures[cart][key].as_f64()?;
        let b = structures[cyl][key].as_f64()?;
        (a > 0.0).then_some(b / a)
    };
    outln!();
    outln!(
        "{:<30} {:>14} {:>14}",
        "cylindrical ÷ Cartesian",
        "talk (rotor)",
        "cylvol"
    );
    let mut comparison = Vec::new();
    for (family, key, label, talk) in TALK_ROTOR {
        let ours = ratio(family, key);
        outln!(
            "{:<30} {:>14.2} {:>14}",
            label,
            talk,
            ours.map(|v| format!("{v:.2}"))
                .unwrap_or_else(|| "-".into())
        );
        comparison.push(json!({ "measure": label, "talk": talk, "cylvol": ours }));
    }
    outln!();
    outln!(
        "(hexahedra tested and nodes visited: per point located, over 100,000 points inside cells)"
    );
    Ok(comparison)
}

/// Renders the same view with each structure along both paths (as `cylvol bench`), writes the
/// fast path's image per structure into `out` and prints the bench's table; returns the bench
/// and the images written.
fn render_views(
    mesh: &Mesh,
    built: &[Accel],
    out: &std::path::Path,
) -> Result<(super::bench::BenchResult, Vec<String>), Error> {
    let setup = super::bench::BenchSetup {
        width: DEMO_IMAGE,
        height: DEMO_IMAGE,
        frames: 1,
        view: Some(DEMO_VIEW),
        step: None,
        max_error: None,
        transfer: Default::default(),
    };
    let bench = super::bench::bench_mesh(
        mesh,
        built,
        DEMO_DATASET.name(),
        &setup,
        (&[RenderPath::Paper, RenderPath::Fast], None),
    )?;
    let mut images = Vec::new();
    for (kind, image) in &bench.images {
        let path = out.join(format!("{}.png", kind.name()));
        super::output::write_replacing(&path, |p| image.write_png(p, Some([0.0; 3])))?;
        images.push(path.display().to_string());
    }
    outln!();
    super::bench::print_table(&bench.report)?;
    Ok((bench, images))
}

/// Prints the talk's per-frame cylindrical ÷ Cartesian ratios beside the bench's (`report`);
/// returns them for the report.
fn compare_frames(report: &Value) -> Result<Vec<Value>, Error> {
    outln!();
    outln!(
        "{:<30} {:>14} {:>10} {:>10}",
        "per frame, cyl ÷ cart",
        "talk (rotor)",
        "paper",
        "fast"
    );
    let mut frame_comparison = Vec::new();
    for (family, key, label, talk) in TALK_ROTOR_FRAME {
        let ours = |path: &str| -> Option<f64> {
            let r = &report["ratios"][family][path];
            match key {
                "fps" => r["frame_s"].as_f64().filter(|v| *v > 0.0).map(|v| 1.0 / v),
                k => r[k].as_f64(),
            }
        };
        let (paper, fast) = (ours("paper"), ours("fast"));
        let show = |v: Option<f64>| v.map(|v| format!("{v:.2}")).unwrap_or_else(|| "-".into());
        outln!(
            "{:<30} {:>14.2} {:>10} {:>10}",
            label,
            talk,
            show(paper),
            show(fast)
        );
        frame_comparison
            .push(json!({ "measure": label, "talk": talk, "paper": paper, "fast": fast }));
    }
    outln!(
        "(per {}×{} frame of the demo's view; fps = cart frame time ÷ cyl frame time)",
        DEMO_IMAGE,
        DEMO_IMAGE
    );
    Ok(frame_comparison)
}

/// The price of accuracy through the cylindrical BVH: the study, its plot written into `out`
/// and its table printed; returns the study and the plot's path.
fn price_of_accuracy(
    mesh: &Mesh,
    built: &[Accel],
    out: &std::path::Path,
) -> Result<(super::accuracy::AccuracyResult, PathBuf), Error> {
    let cyl_bvh = built
        .iter()
        .find(|a| a.kind() == StructureKind::CylBvh)
        .ok_or_else(|| Error::Invalid("demo: the cylindrical BVH is missing".into()))?;
    let neighbours = super::scene::neighbours(mesh, cyl_bvh);
    let of = super::accuracy::SceneOf {
        mesh,
        accel: cyl_bvh,
        neighbours: &neighbours,
        view: Some(DEMO_VIEW),
        sampling: super::accuracy::Sampling {
            path: RenderPath::Fast,
            boundary_segments: true,
        },
        copies: None,
    };
    let accuracy = super::accuracy::study(&of, DEMO_DATASET.name(), DEMO_ACCURACY_IMAGE)?;
    let plot_path = out.join("accuracy.svg");
    let svg = super::accuracy::plot(
        &accuracy.study,
        &format!(
            "{} ({} cells): error against time as the step shrinks",
            DEMO_DATASET.name(),
            mesh.cell_count()
        ),
    );
    super::output::write_replacing(&plot_path, |p| svg.write(p))?;
    outln!();
    super::accuracy::print_table(&accuracy.report, &accuracy.study)?;
    Ok((accuracy, plot_path))
}

fn info_field(info: &super::info::Info, key: &str) -> Value {
    serde_json::to_value(info)
        .ok()
        .and_then(|v| v.get(key).cloned())
        .unwrap_or(Value::Null)
}
