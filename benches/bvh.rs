//! BVH figures: size, surface area and build time of the Cartesian and cylindrical BVHs, and
//! the work of point location (hexahedra tested, internal and leaf nodes visited per lookup)
//! for a sweep of build parameters.
//!
//! `cargo bench --bench bvh` runs the pump datasets at full size and the PLOT3D meshes.
//! Environment: `BVH_CELLS=N` caps the pump datasets' size, `BVH_DATASETS=a,b` picks datasets
//! (`pump-inlet`, `pump-rotor`, `pump-diffuser`, `post`, `comb`), `BVH_SWEEP=0` skips the
//! parameter sweep, `BVH_LOOKUPS=N` sets the lookups per configuration (default 20000).

use std::path::Path;
use std::time::Instant;

use cylvol::accel::bvh::{build_bvh, Bvh, BvhBounds, BvhParams};
use cylvol::accel::space::{self, Coordinates, Pieces};
use cylvol::accel::Counters;
use cylvol::datasets::{generate, Dataset};
use cylvol::geometry::containment::locate_in_cell;
use cylvol::geometry::cylindrical::{CylBounds, CylFrame};
use cylvol::geometry::trilinear::map;
use cylvol::Mesh;
use glam::DVec3;

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn env_usize(name: &str) -> Option<usize> {
    std::env::var(name).ok()?.parse().ok()
}

/// Per lookup: hexahedra tested, internal and leaf nodes visited; and lookups found.
fn lookups<B: BvhBounds>(
    mesh: &Mesh,
    bvh: &Bvh<B>,
    coords: Coordinates,
    points: &[DVec3],
) -> (f64, f64, f64, usize, f64) {
    let mut c = Counters::default();
    let mut found = 0;
    let t = Instant::now();
    for p in points {
        // As the renderer queries: (r, φ, h) for sectors, no atan2.
        let q = coords.query(*p);
        let mut hex = 0u64;
        if bvh
            .find_stored(q, &mut c, |cell| {
                hex += 1;
                locate_in_cell(&mesh.cell_corners(cell as usize), *p, None).is_some()
            })
            .is_some()
        {
            found += 1;
        }
        c.hex_tests += hex;
    }
    let s = t.elapsed().as_secs_f64();
    let n = points.len() as f64;
    (
        c.hex_tests as f64 / n,
        c.internal_visits as f64 / n,
        c.leaf_visits as f64 / n,
        found,
        s / n * 1e9,
    )
}

fn cyl_pieces(mesh: &Mesh) -> (CylFrame, Pieces<CylBounds>, f64) {
    let t = Instant::now();
    let axis = cylvol::axis::detect(mesh);
    let frame = CylFrame::new(axis.origin, axis.direction).expect("axis frame");
    let pieces = space::cylindrical_pieces(mesh, &frame, space::DEFAULT_STRADDLE_SECTORS);
    let (frame, pieces) = space::seam_frame(&axis, pieces).expect("seam frame");
    (frame, pieces, t.elapsed().as_secs_f64())
}

