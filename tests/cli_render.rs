//! The rendering commands as other tools use them: `cylvol bench` (every key for the four
//! structures × both paths, ratios that are the quotients), `cylvol accuracy` (error falling
//! as the step halves against a 1/32 reference, a well-formed plot), `cylvol demo` (its
//! images and plot), and clear errors with a non-zero exit.

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;

const STRUCTURES: [&str; 4] = ["cart-grid", "cyl-grid", "cart-bvh", "cyl-bvh"];
const PATH_KEYS: [&str; 5] = [
    "samples",
    "hex_tests",
    "internal_visits",
    "leaf_visits",
    "frame_s",
];

fn cylvol(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cylvol"))
        .args(args)
        .output()
        .expect("cylvol runs")
}

/// `render INPUT -o OUT --size SIZE`, then each group of `options` in order.
fn render_args<'a>(
    input: &'a str,
    out: &'a str,
    size: &'a str,
    options: &[&[&'a str]],
) -> Vec<&'a str> {
    let mut args = vec!["render", input, "-o", out, "--size", size];
    for group in options {
        args.extend_from_slice(group);
    }
    args
}

fn json_of(args: &[&str]) -> Value {
    let out = cylvol(args);
    assert!(
        out.status.success(),
        "cylvol {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("standard output is JSON alone")
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1e-300)
}

#[test]
fn bench_reports_every_structure_and_path_with_quotient_ratios() {
    let v = json_of(&[
        "bench",
        "pump-rotor:5000",
        "pump-inlet:3000",
        "--size",
        "40",
        // A fixed step: every structure and path takes the same sample positions.
        "--step",
        "0.05",
        "--json",
    ]);
    let reports = v.as_array().expect("an array, one object per input");
    assert_eq!(reports.len(), 2);
    assert_eq!(reports[0]["dataset"], "pump-rotor");
    assert_eq!(reports[1]["dataset"], "pump-inlet");
    for r in reports {
        assert_eq!(r["width"], 40);
        assert_eq!(r["height"], 40);
        assert!(r["cells"].as_u64().unwrap() > 1000);
        for s in STRUCTURES {
            let entry = &r["structures"][s];
            assert!(entry["build_s"].as_f64().unwrap() >= 0.0, "{s} build_s");
            for path in ["paper", "fast"] {
                for k in PATH_KEYS {
                    assert!(
                        entry[path][k].as_f64().is_some(),
                        "{}: {s} {path} lacks {k}",
                        r["dataset"]
                    );
                }
            }
            // The same rays and the same image: the same sample positions.
            assert_eq!(entry["paper"]["samples"], entry["fast"]["samples"], "{s}");
            assert!(entry["paper"]["samples"].as_u64().unwrap() > 0, "{s}");
            // The paper path locates every sample through the structure.
            assert!(entry["paper"]["hex_tests"].as_u64().unwrap() > 0, "{s}");
        }
        for (family, cart, cyl) in [
            ("grid", "cart-grid", "cyl-grid"),
            ("bvh", "cart-bvh", "cyl-bvh"),
        ] {
            for path in ["paper", "fast"] {
                for k in ["hex_tests", "internal_visits", "leaf_visits", "frame_s"] {
                    let a = r["structures"][cart][path][k].as_f64().unwrap();
                    let b = r["structures"][cyl][path][k].as_f64().unwrap();
                    let q = &r["ratios"][family][path][k];
                    if a > 0.0 {
                        assert!(
                            close(q.as_f64().unwrap(), b / a),
                            "{family} {path} {k}: {q} vs {b}/{a}"
                        );
                    } else {
                        assert!(q.is_null());
                    }
                }
            }
        }
    }
}

#[test]
fn bench_takes_the_fastest_of_several_frames_with_the_same_counters() {
    let once = json_of(&["bench", "pump-rotor:3000", "--size", "24", "--json"]);
    let thrice = json_of(&[
        "bench",
        "pump-rotor:3000",
        "--size",
        "24",
        "--frames",
        "3",
        "--json",
    ]);
    assert_eq!(once[0]["frames"], 1);
    assert_eq!(thrice[0]["frames"], 3);
    for s in STRUCTURES {
        for path in ["paper", "fast"] {
            for k in PATH_KEYS.iter().filter(|&&k| k != "frame_s") {
                assert_eq!(
                    once[0]["structures"][s][path][k], thrice[0]["structures"][s][path][k],
                    "{s} {path} {k}"
                );
            }
            assert!(thrice[0]["structures"][s][path]["frame_s"].as_f64() > Some(0.0));
        }
    }
    fails_with(&["bench", "pump-rotor:2000", "--frames", "0"], "frames");
}

#[test]
fn bench_prints_a_table_and_logs_progress() {
    let out = cylvol(&["bench", "pump-rotor:2000", "--size", "24"]);
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    for s in STRUCTURES {
        assert!(stdout.contains(s), "{s} missing from\n{stdout}");
    }
    assert!(stdout.contains("cyl ÷ cart grid paper"));
    assert!(String::from_utf8_lossy(&out.stderr).contains("paper path"));
}

