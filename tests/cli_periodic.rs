//! The periodic options on the command line: `render`, `bench` and `stats` with
//! `--periodic auto|N` and `--copies K0:K1` on the mixer's 90° sector (what they draw and
//! report), and the refusals a user meets, each saying why.

mod common;

use std::process::{Command, Output};

use serde_json::Value;

fn cylvol(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cylvol"))
        .args(args)
        .output()
        .expect("cylvol runs")
}

fn json_of(args: &[&str]) -> (Value, String) {
    let out = cylvol(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "cylvol {args:?} failed: {stderr}");
    let json = serde_json::from_slice(&out.stdout).expect("standard output is JSON alone");
    (json, stderr)
}

fn refusal(args: &[&str]) -> String {
    let out = cylvol(args);
    assert!(!out.status.success(), "cylvol {args:?} should fail");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn render_draws_the_wheel_and_its_copies() {
    let mixer = common::data("mixer.vtk");
    let mixer = mixer.to_str().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("wheel.png");
    let png = png.to_str().unwrap();
    let base = ["render", mixer, "-o", png, "--size", "40x40", "--json"];
    let run = |extra: &[&str]| json_of(&[&base[..], extra].concat());
    let (sector, _) = run(&[]);
    let (wheel, said) = run(&["--periodic", "auto"]);
    let (three, _) = run(&["--periodic", "4", "--copies", "0:3"]);
    assert!(sector["periodic"].is_null());
    let p = &wheel["periodic"];
    assert_eq!(
        (p["copies"].as_u64(), p["first"].as_u64(), p["end"].as_u64()),
        (Some(4), Some(0), Some(4))
    );
    assert!((p["span_deg"].as_f64().unwrap() - 90.0).abs() < 0.1);
    assert!(p["matched_faces"].as_u64().unwrap() > 0);
    assert!(said.contains("periodic: 4 copies"), "{said}");
    // The wheel's box holds the sector turned about z: x from about -0.1.
    assert!(p["bounds"][0].as_f64().unwrap() < -0.09, "{}", p["bounds"]);
    assert_eq!(three["periodic"]["end"].as_u64(), Some(3));
    // The wheel framed in the image takes more samples than its three quarters.
    let samples = |v: &Value| v["stats"]["samples"].as_u64().unwrap();
    assert!(samples(&wheel) > samples(&three) && samples(&three) > 0);
}

#[test]
fn bench_and_stats_say_the_copies_and_the_structures_do_not_grow() {
    let mixer = common::data("mixer.vtk");
    let mixer = mixer.to_str().unwrap();
    let stats = |extra: &[&str]| {
        json_of(&[&["stats", mixer, "--json", "--lookups", "0"][..], extra].concat()).0
    };
    let (alone, wheel) = (stats(&[]), stats(&["--periodic", "auto"]));
    assert!(alone["periodic"].is_null());
    assert_eq!(wheel["periodic"]["copies"].as_u64(), Some(4));
    for s in ["cart-grid", "cyl-grid", "cart-bvh", "cyl-bvh"] {
        assert_eq!(
            wheel["structures"][s]["bytes"], alone["structures"][s]["bytes"],
            "{s}: the structure serves every copy"
        );
    }
    let (bench, _) = json_of(&[
        "bench",
        mixer,
        "--json",
        "--size",
        "24",
        "--frames",
        "1",
        "--periodic",
        "auto",
        "--copies",
        "1:3",
    ]);
    let p = &bench[0]["periodic"];
    assert_eq!((p["first"].as_u64(), p["end"].as_u64()), (Some(1), Some(3)));
    // The accuracy of the wheel drawn from the sector, against its own converged reference.
    let (accuracy, _) = json_of(&[
        "accuracy",
        mixer,
        "--json",
        "--size",
        "24",
        "--periodic",
        "auto",
        "--max-error",
        "2",
        "--repeats",
        "1",
    ]);
    assert_eq!(accuracy["periodic"]["copies"].as_u64(), Some(4));
    let run = &accuracy["settings"][0];
    assert!(run["error"]["max"].as_f64().unwrap() <= 2.0, "{run}");
}

#[test]
fn what_cannot_be_drawn_is_refused_with_the_reason() {
    let mixer = common::data("mixer.vtk");
    let mixer = mixer.to_str().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("x.png");
    let png = png.to_str().unwrap();
    let base = ["render", mixer, "-o", png, "--size", "16x16"];
    for (extra, said) in [
        (&["--copies", "0:2"][..], "--copies needs --periodic"),
        (
            &["--periodic", "4", "--copies", "2:6"][..],
            "not a range of the wheel's 4 copies",
        ),
        (&["--periodic", "4", "--copies", "3:1"][..], "K0 < K1"),
        (
            &["--periodic", "7"][..],
            "the sector's span must be 360° / 7",
        ),
        (&["--periodic", "sometimes"][..], "auto"),
    ] {
        let err = refusal(&[&base[..], extra].concat());
        assert!(err.contains(said), "{extra:?}: {err}");
        assert!(
            !std::path::Path::new(png).exists(),
            "{extra:?} wrote an image"
        );
    }
    // A full ring is no sector: the cube about its own axis.
    let cube = common::data("hexa.vtk");
    let err = refusal(&[
        "render",
        cube.to_str().unwrap(),
        "-o",
        png,
        "--periodic",
        "auto",
    ]);
    assert!(err.contains("periodic") || err.contains("sector"), "{err}");
}
