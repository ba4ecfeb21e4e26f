//! Legacy VTK reader and writer: the real files, agreement with VTK's own readers (through
//! `/usr/bin/python3` and `import vtk`), round trips, both `CELLS` layouts, structured grids,
//! and bad input.

mod common;

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::OnceLock;

use cylvol::io::legacy::{self, CellLayout, Encoding, LegacyOptions};
use cylvol::{CellKind, Component, DataArray, Error, Mesh, MeshError, MeshParts};
use glam::DVec3;
use serde_json::Value;

const MIXER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mixer.vtk");
const HEXA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/hexa.vtk");

fn read_path(path: &str) -> Mesh {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    legacy::read(&bytes).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn mixer() -> &'static Mesh {
    static M: OnceLock<Mesh> = OnceLock::new();
    M.get_or_init(|| read_path(MIXER))
}

fn array<'m>(arrays: &'m [DataArray], name: &str) -> &'m DataArray {
    arrays
        .iter()
        .find(|a| a.name == name)
        .unwrap_or_else(|| panic!("no array '{name}'"))
}

fn names(arrays: &[DataArray]) -> Vec<&str> {
    arrays.iter().map(|a| a.name.as_str()).collect()
}

// ---------------------------------------------------------------------------------------------
// VTK through Python

/// Reads a legacy file with VTK's reader (everything it holds) and prints a JSON summary.
const VTK_SUMMARY: &str = r#"
import sys, json, vtk
path = sys.argv[1]
with open(path, 'rb') as f:
    head = f.read(4096)
structured = b'UNSTRUCTURED_GRID' not in head and b'STRUCTURED_GRID' in head
r = vtk.vtkStructuredGridReader() if structured else vtk.vtkUnstructuredGridReader()
r.SetFileName(path)
r.ReadAllScalarsOn(); r.ReadAllVectorsOn(); r.ReadAllNormalsOn(); r.ReadAllFieldsOn()
r.Update()
g = r.GetOutput()
types = {}
for i in range(g.GetNumberOfCells()):
    t = g.GetCellType(i)
    types[str(t)] = types.get(str(t), 0) + 1
def arrays(d):
    out = []
    for i in range(d.GetNumberOfArrays()):
        a = d.GetArray(i)
        if a is None:
            continue
        n = a.GetNumberOfComponents()
        ranges = [list(a.GetRange(k)) for k in range(n)]
        if n > 1:
            ranges.append(list(a.GetRange(-1)))
        out.append({'name': a.GetName(), 'components': n, 'tuples': a.GetNumberOfTuples(),
                    'ranges': ranges})
    return out
print(json.dumps({'points': g.GetNumberOfPoints(), 'cells': g.GetNumberOfCells(),
                  'bounds': list(g.GetBounds()) if g.GetNumberOfPoints() else [],
                  'cell_types': types, 'point_arrays': arrays(g.GetPointData()),
                  'cell_arrays': arrays(g.GetCellData())}))
"#;

fn vtk_summary(path: &Path) -> Value {
    let text = common::vtk_python(VTK_SUMMARY, &[path.to_str().unwrap()]);
    serde_json::from_str(&text).expect("JSON from python")
}

fn close(ours: f64, theirs: f64, what: &str) {
    let scale = ours.abs().max(theirs.abs());
    assert!(
        (ours - theirs).abs() <= 1e-9 * scale,
        "{what}: ours {ours}, VTK {theirs}"
    );
}