/// Checks with Python's XML parser that the SVG is well-formed and returns the number of
/// point markers in each series; `None` where `/usr/bin/python3` cannot run.
fn svg_points_per_series(path: &Path) -> Option<Vec<usize>> {
    let script = r#"
import sys, xml.etree.ElementTree as ET
ns = '{http://www.w3.org/2000/svg}'
root = ET.parse(sys.argv[1]).getroot()
assert root.tag == ns + 'svg', root.tag
counts = [len([c for c in g.iter(ns + 'circle') if c.get('class') == 'point'])
          for g in root.iter(ns + 'g') if g.get('class') == 'series']
print(' '.join(map(str, counts)))
"#;
    let out = Command::new("/usr/bin/python3")
        .args(["-c", script])
        .arg(path)
        .output()
        .ok()?;
    assert!(
        out.status.success(),
        "{} is not well-formed SVG: {}",
        path.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    Some(
        String::from_utf8_lossy(&out.stdout)
            .split_whitespace()
            .map(|n| n.parse().unwrap())
            .collect(),
    )
}

#[test]
fn accuracy_error_falls_as_the_step_halves() {
    let dir = tempfile::tempdir().unwrap();
    let plot = dir.path().join("acc.svg");
    let v = json_of(&[
        "accuracy",
        "pump-rotor:5000",
        "--size",
        "48",
        "--json",
        "--plot",
        plot.to_str().unwrap(),
    ]);
    assert_eq!(v["dataset"], "pump-rotor");
    let runs = v["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 5);
    // The base is the mean cell size, twice the renderer's default step, computed here
    // independently of the command.
    let mesh = cylvol::datasets::generate(cylvol::datasets::Dataset::PumpRotor, 5000).unwrap();
    let base = 2.0 * cylvol::render::default_step(&mesh);
    assert!(close(v["mean_cell_size"].as_f64().unwrap(), base));
    assert!(close(v["reference"]["step"].as_f64().unwrap(), base / 32.0));
    for (run, factor) in runs.iter().zip([2.0, 1.0, 0.5, 0.25, 0.125]) {
        assert!(close(run["step"].as_f64().unwrap(), base * factor));
        let (rmse, max) = (
            run["rmse"].as_f64().unwrap(),
            run["max_err"].as_f64().unwrap(),
        );
        assert!(rmse > 0.0 && rmse <= max && max <= 1.0, "{run}");
        assert!(run["time_s"].as_f64().unwrap() >= 0.0);
    }
    for w in runs.windows(2) {
        let (a, b) = (
            w[0]["rmse"].as_f64().unwrap(),
            w[1]["rmse"].as_f64().unwrap(),
        );
        assert!(b < a, "rmse did not fall from {a} to {b}: {v}");
    }
    let order = v["order"].as_array().unwrap();
    assert_eq!(order.len(), 4);
    for (k, o) in order.iter().enumerate() {
        let expect =
            (runs[k]["rmse"].as_f64().unwrap() / runs[k + 1]["rmse"].as_f64().unwrap()).log2();
        assert!(close(o.as_f64().unwrap(), expect));
    }
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(svg.contains("<svg"));
    if let Some(counts) = svg_points_per_series(&plot) {
        assert_eq!(
            counts,
            vec![runs.len(); 2],
            "rmse and max error, a point per run"
        );
    } else {
        eprintln!("note: /usr/bin/python3 unavailable, SVG not parsed");
    }
}

fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    assert!(bytes.len() > 33, "{} too short", path.display());
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{}", path.display());
    assert_eq!(&bytes[12..16], b"IHDR");
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    (be(&bytes[16..20]), be(&bytes[20..24]))
}

#[test]
fn demo_writes_an_image_per_structure_and_the_accuracy_plot() {
    let dir = tempfile::tempdir().unwrap();
    let out = cylvol(&[
        "demo",
        "--out",
        dir.path().to_str().unwrap(),
        "--cells",
        "4000",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for s in STRUCTURES {
        let (w, h) = png_size(&dir.path().join(format!("{s}.png")));
        assert_eq!((w, h), (256, 256), "{s}");
    }
    let plot = dir.path().join("accuracy.svg");
    if let Some(counts) = svg_points_per_series(&plot) {
        assert_eq!(counts, vec![5, 5]);
    }
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("demo.json")).unwrap())
            .unwrap();
    assert_eq!(report["frame_comparison"].as_array().unwrap().len(), 5);
    assert!(report["bench"]["structures"]["cyl-bvh"]["fast"]["samples"].as_u64() > Some(0));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("frames per second"), "{stdout}");
}

fn fails_with(args: &[&str], message: &str) {
    let out = cylvol(args);
    assert!(!out.status.success(), "cylvol {args:?} succeeded");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(message),
        "cylvol {args:?}: '{message}' not in {stderr}"
    );
    assert!(
        out.stdout.is_empty(),
        "nothing on standard output on failure"
    );
}

