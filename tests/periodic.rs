//! Detection of rotationally periodic sectors: the real mixer (a 90° sector), the combustor
//! (an 18° sector whose sides bow), full rings (the LOX post, the cube, built rings), and built
//! sectors that cross the ±π seam, about tilted axes, that do not divide 360°, or whose sides
//! do not match; forced copy counts that fit and that do not.

mod common;

use std::f64::consts::PI;

use cylvol::axis::periodic::{self, NotPeriodic, PeriodicRequest};
use cylvol::axis::Axis;
use cylvol::geometry::cylindrical::CylFrame;
use cylvol::{Mesh, MeshParts};
use glam::DVec3;

fn load(name: &str) -> Mesh {
    cylvol::io::read_file(&common::data(name), &Default::default()).expect("real mesh")
}

fn frame(axis: &Axis) -> CylFrame {
    CylFrame::new(axis.origin, axis.direction).unwrap()
}

/// A sector from `start` over `span` degrees about `axis`, r 1–2, h 0–1.
fn sector(axis: &Axis, start: f64, span: f64, n: [usize; 3]) -> Mesh {
    let t = [start.to_radians(), (start + span).to_radians()];
    common::sector(&frame(axis), [1.0, 2.0], t, 1.0, n, false)
}

/// The distance of the line `found` from the line `truth` over the mesh's extent, and the angle
/// between their directions.
fn axis_error(found: &Axis, truth: &Axis) -> (f64, f64) {
    let angle = found.direction.angle_between(truth.direction);
    let off = |p: DVec3| {
        let d = p - truth.origin;
        (d - truth.direction * d.dot(truth.direction)).length()
    };
    (
        off(found.origin).max(off(found.origin + found.direction)),
        angle,
    )
}

#[test]
fn the_mixer_is_a_quarter_of_its_wheel_about_the_exact_axis() {
    let mesh = load("mixer.vtk");
    let detected = cylvol::axis::detect(&mesh);
    let found = periodic::detect(&mesh, &detected).expect("a periodic sector");
    assert_eq!(found.copies, 4);
    assert!((found.span_degrees() - 90.0).abs() < 1e-6, "{found:?}");
    assert!(found.matched_faces > 0 && found.unmatched_side_faces == 0);
    assert!(found.worst_mismatch < 1e-9, "{found:?}");
    // The detected axis is a hair off the z axis; the sides put the copies' axis on it.
    let (off, angle) = axis_error(&found.axis, &Axis::Z);
    assert!(off < 1e-9 && angle < 1e-9, "{found:?}: {off} {angle}");
    let (rough, _) = axis_error(&detected, &Axis::Z);
    assert!(rough > 100.0 * off.max(1e-12), "detected axis {detected:?}");
    // Forced: 4 fits, and reports the same match; 3 leaves gaps, 5 overlaps; 1 is the mesh.
    let forced = periodic::check_copies(&mesh, &detected, 4).unwrap();
    assert_eq!(
        (forced.copies, forced.matched_faces),
        (4, found.matched_faces)
    );
    for (n, what) in [(3, "leave gaps"), (5, "overlap")] {
        let e = periodic::check_copies(&mesh, &detected, n).unwrap_err();
        assert!(matches!(e, NotPeriodic::CopiesDoNotFit { .. }), "{e}");
        assert!(e.to_string().contains(what), "{e}");
    }
    assert_eq!(
        periodic::check_copies(&mesh, &detected, 1).unwrap().copies,
        1
    );
}

#[test]
fn the_combustor_spans_18_degrees_about_x_but_its_sides_bow() {
    let mesh = load("combxyz.bin");
    // About the detected axis (a third of a degree off x) the span is no divisor of 360°.
    let detected = cylvol::axis::detect(&mesh);
    let e = periodic::detect(&mesh, &detected).unwrap_err();
    assert!(matches!(e, NotPeriodic::SpanDoesNotDivide { .. }), "{e}");
    // About x it spans 18.1°, 20 copies, but no face lies on a constant angle: its sides are
    // not planes through the axis.
    let e = periodic::detect(&mesh, &Axis::X).unwrap_err();
    match &e {
        NotPeriodic::NoSides { copies, .. } => assert_eq!(*copies, 20),
        other => panic!("{other}"),
    }
    assert!(e.to_string().contains("give the number of copies"), "{e}");
    // Forcing 20 copies is accepted; 19 leave gaps, 21 overlap.
    assert_eq!(
        periodic::check_copies(&mesh, &Axis::X, 20).unwrap().copies,
        20
    );
    assert!(periodic::check_copies(&mesh, &Axis::X, 19).is_err());
    assert!(periodic::check_copies(&mesh, &Axis::X, 21).is_err());
}

#[test]
fn full_rings_are_not_sectors() {
    for name in ["postxyz.bin", "hexa.vtk"] {
        let mesh = load(name);
        let axis = cylvol::axis::detect(&mesh);
        let e = periodic::detect(&mesh, &axis).unwrap_err();
        assert_eq!(e, NotPeriodic::FullRing, "{name}");
        assert!(periodic::check_copies(&mesh, &axis, 4).is_err(), "{name}");
        // One copy is the mesh as it is.
        assert!(periodic::check_copies(&mesh, &axis, 1).is_ok(), "{name}");
    }
    let f = frame(&Axis::Z);
    for close in [true, false] {
        let ring = common::sector(&f, [1.0, 2.0], [-PI, PI], 1.0, [3, 24, 2], close);
        assert_eq!(
            periodic::detect(&ring, &Axis::Z).unwrap_err(),
            NotPeriodic::FullRing,
            "closed {close}"
        );
    }
}

