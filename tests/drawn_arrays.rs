//! What is drawn of the arrays a file holds, the same through every interface: arrays with
//! NaN or infinite values (as VTK writes them: legacy BINARY and VTU) are loaded, listed with
//! their counts by `cylvol info` (text and JSON) and in the load log, and refused only where a
//! render draws them, naming the array and the count (the C ABI's refusal is in `tests/ffi.rs`);
//! a constant field is drawn, with the transfer function laid about its one value, and said
//! so on standard error; a transfer function transparent over the whole field is said too.

mod common;

use std::path::{Path, PathBuf};

use cylvol::io::{self, ReadOptions};
use cylvol::Association;

/// A 2×2×2 block of hexahedra (27 points, 8 cells) as VTK writes it, legacy BINARY and VTU
/// (appended raw), with point arrays `p` (a ramp), `T` (a ramp with NaN at points 3 and 11
/// and +inf at point 20), `k` (constant 2.5) and `U` (vectors, −inf in point 7's y) and cell
/// array `q` (NaN in cell 0). Prints, as VTK reads each file back, the number of NaN and
/// infinite values of every array.
const VTK_WRITE_NON_FINITE: &str = r#"
import vtk, sys, math
out = sys.argv[1]
sg = vtk.vtkStructuredGrid(); sg.SetDimensions(3, 3, 3)
pts = vtk.vtkPoints()
for k in range(3):
    for j in range(3):
        for i in range(3):
            pts.InsertNextPoint(i, j + 0.25 * i, k)
sg.SetPoints(pts)
a = vtk.vtkAppendFilter(); a.AddInputData(sg); a.Update()
g = vtk.vtkUnstructuredGrid(); g.DeepCopy(a.GetOutput())
def array(name, comps, n, value):
    arr = vtk.vtkDoubleArray(); arr.SetName(name); arr.SetNumberOfComponents(comps)
    arr.SetNumberOfTuples(n)
    for i in range(n):
        for c in range(comps):
            arr.SetComponent(i, c, value(i, c))
    return arr
nan, inf = float('nan'), float('inf')
T = {3: nan, 11: nan, 20: inf}
g.GetPointData().AddArray(array('p', 1, 27, lambda i, c: 0.5 * i))
g.GetPointData().AddArray(array('T', 1, 27, lambda i, c: T.get(i, 300.0 + i)))
g.GetPointData().AddArray(array('k', 1, 27, lambda i, c: 2.5))
g.GetPointData().AddArray(array('U', 3, 27, lambda i, c: -inf if (i, c) == (7, 1) else i + c))
g.GetCellData().AddArray(array('q', 1, 8, lambda i, c: nan if i == 0 else i))
w = vtk.vtkUnstructuredGridWriter(); w.SetInputData(g); w.SetFileTypeToBinary()
w.SetFileName(out + '/nan.vtk'); w.Write()
w = vtk.vtkXMLUnstructuredGridWriter(); w.SetInputData(g); w.SetFileName(out + '/nan.vtu')
w.Write()
for name, r in [('nan.vtk', vtk.vtkUnstructuredGridReader()),
                ('nan.vtu', vtk.vtkXMLUnstructuredGridReader())]:
    r.SetFileName(out + '/' + name); r.Update(); o = r.GetOutput()
    for d in (o.GetPointData(), o.GetCellData()):
        for i in range(d.GetNumberOfArrays()):
            x = d.GetArray(i)
            vals = [x.GetComponent(t, c) for t in range(x.GetNumberOfTuples())
                    for c in range(x.GetNumberOfComponents())]
            bad = sum(1 for v in vals if math.isnan(v) or math.isinf(v))
            print(name, d.GetArrayName(i), bad, len(vals))
"#;

/// The two files of [`VTK_WRITE_NON_FINITE`] in a new folder, with what VTK read back
/// (`file array non-finite values` lines); `None` without VTK's Python.
fn vtk_files() -> Option<(tempfile::TempDir, Vec<PathBuf>, String)> {
    if !common::vtk_python_available() {
        return None;
    }
    let dir = tempfile::tempdir().unwrap();
    let read_back = common::vtk_python(VTK_WRITE_NON_FINITE, &[dir.path().to_str().unwrap()]);
    let files = ["nan.vtk", "nan.vtu"].map(|f| dir.path().join(f)).to_vec();
    Some((dir, files, read_back))
}