#[test]
fn bad_arguments_fail_with_a_message() {
    fails_with(
        &["accuracy", "pump-rotor:2000", "--structure", "kd-tree"],
        "unknown structure 'kd-tree'",
    );
    fails_with(&["bench", "pump-rotor:2000", "--size", "0"], "size '0'");
    fails_with(&["bench", "pump-rotor:2000", "--size", "big"], "size 'big'");
    fails_with(&["accuracy", "pump-rotor:2000", "--size=-4"], "size '-4'");
    fails_with(
        &[
            "bench",
            "pump-rotor:2000",
            "/nonexistent/mesh.vtk",
            "--json",
        ],
        "no such file",
    );
    fails_with(&["accuracy", "/nonexistent/mesh.vtu"], "no such file");
    fails_with(&["bench"], "INPUT");
}

/// `fails_with`, and the refusal comes before the input is loaded.
fn fails_early_with(args: &[&str], message: &str) {
    fails_with(args, message);
    let stderr = String::from_utf8_lossy(&cylvol(args).stderr).into_owned();
    assert!(
        !stderr.contains("loaded"),
        "cylvol {args:?} loaded the input first: {stderr}"
    );
}

/// A negative number given to a numeric option, space-separated, reaches the option's own
/// check and its message (clap took `-1` for a flag: "unexpected argument '-1'"), before the
/// input is loaded; a list that starts with a minus is taken when it is valid.
#[test]
fn negative_numbers_reach_each_options_own_check() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("never.png");
    let png = png.to_str().unwrap();
    let input = "pump-rotor:2000";
    let render = |extra: &[&'static str]| {
        let mut args = vec!["render", input, "-o", png];
        if !extra.contains(&"--size") {
            args.extend_from_slice(&["--size", "8x8"]);
        }
        args.extend_from_slice(extra);
        args
    };
    for (extra, message) in [
        (
            &["--step", "-1"][..],
            "step '-1' must be positive and finite",
        ),
        (
            &["--step", "-inf"],
            "step '-inf' must be positive and finite",
        ),
        (&["--size", "-4x4"], "size '-4x4' must be WxH"),
        (&["--view", "-30,20,-1"], "view '-30,20,-1' must be"),
        (&["--view-angle", "-5"], "view angle '-5' must be"),
        (
            &["--parallel", "--parallel-scale", "-2"],
            "parallel scale '-2' must be",
        ),
        (
            &["--depth", "d.vti", "--depth-opacity", "-0.5"],
            "depth opacity '-0.5' must be",
        ),
        (&["--march-reach", "-1"], "march reach '-1' is not"),
        (
            &["--gradient-opacity", "-1:-0.5"],
            "opacity factors must lie in [0, 1]",
        ),
        (&["--clip-plane", "-1,0,0:-0,0,0"], "zero normal"),
        (&["--opacity", "-5%:-0.1"], "'-0.1' in '-5%:-0.1'"),
        (
            &["--axis", "-1,0,0:0,0,0"],
            "invalid axis '-1,0,0:0,0,0': the direction has zero length",
        ),
    ] {
        let args = render(extra);
        let out = cylvol(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            !stderr.contains("unexpected argument"),
            "{args:?}: {stderr}"
        );
        fails_early_with(&args, message);
    }
    for (args, message) in [
        (
            &["bench", input, "--frames", "-1"][..],
            "frames '-1' must be a whole number from 1 to 100",
        ),
        (
            &["bench", input, "--step", "-0.5"],
            "step '-0.5' must be positive and finite",
        ),
        (&["bench", input, "--size", "-8"], "size '-8'"),
        (&["accuracy", input, "--size", "-4"], "size '-4'"),
        (
            &["stats", input, "--lookups", "-5"],
            "lookups '-5' must be a whole number, 0 or more",
        ),
        (
            &["stats", input, "--grid", "-1,2"],
            "--grid '-1,2': the densities TOP,LEAF must be positive and finite",
        ),
        (
            &["gen", input, "-o", "x.vtu", "--refine", "-1"],
            "refinement '-1' must be a whole number from 1 to 16",
        ),
        (
            &["demo", "--out", png, "--cells", "-5"],
            "cells '-5' must be a whole number from 1000 to 200000000",
        ),
    ] {
        fails_early_with(args, message);
    }
    assert!(!Path::new(png).exists(), "demo made its folder");
    // Valid values that start with a minus are taken.
    let ok = render(&[
        "--view",
        "-30,20,1",
        "--clip-plane",
        "-1,-1,-1:1,0,0",
        "--opacity",
        "-1e9:0.1,1e9:0.2",
    ]);
    let out = cylvol(&ok);
    assert!(
        out.status.success(),
        "{ok:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let camera = cylvol(&render(&["--camera", "-1,-2,-3:0,0,0:0,1,0"]));
    assert!(
        camera.status.success(),
        "{}",
        String::from_utf8_lossy(&camera.stderr)
    );
    let info = json_of(&["info", input, "--json", "--axis", "-1,0,0:0,0,-1"]);
    assert_eq!(info["axis"]["origin"], serde_json::json!([-1.0, 0.0, 0.0]));
    // The direction is reported with its sign made canonical: the line is the same.
    let direction: Vec<f64> = info["axis"]["direction"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap().abs())
        .collect();
    assert_eq!(direction, [0.0, 0.0, 1.0]);
}

