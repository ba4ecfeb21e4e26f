//! Tests of the synthetic pump datasets: specification parsing, cell counts, determinism,
//! conformity (shared points, shared faces, closed rings), the inlet's cells on the axis,
//! documented bounds, and the fields.

use std::collections::HashMap;

use cylvol::datasets::{generate, layout, parse_spec, Dataset, Layout, MAX_CELLS, MIN_CELLS};
use cylvol::mesh::topology::EDGES;
use cylvol::{Error, Mesh};
use glam::{DVec2, DVec3};

const HEX_FACES: [[usize; 4]; 6] = [
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
    [0, 3, 2, 1],
    [4, 5, 6, 7],
];

fn radius(p: DVec3) -> f64 {
    p.truncate().length()
}

fn pressure(mesh: &Mesh) -> &[f64] {
    let a = mesh
        .point_data()
        .iter()
        .find(|a| a.name == "pressure")
        .expect("a pressure array");
    assert_eq!(a.components, 1);
    &a.values
}

// ---------------------------------------------------------------- specifications

#[test]
fn names_round_trip_and_defaults_are_the_talks_sizes() {
    let names: Vec<&str> = Dataset::ALL.iter().map(|d| d.name()).collect();
    assert_eq!(names, ["pump-inlet", "pump-rotor", "pump-diffuser"]);
    for d in Dataset::ALL {
        assert_eq!(Dataset::from_name(d.name()), Some(d));
        assert_eq!(d.to_string(), d.name());
        assert!(!d.description().is_empty());
    }
    assert_eq!(Dataset::PumpInlet.default_cells(), 900_000);
    assert_eq!(Dataset::PumpRotor.default_cells(), 2_100_000);
    assert_eq!(Dataset::PumpDiffuser.default_cells(), 3_400_000);
    assert_eq!(Dataset::from_name("Pump-Rotor"), None);
    assert_eq!(Dataset::from_name("pump"), None);
}

#[test]
fn specs_parse_names_sizes_and_suffixes() {
    let ok = |s: &str| parse_spec(s).unwrap_or_else(|e| panic!("{s}: {e}"));
    assert_eq!(ok("pump-inlet"), Some((Dataset::PumpInlet, 900_000)));
    assert_eq!(ok("pump-rotor"), Some((Dataset::PumpRotor, 2_100_000)));
    assert_eq!(
        ok("pump-diffuser"),
        Some((Dataset::PumpDiffuser, 3_400_000))
    );
    assert_eq!(
        ok("pump-rotor:2100000"),
        Some((Dataset::PumpRotor, 2_100_000))
    );
    assert_eq!(
        ok("pump-rotor:2_100_000"),
        Some((Dataset::PumpRotor, 2_100_000))
    );
    assert_eq!(ok("pump-rotor:2.1M"), Some((Dataset::PumpRotor, 2_100_000)));
    assert_eq!(ok("pump-rotor:2.1m"), Some((Dataset::PumpRotor, 2_100_000)));
    assert_eq!(ok("pump-inlet:900k"), Some((Dataset::PumpInlet, 900_000)));
    assert_eq!(ok("pump-inlet:12.5K"), Some((Dataset::PumpInlet, 12_500)));
    assert_eq!(ok("pump-inlet:0.05M"), Some((Dataset::PumpInlet, 50_000)));
    assert_eq!(ok("pump-inlet:.05M"), Some((Dataset::PumpInlet, 50_000)));
    assert_eq!(ok("pump-inlet:1_000"), Some((Dataset::PumpInlet, 1_000)));
    assert_eq!(ok("pump-inlet:2.000k"), Some((Dataset::PumpInlet, 2_000)));
    assert_eq!(
        ok(&format!("pump-diffuser:{MAX_CELLS}")),
        Some((Dataset::PumpDiffuser, MAX_CELLS))
    );
    assert_eq!(
        ok(&format!("pump-diffuser:{MIN_CELLS}")),
        Some((Dataset::PumpDiffuser, MIN_CELLS))
    );
}

#[test]
fn non_dataset_names_are_left_to_the_caller() {
    for s in [
        "mixer.vtu",
        "../meshes/cube.vtk",
        "pump-rotor.vtk",
        "pump-rotor2:1000",
        "C:\\data\\pump.vtk",
        "",
        ":5000",
        "PUMP-ROTOR",
    ] {
        assert_eq!(parse_spec(s).unwrap(), None, "{s:?}");
    }
}

