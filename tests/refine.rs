//! Uniform refinement (`Mesh::refined`): the children tile their parents exactly (geometry
//! and point fields, by a proptest against the parent's trilinear map), the refined mesh is as
//! conforming as the original (its open faces are the original's, each cut `n × n`), cell
//! arrays follow their parents, a refined volume renders the original's picture, and bad
//! requests get clear errors.

mod common;

use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::datasets::{generate, Dataset};
use cylvol::geometry::cylindrical::CylFrame;
use cylvol::geometry::trilinear::{map, weights};
use cylvol::mesh::topology::{FaceNeighbours, EDGES, FACES};
use cylvol::mesh::MAX_REFINEMENT;
use cylvol::render::BISECTIONS;
use cylvol::render::{face_neighbours, Camera, RenderOptions, Renderer, TransferFunction, Volume};
use cylvol::{CellKind, DataArray, Error, Mesh};
use glam::DVec3;
use proptest::prelude::*;
use std::sync::OnceLock;

fn rotor() -> Mesh {
    generate(Dataset::PumpRotor, 3_000).expect("dataset")
}

/// The rotor and its refinements by 2, 3 and 4, made once for all proptest cases.
fn refined(n: u32) -> &'static (Mesh, Mesh) {
    static MESHES: [OnceLock<(Mesh, Mesh)>; 3] =
        [OnceLock::new(), OnceLock::new(), OnceLock::new()];
    MESHES[(n - 2) as usize].get_or_init(|| {
        let mesh = rotor();
        let fine = mesh.refined(n).expect("refined");
        (mesh, fine)
    })
}

/// The child of `cell` holding parametric point `q` of it, and `q` in the child's parameters
/// (children are numbered parent by parent, `u` fastest).
fn child_of(cell: usize, q: DVec3, n: u32) -> (usize, DVec3) {
    let nf = n as f64;
    let idx = (q * nf).floor().clamp(DVec3::ZERO, DVec3::splat(nf - 1.0));
    let local = q * nf - idx;
    let (i, j, k) = (idx.x as usize, idx.y as usize, idx.z as usize);
    let n = n as usize;
    (cell * n * n * n + i + n * (j + n * k), local)
}

fn interpolate(mesh: &Mesh, cell: usize, array: &DataArray, q: DVec3) -> f64 {
    let w = weights(q);
    mesh.cells()[cell]
        .iter()
        .zip(w)
        .map(|(&p, w)| array.values[p as usize * array.components] * w)
        .sum()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn children_reproduce_the_parents_map_and_field(
        cell in 0usize..3_000,
        u in 0.0f64..1.0, v in 0.0f64..1.0, w in 0.0f64..1.0,
        n in 2u32..5,
    ) {
        let (mesh, fine) = refined(n);
        let cell = cell % mesh.cell_count();
        let q = DVec3::new(u, v, w);
        let (child, local) = child_of(cell, q, n);
        let parent_x = map(&mesh.cell_corners(cell), q);
        let child_x = map(&fine.cell_corners(child), local);
        prop_assert!((parent_x - child_x).length() < 1e-12, "{parent_x} vs {child_x}");
        for (a, b) in mesh.point_data().iter().zip(fine.point_data()) {
            prop_assert_eq!(&a.name, &b.name);
            let (pa, pb) = (interpolate(mesh, cell, a, q), interpolate(fine, child, b, local));
            prop_assert!((pa - pb).abs() <= 1e-12 * pa.abs().max(1.0), "{}: {pa} vs {pb}", a.name);
        }
    }
}

#[test]
fn refinement_is_conforming_and_counts_add_up() {
    let mesh = rotor();
    let coarse = FaceNeighbours::build(&mesh);
    for n in [1, 2, 3] {
        let fine = mesh.refined(n).unwrap();
        assert_eq!(fine.cell_count(), mesh.cell_count() * (n * n * n) as usize);
        // Points on edges and faces are blends of their corners: within rounding of the box.
        for (a, b) in fine.bounds().iter().zip(mesh.bounds()) {
            assert!((a - b).abs() <= 1e-15 * b.abs().max(1.0), "{a} vs {b}");
        }
        assert_eq!(fine.active_scalar(), mesh.active_scalar());
        assert!(fine.kinds().iter().all(|&k| k == CellKind::Hexahedron));
        // Every original face is cut n × n; only the open ones stay open. A point made twice
        // (once per cell reaching it) would open inner faces.
        let faces = FaceNeighbours::build(&fine);
        assert_eq!(
            faces.boundary_face_count(),
            coarse.boundary_face_count() * (n * n) as usize,
            "n = {n}"
        );
        assert_eq!(faces.nonmanifold_faces(), 0);
        // Points: the original ones, n − 1 on each edge, (n − 1)² in each face, (n − 1)³ in
        // each cell, with edges and faces shared.
        let m = (n - 1) as usize;
        let edges = distinct(&mesh, &EDGES);
        let face_count = distinct(&mesh, &FACES);
        assert_eq!(
            fine.point_count(),
            mesh.point_count() + edges * m + face_count * m * m + mesh.cell_count() * m * m * m,
            "n = {n}"
        );
    }
}