/// Numbers in errors read as the user wrote them, or as short as they read back (`1e-300`),
/// never as the hundreds of digits Rust's `{}` writes for them; what they say is in the
/// option's terms.
#[test]
fn numbers_in_errors_are_readable() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("never.png");
    let png = png.to_str().unwrap();
    for (extra, message) in [
        (
            &["--step", "1e-300"][..],
            "--step 1e-300 is too small for this mesh: a ray across its diagonal",
        ),
        (
            &["--unit-distance=-1e-300"],
            "--unit-distance must be positive and finite, not -1e-300",
        ),
        (
            &["--opacity", "1e-300:0,-1e-300:1"],
            "point 2 (scalar -1e-300) is below the point before it (1e-300)",
        ),
        (
            &["--color", "1e300:0:0:0,-2.5e-200:1:1:1"],
            "point 2 (scalar -2.5e-200) is below the point before it (1e300)",
        ),
        (
            &["--clip-plane", "1e200,0,0:1e200,0,0"],
            "clip plane '1e200,0,0:1e200,0,0': its point and normal are too large",
        ),
    ] {
        let mut args = vec!["render", "pump-rotor:2000", "-o", png, "--size", "8x8"];
        args.extend_from_slice(extra);
        fails_with(&args, message);
        let stderr = String::from_utf8_lossy(&cylvol(&args).stderr).into_owned();
        assert!(
            !stderr.contains("0000000000"),
            "{args:?}: a long number in {stderr}"
        );
    }
}

/// `--structure` names `auto` among what it takes, and it, `--path`, `--interpolation` and
/// `--blend` are refused before the input is loaded.
#[test]
fn named_choices_are_refused_early_with_what_is_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("never.png");
    let png = png.to_str().unwrap();
    let input = "pump-rotor:2000";
    for (args, message) in [
        (
            &["render", input, "-o", png, "--structure", "foo"][..],
            "unknown structure 'foo' (expected cart-grid, cyl-grid, cart-bvh, cyl-bvh or auto)",
        ),
        (
            &["accuracy", input, "--structure", "kd-tree"],
            "unknown structure 'kd-tree' (expected cart-grid, cyl-grid, cart-bvh, cyl-bvh or auto)",
        ),
        (
            &["render", input, "-o", png, "--path", "slow"],
            "unknown path 'slow' (expected paper or fast)",
        ),
        (
            &["accuracy", input, "--path", "slow"],
            "unknown path 'slow' (expected paper or fast)",
        ),
        (
            &["render", input, "-o", png, "--interpolation", "cubic"],
            "unknown interpolation 'cubic'",
        ),
        (
            &["render", input, "-o", png, "--blend", "average"],
            "unknown blend mode 'average'",
        ),
    ] {
        fails_early_with(args, message);
    }
    // And every name is taken.
    for structure in STRUCTURES.iter().chain(&["auto"]) {
        let out = cylvol(&render_args(
            input,
            png,
            "8x8",
            &[&["--structure", structure]],
        ));
        assert!(
            out.status.success(),
            "{structure}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// `--shade` and `--gradient-opacity` with a cell scalar (constant in each cell: no gradient)
/// or with a projection (`--blend max`/`min`) change nothing useful, and the command says so
/// on standard error; with a point scalar and compositing it says nothing.
#[test]
fn effects_that_cannot_apply_are_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("x.png");
    let png = png.to_str().unwrap();
    let mixer = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/mixer.vtk");
    let mixer = mixer.to_str().unwrap();
    let warnings = |extra: &[&str]| -> Vec<String> {
        let args = render_args(mixer, png, "8x8", &[extra]);
        let out = cylvol(&args);
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "{args:?}: {stderr}");
        stderr
            .lines()
            .filter(|l| l.starts_with("cylvol: warning:"))
            .map(str::to_string)
            .collect()
    };
    let shade = warnings(&["--scalar", "cell:k", "--shade"]);
    assert_eq!(shade.len(), 1, "{shade:?}");
    assert!(
        shade[0].starts_with(
            "cylvol: warning: --shade: the scalar cell:k is a cell array, constant in each \
             cell, so it has no gradient"
        ),
        "{shade:?}"
    );
    let hidden = warnings(&["--scalar", "cell:k", "--gradient-opacity", "0:0,1:1"]);
    assert_eq!(hidden.len(), 1, "{hidden:?}");
    assert!(
        hidden[0].starts_with("cylvol: warning: --gradient-opacity: the scalar cell:k")
            && hidden[0].contains("the factor of a zero gradient, 0, so nothing is visible"),
        "{hidden:?}"
    );
    let scaled = warnings(&[
        "--scalar",
        "cell:k",
        "--shade",
        "--gradient-opacity",
        "0:0.25,1:1",
    ]);
    assert_eq!(scaled.len(), 2, "{scaled:?}");
    assert!(
        scaled[1].contains("every opacity is scaled by 0.25"),
        "{scaled:?}"
    );
    let projection = warnings(&["--blend", "max", "--shade"]);
    assert_eq!(projection.len(), 1, "{projection:?}");
    assert!(
        projection[0].contains(
            "--blend max takes the extreme scalar's colour and opacity as they are: --shade is \
             ignored"
        ),
        "{projection:?}"
    );
    for quiet in [
        &["--scalar", "p", "--shade", "--gradient-opacity", "0:0,1:1"][..],
        &["--scalar", "cell:k"],
        &["--blend", "min"],
    ] {
        assert_eq!(warnings(quiet), Vec::<String>::new(), "{quiet:?}");
    }
}