#[test]
fn bad_sizes_are_clear_errors() {
    for (spec, needle) in [
        ("pump-rotor:", "empty"),
        ("pump-rotor:abc", "whole number"),
        ("pump-rotor:-5000", "whole number"),
        ("pump-rotor:5e6", "whole number"),
        ("pump-rotor: 5000", "whole number"),
        ("pump-rotor:2.1", "whole number"),
        ("pump-rotor:1.2345k", "whole number"),
        ("pump-rotor:_5000", "separate digits"),
        ("pump-rotor:5__000", "separate digits"),
        ("pump-rotor:k", "whole number"),
        ("pump-rotor:999", "too few"),
        ("pump-rotor:0", "too few"),
        ("pump-rotor:200000001", "too many"),
        ("pump-rotor:1000000M", "too many"),
        (
            "pump-rotor:99999999999999999999999999999999999999999",
            "more than",
        ),
        ("pump-inlet:5000:6000", "whole number"),
        ("pump-inlet:5000é", "whole number"),
    ] {
        match parse_spec(spec) {
            Err(Error::Invalid(msg)) => {
                assert!(msg.contains(needle), "{spec}: {msg}");
                let name = spec.split(':').next().unwrap();
                assert!(
                    msg.contains(name),
                    "{spec}: message should name the dataset: {msg}"
                );
            }
            other => panic!("{spec}: expected Error::Invalid, got {other:?}"),
        }
    }
}

#[test]
fn generate_rejects_sizes_out_of_range() {
    for d in Dataset::ALL {
        assert!(matches!(generate(d, MIN_CELLS - 1), Err(Error::Invalid(_))));
        assert!(matches!(layout(d, MAX_CELLS + 1), Err(Error::Invalid(_))));
    }
}

// ---------------------------------------------------------------- counts and determinism

#[test]
fn planned_counts_are_within_five_percent_over_the_whole_range() {
    for d in Dataset::ALL {
        let mut n = MIN_CELLS;
        let mut worst = 0.0f64;
        while n <= MAX_CELLS {
            let got = layout(d, n).unwrap().cells();
            let err = got.abs_diff(n) as f64 / n as f64;
            worst = worst.max(err);
            assert!(err <= 0.05, "{d} asked {n} planned {got}");
            if n >= 20_000 {
                assert!(err <= 0.01, "{d} asked {n} planned {got}");
            }
            n += n / 37 + 1;
        }
        for n in (MIN_CELLS..20_000).step_by(7) {
            let got = layout(d, n).unwrap().cells();
            assert!(got.abs_diff(n) * 20 <= n, "{d} asked {n} planned {got}");
        }
        eprintln!("{d}: worst planned error {:.3} %", worst * 100.0);
    }
}

#[test]
fn generated_counts_match_the_plan_and_the_request() {
    for d in Dataset::ALL {
        for n in [MIN_CELLS, 5_000, 23_456, 50_000] {
            let plan = layout(d, n).unwrap();
            let mesh = generate(d, n).unwrap();
            assert_eq!(mesh.cell_count(), plan.cells(), "{d}:{n}");
            assert_eq!(mesh.point_count(), plan.points(), "{d}:{n}");
            assert!(
                mesh.cell_count().abs_diff(n) * 20 <= n,
                "{d}:{n} → {}",
                mesh.cell_count()
            );
            assert!(mesh
                .kind_counts()
                .iter()
                .all(|&(k, c)| (k == cylvol::CellKind::Hexahedron) == (c > 0)));
        }
    }
}

#[test]
fn generation_is_deterministic_on_any_thread_count() {
    for d in Dataset::ALL {
        let n = 12_000;
        let in_pool = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| generate(d, n).unwrap())
        };
        let one = in_pool(1);
        let two = in_pool(2);
        let three = in_pool(3);
        assert!(one == two, "{d}: 1 thread and 2 threads differ");
        assert!(one == three, "{d}: 1 thread and 3 threads differ");
        assert!(generate(d, n).unwrap() == one, "{d}: two runs differ");
    }
}

// ---------------------------------------------------------------- conformity

/// Faces used by exactly one cell, after checking that no face is used by more than two
/// cells and that no cell has a repeated point.
fn boundary_faces(mesh: &Mesh) -> Vec<[u32; 4]> {
    let mut uses: HashMap<[u32; 4], u32> = HashMap::new();
    for (c, cell) in mesh.cells().iter().enumerate() {
        let mut ids = *cell;
        ids.sort_unstable();
        assert!(
            ids.windows(2).all(|w| w[0] != w[1]),
            "cell {c} repeats a point"
        );
        for f in HEX_FACES {
            let mut key = f.map(|i| cell[i]);
            key.sort_unstable();
            *uses.entry(key).or_default() += 1;
        }
    }
    assert!(uses.values().all(|&u| u <= 2), "a face shared by 3+ cells");
    let mut once: Vec<[u32; 4]> = uses
        .into_iter()
        .filter(|&(_, u)| u == 1)
        .map(|(k, _)| k)
        .collect();
    once.sort_unstable();
    once
}