/// How many distinct point-id sets the cells' sub-lists `slots` make (edges or faces).
fn distinct<const K: usize>(mesh: &Mesh, slots: &[[usize; K]]) -> usize {
    let mut set = std::collections::HashSet::new();
    for cell in mesh.cells() {
        for s in slots {
            let mut ids: Vec<u32> = s.iter().map(|&k| cell[k]).collect();
            ids.sort_unstable();
            set.insert(ids);
        }
    }
    set.len()
}

#[test]
fn cell_arrays_follow_their_parents() {
    let mut parts = rotor().into_parts();
    let cells = parts.cells.len();
    parts.cell_data.push(DataArray {
        name: "id2".into(),
        components: 2,
        values: (0..cells).flat_map(|c| [c as f64, -(c as f64)]).collect(),
    });
    let mesh = Mesh::from_parts(parts).unwrap();
    let fine = mesh.refined(2).unwrap();
    let a = fine.cell_data().iter().find(|a| a.name == "id2").unwrap();
    for child in (0..fine.cell_count()).step_by(7) {
        let parent = (child / 8) as f64;
        assert_eq!(&a.values[2 * child..2 * child + 2], &[parent, -parent]);
    }
}

/// The refined mesh is the same volume, so it renders the same picture from the same samples.
/// With whole steps the samples' values agree to the inverse map's accuracy, so the images
/// agree to 1e-6 (as different structures' do, `tests/render.rs`). With boundary segments the
/// rays' entries and exits are searched in different cells: each is found to within
/// `step / 2^(BISECTIONS + 1)`, so a pixel may differ by the opacity of two such slivers
/// (entry and exit) of the most opaque medium, and no more.
#[test]
fn a_refined_volume_renders_the_same_picture() {
    let mesh = rotor();
    let fine = mesh.refined(2).unwrap();
    let step = cylvol::render::default_step(&mesh);
    let image = |m: &Mesh, segments: bool| {
        let axis = cylvol::axis::detect(m);
        let accel = Accel::build(m, StructureKind::CylBvh, &axis, &AccelParams::default()).unwrap();
        let neighbours = face_neighbours(m, &accel);
        let volume = Volume::new(m, &accel).unwrap();
        let [lo, hi] = volume.scalar_range();
        let tf = TransferFunction::default_for_range(lo, hi, 0.3, 0.1);
        let camera = Camera::view(m.bounds(), 64, 64, 30.0, 20.0, 1.0);
        let mut options = RenderOptions::new(64, 64, step);
        options.boundary_segments = segments;
        let renderer = Renderer::new(&volume, &tf, &options)
            .unwrap()
            .with_topology(&neighbours);
        let densest = (0..=1000)
            .map(|k| renderer.table().lookup(lo + (hi - lo) * k as f64 / 1000.0)[3])
            .fold(0.0f64, f64::max);
        (renderer.render(&camera, None).unwrap().0, densest)
    };
    for segments in [false, true] {
        let ((a, densest), (b, _)) = (image(&mesh, segments), image(&fine, segments));
        assert!(a.rgba.iter().any(|p| p[3] > 0.05), "something is seen");
        let diff = f64::from(a.max_abs_difference(&b));
        let sliver = 0.5f64.powi(BISECTIONS as i32 + 1);
        let bound = if segments {
            2.0 * (1.0 - (1.0 - densest).powf(sliver))
        } else {
            1e-6
        };
        eprintln!("segments {segments}: differs by {diff}, bound {bound}");
        assert!(
            diff <= bound,
            "segments {segments}: differs by {diff} > {bound}"
        );
    }
}

#[test]
fn bad_requests_get_clear_errors() {
    let mesh = rotor();
    for n in [0, MAX_REFINEMENT + 1] {
        match mesh.refined(n) {
            Err(Error::Invalid(m)) => assert!(m.contains("refinement"), "{m}"),
            other => panic!("{n}: {other:?}"),
        }
    }
    // Wedges (hexahedra with a collapsed edge) cannot be cut into hexahedra.
    let frame = CylFrame::new(DVec3::ZERO, DVec3::Z).unwrap();
    let wedge = common::o_grid_with_axis_wedges(&frame, 1.0, 8, 2, 2);
    match wedge.refined(2) {
        Err(Error::Invalid(m)) => assert!(m.contains("wedge") && m.contains("hexahedral"), "{m}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_refinement_beyond_the_machine_s_memory_is_an_error_not_an_abort() {
    // About a million cells cut 16 × 16 × 16: 4 G cells (within u32), hundreds of GB.
    let mesh =
        cylvol::datasets::generate(cylvol::datasets::Dataset::PumpRotor, 1_000_000).expect("rotor");
    let children = mesh.cell_count() as u64 * u64::from(MAX_REFINEMENT).pow(3);
    assert!(
        children <= u64::from(u32::MAX),
        "{children} cells: over the u32 check instead"
    );
    let needed = cylvol::mesh::refined_bytes(&mesh, children);
    let Some(memory) = cylvol::mesh::physical_memory() else {
        eprintln!("no /proc/meminfo: the allocator's refusal is the only guard here");
        return;
    };
    if memory >= needed {
        eprintln!("{memory} bytes of memory hold the {needed} needed: nothing to refuse");
        return;
    }
    match mesh.refined(MAX_REFINEMENT) {
        Err(Error::Invalid(m)) => assert!(m.contains("GB of memory"), "{m}"),
        other => panic!("{:?}", other.map(|m| m.cell_count())),
    }
}