/// Every output is checked before any work: its extension (`-o` takes `.png` only, in any
/// case), and its folder (it exists and takes a file); a refused command creates nothing and
/// leaves an existing file as it was, and a successful one leaves no partial file behind.
#[test]
fn outputs_are_checked_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let kept = d.join("kept.png");
    std::fs::write(&kept, "keep me").unwrap();
    let kept = kept.to_str().unwrap();
    let path = |name: &str| d.join(name).to_str().unwrap().to_string();
    let (jpg, missing_png, missing_vti, missing_svg, depth_png) = (
        path("out.jpg"),
        path("missing/out.png"),
        path("missing/d.vti"),
        path("missing/p.svg"),
        path("d.png"),
    );
    let input = "pump-rotor:2000";
    let folder = d.join("missing");
    let folder = folder.display();
    for (args, message) in [
        (
            &["render", input, "-o", &jpg][..],
            format!("-o {jpg}: writes a PNG image, so the name must end in .png"),
        ),
        (
            &["render", input, "-o", &missing_png],
            format!("-o {missing_png}: the folder {folder} does not exist"),
        ),
        (
            &["render", input, "-o", kept, "--depth", &missing_vti],
            format!("--depth {missing_vti}: the folder {folder} does not exist"),
        ),
        (
            &["render", input, "-o", kept, "--depth", &depth_png],
            format!("--depth {depth_png}: writes VTK image data, so the name must end in .vti"),
        ),
        (
            &["render", input, "-o", d.to_str().unwrap()],
            "writes a PNG image".to_string(),
        ),
        (
            &["accuracy", input, "--plot", &missing_svg],
            format!("--plot {missing_svg}: the folder {folder} does not exist"),
        ),
        (
            &["accuracy", input, "--plot", kept],
            format!("--plot {kept}: writes an SVG plot, so the name must end in .svg"),
        ),
        (
            &["demo", "--out", kept, "--cells", "2000"],
            format!("--out {kept}: is a file; give a folder"),
        ),
    ] {
        fails_early_with(args, &message);
        let stderr = String::from_utf8_lossy(&cylvol(args).stderr).into_owned();
        assert!(
            !stderr.contains("generated"),
            "{args:?} worked first: {stderr}"
        );
    }
    #[cfg(target_os = "linux")]
    fails_early_with(
        &["render", input, "-o", "/proc/x.png"],
        "-o /proc/x.png: cannot write in /proc",
    );
    assert_eq!(std::fs::read_to_string(kept).unwrap(), "keep me");
    let names = |d: &Path| -> Vec<String> {
        let mut n: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        n.sort();
        n
    };
    assert_eq!(names(d), ["kept.png"]);
    // Upper case is fine; the image replaces what was there, with nothing left beside it.
    let upper = path("OUT.PNG");
    std::fs::write(&upper, "old").unwrap();
    let out = cylvol(&render_args(
        input,
        &upper,
        "8x8",
        &[&["--depth", &path("d.VTI")]],
    ));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(png_size(Path::new(&upper)), (8, 8));
    assert_eq!(names(d), ["OUT.PNG", "d.VTI", "kept.png"]);
}

/// The price of boundary segments is visible: with them (the default) samples next to a
/// boundary crossing are cut at the crossing, found exactly through the boundary surface
/// (`surface_visits`) and, where that cannot tell, by containment tests
/// (`boundary_refinements`, counted in `hex_tests` too); with `--whole-steps` no crossing is
/// sought (no refinement, fewer surface visits) and the error at the default step is larger.
/// At a fixed step (whole steps are never error-bounded), so both take the same samples.
#[test]
fn boundary_segments_cost_tests_and_buy_accuracy() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("x.png");
    let png = png.to_str().unwrap();
    let render = |extra: &[&str]| {
        let fixed = ["--json", "--step", "0.05"];
        let args = render_args("pump-rotor:5000", png, "48x48", &[&fixed, extra]);
        json_of(&args)["stats"].clone()
    };
    let cut = render(&[]);
    let whole = render(&["--whole-steps"]);
    let count = |s: &Value, key: &str| s[key].as_u64().unwrap();
    assert_eq!(count(&whole, "boundary_refinements"), 0);
    assert_eq!(cut["samples"], whole["samples"]);
    assert!(count(&cut, "surface_visits") > count(&whole, "surface_visits"));
    assert_eq!(
        count(&cut, "hex_tests"),
        count(&whole, "hex_tests") + count(&cut, "boundary_refinements")
    );

    let rmse_at_half = |extra: &[&str]| {
        let mut args = vec!["accuracy", "pump-rotor:5000", "--size", "32", "--json"];
        args.extend_from_slice(extra);
        let v = json_of(&args);
        let runs = v["runs"].as_array().unwrap().clone();
        // Runs are at 2, 1, 1/2, 1/4, 1/8 × the mean cell size; the default step is 1/2 ×.
        runs[2]["rmse"].as_f64().unwrap()
    };
    let (cut_err, whole_err) = (rmse_at_half(&[]), rmse_at_half(&["--whole-steps"]));
    assert!(
        cut_err < whole_err,
        "boundary segments {cut_err} vs whole steps {whole_err}"
    );
}

