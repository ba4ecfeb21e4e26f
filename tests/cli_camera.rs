//! `cylvol render`'s camera and depth options as a VTK user sets them: `--camera
//! POSITION:FOCAL_POINT:VIEW_UP` gives the image of the `--view` preset it spells out,
//! `--view-angle` and `--parallel-scale` are the preset's zoom, `--parallel` projects in
//! parallel, `--depth` writes VTK image data (rows bottom to top, NaN where no depth) that
//! VTK's own reader reads, `--depth-opacity` moves the depth sample, `--depth-in` stops rays
//! at a depth image's distances, and bad values fail with a message and write nothing.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use cylvol::render::{Camera, Projection};
use glam::DVec3;

const INPUT: &str = "pump-rotor:3000";
const SIZE: (u32, u32) = (40, 32);

fn cylvol(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cylvol"))
        .args(args)
        .output()
        .expect("cylvol runs")
}

/// `render INPUT -o PNG --size SIZE` and the `extra` options.
fn render_args<'a>(png: &'a Path, size: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["render", INPUT, "-o", png.to_str().unwrap(), "--size", size];
    args.extend_from_slice(extra);
    args
}

/// Renders `INPUT` at `SIZE` into `dir/name.png` with `extra` options; returns the PNG's bytes.
fn render(dir: &Path, name: &str, extra: &[&str]) -> Vec<u8> {
    let png = dir.join(format!("{name}.png"));
    let size = format!("{}x{}", SIZE.0, SIZE.1);
    let args = render_args(&png, &size, extra);
    let out = cylvol(&args);
    assert!(
        out.status.success(),
        "cylvol {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::read(&png).unwrap()
}

fn bounds() -> [f64; 6] {
    cylvol::input::load(INPUT, &Default::default())
        .unwrap()
        .bounds()
}

/// `X,Y,Z` with every digit `f64`'s display keeps (it reads back to the same value).
fn xyz(v: DVec3) -> String {
    format!("{},{},{}", v.x, v.y, v.z)
}

fn camera_arg(c: &Camera) -> String {
    format!("{}:{}:{}", xyz(c.eye), xyz(c.focal), xyz(c.up))
}

#[test]
fn a_camera_set_as_vtk_sets_it_gives_the_presets_image() {
    let dir = tempfile::tempdir().unwrap();
    let preset = Camera::view(bounds(), SIZE.0, SIZE.1, 30.0, 20.0, 1.3);
    let Projection::Perspective(angle) = preset.projection else {
        panic!("the preset is perspective")
    };
    let by_preset = render(dir.path(), "preset", &["--view", "30,20,1.3"]);
    // The zoom divides the view angle: the preset's camera, spelt out.
    let spelt = render(
        dir.path(),
        "spelt",
        &[
            "--camera",
            &camera_arg(&preset),
            "--view-angle",
            &angle.to_string(),
        ],
    );
    assert_eq!(by_preset, spelt);
    // Without --view-angle the camera keeps VTK's 30°: the unzoomed picture.
    let wide = render(dir.path(), "wide", &["--camera", &camera_arg(&preset)]);
    assert_ne!(wide, by_preset);
    let unzoomed = render(dir.path(), "unzoomed", &["--view", "30,20,1"]);
    assert_eq!(wide, unzoomed);
}

#[test]
fn parallel_projection_takes_the_presets_scale_or_the_one_given() {
    let dir = tempfile::tempdir().unwrap();
    let reset = Camera::reset(bounds(), SIZE.0, SIZE.1, true);
    let Projection::Parallel(radius) = reset.projection else {
        panic!("a parallel reset")
    };
    let zoomed = render(dir.path(), "zoomed", &["--view", "0,0,2", "--parallel"]);
    let scaled = render(
        dir.path(),
        "scaled",
        &[
            "--camera",
            &camera_arg(&reset),
            "--parallel",
            "--parallel-scale",
            &(radius / 2.0).to_string(),
        ],
    );
    assert_eq!(zoomed, scaled);
    let perspective = render(dir.path(), "perspective", &["--view", "0,0,2"]);
    assert_ne!(zoomed, perspective, "--parallel changes the projection");
    // With --camera alone the parallel scale is the reset's (the bounding sphere's radius).
    let unscaled = render(
        dir.path(),
        "unscaled",
        &["--camera", &camera_arg(&reset), "--parallel"],
    );
    let reset_view = render(dir.path(), "reset", &["--view", "0,0,1", "--parallel"]);
    assert_eq!(unscaled, reset_view);
    assert_ne!(unscaled, zoomed);
}

/// A `.vti` file as `cylvol render --depth` writes it: its whole extent and its values.
fn read_depth_vti(path: &Path) -> ([usize; 2], Vec<f32>) {
    let bytes = std::fs::read(path).unwrap();
    let marker = b"<AppendedData encoding=\"raw\">";
    let at = bytes
        .windows(marker.len())
        .position(|w| w == marker)
        .expect("raw appended data");
    let header = String::from_utf8_lossy(&bytes[..at]);
    assert!(header.contains(r#"<VTKFile type="ImageData""#), "{header}");
    assert!(header.contains(r#"header_type="UInt64""#), "{header}");
    assert!(
        header.contains(r#"<PointData Scalars="depth">"#),
        "{header}"
    );
    let extent: Vec<usize> = header
        .split("WholeExtent=\"")
        .nth(1)
        .unwrap()
        .split('"')
        .next()
        .unwrap()
        .split(' ')
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(extent[0], 0);
    assert_eq!(extent[2], 0);
    assert_eq!(&extent[4..], &[0, 0]);
    let dims = [extent[1] + 1, extent[3] + 1];
    let start = at + marker.len();
    let data = &bytes[start + bytes[start..].iter().position(|&b| b == b'_').unwrap() + 1..];
    let n = u64::from_le_bytes(data[..8].try_into().unwrap()) as usize;
    assert_eq!(n, 4 * dims[0] * dims[1]);
    let values = data[8..8 + n]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    (dims, values)
}

/// Renders with the camera moved down by `shift` of the bounding sphere's radius (so the
/// mesh shows in the image's upper part) and a depth image; returns the PNG's RGB rows (top
/// to bottom) and the depth file's path.
fn render_shifted(dir: &Path, name: &str, extra: &[&str]) -> (Vec<Vec<[u8; 3]>>, PathBuf) {
    let reset = Camera::reset(bounds(), SIZE.0, SIZE.1, false);
    let Projection::Perspective(_) = reset.projection else {
        panic!("a perspective reset")
    };
    let b = bounds();
    let radius = 0.5 * DVec3::new(b[1] - b[0], b[3] - b[2], b[5] - b[4]).length();
    let down = -reset.up * (0.55 * radius);
    let moved = Camera {
        eye: reset.eye + down,
        focal: reset.focal + down,
        ..reset
    };
    let depth = dir.join(format!("{name}.vti"));
    let mut args = vec![
        "--camera".to_string(),
        camera_arg(&moved),
        "--depth".to_string(),
        depth.to_str().unwrap().to_string(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let png = render(dir, name, &args);
    let mut reader = png::Decoder::new(png.as_slice()).read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut pixels).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgba);
    let rows = pixels[..info.buffer_size()]
        .chunks_exact(4 * SIZE.0 as usize)
        .map(|row| row.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect())
        .collect();
    (rows, depth)
}

#[test]
fn the_depth_image_is_vtk_image_data_bottom_row_first() {
    let dir = tempfile::tempdir().unwrap();
    let (rows, depth) = render_shifted(dir.path(), "shifted", &[]);
    let (dims, values) = read_depth_vti(&depth);
    assert_eq!(dims, [SIZE.0 as usize, SIZE.1 as usize]);
    let (w, h) = (dims[0], dims[1]);
    let depth_at = |i: usize, j_top: usize| values[(h - 1 - j_top) * w + i];
    // Every pixel with a depth shows something (the background is black), and the mesh, seen
    // from below its centre, fills the upper rows: a file written top row first would put the
    // depths in the lower ones.
    let mut finite = 0;
    for (j, row) in rows.iter().enumerate() {
        for (i, rgb) in row.iter().enumerate() {
            let d = depth_at(i, j);
            assert!(
                d.is_nan() || (d.is_finite() && d > 0.0),
                "{d} at ({i}, {j})"
            );
            if d.is_finite() {
                finite += 1;
                assert_ne!(*rgb, [0, 0, 0], "a depth where nothing shows, ({i}, {j})");
            }
        }
    }
    assert!(finite > 20, "{finite} pixels with a depth");
    let upper = (0..h / 2)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .filter(|&(i, j)| depth_at(i, j).is_finite())
        .count();
    assert!(
        upper * 4 > finite * 3,
        "{upper} of {finite} depths in the upper half"
    );
    // VTK's own reader: the same size, array and range, and NaN where we wrote NaN.
    vtk_reads(&depth, dims, &values);
}

#[test]
fn a_higher_depth_opacity_takes_later_samples() {
    let dir = tempfile::tempdir().unwrap();
    let (_, half) = render_shifted(dir.path(), "half", &[]);
    let (_, most) = render_shifted(dir.path(), "most", &["--depth-opacity", "0.9"]);
    let (_, first) = render_shifted(dir.path(), "first", &["--depth-opacity", "1e-6"]);
    let (_, half) = read_depth_vti(&half);
    let (_, most) = read_depth_vti(&most);
    let (_, first) = read_depth_vti(&first);
    let count = |v: &[f32]| v.iter().filter(|d| d.is_finite()).count();
    // Each threshold's depths: fewer pixels reach it, and none sooner than a lower one.
    for (lower, higher) in [(&first, &half), (&half, &most)] {
        assert!(
            count(lower) > count(higher),
            "{} {}",
            count(lower),
            count(higher)
        );
        for (k, (a, b)) in lower.iter().zip(higher.iter()).enumerate() {
            if b.is_finite() {
                assert!(a <= b, "pixel {k}: {a} then {b}");
            }
        }
    }
}

/// Reads the file with `/usr/bin/python3`'s VTK and checks it against `values`; skipped with
/// a note where VTK's Python cannot run.
fn vtk_reads(path: &Path, dims: [usize; 2], values: &[f32]) {
    let script = format!(
        "import math, vtk\n\
         r = vtk.vtkXMLImageDataReader(); r.SetFileName({path:?}); r.Update()\n\
         o = r.GetOutput(); a = o.GetPointData().GetScalars()\n\
         v = [a.GetValue(k) for k in range(a.GetNumberOfTuples())]\n\
         f = [x for x in v if not math.isnan(x)]\n\
         print(*o.GetDimensions(), a.GetName(), len(v) - len(f), repr(min(f)), repr(max(f)), repr(v[{probe}]))",
        path = path.to_str().unwrap(),
        probe = values.iter().position(|d| d.is_finite()).unwrap(),
    );
    let Ok(out) = Command::new("/usr/bin/python3")
        .args(["-c", &script])
        .output()
    else {
        eprintln!("note: /usr/bin/python3 unavailable, the .vti not read by VTK");
        return;
    };
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("No module named 'vtk'"),
            "VTK failed to read the depth image: {err}"
        );
        eprintln!("note: VTK's Python unavailable, the .vti not read by VTK");
        return;
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let fields: Vec<&str> = text.split_whitespace().collect();
    assert_eq!(
        fields[..4],
        [&dims[0].to_string(), &dims[1].to_string(), "1", "depth"]
    );
    let nan = values.iter().filter(|d| d.is_nan()).count();
    assert_eq!(fields[4], nan.to_string());
    let finite: Vec<f32> = values.iter().copied().filter(|d| d.is_finite()).collect();
    let min = finite.iter().copied().fold(f32::INFINITY, f32::min);
    let max = finite.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let probe = finite[0];
    for (field, ours) in fields[5..8].iter().zip([min, max, probe]) {
        assert_eq!(field.parse::<f64>().unwrap(), ours as f64, "{text}");
    }
}

fn fails_with(args: &[&str], message: &str) {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("never.png");
    let all = render_args(&png, "8x8", args);
    let out = cylvol(&all);
    assert!(!out.status.success(), "cylvol {all:?} succeeded");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(message),
        "cylvol {all:?}: '{message}' not in {stderr}"
    );
    assert!(out.stdout.is_empty());
    assert!(!png.exists(), "cylvol {all:?} wrote an image");
}

/// A `--view` zoom is refused in the user's terms: a perspective camera's zoom divides the
/// 30° view angle, which must stay below 180° (checked before the mesh is loaded, for
/// `render`, `bench` and `accuracy` alike); in parallel projection it divides the parallel
/// scale, so a small zoom is fine there and only one that leaves no finite scale is refused.
#[test]
fn a_zoom_is_refused_in_the_options_terms() {
    let zoom_message = "--view 0,0,1e-9: a zoom of 1e-9 would widen the 30° view angle to \
                        30000000000°; the zoom divides the view angle, which must stay below \
                        180°, so the zoom must be more than 30/180 (about 0.1667)";
    fails_with(&["--view", "0,0,1e-9"], zoom_message);
    fails_with(&["--view", "0,0,0.1666"], "a zoom of 0.1666 would widen");
    for command in ["bench", "accuracy"] {
        let out = cylvol(&[command, INPUT, "--view", "0,0,1e-9"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(stderr.contains(zoom_message), "{command}: {stderr}");
        assert!(!stderr.contains("loaded"), "{command}: {stderr}");
    }
    fails_with(
        &["--parallel", "--view", "10,0,1e-320"],
        "--view 10,0,1e-320: a zoom of 1e-320 makes the parallel scale (half the image's \
         height) inf, not a positive, finite length",
    );
    // The same zooms are fine where they make a camera.
    let dir = tempfile::tempdir().unwrap();
    render(dir.path(), "wide", &["--view", "0,0,0.1667"]);
    render(
        dir.path(),
        "parallel",
        &["--parallel", "--view", "0,0,1e-3"],
    );
    render(
        dir.path(),
        "angle",
        &["--view-angle", "170", "--view", "0,0,0.01"],
    );
}

#[test]
fn bad_camera_and_depth_options_fail_with_a_message() {
    fails_with(
        &["--camera", "1,1,1:1,1,1:0,1,0"],
        "degenerate camera '1,1,1:1,1,1:0,1,0': the position is the focal point",
    );
    fails_with(
        &["--camera", "0,0,5:0,0,0:0,0,1"],
        "degenerate camera '0,0,5:0,0,0:0,0,1': the view-up is along the line of sight",
    );
    fails_with(
        &["--camera", "0,0,5:0,0,0:0,0,0"],
        "degenerate camera '0,0,5:0,0,0:0,0,0': the view-up is zero",
    );
    fails_with(
        &["--camera", "1e-300,0,0:1e-300,0,0:0,1,0"],
        "degenerate camera '1e-300,0,0:1e-300,0,0:0,1,0': the position is the focal point",
    );
    fails_with(
        &["--camera", "-1e308,0,0:1e308,0,0:0,1,0"],
        "degenerate camera '-1e308,0,0:1e308,0,0:0,1,0': the position and the focal point are \
         too far apart to give a direction of view",
    );
    fails_with(&["--camera", "0,0,5:0,0,0"], "POSITION:FOCAL_POINT:VIEW_UP");
    fails_with(
        &["--camera", "0,0,5:0,0,0:0,1"],
        "POSITION:FOCAL_POINT:VIEW_UP",
    );
    fails_with(
        &["--camera", "0,0,nan:0,0,0:0,1,0"],
        "POSITION:FOCAL_POINT:VIEW_UP",
    );
    fails_with(
        &["--camera", "0,0,5:0,0,0:0,1,0", "--view", "0,0,1"],
        "cannot be used with",
    );
    fails_with(&["--view-angle", "0"], "(0, 180)");
    fails_with(&["--view-angle", "180"], "(0, 180)");
    fails_with(&["--view-angle", "20", "--parallel"], "cannot be used with");
    fails_with(&["--parallel-scale", "2"], "--parallel");
    fails_with(&["--parallel", "--parallel-scale", "0"], "positive");
    fails_with(&["--parallel", "--parallel-scale", "inf"], "positive");
    fails_with(&["--depth-opacity", "0.5"], "--depth");
    fails_with(&["--depth", "d.vti", "--depth-opacity", "0"], "(0, 1]");
    fails_with(&["--depth", "d.vti", "--depth-opacity", "1.5"], "(0, 1]");
    fails_with(
        &["--depth", "/no/such/folder/d.vti"],
        "--depth /no/such/folder/d.vti: the folder /no/such/folder does not exist",
    );
    fails_with(&["--depth-in", "/no/such/folder/d.vti"], "No such file");
    // A depth image of another size, or not an image at all.
    let dir = tempfile::tempdir().unwrap();
    let other = dir.path().join("other.vti");
    write_depth(&other, 8, 7, |_, _| 1.0);
    fails_with(
        &["--depth-in", other.to_str().unwrap()],
        "a 8x7 image, but the render is 8x8 (--size)",
    );
    let grid = dir.path().join("grid.vtu");
    cylvol::io::write_file(
        &cylvol::input::load(INPUT, &Default::default()).unwrap(),
        &grid,
    )
    .unwrap();
    fails_with(
        &["--depth-in", grid.to_str().unwrap()],
        "only ImageData (.vti)",
    );
}

/// Writes a `w × h` depth image as `--depth` does, `depth(i, j)` at pixel column `i` of row
/// `j` counted from the top.
fn write_depth(path: &Path, w: u32, h: u32, depth: impl Fn(u32, u32) -> f32) {
    let bottom_up: Vec<f32> = (0..h)
        .rev()
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| depth(i, j))
        .collect();
    let mut file = std::fs::File::create(path).unwrap();
    cylvol::io::vti::write_point_scalars(&mut file, w, h, "depth", &bottom_up).unwrap();
}

/// The PNG's RGB rows, top to bottom.
fn rgb_rows(png: &[u8]) -> Vec<Vec<[u8; 3]>> {
    let mut reader = png::Decoder::new(png).read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut pixels).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgba);
    pixels[..info.buffer_size()]
        .chunks_exact(4 * info.width as usize)
        .map(|row| row.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect())
        .collect()
}

/// `--depth-in`: a ray stops at its pixel's depth (0: at the camera, so nothing shows) and
/// NaN stops none; rows are read bottom to top, as VTK stores images.
#[test]
fn depth_in_stops_each_ray_at_its_pixel_depth() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = SIZE;
    let depth = dir.path().join("upper-open.vti");
    // The upper half open, the lower half stopped at the camera, one upper column stopped too.
    write_depth(&depth, w, h, |i, j| {
        if j < h / 2 && i != 3 {
            f32::NAN
        } else {
            0.0
        }
    });
    let plain = rgb_rows(&render(dir.path(), "plain", &[]));
    let stopped = rgb_rows(&render(
        dir.path(),
        "stopped",
        &["--depth-in", depth.to_str().unwrap()],
    ));
    let shown = |rows: &[Vec<[u8; 3]>], range: std::ops::Range<u32>| {
        range
            .flat_map(|j| rows[j as usize].iter())
            .filter(|rgb| **rgb != [0, 0, 0])
            .count()
    };
    assert!(shown(&plain, 0..h / 2) > 20 && shown(&plain, h / 2..h) > 20);
    for j in 0..h as usize {
        for i in 0..w as usize {
            let expected = if j < h as usize / 2 && i != 3 {
                plain[j][i]
            } else {
                [0, 0, 0]
            };
            assert_eq!(stopped[j][i], expected, "pixel ({i}, {j})");
        }
    }
}

/// `--depth` then `--depth-in` of the same file: rays stop where they reached half opacity,
/// so the image's own depth is the same where the stopping sample is kept, none where it is
/// cut, and never farther; pixels without a depth are unchanged, and most others change.
#[test]
fn the_depth_written_read_back_stops_rays_at_half_opacity() {
    let dir = tempfile::tempdir().unwrap();
    let (rows, depth) = render_shifted(dir.path(), "first", &[]);
    let (_, values) = read_depth_vti(&depth);
    let (again, depth_again) = render_shifted(
        dir.path(),
        "again",
        &["--depth-in", depth.to_str().unwrap()],
    );
    let (_, values_again) = read_depth_vti(&depth_again);
    let (w, h) = (SIZE.0 as usize, SIZE.1 as usize);
    let mut changed = 0;
    for j in 0..h {
        for i in 0..w {
            let k = (h - 1 - j) * w + i;
            let (d, d_again) = (values[k], values_again[k]);
            if d.is_nan() {
                assert_eq!(again[j][i], rows[j][i], "pixel ({i}, {j}) has no depth");
                assert!(d_again.is_nan(), "pixel ({i}, {j}): depth {d_again}");
                continue;
            }
            // (Or, where the depth was the middle of a piece of the ray in the mesh too
            // short for a sample, a chord, that piece cut at the depth: the middle of what
            // is left of it, nearer.)
            assert!(
                d_again.is_nan() || d_again <= d,
                "pixel ({i}, {j}): depth {d} then {d_again}"
            );
            changed += usize::from(again[j][i] != rows[j][i]);
        }
    }
    let finite = values.iter().filter(|d| d.is_finite()).count();
    assert!(changed * 2 > finite, "{changed} of {finite} pixels changed");
}
