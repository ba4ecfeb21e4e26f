//! The fast path against the paper path: the same image within 1e-6 (RGBA in [0, 1]) on the
//! pump datasets and the hard meshes (a closed annulus, an annulus with a duplicated seam, an
//! O-grid with wedges on the axis) for all four structures, with the face neighbours the CLI
//! plugs in; about one hexahedron tested per located sample on a smooth mesh at a step below
//! the cell size (counters, not timings); and empty-space skipping across the hub's hole, by
//! the structure's bounds and by the boundary surface. Every fast render is also made
//! without the boundary surface, and must locate the same samples.
//!
//! Why 1e-6: both paths take the same sample positions (asserted) and accept a cell only by
//! the same containment test; they may differ only in which of two cells sharing a face holds
//! a sample on that face, where the interpolated values agree to the inverse map's accuracy
//! (`~1e-9` of the scalar range). A sample located in one path and not in the other would
//! change a pixel's opacity by the sample's opacity, `≥ 1e-2` with these transfer functions.

mod common;

use std::f64::consts::PI;

use common::{o_grid_with_axis_wedges, sector};
use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::axis::Axis;
use cylvol::datasets::{generate, Dataset};
use cylvol::geometry::cylindrical::CylFrame;
use cylvol::io::structured::hexahedra;
use cylvol::mesh::topology::FaceNeighbours;
use cylvol::render::{
    default_step, Camera, Image, RayResult, RenderOptions, RenderPath, RenderStats, Renderer,
    Topology, TransferFunction, Volume,
};
use cylvol::{CellKind, DataArray, Mesh, MeshParts};
use glam::DVec3;

/// What a render walks: face neighbours alone, or with their boundary surface.
trait Walk: Sync {
    /// `renderer` walking these.
    fn onto<'a>(&'a self, renderer: Renderer<'a>) -> Renderer<'a>;
}

impl Walk for Topology {
    fn onto<'a>(&'a self, renderer: Renderer<'a>) -> Renderer<'a> {
        renderer.with_topology(self)
    }
}

impl Walk for FaceNeighbours {
    fn onto<'a>(&'a self, renderer: Renderer<'a>) -> Renderer<'a> {
        renderer.with_neighbours(self)
    }
}

fn frame() -> CylFrame {
    CylFrame::new(DVec3::ZERO, DVec3::Z).expect("z axis")
}

fn render(
    mesh: &Mesh,
    accel: &Accel,
    neighbours: &dyn Walk,
    path: RenderPath,
    step: f64,
    camera: &Camera,
    size: u32,
) -> (Image, RenderStats) {
    let volume = Volume::new(mesh, accel).expect("volume");
    let [lo, hi] = volume.scalar_range();
    let tf = TransferFunction::default_for_range(lo, hi, 0.6, 0.2);
    let mut options = RenderOptions::new(size, size, step);
    options.path = path;
    let r = neighbours.onto(Renderer::new(&volume, &tf, &options).expect("renderer"));
    r.render(camera, None).expect("render")
}