#[test]
fn render_takes_interpolation_and_gradient_opacity_and_counts_gradients_only_for_them() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("r.png");
    let out = out.to_str().expect("utf-8 path");
    let gradients = |extra: &[&str]| {
        let args = render_args("pump-inlet:3000", out, "24x24", &[&["--json"], extra]);
        json_of(&args)["stats"]["gradient_evaluations"]
            .as_u64()
            .expect("a count")
    };
    assert_eq!(gradients(&[]), 0, "no shading, no gradient opacity");
    assert_eq!(gradients(&["--interpolation", "nearest"]), 0);
    assert!(gradients(&["--gradient-opacity", "0:0.2,1:1"]) > 0);
    for bad in [
        &["--interpolation", "cubic"][..],
        &["--gradient-opacity", "1:0,0:1"][..],
        &["--gradient-opacity", "0:2"][..],
        &["--gradient-opacity", "zero"][..],
    ] {
        let args = render_args("pump-inlet:3000", out, "8x8", &[bad]);
        let o = cylvol(&args);
        assert!(!o.status.success(), "{bad:?} accepted");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains("interpolation") || err.contains("gradient"),
            "{bad:?}: {err}"
        );
    }
}

/// `--blend max` and `min` render intensity projections: reported in the JSON, no gradient
/// even with `--shade`, no transparent cell skipped but cells that cannot beat the extreme
/// passed over, images unlike compositing's; an unknown mode is refused by name.
#[test]
fn render_takes_a_blend_mode() {
    let dir = tempfile::tempdir().expect("temp dir");
    let png = |name: &str| dir.path().join(name).to_str().expect("utf-8").to_string();
    let run = |out: &str, extra: &[&str]| {
        let args = render_args(
            "pump-inlet:3000",
            out,
            "24x24",
            &[
                &["--shade", "--opacity", "0%:0, 60%:0, 100%:1", "--json"],
                extra,
            ],
        );
        json_of(&args)
    };
    let composite = run(&png("c.png"), &[]);
    assert_eq!(composite["blend"], "composite");
    assert!(composite["stats"]["gradient_evaluations"].as_u64().unwrap() > 0);
    assert!(composite["stats"]["samples_skipped"].as_u64().unwrap() > 0);
    assert!(composite["stats"]["early_terminations"].as_u64().unwrap() > 0);
    for mode in ["max", "min"] {
        let j = run(&png(&format!("{mode}.png")), &["--blend", mode]);
        assert_eq!(j["blend"], mode);
        assert_eq!(j["stats"]["gradient_evaluations"], 0, "{mode}");
        assert_eq!(j["stats"]["samples_skipped"], 0, "{mode}");
        assert_eq!(j["stats"]["early_terminations"], 0, "{mode}");
        if mode == "max" {
            // Cells that cannot beat a ray's maximum so far are passed over, jumping to the
            // next that may through the BVH (counts compositing never makes; this view's
            // minima come last on their rays).
            assert!(j["stats"]["extreme_skips"].as_u64().unwrap() > 0);
            assert!(j["stats"]["extreme_jumps"].as_u64().unwrap() > 0);
        }
    }
    assert_eq!(composite["stats"]["extreme_skips"], 0);
    assert_eq!(composite["stats"]["extreme_jumps"], 0);
    let bytes = |name: &str| std::fs::read(dir.path().join(name)).expect("png written");
    assert_ne!(bytes("max.png"), bytes("c.png"));
    assert_ne!(bytes("max.png"), bytes("min.png"));
    let o = cylvol(&[
        "render",
        "pump-inlet:3000",
        "-o",
        &png("x.png"),
        "--blend",
        "average",
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("unknown blend mode 'average'"), "{err}");
}

#[test]
fn render_takes_a_transfer_function_like_vtk_and_skips_what_it_makes_transparent() {
    let dir = tempfile::tempdir().expect("temp dir");
    let png = |name: &str| dir.path().join(name).to_str().expect("utf-8").to_string();
    let render = |out: &str, extra: &[&str]| {
        let args = render_args(
            "pump-rotor:3000",
            out,
            "32x32",
            &[
                &["--structure", "cyl-bvh", "--view", "30, 20, 2", "--json"],
                extra,
            ],
        );
        json_of(&args)["stats"].clone()
    };
    let count = |v: &Value, key: &str| v[key].as_u64().expect("a count");
    let (default_png, clear_png) = (png("default.png"), png("clear.png"));
    let default = render(&default_png, &[]);
    let rays = count(&default, "rays");
    assert!(count(&default, "samples_located") > 2 * rays);
    // Transparent everywhere: no sample is taken, no cell tested, and nothing is drawn.
    let clear = render(&clear_png, &["--opacity", "0%:0,100%:0"]);
    assert_eq!(count(&clear, "rays"), rays);
    for key in [
        "samples",
        "samples_located",
        "hex_tests",
        "transparent_jumps",
    ] {
        assert_eq!(count(&clear, key), 0, "{key}");
    }
    assert_ne!(
        std::fs::read(&default_png).unwrap(),
        std::fs::read(&clear_png).unwrap()
    );
    let decoder = png::Decoder::new(std::fs::File::open(&clear_png).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut pixels).unwrap();
    let first = pixels[..4].to_vec();
    assert!(
        pixels[..info.buffer_size()]
            .chunks(4)
            .all(|p| p == first.as_slice()),
        "a transparent table draws nothing: every pixel is the background"
    );
    // Zero only at the lowest scalar (percentages and values mixed): no cell is wholly
    // transparent, so nothing is jumped over.
    let (red, blue) = (png("red.png"), png("blue.png"));
    let opaque = ["--opacity", "0%:0,50%:0.5,100%:1", "--unit-distance", "10%"];
    let red_stats = render(&red, &[&opaque[..], &["--color", "0%:1:0:0"]].concat());
    assert_eq!(count(&red_stats, "transparent_jumps"), 0);
    assert!(count(&default, "transparent_jumps") > 0);
    render(
        &blue,
        &[&opaque[..], &["--color", "0%:0:0:1,100%:0:0:1"]].concat(),
    );
    assert_ne!(std::fs::read(&red).unwrap(), std::fs::read(&blue).unwrap());
    for (bad, says) in [
        (&["--opacity", "50%:0,0%:1"][..], "--opacity: point 2"),
        (&["--opacity", "0%:2"][..], "not a number in [0, 1]"),
        (&["--color", "0%:1:0"][..], "S:R:G:B"),
        (&["--unit-distance", "0"][..], "--unit-distance"),
        (&["--unit-distance", "-5%"][..], "--unit-distance"),
    ] {
        let out = png("bad.png");
        let args = render_args("pump-rotor:3000", &out, "8x8", &[bad]);
        let o = cylvol(&args);
        assert!(!o.status.success(), "{bad:?} accepted");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(says), "{bad:?}: {err}");
        assert!(!Path::new(&out).exists(), "{bad:?} wrote an image");
    }
}

