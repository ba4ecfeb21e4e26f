//! Axis detection on synthetic meshes built here (sectors, rings, an O-grid, a Cartesian
//! block) and the `--axis` override syntax.

use std::f64::consts::{PI, TAU};

use cylvol::axis::{self, Axis, CLEAR_AXIS_GAIN};
use cylvol::{CellKind, Mesh, MeshParts};
use glam::DVec3;

/// A structured ring or sector about the line through `origin` along `direction`:
/// `nr × nt × nh` cells over r ∈ [r0, r1], θ ∈ [0, sector] (closed when `sector` is 2π),
/// h ∈ [0, height]. `shear(r, h)` is added to θ (blade twist, lean).
#[allow(clippy::too_many_arguments)]
fn ring(
    origin: DVec3,
    direction: DVec3,
    [r0, r1]: [f64; 2],
    sector: f64,
    height: f64,
    [nr, nt, nh]: [usize; 3],
    shear: &dyn Fn(f64, f64) -> f64,
) -> Mesh {
    let d = direction.normalize();
    let u = d.any_orthonormal_vector();
    let v = d.cross(u);
    let closed = (sector - TAU).abs() < 1e-12;
    let nt_points = if closed { nt } else { nt + 1 };
    let mut points = Vec::new();
    for k in 0..=nh {
        for j in 0..nt_points {
            for i in 0..=nr {
                // Radial grading, so cells differ in size.
                let s = i as f64 / nr as f64;
                let r = r0 + (r1 - r0) * s * s.sqrt();
                let h = height * k as f64 / nh as f64;
                let t = sector * j as f64 / nt as f64 + shear(r, h);
                points.push(origin + u * (r * t.cos()) + v * (r * t.sin()) + d * h);
            }
        }
    }
    let id = |i: usize, j: usize, k: usize| (i + (nr + 1) * (j % nt_points + nt_points * k)) as u32;
    let mut cells = Vec::new();
    for k in 0..nh {
        for j in 0..nt {
            for i in 0..nr {
                cells.push(cylvol::io::structured::cell_ids(i, j, k, id));
            }
        }
    }
    mesh(points, cells, None)
}

fn mesh(points: Vec<DVec3>, cells: Vec<[u32; 8]>, kinds: Option<Vec<CellKind>>) -> Mesh {
    let kinds = kinds.unwrap_or_else(|| vec![CellKind::Hexahedron; cells.len()]);
    Mesh::from_parts(MeshParts {
        points,
        cells,
        kinds,
        ..Default::default()
    })
    .expect("test mesh is valid")
}

fn size(m: &Mesh) -> f64 {
    let b = m.bounds();
    DVec3::new(b[1] - b[0], b[3] - b[2], b[5] - b[4]).length()
}

/// Asserts the detected axis is within `max_deg` of the true line and passes within
/// `max_offset × size` of it at its origin, and that detection calls it clear.
fn assert_axis(m: &Mesh, origin: DVec3, direction: DVec3, max_deg: f64, max_offset: f64) {
    let truth = Axis::new(origin, direction).unwrap();
    let report = axis::detect_with_report(m);
    let a = report.axis;
    let angle = a.angle_to(&truth).to_degrees();
    let offset = truth.distance_to(a.origin) / size(m);
    assert!(report.clear, "no clear axis: {report:?}");
    assert!(angle < max_deg, "angle {angle}° ≥ {max_deg}°: {report:?}");
    assert!(offset < max_offset, "offset {offset} of size: {report:?}");
    // The documented conventions.
    assert!((a.direction.length() - 1.0).abs() < 1e-12);
    let major = a.direction.abs().max_element();
    assert!(a.direction.to_array().contains(&major));
    let b = m.bounds();
    let centre = DVec3::new(b[0] + b[1], b[2] + b[3], b[4] + b[5]) * 0.5;
    assert!((a.origin - centre).dot(a.direction).abs() < 1e-6 * size(m));
}

fn no_shear(_: f64, _: f64) -> f64 {
    0.0
}

#[test]
fn sectors_about_tilted_axes() {
    let cases = [
        (
            10.0f64,
            DVec3::new(0.3, -0.5, 0.8),
            DVec3::new(2.5, -1.0, 0.7),
        ),
        (
            18.0,
            DVec3::new(1.0, 0.05, -0.02),
            DVec3::new(0.0, 0.0, 0.0),
        ),
        (90.0, DVec3::new(-0.2, 0.9, 0.4), DVec3::new(-3.0, 4.0, 1.0)),
        (
            360.0,
            DVec3::new(0.6, 0.6, -0.5),
            DVec3::new(10.0, 0.0, -7.0),
        ),
    ];
    for (degrees, direction, origin) in cases {
        let m = ring(
            origin,
            direction,
            [1.0, 2.0],
            degrees.to_radians(),
            0.8,
            [8, (degrees / 3.0) as usize + 3, 6],
            &no_shear,
        );
        assert_axis(&m, origin, direction, 0.1, 1e-3);
    }
}