/// Renders `mesh` with every structure and both paths; asserts the fast images equal the
/// paper image within 1e-6 and the sample positions are the same. Returns the fast stats.
fn fast_equals_paper(name: &str, mesh: &Mesh, axis: &Axis, views: &[(f64, f64, f64)]) {
    let neighbours = common::closed_neighbours(mesh);
    // Samples in transparent cells found by face planes alone, over every render.
    let mut certified = 0;
    // Jumps over transparent space by the fast path through a BVH, over every render.
    let mut jumps = 0;
    // Chords sampled and gaps left out by the fast path, over every render.
    let (mut chords, mut gaps) = (0, 0);
    // The fast renders' work with and without the boundary surface, over every render.
    let mut with_surface = RenderStats::default();
    let mut without_surface = RenderStats::default();
    let step = default_step(mesh);
    let size = 40;
    for &(az, el, zoom) in views {
        let camera = Camera::view(mesh.bounds(), size, size, az, el, zoom);
        let mut reference: Option<(Image, RenderStats)> = None;
        for kind in StructureKind::ALL {
            let accel = Accel::build(mesh, kind, axis, &AccelParams::default()).expect("build");
            let (paper, ps) = render(
                mesh,
                &accel,
                &neighbours,
                RenderPath::Paper,
                step,
                &camera,
                size,
            );
            let (fast, fs) = render(
                mesh,
                &accel,
                &neighbours,
                RenderPath::Fast,
                step,
                &camera,
                size,
            );
            // Without the boundary surface (face neighbours alone): the paper path's image
            // without it, the same samples located, and no surface visited. Only the surface
            // finds the pieces of rays in the mesh that hold no sample (chords): they are the
            // whole difference between the two, and neither path finds one without it.
            let faces: &FaceNeighbours = &neighbours;
            let (walk_only, ws) =
                render(mesh, &accel, faces, RenderPath::Fast, step, &camera, size);
            let (paper_walk_only, pws) =
                render(mesh, &accel, faces, RenderPath::Paper, step, &camera, size);
            assert!(
                walk_only.max_abs_difference(&paper_walk_only) <= 1e-6,
                "{name} {kind}"
            );
            assert_eq!(ws.surface_visits, 0, "{name} {kind}");
            assert_eq!(
                (ws.chord_samples, pws.chord_samples, ws.gaps, pws.gaps),
                (0, 0, 0, 0),
                "{name} {kind}"
            );
            // (The fast path's jumps pass over the chords and gaps in transparent space.)
            assert!(fs.chord_samples <= ps.chord_samples, "{name} {kind}");
            assert!(fs.gaps <= ps.gaps, "{name} {kind}");
            // Where the surface found neither, it changed the work only (with them, the
            // opacities, and so where rays stop).
            if fs.chord_samples + fs.gaps == 0 {
                assert!(walk_only.max_abs_difference(&fast) <= 1e-6, "{name} {kind}");
                assert_eq!(ws.samples_located, fs.samples_located, "{name} {kind}");
            }
            chords += fs.chord_samples;
            gaps += fs.gaps;
            with_surface += fs;
            without_surface += ws;
            // Samples certified by face planes are skipped ones (transparent cells), and
            // only the fast path certifies.
            assert!(
                fs.plane_certified <= fs.samples_skipped,
                "{name} {kind}: {fs:?}"
            );
            assert_eq!(ps.plane_certified, 0, "{name} {kind}");
            certified += fs.plane_certified;
            // Only the fast path jumps.
            assert_eq!(ps.transparent_jumps, 0, "{name} {kind}");
            jumps += fs.transparent_jumps;
            let (reference, rs) = reference.get_or_insert_with(|| (paper.clone(), ps));
            assert!(
                reference.rgba.iter().any(|p| p[3] > 0.05),
                "{name}: the image is not empty"
            );
            let d_paper = paper.max_abs_difference(reference);
            let d_fast = fast.max_abs_difference(&paper);
            assert!(d_paper <= 1e-6, "{name} {kind} paper: {d_paper}");
            assert!(d_fast <= 1e-6, "{name} {kind} fast vs paper: {d_fast}");
            assert_eq!(ps.samples, rs.samples, "{name} {kind}");
            assert_eq!(fs.samples, ps.samples, "{name} {kind}");
            assert!(
                fs.hex_tests < ps.hex_tests,
                "{name} {kind}: fast {} vs paper {} tests",
                fs.hex_tests,
                ps.hex_tests
            );
            eprintln!(
                "{name} view ({az}, {el}) {kind}: paper {:.2} tests/located sample, fast {:.2}; fast {fs:?}",
                ps.hex_tests as f64 / ps.samples_located.max(1) as f64,
                fs.hex_tests as f64 / fs.samples_located.max(1) as f64,
            );
        }
    }
    // The transfer function leaves part of every test mesh's range transparent.
    assert!(certified > 0, "{name}: no sample certified by face planes");
    assert!(jumps > 0, "{name}: no jump over transparent space");
    // Some rays of every mesh graze it between two samples.
    assert!(chords > 0, "{name}: no chord sampled");
    eprintln!("{name}: {chords} chords, {gaps} gaps");
    // The surface saves cells tested and structure nodes visited over all the renders (a
    // single render may test a few more: the first sample past an exit from the mesh goes to
    // the structure, where the structure's bounds might have skipped it).
    let nodes = |s: &RenderStats| s.internal_visits + s.leaf_visits;
    assert!(
        with_surface.hex_tests < without_surface.hex_tests,
        "{name}: {with_surface:?} {without_surface:?}"
    );
    assert!(
        nodes(&with_surface) < nodes(&without_surface),
        "{name}: {with_surface:?} {without_surface:?}"
    );
}