/// `cylvol ARGS`: the exit code, standard output and standard error.
fn cylvol(args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cylvol"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn text(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// The files load whole: every value where VTK has it (NaN and infinities at their indices),
/// the arrays with non-finite values listed with the counts VTK's own readers give, and a
/// default scalar that can be drawn.
#[test]
fn non_finite_values_vtk_writes_are_loaded_and_counted_as_vtk_counts_them() {
    let Some((_dir, files, read_back)) = vtk_files() else {
        return;
    };
    for path in &files {
        let mesh = io::read_file(path, &ReadOptions::default())
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!((mesh.point_count(), mesh.cell_count()), (27, 8));
        let t = &mesh
            .point_data()
            .iter()
            .find(|a| a.name == "T")
            .unwrap()
            .values;
        assert!(t[3].is_nan() && t[11].is_nan() && t[20] == f64::INFINITY);
        assert_eq!(t[4], 304.0);
        let name = path.file_name().unwrap().to_str().unwrap();
        let listed: Vec<String> = mesh
            .non_finite_arrays()
            .iter()
            .map(|a| format!("{name} {} {} {}", a.name, a.count, a.values))
            .collect();
        let vtk: Vec<&str> = read_back
            .lines()
            .filter(|l| l.starts_with(name) && !l.contains(" 0 "))
            .collect();
        assert_eq!(listed, vtk, "{name}");
        assert_eq!(
            mesh.non_finite_arrays()
                .iter()
                .map(|a| a.association)
                .collect::<Vec<_>>(),
            [Association::Point, Association::Point, Association::Cell]
        );
        assert_eq!(mesh.active_array().unwrap().name, "p", "{name}");
    }
}

/// `cylvol info` lists the arrays with NaN or infinite values and their counts, in its text
/// and in its JSON; the load log names them.
#[test]
fn info_lists_the_arrays_with_non_finite_values() {
    let Some((_dir, files, _)) = vtk_files() else {
        return;
    };
    for path in &files {
        let (code, out, err) = cylvol(&["info", text(path), "--json"]);
        assert_eq!(code, 0, "{err}");
        let info: serde_json::Value = serde_json::from_str(&out).unwrap();
        let listed: Vec<(String, String, u64, u64)> = info["non_finite"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| {
                (
                    a["association"].as_str().unwrap().to_string(),
                    a["name"].as_str().unwrap().to_string(),
                    a["count"].as_u64().unwrap(),
                    a["values"].as_u64().unwrap(),
                )
            })
            .collect();
        let want = [
            ("point", "T", 3, 27),
            ("point", "U", 1, 81),
            ("cell", "q", 1, 8),
        ]
        .map(|(a, n, c, v)| (a.to_string(), n.to_string(), c, v));
        assert_eq!(listed, want);
        assert!(
            err.contains(
                "point array 'T': 3 of 27 values are NaN or infinite: it is kept, but \
                 cannot be drawn"
            ),
            "{err}"
        );
        let (code, out, _) = cylvol(&["info", text(path)]);
        assert_eq!(code, 0);
        assert!(
            out.contains("non-finite     point array 'T': 3 of 27 values are NaN or infinite")
                && out.contains("non-finite     cell array 'q': 1 of 8 values is NaN or infinite"),
            "{out}"
        );
    }
}

/// A render of an array without such values draws; one of an array with them is refused,
/// naming the array, how many and the first, and the arrays that can be drawn; a component
/// without them draws.
#[test]
fn render_refuses_only_the_array_it_draws() {
    let Some((dir, files, _)) = vtk_files() else {
        return;
    };
    let png = dir.path().join("out.png");
    for path in &files {
        let render = |scalar: &str| {
            cylvol(&[
                "render",
                text(path),
                "--scalar",
                scalar,
                "--size",
                "24x24",
                "-o",
                text(&png),
            ])
        };
        for scalar in ["p", "U[0]", "k"] {
            let (code, _, err) = render(scalar);
            assert_eq!(code, 0, "{scalar}: {err}");
        }
        let (code, _, err) = render("T");
        assert_eq!(code, 1, "{err}");
        assert!(
            err.contains(
                "error: point array 'T' cannot be drawn: 3 of its 27 values are NaN or infinite \
                 (the first, NaN, at point 3); draw another array with --scalar (p, k)"
            ),
            "{err}"
        );
        let (code, _, err) = render("q");
        assert_eq!(code, 1);
        assert!(
            err.contains(
                "error: cell array 'q' cannot be drawn: 1 of its 8 values is NaN or \
                          infinite (the first, NaN, at cell 0)"
            ),
            "{err}"
        );
        let (code, _, err) = render("U[1]");
        assert_eq!(code, 1);
        assert!(
            err.contains("component 1 of point array 'U' cannot be drawn: 1 of its 27 values"),
            "{err}"
        );
    }
}

/// The number of pixels of a PNG that are not black.
fn lit_pixels(path: &Path) -> usize {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    buf[..info.buffer_size()]
        .chunks_exact(channels)
        .filter(|px| px[..3].iter().any(|&c| c > 0))
        .count()
}

/// A constant field (`k`, 2.5 everywhere) is drawn, the default transfer function laid
/// about its value, and standard error says so: the value, the empty range, what to do.
/// Given an opacity of zero at that value, the image is empty, and standard error says that.
#[test]
fn a_constant_field_is_drawn_and_explained() {
    let Some((dir, files, _)) = vtk_files() else {
        return;
    };
    let png = dir.path().join("k.png");
    let (code, _, err) = cylvol(&[
        "render",
        text(&files[1]),
        "--scalar",
        "k",
        "--size",
        "32x32",
        "-o",
        text(&png),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(
            "warning: the scalar k is 2.5 everywhere: its range [2.5, 2.5] is empty, so the \
             transfer function is laid over [2.4999975, 2.5000025]"
        ) && err.contains("--opacity 2.5:0.05"),
        "{err}"
    );
    assert!(!err.contains("image is empty"), "{err}");
    let lit = lit_pixels(&png);
    assert!(lit > 100, "{lit} pixels lit");

    let (code, _, err) = cylvol(&[
        "render",
        text(&files[1]),
        "--scalar",
        "k",
        "--size",
        "32x32",
        "--opacity",
        "2.5:0",
        "-o",
        text(&png),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(
            "warning: the transfer function's opacity is zero at every value of the scalar \
             (over [2.5, 2.5]): the image is empty"
        ),
        "{err}"
    );
    assert_eq!(lit_pixels(&png), 0);
}
