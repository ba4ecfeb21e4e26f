//! Generation time of the synthetic pump datasets at their default (the talk's) sizes.
//!
//! `cargo bench --bench datasets` — prints each mesh's cells, points and memory first, then
//! criterion's timings. `CYLVOL_BENCH_SCALE=0.1` generates a tenth of the default size.

use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use cylvol::datasets::{generate, Dataset};
use cylvol::Mesh;

fn mesh_bytes(mesh: &Mesh) -> usize {
    let arrays: usize = mesh
        .point_data()
        .iter()
        .chain(mesh.cell_data())
        .map(|a| a.values.len() * 8)
        .sum();
    mesh.point_count() * 24 + mesh.cell_count() * (32 + 1) + arrays
}

fn bench(c: &mut Criterion) {
    let scale: f64 = std::env::var("CYLVOL_BENCH_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.0);
    let mut group = c.benchmark_group("generate");
    group.sample_size(10);
    for d in Dataset::ALL {
        let cells = (d.default_cells() as f64 * scale) as usize;
        let start = Instant::now();
        let mesh = generate(d, cells).expect("dataset");
        eprintln!(
            "{d}:{cells}: {} cells, {} points, {:.1} MB, first run {:.2} s on {} threads",
            mesh.cell_count(),
            mesh.point_count(),
            mesh_bytes(&mesh) as f64 / 1e6,
            start.elapsed().as_secs_f64(),
            rayon::current_num_threads()
        );
        drop(mesh);
        group.bench_function(d.name(), |b| {
            b.iter(|| generate(d, cells).expect("dataset"))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