fn assert_no_duplicate_or_unused_points(mesh: &Mesh) {
    let (lo, hi) = {
        let b = mesh.bounds();
        (DVec3::new(b[0], b[2], b[4]), DVec3::new(b[1], b[3], b[5]))
    };
    let q = 1e-9 * (hi - lo).max_element();
    let mut seen: HashMap<[i64; 3], usize> = HashMap::new();
    for (i, p) in mesh.points().iter().enumerate() {
        let key = ((*p - lo) / q).round().as_i64vec3().to_array();
        if let Some(j) = seen.insert(key, i) {
            panic!("points {j} and {i} coincide at {p}");
        }
    }
    let mut used = vec![false; mesh.point_count()];
    for cell in mesh.cells() {
        for &i in cell {
            used[i as usize] = true;
        }
    }
    assert!(used.iter().all(|&u| u), "a point no cell uses");
}

#[test]
fn rings_are_conforming_and_closed_with_boundaries_only_where_expected() {
    for d in [Dataset::PumpRotor, Dataset::PumpDiffuser] {
        for n in [MIN_CELLS, 20_000] {
            let mesh = generate(d, n).unwrap();
            assert_no_duplicate_or_unused_points(&mesh);
            let Layout::Ring {
                blades,
                radial,
                per_passage,
                axial,
            } = layout(d, n).unwrap()
            else {
                panic!("{d} is a ring")
            };
            let nr: usize = radial.iter().sum();
            let around = blades * per_passage;
            // Hub and shroud, inner and outer cylinders, two walls per blade.
            let expected = 2 * nr * around + 2 * around * axial + 2 * blades * radial[1] * axial;
            let faces = boundary_faces(&mesh);
            assert_eq!(faces.len(), expected, "{d}:{n} boundary faces");
            // The inner and outer cylinders alone: faces whose points all lie at r_in or r_out.
            let r: Vec<f64> = mesh.points().iter().map(|&p| radius(p)).collect();
            let (r_in, r_out) = r
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
            let on = |f: &[u32; 4], r0: f64| f.iter().all(|&i| (r[i as usize] - r0).abs() < 1e-9);
            let cylinders = faces.iter().filter(|f| on(f, r_in) || on(f, r_out)).count();
            assert_eq!(cylinders, 2 * around * axial, "{d}:{n} cylinder faces");
        }
    }
}

#[test]
fn pipe_is_conforming_with_boundaries_only_on_wall_and_ends() {
    for n in [MIN_CELLS, 20_000] {
        let mesh = generate(Dataset::PumpInlet, n).unwrap();
        assert_no_duplicate_or_unused_points(&mesh);
        let Layout::Pipe {
            core,
            layers,
            levels,
        } = layout(Dataset::PumpInlet, n).unwrap()
        else {
            panic!("the inlet is a pipe")
        };
        let section = core * core + 4 * core * layers;
        let faces = boundary_faces(&mesh);
        assert_eq!(
            faces.len(),
            2 * section + 4 * core * levels,
            "pump-inlet:{n}"
        );
        let b = mesh.bounds();
        let p = mesh.points();
        let at_z = |f: &[u32; 4], z: f64| f.iter().all(|&i| (p[i as usize].z - z).abs() < 1e-12);
        let ends = faces
            .iter()
            .filter(|f| at_z(f, b[4]) || at_z(f, b[5]))
            .count();
        assert_eq!(ends, 2 * section);
        // Every other boundary face is on the wall (r ≥ 0.30, the narrowest pipe radius).
        for f in faces.iter().filter(|f| !at_z(f, b[4]) && !at_z(f, b[5])) {
            assert!(f.iter().all(|&i| radius(p[i as usize]) > 0.2999), "{f:?}");
        }
    }
}

#[test]
fn all_datasets_pass_validation_at_many_sizes() {
    // Mesh::from_parts rejects inverted cells, so generating is the check.
    for d in Dataset::ALL {
        for n in [MIN_CELLS, 1_234, 2_500, 7_777, 31_000, 64_000] {
            let mesh = generate(d, n).unwrap_or_else(|e| panic!("{d}:{n}: {e}"));
            assert!(mesh.points().iter().all(|p| p.is_finite()));
        }
    }
}

