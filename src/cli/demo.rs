//! `cylvol demo [--out DIR]`: the main job on the built-in default dataset.
//!
//! It generates the default dataset (`pump-rotor` at a demo size), describes it, builds the
//! four acceleration structures, measures point location through each, and prints the talk's
//! cylindrical ÷ Cartesian ratios for the rotor beside ours. It writes the mesh (VTU) and the
//! figures (JSON) into `DIR`. The ray caster, as it lands, adds its images here.

use std::path::PathBuf;
use std::time::Instant;

use serde_json::{json, Value};

use super::log;
use cylvol::accel::probe::{lookup_cost, points_in_cells};
use cylvol::accel::AccelParams;
use cylvol::datasets::Dataset;
use cylvol::Error;

/// The dataset and size the demo uses.
pub const DEMO_DATASET: Dataset = Dataset::PumpRotor;
/// Cells in the demo's dataset: large enough to be a real mesh, small enough for seconds.
pub const DEMO_CELLS: usize = 400_000;

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
    #[arg(long, default_value_t = DEMO_CELLS)]
    cells: usize,
}

fn io_error(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |source| Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

pub fn run(args: &DemoArgs) -> Result<(), Error> {
    std::fs::create_dir_all(&args.out).map_err(io_error(&args.out))?;
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
    let points = points_in_cells(&mesh, 100_000, 0x00C7_1D0F);
    let mut structures = serde_json::Map::new();
    for accel in &built {
        let mut entry = super::stats::stats_json(&accel.stats());
        let cost = lookup_cost(accel, &mesh, &points);
        entry["hex_tests"] = json!(cost.hex_tests);
        entry["internal_visits"] = json!(cost.internal_visits);
        entry["leaf_visits"] = json!(cost.leaf_visits);
        structures.insert(accel.kind().name().to_string(), entry);
    }
    let ratio = |family: &str, key: &str| -> Option<f64> {
        let (cart, cyl) = match family {
            "grid" => ("cart-grid", "cyl-grid"),
            _ => ("cart-bvh", "cyl-bvh"),
        };
        let a = structures[cart][key].as_f64()?;
        let b = structures[cyl][key].as_f64()?;
        (a > 0.0).then_some(b / a)
    };

    println!(
        "{} — {} cells, {} points, scalar '{}', axis {:?}",
        DEMO_DATASET.name(),
        info_field(&info, "cells"),
        info_field(&info, "points"),
        mesh.active_array()
            .map(|a| a.name.as_str())
            .unwrap_or("none"),
        detection.axis.direction.to_array()
    );
    println!();
    println!(
        "{:<30} {:>14} {:>14}",
        "cylindrical ÷ Cartesian", "talk (rotor)", "cylvol"
    );
    let mut comparison = Vec::new();
    for (family, key, label, talk) in TALK_ROTOR {
        let ours = ratio(family, key);
        println!(
            "{:<30} {:>14.2} {:>14}",
            label,
            talk,
            ours.map(|v| format!("{v:.2}"))
                .unwrap_or_else(|| "-".into())
        );
        comparison.push(json!({ "measure": label, "talk": talk, "cylvol": ours }));
    }
    println!();
    println!(
        "(hexahedra tested and nodes visited: per point located, over 100,000 points inside cells;"
    );
    println!(" the talk counted them per rendered frame. Rendering comes with the ray caster.)");

    let mesh_path = args.out.join(format!("{}.vtu", DEMO_DATASET.name()));
    cylvol::io::write_file(&mesh, &mesh_path)?;
    let report = json!({
        "dataset": DEMO_DATASET.name(),
        "info": serde_json::to_value(&info).map_err(|e| Error::Invalid(e.to_string()))?,
        "structures": structures,
        "comparison": comparison,
    });
    let report_path = args.out.join("demo.json");
    let text = serde_json::to_string_pretty(&report).map_err(|e| Error::Invalid(e.to_string()))?;
    std::fs::write(&report_path, text).map_err(io_error(&report_path))?;
    log(format_args!(
        "wrote {} and {} ({:.2} s in all)",
        mesh_path.display(),
        report_path.display(),
        started.elapsed().as_secs_f64()
    ));
    Ok(())
}

fn info_field(info: &super::info::Info, key: &str) -> Value {
    serde_json::to_value(info)
        .ok()
        .and_then(|v| v.get(key).cloned())
        .unwrap_or(Value::Null)
}
