//! Ray-casting measurements (a plain program, not criterion: it prints a table).
//!
//! `cargo bench --bench render -- [INPUT] [SIZE] [FRAMES] [STRUCTURES] [PATHS] [SEGMENTS]`
//! (default `pump-rotor:200000 256 3 all both segments`; `INPUT` a dataset `NAME[:CELLS]` or a
//! mesh file, as the CLI takes it, `--scalar=NAME` its scalar array): builds the face
//! neighbours and each chosen structure once (not timed as frames), then renders `FRAMES`
//! frames per structure and path at `SIZE × SIZE` with the default step and view, and prints
//! the best frame time (wall and process CPU seconds, the latter less sensitive to other
//! programs on the machine) with the work counters: samples, samples located, hexahedra tested
//! (in total, per located sample, and per located sample without the boundary crossing
//! searches), the crossing searches' tests, internal and leaf visits, samples skipped as empty
//! space, cells walked across, structure locations. `STRUCTURES` is `all` or a comma-separated
//! list (`cyl-bvh,cart-grid`), `PATHS` `both`, `paper` or `fast`, `SEGMENTS` `segments`
//! (boundary segments, the default) or `whole` (whole steps).
//!
//! `--vtk-scene` renders the scene of the VTK comparison (`scripts/bench_vtk.py`, whose
//! `cylvol render` options docs/cli.md gives) instead of the default one: its opacity and
//! colour points, the opacity read as an attenuation (as VTK's unstructured ray caster and
//! vtkCylVolMapper read it), a unit distance of 10 % of the bounding-box diagonal, every cell
//! with some opacity; `--step-factor=F` multiplies the default step by `F` (the comparison is also run
//! at 4× and 8×). `--march-reach=R` sets [`RenderOptions::march_reach`] (how many cells ahead
//! the fast path still marches to a sample; `inf` always marches); the `far` column counts the
//! samples it located through the structure instead.

use std::time::Instant;

#[path = "common/timing.rs"]
mod timing;

use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::geometry::bounds::Aabb;
use cylvol::input::Input;
use cylvol::io::ReadOptions;
use cylvol::render::{
    default_step, face_neighbours, Camera, RenderOptions, RenderPath, RenderStats, Renderer,
    TransferFunction, Volume,
};
use timing::cpu_seconds;