#[test]
fn fast_equals_paper_on_the_pump_datasets() {
    for (dataset, cells) in [
        (Dataset::PumpInlet, 6_000),
        (Dataset::PumpRotor, 8_000),
        (Dataset::PumpDiffuser, 8_000),
    ] {
        let mesh = generate(dataset, cells).expect("dataset");
        fast_equals_paper(
            &format!("{dataset:?}"),
            &mesh,
            &Axis::Z,
            &[(30.0, 25.0, 1.0), (0.0, 89.0, 1.3)],
        );
    }
}

#[test]
fn fast_equals_paper_on_the_hard_meshes() {
    for close_ring in [true, false] {
        let mesh = sector(&frame(), [0.5, 1.0], [-PI, PI], 1.0, [4, 24, 4], close_ring);
        fast_equals_paper(
            if close_ring {
                "closed annulus"
            } else {
                "annulus with a duplicated seam"
            },
            &mesh,
            &Axis::Z,
            &[(30.0, 25.0, 1.2), (0.0, 89.0, 1.0), (180.0, 0.0, 1.0)],
        );
    }
    let mesh = o_grid_with_axis_wedges(&frame(), 1.0, 16, 4, 4);
    fast_equals_paper(
        "O-grid with wedges on the axis",
        &mesh,
        &Axis::Z,
        &[(30.0, 25.0, 1.2), (0.0, 89.0, 1.0), (45.0, 0.0, 1.0)],
    );
}

/// The unit cube as `n³` cells, smoothly bent (a sine displacement that vanishes on the
/// boundary), with a smooth point scalar.
fn smooth_cube(n: usize) -> Mesh {
    let m = n + 1;
    let mut points = Vec::with_capacity(m * m * m);
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                let p = DVec3::new(i as f64, j as f64, k as f64) / n as f64;
                let s = (PI * p.x).sin() * (PI * p.y).sin() * (PI * p.z).sin();
                points.push(p + DVec3::new(0.08, -0.05, 0.06) * s);
            }
        }
    }
    let cells = hexahedra([m, m, m], &points);
    let values = points.iter().map(|p| p.x + p.y * p.z).collect();
    Mesh::from_parts(MeshParts {
        kinds: vec![CellKind::Hexahedron; cells.len()],
        cells,
        points,
        point_data: vec![DataArray::scalar("f", values)],
        cell_data: vec![],
    })
    .expect("smooth cube is valid")
}

/// On a smooth mesh, at a step of half and of one cell size, the fast path tests at most 1.1
/// hexahedra per located sample (the ray's entry is located through the structure; every
/// later sample is reached by a walk over face planes and tested once). Every ray leaves this
/// cube through a face on its box, where the ray's end lies outside the box of the mesh's
/// points: proved outside with no boundary search, so the only tests spent at the boundary
/// (`boundary_refinements`, also in `hex_tests`) locate the middles of the chords that rays
/// grazing the cube's edges cut, a walk from the face each.
#[test]
fn about_one_cell_test_per_located_sample_on_a_smooth_mesh() {
    let n = 24;
    let mesh = smooth_cube(n);
    let neighbours = common::closed_neighbours(&mesh);
    let cell = 1.0 / n as f64;
    let (mut refinements, mut chords) = (0, 0);
    for kind in StructureKind::ALL {
        let accel = Accel::build(&mesh, kind, &Axis::Z, &AccelParams::default()).expect("build");
        for step in [0.5 * cell, cell] {
            let camera = Camera::view(mesh.bounds(), 32, 32, 35.0, 25.0, 1.0);
            let (_, s) = render(
                &mesh,
                &accel,
                &neighbours,
                RenderPath::Fast,
                step,
                &camera,
                32,
            );
            // (Locating the middles of chords, pieces of grazing rays too short for a
            // sample, is counted there too.)
            if s.chord_samples == 0 {
                assert_eq!(s.boundary_refinements, 0, "{kind} step {step}: {s:?}");
            }
            refinements += s.boundary_refinements;
            chords += s.chord_samples;
            let per = s.hex_tests as f64 / s.samples_located as f64;
            eprintln!("{kind} step {step}: {per:.3} tests per located sample; {s:?}");
            assert!(s.samples_located > 5_000, "{kind}: {s:?}");
            assert!(per <= 1.1, "{kind} step {step}: {per} tests per sample");
        }
    }
    // No crossing search: the tests for the boundary are the chords' (a walk each).
    assert!(
        refinements <= 4 * chords,
        "{refinements} tests for {chords} chords"
    );
}

