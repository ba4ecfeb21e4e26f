//! Build time of the face adjacency (`cylvol::mesh::topology::FaceNeighbours`) on the synthetic
//! pump datasets at their default sizes, against two simpler ways of computing the same table:
//! a `HashMap` from face key to face, and one parallel sort of all faces by key.
//!
//! `cargo bench --bench topology` — prints each table's bytes per cell and a first-run time,
//! then criterion's timings. `CYLVOL_BENCH_SCALE=0.1` uses a tenth of the default sizes.

use std::collections::HashMap;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use cylvol::datasets::{generate, Dataset};
use cylvol::mesh::topology::{FaceKey, FaceNeighbours, NONE};
use cylvol::Mesh;
use rayon::prelude::*;

/// The table by a `HashMap` from key to the first face seen with it (sequential).
fn hashmap_table(mesh: &Mesh) -> Vec<u32> {
    let cells = mesh.cells();
    let mut table = vec![NONE; cells.len() * 6];
    let mut open: HashMap<FaceKey, (u32, u8, u32)> = HashMap::with_capacity(cells.len() * 3);
    for (c, cell) in cells.iter().enumerate() {
        for f in 0..6 {
            let key = FaceKey::of_cell(cell, f);
            if key.is_degenerate() {
                continue;
            }
            open.entry(key)
                .and_modify(|e| e.2 += 1)
                .or_insert((c as u32, f as u8, 1));
        }
    }
    for (c, cell) in cells.iter().enumerate() {
        for f in 0..6 {
            let key = FaceKey::of_cell(cell, f);
            if let Some(&(c0, f0, 2)) = open.get(&key) {
                if c0 as usize != c {
                    table[c * 6 + f] = c0;
                    table[c0 as usize * 6 + f0 as usize] = c as u32;
                }
            }
        }
    }
    table
}

/// The table by one parallel sort of every non-degenerate face by key.
fn sorted_table(mesh: &Mesh) -> Vec<u32> {
    let cells = mesh.cells();
    let mut faces: Vec<(FaceKey, u32, u8)> = cells
        .par_iter()
        .enumerate()
        .flat_map_iter(|(c, cell)| {
            (0..6).filter_map(move |f| {
                let key = FaceKey::of_cell(cell, f);
                (!key.is_degenerate()).then_some((key, c as u32, f as u8))
            })
        })
        .collect();
    faces.par_sort_unstable();
    let mut table = vec![NONE; cells.len() * 6];
    for run in faces.chunk_by(|a, b| a.0 == b.0) {
        if let [(_, ca, fa), (_, cb, fb)] = run {
            if ca != cb {
                table[*ca as usize * 6 + *fa as usize] = *cb;
                table[*cb as usize * 6 + *fb as usize] = *ca;
            }
        }
    }
    table
}

fn bench(c: &mut Criterion) {
    let scale: f64 = std::env::var("CYLVOL_BENCH_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.0);
    let mut group = c.benchmark_group("topology");
    group.sample_size(10);
    for d in Dataset::ALL {
        let cells = (d.default_cells() as f64 * scale) as usize;
        let mesh = generate(d, cells).expect("dataset");
        let start = Instant::now();
        let adj = FaceNeighbours::build(&mesh);
        let first = start.elapsed().as_secs_f64();
        eprintln!(
            "{d}:{cells}: {} cells, {} boundary faces, {:.2} bytes/cell, first build {:.3} s on {} threads",
            mesh.cell_count(),
            adj.boundary_face_count(),
            adj.bytes() as f64 / mesh.cell_count() as f64,
            first,
            rayon::current_num_threads()
        );
        group.bench_function(format!("build/{d}"), |b| {
            b.iter(|| FaceNeighbours::build(&mesh))
        });
        let tolerance = FaceNeighbours::seam_tolerance(&mesh);
        group.bench_function(format!("build_with_tolerance/{d}"), |b| {
            b.iter(|| FaceNeighbours::build_with_tolerance(&mesh, tolerance))
        });
        if d == Dataset::PumpRotor {
            assert_eq!(hashmap_table(&mesh), adj.raw());
            assert_eq!(sorted_table(&mesh), adj.raw());
            group.bench_function(format!("hashmap/{d}"), |b| b.iter(|| hashmap_table(&mesh)));
            group.bench_function(format!("full_sort/{d}"), |b| b.iter(|| sorted_table(&mesh)));
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