#[test]
fn sector_a_million_units_away() {
    let origin = DVec3::new(1e6, -1e6, 5e5);
    let direction = DVec3::new(0.1, 0.2, -1.0);
    let m = ring(
        origin,
        direction,
        [3.0, 4.0],
        20f64.to_radians(),
        1.0,
        [6, 10, 5],
        &no_shear,
    );
    assert_axis(&m, origin, direction, 0.1, 1e-3);
    // The same mesh near the origin finds the same (shifted) line.
    let near = ring(
        DVec3::ZERO,
        direction,
        [3.0, 4.0],
        20f64.to_radians(),
        1.0,
        [6, 10, 5],
        &no_shear,
    );
    let (a, b) = (axis::detect(&m), axis::detect(&near));
    assert!(a.angle_to(&b) < 1e-6, "{a} vs {b}");
}

#[test]
fn twisted_blade_passage_ring() {
    // Cells sheared in θ along h (twist) and r (lean), as in an impeller passage.
    let origin = DVec3::new(0.5, 0.25, -2.0);
    let direction = DVec3::new(0.2, -0.1, 1.0);
    let twist = |r: f64, h: f64| 0.6 * h + 0.3 * (r - 1.0) * (1.0 + h);
    let m = ring(origin, direction, [1.0, 1.6], TAU, 1.0, [6, 48, 8], &twist);
    assert_axis(&m, origin, direction, 0.1, 1e-3);
}

#[test]
fn o_grid_cylinder_with_wedges_on_the_axis() {
    // A cylinder of radius 1 about x through (1, 2, 3): a ring of wedges round the axis,
    // hexahedra outside.
    let origin = DVec3::new(1.0, 2.0, 3.0);
    let (nr, nt, nh) = (6usize, 24usize, 5usize);
    let mut points = Vec::new();
    let mut kinds = Vec::new();
    let mut cells = Vec::new();
    // Per layer: the axis point, then nt points on each of nr rings.
    let per_layer = 1 + nr * nt;
    for k in 0..=nh {
        let h = 2.0 * k as f64 / nh as f64;
        points.push(origin + DVec3::X * h);
        for i in 1..=nr {
            for j in 0..nt {
                let (r, t) = (i as f64 / nr as f64, TAU * j as f64 / nt as f64);
                points.push(origin + DVec3::new(h, r * t.cos(), r * t.sin()));
            }
        }
    }
    let ring_id = |i: usize, j: usize, k: usize| (k * per_layer + 1 + (i - 1) * nt + j % nt) as u32;
    let axis_id = |k: usize| (k * per_layer) as u32;
    for k in 0..nh {
        for j in 0..nt {
            // Wedge: triangle (axis, p_j, p_j+1) at k and k+1, collapsed to a hexahedron.
            let wedge = [
                axis_id(k),
                ring_id(1, j, k),
                ring_id(1, j + 1, k),
                axis_id(k + 1),
                ring_id(1, j, k + 1),
                ring_id(1, j + 1, k + 1),
            ];
            // Orientation: VTK's wedge has its first triangle's normal pointing away from
            // the second; try both orders and keep the valid one.
            let swapped = [wedge[0], wedge[2], wedge[1], wedge[3], wedge[5], wedge[4]];
            let ok = |w: &[u32; 6]| {
                let c = CellKind::Wedge.collapse(w);
                let x = c.map(|i| points[i as usize]);
                cylvol::geometry::trilinear::corner_jacobian_determinants(&x)
                    .iter()
                    .all(|&d| d >= 0.0)
            };
            let w = if ok(&wedge) { wedge } else { swapped };
            cells.push(CellKind::Wedge.collapse(&w));
            kinds.push(CellKind::Wedge);
            for i in 1..nr {
                let hex = cylvol::io::structured::cell_ids(i, j, k, ring_id);
                let x = hex.map(|i| points[i as usize]);
                let flip = cylvol::geometry::trilinear::corner_jacobian_determinants(&x)[0] < 0.0;
                cells.push(if flip {
                    [
                        hex[1], hex[0], hex[3], hex[2], hex[5], hex[4], hex[7], hex[6],
                    ]
                } else {
                    hex
                });
                kinds.push(CellKind::Hexahedron);
            }
        }
    }
    let m = mesh(points, cells, Some(kinds));
    assert_axis(&m, origin, DVec3::X, 0.1, 1e-3);
}