/// A closed annulus `0.5 ≤ r ≤ 1` (the hub's hole inside), `0 ≤ z ≤ 1`.
fn annulus_with_hole() -> Mesh {
    sector(&frame(), [0.5, 1.0], [-PI, PI], 1.0, [4, 48, 4], true)
}

/// For every structure over `mesh`: its volume, the annulus tests' transfer function, and
/// options for casting single rays at `step`, never terminated early.
fn each_single_ray_volume(
    mesh: &Mesh,
    step: f64,
    mut f: impl FnMut(StructureKind, &Volume, &TransferFunction, &RenderOptions),
) {
    for kind in StructureKind::ALL {
        let accel = Accel::build(mesh, kind, &Axis::Z, &AccelParams::default()).expect("build");
        let volume = Volume::new(mesh, &accel).expect("volume");
        let [lo, hi] = volume.scalar_range();
        let tf = TransferFunction::default_for_range(lo, hi, 0.6, 0.2);
        let mut options = RenderOptions::new(1, 1, step);
        options.early_termination = 2.0;
        f(kind, &volume, &tf, &options);
    }
}

/// One ray cast through `volume` with the neighbours `n`, and its counters.
fn cast_one(
    volume: &Volume,
    tf: &TransferFunction,
    options: &RenderOptions,
    n: &dyn Walk,
    o: DVec3,
    d: DVec3,
) -> (RayResult, RenderStats) {
    let renderer = n.onto(Renderer::new(volume, tf, options).expect("renderer"));
    let mut s = RenderStats::default();
    let r = renderer.cast(o, d, f64::INFINITY, &mut s);
    (r, s)
}

/// Two rays slanted across the annulus and its hole, from outside it.
fn slanted_rays() -> [(DVec3, DVec3); 2] {
    [
        (
            DVec3::new(-2.0, -1.5, 0.37),
            DVec3::new(1.0, 0.8, 0.05).normalize(),
        ),
        (
            DVec3::new(0.1, -3.0, 0.9),
            DVec3::new(0.05, 1.0, -0.2).normalize(),
        ),
    ]
}

/// Rays across the hole of an annulus: samples in the hole lie outside every piece of the
/// BVHs and are passed over without location, and so are the samples in empty grid cells.
#[test]
fn empty_space_is_skipped_across_the_hub_hole() {
    let mesh = annulus_with_hole();
    let neighbours = common::closed_neighbours(&mesh);
    let step = 0.01;
    each_single_ray_volume(&mesh, step, |kind, volume, tf, options| {
        let renderer = Renderer::new(volume, tf, options)
            .expect("renderer")
            .with_topology(&neighbours);
        // Along x through the axis at mid height: the hole is r < 0.5.
        let (o, d) = (DVec3::new(-2.0, 0.003, 0.5), DVec3::X);
        let mut s = RenderStats::default();
        renderer.cast(o, d, f64::INFINITY, &mut s);
        let (t_in, t_out) = renderer.clip(o, d).expect("the ray hits the box");
        let in_hole = (0..)
            .map(|k| t_in + (k as f64 + 0.5) * step)
            .take_while(|&t| t < t_out)
            .filter(|&t| (o + d * t).truncate().length() < 0.45)
            .count() as u64;
        eprintln!("{kind}: {in_hole} samples in the hole; {s:?}");
        assert!(in_hole > 50);
        assert!(s.space_skips > 0, "{kind}: {s:?}");
        if !kind.is_grid() {
            assert!(s.space_skips >= in_hole, "{kind}: {s:?}");
        }
        assert!(
            s.space_skips + s.samples_located <= s.samples,
            "{kind}: {s:?}"
        );
    });
}

