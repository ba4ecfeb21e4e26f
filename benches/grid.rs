//! Two-level grid measurements (a plain program, not criterion: it prints tables).
//!
//! - `cargo bench --bench grid -- sweep [CELLS]`: for pump-rotor (`CELLS`, default 300 000)
//!   and the real meshes, sweeps the top and leaf densities and prints, for Cartesian and
//!   cylindrical grids, bytes per mesh cell, references per mesh cell, hexahedra tested per
//!   lookup (the real cell test on random points inside random cells) and build time.
//!   `sweep-real` sweeps the real meshes alone.
//! - `cargo bench --bench grid -- compare [SCALE]`: Cartesian against cylindrical grids on the
//!   three pump datasets (`SCALE` × their default sizes, default 1): grid cells, references,
//!   bytes, build time, hexahedra tested per lookup, with default densities and with the
//!   cylindrical leaf density tuned to within ±5 % of the Cartesian grid cells.
//! - no mode: both, at small sizes.

use std::path::Path;
use std::time::Instant;

use cylvol::accel::grid::{build_grid, GridParams, TwoLevelGrid};
use cylvol::accel::space::{self, Coordinates};
use cylvol::accel::Counters;
use cylvol::datasets::{generate, Dataset};
use cylvol::geometry::containment::locate_in_cell;
use cylvol::geometry::cylindrical::CylFrame;
use cylvol::geometry::trilinear::map;
use cylvol::Mesh;
use glam::DVec3;

/// Deterministic points inside random cells.
fn points(mesh: &Mesh, n: usize) -> Vec<DVec3> {
    let mut s = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let c = ((next() * mesh.cell_count() as f64) as usize).min(mesh.cell_count() - 1);
            map(&mesh.cell_corners(c), DVec3::new(next(), next(), next()))
        })
        .collect()
}

/// The grid's coordinates and boxes for a mesh, and the time to make the boxes.
fn boxes(
    mesh: &Mesh,
    cylindrical: bool,
) -> (
    Coordinates,
    space::Pieces<cylvol::geometry::bounds::Aabb>,
    f64,
) {
    let t = Instant::now();
    if !cylindrical {
        let p = space::cartesian_pieces(mesh);
        return (Coordinates::Cartesian, p, t.elapsed().as_secs_f64());
    }
    let axis = cylvol::axis::detect(mesh);
    let frame = CylFrame::new(axis.origin, axis.direction).expect("axis");
    let pieces = space::cylindrical_pieces(mesh, &frame, space::DEFAULT_STRADDLE_SECTORS);
    let (frame, pieces) = space::seam_frame(&axis, pieces).expect("axis");
    let b = space::linear_boxes(&pieces);
    (
        Coordinates::Cylindrical(frame),
        b,
        t.elapsed().as_secs_f64(),
    )
}

/// Hexahedra tested per lookup (points inside the mesh), the fraction found, and the time per
/// lookup in nanoseconds (one thread).
fn tests_per_lookup(mesh: &Mesh, grid: &TwoLevelGrid, pts: &[DVec3]) -> (f64, f64, f64) {
    let start = Instant::now();
    let coords = grid.coordinates();
    let mut counters = Counters::default();
    let mut tests = 0u64;
    let mut found = 0usize;
    for &p in pts {
        let f = grid.find(coords.query(p), &mut counters, |c| {
            tests += 1;
            locate_in_cell(&mesh.cell_corners(c as usize), p, None).is_some()
        });
        found += f.is_some() as usize;
    }
    let ns = start.elapsed().as_secs_f64() * 1e9 / pts.len() as f64;
    (
        tests as f64 / pts.len() as f64,
        found as f64 / pts.len() as f64,
        ns,
    )
}