/// Checks our mesh against VTK's summary of the same file: counts and cell types exactly,
/// bounds and every component's range (and vectors' magnitude range) to 1e-9 relative.
fn assert_matches_vtk(ours: &Mesh, vtk: &Value) {
    assert_eq!(vtk["points"].as_u64(), Some(ours.point_count() as u64));
    assert_eq!(vtk["cells"].as_u64(), Some(ours.cell_count() as u64));
    let mut types = BTreeMap::new();
    for (kind, count) in ours.kind_counts() {
        if count > 0 {
            types.insert(kind.vtk_type().to_string(), count as u64);
        }
    }
    let vtk_types: BTreeMap<String, u64> = vtk["cell_types"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| (k.clone(), v.as_u64().unwrap()))
        .collect();
    assert_eq!(vtk_types, types, "cell types");
    let bounds: Vec<f64> = vtk["bounds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    for (i, (o, t)) in ours.bounds().iter().zip(&bounds).enumerate() {
        close(*o, *t, &format!("bounds[{i}]"));
    }
    assert_eq!(bounds.len(), 6);
    for (key, arrays) in [
        ("point_arrays", ours.point_data()),
        ("cell_arrays", ours.cell_data()),
    ] {
        let theirs = vtk[key].as_array().unwrap();
        let mut their_names: Vec<&str> =
            theirs.iter().map(|a| a["name"].as_str().unwrap()).collect();
        let mut our_names = names(arrays);
        their_names.sort();
        our_names.sort();
        assert_eq!(our_names, their_names, "{key}");
        for t in theirs {
            let name = t["name"].as_str().unwrap();
            let a = array(arrays, name);
            assert_eq!(
                t["components"].as_u64(),
                Some(a.components as u64),
                "{name}"
            );
            assert_eq!(t["tuples"].as_u64(), Some(a.tuples() as u64), "{name}");
            let ranges = t["ranges"].as_array().unwrap();
            for (k, r) in ranges.iter().enumerate() {
                let component = if k < a.components {
                    Component::Index(k)
                } else {
                    Component::Magnitude
                };
                let ours = a.range(component).unwrap();
                close(
                    ours[0],
                    r[0].as_f64().unwrap(),
                    &format!("{key} {name}[{k}] min"),
                );
                close(
                    ours[1],
                    r[1].as_f64().unwrap(),
                    &format!("{key} {name}[{k}] max"),
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The real files

#[test]
fn mixer_has_the_documented_counts_and_arrays() {
    let m = mixer();
    assert_eq!(m.point_count(), 37_843);
    assert_eq!(m.cell_count(), 33_600);
    assert_eq!(m.kind_counts()[0], (CellKind::Hexahedron, 33_600));
    let expected = ["k", "nut", "omega", "p", "U", "Urel"];
    assert_eq!(names(m.point_data()), expected);
    assert_eq!(names(m.cell_data()), expected);
    for a in m.point_data().iter().chain(m.cell_data()) {
        let comps = if a.name.starts_with('U') { 3 } else { 1 };
        assert_eq!(a.components, comps, "{}", a.name);
    }
    // tests/data/README.md's rounded figures; the exact ones are checked against VTK below.
    let [lo, hi] = array(m.point_data(), "p")
        .range(Component::Index(0))
        .unwrap();
    assert!(
        (lo + 44.25).abs() < 0.01 && (hi - 74.65).abs() < 0.01,
        "{lo} {hi}"
    );
    let b = m.bounds();
    assert!(
        (b[5] - 0.2).abs() < 1e-6 && (b[1] - 0.1).abs() < 1e-6,
        "{b:?}"
    );
}

#[test]
fn mixer_point_p_range_matches_vtk_to_1e6() {
    if !common::vtk_python_available() {
        return;
    }
    let script = "import vtk,sys\nr=vtk.vtkUnstructuredGridReader()\nr.SetFileName(sys.argv[1])\n\
                  r.Update()\nlo,hi=r.GetOutput().GetPointData().GetArray('p').GetRange()\n\
                  print(repr(lo), repr(hi))";
    let out = common::vtk_python(script, &[MIXER]);
    let v: Vec<f64> = out.split_whitespace().map(|s| s.parse().unwrap()).collect();
    let ours = array(mixer().point_data(), "p")
        .range(Component::Index(0))
        .unwrap();
    assert!((ours[0] - v[0]).abs() < 1e-6 && (ours[1] - v[1]).abs() < 1e-6);
}

#[test]
fn hexa_is_ascii_hexahedra_with_point_scalars() {
    let m = read_path(HEXA);
    assert_eq!(m.cell_count(), 10_648);
    assert_eq!(m.point_count(), 12_167);
    assert_eq!(m.kind_counts()[0].1, 10_648);
    assert_eq!(names(m.point_data()), ["scalars"]);
    assert!(m.cell_data().is_empty());
}

#[test]
fn real_files_agree_with_vtk() {
    if !common::vtk_python_available() {
        return;
    }
    assert_matches_vtk(mixer(), &vtk_summary(Path::new(MIXER)));
    assert_matches_vtk(&read_path(HEXA), &vtk_summary(Path::new(HEXA)));
}

/// The start of a script that has VTK write `sys.argv[1]`'s grid again into the folder
/// `sys.argv[2]` (`src`, `out`): VTK reads the file with every array, into `g`.
const VTK_READS_SRC: &str = r#"
import sys, vtk
src, out = sys.argv[1], sys.argv[2]
r = vtk.vtkUnstructuredGridReader(); r.SetFileName(src)
r.ReadAllScalarsOn(); r.ReadAllVectorsOn(); r.ReadAllFieldsOn(); r.Update()
g = r.GetOutput()"#;

/// Runs `body` after [`VTK_READS_SRC`] on the mixer, with a new folder as `out`: the folder
/// and what the script printed; `None` (the test skipped) without VTK.
fn vtk_rewrites_the_mixer(body: &str) -> Option<(tempfile::TempDir, String)> {
    if !common::vtk_python_available() {
        return None;
    }
    let dir = tempfile::tempdir().unwrap();
    let script = VTK_READS_SRC.to_string() + body;
    let out = common::vtk_python(&script, &[MIXER, dir.path().to_str().unwrap()]);
    Some((dir, out))
}

/// VTK 9.1 writes the mixer again: its default (VTK 5.1 layout, with METADATA blocks when
/// arrays carry range information) in binary and ASCII, and the classic layout (version 4.2).
#[test]
fn files_vtk_writes_read_the_same_in_both_cell_layouts() {
    let script = format!(
        r#"
g.GetPoints().GetData().GetRange(-1)
for i in range(g.GetPointData().GetNumberOfArrays()):
    g.GetPointData().GetArray(i).GetRange(-1)
{four_layouts}
print(vtk.vtkUnstructuredGridWriter().GetFileVersion())
"#,
        four_layouts = vtk_writes_four_layouts()
    );
    let Some((dir, default_version)) = vtk_rewrites_the_mixer(&script) else {
        return;
    };
    assert_eq!(
        default_version.trim(),
        "51",
        "VTK 9.1's default legacy version"
    );
    let reference = mixer();
    for name in ["v51_binary", "v51_ascii", "v42_binary", "v42_ascii"] {
        let path = dir.path().join(format!("{name}.vtk"));
        let bytes = std::fs::read(&path).unwrap();
        let text = String::from_utf8_lossy(&bytes[..200]);
        assert_eq!(
            text.contains("Version 5.1"),
            name.starts_with("v51"),
            "{name}: {text}"
        );
        // Points and arrays carry range information, which VTK writes as METADATA blocks.
        assert!(bytes.windows(9).any(|w| w == b"METADATA\n"), "{name}");
        let m = legacy::read(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.cells(), reference.cells(), "{name}");
        assert_eq!(m.kinds(), reference.kinds(), "{name}");
        if name.ends_with("binary") {
            assert_eq!(m.points(), reference.points(), "{name}");
            for (ours, theirs) in [
                (m.point_data(), reference.point_data()),
                (m.cell_data(), reference.cell_data()),
            ] {
                assert_eq!(ours.len(), theirs.len(), "{name}");
                for a in theirs {
                    assert_eq!(array(ours, &a.name), a, "{name}: array {}", a.name);
                }
            }
        }
        // VTK 9.1 writes ASCII floats with 6 significant digits: compare with what VTK reads.
        assert_matches_vtk(&m, &vtk_summary(&path));
    }
}

/// VTK writes the mixer with ghost flags (as a parallel writer's ghost layer and blanking
/// leave them): the cells flagged as another piece's or hidden go, those with other flags
/// stay, and neither ghost array is kept, in both encodings and both cell layouts.
#[test]
fn ghost_cells_vtk_writes_are_dropped() {
    let script = VTK_WRITE.to_string()
        + r#"
cells = g.AllocateCellGhostArray()
for c in range(g.GetNumberOfCells()):
    # DUPLICATECELL (1) every 7th, HIDDENCELL (32) every 11th, REFINEDCELL (4) every 5th.
    cells.SetValue(c, (1 if c % 7 == 0 else 0) | (32 if c % 11 == 0 else 0) | (4 if c % 5 == 0 else 0))
points = g.AllocatePointGhostArray()
for p in range(0, g.GetNumberOfPoints(), 3):
    points.SetValue(p, 1)
write('v51_binary', True, None)
write('v42_ascii', False, 42)
"#;
    let Some((dir, _)) = vtk_rewrites_the_mixer(&script) else {
        return;
    };
    let reference = mixer();
    let kept: Vec<usize> = (0..reference.cell_count())
        .filter(|c| c % 7 != 0 && c % 11 != 0)
        .collect();
    for name in ["v51_binary", "v42_ascii"] {
        let bytes = std::fs::read(dir.path().join(format!("{name}.vtk"))).unwrap();
        assert!(
            bytes.windows(12).any(|w| w == b"vtkGhostType"),
            "{name}: VTK wrote no ghost array"
        );
        let m = legacy::read(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.cell_count(), kept.len(), "{name}");
        let cells: Vec<[u32; 8]> = kept.iter().map(|&c| reference.cells()[c]).collect();
        assert!(m.cells() == &cells[..], "{name}: other cells");
        assert_eq!(m.points().len(), reference.points().len(), "{name}");
        assert_eq!(
            names(m.point_data()),
            names(reference.point_data()),
            "{name}"
        );
        assert_eq!(names(m.cell_data()), names(reference.cell_data()), "{name}");
        for a in reference.cell_data() {
            let k = a.components;
            let expected: Vec<f64> = kept
                .iter()
                .flat_map(|&c| a.values[c * k..(c + 1) * k].iter().copied())
                .collect();
            let ours = &array(m.cell_data(), &a.name).values;
            assert_eq!(ours.len(), expected.len(), "{name}: {}", a.name);
            if name.ends_with("binary") {
                assert_eq!(ours, &expected, "{name}: {}", a.name);
            }
        }
    }
}

/// Defines `write(name, binary, version)` in a script: VTK 9.1's legacy writer writes the
/// grid `g` to `out/NAME.vtk`, binary or ASCII, in VTK 5.1's cell layout (version `None`) or
/// version 4.2's (`42`).
const VTK_WRITE: &str = r#"
def write(name, binary, version):
    w = vtk.vtkUnstructuredGridWriter(); w.SetInputData(g)
    w.SetFileName(out + '/' + name + '.vtk')
    if binary: w.SetFileTypeToBinary()
    else: w.SetFileTypeToASCII()
    if version: w.SetFileVersion(version)
    w.Write()
"#;

/// The four legacy layouts VTK 9.1 writes (binary or ASCII, VTK 5.1's cell layout or version
/// 4.2's), as a script that defines [`VTK_WRITE`]'s `write(name, binary, version)`, which
/// later lines may call too, and calls it for each.
fn vtk_writes_four_layouts() -> String {
    VTK_WRITE.to_string()
        + r#"
for name, binary, version in [('v51_binary', True, None), ('v51_ascii', False, None),
                              ('v42_binary', True, 42), ('v42_ascii', False, 42)]:
    write(name, binary, version)
"#
}

/// Our reader on a file VTK wrote from the mixer with arrays added: both the whole-file and
/// the block-by-block reader give the mixer (VTK's ASCII files with VTK's rounding, so their
/// points and arrays are compared with what VTK reads), and every numeric array VTK's reader
/// gives.
fn read_like_vtk(path: &Path, name: &str) -> Mesh {
    let bytes = std::fs::read(path).unwrap();
    let m = legacy::read(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
    let from_file = legacy::read_file(path).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert!(from_file == m, "{name}: read_file gives another mesh");
    let reference = mixer();
    assert_eq!(m.cells(), reference.cells(), "{name}");
    assert_eq!(m.kinds(), reference.kinds(), "{name}");
    if name.ends_with("binary") {
        assert_eq!(m.points(), reference.points(), "{name}");
    }
    assert_matches_vtk(&m, &vtk_summary(path));
    m
}

/// VTK writes string arrays — a case name in field data (with a space, an empty one, and one
/// of 20,000 characters), a label per point (empty ones, 60- to 69-character ones: 1- and
/// 2-byte length headers), a tag per cell, cell pedigree ids — and a variant array, in all four
/// layouts. Both readers skip them and read the mixer and the numeric arrays VTK's reader
/// gives; before, the whole file was refused ("'string' arrays are not supported"). Cut inside
/// the point labels, either reader says where it ended.
#[test]
fn string_arrays_vtk_writes_are_skipped() {
    let body = r#"
def strings(name, n, value):
    s = vtk.vtkStringArray(); s.SetName(name)
    for i in range(n):
        s.InsertNextValue(value(i))
    return s
g.GetFieldData().AddArray(strings('case name', 3, lambda i: ['mixer run 7', '', 'x' * 20000][i]))
g.GetPointData().AddArray(strings('zone label', g.GetNumberOfPoints(),
    lambda i: '' if i % 5 == 0 else 'y' * (60 + i % 10) if i % 3 == 0 else 'blade %d' % (i % 7)))
g.GetCellData().AddArray(strings('tag', g.GetNumberOfCells(), lambda i: 'c%d' % i))
g.GetCellData().SetPedigreeIds(strings('ids', g.GetNumberOfCells(), lambda i: 'cell %d' % i))
v = vtk.vtkVariantArray(); v.SetName('notes')
for x in (3, 'a b', 2.5):
    v.InsertNextValue(vtk.vtkVariant(x))
g.GetFieldData().AddArray(v)
"#
    .to_string()
        + &vtk_writes_four_layouts();
    let Some((dir, _)) = vtk_rewrites_the_mixer(&body) else {
        return;
    };
    for name in ["v51_binary", "v51_ascii", "v42_binary", "v42_ascii"] {
        let path = dir.path().join(format!("{name}.vtk"));
        let bytes = std::fs::read(&path).unwrap();
        let has = |what: &[u8]| bytes.windows(what.len()).any(|w| w == what);
        assert!(has(b"zone%20label 1 37843 string\n"), "{name}");
        assert!(has(b"PEDIGREE_IDS ids string\n") && has(b"notes 1 3 variant\n"));
        if name.ends_with("binary") {
            // "mixer run 7", "", then 20,000 bytes: 1- and 4-byte length headers; and a
            // 64-character label's 2-byte one.
            assert!(has(b"\xcbmixer run 7\xc0\x40\x00\x4e\x20xxx"), "{name}");
            assert!(has(&[&[0x80, 64][..], &[b'y'; 64]].concat()), "{name}");
        } else {
            assert!(has(b"mixer%20run%207\n\nxxx"), "{name}");
        }
        let m = read_like_vtk(&path, name);
        assert_eq!(names(m.point_data()), names(mixer().point_data()), "{name}");
        assert_eq!(names(m.cell_data()), names(mixer().cell_data()), "{name}");

        let start = bytes
            .windows(28)
            .position(|w| w == b"zone%20label 1 37843 string\n")
            .unwrap()
            + 28;
        for k in 1..8 {
            let cut = &bytes[..start + k * 10_000];
            let message = read_error_message(&legacy::read(cut).unwrap_err());
            assert!(
                message.contains("file ends inside FIELD array 'zone label' after")
                    && message.contains("of 37843 tuples"),
                "{name}, cut {k}: {message}"
            );
            let cut_file = dir.path().join("cut.vtk");
            std::fs::write(&cut_file, cut).unwrap();
            let from_file = legacy::read_file(&cut_file).unwrap_err().to_string();
            assert!(from_file.ends_with(&message), "{from_file} / {message}");
        }
    }
}

/// VTK writes bit arrays — dataset field flags, point scalars, a cell array — in all four
/// layouts, and, in ASCII, a 2-component point array and 3-component cell vectors. Both
/// readers read them as the 0s and 1s VTK set (VTK's reader gives them to the pipeline as
/// numeric arrays, with the names and ranges compared here), beside the mixer's own; before,
/// the whole file was refused ("'bit' arrays are not supported"). Cut inside the point
/// scalars, either reader says where.
///
/// VTK 9.1's writer puts a multi-component bit array in a BINARY file as one bit a tuple
/// (4,200 bytes for 33,600 × 3 bits) where its reader reads them all, so VTK's reader cannot
/// read such a file back (it fails on the next keyword and drops what follows); ours says
/// where it fails. The test checks that quirk is still there.
#[test]
fn bit_arrays_vtk_writes_read_as_zeros_and_ones() {
    let body = r#"
def bits(name, n, comps, value):
    b = vtk.vtkBitArray(); b.SetName(name); b.SetNumberOfComponents(comps)
    for i in range(n * comps):
        b.InsertNextValue(value(i))
    return b
np, nc = g.GetNumberOfPoints(), g.GetNumberOfCells()
g.GetFieldData().AddArray(bits('flags', 3, 1, lambda i: i != 1))
g.GetPointData().SetScalars(bits('wet', np, 1, lambda i: i % 3 == 0))
g.GetCellData().AddArray(bits('marks', nc, 1, lambda i: i % 11 == 0))
"#
    .to_string()
        + &vtk_writes_four_layouts()
        + r#"
g.GetPointData().AddArray(bits('pair', np, 2, lambda i: i % 5 < 2))
g.GetCellData().SetVectors(bits('bv', nc, 3, lambda i: i % 7 == 1))
for name, binary, version in [('multi_v51_ascii', False, None), ('multi_v42_ascii', False, 42),
                              ('multi_v51_binary', True, None)]:
    write(name, binary, version)
"#;
    let Some((dir, _)) = vtk_rewrites_the_mixer(&body) else {
        return;
    };
    let pattern = |n: usize, set: fn(usize) -> bool| -> Vec<f64> {
        (0..n).map(|i| f64::from(u8::from(set(i)))).collect()
    };
    let (np, nc) = (mixer().point_count(), mixer().cell_count());
    for name in [
        "v51_binary",
        "v51_ascii",
        "v42_binary",
        "v42_ascii",
        "multi_v51_ascii",
        "multi_v42_ascii",
    ] {
        let path = dir.path().join(format!("{name}.vtk"));
        let bytes = std::fs::read(&path).unwrap();
        let has = |what: &[u8]| bytes.windows(what.len()).any(|w| w == what);
        assert!(
            has(b"SCALARS wet bit\n") && has(b"flags 1 3 bit\n"),
            "{name}"
        );
        let m = read_like_vtk(&path, name);
        let mut expected = vec![
            (m.point_data(), "wet", pattern(np, |i| i % 3 == 0)),
            (m.cell_data(), "marks", pattern(nc, |i| i % 11 == 0)),
        ];
        if name.starts_with("multi") {
            assert!(
                has(b"VECTORS bv bit\n") && has(b"pair 2 37843 bit\n"),
                "{name}"
            );
            expected.push((m.point_data(), "pair", pattern(2 * np, |i| i % 5 < 2)));
            expected.push((m.cell_data(), "bv", pattern(3 * nc, |i| i % 7 == 1)));
        }
        for (arrays, array_name, values) in expected {
            assert!(
                array(arrays, array_name).values == values,
                "{name}: {array_name}"
            );
        }

        let header = b"SCALARS wet bit\nLOOKUP_TABLE default\n";
        let start = bytes
            .windows(header.len())
            .position(|w| w == header)
            .unwrap()
            + header.len();
        let cut = &bytes[..start + 1000];
        let message = read_error_message(&legacy::read(cut).unwrap_err());
        let expected = if name.ends_with("binary") {
            "file ends inside point SCALARS 'wet' after 8000 of 37843 tuples"
        } else {
            "file ends inside point SCALARS 'wet' after"
        };
        assert!(
            message.contains(expected) && message.contains("of 37843 tuples"),
            "{name}: {message}"
        );
        let cut_file = dir.path().join("cut.vtk");
        std::fs::write(&cut_file, cut).unwrap();
        let from_file = legacy::read_file(&cut_file).unwrap_err().to_string();
        assert!(from_file.ends_with(&message), "{from_file} / {message}");
    }

    // VTK's quirk: one bit a tuple of the 3-component cell vectors, then the next keyword.
    let path = dir.path().join("multi_v51_binary.vtk");
    let bytes = std::fs::read(&path).unwrap();
    let header = b"VECTORS bv bit\n";
    let start = bytes
        .windows(header.len())
        .position(|w| w == header)
        .unwrap()
        + header.len();
    assert!(
        bytes[start + nc / 8..].starts_with(b"\nFIELD FieldData"),
        "VTK's writer now writes every bit of a multi-component bit array: test such binary \
         files as the others"
    );
    let message = read_error_message(&legacy::read(&bytes).unwrap_err());
    assert!(
        message.contains("unknown keyword") && message.contains("in cell data"),
        "{message}"
    );
    let from_file = legacy::read_file(&path).unwrap_err().to_string();
    assert!(from_file.ends_with(&message), "{from_file} / {message}");
}

/// Bits written by hand, as text: VTK's reader makes every integer but 0 a 1; so does ours.
#[test]
fn bits_by_hand_read_as_vtk_reads_them() {
    let data = "POINT_DATA 8\nSCALARS s bit\nLOOKUP_TABLE default\n0 1 2 -1 0 7 0 1\n";
    let text = cube(CUBE_POINTS, CUBE_CELLS, CUBE_TYPES, data);
    let m = legacy::read(text.as_bytes()).unwrap();
    let ours = &array(m.point_data(), "s").values;
    assert_eq!(ours, &[0., 1., 1., 1., 0., 1., 0., 1.]);
    if !common::vtk_python_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bits.vtk");
    std::fs::write(&path, &text).unwrap();
    let script = "import vtk,sys\nr=vtk.vtkUnstructuredGridReader()\nr.SetFileName(sys.argv[1])\n\
                  r.Update()\na=r.GetOutput().GetPointData().GetArray('s')\n\
                  print(a.GetClassName(), *[a.GetValue(i) for i in range(8)])";
    let out = common::vtk_python(script, &[path.to_str().unwrap()]);
    let mut words = out.split_whitespace();
    assert_eq!(words.next(), Some("vtkBitArray"));
    let theirs: Vec<f64> = words.map(|w| w.parse().unwrap()).collect();
    assert_eq!(ours, &theirs);
}

// ---------------------------------------------------------------------------------------------
// Writing

/// One cell of each kind, apart, each with positive Jacobians; point scalars (two), a point
/// vector, a 2-component point array, a name with a space, and cell scalars.
fn small_mesh() -> Mesh {
    let mut points = Vec::new();
    let mut cells = Vec::new();
    let mut kinds = Vec::new();
    let mut add = |kind: CellKind, pts: &[[f64; 3]]| {
        let base = points.len() as u32;
        points.extend(pts.iter().map(|p| DVec3::from_array(*p)));
        let ids: Vec<u32> = (0..pts.len() as u32).map(|i| base + i).collect();
        cells.push(kind.collapse(&ids));
        kinds.push(kind);
    };
    add(
        CellKind::Hexahedron,
        &[
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
            [0., 0., 1.],
            [1., 0., 1.2],
            [1., 1., 1.],
            [0., 1., 1.],
        ],
    );
    add(
        CellKind::Wedge,
        &[
            [2., 0., 0.],
            [2., 1., 0.],
            [3., 0., 0.],
            [2., 0., 1.],
            [2., 1., 1.],
            [3., 0., 1.],
        ],
    );
    add(
        CellKind::Pyramid,
        &[
            [4., 0., 0.],
            [5., 0., 0.],
            [5., 1., 0.],
            [4., 1., 0.],
            [4.5, 0.5, 1.],
        ],
    );
    add(
        CellKind::Tetrahedron,
        &[[6., 0., 0.], [7., 0., 0.], [6., 1., 0.], [6., 0., 1.]],
    );
    let f = |p: &DVec3| p.x * 0.1 + 2.0 * p.y - p.z / 3.0;
    let point_data = vec![
        DataArray::vector(
            "velocity",
            points.iter().flat_map(|p| [p.x, p.y * p.y, -p.z]).collect(),
        ),
        DataArray::scalar("p", points.iter().map(f).collect()),
        DataArray {
            name: "uv".into(),
            components: 2,
            values: points
                .iter()
                .flat_map(|p| [p.x + 1e-7, p.y - 3e12])
                .collect(),
        },
        DataArray::scalar(
            "total pressure",
            points.iter().map(|p| f(p) * 1e-30).collect(),
        ),
    ];
    let cell_data = vec![DataArray::scalar("zone", vec![1.5, -2.0, 3.25, 4.0])];
    Mesh::from_parts(MeshParts {
        points,
        cells,
        kinds,
        point_data,
        cell_data,
    })
    .expect("the small mesh is valid")
}

const ALL_OPTIONS: [(Encoding, CellLayout); 4] = [
    (Encoding::Binary, CellLayout::Classic),
    (Encoding::Binary, CellLayout::Vtk51),
    (Encoding::Ascii, CellLayout::Classic),
    (Encoding::Ascii, CellLayout::Vtk51),
];

fn written(mesh: &Mesh, encoding: Encoding, cell_layout: CellLayout) -> Vec<u8> {
    let mut bytes = Vec::new();
    legacy::write_with(
        mesh,
        &mut bytes,
        &LegacyOptions {
            encoding,
            cell_layout,
        },
    )
    .unwrap();
    bytes
}

#[test]
fn write_then_read_gives_the_same_mesh() {
    let mesh = small_mesh();
    assert_eq!(mesh.kind_counts().map(|(_, n)| n), [1, 1, 1, 1]);
    for (encoding, layout) in ALL_OPTIONS {
        let bytes = written(&mesh, encoding, layout);
        let back = legacy::read(&bytes).unwrap_or_else(|e| panic!("{encoding:?} {layout:?}: {e}"));
        assert_eq!(back, mesh, "{encoding:?} {layout:?}");
    }
    let mut plain = Vec::new();
    legacy::write(&mesh, &mut plain).unwrap();
    assert_eq!(plain, written(&mesh, Encoding::Binary, CellLayout::Classic));
    assert!(plain.starts_with(b"# vtk DataFile Version 3.0\n"));
    let mut text = Vec::new();
    legacy::write_ascii(&mesh, &mut text).unwrap();
    assert_eq!(text, written(&mesh, Encoding::Ascii, CellLayout::Classic));
}

#[test]
fn the_mixer_round_trips_through_our_writer() {
    let m = mixer();
    for (encoding, layout) in [
        (Encoding::Binary, CellLayout::Classic),
        (Encoding::Ascii, CellLayout::Vtk51),
    ] {
        let back = legacy::read(&written(m, encoding, layout)).unwrap();
        assert_eq!(&back, m, "{encoding:?} {layout:?}");
    }
}

#[test]
fn vtk_reads_what_we_write() {
    if !common::vtk_python_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mesh = small_mesh();
    for (encoding, layout) in ALL_OPTIONS {
        let path = dir.path().join(format!("{encoding:?}_{layout:?}.vtk"));
        std::fs::write(&path, written(&mesh, encoding, layout)).unwrap();
        assert_matches_vtk(&mesh, &vtk_summary(&path));
    }
    // VTK's default reader settings (no ReadAll…) still see every array: only one SCALARS and
    // one VECTORS per section, the rest as FIELD arrays.
    let path = dir.path().join("default.vtk");
    std::fs::write(&path, written(&mesh, Encoding::Binary, CellLayout::Classic)).unwrap();
    let script = "import vtk,sys\nr=vtk.vtkUnstructuredGridReader()\nr.SetFileName(sys.argv[1])\n\
                  r.Update()\npd=r.GetOutput().GetPointData()\n\
                  print(' '.join(sorted(pd.GetArrayName(i).replace(' ','_') for i in range(pd.GetNumberOfArrays()))))";
    assert_eq!(
        common::vtk_python(script, &[path.to_str().unwrap()]).trim(),
        "p total_pressure uv velocity"
    );
}

// ---------------------------------------------------------------------------------------------
// Structured grids and hand-written layouts

/// A 3 × 4 × 2 curvilinear grid (a bent slab), with point and cell scalars.
fn structured_ascii() -> String {
    let mut s = String::from(
        "# vtk DataFile Version 3.0\nbent slab\nASCII\nDATASET STRUCTURED_GRID\nDIMENSIONS 3 4 2\nPOINTS 24 double\n",
    );
    for k in 0..2 {
        for j in 0..4 {
            for i in 0..3 {
                let (r, t, z) = (1.0 + i as f64 * 0.5, j as f64 * 0.3, k as f64 * 0.7);
                s += &format!("{} {} {}\n", r * t.cos(), r * t.sin(), z);
            }
        }
    }
    s += "CELL_DATA 6\nSCALARS c int\nLOOKUP_TABLE default\n0 1 2 3 4 5\n";
    s += "POINT_DATA 24\nSCALARS id float 1\nLOOKUP_TABLE default\n";
    s += &(0..24).map(|i| i.to_string()).collect::<Vec<_>>().join(" ");
    s += "\n";
    s
}

#[test]
fn structured_grid_gives_the_product_of_cell_dimensions() {
    let text = structured_ascii();
    let m = legacy::read(text.as_bytes()).unwrap();
    assert_eq!(m.cell_count(), 2 * 3);
    assert_eq!(m.point_count(), 24);
    assert!(m.kinds().iter().all(|&k| k == CellKind::Hexahedron));
    assert_eq!(array(m.cell_data(), "c").values, [0., 1., 2., 3., 4., 5.]);
    // The first cell's corners are grid points (0,0,0), (1,0,0), (1,1,0), (0,1,0) and above.
    let mut first = m.cells()[0];
    first.sort();
    assert_eq!(first, [0, 1, 3, 4, 12, 13, 15, 16]);
    if common::vtk_python_available() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("slab.vtk");
        std::fs::write(&path, &text).unwrap();
        assert_matches_vtk(&m, &vtk_summary(&path));
    }
}

#[test]
fn structured_grid_written_by_vtk_in_binary() {
    if !common::vtk_python_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sector.vtk");
    let script = r#"
import sys, math, vtk
ni, nj, nk = 5, 7, 4
pts = vtk.vtkPoints(); pts.SetDataTypeToDouble()
s = vtk.vtkDoubleArray(); s.SetName('swirl')
v = vtk.vtkFloatArray(); v.SetName('flow'); v.SetNumberOfComponents(3)
for k in range(nk):
    for j in range(nj):
        for i in range(ni):
            r, t, z = 1 + 0.25 * i, 0.2 * j, 0.3 * k
            pts.InsertNextPoint(r * math.cos(t), r * math.sin(t), z)
            s.InsertNextValue(r * t - z)
            v.InsertNextTuple3(-math.sin(t), math.cos(t), 0.1 * z)
g = vtk.vtkStructuredGrid(); g.SetDimensions(ni, nj, nk); g.SetPoints(pts)
g.GetPointData().SetScalars(s); g.GetPointData().SetVectors(v)
c = vtk.vtkIntArray(); c.SetName('cell_id')
for i in range(g.GetNumberOfCells()):
    c.InsertNextValue(i)
g.GetCellData().AddArray(c)
w = vtk.vtkStructuredGridWriter(); w.SetInputData(g); w.SetFileName(sys.argv[1])
w.SetFileTypeToBinary(); w.Write()
"#;
    common::vtk_python(script, &[path.to_str().unwrap()]);
    let m = legacy::read(&std::fs::read(&path).unwrap()).unwrap();
    assert_eq!(m.cell_count(), 4 * 6 * 3);
    assert_eq!(array(m.point_data(), "flow").components, 3);
    assert_matches_vtk(&m, &vtk_summary(&path));
}

/// VTK writes a structured grid with blanking (`BlankPoint`, `BlankCell`: `vtkGhostType`
/// point and cell flags), binary and ASCII: the cells VTK shows (`IsCellVisible`, as its
/// triangulation for the unstructured ray caster keeps them) are the ones read, by their
/// point ids: every cell about a hidden point goes, as well as the hidden cell (the cells
/// about hidden points were kept).
#[test]
fn structured_grid_blanking_vtk_writes_hides_the_cells_vtk_hides() {
    if !common::vtk_python_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let script = r#"
import sys, vtk
ni, nj, nk = 6, 5, 4
pts = vtk.vtkPoints()
for k in range(nk):
    for j in range(nj):
        for i in range(ni):
            pts.InsertNextPoint(i + 0.1 * j, j, k + 0.05 * i)
g = vtk.vtkStructuredGrid(); g.SetDimensions(ni, nj, nk); g.SetPoints(pts)
s = vtk.vtkFloatArray(); s.SetName('s')
for n in range(g.GetNumberOfPoints()): s.InsertNextValue(0.5 * n)
g.GetPointData().SetScalars(s)
for (i, j, k) in [(2, 2, 1), (5, 0, 3)]:
    g.BlankPoint(i + ni * (j + nj * k))
g.BlankCell(17)
for name, binary in [('blank_binary', True), ('blank_ascii', False)]:
    w = vtk.vtkStructuredGridWriter(); w.SetInputData(g)
    w.SetFileName(sys.argv[1] + '/' + name + '.vtk')
    if binary: w.SetFileTypeToBinary()
    w.Write()
for c in range(g.GetNumberOfCells()):
    if g.IsCellVisible(c):
        ids = g.GetCell(c).GetPointIds()
        print(' '.join(str(x) for x in sorted(ids.GetId(k) for k in range(8))))
"#;
    let out = common::vtk_python(script, &[dir.path().to_str().unwrap()]);
    let visible: Vec<Vec<u32>> = out
        .lines()
        .map(|l| l.split(' ').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(visible.len(), 5 * 4 * 3 - 8 - 1 - 1);
    for name in ["blank_binary", "blank_ascii"] {
        let m = read_path(dir.path().join(format!("{name}.vtk")).to_str().unwrap());
        let mut ours: Vec<Vec<u32>> = m
            .cells()
            .iter()
            .map(|c| {
                let mut ids = c.to_vec();
                ids.sort_unstable();
                ids
            })
            .collect();
        ours.sort();
        let mut theirs = visible.clone();
        theirs.sort();
        assert_eq!(ours, theirs, "{name}");
        assert_eq!(m.point_count(), 6 * 5 * 4, "{name}: every point kept");
        assert_eq!(names(m.point_data()), ["s"], "{name}: no ghost array");
    }
}

/// Hand-written files carry several attribute blocks of one kind, which VTK's writer never
/// writes (it writes one SCALARS and puts the rest in a FIELD): three SCALARS blocks (one
/// with a custom LOOKUP_TABLE, defined after it, one of two components), COLOR_SCALARS,
/// VECTORS, and two cell SCALARS. Every numeric block is read as VTK's reader reads it with
/// ReadAllScalarsOn (COLOR_SCALARS, which VTK reads only on request, and lookup tables
/// dropped), and the first SCALARS block is the active scalar, as VTK's are.
#[test]
fn several_scalar_blocks_read_as_vtk_reads_them_all() {
    let text = "# vtk DataFile Version 3.0\nseveral scalar blocks\nASCII\n\
DATASET UNSTRUCTURED_GRID\nPOINTS 8 float\n0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1\n\
CELLS 1 9\n8 0 1 2 3 4 5 6 7\nCELL_TYPES 1\n12\nPOINT_DATA 8\n\
SCALARS p float 1\nLOOKUP_TABLE default\n0 1 2 3 4 5 6 7\n\
SCALARS T double\nLOOKUP_TABLE warm\n10 11 12 13 14 15 16 17\n\
LOOKUP_TABLE warm 2\n0 0 0 1 1 1 1 1\n\
COLOR_SCALARS rgb 3\n0 0 0 1 1 1 0 0 0 1 1 1 0 0 0 1 1 1 0 0 0 1 1 1\n\
SCALARS k int 2\nLOOKUP_TABLE default\n1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16\n\
VECTORS U float\n0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1\n\
CELL_DATA 1\nSCALARS cp float\nLOOKUP_TABLE default\n3\n\
SCALARS cq float\nLOOKUP_TABLE default\n4\n";
    let m = legacy::read(text.as_bytes()).unwrap();
    assert_eq!(names(m.point_data()), ["p", "T", "k", "U"]);
    assert_eq!(names(m.cell_data()), ["cp", "cq"]);
    assert_eq!(array(m.point_data(), "k").components, 2);
    assert_eq!(m.active_array().unwrap().name, "p");
    if common::vtk_python_available() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("several.vtk");
        std::fs::write(&path, text).unwrap();
        assert_matches_vtk(&m, &vtk_summary(&path));
    }
}

/// One unit cube: 8 points, one hexahedron, in the classic layout; pieces replaceable.
fn cube(points: &str, cells: &str, types: &str, data: &str) -> String {
    format!(
        "# vtk DataFile Version 2.0\ncube\nASCII\nDATASET UNSTRUCTURED_GRID\n{points}{cells}{types}{data}"
    )
}

const CUBE_POINTS: &str =
    "POINTS 8 float\n0 0 0  1 0 0  1 1 0  0 1 0\n0 0 1  1 0 1  1 1 1  0 1 1\n";
const CUBE_CELLS: &str = "CELLS 1 9\n8 0 1 2 3 4 5 6 7\n";
const CUBE_TYPES: &str = "CELL_TYPES 1\n12\n";

#[test]
fn vtk51_layout_by_hand_and_metadata_blocks() {
    let cells = "CELLS 3 11\nOFFSETS vtktypeint64\n0 8 11\nCONNECTIVITY vtktypeint64\n\
                 0 1 2 3 4 5 6 7\n0 1 4\n";
    let metadata = "METADATA\nINFORMATION 2\nNAME L2_NORM_RANGE LOCATION vtkDataArray\n\
                    DATA 2 0 1.73\nNAME L2_NORM_FINITE_RANGE LOCATION vtkDataArray\nDATA 2 0 1.73\n\n";
    let points = format!("{CUBE_POINTS}{metadata}");
    let data = format!(
        "FIELD FieldData 2\nTimeValue 1 1 double\n0.5\nNULL_ARRAY\n\
         POINT_DATA 8\nFIELD FieldData 2\nNULL_ARRAY\nt 1 8 double\n0 1 2 3 4 5 6 7\n{metadata}\
         NORMALS n float\n{}\nTENSORS tt float\n{}\nLOOKUP_TABLE lut 2\n0 0 0 1 1 1 1 1\n\
         CELL_DATA 2\nVECTORS v double\n1 0 0 0 1 0\n",
        "0 0 1 ".repeat(8),
        "1 0 0 0 1 0 0 0 1 ".repeat(8)
    );
    let triangle_types = "CELL_TYPES 2\n12 5\n";
    let e = legacy::read(cube(&points, cells, triangle_types, &data).as_bytes()).unwrap_err();
    assert!(e.to_string().contains("1 × triangle"), "{e}");
    // Without the triangle: a tetrahedron needs four ids.
    let cells = cells
        .replace("CELLS 3 11", "CELLS 3 12")
        .replace("0 8 11", "0 8 12")
        .replace("0 1 4\n", "0 1 3 4\n");
    let m = legacy::read(cube(&points, &cells, "CELL_TYPES 2\n12 10\n", &data).as_bytes())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.kind_counts().map(|(_, n)| n), [1, 0, 0, 1]);
    assert_eq!(names(m.point_data()), ["t", "n"]);
    assert_eq!(names(m.cell_data()), ["v"]);
    assert_eq!(m.cells()[1], [0, 1, 3, 3, 4, 4, 4, 4]);
}

// ---------------------------------------------------------------------------------------------
// Bad input

fn read_err(text: &str) -> Error {
    legacy::read(text.as_bytes()).expect_err("this input must be rejected")
}

fn read_error_message(e: &Error) -> String {
    match e {
        Error::Read(r) => r.to_string(),
        other => panic!("expected a read error, got {other:?}"),
    }
}

#[test]
fn the_cube_reads() {
    let m = legacy::read(cube(CUBE_POINTS, CUBE_CELLS, CUBE_TYPES, "").as_bytes()).unwrap();
    assert_eq!(m.cells()[0], [0, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(m.cell_count(), 1);
}

#[test]
fn truncated_mixer_is_always_an_error_with_an_offset() {
    let bytes = std::fs::read(MIXER).unwrap();
    for i in 0..200 {
        let cut = i * bytes.len() / 200;
        match legacy::read(&bytes[..cut]) {
            Ok(_) => panic!("cut at {cut} read as a mesh"),
            Err(e) => {
                let message = e.to_string();
                assert!(message.contains("at byte"), "cut at {cut}: {message}");
            }
        }
    }
    // Inside POINTS (37,843 × 3 big-endian floats): the number of whole points there.
    let header = b"POINTS 37843 float\n";
    let start = bytes
        .windows(header.len())
        .position(|w| w == header)
        .unwrap()
        + header.len();
    let e = legacy::read(&bytes[..start + 12 * 1000 + 5]).unwrap_err();
    let message = read_error_message(&e);
    assert!(
        message.contains("file ends inside POINTS after 1000 of 37843 points"),
        "{message}"
    );
}

#[test]
fn ascii_truncation_in_cells_says_how_far_it_got() {
    let text = cube(CUBE_POINTS, "CELLS 2 18\n8 0 1 2 3 4 5 6 7\n8 0 1", "", "");
    let message = read_error_message(&read_err(&text));
    assert!(
        message.contains("file ends inside CELLS after 12 of 18 values"),
        "{message}"
    );
    assert!(message.contains(", line 10)"), "{message}");
}

#[test]
fn triangle_is_reported_by_name_and_count() {
    let cells = "CELLS 3 17\n8 0 1 2 3 4 5 6 7\n3 0 1 2\n3 4 5 6\n";
    let e = read_err(&cube(CUBE_POINTS, cells, "CELL_TYPES 3\n12 5 5\n", ""));
    match &e {
        Error::Mesh(MeshError::UnsupportedCellTypes { types }) => {
            assert_eq!(types, &[(5, "triangle", 2)])
        }
        other => panic!("{other:?}"),
    }
    assert!(e.to_string().contains("2 × triangle"));
}

#[test]
fn nan_point_is_a_non_finite_point_error() {
    let points = CUBE_POINTS.replace("0 1 0\n", "0 nan 0\n");
    match read_err(&cube(&points, CUBE_CELLS, CUBE_TYPES, "")) {
        Error::Mesh(MeshError::NonFinitePoint { index, .. }) => assert_eq!(index, 3),
        other => panic!("{other:?}"),
    }
}

#[test]
fn out_of_range_id_is_reported() {
    let cells = CUBE_CELLS.replace(" 7\n", " 8\n");
    match read_err(&cube(CUBE_POINTS, &cells, CUBE_TYPES, "")) {
        Error::Mesh(MeshError::IndexOutOfRange { index, points, .. }) => {
            assert_eq!((index, points), (8, 8))
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn point_data_count_mismatch_is_reported_where_it_is() {
    let data = "POINT_DATA 7\nSCALARS s float\nLOOKUP_TABLE default\n1 2 3 4 5 6 7\n";
    let text = cube(CUBE_POINTS, CUBE_CELLS, CUBE_TYPES, data);
    let message = read_error_message(&read_err(&text));
    assert!(
        message.contains("POINT_DATA has 7 tuples, but the dataset has 8 points"),
        "{message}"
    );
    let offset = text.find("POINT_DATA").unwrap();
    assert!(
        message.contains(&format!("at byte {offset}, line 12")),
        "{message}"
    );
}

#[test]
fn unknown_dataset_type_and_garbage_header() {
    let text = "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 0 float\n";
    let message = read_error_message(&read_err(text));
    assert!(
        message.contains("dataset type POLYDATA is not supported"),
        "{message}"
    );
    assert!(message.contains("line 4"), "{message}");

    let message = read_error_message(&read_err("PK\x03\x04 this is a zip file"));
    assert!(
        message.contains("not a legacy VTK file") && message.contains("at byte 0"),
        "{message}"
    );
    let message = read_error_message(&read_err("# vtk DataFile Version 3.0\nx\nEBCDIC\n"));
    assert!(
        message.contains("expected ASCII or BINARY, found 'EBCDIC'"),
        "{message}"
    );
    assert!(legacy::read(b"").is_err());
}

#[test]
fn bad_numbers_and_keywords_name_their_line() {
    let points = CUBE_POINTS.replace("1 1 1", "1 x 1");
    let message = read_error_message(&read_err(&cube(&points, CUBE_CELLS, CUBE_TYPES, "")));
    assert!(
        message.contains("'x' in POINTS is not a number") && message.contains("line 7"),
        "{message}"
    );
    let message = read_error_message(&read_err(&cube(
        CUBE_POINTS,
        CUBE_CELLS,
        "POLYGONS 1 4\n",
        "",
    )));
    assert!(
        message.contains("unexpected keyword 'POLYGONS'"),
        "{message}"
    );
    let message = read_error_message(&read_err(&cube(CUBE_POINTS, CUBE_CELLS, "", "")));
    assert!(message.contains("no CELL_TYPES"), "{message}");
    let data = "POINT_DATA 8\nSCALARS s bit\nLOOKUP_TABLE default\n0 1 0 1 0 1 0 x\n";
    let message = read_error_message(&read_err(&cube(CUBE_POINTS, CUBE_CELLS, CUBE_TYPES, data)));
    assert!(
        message.contains("'x' in point SCALARS 's' is not an integer (bits are 0 or 1)")
            && message.contains("line 15"),
        "{message}"
    );
    let message = read_error_message(&read_err(&cube(
        "POINTS 8 bit\n0 0 0\n",
        CUBE_CELLS,
        CUBE_TYPES,
        "",
    )));
    assert!(
        message.contains("POINTS: 'bit' values are not allowed here"),
        "{message}"
    );
    // Strings are no scalars: VTK's reader takes no attribute from them either.
    let data = "POINT_DATA 8\nSCALARS s string\nLOOKUP_TABLE default\na\nb\nc\nd\ne\nf\ng\nh\n";
    let message = read_error_message(&read_err(&cube(CUBE_POINTS, CUBE_CELLS, CUBE_TYPES, data)));
    assert!(
        message.contains("point SCALARS 's': 'string' values are not numbers")
            && message.contains("line 13"),
        "{message}"
    );
}

#[test]
fn huge_claimed_counts_fail_fast_without_allocating() {
    for format in ["ASCII", "BINARY"] {
        let text = format!(
            "# vtk DataFile Version 3.0\nx\n{format}\nDATASET UNSTRUCTURED_GRID\nPOINTS 4000000000000000 double\n0 0 0\n"
        );
        let message = read_error_message(&read_err(&text));
        assert!(
            message.contains("POINTS") && message.contains("of 4000000000000000 points")
                || message.contains("too large"),
            "{format}: {message}"
        );
        let text = cube(CUBE_POINTS, "CELLS 1000000000000 9000000000000\n", "", "")
            .replace("ASCII", format);
        assert!(legacy::read(text.as_bytes()).is_err());
    }
    let text = "# vtk DataFile Version 3.0\nx\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 18446744073709551615 double\n";
    assert!(read_error_message(&read_err(text)).contains("number of points"));
}

#[test]
fn binary_written_file_cut_anywhere_is_an_error() {
    let mut bytes = Vec::new();
    legacy::write(&small_mesh(), &mut bytes).unwrap();
    // A cut gives an error, unless it falls just before a section the mesh can do without.
    let optional = ["CELL_DATA", "POINT_DATA", "SCALARS", "VECTORS", "FIELD"];
    let mut ok_cuts = 0;
    for cut in 0..bytes.len() - 1 {
        if legacy::read(&bytes[..cut]).is_ok() {
            let rest = String::from_utf8_lossy(&bytes[cut..]);
            let rest = rest.trim_start();
            assert!(
                optional.iter().any(|k| rest.starts_with(k)),
                "cut at {cut} of {} read as a mesh",
                bytes.len()
            );
            ok_cuts += 1;
        }
    }
    // Seven places, each just before and just after a newline: before CELL_DATA, after
    // `CELL_DATA 4`, before POINT_DATA, after `POINT_DATA 23`, and after each of the first three
    // point arrays.
    assert_eq!(ok_cuts, 14);
}

/// Not a timing assertion: prints how long reading a 2.1 M-hexahedron binary file takes.
/// Run with `cargo test --release --test legacy_vtk -- --ignored --nocapture`.
#[test]
#[ignore]
fn print_read_time_of_large_binary_file() {
    let (ni, nj, nk) = (130usize, 130usize, 126usize);
    let mut points = Vec::with_capacity(ni * nj * nk);
    for k in 0..nk {
        for j in 0..nj {
            for i in 0..ni {
                let (r, t, z) = (1.0 + i as f64 * 0.01, j as f64 * 0.01, k as f64 * 0.01);
                points.push(DVec3::new(r * t.cos(), r * t.sin(), z));
            }
        }
    }
    let cells = cylvol::io::structured::hexahedra([ni, nj, nk], &points);
    let n = cells.len();
    let p: Vec<f64> = points.iter().map(|q| q.x * q.y + q.z).collect();
    let mesh = Mesh::from_parts(MeshParts {
        kinds: vec![CellKind::Hexahedron; n],
        cells,
        point_data: vec![DataArray::scalar("p", p)],
        points,
        cell_data: vec![],
    })
    .unwrap();
    let mut bytes = Vec::new();
    legacy::write(&mesh, &mut bytes).unwrap();
    let start = std::time::Instant::now();
    let back = legacy::read(&bytes).unwrap();
    let elapsed = start.elapsed();
    assert_eq!(back.cell_count(), n);
    let start = std::time::Instant::now();
    Mesh::from_parts(back.into_parts()).unwrap();
    eprintln!(
        "of which validation takes about {:.3} s",
        start.elapsed().as_secs_f64()
    );
    let mixer_bytes = std::fs::read(MIXER).unwrap();
    let start = std::time::Instant::now();
    legacy::read(&mixer_bytes).unwrap();
    eprintln!(
        "read {n} hexahedra ({} MB) in {:.3} s; mixer.vtk in {:.4} s",
        bytes.len() / 1_000_000,
        elapsed.as_secs_f64(),
        start.elapsed().as_secs_f64()
    );
}

/// The fuzzer's seeds are valid files, so fuzzing starts from deep inside the reader.
#[test]
fn fuzz_seeds_are_valid_files() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/fuzz/seeds/read_legacy_vtk");
    let mut seen = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let m = legacy::read(&std::fs::read(&path).unwrap())
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(m.cell_count() >= 2, "{}", path.display());
        seen += 1;
    }
    assert!(seen >= 6);
}
