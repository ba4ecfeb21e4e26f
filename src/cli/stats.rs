//! `cylvol stats INPUT [--json]`: builds the four structures and reports the talk's figures —
//! grid cells, references, bytes, surface area, build time — with cylindrical ÷ Cartesian
//! ratios.

use serde_json::{json, Map, Value};

use super::periodic::PeriodicArgs;
use super::{log, InputArgs};
use cylvol::accel::probe::{candidate_count, lookup_cost, points_in_cells};
use cylvol::accel::{
    Accel, AccelParams, BvhParams, CandidateOrder, GridParams, StructureKind, StructureStats,
};
use cylvol::Error;

/// Arguments of `cylvol stats`.
#[derive(clap::Args, Debug)]
pub struct StatsArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Print JSON on standard output.
    #[arg(long)]
    json: bool,
    /// Points (inside random cells, seeded) to locate through each structure to measure the
    /// work per lookup; 0 skips it.
    #[arg(long, default_value_t = 100_000, value_parser = parse_lookups, allow_hyphen_values = true)]
    lookups: usize,
    /// Grid densities: a preset (default, fast, compact, paper) or `TOP,LEAF` densities.
    #[arg(
        long,
        value_name = "PRESET|λ1,λ2",
        default_value = "default",
        allow_hyphen_values = true
    )]
    grid: String,
    /// BVH parameters: a preset (balanced, fast-build, fine).
    #[arg(long, value_name = "PRESET", default_value = "balanced")]
    bvh: String,
    /// The grids' candidate order instead of the preset's: `cells` (cell ids, the talk's
    /// grids; every preset but `fast`) or `share` (the cells covering most of the grid cell
    /// first).
    #[arg(long, value_name = "cells|share")]
    grid_order: Option<CandidateOrder>,
    /// The wheel of a periodic sector: said in the report (the structures serve every copy,
    /// so their figures are the sector's whatever the copies).
    #[command(flatten)]
    periodic: PeriodicArgs,
}

/// Parses `--lookups N`, 0 or more.
fn parse_lookups(s: &str) -> Result<usize, String> {
    super::number::whole_in(s, "lookups", 0, usize::MAX as u64).map(|n| n as usize)
}

