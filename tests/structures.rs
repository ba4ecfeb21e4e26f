//! All four acceleration structures locate exactly the points brute force locates, on every
//! real mesh, every synthetic dataset (small), and the hard meshes: sectors
//! crossing θ = ±π and θ = 0, a full ring (closed, and with a duplicated seam), an O-grid with
//! collapsed cells on the axis, and meshes moved 10⁶ units away. Validation passes for all.

mod common;

use std::f64::consts::PI;

use common::{data, moved, o_grid_with_axis_wedges, sample_points, sector};
use cylvol::accel::{Accel, AccelParams, Counters, StructureKind};
use cylvol::axis::Axis;
use cylvol::datasets::{generate, Dataset};
use cylvol::geometry::containment::locate_in_cell;
use cylvol::geometry::cylindrical::CylFrame;
use cylvol::Mesh;
use glam::DVec3;

/// Every cell containing `p`, by testing all of them.
fn brute_force(mesh: &Mesh, p: DVec3) -> Vec<u32> {
    (0..mesh.cell_count())
        .filter(|&c| locate_in_cell(&mesh.cell_corners(c), p, None).is_some())
        .map(|c| c as u32)
        .collect()
}

/// Builds all four structures about `axis`, validates them, and checks location against brute
/// force on seeded points inside, on faces of, and around the mesh.
fn check_all_structures(name: &str, mesh: &Mesh, axis: &Axis, points_per_kind: usize) {
    let points = sample_points(mesh, points_per_kind, 0x5EED ^ mesh.cell_count() as u64);
    let truth: Vec<Vec<u32>> = points.iter().map(|&p| brute_force(mesh, p)).collect();
    let inside = truth.iter().filter(|t| !t.is_empty()).count();
    assert!(
        inside >= points_per_kind,
        "{name}: too few points inside ({inside})"
    );
    for kind in StructureKind::ALL {
        let accel = Accel::build(mesh, kind, axis, &AccelParams::default())
            .unwrap_or_else(|e| panic!("{name}: {kind} failed to build: {e}"));
        accel.assert_well_formed(mesh);
        let mut counters = Counters::default();
        for (p, expected) in points.iter().zip(&truth) {
            let found = accel.locate(mesh, *p, &mut counters);
            match found {
                Some((cell, param)) => {
                    assert!(
                        expected.contains(&cell),
                        "{name}: {kind} returned cell {cell} for {p}, brute force finds {expected:?}"
                    );
                    let back =
                        cylvol::geometry::trilinear::map(&mesh.cell_corners(cell as usize), param);
                    let size =
                        cylvol::geometry::bounds::cell_bounds(&mesh.cell_corners(cell as usize))
                            .diagonal();
                    assert!(
                        (back - *p).length() <= 1e-8 * size,
                        "{name}: {kind} parameters do not map back"
                    );
                }
                None => assert!(
                    expected.is_empty(),
                    "{name}: {kind} missed {p}, which lies in cells {expected:?}"
                ),
            }
        }
        assert!(
            counters.hex_tests >= inside as u64,
            "{name}: {kind} counted too few tests"
        );
    }
}

fn frame(origin: DVec3, direction: DVec3) -> (CylFrame, Axis) {
    let axis = Axis::new(origin, direction).unwrap();
    (CylFrame::new(axis.origin, axis.direction).unwrap(), axis)
}

#[test]
fn sector_crossing_the_seam_at_pi() {
    let (f, axis) = frame(DVec3::ZERO, DVec3::Z);
    let mesh = sector(&f, [0.5, 1.0], [PI - 0.4, PI + 0.3], 0.5, [6, 14, 5], false);
    check_all_structures("sector across ±π", &mesh, &axis, 300);
}

#[test]
fn sector_crossing_theta_zero_about_a_tilted_axis() {
    let (f, axis) = frame(DVec3::new(0.3, -0.2, 0.1), DVec3::new(1.0, 0.5, 0.2));
    let mesh = sector(&f, [2.0, 3.0], [-0.3, 0.25], 1.0, [5, 12, 6], false);
    check_all_structures("sector across 0", &mesh, &axis, 300);
}

#[test]
fn full_rings_closed_and_with_a_duplicated_seam() {
    let (f, axis) = frame(DVec3::ZERO, DVec3::Z);
    let closed = sector(&f, [0.4, 1.0], [-PI, PI], 0.6, [5, 36, 4], true);
    check_all_structures("closed ring", &closed, &axis, 300);
    let seamed = sector(&f, [0.4, 1.0], [-PI, PI], 0.6, [5, 36, 4], false);
    let used = |m: &cylvol::Mesh| {
        let mut ids: Vec<u32> = m.cells().iter().flatten().copied().collect();
        ids.sort_unstable();
        ids.dedup();
        ids.len()
    };
    // The closed ring shares its seam points; the other has a second, coincident set.
    assert_eq!(used(&seamed), used(&closed) + 6 * 5);
    check_all_structures("ring with duplicated seam", &seamed, &axis, 300);
}

#[test]
fn o_grid_with_wedges_on_the_axis() {
    let (f, axis) = frame(DVec3::ZERO, DVec3::new(0.0, 1.0, 0.0));
    let mesh = o_grid_with_axis_wedges(&f, 1.0, 16, 4, 4);
    check_all_structures("O-grid", &mesh, &axis, 300);
    // Points on the axis itself.
    let accel = Accel::build(
        &mesh,
        StructureKind::CylGrid,
        &axis,
        &AccelParams::default(),
    )
    .unwrap();
    let bvh = Accel::build(&mesh, StructureKind::CylBvh, &axis, &AccelParams::default()).unwrap();
    for i in 0..=20 {
        let p = DVec3::new(0.0, i as f64 / 20.0, 0.0);
        let mut c = Counters::default();
        assert!(
            accel.locate(&mesh, p, &mut c).is_some(),
            "grid misses the axis at {p}"
        );
        assert!(
            bvh.locate(&mesh, p, &mut c).is_some(),
            "BVH misses the axis at {p}"
        );
    }
}

#[test]
fn meshes_moved_a_million_units_away() {
    let (f, axis) = frame(DVec3::ZERO, DVec3::Z);
    let ring = sector(&f, [0.4, 1.0], [-PI, PI], 0.6, [4, 24, 3], true);
    let offset = DVec3::new(1e6, -1e6, 1e6);
    let far = moved(&ring, offset);
    let far_axis = Axis::new(axis.origin + offset, axis.direction).unwrap();
    check_all_structures("ring 1e6 away", &far, &far_axis, 200);
    let (f, _) = frame(DVec3::ZERO, DVec3::Z);
    let grid = o_grid_with_axis_wedges(&f, 1.0, 12, 3, 3);
    let far = moved(&grid, offset);
    check_all_structures("O-grid 1e6 away", &far, &far_axis, 200);
}

#[test]
fn synthetic_datasets_small() {
    for d in Dataset::ALL {
        let mesh = generate(d, 6_000).unwrap();
        let axis = cylvol::axis::detect(&mesh);
        check_all_structures(d.name(), &mesh, &axis, 150);
    }
}

#[test]
fn real_meshes() {
    for name in ["mixer.vtk", "postxyz.bin", "combxyz.bin", "hexa.vtk"] {
        let mesh = cylvol::io::read_file(&data(name), &Default::default()).unwrap();
        let axis = cylvol::axis::detect(&mesh);
        check_all_structures(name, &mesh, &axis, 100);
    }
}