#[test]
fn cartesian_block_has_no_clear_axis() {
    let n = 10usize;
    let mut points = Vec::new();
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                // A box longer in y, so the fallback direction is known.
                points.push(DVec3::new(i as f64, 1.5 * j as f64, k as f64) * 0.1);
            }
        }
    }
    let m = mesh(
        points.clone(),
        cylvol::io::structured::hexahedra([n + 1, n + 1, n + 1], &points),
        None,
    );
    let report = axis::detect_with_report(&m);
    assert!(!report.clear, "{report:?}");
    assert!(report.gain < CLEAR_AXIS_GAIN, "{report:?}");
    // The fallback: the longest extent (y) through the box centre.
    assert_eq!(report.axis.direction, DVec3::Y);
    assert!((report.axis.origin - DVec3::new(0.5, 0.75, 0.5)).length() < 1e-12);
    // Cartesian boxes fit a Cartesian block exactly.
    assert!((report.cartesian_fit - 1.0).abs() < 1e-9, "{report:?}");
}

#[test]
fn a_clear_axis_beats_the_straight_sweep() {
    let m = ring(
        DVec3::ZERO,
        DVec3::Z,
        [1.0, 2.0],
        PI,
        1.0,
        [6, 30, 4],
        &no_shear,
    );
    let r = axis::detect_with_report(&m);
    assert!(r.residual < 1e-6, "{r:?}");
    assert!(r.inliers > 0.999, "{r:?}");
    assert!(r.inliers_at_infinity < 0.5, "{r:?}");
    assert!(r.gain > CLEAR_AXIS_GAIN && r.clear, "{r:?}");
    // Cylindrical boxes about the axis fit a polar grid better than x, y, z boxes.
    assert!(r.cylindrical_fit < r.cartesian_fit, "{r:?}");
    assert!(axis::residual_about(&m, &Axis::X) > 0.1);
}

#[test]
fn parse_shortcuts_and_full_form() {
    assert_eq!("x".parse::<Axis>().unwrap(), Axis::X);
    assert_eq!(" Y ".parse::<Axis>().unwrap(), Axis::Y);
    assert_eq!("z".parse::<Axis>().unwrap(), Axis::Z);
    let a: Axis = "1, 2.5, -3 : 0, 0, -4".parse().unwrap();
    assert_eq!(a.origin, DVec3::new(1.0, 2.5, -3.0));
    assert_eq!(
        a.direction,
        DVec3::Z,
        "normalised, largest component positive"
    );
    let b: Axis = "0,0,0:-1,1,0".parse().unwrap();
    let s = 0.5f64.sqrt();
    // Tie between |x| and |y|: the first (x) is made positive.
    assert!(
        (b.direction - DVec3::new(s, -s, 0.0)).length() < 1e-15,
        "{b:?}"
    );
    // Display round-trips exactly.
    let c: Axis = "0.1,-2e6,3:1,2,3".parse().unwrap();
    assert_eq!(c.to_string().parse::<Axis>().unwrap(), c);
}

#[test]
fn parse_errors_are_clear() {
    let cases = [
        ("", "empty"),
        ("w", "expected x, y, z"),
        ("1,2,3", "expected x, y, z"),
        ("1,2:0,0,1", "origin needs 3"),
        ("1,2,3:0,1", "direction needs 3"),
        ("1,a,3:0,0,1", "'a', which is not a number"),
        ("1,2,3:0,0,0", "zero length"),
        ("1,2,3:0,0,1e-320", "zero length"),
        ("nan,0,0:0,0,1", "non-finite"),
        ("0,0,0:inf,0,1", "non-finite"),
    ];
    for (text, expected) in cases {
        let e = text.parse::<Axis>().unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains(expected), "{text:?}: {msg}");
        assert!(msg.contains(&format!("'{text}'")), "{text:?}: {msg}");
        // Converts into the crate error for the CLI.
        let err: cylvol::Error = e.into();
        assert!(err.to_string().contains(expected));
    }
    assert!(Axis::new(DVec3::ZERO, DVec3::ZERO).is_err());
    assert!(Axis::new(DVec3::splat(f64::NAN), DVec3::Z).is_err());
}

#[test]
fn axis_geometry_helpers() {
    let a = Axis::new(DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.0, 0.0, -2.0)).unwrap();
    assert_eq!(a.direction, DVec3::Z);
    assert!((a.distance_to(DVec3::new(4.0, 5.0, 9.0)) - 5.0).abs() < 1e-12);
    let c = a.cylindrical(DVec3::new(1.0, 3.0, 2.0));
    assert!((c.x - 2.0).abs() < 1e-12 && (c.z - 2.0).abs() < 1e-12);
    let (u, v, d) = a.frame();
    assert!(u.dot(v).abs() < 1e-15 && u.dot(d).abs() < 1e-15 && (u.cross(v) - d).length() < 1e-15);
    assert!((Axis::X.angle_to(&Axis::Y) - PI / 2.0).abs() < 1e-15);
    let tilted = Axis::new(DVec3::ZERO, DVec3::new(1.0, 0.0, 1.0)).unwrap();
    assert!((Axis::Z.angle_to(&tilted) - PI / 4.0).abs() < 1e-15);
}