/// Rays across the hole of an annulus, from outside the mesh: with the boundary surface the
/// samples before the mesh and in the hole are known to be outside without any structure
/// look-up, so no more cells are tested (fewer over all) and no more structure nodes visited,
/// while the same samples are located and the pixel is the same; without it, no surface node
/// is visited.
#[test]
fn the_boundary_surface_skips_outside_samples_without_location() {
    let mesh = annulus_with_hole();
    let topology = common::closed_neighbours(&mesh);
    let step = 0.01;
    // Cells tested with and without the surface, over every ray and structure.
    let mut totals = [0u64; 2];
    each_single_ray_volume(&mesh, step, |kind, volume, tf, options| {
        let cast = |n: &dyn Walk, o: DVec3, d: DVec3| cast_one(volume, tf, options, n, o, d);
        let faces: &FaceNeighbours = &topology;
        let [a, b] = slanted_rays();
        for (o, d) in [(DVec3::new(-2.0, 0.003, 0.5), DVec3::X), a, b] {
            let (with, ws) = cast(&topology, o, d);
            let (without, ns) = cast(faces, o, d);
            eprintln!("{kind}: with the surface {ws:?}\n  without {ns:?}");
            assert_eq!(ws.samples, ns.samples, "{kind}");
            assert_eq!(ws.samples_located, ns.samples_located, "{kind}");
            assert!(ws.samples_located > 20, "{kind}: {ws:?}");
            for c in 0..4 {
                assert!((with.rgba[c] - without.rgba[c]).abs() <= 1e-9, "{kind}");
            }
            assert!(ws.surface_visits > 0, "{kind}: {ws:?}");
            assert_eq!(ns.surface_visits, 0, "{kind}: {ns:?}");
            assert!(ws.hex_tests <= ns.hex_tests, "{kind}: {ws:?} {ns:?}");
            assert!(
                ws.internal_visits + ws.leaf_visits <= ns.internal_visits + ns.leaf_visits,
                "{kind}: {ws:?} {ns:?}"
            );
            totals[0] += ws.hex_tests;
            totals[1] += ns.hex_tests;
        }
    });
    assert!(totals[0] < totals[1], "{totals:?}");
}

/// Rays leaving the annulus (into the hole, out of its far side), away from cell edges:
/// with the boundary surface, each sample past an exit is proved outside by parity (the
/// segment from the last sample inside crosses one boundary face, once, and no other), with
/// no structure look-up at all; without it, the structure is asked at each exit. The pixel
/// is the same either way. The transfer function here leaves no cell transparent, so that
/// no ray jumps over an exit (see `jumps_over_transparent_space_...`).
#[test]
fn exits_from_the_mesh_are_proved_outside_without_the_structure() {
    let mesh = annulus_with_hole();
    let topology = common::closed_neighbours(&mesh);
    let step = 0.01;
    each_single_ray_volume(&mesh, step, |kind, volume, tf, options| {
        let [lo, hi] = volume.scalar_range();
        let tf = &TransferFunction {
            opacity: vec![(lo, 0.05), (hi, 0.6)],
            ..tf.clone()
        };
        let cast = |n: &dyn Walk, o: DVec3, d: DVec3| cast_one(volume, tf, options, n, o, d);
        let faces: &FaceNeighbours = &topology;
        let [a, b] = slanted_rays();
        for (o, d) in [(DVec3::new(-2.0, 0.013, 0.41), DVec3::X), a, b] {
            let (with, ws) = cast(&topology, o, d);
            let (without, ns) = cast(faces, o, d);
            eprintln!("{kind}: with the surface {ws:?}\n  without {ns:?}");
            assert_eq!(ws.samples_skipped + ns.samples_skipped, 0, "{kind}");
            assert_eq!(ws.structure_locates, 0, "{kind}: {ws:?}");
            assert!(ns.structure_locates >= 2, "{kind}: {ns:?}");
            assert_eq!(ws.samples_located, ns.samples_located, "{kind}");
            for c in 0..4 {
                assert!((with.rgba[c] - without.rgba[c]).abs() <= 1e-9, "{kind}");
            }
        }
    });
}