// ---------------------------------------------------------------- geometry

/// Convex hull (anticlockwise) of 2-D points, by the monotone chain.
fn hull(mut pts: Vec<DVec2>) -> Vec<DVec2> {
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut h: Vec<DVec2> = Vec::new();
    for pass in 0..2 {
        let start = h.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while h.len() >= start + 2 && cross(h[h.len() - 2], h[h.len() - 1], p) <= 0.0 {
                h.pop();
            }
            h.push(p);
        }
        h.pop();
    }
    h
}

#[test]
fn inlet_has_cells_touching_and_cells_straddling_the_axis() {
    for n in [5_000, 50_000] {
        let mesh = generate(Dataset::PumpInlet, n).unwrap();
        let (mut touching, mut straddling) = (0, 0);
        for c in 0..mesh.cell_count() {
            let corners = mesh.cell_corners(c);
            let xy: Vec<DVec2> = corners.iter().map(|p| p.truncate()).collect();
            let size = corners[0].distance(corners[6]);
            if xy.iter().any(|p| p.length() < 1e-12) {
                touching += 1;
                continue;
            }
            let h = hull(xy);
            let inside = (0..h.len()).all(|i| {
                let (a, b) = (h[i], h[(i + 1) % h.len()]);
                // Signed distance of the origin to the left of edge a→b.
                (b - a).perp_dot(-a) / (b - a).length() > 1e-6 * size
            });
            if inside {
                straddling += 1;
            }
        }
        let Layout::Pipe { levels, .. } = layout(Dataset::PumpInlet, n).unwrap() else {
            unreachable!()
        };
        eprintln!("pump-inlet:{n}: {touching} cells touch the axis, {straddling} straddle it, {levels} levels");
        // Four cells per level touch it where the core is centred, one per level straddles it
        // where it has drifted: both occur on a good share of the levels.
        assert!(touching >= 4 * levels / 3, "{touching} touching");
        assert!(straddling >= levels / 5, "{straddling} straddling");
        assert!(touching + straddling <= 4 * levels);
    }
}

fn extent(mesh: &Mesh, f: impl Fn(DVec3) -> f64) -> [f64; 2] {
    mesh.points()
        .iter()
        .fold([f64::MAX, f64::MIN], |[lo, hi], &p| {
            [lo.min(f(p)), hi.max(f(p))]
        })
}

#[test]
fn bounds_are_as_documented() {
    // (dataset, r range, z range) from the module documentation.
    let cases = [
        (Dataset::PumpInlet, [0.0, 0.40], [0.10, 2.10]),
        (Dataset::PumpRotor, [0.30, 1.00], [0.0, 0.45]),
        (Dataset::PumpDiffuser, [1.05, 1.80], [-0.0465, 0.2065]),
    ];
    for (d, r, z) in cases {
        let mesh = generate(d, 20_000).unwrap();
        let got_r = extent(&mesh, radius);
        let got_z = extent(&mesh, |p| p.z);
        assert!(
            (got_r[0] - r[0]).abs() < 1e-9 && (got_r[1] - r[1]).abs() < 1e-9,
            "{d} r {got_r:?}"
        );
        assert!(
            (got_z[0] - z[0]).abs() < 1e-9 && (got_z[1] - z[1]).abs() < 1e-9,
            "{d} z {got_z:?}"
        );
        // Full rings and the pipe cover every azimuth: x and y span ±r_max.
        let b = mesh.bounds();
        for v in [b[0], b[2]] {
            assert!((v + r[1]).abs() < 0.02 * r[1], "{d} bounds {b:?}");
        }
        for v in [b[1], b[3]] {
            assert!((v - r[1]).abs() < 0.02 * r[1], "{d} bounds {b:?}");
        }
    }
}