fn main() {
    // `cargo bench` passes `--bench`; nothing else is expected.
    let cap = env_usize("BVH_CELLS");
    let sweep = env_usize("BVH_SWEEP").unwrap_or(1) != 0;
    let n_lookups = env_usize("BVH_LOOKUPS").unwrap_or(20_000);
    let wanted: Option<Vec<String>> = std::env::var("BVH_DATASETS")
        .ok()
        .map(|s| s.split(',').map(str::to_owned).collect());
    let want = |n: &str| wanted.as_ref().map_or(true, |w| w.iter().any(|x| x == n));

    let mut meshes: Vec<(String, Mesh)> = Vec::new();
    for d in [
        Dataset::PumpInlet,
        Dataset::PumpRotor,
        Dataset::PumpDiffuser,
    ] {
        if want(d.name()) {
            let cells = cap.map_or(d.default_cells(), |c| c.min(d.default_cells()));
            meshes.push((d.name().to_owned(), generate(d, cells).expect("dataset")));
        }
    }
    for (short, file) in [("post", "postxyz.bin"), ("comb", "combxyz.bin")] {
        if want(short) {
            let path = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/data")
                .join(file);
            match cylvol::io::read_file(&path, &Default::default()) {
                Ok(m) => meshes.push((short.to_owned(), m)),
                Err(e) => eprintln!("skipping {file}: {e}"),
            }
        }
    }

    println!(
        "| dataset | cells | bvh | nodes | leaves | refs | bytes | B/cell | surface area | build s | cyl÷cart area |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let mut sweeps = Vec::new();
    for (name, mesh) in &meshes {
        let n = mesh.cell_count();
        let t = Instant::now();
        let cart = space::cartesian_pieces(mesh);
        let cart_s = t.elapsed().as_secs_f64();
        let (frame, cyl, cyl_s) = cyl_pieces(mesh);
        eprintln!("{name}: pieces in {cart_s:.3} s (cart), {cyl_s:.3} s (cyl)");
        let params = BvhParams::default();
        let bc = build_bvh(&cart, &params);
        let by = build_bvh(&cyl, &params);
        let (sc, sy) = (bc.stats(), by.stats());
        for (kind, s, ratio) in [
            ("cart", sc, String::new()),
            (
                "cyl",
                sy,
                format!("{:.3}", sy.surface_area / sc.surface_area),
            ),
        ] {
            println!(
                "| {name} | {n} | {kind} | {} | {} | {} | {} | {:.1} | {:.4e} | {:.3} | {ratio} |",
                s.nodes,
                s.leaves,
                s.references,
                s.bytes,
                s.bytes as f64 / n as f64,
                s.surface_area,
                s.build_s
            );
        }
        // Lookup points: random points inside random cells.
        let mut rng = Lcg(12345);
        let points: Vec<DVec3> = (0..n_lookups)
            .map(|_| {
                let c = ((rng.next() * n as f64) as usize).min(n - 1);
                map(
                    &mesh.cell_corners(c),
                    DVec3::new(rng.next(), rng.next(), rng.next()),
                )
            })
            .collect();
        let mut rows = Vec::new();
        let configs: Vec<(String, BvhParams)> = if sweep {
            let mut v = Vec::new();
            for leaf in [2usize, 4, 8, 16] {
                for traversal_cost in [1.0, 2.0, 4.0] {
                    v.push((
                        format!("leaf {leaf}, C_t {traversal_cost}, bins 16"),
                        BvhParams {
                            max_leaf_size: leaf,
                            bins: 16,
                            traversal_cost,
                        },
                    ));
                }
            }
            for bins in [8usize, 32] {
                v.push((
                    format!("leaf 8, C_t 2, bins {bins}"),
                    BvhParams {
                        max_leaf_size: 8,
                        bins,
                        traversal_cost: 2.0,
                    },
                ));
            }
            v
        } else {
            BvhParams::PRESETS
                .iter()
                .map(|(n, p)| (n.to_string(), *p))
                .collect()
        };
        for (label, p) in &configs {
            let bc = build_bvh(&cart, p);
            let by = build_bvh(&cyl, p);
            let lc = lookups(mesh, &bc, Coordinates::Cartesian, &points);
            let ly = lookups(mesh, &by, Coordinates::Cylindrical(frame), &points);
            assert_eq!(
                lc.3, ly.3,
                "{name}: the two BVHs find different numbers of points"
            );
            let (sc, sy) = (bc.stats(), by.stats());
            rows.push(format!(
                "| {name} | {label} | {:.2} / {:.2} | {:.1} / {:.1} | {:.2} / {:.2} | {:.1} / {:.1} | {:.3} / {:.3} | {:.0} / {:.0} |",
                lc.0, ly.0, lc.1, ly.1, lc.2, ly.2,
                sc.bytes as f64 / n as f64, sy.bytes as f64 / n as f64,
                sc.build_s, sy.build_s, lc.4, ly.4,
            ));
        }
        sweeps.push(rows);
    }
    println!();
    println!("Per lookup (points inside random cells), cart / cyl:");
    println!();
    println!(
        "| dataset | params | hex tested | internal visits | leaf visits | B/cell | build s | ns/lookup |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for rows in sweeps {
        for r in rows {
            println!("{r}");
        }
    }
}