/// A full ring whose seam is not welded: the two coincident faces of the seam have no
/// neighbour, so both are in the boundary surface. A ray crossing the seam leaves the cell
/// on one side by a face without a neighbour, but the segment to the next sample crosses the
/// other seam face too, so the exit is not proved by parity: the sample is found in the cell
/// across the seam, and the pixel is the welded ring's and the paper path's.
#[test]
fn an_unwelded_seam_is_not_taken_for_the_mesh_boundary() {
    let mesh = sector(&frame(), [0.5, 1.0], [-PI, PI], 1.0, [4, 48, 4], false);
    let unwelded = Topology::new(&mesh, FaceNeighbours::build(&mesh));
    let welded = common::closed_neighbours(&mesh);
    assert!(
        unwelded.surface().face_count() > welded.surface().face_count(),
        "the seam's faces are in the unwelded ring's surface"
    );
    each_single_ray_volume(&mesh, 0.01, |kind, volume, tf, options| {
        let cast = |n: &dyn Walk, path: RenderPath, o: DVec3, d: DVec3| {
            let mut options = *options;
            options.path = path;
            cast_one(volume, tf, &options, n, o, d)
        };
        // Across the seam (θ = ±π: y = 0, x < 0), square to it and slanted.
        for (o, d) in [
            (DVec3::new(-0.77, -2.0, 0.41), DVec3::Y),
            (
                DVec3::new(-0.62, -1.0, 0.13),
                DVec3::new(-0.1, 1.0, 0.3).normalize(),
            ),
        ] {
            let (seam, ss) = cast(&unwelded, RenderPath::Fast, o, d);
            let (ring, rs) = cast(&welded, RenderPath::Fast, o, d);
            let (paper, _) = cast(&welded, RenderPath::Paper, o, d);
            eprintln!("{kind}: unwelded {ss:?}\n  welded {rs:?}");
            assert!(seam.rgba[3] > 0.1, "{kind}: the ray crosses the ring");
            assert_eq!(ss.samples_located, rs.samples_located, "{kind}");
            for c in 0..4 {
                assert!((seam.rgba[c] - ring.rgba[c]).abs() <= 1e-9, "{kind}");
                assert!((seam.rgba[c] - paper.rgba[c]).abs() <= 1e-6, "{kind}");
            }
        }
    });
}

/// Opacity points over a scalar range `[lo, hi]`.
type OpacityRamp = fn(f64, f64) -> Vec<(f64, f64)>;

