//! What axis detection costs and finds (a plain program, not criterion: it prints a table).
//!
//! `cargo bench --bench axis -- [INPUT ...] [--repeats=N]`: for each `INPUT` (what `cylvol
//! render` takes: a dataset `NAME[:CELLS]` or a mesh file; by default the real meshes of
//! `tests/data/` and the three pump datasets at 2,000, 3,000, 20,000 and 200,000 cells), the
//! best of `N` (default 3) runs of [`cylvol::axis::detect_with_report`]: wall and process CPU
//! seconds, the cells sampled and the evaluations over the sample, whether the axis is clear,
//! and the axis found, every coordinate printed in full (`{:?}`) so that two builds' outputs
//! can be compared line by line for the same axes.

#[path = "common/timing.rs"]
mod timing;

use cylvol::axis::detect_with_report;
use cylvol::io::ReadOptions;
use timing::best;

fn main() {
    let all: Vec<String> = std::env::args().skip(1).collect();
    let repeats: usize = all
        .iter()
        .find_map(|a| a.strip_prefix("--repeats="))
        .map_or(3, |r| r.parse().expect("a number of repeats"));
    let mut inputs: Vec<String> = all.into_iter().filter(|a| !a.starts_with("--")).collect();
    if inputs.is_empty() {
        let data = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");
        for file in ["mixer.vtk", "postxyz.bin", "combxyz.bin", "hexa.vtk"] {
            inputs.push(format!("{data}{file}"));
        }
        for cells in [2_000, 3_000, 20_000, 200_000] {
            for name in ["pump-inlet", "pump-rotor", "pump-diffuser"] {
                inputs.push(format!("{name}:{cells}"));
            }
        }
    }
    println!(
        "{:<24} {:>8} {:>7} {:>6} {:>8} {:>8} {:>6}  axis (origin; direction)",
        "input", "cells", "sampled", "evals", "wall ms", "cpu ms", "clear"
    );
    for spec in &inputs {
        let mesh = cylvol::input::load(spec, &ReadOptions::default()).expect("a loadable INPUT");
        let ((wall, cpu), report) = best(repeats, || detect_with_report(&mesh));
        let name = spec.rsplit('/').next().unwrap_or(spec);
        println!(
            "{name:<24} {:>8} {:>7} {:>6} {:>8.1} {:>8.1} {:>6}  {:?}; {:?}",
            mesh.cell_count(),
            report.sampled_cells,
            report.evaluations,
            wall * 1e3,
            cpu * 1e3,
            report.clear,
            report.axis.origin.to_array(),
            report.axis.direction.to_array(),
        );
    }
}