/// The structure parameters `--grid` and `--bvh` name.
pub fn params_from(grid: &str, bvh: &str) -> Result<AccelParams, Error> {
    let grid_params = match GridParams::PRESETS.iter().find(|(n, _)| *n == grid) {
        Some((_, p)) => *p,
        None => {
            let bad = || {
                Error::Invalid(format!(
                    "--grid '{grid}': expected default, fast, compact, paper, or two densities TOP,LEAF"
                ))
            };
            let (a, b) = grid.split_once(',').ok_or_else(bad)?;
            let top: f64 = a.trim().parse().map_err(|_| bad())?;
            let leaf: f64 = b.trim().parse().map_err(|_| bad())?;
            if !(top > 0.0 && leaf > 0.0 && top.is_finite() && leaf.is_finite()) {
                return Err(Error::Invalid(format!(
                    "--grid '{grid}': the densities TOP,LEAF must be positive and finite"
                )));
            }
            GridParams {
                top_density: top,
                leaf_density: leaf,
                ..GridParams::DEFAULT
            }
        }
    };
    let bvh_params = BvhParams::PRESETS
        .iter()
        .find(|(n, _)| *n == bvh)
        .map(|(_, p)| *p)
        .ok_or_else(|| {
            Error::Invalid(format!(
                "--bvh '{bvh}': expected balanced, fast-build or fine"
            ))
        })?;
    Ok(AccelParams {
        grid: grid_params,
        bvh: bvh_params,
        ..AccelParams::default()
    })
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
pub fn build_all(
    mesh: &cylvol::Mesh,
    axis: &cylvol::axis::Axis,
    params: &AccelParams,
) -> Result<Vec<Accel>, Error> {
    StructureKind::ALL
        .iter()
        .map(|&kind| super::build_logged(mesh, kind, axis, params))
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
    // Checked before the mesh is loaded.
    let mut params = params_from(&args.grid, &args.bvh)?;
    let mesh = args.input.load()?;
    let (axis, _) = args.input.axis(&mesh);
    if let Some(order) = args.grid_order {
        params.grid.order = order;
    }
    let copies = args.periodic.copies(&mesh, &axis)?;
    let built = build_all(&mesh, &axis, &params)?;
    let points = points_in_cells(&mesh, args.lookups, 0x00C7_1D0F);
    let mut structures = Map::new();
    for accel in &built {
        let mut entry = stats_json(&accel.stats());
        if !points.is_empty() {
            let cost = lookup_cost(accel, &mesh, &points);
            let all = candidate_count(accel, &mesh, &points);
            log(format_args!(
                "{}: {:.2} hexahedra tested, {:.1} internal and {:.2} leaf visits per lookup, {:.0} ns; {:.2} candidates, {:.2} with the point in their box",
                accel.kind(),
                cost.hex_tests,
                cost.internal_visits,
                cost.leaf_visits,
                cost.ns_per_lookup,
                all.candidates,
                all.in_box
            ));
            entry["lookup"] = json!({
                "lookups": cost.lookups,
                "found": cost.found,
                "hex_tests": cost.hex_tests,
                "internal_visits": cost.internal_visits,
                "leaf_visits": cost.leaf_visits,
                "ns_per_lookup": cost.ns_per_lookup,
                "candidates": all.candidates,
                "candidates_in_box": all.in_box,
            });
            for (k, v) in [
                ("hex_tests", cost.hex_tests),
                ("internal_visits", cost.internal_visits),
                ("leaf_visits", cost.leaf_visits),
                ("candidates", all.candidates),
                ("candidates_in_box", all.in_box),
            ] {
                entry[k] = json!(v);
            }
        }
        structures.insert(accel.kind().name().to_string(), entry);
    }
    let grid_keys = [
        "grid_cells",
        "references",
        "bytes",
        "build_s",
        "hex_tests",
        "candidates",
        "candidates_in_box",
    ];
    let bvh_keys = [
        "nodes",
        "references",
        "bytes",
        "surface_area",
        "build_s",
        "hex_tests",
        "internal_visits",
        "leaf_visits",
        "candidates",
        "candidates_in_box",
    ];
    let report = json!({
        "dataset": cylvol::input::Input::parse(&args.input.input)?.label(),
        "cells": mesh.cell_count(),
        "periodic": super::periodic::json(copies.as_ref()),
        "structures": structures,
        "ratios": {
            "grid": ratios(&structures["cart-grid"], &structures["cyl-grid"], &grid_keys),
            "bvh": ratios(&structures["cart-bvh"], &structures["cyl-bvh"], &bvh_keys),
        },
    });
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| Error::Invalid(e.to_string()))?
        );
        return Ok(());
    }
    let cells = mesh.cell_count() as f64;
    outln!(
        "{} — {} cells",
        report["dataset"].as_str().unwrap_or(""),
        mesh.cell_count()
    );
    outln!(
        "{:<10} {:>12} {:>12} {:>8} {:>10} {:>8} {:>8} {:>9} {:>7} {:>8} {:>7}",
        "structure",
        "grid cells",
        "references",
        "B/cell",
        "area",
        "build s",
        "hex/lk",
        "inner/lk",
        "leaf/lk",
        "cand/lk",
        "box/lk"
    );
    for accel in &built {
        let s = &structures[accel.kind().name()];
        let fmt = |k: &str, digits: usize| {
            s[k].as_f64()
                .map(|v| format!("{v:.digits$}"))
                .unwrap_or_else(|| "-".into())
        };
        outln!(
            "{:<10} {:>12} {:>12} {:>8.1} {:>10} {:>8.3} {:>8} {:>9} {:>7} {:>8} {:>7}",
            accel.kind().name(),
            if accel.kind().is_grid() {
                fmt("grid_cells", 0)
            } else {
                fmt("nodes", 0) + " n"
            },
            fmt("references", 0),
            s["bytes"].as_f64().unwrap_or(0.0) / cells,
            fmt("surface_area", 2),
            s["build_s"].as_f64().unwrap_or(0.0),
            fmt("hex_tests", 2),
            fmt("internal_visits", 2),
            fmt("leaf_visits", 2),
            fmt("candidates", 2),
            fmt("candidates_in_box", 2),
        );
    }
    for (name, keys) in [("grid", &grid_keys[..]), ("bvh", &bvh_keys[..])] {
        let r = &report["ratios"][name];
        let parts: Vec<String> = keys
            .iter()
            .filter_map(|k| r[k].as_f64().map(|v| format!("{k} {v:.2}")))
            .collect();
        outln!("cyl ÷ cart {name}: {}", parts.join(", "));
    }
    Ok(())
}