/// The fast path's jumps over transparent space: from a sample in a cell the transfer function
/// makes wholly transparent to the next bound of a piece of a cell it does not (BVHs), or to
/// the next grid cell referencing such a cell (grids). On the pump rotor with an opacity ramp
/// that is zero over the lower half of the range, every structure's fast image equals the
/// paper path's (which samples every cell and never jumps) within 1e-6 with the same sample
/// positions, while it jumps, and locates and tests fewer cells. A transfer function
/// transparent everywhere takes no sample at all, on every structure, and one transparent
/// nowhere never jumps.
#[test]
fn jumps_over_transparent_space_cross_fewer_cells_for_the_same_image() {
    let mesh = generate(Dataset::PumpRotor, 8_000).expect("dataset");
    let neighbours = common::closed_neighbours(&mesh);
    let size = 40;
    let camera = Camera::view(mesh.bounds(), size, size, 30.0, 25.0, 1.0);
    let step = default_step(&mesh);
    let options = RenderOptions::new(size, size, step);
    let opacity_ramps: [(&str, OpacityRamp); 3] = [
        ("upper half", |lo, hi| {
            vec![(lo, 0.0), (0.5 * (lo + hi), 0.0), (hi, 0.8)]
        }),
        ("nowhere", |lo, hi| vec![(lo, 0.0), (hi, 0.0)]),
        ("everywhere", |lo, hi| vec![(lo, 0.1), (hi, 0.8)]),
    ];
    for (name, ramp) in opacity_ramps {
        let mut paper: Option<(Image, RenderStats)> = None;
        for kind in [
            StructureKind::CartGrid,
            StructureKind::CylGrid,
            StructureKind::CartBvh,
            StructureKind::CylBvh,
        ] {
            let accel =
                Accel::build(&mesh, kind, &Axis::Z, &AccelParams::default()).expect("build");
            let volume = Volume::new(&mesh, &accel).expect("volume");
            let [lo, hi] = volume.scalar_range();
            let tf = TransferFunction {
                opacity: ramp(lo, hi),
                ..TransferFunction::default_for_range(lo, hi, 0.8, 0.2)
            };
            let render = |path| {
                let options = RenderOptions { path, ..options };
                Renderer::new(&volume, &tf, &options)
                    .expect("renderer")
                    .with_topology(&neighbours)
                    .render(&camera, None)
                    .expect("render")
            };
            let (image, s) = render(RenderPath::Fast);
            eprintln!("{name} {kind}: {s:?}");
            let (p_image, p) = paper.get_or_insert_with(|| render(RenderPath::Paper));
            assert_eq!(p.transparent_jumps, 0, "{name} {kind}");
            // (Where nothing is visible the fast path takes no sample; the paper path
            // samples all the same, a measurement.)
            if name != "nowhere" {
                assert_eq!(s.samples, p.samples, "{name} {kind}");
            }
            let d = image.max_abs_difference(p_image);
            assert!(d <= 1e-6, "{name} {kind}: {d}");
            match name {
                "upper half" => {
                    assert!(s.transparent_jumps > 0, "{name} {kind}: {s:?}");
                    assert!(s.hex_tests < p.hex_tests, "{name} {kind}: {s:?} {p:?}");
                    assert!(
                        s.samples_located < p.samples_located,
                        "{name} {kind}: {s:?} {p:?}"
                    );
                    assert!(
                        image.rgba.iter().any(|p| p[3] > 0.05),
                        "{name}: empty image"
                    );
                }
                "nowhere" => {
                    // Nothing can be seen: no ray samples, tests a cell or asks a structure.
                    assert_eq!(s.rays, (size * size) as u64, "{name} {kind}");
                    assert_eq!(
                        (
                            s.samples,
                            s.hex_tests,
                            s.transparent_jumps,
                            s.internal_visits
                        ),
                        (0, 0, 0, 0),
                        "{name} {kind}: {s:?}"
                    );
                    assert!(image.rgba.iter().all(|p| p[3] == 0.0), "{name} {kind}");
                }
                "everywhere" => {
                    assert_eq!(s.samples_skipped, 0, "{name} {kind}: {s:?}");
                    assert_eq!(s.transparent_jumps, 0, "{name} {kind}: {s:?}");
                }
                _ => {}
            }
        }
    }
}

/// A cylindrical BVH's node ray tests are made by its first render and kept with the structure:
/// a second render (a new renderer, as every frame of the C ABI and the VTK mapper makes)
/// finds the same table, one entry a node; other structures have none.
#[test]
fn node_shapes_are_made_once_per_structure_and_kept_across_frames() {
    let mesh = generate(Dataset::PumpRotor, 3000).expect("rotor");
    let axis = cylvol::axis::detect(&mesh);
    let frame = |accel: &Accel| {
        let volume = Volume::new(&mesh, accel).expect("volume");
        let [lo, hi] = volume.scalar_range();
        let tf = TransferFunction::default_for_range(lo, hi, 0.3, 0.1);
        let options = RenderOptions::new(24, 24, cylvol::render::default_step(&mesh));
        let camera = Camera::view(mesh.bounds(), 24, 24, 30.0, 20.0, 1.0);
        Renderer::new(&volume, &tf, &options)
            .expect("renderer")
            .render(&camera, None)
            .expect("render");
    };
    let cyl = Accel::build(&mesh, StructureKind::CylBvh, &axis, &AccelParams::default())
        .expect("cyl-bvh");
    frame(&cyl);
    let first = cyl.node_shapes().all().as_ptr();
    let nodes = match cyl.stats() {
        cylvol::accel::StructureStats::Bvh(b) => b.nodes,
        other => panic!("{other:?}"),
    };
    assert_eq!(cyl.node_shapes().all().len(), nodes);
    frame(&cyl);
    assert_eq!(cyl.node_shapes().all().as_ptr(), first, "made again");
    let cart = Accel::build(
        &mesh,
        StructureKind::CartBvh,
        &axis,
        &AccelParams::default(),
    )
    .expect("cart-bvh");
    frame(&cart);
    assert!(cart.node_shapes().all().is_empty());
}