fn main() {
    let all: Vec<String> = std::env::args().skip(1).collect();
    let vtk_scene = all.iter().any(|a| a == "--vtk-scene");
    let step_factor: f64 = all
        .iter()
        .find_map(|a| a.strip_prefix("--step-factor="))
        .map_or(1.0, |f| f.parse().expect("a step factor"));
    let scalar = all
        .iter()
        .find_map(|a| a.strip_prefix("--scalar="))
        .map(str::to_string);
    let march_reach: Option<f64> = all
        .iter()
        .find_map(|a| a.strip_prefix("--march-reach="))
        .map(|r| r.parse().expect("a number of cells (or inf)"));
    let args: Vec<String> = all.into_iter().filter(|a| !a.starts_with("--")).collect();
    let spec = args.first().map_or("pump-rotor:200000", |s| s.as_str());
    let size: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(256);
    let frames: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3);
    let kinds: Vec<StructureKind> = match args.get(3).map(|s| s.as_str()) {
        None | Some("all") => StructureKind::ALL.to_vec(),
        Some(list) => list
            .split(',')
            .map(|k| k.parse().expect("a structure name"))
            .collect(),
    };
    let paths = match args.get(4).map(|s| s.as_str()) {
        None | Some("both") => vec![RenderPath::Paper, RenderPath::Fast],
        Some(p) => vec![p.parse().expect("paper, fast or both")],
    };
    let segments = args.get(5).map_or(true, |s| s != "whole");
    let input = Input::parse(spec).expect("an input");
    let mut mesh = input.load(&ReadOptions::default()).expect("input");
    if let Some(name) = &scalar {
        mesh.set_active_scalar(name).expect("scalar");
    }
    let synthetic = matches!(input, Input::Synthetic(..));
    let name = input.label();
    let axis = cylvol::axis::detect(&mesh);
    let neighbours = {
        let check = Accel::build(
            &mesh,
            StructureKind::CartBvh,
            &axis,
            &AccelParams::default(),
        )
        .expect("build");
        let n = face_neighbours(&mesh, &check);
        if synthetic {
            assert_eq!(
                n.hanging_faces(),
                Some(0),
                "the synthetic datasets are conforming"
            );
        }
        n
    };
    let step = default_step(&mesh) * step_factor;
    println!(
        "{name}: {} cells, {size}x{size}, step {step:.5}, best of {frames} frames",
        mesh.cell_count()
    );
    println!(
        "{:<10} {:<6} {:>8} {:>8} {:>10} {:>9} {:>10} {:>7} {:>7} {:>9} {:>11} {:>10} {:>10} {:>10} {:>9} {:>9}",
        "structure",
        "path",
        "frame_s",
        "cpu_s",
        "samples",
        "located",
        "hex_tests",
        "/loc",
        "/loc-bd",
        "boundary",
        "internal",
        "leaf",
        "skipped",
        "walked",
        "struct",
        "far"
    );
    for kind in kinds {
        let accel = Accel::build(&mesh, kind, &axis, &AccelParams::default()).expect("build");
        let volume = Volume::new(&mesh, &accel).expect("volume");
        let [lo, hi] = volume.scalar_range();
        let tf = if vtk_scene {
            let diagonal = Aabb::from_points(mesh.points()).diagonal();
            vtk_comparison_transfer(lo, hi, diagonal)
        } else {
            TransferFunction::default_for_range(lo, hi, 0.3, 0.1)
        };
        let camera = Camera::view(mesh.bounds(), size, size, 30.0, 20.0, 1.0);
        for &path in &paths {
            let mut options = RenderOptions::new(size, size, step);
            options.path = path;
            options.boundary_segments = segments;
            if let Some(r) = march_reach {
                options.march_reach = r;
            }
            let renderer = Renderer::new(&volume, &tf, &options)
                .expect("renderer")
                .with_topology(&neighbours);
            let mut best = f64::INFINITY;
            let mut best_cpu = f64::INFINITY;
            let mut stats = RenderStats::default();
            for _ in 0..frames.max(1) {
                let cpu = cpu_seconds();
                let started = Instant::now();
                let (_, s) = renderer.render(&camera, None).expect("render");
                best = best.min(started.elapsed().as_secs_f64());
                best_cpu = best_cpu.min(cpu_seconds() - cpu);
                stats = s;
            }
            let located = stats.samples_located.max(1) as f64;
            println!(
                "{:<10} {:<6} {:>8.3} {:>8.3} {:>10} {:>9} {:>10} {:>7.3} {:>7.3} {:>9} {:>11} {:>10} {:>10} {:>10} {:>9} {:>9}",
                kind.name(),
                path.name(),
                best,
                best_cpu,
                stats.samples,
                stats.samples_located,
                stats.hex_tests,
                stats.hex_tests as f64 / located,
                (stats.hex_tests - stats.boundary_refinements) as f64 / located,
                stats.boundary_refinements,
                stats.internal_visits,
                stats.leaf_visits,
                stats.space_skips,
                stats.walk_steps,
                stats.structure_locates,
                stats.far_locates
            );
        }
    }
}

/// The transfer function of the VTK comparison over the scalar range `[lo, hi]`: the CLI's
/// `--opacity 0%:0,35%:0.1,70%:0.5,100%:1 --color 0%:0.1:0.2:0.9,35%:0.1:0.8:0.8,
/// 70%:0.95:0.85:0.2,100%:0.9:0.1:0.1 --unit-distance 10%`.
fn vtk_comparison_transfer(lo: f64, hi: f64, diagonal: f64) -> TransferFunction {
    let at = |f: f64| lo + f * (hi - lo);
    let mut tf = TransferFunction::default_for_range(lo, hi, 0.3, 0.1);
    tf.opacity = vec![
        (at(0.0), 0.0),
        (at(0.35), 0.1),
        (at(0.7), 0.5),
        (at(1.0), 1.0),
    ];
    tf.color = vec![
        (at(0.0), [0.1, 0.2, 0.9]),
        (at(0.35), [0.1, 0.8, 0.8]),
        (at(0.7), [0.95, 0.85, 0.2]),
        (at(1.0), [0.9, 0.1, 0.1]),
    ];
    tf.unit_distance = 0.1 * diagonal;
    // Read as vtkCylVolMapper reads it by default (`--opacity-convention attenuation`).
    tf.attenuation_as_opacity(lo, hi, cylvol::render::VTK_MAPPER_TABLE_ENTRIES)
}