#[test]
fn sectors_across_the_seam_about_tilted_axes_are_found_exactly() {
    let truth = Axis::new(DVec3::new(3.0, -2.0, 1.0), DVec3::new(0.3, -0.2, 1.0)).unwrap();
    for (start, span, copies) in [(150.0, 60.0, 6), (-20.0, 40.0, 9), (170.0, 20.0, 18)] {
        let mesh = sector(&truth, start, span, [4, 7, 3]);
        // Given a slightly wrong axis, the sides fix it.
        let rough = Axis::new(
            truth.origin + DVec3::new(2e-5, -1e-5, 0.0),
            truth.direction + DVec3::new(1e-5, 0.0, 0.0),
        )
        .unwrap();
        let found = periodic::detect(&mesh, &rough).expect("sector");
        assert_eq!(found.copies, copies, "{start} {span}");
        assert!((found.span_degrees() - span).abs() < 1e-7, "{found:?}");
        let (off, angle) = axis_error(&found.axis, &truth);
        assert!(off < 1e-9 && angle < 1e-9, "{start}: {off} {angle}");
        // The start angle is the sector's own, about the found axis.
        let first = mesh.points()[0];
        let (_, t, _) = found.frame().to_cylindrical(first);
        let d = (t - found.start).rem_euclid(std::f64::consts::TAU);
        assert!(
            d.min(std::f64::consts::TAU - d) < 1e-9,
            "{start}: {t} {}",
            found.start
        );
    }
}

#[test]
fn a_span_that_does_not_divide_360_is_refused_with_the_reason() {
    let mesh = sector(&Axis::Z, 10.0, 100.0, [3, 8, 2]);
    let e = periodic::detect(&mesh, &Axis::Z).unwrap_err();
    assert!(matches!(e, NotPeriodic::SpanDoesNotDivide { .. }), "{e}");
    let text = e.to_string();
    assert!(text.contains("100°") && text.contains("3.6"), "{text}");
    // Forcing a count it does not fit is refused too, saying how.
    let e = periodic::check_copies(&mesh, &Axis::Z, 4).unwrap_err();
    assert!(
        e.to_string().contains("400°") && e.to_string().contains("overlap"),
        "{e}"
    );
}

#[test]
fn sides_whose_points_do_not_land_on_each_other_are_refused() {
    // A quarter annulus whose end side's points are pulled along r by a fifth of a cell.
    let mesh = sector(&Axis::Z, 0.0, 90.0, [5, 6, 2]);
    let mut parts: MeshParts = mesh.into_parts();
    for p in &mut parts.points {
        let (r, t, h) = frame(&Axis::Z).to_cylindrical(*p);
        let inner = r > 1.0 + 1e-9 && r < 2.0 - 1e-9;
        if (t - PI / 2.0).abs() < 1e-12 && inner {
            *p = frame(&Axis::Z).from_cylindrical(r + 0.04, t, h);
        }
    }
    let bent = Mesh::from_parts(parts).unwrap();
    let e = periodic::detect(&bent, &Axis::Z).unwrap_err();
    match &e {
        NotPeriodic::SidesDoNotMatch {
            copies,
            unmatched,
            side,
            ..
        } => {
            assert_eq!(*copies, 4);
            assert!(*unmatched > 0 && *unmatched <= *side, "{e}");
        }
        other => panic!("{other}"),
    }
    // Forced, it is drawn anyway, and the mismatch is reported.
    let forced = periodic::check_copies(&bent, &Axis::Z, 4).unwrap();
    assert!(forced.unmatched_side_faces > 0 && forced.worst_mismatch > periodic::MATCH_TOLERANCE);
}

#[test]
fn requests_parse_and_resolve() {
    assert_eq!(
        "AUTO".parse::<PeriodicRequest>().unwrap(),
        PeriodicRequest::Auto
    );
    assert_eq!(
        "off".parse::<PeriodicRequest>().unwrap(),
        PeriodicRequest::Off
    );
    assert_eq!(
        " 20 ".parse::<PeriodicRequest>().unwrap(),
        PeriodicRequest::Copies(20)
    );
    for bad in ["0", "-4", "3601", "four", ""] {
        let e = bad.parse::<PeriodicRequest>().unwrap_err();
        assert!(e.to_string().contains("auto"), "{bad}: {e}");
    }
    let mesh = sector(&Axis::Z, 0.0, 45.0, [2, 3, 1]);
    assert_eq!(
        periodic::resolve(&mesh, &Axis::Z, PeriodicRequest::Off).unwrap(),
        None
    );
    let auto = periodic::resolve(&mesh, &Axis::Z, PeriodicRequest::Auto).unwrap();
    assert_eq!(auto.map(|p| p.copies), Some(8));
}

#[test]
fn info_reports_the_periodicity() {
    let json = |name: &str| -> serde_json::Value {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_cylvol"))
            .args(["info", common::data(name).to_str().unwrap(), "--json"])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let mixer = json("mixer.vtk");
    assert_eq!(mixer["periodic"]["copies"], 4);
    assert!((mixer["periodic"]["span_deg"].as_f64().unwrap() - 90.0).abs() < 1e-6);
    let post = json("postxyz.bin");
    assert!(post["periodic"]["copies"].is_null());
    assert!(post["periodic"]["reason"]
        .as_str()
        .unwrap()
        .contains("full ring"));
}
