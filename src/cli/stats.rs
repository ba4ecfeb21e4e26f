//! `cylvol stats INPUT [--json]`: builds the four structures and reports the talk's figures —
//! grid cells, references, bytes, surface area, build time — with cylindrical ÷ Cartesian
//! ratios.

use serde_json::{json, Map, Value};

use super::{log, InputArgs};
use cylvol::accel::{Accel, AccelParams, StructureKind, StructureStats};
use cylvol::Error;

/// Arguments of `cylvol stats`.
#[derive(clap::Args, Debug)]
pub struct StatsArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Print JSON on standard output.
    #[arg(long)]
    json: bool,
}

/// The JSON object of one structure's figures.
pub fn stats_json(stats: &StructureStats) -> Value {
    match stats {
        StructureStats::Grid(g) => json!({
            "grid_cells": g.grid_cells,
            "top_cells": g.top_cells,
            "references": g.references,
            "bytes": g.bytes,
            "build_s": g.build_s,
        }),
        StructureStats::Bvh(b) => json!({
            "nodes": b.nodes,
            "leaves": b.leaves,
            "references": b.references,
            "bytes": b.bytes,
            "surface_area": b.surface_area,
            "build_s": b.build_s,
        }),
    }
}

/// Builds the four structures over `mesh` about `axis`, logging each.
pub fn build_all(mesh: &cylvol::Mesh, axis: &cylvol::axis::Axis) -> Result<Vec<Accel>, Error> {
    StructureKind::ALL
        .iter()
        .map(|&kind| {
            let accel = Accel::build(mesh, kind, axis, &AccelParams::default())?;
            let s = accel.stats();
            log(format_args!(
                "built {kind}: {} references, {:.1} MB, {:.2} s",
                s.references(),
                s.bytes() as f64 / 1e6,
                s.build_s()
            ));
            Ok(accel)
        })
        .collect()
}

/// `cyl ÷ cart` for each key the two objects share.
fn ratios(cart: &Value, cyl: &Value, keys: &[&str]) -> Value {
    let mut out = Map::new();
    for k in keys {
        if let (Some(a), Some(b)) = (cart[k].as_f64(), cyl[k].as_f64()) {
            if a > 0.0 {
                out.insert((*k).to_string(), json!(b / a));
            }
        }
    }
    Value::Object(out)
}

pub fn run(args: &StatsArgs) -> Result<(), Error> {
    let mesh = args.input.load()?;
    let (axis, _) = args.input.axis(&mesh);
    let built = build_all(&mesh, &axis)?;
    let mut structures = Map::new();
    for accel in &built {
        structures.insert(accel.kind().name().to_string(), stats_json(&accel.stats()));
    }
    let grid_keys = ["grid_cells", "references", "bytes", "build_s"];
    let bvh_keys = ["nodes", "references", "bytes", "surface_area", "build_s"];
    let report = json!({
        "dataset": cylvol::input::Input::parse(&args.input.input)?.label(),
        "cells": mesh.cell_count(),
        "structures": structures,
        "ratios": {
            "grid": ratios(&structures["cart-grid"], &structures["cyl-grid"], &grid_keys),
            "bvh": ratios(&structures["cart-bvh"], &structures["cyl-bvh"], &bvh_keys),
        },
    });
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| Error::Invalid(e.to_string()))?
        );
        return Ok(());
    }
    let cells = mesh.cell_count() as f64;
    println!(
        "{} — {} cells",
        report["dataset"].as_str().unwrap_or(""),
        mesh.cell_count()
    );
    println!(
        "{:<10} {:>12} {:>12} {:>10} {:>12} {:>9}",
        "structure", "grid cells", "references", "B/cell", "area", "build s"
    );
    for accel in &built {
        let s = stats_json(&accel.stats());
        let num = |k: &str| {
            s[k].as_f64()
                .map(|v| format!("{v:.0}"))
                .unwrap_or_else(|| "-".into())
        };
        println!(
            "{:<10} {:>12} {:>12} {:>10.1} {:>12} {:>9.3}",
            accel.kind().name(),
            if accel.kind().is_grid() {
                num("grid_cells")
            } else {
                num("nodes") + " n"
            },
            num("references"),
            s["bytes"].as_f64().unwrap_or(0.0) / cells,
            s["surface_area"]
                .as_f64()
                .map(|v| format!("{v:.2}"))
                .unwrap_or_else(|| "-".into()),
            s["build_s"].as_f64().unwrap_or(0.0)
        );
    }
    for (name, keys) in [("grid", &grid_keys[..]), ("bvh", &bvh_keys[..])] {
        let r = &report["ratios"][name];
        let parts: Vec<String> = keys
            .iter()
            .filter_map(|k| r[k].as_f64().map(|v| format!("{k} {v:.2}")))
            .collect();
        println!("cyl ÷ cart {name}: {}", parts.join(", "));
    }
    Ok(())
}