/// `--opacity-convention attenuation` reads the opacity as VTK's unstructured ray caster does,
/// as an attenuation coefficient (a unit distance lets `e^(−A)` through, more than the
/// `1 − A` of the default `sampled`): in white, every pixel is at most as bright, the image
/// darker, from the same samples (at a fixed step: an error-bounded render places its samples
/// for each transfer function).
#[test]
fn opacity_convention_attenuation_lets_more_through() {
    let dir = tempfile::tempdir().unwrap();
    let render = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let out = out.to_str().unwrap().to_string();
        let args = render_args(
            "pump-rotor:4000",
            &out,
            "24x24",
            &[
                &[
                    "--opacity",
                    "0%:0.2, 100%:0.9",
                    "--color",
                    "0%:1:1:1",
                    "--unit-distance",
                    "5%",
                    "--step",
                    "0.05",
                    "--json",
                ],
                extra,
            ],
        );
        let stats = json_of(&args)["stats"].clone();
        let decoder = png::Decoder::new(std::fs::File::open(&out).unwrap());
        let mut reader = decoder.read_info().unwrap();
        let mut pixels = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut pixels).unwrap();
        pixels.truncate(info.buffer_size());
        (stats, pixels)
    };
    let (sampled, bright) = render("sampled.png", &[]);
    let (attenuation, dim) = render("attenuation.png", &["--opacity-convention", "attenuation"]);
    assert_eq!(sampled["samples_located"], attenuation["samples_located"]);
    assert!(bright.iter().zip(&dim).all(|(b, d)| d <= b));
    let sum = |p: &[u8]| p.chunks(4).map(|c| u64::from(c[0])).sum::<u64>();
    assert!(
        sum(&dim) < sum(&bright),
        "{} vs {}",
        sum(&dim),
        sum(&bright)
    );
}

