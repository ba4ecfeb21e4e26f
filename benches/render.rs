//! Ray-casting measurements (a plain program, not criterion: it prints a table).
//!
//! `cargo bench --bench render -- [DATASET[:CELLS]] [SIZE] [FRAMES]` (default
//! `pump-rotor:200000 256 3`): builds the four structures and the face neighbours once (not
//! timed as frames), then renders `FRAMES` frames per structure and path at `SIZE × SIZE`
//! with the default step and view, and prints the best frame time with the work counters:
//! samples, samples located, hexahedra tested (in total and per located sample), internal and
//! leaf visits, samples skipped as empty space, cells walked across, structure locations.

use std::time::Instant;

use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::datasets::{generate, Dataset};
use cylvol::mesh::topology::FaceNeighbors;
use cylvol::render::{
    default_step, Camera, RenderOptions, RenderPath, RenderStats, Renderer, TransferFunction,
    Volume,
};

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let spec = args.first().map_or("pump-rotor:200000", |s| s.as_str());
    let size: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(256);
    let frames: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3);
    let (name, cells) = spec.split_once(':').unwrap_or((spec, "200000"));
    let dataset = match name {
        "pump-inlet" => Dataset::PumpInlet,
        "pump-diffuser" => Dataset::PumpDiffuser,
        _ => Dataset::PumpRotor,
    };
    let cells: usize = cells.parse().unwrap_or(200_000);
    let mesh = generate(dataset, cells).expect("dataset");
    let axis = cylvol::axis::detect(&mesh);
    let neighbours =
        FaceNeighbors::build_with_tolerance(&mesh, FaceNeighbors::seam_tolerance(&mesh));
    let step = default_step(&mesh);
    println!(
        "{name}: {} cells, {size}x{size}, step {step:.5}, best of {frames} frames",
        mesh.cell_count()
    );
    println!(
        "{:<10} {:<6} {:>8} {:>10} {:>9} {:>10} {:>7} {:>11} {:>10} {:>10} {:>10} {:>9}",
        "structure",
        "path",
        "frame_s",
        "samples",
        "located",
        "hex_tests",
        "/loc",
        "internal",
        "leaf",
        "skipped",
        "walked",
        "struct"
    );
    for kind in StructureKind::ALL {
        let accel = Accel::build(&mesh, kind, &axis, &AccelParams::default()).expect("build");
        let volume = Volume::new(&mesh, &accel).expect("volume");
        let [lo, hi] = volume.scalar_range();
        let tf = TransferFunction::default_for_range(lo, hi, 0.3, 0.1);
        let camera = Camera::view(mesh.bounds(), size, size, 30.0, 20.0, 1.0);
        for path in [RenderPath::Paper, RenderPath::Fast] {
            let mut options = RenderOptions::new(size, size, step);
            options.path = path;
            let renderer = Renderer::new(&volume, &tf, &options)
                .expect("renderer")
                .with_neighbours(&neighbours);
            let mut best = f64::INFINITY;
            let mut stats = RenderStats::default();
            for _ in 0..frames.max(1) {
                let started = Instant::now();
                let (_, s) = renderer.render(&camera, None).expect("render");
                best = best.min(started.elapsed().as_secs_f64());
                stats = s;
            }
            println!(
                "{:<10} {:<6} {:>8.3} {:>10} {:>9} {:>10} {:>7.3} {:>11} {:>10} {:>10} {:>10} {:>9}",
                kind.name(),
                path.name(),
                best,
                stats.samples,
                stats.samples_located,
                stats.hex_tests,
                stats.hex_tests as f64 / stats.samples_located.max(1) as f64,
                stats.internal_visits,
                stats.leaf_visits,
                stats.space_skips,
                stats.walk_steps,
                stats.structure_locates
            );
        }
    }
}
