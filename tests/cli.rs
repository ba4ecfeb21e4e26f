//! The `cylvol` program as other tools use it: `info` and `gen` on real files and synthetic
//! datasets, JSON alone on standard output, errors on standard error with a non-zero exit.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn cylvol(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cylvol"))
        .args(args)
        .output()
        .expect("cylvol runs")
}

/// Runs `cylvol info INPUT --json` and parses standard output, which must be JSON alone.
fn info(input: &str) -> Value {
    let out = cylvol(&["info", input, "--json"]);
    assert!(
        out.status.success(),
        "cylvol info {input} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("standard output is JSON alone")
}

fn angle_to_deg(v: &Value, axis: [f64; 3]) -> f64 {
    let d: Vec<f64> = v["axis"]["direction"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let dot: f64 = d.iter().zip(axis).map(|(a, b)| a * b).sum();
    let norm = d.iter().map(|x| x * x).sum::<f64>().sqrt();
    (dot.abs() / norm).min(1.0).acos().to_degrees()
}

#[test]
fn info_on_the_mixer_gives_counts_scalars_and_axis() {
    let v = info(data("mixer.vtk").to_str().unwrap());
    assert_eq!(v["points"], 37_843);
    assert_eq!(v["cells"], 33_600);
    assert_eq!(v["cell_types"]["hexahedron"], 33_600);
    assert_eq!(v["cell_types"]["wedge"], 0);
    // The default is the first point array whose range is not constant: `k` in file order.
    assert_eq!(v["active_scalar"], "k");
    let out = cylvol(&[
        "info",
        data("mixer.vtk").to_str().unwrap(),
        "--json",
        "--scalar",
        "p",
    ]);
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["active_scalar"], "p");
    let range = v["scalar_range"].as_array().unwrap();
    assert!(
        (range[0].as_f64().unwrap() + 44.25).abs() < 0.01,
        "{range:?}"
    );
    assert!(
        (range[1].as_f64().unwrap() - 74.65).abs() < 0.01,
        "{range:?}"
    );
    let names: Vec<&str> = v["scalars"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect();
    for n in ["p", "k", "omega", "nut", "U", "Urel"] {
        assert!(names.contains(&n), "{n} missing from {names:?}");
    }
    assert_eq!(v["bounds"].as_array().unwrap().len(), 6);
    assert!(angle_to_deg(&v, [0.0, 0.0, 1.0]) < 1.0);
}

#[test]
fn info_on_the_plot3d_files_finds_the_q_file_and_axis() {
    let post = info(data("postxyz.bin").to_str().unwrap());
    assert_eq!(post["cells"], 102_675);
    assert!(post["scalars"]
        .as_array()
        .unwrap()
        .iter()
        .any(|s| s == "StagnationEnergy"));
    assert!(angle_to_deg(&post, [0.0, 0.0, 1.0]) < 1.0);
    let comb = info(data("combxyz.bin").to_str().unwrap());
    assert_eq!(comb["cells"], 43_008);
    assert!(angle_to_deg(&comb, [1.0, 0.0, 0.0]) < 1.0);
    let cube = info(data("hexa.vtk").to_str().unwrap());
    assert_eq!(cube["cells"], 10_648);
}

#[test]
fn scalar_option_selects_an_array_and_rejects_unknown_names() {
    let out = cylvol(&[
        "info",
        data("mixer.vtk").to_str().unwrap(),
        "--json",
        "--scalar",
        "cell:k",
    ]);
    assert!(out.status.success());
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    // The mixer has a point array k too, which a bare `k` would select.
    assert_eq!(v["active_scalar"], "cell:k");
    assert_eq!(v["active_association"], "cell");
    let out = cylvol(&[
        "info",
        data("mixer.vtk").to_str().unwrap(),
        "--scalar",
        "nope",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no scalar array named 'nope'"));
}

/// `active_scalar` is what was selected, as `--scalar` takes it (a component `U[2]`, a cell
/// array whose name a point array shares `cell:p`), so that it selects the same scalar when
/// given back; the error for an unknown name lists the arrays the same way, each once.
#[test]
fn the_active_scalar_and_the_arrays_are_named_as_scalar_takes_them() {
    let mixer = data("mixer.vtk");
    let mixer = mixer.to_str().unwrap();
    let selected = |scalar: &str| -> Value {
        let out = cylvol(&["info", mixer, "--json", "--scalar", scalar]);
        assert!(
            out.status.success(),
            "{scalar}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    for (given, reported, association) in [
        ("U[2]", "U[2]", "point"),
        ("point:U[0]", "U[0]", "point"),
        ("U", "U", "point"),
        ("cell:U[1]", "cell:U[1]", "cell"),
        ("cell:p", "cell:p", "cell"),
        ("p", "p", "point"),
    ] {
        let v = selected(given);
        assert_eq!(v["active_scalar"], reported, "{given}");
        assert_eq!(v["active_association"], association, "{given}");
        // Given back, it selects the same scalar.
        let again = selected(reported);
        assert_eq!(again["active_scalar"], reported, "{given}");
        assert_eq!(again["scalar_range"], v["scalar_range"], "{given}");
        assert_eq!(again["active_association"], association, "{given}");
    }
    let text = cylvol(&["info", mixer, "--scalar", "cell:U[1]"]);
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.contains("active scalar  cell:U[1] (cell) range ["),
        "{text}"
    );
    let out = cylvol(&["info", mixer, "--scalar", "nope"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(
            "no scalar array named 'nope' (the mesh has: point:k, point:nut, point:omega, \
             point:p, point:U, point:Urel, cell:k, cell:nut, cell:omega, cell:p, cell:U, \
             cell:Urel)"
        ),
        "{err}"
    );
}

#[test]
fn gen_writes_files_that_read_back_with_the_same_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let direct = info("pump-rotor:20000");
    let n = direct["cells"].as_u64().unwrap();
    assert!(
        (19_000..=21_000).contains(&n),
        "{n} cells for a request of 20000"
    );
    for ext in ["vtu", "vtk"] {
        let path = dir.path().join(format!("rotor.{ext}"));
        let out = cylvol(&["gen", "pump-rotor:20000", "-o", path.to_str().unwrap()]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(
            out.stdout.is_empty(),
            "gen prints nothing on standard output"
        );
        let back = info(path.to_str().unwrap());
        for key in [
            "points",
            "cells",
            "cell_types",
            "scalars",
            "active_scalar",
            "scalar_range",
            "bounds",
        ] {
            assert_eq!(
                back[key], direct[key],
                "{key} differs after a .{ext} round trip"
            );
        }
    }
}

#[test]
fn gen_refines_a_mesh_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mixer2.vtu");
    let mixer = data("mixer.vtk");
    let out = cylvol(&[
        "gen",
        mixer.to_str().unwrap(),
        "--refine",
        "2",
        "-o",
        path.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (coarse, fine) = (info(mixer.to_str().unwrap()), info(path.to_str().unwrap()));
    assert_eq!(fine["cells"], 8 * coarse["cells"].as_u64().unwrap());
    assert_eq!(fine["cell_types"]["hexahedron"], fine["cells"]);
    // The original points are kept and the new ones blend them: the same range and box.
    for key in ["scalars", "active_scalar", "scalar_range"] {
        assert_eq!(fine[key], coarse[key], "{key}");
    }
    for (a, b) in fine["bounds"]
        .as_array()
        .unwrap()
        .iter()
        .zip(coarse["bounds"].as_array().unwrap())
    {
        let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{a} vs {b}");
    }
    let bad = cylvol(&["gen", "pump-rotor:2000", "--refine", "0", "-o", "x.vtu"]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("refinement '0' must be a whole number from 1 to 16"),
        "{err}"
    );
    assert!(
        !err.contains("generated"),
        "generated before refusing: {err}"
    );
}

#[test]
fn errors_go_to_standard_error_with_a_non_zero_exit() {
    let cases: [(&[&str], &str); 4] = [
        (&["info", "no/such/file.vtk"], "no such file"),
        (&["info", "mesh.unknown"], "no such file"),
        (
            &["gen", "pump-nothing:10", "-o", "x.vtu"],
            "not a dataset name",
        ),
        (&["gen", "pump-rotor:10", "-o", "x.txt"], ""),
    ];
    for (args, expected) in cases {
        let out = cylvol(args);
        assert!(!out.status.success(), "{args:?} should fail");
        assert!(out.stdout.is_empty(), "{args:?} printed on standard output");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("error"), "{args:?}: {err}");
        assert!(err.contains(expected), "{args:?}: {err}");
    }
}

/// Standard output that cannot be written is an error, not a panic: a full device is
/// reported on standard error; a reader that closed the pipe ends the program quietly with
/// the status a shell gives a program SIGPIPE ended (141).
#[cfg(unix)]
#[test]
fn standard_output_that_cannot_be_written_is_not_a_panic() {
    let full = Command::new(env!("CARGO_BIN_EXE_cylvol"))
        .args(["info", "pump-rotor:20000", "--json"])
        .stdout(std::fs::File::create("/dev/full").unwrap())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&full.stderr);
    assert_eq!(full.status.code(), Some(1), "{err}");
    assert!(err.contains("error: standard output"), "{err}");
    assert!(!err.contains("panicked"), "{err}");

    for args in [
        &["info", "pump-rotor:20000", "--json"][..],
        &["stats", "pump-rotor:20000", "--json"][..],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_cylvol"))
            .args(args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take()); // the reader goes before anything is written
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(141), "{args:?}: {err}");
        assert!(
            !err.contains("panicked") && !err.contains("error"),
            "{args:?}: {err}"
        );
    }
}

/// `gen` to a file it cannot write (another extension) says so before generating anything
/// and leaves an existing file as it was.
#[test]
fn gen_to_another_extension_leaves_the_file_alone() {
    let dir = tempfile::tempdir().unwrap();
    let notes = dir.path().join("notes.txt");
    std::fs::write(&notes, "keep me").unwrap();
    let out = cylvol(&["gen", "pump-rotor:20000", "-o", notes.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("can only write .vtk or .vtu"), "{err}");
    assert!(
        !err.contains("generated"),
        "generated before refusing: {err}"
    );
    assert_eq!(std::fs::read_to_string(&notes).unwrap(), "keep me");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

/// `gen` to a folder that does not exist, or that takes no file, says so before generating
/// anything (it said so only once the mesh was made).
#[test]
fn gen_to_a_folder_it_cannot_write_says_so_first() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing/x.vtu");
    let mut cases = vec![(
        missing.to_str().unwrap().to_string(),
        format!(
            "-o {}: the folder {} does not exist",
            missing.display(),
            dir.path().join("missing").display()
        ),
    )];
    if cfg!(target_os = "linux") {
        cases.push((
            "/proc/x.vtu".into(),
            "-o /proc/x.vtu: cannot write in /proc".into(),
        ));
    }
    for (output, message) in cases {
        let out = cylvol(&["gen", "pump-rotor:20000", "-o", &output]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(err.contains(&message), "{err}");
        assert!(
            !err.contains("generated"),
            "generated before refusing: {err}"
        );
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn a_truncated_file_is_reported_with_its_name_and_where() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = std::fs::read(data("mixer.vtk")).unwrap();
    let path = dir.path().join("cut.vtk");
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let out = cylvol(&["info", path.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("cut.vtk") && err.contains("byte"), "{err}");
}

#[test]
fn stats_reports_the_four_structures_with_ratios() {
    let out = cylvol(&["stats", "pump-rotor:20000", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON alone on standard output");
    assert_eq!(v["dataset"], "pump-rotor");
    let cells = v["cells"].as_u64().unwrap();
    for grid in ["cart-grid", "cyl-grid"] {
        let g = &v["structures"][grid];
        for key in ["grid_cells", "references", "bytes", "build_s"] {
            assert!(g[key].as_f64().unwrap() > 0.0, "{grid}.{key}");
        }
        assert!(
            g["references"].as_u64().unwrap() >= cells,
            "every cell is referenced"
        );
    }
    for bvh in ["cart-bvh", "cyl-bvh"] {
        let b = &v["structures"][bvh];
        for key in [
            "nodes",
            "leaves",
            "references",
            "bytes",
            "surface_area",
            "build_s",
        ] {
            assert!(b[key].as_f64().unwrap() > 0.0, "{bvh}.{key}");
        }
        assert_eq!(
            b["nodes"].as_u64().unwrap(),
            2 * b["leaves"].as_u64().unwrap() - 1
        );
        assert!(b["references"].as_u64().unwrap() >= cells);
    }
    let area = |k: &str| v["structures"][k]["surface_area"].as_f64().unwrap();
    let ratio = v["ratios"]["bvh"]["surface_area"].as_f64().unwrap();
    assert!((ratio - area("cyl-bvh") / area("cart-bvh")).abs() < 1e-12);
    // Sectors hug the rotor's curved cells better than boxes.
    assert!(ratio < 1.0, "cyl ÷ cart BVH area {ratio}");
}

#[test]
fn stats_measures_lookups_and_takes_presets() {
    let out = cylvol(&[
        "stats",
        "pump-inlet:8000",
        "--json",
        "--lookups",
        "2000",
        "--grid",
        "paper",
        "--bvh",
        "fine",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    for kind in ["cart-grid", "cyl-grid", "cart-bvh", "cyl-bvh"] {
        let s = &v["structures"][kind];
        assert_eq!(s["lookup"]["lookups"], 2000);
        // Every point lies inside a cell, so every lookup finds one, after at least one test.
        assert_eq!(s["lookup"]["found"], 2000, "{kind}");
        assert!(s["hex_tests"].as_f64().unwrap() >= 1.0, "{kind}");
        // All the candidates bound the tests, and those with the point in their box (the
        // holding cell's among them) bound nothing more.
        let [tests, all, in_box] = ["hex_tests", "candidates", "candidates_in_box"]
            .map(|k| s["lookup"][k].as_f64().unwrap());
        assert!(
            1.0 <= in_box && in_box <= all && tests <= all,
            "{kind}: {s}"
        );
        assert_eq!(s["candidates"], s["lookup"]["candidates"], "{kind}");
    }
    for family in ["grid", "bvh"] {
        for k in ["candidates", "candidates_in_box"] {
            assert!(
                v["ratios"][family][k].as_f64().unwrap() > 0.0,
                "{family} {k}"
            );
        }
    }
    let paper = v["structures"]["cart-grid"]["grid_cells"].as_f64().unwrap();
    let out = cylvol(&["stats", "pump-inlet:8000", "--json", "--lookups", "0"]);
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["structures"]["cart-grid"]["lookup"].is_null());
    assert!(
        paper > v["structures"]["cart-grid"]["grid_cells"].as_f64().unwrap(),
        "the paper preset is finer"
    );
    for bad in [["--grid", "nope"], ["--grid", "1,-2"], ["--bvh", "x"]] {
        let out = cylvol(&["stats", "pump-inlet:8000", bad[0], bad[1]]);
        assert!(!out.status.success());
        assert!(String::from_utf8_lossy(&out.stderr).contains(bad[0]));
    }
}

#[test]
fn demo_writes_the_mesh_and_the_comparison_with_the_talk() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("demo");
    let out = cylvol(&[
        "demo",
        "--out",
        out_dir.to_str().unwrap(),
        "--cells",
        "20000",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("BVH: surface area"), "{text}");
    let report: Value =
        serde_json::from_slice(&std::fs::read(out_dir.join("demo.json")).unwrap()).unwrap();
    let rows = report["comparison"].as_array().unwrap();
    assert_eq!(rows.len(), 7);
    assert!(rows
        .iter()
        .all(|r| r["talk"].as_f64().is_some() && r["cylvol"].as_f64().is_some()));
    let back = info(out_dir.join("pump-rotor.vtu").to_str().unwrap());
    assert_eq!(back["cells"], report["info"]["cells"]);
}
