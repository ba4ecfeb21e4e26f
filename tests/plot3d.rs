//! PLOT3D reader tests: the real LOX post and combustor files, a comparison with VTK's own
//! reader, layout variants made from the real files (byte order, record markers, IBLANK,
//! precision, grid count, several grids, bytes after the data), and malformed files (2-D,
//! truncated, mismatched Q).

mod common;

use std::path::{Path, PathBuf};

use cylvol::io::plot3d::{self, ByteOrder, Precision};
use cylvol::io::ReadOptions;
use cylvol::{Component, Error, Mesh};

fn data(name: &str) -> String {
    format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn bytes(name: &str) -> Vec<u8> {
    std::fs::read(data(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn message(result: Result<Mesh, Error>) -> String {
    match result {
        Ok(m) => panic!("expected an error, got a mesh of {} cells", m.cell_count()),
        Err(e) => e.to_string(),
    }
}

/// The real files' contents, parsed here independently of the reader: big-endian, `f32`,
/// no record markers, no grid count.
struct Grid {
    dims: [u32; 3],
    /// x block, y block, z block as raw `f32` bits.
    coords: Vec<u32>,
    iblank: Option<Vec<i32>>,
}

struct Solution {
    dims: [u32; 3],
    /// The four free-stream floats, then five blocks, as raw `f32` bits.
    values: Vec<u32>,
}

fn be_words(b: &[u8]) -> Vec<u32> {
    b.chunks_exact(4)
        .map(|w| u32::from_be_bytes(w.try_into().unwrap()))
        .collect()
}

fn parse_grid(b: &[u8]) -> Grid {
    let words = be_words(b);
    let dims = [words[0], words[1], words[2]];
    let n = dims.iter().product::<u32>() as usize;
    let coords = words[3..3 + 3 * n].to_vec();
    let rest = &words[3 + 3 * n..];
    let iblank = match rest.len() {
        0 => None,
        r if r == n => Some(rest.iter().map(|&w| w as i32).collect()),
        r => panic!("unexpected {r} words after the coordinates"),
    };
    Grid {
        dims,
        coords,
        iblank,
    }
}

fn parse_solution(b: &[u8]) -> Solution {
    let words = be_words(b);
    let dims = [words[0], words[1], words[2]];
    let n = dims.iter().product::<u32>() as usize;
    assert_eq!(words.len(), 3 + 4 + 5 * n);
    Solution {
        dims,
        values: words[3..].to_vec(),
    }
}

/// How to write a variant.
#[derive(Clone, Copy, Default)]
struct Opts {
    little: bool,
    markers: bool,
    f64: bool,
    /// Write a leading grid count of this value (the body is repeated that many times).
    count: Option<u32>,
}

struct Writer {
    opts: Opts,
    out: Vec<u8>,
}

impl Writer {
    fn new(opts: Opts) -> Writer {
        Writer {
            opts,
            out: Vec::new(),
        }
    }
    fn int(&mut self, v: u32) {
        let b = if self.opts.little {
            v.to_le_bytes()
        } else {
            v.to_be_bytes()
        };
        self.out.extend(b);
    }
    fn float(&mut self, bits: u32) {
        if self.opts.f64 {
            let v = f64::from(f32::from_bits(bits));
            let b = if self.opts.little {
                v.to_le_bytes()
            } else {
                v.to_be_bytes()
            };
            self.out.extend(b);
        } else {
            self.int(bits);
        }
    }
    /// A record: `f` writes its content; markers around it if asked.
    fn record(&mut self, f: impl FnOnce(&mut Writer)) {
        let at = self.out.len();
        if self.opts.markers {
            self.int(0);
        }
        let start = self.out.len();
        f(self);
        if self.opts.markers {
            let len = (self.out.len() - start) as u32;
            let b = if self.opts.little {
                len.to_le_bytes()
            } else {
                len.to_be_bytes()
            };
            self.out[at..at + 4].copy_from_slice(&b);
            self.int(len);
        }
    }
    fn header(&mut self, dims: [u32; 3]) {
        let grids = self.opts.count.unwrap_or(1);
        if let Some(count) = self.opts.count {
            self.record(|w| w.int(count));
        }
        self.record(|w| {
            for _ in 0..grids {
                dims.iter().for_each(|&d| w.int(d));
            }
        });
    }
}

fn write_grid(g: &Grid, iblank: bool, opts: Opts) -> Vec<u8> {
    let mut w = Writer::new(opts);
    w.header(g.dims);
    for _ in 0..opts.count.unwrap_or(1) {
        w.record(|w| {
            g.coords.iter().for_each(|&c| w.float(c));
            if iblank {
                let blank = g.iblank.as_ref().expect("grid has IBLANK");
                blank.iter().for_each(|&b| w.int(b as u32));
            }
        });
    }
    w.out
}

fn write_solution(s: &Solution, dims: [u32; 3], opts: Opts) -> Vec<u8> {
    let mut w = Writer::new(opts);
    w.header(dims);
    for _ in 0..opts.count.unwrap_or(1) {
        w.record(|w| s.values[..4].iter().for_each(|&v| w.float(v)));
        w.record(|w| s.values[4..].iter().for_each(|&v| w.float(v)));
    }
    w.out
}

fn post() -> Mesh {
    plot3d::read(&bytes("postxyz.bin"), Some(&bytes("postq.bin"))).expect("post reads")
}

fn comb() -> Mesh {
    plot3d::read(&bytes("combxyz.bin"), Some(&bytes("combq.bin"))).expect("comb reads")
}

fn range(mesh: &Mesh, name: &str) -> [f64; 2] {
    let a = mesh
        .point_data()
        .iter()
        .find(|a| a.name == name)
        .unwrap_or_else(|| panic!("no array {name}"));
    a.range(a.default_component()).expect("non-empty")
}

#[test]
fn lox_post_counts_and_fields() {
    let xyz = bytes("postxyz.bin");
    let layout = plot3d::detect_layout(&xyz).unwrap();
    assert_eq!(layout.dims, [38, 76, 38]);
    assert_eq!(layout.byte_order, ByteOrder::Big);
    assert_eq!(layout.precision, Precision::F32);
    assert!(layout.iblank && !layout.record_markers && !layout.grid_count);
    let q = plot3d::detect_q_layout(&bytes("postq.bin")).unwrap();
    assert_eq!(q.dims, [38, 76, 38]);
    assert!(!q.iblank);

    let mesh = post();
    assert_eq!(mesh.point_count(), 109_744);
    // IBLANK is −1 on the seam, never 0: every cell is kept.
    assert_eq!(mesh.cell_count(), 102_675);
    let names: Vec<_> = mesh.point_data().iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["Density", "Momentum", "StagnationEnergy"]);
    assert_eq!(mesh.point_data()[1].components, 3);
    assert_eq!(
        mesh.point_data()[1].default_component(),
        Component::Magnitude
    );
    assert_eq!(range(&mesh, "Density"), [1.0, 1.0]);
    let [lo, hi] = range(&mesh, "StagnationEnergy");
    assert!(
        (-0.55..-0.54).contains(&lo) && (4.39..4.40).contains(&hi),
        "{lo} {hi}"
    );
    // The LOX post is an O-grid about z from z = 0 to 4.82.
    let b = mesh.bounds();
    assert!(b[4].abs() < 1e-6 && (b[5] - 4.8205).abs() < 1e-3, "{b:?}");
}

#[test]
fn combustor_counts_and_fields() {
    let layout = plot3d::detect_layout(&bytes("combxyz.bin")).unwrap();
    assert_eq!(layout.dims, [57, 33, 25]);
    assert!(!layout.iblank);
    let mesh = comb();
    assert_eq!(mesh.point_count(), 57 * 33 * 25);
    assert_eq!(mesh.cell_count(), 43_008);
    let [lo, hi] = range(&mesh, "Density");
    assert!(
        (0.197..0.199).contains(&lo) && (0.710..0.711).contains(&hi),
        "{lo} {hi}"
    );
    assert_eq!(range(&mesh, "StagnationEnergy"), [0.0, 0.0]);
}

#[test]
fn no_q_file_no_arrays() {
    let mesh = plot3d::read(&bytes("postxyz.bin"), None).unwrap();
    assert!(mesh.point_data().is_empty() && mesh.cell_data().is_empty());
    assert!(mesh.active_scalar().is_none());
    assert_eq!(mesh.cell_count(), 102_675);
    assert_eq!(mesh.points(), post().points());
}

const VTK_SCRIPT: &str = r#"
import vtk, sys, json
r = vtk.vtkMultiBlockPLOT3DReader()
errors = []
r.AddObserver('ErrorEvent', lambda o, e: errors.append(e))
r.AutoDetectFormatOn()
r.SetXYZFileName(sys.argv[1])
r.SetQFileName(sys.argv[2])
r.Update()
b = r.GetOutput().GetBlock(0)
n = b.GetNumberOfPoints()
ids = [0, 1, 777, n // 2, n - 1]
# Numbers as repr strings: Rust's str::parse rounds them exactly back to the same double.
s = lambda v: [repr(x) for x in v]
out = {"errors": len(errors), "dims": list(b.GetDimensions()), "bounds": s(b.GetBounds()),
       "ids": ids, "points": [s(b.GetPoint(i)) for i in ids], "ranges": {}}
pd = b.GetPointData()
for name in ["Density", "Momentum", "StagnationEnergy"]:
    out["ranges"][name] = s(pd.GetArray(name).GetRange(-1))
print(json.dumps(out))
"#;

fn compare_with_vtk(xyz: &str, q: &str, mesh: &Mesh) {
    compare_files_with_vtk(Path::new(&data(xyz)), Path::new(&data(q)), mesh);
}

/// What VTK's reader gives for the grid file `xyz` and Q file `q` (dimensions, bounds, some
/// points, the arrays' ranges) is what `mesh` holds.
fn compare_files_with_vtk(xyz: &Path, q: &Path, mesh: &Mesh) {
    let dims = plot3d::detect_layout(&std::fs::read(xyz).unwrap())
        .unwrap()
        .dims;
    if !common::vtk_python_available() {
        return;
    }
    let out = common::vtk_python(VTK_SCRIPT, &[xyz.to_str().unwrap(), q.to_str().unwrap()]);
    let xyz = xyz.display();
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    assert_eq!(v["errors"], 0, "{xyz}: VTK's reader reported errors");
    let f = |v: &serde_json::Value| -> f64 { v.as_str().expect("string").parse().expect("number") };
    let vtk_dims: Vec<usize> = v["dims"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d.as_u64().unwrap() as usize)
        .collect();
    assert_eq!(vtk_dims, dims);
    let bounds: Vec<f64> = v["bounds"].as_array().unwrap().iter().map(f).collect();
    assert_eq!(bounds, mesh.bounds().to_vec(), "bounds");
    for (id, p) in v["ids"]
        .as_array()
        .unwrap()
        .iter()
        .zip(v["points"].as_array().unwrap())
    {
        let id = id.as_u64().unwrap() as usize;
        let p: Vec<f64> = p.as_array().unwrap().iter().map(f).collect();
        assert_eq!(p, mesh.points()[id].to_array().to_vec(), "point {id}");
    }
    for name in ["Density", "Momentum", "StagnationEnergy"] {
        let theirs: Vec<f64> = v["ranges"][name]
            .as_array()
            .unwrap()
            .iter()
            .map(f)
            .collect();
        let ours = range(mesh, name);
        for (a, b) in ours.iter().zip(&theirs) {
            let scale = a.abs().max(b.abs()).max(1e-30);
            assert!(
                (a - b).abs() <= 1e-6 * scale || (a - b).abs() == 0.0,
                "{xyz} {name}: ours {ours:?}, VTK {theirs:?}"
            );
        }
    }
}

#[test]
fn lox_post_matches_vtk() {
    compare_with_vtk("postxyz.bin", "postq.bin", &post());
}

#[test]
fn combustor_matches_vtk() {
    compare_with_vtk("combxyz.bin", "combq.bin", &comb());
}

#[test]
fn layout_variants_read_to_the_same_mesh() {
    let xyz = bytes("postxyz.bin");
    let qb = bytes("postq.bin");
    let g = parse_grid(&xyz);
    let s = parse_solution(&qb);
    assert_eq!(g.dims, s.dims);
    let reference = post();
    // The plain writer reproduces the file byte for byte: the writer is right.
    assert_eq!(write_grid(&g, true, Opts::default()), xyz);
    assert_eq!(write_solution(&s, s.dims, Opts::default()), qb);
    let all = Opts {
        little: true,
        markers: true,
        f64: true,
        count: Some(1),
    };
    let variants = [
        (
            "little-endian",
            Opts {
                little: true,
                ..Opts::default()
            },
        ),
        (
            "record markers",
            Opts {
                markers: true,
                ..Opts::default()
            },
        ),
        (
            "f64",
            Opts {
                f64: true,
                ..Opts::default()
            },
        ),
        (
            "grid count 1",
            Opts {
                count: Some(1),
                ..Opts::default()
            },
        ),
        (
            "markers + count",
            Opts {
                markers: true,
                count: Some(1),
                ..Opts::default()
            },
        ),
        ("little + markers + f64", Opts { count: None, ..all }),
        ("everything", all),
    ];
    for (what, opts) in variants {
        for iblank in [true, false] {
            let v_xyz = write_grid(&g, iblank, opts);
            let v_q = write_solution(&s, s.dims, opts);
            let layout = plot3d::detect_layout(&v_xyz).unwrap_or_else(|e| panic!("{what}: {e}"));
            assert_eq!(layout.dims, [38, 76, 38], "{what}");
            assert_eq!(layout.iblank, iblank, "{what}");
            assert_eq!(layout.record_markers, opts.markers, "{what}");
            assert_eq!(layout.grid_count, opts.count.is_some(), "{what}");
            assert_eq!(
                layout.byte_order,
                if opts.little {
                    ByteOrder::Little
                } else {
                    ByteOrder::Big
                },
                "{what}"
            );
            assert_eq!(
                layout.precision,
                if opts.f64 {
                    Precision::F64
                } else {
                    Precision::F32
                },
                "{what}"
            );
            let mesh = plot3d::read(&v_xyz, Some(&v_q))
                .unwrap_or_else(|e| panic!("{what}, iblank {iblank}: {e}"));
            // The post has no IBLANK = 0 point, so stripping IBLANK changes nothing.
            assert!(mesh == reference, "{what}, iblank {iblank}: mesh differs");
        }
    }
    // A Q file in another layout than its grid is fine too.
    let q_le = write_solution(&s, s.dims, all);
    assert!(plot3d::read(&xyz, Some(&q_le)).unwrap() == reference);
}

#[test]
fn two_d_is_refused() {
    // A 4×3 2-D grid: two ints, the x block, the y block.
    let mut b: Vec<u8> = [4u32, 3].iter().flat_map(|v| v.to_be_bytes()).collect();
    for n in 0..24 {
        b.extend((1.0f32 + n as f32).to_be_bytes());
    }
    let msg = message(plot3d::read(&b, None));
    assert!(msg.contains("2-D PLOT3D files are not supported"), "{msg}");
}

#[test]
fn truncated_files_are_errors_with_sizes() {
    for (xyz, q) in [("postxyz.bin", "postq.bin"), ("combxyz.bin", "combq.bin")] {
        let xyz = bytes(xyz);
        let q = bytes(q);
        for n in 0..100 {
            // Spread over the file, including the header's first bytes and the last byte.
            let cut = if n == 0 { 0 } else { (n * xyz.len()) / 100 - 1 };
            let short = &xyz[..cut];
            let msg = message(plot3d::read(short, Some(&q)));
            assert!(
                msg.contains(&format!("{cut} bytes")) && msg.contains("expected"),
                "grid cut at {cut}: {msg}"
            );
            let cut = if n == 0 { 5 } else { (n * q.len()) / 100 - 1 };
            let msg = message(plot3d::read(&xyz, Some(&q[..cut])));
            assert!(
                msg.contains(&format!("{cut} bytes")) && msg.contains("expected"),
                "Q cut at {cut}: {msg}"
            );
            assert!(msg.starts_with("PLOT3D Q"), "{msg}");
        }
    }
}

#[test]
fn q_file_with_other_dims_is_refused() {
    let xyz = bytes("combxyz.bin");
    let s = parse_solution(&bytes("combq.bin"));
    // Same number of points, other dimensions: the size alone cannot catch it.
    let q = write_solution(&s, [33, 57, 25], Opts::default());
    let msg = message(plot3d::read(&xyz, Some(&q)));
    assert!(
        msg.contains("33×57×25") && msg.contains("57×33×25"),
        "{msg}"
    );
}

#[test]
fn iblank_zero_drops_the_cells_touching_the_point() {
    let mut g = parse_grid(&bytes("postxyz.bin"));
    let [ni, nj, _] = g.dims.map(|d| d as usize);
    let n = g.coords.len() / 3;
    let id = |i: usize, j: usize, k: usize| i + ni * (j + nj * k);
    let mut blank = g.iblank.clone().expect("the post has IBLANK");
    assert!(blank.iter().all(|&b| b != 0));
    // A grid corner touches 1 cell, an edge point 2, a face point 4, an interior point 8;
    // these are far enough apart to share no cell. A −1 point elsewhere removes nothing.
    let hidden = [
        (id(0, 0, 0), 1),
        (id(10, 0, 0), 2),
        (id(0, 10, 10), 4),
        (id(30, 20, 12), 8),
    ];
    for (p, _) in hidden {
        blank[p] = 0;
    }
    blank[id(20, 5, 5)] = -1;
    g.iblank = Some(blank);
    let b = write_grid(&g, true, Opts::default());
    let mesh = plot3d::read(&b, None).unwrap();
    let dropped: usize = hidden.iter().map(|(_, c)| c).sum();
    assert_eq!(mesh.cell_count(), 102_675 - dropped);
    assert_eq!(mesh.point_count(), n, "every point is kept");
    for (p, _) in hidden {
        assert!(
            !mesh.cells().iter().any(|c| c.contains(&(p as u32))),
            "a cell still uses hidden point {p}"
        );
    }
}

#[test]
fn garbage_is_an_error() {
    assert!(plot3d::read(&[], None).is_err());
    assert!(plot3d::read(&[0u8; 64], None).is_err());
    assert!(plot3d::read(&[0xffu8; 64], None).is_err());
    // Dimensions beyond any real grid: not a plausible header.
    let mut b: Vec<u8> = [i32::MAX, i32::MAX, i32::MAX]
        .iter()
        .flat_map(|v| v.to_be_bytes())
        .collect();
    b.extend([0u8; 100]);
    let msg = message(plot3d::read(&b, None));
    assert!(
        msg.contains("no plausible PLOT3D header") && msg.contains("112 bytes"),
        "{msg}"
    );
    // Plausible dimensions whose size overflows 64 bits: no allocation, an error.
    let big = plot3d::detect::MAX_DIMENSION as u32;
    let mut b: Vec<u8> = [big, big, big]
        .iter()
        .flat_map(|v| v.to_be_bytes())
        .collect();
    b.extend([0u8; 100]);
    let msg = message(plot3d::read(&b, None));
    assert!(
        msg.contains("over 2^64 bytes") && msg.contains("112 bytes"),
        "{msg}"
    );
}

#[test]
fn fuzz_seeds_are_valid_files() {
    // The seeds in fuzz/seeds/read_plot3d are a 2-byte grid length, the grid, then the Q file
    // (the split the fuzz target makes): each must read to the unit cube with its Q arrays,
    // once per grid (`two_grids`: twice), with or without bytes after the data (`padded`).
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/fuzz/seeds/read_plot3d");
    let mut seen = 0;
    for entry in std::fs::read_dir(dir).expect("seed folder") {
        let path = entry.unwrap().path();
        let b = std::fs::read(&path).unwrap();
        let at = usize::from(u16::from_le_bytes([b[0], b[1]]));
        let (xyz, q) = b[2..].split_at(at);
        let mesh = plot3d::read(xyz, Some(q)).unwrap_or_else(|e| panic!("{path:?}: {e}"));
        let grids = if path.ends_with("be_f32_two_grids") {
            2
        } else {
            1
        };
        assert_eq!(
            (mesh.point_count(), mesh.cell_count()),
            (8 * grids, grids),
            "{path:?}"
        );
        assert_eq!(mesh.bounds(), [0.0, 1.0, 0.0, 1.0, 0.0, 1.0], "{path:?}");
        assert_eq!(range(&mesh, "StagnationEnergy"), [2.5, 2.5], "{path:?}");
        seen += 1;
    }
    assert_eq!(seen, 8);
}

/// Copies of the shared files in a new folder, under the names given (`(shared, copy)`).
fn copies(files: &[(&str, &str)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (from, to) in files {
        std::fs::copy(data(from), dir.path().join(to)).unwrap();
    }
    dir
}

/// What `io::read_file` says about a grid, with or without `--q`.
fn read_file_error(grid: &Path, q: Option<PathBuf>) -> String {
    let options = ReadOptions { q_file: q };
    message(cylvol::io::read_file(grid, &options))
}

/// A bad Q file is reported under its own name, never the grid's: cut short (found beside the
/// grid, or given), of other dimensions, with a NaN in it. A bad grid is still the grid's.
#[test]
fn q_file_errors_name_the_q_file() {
    let dir = copies(&[("combxyz.bin", "combxyz.bin"), ("postq.bin", "postq.bin")]);
    let grid = dir.path().join("combxyz.bin");
    let q = dir.path().join("combq.bin");
    let full = bytes("combq.bin");
    std::fs::write(&q, &full[..1000]).unwrap();
    let prefix = format!(
        "{}: PLOT3D Q: truncated file: it has 1000 bytes",
        q.display()
    );
    let msg = read_file_error(&grid, None);
    assert!(msg.starts_with(&prefix), "{msg}");
    assert!(!msg.contains("combxyz"), "{msg}");
    let other = dir.path().join("other.bin");
    std::fs::write(&other, &full[..1000]).unwrap();
    let msg = read_file_error(&grid, Some(other.clone()));
    assert!(
        msg.starts_with(&format!("{}: PLOT3D Q", other.display())),
        "{msg}"
    );

    let post_q = dir.path().join("postq.bin");
    let msg = read_file_error(&grid, Some(post_q.clone()));
    assert!(
        msg.starts_with(&format!(
            "{}: PLOT3D Q: the Q file's dimensions 38×76×38",
            post_q.display()
        )),
        "{msg}"
    );

    // A NaN density at point 100 (the Q file's header is 12 bytes of dimensions and 16 of
    // free-stream values, big-endian f32, no record markers): read, and counted.
    let mut nan = full.clone();
    nan[28 + 4 * 100..28 + 4 * 101].copy_from_slice(&f32::NAN.to_be_bytes());
    std::fs::write(&q, &nan).unwrap();
    let mesh = read_file(&grid);
    assert!(mesh.point_data()[0].values[100].is_nan());
    let listed = mesh.non_finite_arrays();
    assert_eq!(
        (listed.len(), listed[0].name.as_str(), listed[0].count),
        (1, "Density", 1)
    );

    // The grid cut short, the Q file whole: the grid's error.
    std::fs::write(&q, &full).unwrap();
    std::fs::write(&grid, &bytes("combxyz.bin")[..5000]).unwrap();
    let msg = read_file_error(&grid, None);
    assert!(
        msg.starts_with(&format!("{}: PLOT3D grid", grid.display())),
        "{msg}"
    );
}

/// The mesh `io::read_file` gives for a grid (its Q file found by name).
fn read_file(grid: &Path) -> Mesh {
    cylvol::io::read_file(grid, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// Upper-case names, as old PLOT3D data often has them: `COMBXYZ.BIN` finds `COMBQ.BIN`, or
/// `COMBq.bin` (another case for the `q` or the extension), preferring the grid's own case
/// style when both are there; never a file whose name differs before the `xyz`
/// (`combq.bin`), nor a folder.
#[test]
fn q_files_are_found_whatever_the_case_of_q_and_the_extension() {
    let arrays = |m: &Mesh| m.point_data().len();
    let dir = copies(&[("combxyz.bin", "COMBXYZ.BIN"), ("combq.bin", "COMBQ.BIN")]);
    let grid = dir.path().join("COMBXYZ.BIN");
    assert_eq!(read_file(&grid).point_data(), comb().point_data());

    // A second candidate in another case style: the wrong dimensions, so taking it fails.
    std::fs::write(dir.path().join("COMBq.bin"), bytes("postq.bin")).unwrap();
    assert_eq!(arrays(&read_file(&grid)), 3);
    std::fs::remove_file(dir.path().join("COMBQ.BIN")).unwrap();
    let msg = read_file_error(&grid, None);
    assert!(
        msg.starts_with(&format!("{}:", dir.path().join("COMBq.bin").display())),
        "{msg}"
    );
    std::fs::copy(data("combq.bin"), dir.path().join("COMBq.bin")).unwrap();
    assert_eq!(read_file(&grid).point_data(), comb().point_data());

    // Lower-case grid, upper-case extension on the Q file.
    let dir = copies(&[("combxyz.bin", "combxyz.bin"), ("combq.bin", "combq.BIN")]);
    assert_eq!(arrays(&read_file(&dir.path().join("combxyz.bin"))), 3);

    // Not another prefix's Q file, not a folder.
    let dir = copies(&[("combxyz.bin", "COMBXYZ.BIN"), ("combq.bin", "combq.bin")]);
    std::fs::create_dir(dir.path().join("COMBQ.BIN")).unwrap();
    assert_eq!(arrays(&read_file(&dir.path().join("COMBXYZ.BIN"))), 0);
}

/// Runs the `cylvol` program: its status and standard error.
fn cylvol(args: &[&str]) -> (i32, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cylvol"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A Q file given for anything but a PLOT3D grid is refused, naming both (it was ignored):
/// a legacy file, a VTU file, a synthetic dataset; through the library and the program.
#[test]
fn q_file_for_other_inputs_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let vtu = dir.path().join("inlet.vtu");
    let inlet = cylvol::input::load("pump-inlet:1000", &ReadOptions::default()).unwrap();
    cylvol::io::write_file(&inlet, &vtu).unwrap();
    let q = data("combq.bin");
    let with_q = ReadOptions {
        q_file: Some(q.clone().into()),
    };
    let hexa = data("hexa.vtk");
    for (input, what) in [
        (hexa.as_str(), "a legacy VTK file"),
        (vtu.to_str().unwrap(), "a VTU file"),
        ("pump-inlet:1000", "a synthetic dataset"),
    ] {
        let msg = message(cylvol::input::load(input, &with_q));
        let want = format!("{q}: a PLOT3D Q file goes with a PLOT3D grid, but");
        assert!(msg.starts_with(&want) && msg.ends_with(what), "{msg}");
        let (status, stderr) = cylvol(&["info", input, "--q", &q]);
        assert_eq!(status, 1, "{stderr}");
        assert!(stderr.contains(&want) && stderr.contains(what), "{stderr}");
    }
    // Still read as before without it.
    assert!(cylvol::input::load(&hexa, &ReadOptions::default()).is_ok());
}

/// A grid with no Q file beside it and none given says so on standard error, with the names
/// looked for (it was silent), before `render`'s "no point or cell array" error, so that error
/// can be understood; with a Q file beside it or given, nothing is said.
#[test]
fn missing_q_file_is_said_on_standard_error() {
    let dir = copies(&[("combxyz.bin", "combxyz.bin")]);
    let grid = dir.path().join("combxyz.bin");
    let grid = grid.to_str().unwrap();
    let note = format!(
        "cylvol: no PLOT3D Q file found beside {grid} (looked for combq.bin, combq.BIN, \
         combQ.bin, combQ.BIN): the mesh has no point arrays to render; give its Q file with \
         --q FILE\n"
    );
    let (status, stderr) = cylvol(&["info", grid]);
    assert_eq!(status, 0, "{stderr}");
    assert!(stderr.starts_with(&note), "{stderr}");
    let png = dir.path().join("out.png");
    let args = [
        "render",
        grid,
        "-o",
        png.to_str().unwrap(),
        "--size",
        "16x16",
    ];
    let (status, stderr) = cylvol(&args);
    assert_eq!(status, 1, "{stderr}");
    let error = stderr.find("cylvol: error:").expect("an error");
    assert!(
        stderr[error..].contains("no point or cell array to render"),
        "{stderr}"
    );
    assert!(stderr[..error].starts_with(&note), "{stderr}");

    let q = data("combq.bin");
    let (status, stderr) = cylvol(&["info", grid, "--q", &q]);
    assert!(status == 0 && !stderr.contains("Q file"), "{stderr}");
    std::fs::copy(&q, dir.path().join("combq.bin")).unwrap();
    let (status, stderr) = cylvol(&["info", grid]);
    assert!(status == 0 && !stderr.contains("Q file"), "{stderr}");

    let mut notes = Vec::new();
    let input = cylvol::input::Input::parse(&data("postxyz.bin")).unwrap();
    let mesh = input
        .load_logged(&ReadOptions::default(), &mut |n| notes.push(n))
        .unwrap();
    assert!(
        notes.is_empty() && mesh.point_data().len() == 3,
        "{notes:?}"
    );
}

/// `bytes` with `n` more bytes of `fill` after them.
fn padded(bytes: &[u8], n: usize, fill: u8) -> Vec<u8> {
    let mut out = bytes.to_vec();
    out.resize(bytes.len() + n, fill);
    out
}

/// The combustor's Q file with 484 zero bytes after its last record (what a file of VTK's
/// test data carries): read as the file without them, VTK's reader reading the same, and the
/// note says how many bytes were ignored, through the library and the program (it was
/// refused: "matches no layout"). Bytes that are not zero are said to be so.
#[test]
fn bytes_after_a_q_file_are_ignored_and_said() {
    let q = padded(&bytes("combq.bin"), 484, 0);
    let mut notes = Vec::new();
    let mesh = plot3d::read_logged(&bytes("combxyz.bin"), Some(&q), &mut |n| notes.push(n))
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(mesh == comb(), "the mesh of the file without the padding");
    assert_eq!(
        notes,
        ["the Q file: 484 bytes after its last record (all zero) were ignored"]
    );
    let dir = copies(&[("combxyz.bin", "combxyz.bin")]);
    let (grid, q_path) = (dir.path().join("combxyz.bin"), dir.path().join("combq.bin"));
    std::fs::write(&q_path, &q).unwrap();
    compare_files_with_vtk(&grid, &q_path, &mesh);
    let (status, stderr) = cylvol(&["info", grid.to_str().unwrap()]);
    assert_eq!(status, 0, "{stderr}");
    let note = format!(
        "cylvol: {}: 484 bytes after its last record (all zero) were ignored\n",
        q_path.display()
    );
    assert!(stderr.starts_with(&note), "{stderr}");

    for (n, fill, said) in [
        (1, 0, "1 byte after its last record (all zero) was ignored"),
        (
            4096,
            0x3f,
            "4096 bytes after its last record (not all zero) were ignored",
        ),
    ] {
        let mut notes = Vec::new();
        let q = padded(&bytes("combq.bin"), n, fill);
        let mesh = plot3d::read_logged(&bytes("combxyz.bin"), Some(&q), &mut |n| notes.push(n))
            .unwrap_or_else(|e| panic!("{n} bytes: {e}"));
        assert!(mesh == comb(), "{n} bytes");
        assert_eq!(notes, [format!("the Q file: {said}")]);
    }
}

/// With record markers, which hold every record's length, bytes after the last record of a
/// grid file or a Q file are ignored, in every byte order, precision and grid-count layout,
/// as VTK's reader ignores them (compared with VTK on two of them).
#[test]
fn bytes_after_records_are_ignored_in_grid_and_q_files() {
    let g = parse_grid(&bytes("postxyz.bin"));
    let s = parse_solution(&bytes("postq.bin"));
    let reference = post();
    let dir = tempfile::tempdir().unwrap();
    for (k, opts) in [
        Opts {
            markers: true,
            ..Opts::default()
        },
        Opts {
            markers: true,
            little: true,
            f64: true,
            count: Some(1),
        },
    ]
    .into_iter()
    .enumerate()
    {
        let xyz = padded(&write_grid(&g, true, opts), 484, 0);
        let q = padded(&write_solution(&s, s.dims, opts), 1000, 7);
        let layout = plot3d::detect_layout(&xyz).unwrap();
        assert_eq!((layout.trailing_bytes, layout.iblank), (484, true));
        let mut notes = Vec::new();
        let mesh = plot3d::read_logged(&xyz, Some(&q), &mut |n| notes.push(n)).unwrap();
        assert!(mesh == reference, "layout {k}");
        assert_eq!(
            notes,
            [
                "the grid file: 484 bytes after its last record (all zero) were ignored",
                "the Q file: 1000 bytes after its last record (not all zero) were ignored"
            ]
        );
        let (xyz_path, q_path) = (dir.path().join("xyz.bin"), dir.path().join("q.bin"));
        std::fs::write(&xyz_path, &xyz).unwrap();
        std::fs::write(&q_path, &q).unwrap();
        compare_files_with_vtk(&xyz_path, &q_path, &mesh);
    }
}

/// A grid file without record markers has no measure of its layout but its size: with bytes
/// after its data it is refused (VTK's reader cannot tell its settings either), the error
/// saying what it reads as if they are padding. A Q file cut short in another layout than
/// its grid's (`f64` values for an `f32` grid), or with a block's worth of bytes after its
/// data, is not taken for a padded file in its grid's layout.
#[test]
fn bytes_after_data_that_nothing_proves_are_padding_are_refused() {
    let xyz = padded(&bytes("combxyz.bin"), 484, 0);
    let msg = message(plot3d::read(&xyz, Some(&bytes("combq.bin"))));
    assert!(
        msg.contains("the file has 564796 bytes, which matches no layout")
            && msg.contains("if its last 484 bytes are padding, it reads as f32, a file of 564312")
            && msg.contains("(truncate -s 564312 FILE)"),
        "{msg}"
    );
    let xyz = padded(&bytes("postxyz.bin"), 484, 0);
    let msg = message(plot3d::read(&xyz, None));
    assert!(
        msg.contains("reads as f32 + IBLANK, a file of 1755916 bytes"),
        "{msg}"
    );

    let s = parse_solution(&bytes("combq.bin"));
    let f64_q = write_solution(
        &s,
        s.dims,
        Opts {
            f64: true,
            ..Opts::default()
        },
    );
    assert!(plot3d::read(&bytes("combxyz.bin"), Some(&f64_q)).unwrap() == comb());
    let cut = &f64_q[..f64_q.len() - 4];
    let msg = message(plot3d::read(&bytes("combxyz.bin"), Some(cut)));
    assert!(
        msg.starts_with("PLOT3D Q: the file has") && msg.contains("matches no layout"),
        "{msg}"
    );
    let block = 57 * 33 * 25 * 4;
    for n in [block - 1, block] {
        let q = padded(&bytes("combq.bin"), n, 0);
        let read = plot3d::read(&bytes("combxyz.bin"), Some(&q));
        assert_eq!(read.is_ok(), n < block, "{n} bytes after the data");
    }
}

/// A grid file of several grids (each a whole grid), with a grid count.
fn write_grids(grids: &[&Grid], opts: Opts) -> Vec<u8> {
    let mut w = Writer::new(opts);
    w.record(|w| w.int(grids.len() as u32));
    w.record(|w| {
        grids
            .iter()
            .for_each(|g| g.dims.iter().for_each(|&d| w.int(d)))
    });
    for g in grids {
        w.record(|w| {
            g.coords.iter().for_each(|&c| w.float(c));
            let blank = g.iblank.as_ref().expect("every grid has IBLANK");
            blank.iter().for_each(|&b| w.int(b as u32));
        });
    }
    w.out
}

/// The Q file of several grids, with a grid count.
fn write_solutions(solutions: &[&Solution], opts: Opts) -> Vec<u8> {
    let mut w = Writer::new(opts);
    w.record(|w| w.int(solutions.len() as u32));
    w.record(|w| {
        solutions
            .iter()
            .for_each(|s| s.dims.iter().for_each(|&d| w.int(d)))
    });
    for s in solutions {
        w.record(|w| s.values[..4].iter().for_each(|&v| w.float(v)));
        w.record(|w| s.values[4..].iter().for_each(|&v| w.float(v)));
    }
    w.out
}

/// Per block of VTK's multi-block output: points, visible cells (IBLANK hides a cell with a
/// blanked point), and some points' coordinates and values; the count of reader errors.
const VTK_BLOCKS: &str = r#"
import vtk, sys, json
r = vtk.vtkMultiBlockPLOT3DReader()
errors = []
r.AddObserver('ErrorEvent', lambda o, e: errors.append(e))
r.AutoDetectFormatOn()
r.SetXYZFileName(sys.argv[1])
r.SetQFileName(sys.argv[2])
r.Update()
o = r.GetOutput()
s = lambda v: [repr(x) for x in v]
blocks = []
for k in range(o.GetNumberOfBlocks()):
    b = o.GetBlock(k)
    n = b.GetNumberOfPoints()
    ids = [0, 1, 777, n // 2, n - 1]
    pd = b.GetPointData()
    blocks.append({"points": n,
                   "visible": sum(1 for c in range(b.GetNumberOfCells()) if b.IsCellVisible(c)),
                   "ids": ids, "coords": [s(b.GetPoint(i)) for i in ids],
                   "density": [repr(pd.GetArray("Density").GetValue(i)) for i in ids],
                   "energy": [repr(pd.GetArray("StagnationEnergy").GetValue(i)) for i in ids]})
print(json.dumps({"errors": len(errors), "blocks": blocks}))
"#;

/// A two-grid file — the LOX post, then the combustor with some points blanked — and its Q
/// file, with and without record markers (and, with them, bytes after the data): read as one
/// mesh, the combustor's points and cells after the post's, IBLANK applied to each grid, the
/// arrays joined, as VTK's reader reads the two blocks; the note says the grids were joined
/// (multi-grid files were refused).
#[test]
fn multi_grid_files_read_as_one_mesh_as_vtk_reads_their_blocks() {
    let post_grid = parse_grid(&bytes("postxyz.bin"));
    let mut comb_grid = parse_grid(&bytes("combxyz.bin"));
    let comb_points = comb_grid.coords.len() / 3;
    let mut blank = vec![1i32; comb_points];
    for p in [0, 5000, 20_000] {
        blank[p] = 0;
    }
    comb_grid.iblank = Some(blank);
    let post_q = parse_solution(&bytes("postq.bin"));
    let comb_q = parse_solution(&bytes("combq.bin"));
    let (post, comb) = (post(), comb());
    let dir = tempfile::tempdir().unwrap();
    for opts in [
        Opts::default(),
        Opts {
            markers: true,
            little: true,
            ..Opts::default()
        },
    ] {
        let mut xyz = write_grids(&[&post_grid, &comb_grid], opts);
        let mut q = write_solutions(&[&post_q, &comb_q], opts);
        if opts.markers {
            xyz = padded(&xyz, 484, 0);
            q = padded(&q, 484, 0);
        }
        let layout = plot3d::detect_layout(&xyz).unwrap();
        assert_eq!(layout.grids, [[38, 76, 38], [57, 33, 25]]);
        let mut notes = Vec::new();
        let mesh = plot3d::read_logged(&xyz, Some(&q), &mut |n| notes.push(n))
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(
            notes.contains(
                &"the grid file: its 2 grids are joined into one mesh, each grid's points and \
                  cells after those of the grid before it (VTK's reader gives them as 2 blocks)"
                    .to_string()
            ),
            "{notes:?}"
        );
        let n_post = post.point_count();
        assert_eq!(mesh.point_count(), n_post + comb_points);
        assert_eq!(&mesh.points()[..n_post], post.points());
        assert_eq!(&mesh.points()[n_post..], comb.points());
        assert_eq!(&mesh.cells()[..post.cell_count()], post.cells());
        // A corner point blanks 1 cell, an edge or face point 2 or 4.
        let comb_cells = &mesh.cells()[post.cell_count()..];
        assert!(comb_cells.len() < comb.cell_count());
        for (a, name) in mesh
            .point_data()
            .iter()
            .zip(["Density", "Momentum", "StagnationEnergy"])
        {
            assert_eq!(a.name, name);
            let [p, c] = [&post, &comb].map(|m| {
                &m.point_data()
                    .iter()
                    .find(|b| b.name == name)
                    .unwrap()
                    .values
            });
            assert_eq!(a.values, [p.as_slice(), c.as_slice()].concat(), "{name}");
        }

        if !common::vtk_python_available() {
            continue;
        }
        let (xyz_path, q_path) = (dir.path().join("multi.xyz"), dir.path().join("multi.q"));
        std::fs::write(&xyz_path, &xyz).unwrap();
        std::fs::write(&q_path, &q).unwrap();
        let out = common::vtk_python(
            VTK_BLOCKS,
            &[xyz_path.to_str().unwrap(), q_path.to_str().unwrap()],
        );
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert_eq!(v["errors"], 0, "VTK's reader reported errors");
        let blocks = v["blocks"].as_array().unwrap();
        assert_eq!(blocks.len(), 2);
        let f = |v: &serde_json::Value| -> f64 { v.as_str().unwrap().parse().unwrap() };
        let mut base = 0;
        let mut visible = 0;
        for b in blocks {
            let ids: Vec<usize> = b["ids"]
                .as_array()
                .unwrap()
                .iter()
                .map(|i| i.as_u64().unwrap() as usize)
                .collect();
            for (k, &id) in ids.iter().enumerate() {
                let p: Vec<f64> = b["coords"][k].as_array().unwrap().iter().map(f).collect();
                assert_eq!(p, mesh.points()[base + id].to_array(), "point {id}");
                for (key, array) in [("density", 0), ("energy", 2)] {
                    assert_eq!(
                        f(&b[key][k]),
                        mesh.point_data()[array].values[base + id],
                        "{key} {id}"
                    );
                }
            }
            base += b["points"].as_u64().unwrap() as usize;
            visible += b["visible"].as_u64().unwrap() as usize;
        }
        assert_eq!(base, mesh.point_count());
        assert_eq!(visible, mesh.cell_count(), "the cells VTK shows");
    }
}

/// A Q file whose grids are not the grid file's: another count, or other dimensions.
#[test]
fn multi_grid_q_file_with_other_grids_is_refused() {
    let g = parse_grid(&bytes("combxyz.bin"));
    let mut g = g;
    g.iblank = Some(vec![1; g.coords.len() / 3]);
    let s = parse_solution(&bytes("combq.bin"));
    let xyz = write_grids(&[&g, &g], Opts::default());
    let one = write_solutions(&[&s], Opts::default());
    let msg = message(plot3d::read(&xyz, Some(&one)));
    assert!(
        msg.contains(
            "the Q file's dimensions 57×33×25 differ from the grid's 2 grids 57×33×25, 57×33×25"
        ),
        "{msg}"
    );
    assert!(plot3d::read(&xyz, Some(&write_solutions(&[&s, &s], Opts::default()))).is_ok());
}