#[test]
fn ring_cells_follow_arcs_and_blades() {
    // The grid lines across a passage are arcs, and those along it follow the spiral blades:
    // a cell's azimuth changes along each of its three edge directions, and the azimuthal
    // span of the rotor's radial grid lines adds up to the blades' wrap (about 135°).
    let mesh = generate(Dataset::PumpRotor, 20_000).unwrap();
    let Layout::Ring {
        blades,
        radial,
        per_passage,
        ..
    } = layout(Dataset::PumpRotor, 20_000).unwrap()
    else {
        unreachable!()
    };
    let around = blades * per_passage;
    let nr: usize = radial.iter().sum();
    // Walk the first radial grid line (cells with j = 0, k = 0, i = 0..nr) by cell index.
    let mut turn = 0.0;
    for i in 0..nr {
        let c = mesh.cell_corners(i * around);
        let a = c[0].y.atan2(c[0].x);
        let b = c[1].y.atan2(c[1].x);
        turn +=
            (b - a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    }
    let degrees = turn.to_degrees();
    assert!((-145.0..-115.0).contains(&degrees), "wrap {degrees}°");
}

// ---------------------------------------------------------------- fields

/// Largest pressure difference along a cell edge, relative to the pressure range.
fn largest_edge_jump(mesh: &Mesh) -> f64 {
    let p = pressure(mesh);
    let [lo, hi] = mesh.scalar_range().unwrap();
    let jump = mesh
        .cells()
        .iter()
        .flat_map(|c| EDGES.map(|[a, b]| (p[c[a] as usize] - p[c[b] as usize]).abs()))
        .fold(0.0, f64::max);
    jump / (hi - lo)
}

#[test]
fn pressure_is_active_varied_and_smooth() {
    for d in Dataset::ALL {
        let coarse = generate(d, 20_000).unwrap();
        let fine = generate(d, 160_000).unwrap();
        assert_eq!(coarse.active_array().unwrap().name, "pressure");
        let [lo, hi] = coarse.scalar_range().unwrap();
        assert!(hi - lo > 0.05, "{d}: pressure range {lo}..{hi}");
        assert!(pressure(&coarse).iter().all(|v| v.is_finite()));
        let (jc, jf) = (largest_edge_jump(&coarse), largest_edge_jump(&fine));
        eprintln!("{d}: largest edge jump {jc:.3} → {jf:.3} of the range");
        assert!(jc < 0.2, "{d}: jump {jc}");
        // Halving the cell size (8× the cells) about halves the jumps of a smooth field.
        assert!(jf < 0.7 * jc, "{d}: jumps {jc} → {jf}");
    }
}

#[test]
fn pressure_rises_with_radius_and_varies_along_the_axis_and_around() {
    for d in Dataset::ALL {
        let mesh = generate(d, 30_000).unwrap();
        let p = pressure(&mesh);
        let pts = mesh.points();
        let [r_lo, r_hi] = extent(&mesh, radius);
        let [z_lo, z_hi] = extent(&mesh, |q| q.z);
        let mean_where = |f: &dyn Fn(DVec3) -> bool| {
            let (s, n) = pts
                .iter()
                .zip(p)
                .filter(|(q, _)| f(**q))
                .fold((0.0, 0usize), |(s, n), (_, v)| (s + v, n + 1));
            assert!(n > 0);
            s / n as f64
        };
        let rf = |q: DVec3| (radius(q) - r_lo) / (r_hi - r_lo);
        let inner = mean_where(&|q| rf(q) < 0.3);
        let outer = mean_where(&|q| rf(q) > 0.7);
        assert!(
            outer > inner,
            "{d}: pressure {inner} inside, {outer} outside"
        );
        let zf = |q: DVec3| (q.z - z_lo) / (z_hi - z_lo);
        let low = mean_where(&|q| zf(q) < 0.3);
        let high = mean_where(&|q| zf(q) > 0.7);
        assert!(
            (low - high).abs() > 1e-3,
            "{d}: no axial variation ({low}, {high})"
        );
        // Around the axis: on the points of one radius band, pressure is not axisymmetric.
        let band: Vec<f64> = pts
            .iter()
            .zip(p)
            .filter(|(q, _)| (rf(**q) - 0.5).abs() < 0.1 && zf(**q) > 0.2)
            .map(|(_, v)| *v)
            .collect();
        let (lo, hi) = band
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        assert!(hi - lo > 0.01, "{d}: band range {lo}..{hi}");
    }
}

#[test]
fn velocity_is_a_finite_non_trivial_vector() {
    for d in Dataset::ALL {
        let mesh = generate(d, 10_000).unwrap();
        let v = mesh
            .point_data()
            .iter()
            .find(|a| a.name == "velocity")
            .expect("velocity");
        assert_eq!(v.components, 3);
        assert_eq!(v.tuples(), mesh.point_count());
        assert!(v.values.iter().all(|x| x.is_finite()));
        for comp in 0..3 {
            let (lo, hi) = v
                .values
                .iter()
                .skip(comp)
                .step_by(3)
                .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
            assert!(hi - lo > 1e-3, "{d}: velocity component {comp} constant");
        }
    }
}
