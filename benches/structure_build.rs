//! Build-time breakdown of the four structures (a plain program, not criterion: it prints a
//! table).
//!
//! `cargo bench --bench structure_build -- [CELLS] [REPEATS] [INPUT] [--hash]` generates
//! pump-rotor with `CELLS` cells (default 2 100 000, its default size), or loads `INPUT` (what
//! `cylvol render` takes: a dataset `NAME[:CELLS]` or a mesh file), detects its axis, and times each
//! phase of the builds `REPEATS` times (default 3), printing the best time of each:
//! Cartesian pieces, cylindrical pieces, the seam frame, the linear boxes, each structure alone,
//! and `Accel::build` of each of the four (pieces included — the figure `cylvol stats` reports).
//! With `--hash`, it also prints a hash of every built structure (its `Debug` form, build time
//! left out), so two versions of the build code can be checked to give identical structures.
//! Set `RAYON_NUM_THREADS` to check that the hashes do not depend on the thread count.

use std::fmt::{self, Write};
use std::hash::Hasher;

#[path = "common/timing.rs"]
mod timing;

use cylvol::accel::bvh::build_bvh;
use cylvol::accel::grid::build_grid;
use cylvol::accel::space::{
    cartesian_pieces, cylindrical_pieces, linear_boxes, seam_frame, Coordinates,
    DEFAULT_STRADDLE_SECTORS,
};
use cylvol::accel::{Accel, AccelParams, BvhParams, GridParams, StructureKind};
use cylvol::geometry::cylindrical::CylFrame;
use cylvol::io::ReadOptions;
use timing::best;

/// Hashes what is written to it, skipping every `build_s: VALUE` (a timing, not a result).
struct DebugHash {
    hasher: std::collections::hash_map::DefaultHasher,
    tail: [u8; 9],
    skipping: bool,
}

impl DebugHash {
    fn new() -> Self {
        DebugHash {
            hasher: Default::default(),
            tail: [0; 9],
            skipping: false,
        }
    }
}

impl Write for DebugHash {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for &b in s.as_bytes() {
            if self.skipping {
                if b == b',' || b == b'}' || b == b'\n' {
                    self.skipping = false;
                } else {
                    continue;
                }
            }
            self.hasher.write_u8(b);
            self.tail.rotate_left(1);
            self.tail[8] = b;
            if &self.tail == b"build_s: " {
                self.skipping = true;
            }
        }
        Ok(())
    }
}

fn hash_of(x: &impl fmt::Debug) -> u64 {
    let mut h = DebugHash::new();
    write!(h, "{x:?}").expect("hashing never fails");
    h.hasher.finish()
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let hash = args.iter().any(|a| a == "--hash");
    let nums: Vec<usize> = args.iter().filter_map(|a| a.parse().ok()).collect();
    let cells = nums.first().copied().unwrap_or(2_100_000);
    let repeats = nums.get(1).copied().unwrap_or(3).max(1);

    let spec = args
        .iter()
        .find(|a| !a.starts_with("--") && a.parse::<usize>().is_err())
        .cloned()
        .unwrap_or_else(|| format!("pump-rotor:{cells}"));
    let mesh = cylvol::input::load(&spec, &ReadOptions::default()).expect("a loadable INPUT");
    let axis = cylvol::axis::detect(&mesh);
    println!(
        "{spec}, {} cells, {} threads, best of {repeats}",
        mesh.cell_count(),
        rayon::current_num_threads()
    );
    println!("  {:<28} {:>8} {:>8}", "phase", "wall s", "cpu s");
    let row = |name: &str, (w, c): (f64, f64)| println!("  {name:<28} {w:>8.3} {c:>8.2}");

    let (t, cart) = best(repeats, || cartesian_pieces(&mesh));
    row("cartesian_pieces", t);
    let frame = CylFrame::new(axis.origin, axis.direction).expect("usable axis");
    let (t, cyl) = best(repeats, || {
        cylindrical_pieces(&mesh, &frame, DEFAULT_STRADDLE_SECTORS)
    });
    row("cylindrical_pieces", t);
    let (t, seamed) = best(repeats, || seam_frame(&axis, cyl.clone()).expect("usable"));
    row("seam_frame (incl. clone)", t);
    let (frame, cyl) = seamed;
    let (t, boxes) = best(repeats, || linear_boxes(&cyl));
    row("linear_boxes", t);
    let grid = GridParams::default();
    let bvh = BvhParams::default();
    let (t, _) = best(repeats, || build_grid(Coordinates::Cartesian, &cart, &grid));
    row("build_grid (cartesian)", t);
    let (t, _) = best(repeats, || {
        build_grid(Coordinates::Cylindrical(frame), &boxes, &grid)
    });
    row("build_grid (cylindrical)", t);
    let (t, _) = best(repeats, || build_bvh(&cart, &bvh));
    row("build_bvh (cartesian)", t);
    let (t, _) = best(repeats, || build_bvh(&cyl, &bvh));
    row("build_bvh (cylindrical)", t);
    drop((cart, cyl, boxes));

    for kind in StructureKind::ALL {
        let (t, accel) = best(repeats, || {
            Accel::build(&mesh, kind, &axis, &AccelParams::default()).expect("builds")
        });
        let s = accel.stats();
        let extra = if hash {
            format!("  hash {:016x}", hash_of(accel.structure()))
        } else {
            String::new()
        };
        println!(
            "  Accel::build {:<15} {:>8.3} {:>8.2}  {:>5.1} bytes/cell  {} refs{extra}",
            kind.name(),
            t.0,
            t.1,
            s.bytes() as f64 / mesh.cell_count() as f64,
            s.references(),
        );
    }
}