fn sweep(name: &str, mesh: &Mesh) {
    let pts = points(mesh, 20_000);
    let n = mesh.cell_count() as f64;
    println!("\n## {name}: {} cells", mesh.cell_count());
    println!("| coords | λ1 | λ2 | grid cells/cell | refs/cell | bytes/cell | hex tests/lookup | ns/lookup | build s |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for cyl in [false, true] {
        let (coords, b, _) = boxes(mesh, cyl);
        for top in [1.0 / 64.0, 1.0 / 16.0, 1.0 / 4.0] {
            for leaf in [0.125, 0.25, 0.5, 1.0, 2.0, 4.0] {
                let params = GridParams {
                    top_density: top,
                    leaf_density: leaf,
                    ..GridParams::DEFAULT
                };
                let g = build_grid(coords, &b, &params);
                let s = g.stats();
                let (t, found, ns) = tests_per_lookup(mesh, &g, &pts);
                assert!(
                    found > 0.999,
                    "{name}: only {found} of points inside cells found"
                );
                println!(
                    "| {} | 1/{} | {leaf} | {:.2} | {:.2} | {:.1} | {:.2} | {:.0} | {:.3} |",
                    if cyl { "cyl" } else { "cart" },
                    (1.0 / top).round(),
                    s.grid_cells as f64 / n,
                    s.references as f64 / n,
                    s.bytes as f64 / n,
                    t,
                    ns,
                    s.build_s
                );
            }
        }
    }
}

fn compare(scale: f64) {
    println!("\n| dataset | cells | grid | λ2 | grid cells | references | MB | bytes/cell | build s (+boxes s) | hex tests/lookup |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for d in [
        Dataset::PumpInlet,
        Dataset::PumpRotor,
        Dataset::PumpDiffuser,
    ] {
        let cells = ((d.default_cells() as f64 * scale) as usize).max(1_000);
        let mesh = generate(d, cells).expect("dataset");
        let pts = points(&mesh, 20_000);
        let n = mesh.cell_count() as f64;
        let row = |label: &str, g: &TwoLevelGrid, leaf: f64, boxes_s: f64| {
            let s = g.stats();
            let (t, _, _) = tests_per_lookup(&mesh, g, &pts);
            println!(
                "| {d} | {} | {label} | {leaf:.2} | {} | {} | {:.1} | {:.1} | {:.3} (+{:.3}) | {:.2} |",
                mesh.cell_count(),
                s.grid_cells,
                s.references,
                s.bytes as f64 / 1e6,
                s.bytes as f64 / n,
                s.build_s,
                boxes_s,
                t
            );
            s
        };
        let params = GridParams::default();
        let (cc, cb, cs) = boxes(&mesh, false);
        let cart = build_grid(cc, &cb, &params);
        drop(cb);
        let sc = row("cart", &cart, params.leaf_density, cs);
        drop(cart);
        let (yc, yb, ys) = boxes(&mesh, true);
        let cyl = build_grid(yc, &yb, &params);
        let sy = row("cyl", &cyl, params.leaf_density, ys);
        drop(cyl);
        // Equal grid cells: tune the cylindrical leaf density (grid cells ≈ ∝ λ2).
        let mut leaf = params.leaf_density;
        let mut cells_now = sy.grid_cells as f64;
        for _ in 0..8 {
            let ratio = cells_now / sc.grid_cells as f64;
            if (ratio - 1.0).abs() <= 0.05 {
                break;
            }
            leaf /= ratio;
            let g = build_grid(
                yc,
                &yb,
                &GridParams {
                    leaf_density: leaf,
                    ..params
                },
            );
            cells_now = g.stats().grid_cells as f64;
        }
        let g = build_grid(
            yc,
            &yb,
            &GridParams {
                leaf_density: leaf,
                ..params
            },
        );
        let st = row("cyl, equal cells", &g, leaf, ys);
        println!(
            "| {d} | ratio cyl/cart at equal cells | | | {:.2} | {:.2} | {:.2} | | {:.2} | |",
            st.grid_cells as f64 / sc.grid_cells as f64,
            st.references as f64 / sc.references as f64,
            st.bytes as f64 / sc.bytes as f64,
            st.build_s / sc.build_s
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let mode = args.first().map(String::as_str).unwrap_or("");
    let number = |i: usize| args.get(i).and_then(|s| s.parse::<f64>().ok());
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    match mode {
        "sweep" => {
            let cells = number(1).unwrap_or(300_000.0) as usize;
            sweep(
                "pump-rotor",
                &generate(Dataset::PumpRotor, cells).expect("dataset"),
            );
            for f in ["postxyz.bin", "combxyz.bin"] {
                match cylvol::io::read_file(&data.join(f), &Default::default()) {
                    Ok(m) => sweep(f, &m),
                    Err(e) => eprintln!("skipping {f}: {e}"),
                }
            }
        }
        "compare" => compare(number(1).unwrap_or(1.0)),
        _ => {
            sweep(
                "pump-rotor",
                &generate(Dataset::PumpRotor, 30_000).expect("dataset"),
            );
            compare(0.02);
        }
    }
}