/// `--clip-plane POINT:NORMAL` as VTK's clipping planes: a plane beyond the mesh on its
/// normal's far side keeps everything (the same PNG bytes and work); one through the rotor's
/// axis keeps the side its normal points to (fewer samples, another image, the equation in the
/// JSON); bad planes and seven of them fail before anything is written.
#[test]
fn render_takes_clipping_planes() {
    let dir = tempfile::tempdir().expect("temp dir");
    let png = |name: &str| dir.path().join(name).to_str().expect("utf-8").to_string();
    let run = |out: &str, planes: &[&str]| {
        let mut clip: Vec<&str> = Vec::new();
        for p in planes {
            clip.extend(["--clip-plane", p]);
        }
        json_of(&render_args(
            "pump-rotor:3000",
            out,
            "24x24",
            &[&["--view", "30,30,1", "--json"], &clip],
        ))
    };
    let whole = run(&png("whole.png"), &[]);
    assert_eq!(whole["clip_planes"], serde_json::json!([]));
    let kept = run(&png("kept.png"), &["-1e3,0,0:1,0,0"]);
    let half = run(&png("half.png"), &["0,0,0:2,0,0"]);
    let bytes = |name: &str| std::fs::read(dir.path().join(name)).expect("png written");
    assert_eq!(bytes("whole.png"), bytes("kept.png"));
    assert_eq!(whole["stats"], kept["stats"]);
    assert_ne!(bytes("whole.png"), bytes("half.png"));
    assert_eq!(
        half["clip_planes"],
        serde_json::json!([[2.0, 0.0, 0.0, -0.0]])
    );
    let located = |j: &Value| j["stats"]["samples_located"].as_u64().unwrap();
    assert!(located(&half) > 0 && located(&half) < located(&whole) * 3 / 4);
    // The other side's samples make up the rest, give or take the ones the cut moves.
    let other = run(&png("other.png"), &["0,0,0:-1,0,0"]);
    let sum = located(&half) + located(&other);
    assert!(
        sum.abs_diff(located(&whole)) * 20 < located(&whole),
        "{sum}"
    );

    let out = png("bad.png");
    for (plane, message) in [
        ("0,0,0:0,0,0", "zero normal"),
        ("0,0:1,0,0", "is not POINT:NORMAL"),
        ("0,0,0:1,0,nan", "is not POINT:NORMAL"),
    ] {
        fails_with(
            &render_args("pump-rotor:3000", &out, "8x8", &[&["--clip-plane", plane]]),
            message,
        );
    }
    let seven: Vec<&str> = (0..7)
        .flat_map(|_| ["--clip-plane", "0,0,0:1,0,0"])
        .collect();
    fails_with(
        &render_args("pump-rotor:3000", &out, "8x8", &[&seven]),
        "--clip-plane: 7 clipping planes (at most 6)",
    );
    assert!(!Path::new(&out).exists(), "nothing written");
}

/// `--march-reach CELLS`: how far ahead the fast path still marches to a sample. At three
/// times the default step on the rotor, the default reach locates some samples through the
/// structure, 0 more, `inf` none — with the same PNG bytes and the same samples located; bad
/// values fail before anything is written.
#[test]
fn render_takes_a_march_reach_with_the_same_image() {
    let dir = tempfile::tempdir().expect("temp dir");
    let png = |name: &str| dir.path().join(name).to_str().expect("utf-8").to_string();
    let step = {
        let j = json_of(&render_args(
            "pump-rotor:3000",
            &png("probe.png"),
            "8x8",
            &[&["--json"]],
        ));
        3.0 * j["step"].as_f64().expect("a step")
    }
    .to_string();
    let run = |out: &str, reach: &[&str]| {
        json_of(&render_args(
            "pump-rotor:3000",
            out,
            "48x48",
            &[&["--view", "30,30,1", "--step", &step, "--json"], reach],
        ))
    };
    let default = run(&png("default.png"), &[]);
    let zero = run(&png("zero.png"), &["--march-reach", "0"]);
    let never = run(&png("never.png"), &["--march-reach", "inf"]);
    let bytes = |name: &str| std::fs::read(dir.path().join(name)).expect("png written");
    assert_eq!(bytes("default.png"), bytes("never.png"));
    assert_eq!(bytes("zero.png"), bytes("never.png"));
    let count = |j: &Value, key: &str| j["stats"][key].as_u64().expect("a count");
    for j in [&default, &zero] {
        assert_eq!(
            count(j, "samples_located"),
            count(&never, "samples_located")
        );
    }
    assert_eq!(count(&never, "far_locates"), 0);
    assert!(count(&default, "far_locates") > 0, "{default}");
    assert!(count(&zero, "far_locates") > count(&default, "far_locates"));
    assert!(count(&zero, "walk_steps") < count(&never, "walk_steps"));

    let out = png("bad.png");
    for value in ["-1", "nan", "many"] {
        fails_with(
            &render_args(
                "pump-rotor:3000",
                &out,
                "8x8",
                &[&[&format!("--march-reach={value}")]],
            ),
            "is not a number of cells",
        );
    }
    assert!(!Path::new(&out).exists(), "nothing written");
}

/// A mesh with no point or cell array (a PLOT3D grid without its Q file) is refused by every
/// rendering command as soon as it is loaded, before any structure is built for it.
#[test]
fn a_mesh_with_nothing_to_render_is_refused_before_any_build() {
    let dir = tempfile::tempdir().unwrap();
    let grid = dir.path().join("combxyz.bin");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/combxyz.bin"),
        &grid,
    )
    .unwrap();
    let grid = grid.to_str().unwrap();
    let png = dir.path().join("x.png");
    for args in [
        vec!["render", grid, "-o", png.to_str().unwrap()],
        vec!["accuracy", grid],
        vec!["bench", grid],
    ] {
        fails_with(&args, "the mesh has no point or cell array to render");
        let stderr = String::from_utf8_lossy(&cylvol(&args).stderr).into_owned();
        assert!(stderr.contains("loaded"), "{args:?}: {stderr}");
        assert!(!stderr.contains("built"), "{args:?} built first: {stderr}");
    }
}