/// A renderer takes over the transparent cells and visible nodes an earlier renderer of the
/// same volume derived from the same transfer table (as the C ABI's next frame does): the
/// image and work are those of a renderer that made its own. Taken over from a volume with
/// other scalars but the same table, they change the picture — so they are used, not made
/// again — and with another table they are dropped.
#[test]
fn derived_parts_are_taken_over_for_the_same_table_only() {
    let mesh = generate(Dataset::PumpRotor, 8_000).expect("dataset");
    let neighbours = common::closed_neighbours(&mesh);
    let accel = Accel::build(
        &mesh,
        StructureKind::CylBvh,
        &Axis::Z,
        &AccelParams::default(),
    )
    .expect("build");
    let size = 32;
    let camera = Camera::view(mesh.bounds(), size, size, 30.0, 25.0, 1.0);
    let options = RenderOptions::new(size, size, default_step(&mesh));
    let volume = Volume::new(&mesh, &accel).expect("volume");
    let [lo, hi] = volume.scalar_range();
    let upper_half = TransferFunction {
        opacity: vec![(lo, 0.0), (0.5 * (lo + hi), 0.0), (hi, 0.8)],
        ..TransferFunction::default_for_range(lo, hi, 0.8, 0.2)
    };
    let lower_half = TransferFunction {
        opacity: vec![(lo, 0.8), (0.5 * (lo + hi), 0.0), (hi, 0.0)],
        ..upper_half.clone()
    };
    let renderer = |v, tf| {
        Renderer::new(v, tf, &options)
            .expect("renderer")
            .with_topology(&neighbours)
    };
    // The frame of a renderer that makes its own parts, and of one handed `derived`.
    let own_and_taken = |v, tf, derived| {
        let render = |r: Renderer| r.render(&camera, None).expect("render");
        (
            render(renderer(v, tf)),
            render(renderer(v, tf).with_derived(derived)),
        )
    };
    let first = renderer(&volume, &upper_half);
    let (image, stats) = first.render(&camera, None).expect("render");
    let derived = first.into_derived().expect("made before the rays");
    // The same table: the same frame.
    let second = renderer(&volume, &upper_half).with_derived(derived);
    let (again, again_stats) = second.render(&camera, None).expect("render");
    assert_eq!(again.rgba, image.rgba);
    assert_eq!(again_stats, stats);
    // Another table: dropped, the frame of a renderer that made its own.
    let derived = second.into_derived().expect("kept");
    let ((own, own_stats), (taken, taken_stats)) = own_and_taken(&volume, &lower_half, derived);
    assert_eq!(taken.rgba, own.rgba);
    assert_eq!(taken_stats, own_stats);
    // Another volume (the scalars in reverse point order) with the first table: what it takes
    // over is used, so the picture is not its own.
    let made = renderer(&volume, &upper_half);
    made.render(&camera, None).expect("render");
    let derived = made.into_derived().expect("made");
    let mut reversed = mesh.clone();
    let (association, values) = mesh.active_scalars().expect("a scalar");
    assert_eq!(association, cylvol::Association::Point);
    let flipped = values.iter().rev().copied().collect();
    reversed
        .replace_arrays(vec![cylvol::DataArray::scalar("flipped", flipped)], vec![])
        .expect("arrays");
    let other = Volume::new(&reversed, &accel).expect("volume");
    assert_eq!(other.scalar_range(), [lo, hi]);
    let ((own, _), (taken, _)) = own_and_taken(&other, &upper_half, derived);
    assert!(own.max_abs_difference(&taken) > 1e-2, "not taken over");
}
