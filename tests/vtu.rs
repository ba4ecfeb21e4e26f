//! VTU reader and writer: round trips in every mode, files written by VTK itself, our files read
//! by VTK, and bad input (truncation, corruption, wrong types) giving errors, never panics.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use cylvol::io::vtu::{self, ByteOrder, Encoding, HeaderType, VtuOptions};
use cylvol::{CellKind, DataArray, Error, Mesh, MeshParts};
use glam::DVec3;

fn hexa_vtk() -> &'static str {
    concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/hexa.vtk")
}

/// Two hexahedra, a wedge, a pyramid and a tetrahedron, with point scalars, a point vector
/// and a cell scalar.
fn small_mesh() -> Mesh {
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let points = vec![
        // Hexahedra: a 3×2×2 lattice, x in 0..2.
        p(0.0, 0.0, 0.0),
        p(1.0, 0.0, 0.0),
        p(2.0, 0.0, 0.0),
        p(0.0, 1.0, 0.0),
        p(1.0, 1.0, 0.0),
        p(2.0, 1.0, 0.0),
        p(0.0, 0.0, 1.0),
        p(1.0, 0.0, 1.0),
        p(2.0, 0.0, 1.0),
        p(0.0, 1.0, 1.0),
        p(1.0, 1.0, 1.0),
        p(2.0, 1.0, 1.0),
        // Wedge top (on the first hexahedron), 12..15.
        p(0.0, 0.0, 2.0),
        p(1.0, 0.0, 2.0),
        p(0.0, 1.0, 2.0),
        // Pyramid apex (on the second hexahedron), 15.
        p(1.5, 0.5, 2.1),
        // Tetrahedron beside them, 16..20.
        p(3.0, 0.0, 0.0),
        p(4.0, 0.0, 0.0),
        p(3.0, 1.0, 0.0),
        p(3.0, 0.0, 1.0),
    ];
    let vtk_cells: Vec<(CellKind, Vec<u32>)> = vec![
        (CellKind::Hexahedron, vec![0, 1, 4, 3, 6, 7, 10, 9]),
        (CellKind::Hexahedron, vec![1, 2, 5, 4, 7, 8, 11, 10]),
        (CellKind::Wedge, vec![6, 9, 7, 12, 14, 13]),
        (CellKind::Pyramid, vec![7, 8, 11, 10, 15]),
        (CellKind::Tetrahedron, vec![16, 17, 18, 19]),
    ];
    let cells = vtk_cells.iter().map(|(k, ids)| k.collapse(ids)).collect();
    let kinds = vtk_cells.iter().map(|(k, _)| *k).collect();
    let pressure = points
        .iter()
        .map(|q| q.x + 2.0 * q.y + 3.0 * q.z * q.z - 0.1)
        .collect();
    let temperature = points
        .iter()
        .map(|q| 300.0 + (q.x * 0.7).sin() * 1e-3)
        .collect();
    let velocity = points
        .iter()
        .flat_map(|q| [q.y, -q.x, 0.25 * q.z])
        .collect();
    Mesh::from_parts(MeshParts {
        points,
        cells,
        kinds,
        point_data: vec![
            DataArray::scalar("p", pressure),
            DataArray::scalar("T <&\"'>", temperature),
            DataArray::vector("U", velocity),
        ],
        cell_data: vec![DataArray::scalar("id", vec![0.0, 1.5, 3.0, 4.5, -6.0])],
    })
    .unwrap()
}

fn all_options() -> Vec<VtuOptions> {
    let mut out = Vec::new();
    for encoding in [
        Encoding::Ascii,
        Encoding::Base64,
        Encoding::AppendedRaw,
        Encoding::AppendedBase64,
    ] {
        for zlib in [None, Some(6)] {
            for header in [HeaderType::UInt32, HeaderType::UInt64] {
                for byte_order in [ByteOrder::LittleEndian, ByteOrder::BigEndian] {
                    // Small blocks so compressed arrays span several blocks.
                    for block_size in [64, 1 << 15] {
                        out.push(VtuOptions {
                            encoding,
                            zlib,
                            header,
                            byte_order,
                            block_size,
                        });
                    }
                }
            }
        }
    }
    out
}

fn write_to_vec(mesh: &Mesh, o: &VtuOptions) -> Vec<u8> {
    let mut bytes = Vec::new();
    vtu::write_with(mesh, &mut bytes, o).unwrap();
    bytes
}

#[test]
fn round_trip_in_every_mode() {
    let mesh = small_mesh();
    let mut sizes = BTreeMap::new();
    for o in all_options() {
        let bytes = write_to_vec(&mesh, &o);
        let back = vtu::read(&bytes).unwrap_or_else(|e| panic!("{o:?}: {e}"));
        assert_eq!(back.points(), mesh.points(), "{o:?}");
        assert_eq!(back.cells(), mesh.cells(), "{o:?}");
        assert_eq!(back.kinds(), mesh.kinds(), "{o:?}");
        assert_eq!(back.point_data(), mesh.point_data(), "{o:?}");
        assert_eq!(back.cell_data(), mesh.cell_data(), "{o:?}");
        assert_eq!(back.active_scalar(), mesh.active_scalar(), "{o:?}");
        sizes.insert(format!("{:?}/{:?}", o.encoding, o.zlib), bytes.len());
    }
    // The modes really differ: base64 is larger than raw.
    assert!(sizes["AppendedBase64/None"] > sizes["AppendedRaw/None"]);
}

#[test]
fn default_write_is_appended_raw_and_reads_back() {
    let mesh = small_mesh();
    let mut bytes = Vec::new();
    vtu::write(&mesh, &mut bytes).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    assert!(text.contains("<AppendedData encoding=\"raw\">"));
    assert!(text.contains("header_type=\"UInt64\""));
    assert_eq!(vtu::read(&bytes).unwrap(), mesh);
}

#[test]
fn active_cell_scalar_round_trips() {
    let mut mesh = small_mesh();
    mesh.set_active_scalar("cell:id").unwrap();
    let back = vtu::read(&write_to_vec(&mesh, &VtuOptions::default())).unwrap();
    assert_eq!(back.active_scalar(), mesh.active_scalar());
}

#[test]
fn several_pieces_are_joined() {
    // Two copies of a one-tetrahedron piece, by hand, the second with its own point ids.
    let piece = |shift: f64, p: f64| {
        format!(
            r#"<Piece NumberOfPoints="4" NumberOfCells="1">
  <PointData Scalars="s"><DataArray type="Float32" Name="s" format="ascii">{p} 1 2 3</DataArray>
   <DataArray type="Int32" Name="only_first" format="ascii">1 1 1 1</DataArray></PointData>
  <Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">
   {shift} 0 0  {x1} 0 0  {shift} 1 0  {shift} 0 1</DataArray></Points>
  <Cells><DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 3</DataArray>
   <DataArray type="Int64" Name="offsets" format="ascii">4</DataArray>
   <DataArray type="UInt8" Name="types" format="ascii">10</DataArray></Cells></Piece>"#,
            x1 = shift + 1.0
        )
    };
    let second = piece(5.0, 9.0).replace(
        "<DataArray type=\"Int32\" Name=\"only_first\" format=\"ascii\">1 1 1 1</DataArray>",
        "",
    );
    let file = format!(
        "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid>{}\
         <Piece NumberOfPoints=\"0\" NumberOfCells=\"0\"/>{}</UnstructuredGrid></VTKFile>",
        piece(0.0, 0.0),
        second
    );
    let mesh = vtu::read(file.as_bytes()).unwrap();
    assert_eq!(mesh.point_count(), 8);
    assert_eq!(mesh.cells()[1], [4, 5, 6, 6, 7, 7, 7, 7]);
    assert_eq!(mesh.points()[5], DVec3::new(6.0, 0.0, 0.0));
    assert_eq!(
        mesh.point_data().len(),
        1,
        "arrays missing from a piece are dropped"
    );
    assert_eq!(
        mesh.point_data()[0].values,
        vec![0.0, 1.0, 2.0, 3.0, 9.0, 1.0, 2.0, 3.0]
    );
}

// ---------------------------------------------------------------------------------------------
// VTK's own reader and writer.

/// Python helper: `gen DIR HEXA` writes VTK files; `summary FILE…` prints what VTK reads.
const SCRIPT: &str = r#"
import json, sys, os
import vtk

def mixed_grid():
    pts = [(0,0,0),(1,0,0),(2,0,0),(0,1,0),(1,1,0),(2,1,0),(0,0,1),(1,0,1),(2,0,1),(0,1,1),
           (1,1,1),(2,1,1),(0,0,2),(1,0,2),(0,1,2),(1.5,0.5,2.1),(3,0,0),(4,0,0),(3,1,0),(3,0,1)]
    cells = [(vtk.VTK_HEXAHEDRON,[0,1,4,3,6,7,10,9]),(vtk.VTK_HEXAHEDRON,[1,2,5,4,7,8,11,10]),
             (vtk.VTK_WEDGE,[6,9,7,12,14,13]),(vtk.VTK_PYRAMID,[7,8,11,10,15]),
             (vtk.VTK_TETRA,[16,17,18,19])]
    g = vtk.vtkUnstructuredGrid()
    p = vtk.vtkPoints(); p.SetDataTypeToFloat()
    for q in pts: p.InsertNextPoint(*q)
    g.SetPoints(p)
    for t, ids in cells: g.InsertNextCell(t, len(ids), ids)
    pr = vtk.vtkFloatArray(); pr.SetName("pressure")
    ve = vtk.vtkFloatArray(); ve.SetName("velocity"); ve.SetNumberOfComponents(3)
    lab = vtk.vtkStringArray(); lab.SetName("labels")
    for i, q in enumerate(pts):
        pr.InsertNextValue(q[0] + 2*q[1] + 3*q[2]*q[2] + 0.1)
        ve.InsertNextTuple3(q[1], -q[0], 0.25*q[2])
        lab.InsertNextValue("point %d" % i)
    g.GetPointData().AddArray(pr); g.GetPointData().SetActiveScalars("pressure")
    g.GetPointData().AddArray(ve); g.GetPointData().AddArray(lab)
    reg = vtk.vtkIntArray(); reg.SetName("region")
    qu = vtk.vtkDoubleArray(); qu.SetName("quality")
    for i in range(len(cells)):
        reg.InsertNextValue(7 - 3*i); qu.InsertNextValue(0.5 + i/3.0)
    g.GetCellData().AddArray(reg); g.GetCellData().AddArray(qu)
    tv = vtk.vtkDoubleArray(); tv.SetName("TimeValue"); tv.InsertNextValue(1.25)
    g.GetFieldData().AddArray(tv)
    note = vtk.vtkStringArray(); note.SetName("note"); note.InsertNextValue("made by VTK")
    g.GetFieldData().AddArray(note)
    return g

def hexa(path):
    r = vtk.vtkUnstructuredGridReader(); r.SetFileName(path); r.Update()
    return r.GetOutput()

MODES = {
  "ascii": ("ascii", None, None),
  "binary": ("binary", None, False),
  "binary-zlib": ("binary", "zlib", False),
  "raw": ("appended", None, False),
  "raw-zlib": ("appended", "zlib", False),
  "b64": ("appended", None, True),
  "b64-zlib": ("appended", "zlib", True),
  "binary-lz4": ("binary", "lz4", False),
  "raw-lz4": ("appended", "lz4", False),
  "b64-lz4": ("appended", "lz4", True),
  "binary-lzma": ("binary", "lzma", False),
  "raw-lzma": ("appended", "lzma", False),
  "b64-lzma": ("appended", "lzma", True),
}

def write(grid, path, mode, header64, pieces=1):
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetInputData(grid); w.SetFileName(path)
    data, comp, encode = MODES[mode]
    {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary,
     "appended": w.SetDataModeToAppended}[data]()
    if encode is not None: w.SetEncodeAppendedData(encode)
    {None: w.SetCompressorTypeToNone, "zlib": w.SetCompressorTypeToZLib,
     "lz4": w.SetCompressorTypeToLZ4, "lzma": w.SetCompressorTypeToLZMA}[comp]()
    if header64: w.SetHeaderTypeToUInt64()
    else: w.SetHeaderTypeToUInt32()
    w.SetNumberOfPieces(pieces)
    w.SetBlockSize(256 if comp else 32768)
    assert w.Write() == 1, path

def summary(path):
    r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(path); r.Update()
    g = r.GetOutput()
    types = {}
    for i in range(g.GetNumberOfCells()):
        t = g.GetCellType(i); types[str(t)] = types.get(str(t), 0) + 1
    def arrays(d):
        out = []
        for i in range(d.GetNumberOfArrays()):
            a = d.GetAbstractArray(i)
            if not isinstance(a, vtk.vtkDataArray): continue
            out.append({"name": a.GetName(), "components": a.GetNumberOfComponents(),
                        "ranges": [[repr(v) for v in a.GetRange(k)]
                                   for k in range(a.GetNumberOfComponents())]})
        return out
    return {"points": g.GetNumberOfPoints(), "cells": g.GetNumberOfCells(), "types": types,
            "bounds": [repr(v) for v in g.GetBounds()],
            "point": arrays(g.GetPointData()), "cell": arrays(g.GetCellData())}

def pgen(out, hexa_path):
    # The cube in three pieces, each through VTK's piece extractor, with no ghost level and
    # with one (the ghost cells flagged in vtkGhostType); LZ4-compressed appended data.
    for ghost in (0, 1):
        e = vtk.vtkExtractUnstructuredGridPiece()
        r = vtk.vtkUnstructuredGridReader(); r.SetFileName(hexa_path)
        e.SetInputConnection(r.GetOutputPort())
        w = vtk.vtkXMLPUnstructuredGridWriter(); w.SetInputConnection(e.GetOutputPort())
        w.SetFileName(os.path.join(out, "cube-ghost%d.pvtu" % ghost))
        w.SetNumberOfPieces(3); w.SetStartPiece(0); w.SetEndPiece(2); w.SetGhostLevel(ghost)
        w.SetDataModeToAppended(); w.SetCompressorTypeToLZ4()
        assert w.Write() == 1

def bits(out):
    # The mixed grid with bit arrays (counts that are not multiples of 8, several components),
    # in every mode; prints the values VTK's reader gives for each file.
    g = mixed_grid()
    def bit(name, n, comps, value):
        a = vtk.vtkBitArray(); a.SetName(name); a.SetNumberOfComponents(comps)
        for i in range(n * comps): a.InsertNextValue(1 if value(i) else 0)
        return a
    n, c = g.GetNumberOfPoints(), g.GetNumberOfCells()
    g.GetPointData().AddArray(bit("wet", n, 1, lambda i: i % 3 == 0))
    g.GetPointData().AddArray(bit("pair", n, 2, lambda i: i % 5 < 2))
    g.GetCellData().AddArray(bit("marks", c, 3, lambda i: i % 7 in (1, 4)))
    g.GetFieldData().AddArray(bit("flags", 3, 1, lambda i: i != 1))
    read = {}
    for mode in MODES:
        for header64 in (False, True):
            path = os.path.join(out, "bits-%s-%d.vtu" % (mode, 64 if header64 else 32))
            write(g, path, mode, header64)
            r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(path); r.Update()
            o = r.GetOutput()
            def values(d, name):
                a = d.GetArray(name)
                assert a.GetClassName() == "vtkBitArray", a.GetClassName()
                return [a.GetValue(i) for i in range(a.GetNumberOfValues())]
            read[path] = {"wet": values(o.GetPointData(), "wet"),
                          "pair": values(o.GetPointData(), "pair"),
                          "marks": values(o.GetCellData(), "marks")}
    print(json.dumps(read))

if sys.argv[1] == "pgen":
    pgen(sys.argv[2], sys.argv[3])
elif sys.argv[1] == "bits":
    bits(sys.argv[2])
elif sys.argv[1] == "gen":
    out, hexa_path = sys.argv[2], sys.argv[3]
    m, h = mixed_grid(), hexa(hexa_path)
    for mode in MODES:
        for header64 in (False, True):
            suffix = "%s-%d.vtu" % (mode, 64 if header64 else 32)
            write(m, os.path.join(out, "mixed-" + suffix), mode, header64)
            write(h, os.path.join(out, "hexa-" + suffix), mode, header64)
    write(m, os.path.join(out, "pieces-raw-zlib.vtu"), "raw-zlib", True, pieces=3)
    write(h, os.path.join(out, "hexa-pieces-b64.vtu"), "b64", False, pieces=4)
    write(m, os.path.join(out, "pieces-b64-lzma.vtu"), "b64-lzma", False, pieces=2)
    pw = vtk.vtkXMLPolyDataWriter(); pw.SetFileName(os.path.join(out, "poly.vtp"))
    s = vtk.vtkSphereSource(); s.Update(); pw.SetInputData(s.GetOutput()); pw.Write()
else:
    print(json.dumps([summary(p) for p in sys.argv[2:]]))
"#;

/// What VTK (or we) read from a file: counts, VTK cell types, bounds, per-component ranges.
#[derive(Debug, PartialEq)]
struct Summary {
    points: usize,
    cells: usize,
    types: BTreeMap<u8, usize>,
    bounds: [f64; 6],
    point: Vec<(String, usize, Vec<[f64; 2]>)>,
    cell: Vec<(String, usize, Vec<[f64; 2]>)>,
}

fn num(v: &serde_json::Value) -> f64 {
    v.as_str().unwrap().parse().unwrap()
}

fn vtk_summaries(files: &[PathBuf]) -> Vec<Summary> {
    let mut args = vec!["summary".to_string()];
    args.extend(files.iter().map(|f| f.to_str().unwrap().to_string()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let json: serde_json::Value = serde_json::from_str(&common::vtk_python(SCRIPT, &args)).unwrap();
    let arrays = |v: &serde_json::Value| {
        v.as_array()
            .unwrap()
            .iter()
            .map(|a| {
                (
                    a["name"].as_str().unwrap().to_string(),
                    a["components"].as_u64().unwrap() as usize,
                    a["ranges"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .map(|r| [num(&r[0]), num(&r[1])])
                        .collect(),
                )
            })
            .collect()
    };
    json.as_array()
        .unwrap()
        .iter()
        .map(|s| Summary {
            points: s["points"].as_u64().unwrap() as usize,
            cells: s["cells"].as_u64().unwrap() as usize,
            types: s["types"]
                .as_object()
                .unwrap()
                .iter()
                .map(|(k, v)| (k.parse().unwrap(), v.as_u64().unwrap() as usize))
                .collect(),
            bounds: std::array::from_fn(|i| num(&s["bounds"][i])),
            point: arrays(&s["point"]),
            cell: arrays(&s["cell"]),
        })
        .collect()
}

fn our_summary(mesh: &Mesh) -> Summary {
    let arrays = |list: &[DataArray]| {
        list.iter()
            .map(|a| {
                let ranges = (0..a.components)
                    .map(|k| {
                        let it = a.values.iter().skip(k).step_by(a.components);
                        [
                            it.clone().copied().fold(f64::INFINITY, f64::min),
                            it.copied().fold(f64::NEG_INFINITY, f64::max),
                        ]
                    })
                    .collect();
                (a.name.clone(), a.components, ranges)
            })
            .collect()
    };
    let mut types = BTreeMap::new();
    for k in mesh.kinds() {
        *types.entry(k.vtk_type()).or_default() += 1;
    }
    Summary {
        points: mesh.point_count(),
        cells: mesh.cell_count(),
        types,
        bounds: mesh.bounds(),
        point: arrays(mesh.point_data()),
        cell: arrays(mesh.cell_data()),
    }
}

/// Reads a file from its bytes and as `vtu::read_file` reads it (raw appended data an array
/// at a time from the file, for files beyond its head of 64 KiB): both must agree.
fn read_file(path: &Path) -> Result<Mesh, Error> {
    let from_bytes = vtu::read(&std::fs::read(path).unwrap());
    match (&from_bytes, vtu::read_file(path)) {
        (Ok(a), Ok(b)) => assert_eq!(a, &b, "{}", path.display()),
        (Err(a), Err(b)) => assert!(b.to_string().ends_with(&a.to_string()), "{a} / {b}"),
        (a, b) => panic!(
            "{}: {a:?} from its bytes, {b:?} from the file",
            path.display()
        ),
    }
    from_bytes
}

#[test]
fn files_written_by_vtk_read_as_vtk_reads_them() {
    if !common::vtk_python_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    common::vtk_python(SCRIPT, &["gen", dir.path().to_str().unwrap(), hexa_vtk()]);
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_str().unwrap();
            name.ends_with(".vtu")
        })
        .collect();
    files.sort();
    // 13 modes (none, zlib, LZ4 and LZMA compression) × two headers × two meshes, and three
    // files in pieces.
    assert_eq!(files.len(), 55, "{files:?}");
    let expected = vtk_summaries(&files);
    for (file, want) in files.iter().zip(&expected) {
        let mesh = read_file(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let got = our_summary(&mesh);
        assert_eq!(&got, want, "{}", file.display());
        let name = file.file_name().unwrap().to_str().unwrap();
        if name.starts_with("hexa-pieces") {
            // VTK's writer repeats a non-streaming input in each of the 4 pieces.
            assert_eq!(got.types, BTreeMap::from([(12, 4 * 10_648)]), "{name}");
        } else if name.starts_with("hexa") {
            assert_eq!(got.types, BTreeMap::from([(12, 10_648)]), "{name}");
            assert_eq!(got.point[0].0, "scalars");
        } else {
            let n = if name.starts_with("pieces-raw") {
                3
            } else if name.starts_with("pieces") {
                2
            } else {
                1
            };
            assert_eq!(
                got.types,
                BTreeMap::from([(10, n), (12, 2 * n), (13, n), (14, n)])
            );
            // The string array is skipped; the numeric ones are kept, the vector whole.
            let names: Vec<&str> = mesh.point_data().iter().map(|a| a.name.as_str()).collect();
            assert_eq!(names, ["pressure", "velocity"]);
            assert_eq!(mesh.point_data()[1].components, 3);
            assert_eq!(mesh.active_array().unwrap().name, "pressure");
        }
    }

    let poly = read_file(&dir.path().join("poly.vtp"))
        .unwrap_err()
        .to_string();
    assert!(poly.contains("PolyData"), "{poly}");
}

/// VTK's XML writer writes `type="Bit"` arrays — ASCII as one number a value, binary and
/// appended data packed eight values a byte, the first in the highest bit — and its reader
/// reads them back. We read them as 0 and 1, value for value as VTK reads them, in every mode,
/// compressor and header size, for a one-, two- and three-component array whose value counts
/// are not multiples of 8 (they were skipped, while the legacy reader read them). Reading the
/// bits lowest first, or one byte late, fails this test.
#[test]
fn bit_arrays_vtk_writes_read_as_vtk_reads_them() {
    if !common::vtk_python_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let json: serde_json::Value = serde_json::from_str(&common::vtk_python(
        SCRIPT,
        &["bits", dir.path().to_str().unwrap()],
    ))
    .unwrap();
    let files = json.as_object().unwrap();
    assert_eq!(files.len(), 26);
    for (path, vtk_read) in files {
        let mesh = read_file(Path::new(path)).unwrap_or_else(|e| panic!("{path}: {e}"));
        let names: Vec<&str> = mesh.point_data().iter().map(|a| a.name.as_str()).collect();
        assert_eq!(names, ["pressure", "velocity", "wet", "pair"], "{path}");
        let ours = |arrays: &[DataArray], name: &str, components: usize| {
            let a = arrays.iter().find(|a| a.name == name).unwrap();
            assert_eq!(a.components, components, "{path}: {name}");
            a.values.clone()
        };
        for (arrays, name, components) in [
            (mesh.point_data(), "wet", 1),
            (mesh.point_data(), "pair", 2),
            (mesh.cell_data(), "marks", 3),
        ] {
            let theirs: Vec<f64> = vtk_read[name]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            assert!(
                theirs.contains(&0.0) && theirs.contains(&1.0),
                "{path}: {name}"
            );
            assert_eq!(ours(arrays, name, components), theirs, "{path}: {name}");
        }
    }
}

/// A mesh's cells as sets of corner positions (bit patterns), sorted: equal for two meshes
/// holding the same cells, whatever their order and point numbering.
fn cell_set(mesh: &Mesh) -> Vec<[[u64; 3]; 8]> {
    let mut cells: Vec<[[u64; 3]; 8]> = (0..mesh.cell_count())
        .map(|c| {
            let mut corners = mesh.cell_corners(c).map(|p| p.to_array().map(f64::to_bits));
            corners.sort_unstable();
            corners
        })
        .collect();
    cells.sort_unstable();
    cells
}

/// A small render of the mesh on the fast path (cell to cell through face neighbours), with
/// its counters.
fn fast_render(mesh: &Mesh) -> (cylvol::render::Image, cylvol::render::RenderStats) {
    use cylvol::accel::{Accel, AccelParams, StructureKind};
    use cylvol::render::{
        default_step, face_neighbours, Camera, RenderOptions, RenderPath, Renderer,
        TransferFunction, Volume,
    };
    let axis = cylvol::axis::detect(mesh);
    let accel = Accel::build(mesh, StructureKind::CartBvh, &axis, &AccelParams::default()).unwrap();
    let neighbours = face_neighbours(mesh, &accel);
    let volume = Volume::new(mesh, &accel).unwrap();
    let [lo, hi] = volume.scalar_range();
    let tf = TransferFunction::default_for_range(lo, hi, 0.3, 0.1);
    let camera = Camera::view(mesh.bounds(), 64, 64, 30.0, 20.0, 1.0);
    let mut options = RenderOptions::new(64, 64, default_step(mesh));
    options.path = RenderPath::Fast;
    Renderer::new(&volume, &tf, &options)
        .unwrap()
        .with_topology(&neighbours)
        .render(&camera, None)
        .unwrap()
}

#[test]
fn parallel_files_written_by_vtk_read_as_the_whole_mesh() {
    if !common::vtk_python_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    common::vtk_python(SCRIPT, &["pgen", dir.path().to_str().unwrap(), hexa_vtk()]);
    let options = cylvol::io::ReadOptions::default();
    let whole = cylvol::io::read_file(Path::new(hexa_vtk()), &options).unwrap();
    let (whole_image, whole_stats) = fast_render(&whole);
    assert!(
        whole_image.rgba.iter().any(|p| p[3] > 0.05),
        "something is seen"
    );
    for ghost in [0, 1] {
        let path = dir.path().join(format!("cube-ghost{ghost}.pvtu"));
        let mesh = cylvol::io::read_file(&path, &options).unwrap();
        // Each piece repeats the points it shares with another (more with ghost cells).
        assert!(
            mesh.point_count() > whole.point_count(),
            "ghost level {ghost}"
        );
        // The same cells, each once: ghost cells dropped.
        assert_eq!(cell_set(&mesh), cell_set(&whole), "ghost level {ghost}");
        // The ghost flags are gone; the field is the file's active scalar.
        let names: Vec<&str> = mesh.point_data().iter().map(|a| a.name.as_str()).collect();
        assert_eq!(names, ["scalars"], "ghost level {ghost}");
        assert!(mesh.cell_data().is_empty(), "ghost level {ghost}");
        assert_eq!(mesh.scalar_range(), whole.scalar_range());
        // The faces between pieces are welded: rays cross them cell to cell, as in the whole
        // mesh, and see the same picture.
        let (image, stats) = fast_render(&mesh);
        assert_eq!(image.rgba, whole_image.rgba, "ghost level {ghost}");
        assert_eq!(
            (stats.samples_located, stats.structure_locates),
            (whole_stats.samples_located, whole_stats.structure_locates),
            "ghost level {ghost}"
        );
    }
    // A piece missing: the error names it.
    std::fs::remove_file(dir.path().join("cube-ghost0_1.vtu")).unwrap();
    let e = cylvol::io::read_file(&dir.path().join("cube-ghost0.pvtu"), &options)
        .unwrap_err()
        .to_string();
    assert!(e.contains("cube-ghost0_1.vtu"), "{e}");
}

/// Pieces written by hand: ghost cells in a plain `.vtu` go, a bad piece is named, and the
/// index's scalar choice holds.
#[test]
fn parallel_index_joins_pieces_and_names_bad_ones() {
    let mesh = small_mesh();
    let mut piece = Vec::new();
    vtu::write(&mesh, &mut piece).unwrap();
    let index = |scalars: &str, sources: &[&str]| {
        let pieces: String = sources
            .iter()
            .map(|s| format!("<Piece Source=\"{s}\"/>"))
            .collect();
        format!(
            "<VTKFile type=\"PUnstructuredGrid\"><PUnstructuredGrid>\
             <PCellData Scalars=\"{scalars}\"/>{pieces}</PUnstructuredGrid></VTKFile>"
        )
    };
    let load = |name: &str| -> Result<Vec<u8>, Error> {
        match name {
            "good.vtu" => Ok(piece.clone()),
            "bad.vtu" => Ok(piece[..piece.len() / 2].to_vec()),
            _ => Err(Error::Invalid(format!("no file {name}"))),
        }
    };
    let cell_array = mesh.cell_data()[0].name.clone();
    let two = vtu::read_parallel(
        index(&cell_array, &["good.vtu", "good.vtu"]).as_bytes(),
        load,
    )
    .unwrap();
    assert_eq!(two.cell_count(), 2 * mesh.cell_count());
    assert_eq!(two.point_count(), 2 * mesh.point_count());
    assert_eq!(two.active_array().unwrap().name, cell_array);
    let e = vtu::read_parallel(index("x", &["good.vtu", "bad.vtu"]).as_bytes(), load)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("bad.vtu: "), "{e}");
    let e = vtu::read_parallel(index("x", &["gone.vtu"]).as_bytes(), load)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no file gone.vtu"), "{e}");

    // A ghost flag array: flagged cells (duplicate 1, hidden 32) go; others (exterior 16) stay.
    let mut parts = mesh.clone().into_parts();
    let n = parts.cells.len();
    let flags: Vec<f64> = (0..n).map(|i| [0.0, 1.0, 16.0, 32.0][i % 4]).collect();
    let kept = flags.iter().filter(|&&f| f == 0.0 || f == 16.0).count();
    parts
        .cell_data
        .push(DataArray::scalar("vtkGhostType", flags));
    parts.point_data.push(DataArray::scalar(
        "vtkGhostType",
        vec![0.0; parts.points.len()],
    ));
    let flagged = Mesh::from_parts(parts).unwrap();
    let mut bytes = Vec::new();
    vtu::write(&flagged, &mut bytes).unwrap();
    let back = vtu::read(&bytes).unwrap();
    assert_eq!(back.cell_count(), kept);
    assert!(back.point_data().iter().all(|a| a.name != "vtkGhostType"));
    assert!(back.cell_data().iter().all(|a| a.name != "vtkGhostType"));
    assert_eq!(back.cell_data().len(), mesh.cell_data().len());
    assert_eq!(
        back.cell_data()[0].values.len(),
        kept * mesh.cell_data()[0].components
    );
}

#[test]
fn our_files_read_in_vtk() {
    if !common::vtk_python_available() {
        return;
    }
    let mesh = small_mesh();
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for (i, o) in all_options().iter().enumerate() {
        let path = dir.path().join(format!("m{i}.vtu"));
        std::fs::write(&path, write_to_vec(&mesh, o)).unwrap();
        files.push(path);
    }
    let want = our_summary(&mesh);
    for (s, o) in vtk_summaries(&files).iter().zip(all_options()) {
        assert_eq!(s, &want, "{o:?}");
    }
}

// ---------------------------------------------------------------------------------------------
// Bad input.

/// Lengths spread over `[0, len)`: always including the first and last few.
fn cut_points(len: usize, n: usize) -> Vec<usize> {
    let mut v: Vec<usize> = (0..n).map(|i| i * len / n).collect();
    v.extend(len.saturating_sub(5)..len);
    v.sort_unstable();
    v.dedup();
    v
}

#[test]
fn truncated_files_are_errors() {
    let mesh = small_mesh();
    for o in [
        VtuOptions::default(),
        VtuOptions {
            zlib: Some(6),
            block_size: 64,
            ..VtuOptions::default()
        },
        VtuOptions {
            encoding: Encoding::Base64,
            zlib: Some(6),
            header: HeaderType::UInt32,
            ..VtuOptions::default()
        },
        VtuOptions {
            encoding: Encoding::AppendedBase64,
            ..VtuOptions::default()
        },
        VtuOptions {
            encoding: Encoding::Ascii,
            ..VtuOptions::default()
        },
    ] {
        let bytes = write_to_vec(&mesh, &o);
        // Everything up to the final '>' matters.
        let end = bytes.iter().rposition(|&b| b == b'>').unwrap() + 1;
        for cut in cut_points(end, 200) {
            assert!(
                vtu::read(&bytes[..cut]).is_err(),
                "{o:?}: a file cut at {cut} of {end} bytes was read"
            );
        }
    }
}

/// `(start, length)` of each appended array's compressed blocks, from the XML offsets and the
/// 64-bit little-endian headers.
fn compressed_block_ranges(bytes: &[u8]) -> Vec<(usize, usize)> {
    let text = String::from_utf8_lossy(bytes);
    let appended = text.find("<AppendedData").unwrap();
    let data = appended + text[appended..].find('_').unwrap() + 1;
    let word = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
    text.match_indices("offset=\"")
        .map(|(i, m)| {
            let rest = &text[i + m.len()..];
            let off: usize = rest[..rest.find('"').unwrap()].parse().unwrap();
            let at = data + off;
            let n = word(at);
            let header = 8 * (3 + n);
            let len: usize = (0..n).map(|b| word(at + 24 + 8 * b)).sum();
            (at + header, len)
        })
        .collect()
}

#[test]
fn corrupt_zlib_data_is_an_error() {
    let mesh = small_mesh();
    let o = VtuOptions {
        zlib: Some(6),
        ..VtuOptions::default()
    };
    let bytes = write_to_vec(&mesh, &o);
    let ranges = compressed_block_ranges(&bytes);
    assert_eq!(ranges.len(), 8);
    let mut tried = 0;
    for (start, len) in ranges {
        for i in (0..len).step_by(3) {
            let mut bad = bytes.clone();
            bad[start + i] ^= 0x5a;
            let e = vtu::read(&bad).err().unwrap_or_else(|| {
                panic!("byte {i} of the {len}-byte block at {start} was corrupted, yet read")
            });
            assert!(e.to_string().contains("zlib"), "{e}");
            tried += 1;
        }
    }
    assert!(tried > 50);
}

#[test]
fn corrupt_base64_is_an_error() {
    let mesh = small_mesh();
    let o = VtuOptions {
        encoding: Encoding::Base64,
        ..VtuOptions::default()
    };
    let text = String::from_utf8(write_to_vec(&mesh, &o)).unwrap();
    // The points array's data line: replace one character with one outside the alphabet.
    let at = text.find("format=\"binary\">\n").unwrap() + 30;
    let mut bad = text.clone().into_bytes();
    bad[at] = b'*';
    let e = vtu::read(&bad).unwrap_err().to_string();
    assert!(e.contains("invalid base64 character"), "{e}");
}

fn replace(bytes: &[u8], from: &str, to: &str) -> Vec<u8> {
    let at = bytes
        .windows(from.len())
        .position(|w| w == from.as_bytes())
        .unwrap_or_else(|| panic!("{from} not found"));
    [&bytes[..at], to.as_bytes(), &bytes[at + from.len()..]].concat()
}

#[test]
fn wrong_attributes_are_named_in_errors() {
    let mesh = small_mesh();
    let ascii = write_to_vec(
        &mesh,
        &VtuOptions {
            encoding: Encoding::Ascii,
            ..VtuOptions::default()
        },
    );
    let zlib = write_to_vec(
        &mesh,
        &VtuOptions {
            zlib: Some(1),
            ..VtuOptions::default()
        },
    );
    let cases = [
        (
            replace(&ascii, "type=\"UnstructuredGrid\"", "type=\"PolyData\""),
            "PolyData",
        ),
        (
            replace(
                &ascii,
                "type=\"UnstructuredGrid\"",
                "type=\"PUnstructuredGrid\"",
            ),
            "PUnstructuredGrid",
        ),
        (
            replace(&zlib, "vtkZLibDataCompressor", "vtkBloscDataCompressor"),
            "vtkBloscDataCompressor",
        ),
        // zlib blocks read as another compressor's: that compressor's error.
        (
            replace(&zlib, "vtkZLibDataCompressor", "vtkLZ4DataCompressor"),
            "LZ4 block",
        ),
        (
            replace(&zlib, "vtkZLibDataCompressor", "vtkLZMADataCompressor"),
            "LZMA block",
        ),
        (
            replace(
                &ascii,
                "type=\"Float64\" Name=\"Points\"",
                "type=\"Float128\" Name=\"Points\"",
            ),
            "Float128",
        ),
        (
            replace(&ascii, "header_type=\"UInt64\"", "header_type=\"UInt16\""),
            "UInt16",
        ),
        (replace(&ascii, "format=\"ascii\"", "format=\"hex\""), "hex"),
        (
            replace(
                &ascii,
                "byte_order=\"LittleEndian\"",
                "byte_order=\"Middle\"",
            ),
            "Middle",
        ),
        (
            replace(&ascii, "NumberOfPoints=\"20\"", "NumberOfPoints=\"21\""),
            "expected 63",
        ),
        (replace(&ascii, "</Piece>", "</Peace>"), "</Peace>"),
        (
            replace(&zlib, "offset=\"0\"", "offset=\"99999999\""),
            "beyond",
        ),
        (b"hello".to_vec(), "not a VTK XML file"),
        (b"<Foo/>".to_vec(), "<Foo>"),
    ];
    for (bytes, needle) in cases {
        let e = vtu::read(&bytes).unwrap_err();
        assert!(matches!(e, Error::Read(_)), "{e:?}");
        assert!(e.to_string().contains(needle), "{needle}: {e}");
    }
}

#[test]
fn unsupported_cells_are_a_mesh_error() {
    let file = r#"<VTKFile type="UnstructuredGrid"><UnstructuredGrid>
<Piece NumberOfPoints="3" NumberOfCells="1"><Points>
<DataArray type="Float32" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 0 1 0</DataArray>
</Points><Cells><DataArray type="Int32" Name="connectivity" format="ascii">0 1 2</DataArray>
<DataArray type="Int32" Name="offsets" format="ascii">3</DataArray>
<DataArray type="UInt8" Name="types" format="ascii">5</DataArray></Cells></Piece>
</UnstructuredGrid></VTKFile>"#;
    let e = vtu::read(file.as_bytes()).unwrap_err();
    assert!(e.to_string().contains("triangle"), "{e}");
}

#[test]
fn byte_swapped_files_read_the_same() {
    // The same mesh written in both byte orders decodes identically, and the big-endian file
    // really differs from the little-endian one beyond its header.
    let mesh = small_mesh();
    for encoding in [Encoding::AppendedRaw, Encoding::Base64] {
        let le = write_to_vec(
            &mesh,
            &VtuOptions {
                encoding,
                ..VtuOptions::default()
            },
        );
        let be = write_to_vec(
            &mesh,
            &VtuOptions {
                encoding,
                byte_order: ByteOrder::BigEndian,
                ..VtuOptions::default()
            },
        );
        assert_ne!(
            replace(&le, "LittleEndian", "BigEndian"),
            be,
            "data must be swapped"
        );
        assert_eq!(vtu::read(&be).unwrap(), vtu::read(&le).unwrap());
        // Claiming the wrong byte order gives garbage sizes: an error, not a panic.
        assert!(vtu::read(&replace(&le, "LittleEndian", "BigEndian")).is_err());
    }
}

// ---------------------------------------------------------------------------------------------
// Timings on a large mesh (not a test of speed: run with `--ignored --nocapture` to see them).

fn lattice(n: [usize; 3]) -> Mesh {
    let [nx, ny, nz] = n;
    let id = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    let mut points = Vec::new();
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let (r, t, z) = (
                    1.0 + i as f64 / nx as f64,
                    j as f64 / ny as f64 * 1.5,
                    k as f64 / nz as f64,
                );
                points.push(DVec3::new(r * t.cos(), r * t.sin(), z));
            }
        }
    }
    let mut cells = Vec::new();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                cells.push(cylvol::io::structured::cell_ids(i, j, k, id));
            }
        }
    }
    let p = points
        .iter()
        .map(|q| (q.x * 3.0).sin() * (q.y * 2.0).cos() + q.z)
        .collect();
    let kinds = vec![CellKind::Hexahedron; cells.len()];
    Mesh::from_parts(MeshParts {
        points,
        cells,
        kinds,
        point_data: vec![DataArray::scalar("p", p)],
        cell_data: vec![],
    })
    .unwrap()
}

#[test]
#[ignore = "timings on a 2.1 M-cell mesh; run with --ignored --nocapture"]
fn big_mesh_timings() {
    use std::time::Instant;
    let mesh = lattice([128, 128, 128]);
    println!("{} cells, {} points", mesh.cell_count(), mesh.point_count());
    let t = Instant::now();
    let again = Mesh::from_parts(mesh.clone().into_parts()).unwrap();
    println!(
        "Mesh::from_parts alone (validation): {:.2} s",
        t.elapsed().as_secs_f64()
    );
    assert_eq!(again.cell_count(), mesh.cell_count());
    for (label, o) in [
        ("appended raw", VtuOptions::default()),
        (
            "appended raw zlib 1",
            VtuOptions {
                zlib: Some(1),
                ..VtuOptions::default()
            },
        ),
        (
            "appended raw zlib 6",
            VtuOptions {
                zlib: Some(6),
                ..VtuOptions::default()
            },
        ),
        (
            "appended base64",
            VtuOptions {
                encoding: Encoding::AppendedBase64,
                ..VtuOptions::default()
            },
        ),
    ] {
        let t = Instant::now();
        let bytes = write_to_vec(&mesh, &o);
        let write_s = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let back = vtu::read(&bytes).unwrap();
        let read_s = t.elapsed().as_secs_f64();
        assert_eq!(back.cell_count(), mesh.cell_count());
        println!(
            "{label:>22}: {:7.1} MB, write {write_s:.2} s, read {read_s:.2} s",
            bytes.len() as f64 / 1e6
        );
    }
}

/// Writes the fuzzing seeds under `fuzz/seeds/read_vtu/` (tiny files in each mode).
#[test]
#[ignore = "writes fuzz/seeds/read_vtu/; run by hand when the writer changes"]
fn write_fuzz_seeds() {
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let mesh = Mesh::from_parts(MeshParts {
        points: vec![p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.), p(0., 0., 1.)],
        cells: vec![CellKind::Tetrahedron.collapse(&[0, 1, 2, 3])],
        kinds: vec![CellKind::Tetrahedron],
        point_data: vec![DataArray::scalar("p", vec![0.0, 1.0, 2.0, 3.0])],
        cell_data: vec![DataArray::vector("v", vec![1.0, 2.0, 3.0])],
    })
    .unwrap();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds/read_vtu");
    std::fs::create_dir_all(&dir).unwrap();
    let base = VtuOptions {
        block_size: 16,
        ..VtuOptions::default()
    };
    for (name, o) in [
        (
            "ascii.vtu",
            VtuOptions {
                encoding: Encoding::Ascii,
                ..base
            },
        ),
        (
            "base64.vtu",
            VtuOptions {
                encoding: Encoding::Base64,
                header: HeaderType::UInt32,
                ..base
            },
        ),
        (
            "base64-zlib.vtu",
            VtuOptions {
                encoding: Encoding::Base64,
                zlib: Some(6),
                ..base
            },
        ),
        ("raw.vtu", base),
        (
            "raw-zlib-be32.vtu",
            VtuOptions {
                zlib: Some(6),
                header: HeaderType::UInt32,
                byte_order: ByteOrder::BigEndian,
                ..base
            },
        ),
        (
            "appended-base64-zlib.vtu",
            VtuOptions {
                encoding: Encoding::AppendedBase64,
                zlib: Some(1),
                ..base
            },
        ),
    ] {
        std::fs::write(dir.join(name), write_to_vec(&mesh, &o)).unwrap();
    }
}

/// A piece-aware source written by VTK in three pieces in one file, without and with a ghost
/// level: read as the cells VTK's reader gives less those it flags as ghosts (VTK's reader
/// keeps them for the pipeline to skip), each once, by their corners' mean.
#[test]
fn one_file_of_several_pieces_with_ghost_cells_reads_each_cell_once() {
    if !common::vtk_python_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let script = r#"
import sys, os, vtk
src = vtk.vtkRTAnalyticSource(); src.SetWholeExtent(0, 8, 0, 6, 0, 5)
sg = vtk.vtkImageDataToPointSet(); sg.SetInputConnection(src.GetOutputPort())
ug = vtk.vtkAppendFilter(); ug.SetInputConnection(sg.GetOutputPort())
for ghost in (0, 1):
    path = os.path.join(sys.argv[1], "pieces%d.vtu" % ghost)
    w = vtk.vtkXMLUnstructuredGridWriter(); w.SetInputConnection(ug.GetOutputPort())
    w.SetFileName(path); w.SetNumberOfPieces(3); w.SetGhostLevel(ghost)
    assert w.Write() == 1
    r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(path); r.Update(); g = r.GetOutput()
    flags = g.GetCellData().GetArray("vtkGhostType")
    for c in range(g.GetNumberOfCells()):
        if flags is not None and flags.GetValue(c) & 1: continue
        ids = g.GetCell(c).GetPointIds()
        pts = [g.GetPoint(ids.GetId(k)) for k in range(ids.GetNumberOfIds())]
        print(ghost, " ".join(repr(sum(p[a] for p in pts) / len(pts)) for a in range(3)))
"#;
    let out = common::vtk_python(script, &[dir.path().to_str().unwrap()]);
    for ghost in [0, 1] {
        let path = dir.path().join(format!("pieces{ghost}.vtu"));
        let text = std::fs::read(&path).unwrap();
        assert_eq!(text.windows(6).filter(|w| w == b"<Piece").count(), 3);
        let mesh = vtu::read_file(&path).unwrap();
        let mut theirs: Vec<[f64; 3]> = out
            .lines()
            .filter_map(|l| l.strip_prefix(&format!("{ghost} ")))
            .map(|l| {
                let v: Vec<f64> = l.split(' ').map(|x| x.parse().unwrap()).collect();
                [v[0], v[1], v[2]]
            })
            .collect();
        let mut ours: Vec<[f64; 3]> = (0..mesh.cell_count())
            .map(|c| {
                let p = mesh.cell_corners(c);
                [0, 1, 2].map(|a| p.iter().map(|q| q[a]).sum::<f64>() / 8.0)
            })
            .collect();
        assert_eq!(ours.len(), 8 * 6 * 5, "ghost level {ghost}");
        theirs.sort_by(|a, b| a.partial_cmp(b).unwrap());
        ours.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert_eq!(ours.len(), theirs.len(), "ghost level {ghost}");
        for (o, t) in ours.iter().zip(&theirs) {
            assert!(
                o.iter().zip(t).all(|(a, b)| (a - b).abs() < 1e-9),
                "ghost level {ghost}: {o:?} against VTK's {t:?}"
            );
        }
    }
}

/// A blanked structured grid made unstructured by VTK (vtkAppendFilter, as ParaView's Merge
/// Blocks makes it) has VTK's empty cells (type 0, no points) where the blanked cells were;
/// VTK writes them to VTU and legacy files and reads them back. Both read as the grid's other
/// cells, the cell data of the empty ones dropped with them, and the load notes say how many
/// (they were refused: "unsupported cell types: 2 × empty cell").
#[test]
fn empty_cells_vtk_writes_are_dropped_with_their_cell_data_and_said() {
    if !common::vtk_python_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let script = r#"
import sys, os, vtk
ni, nj, nk = 4, 3, 3
pts = vtk.vtkPoints()
for k in range(nk):
    for j in range(nj):
        for i in range(ni):
            pts.InsertNextPoint(i, j + 0.2 * i, k)
g = vtk.vtkStructuredGrid(); g.SetDimensions(ni, nj, nk); g.SetPoints(pts)
c = vtk.vtkDoubleArray(); c.SetName('c')
for n in range(g.GetNumberOfCells()): c.InsertNextValue(n)
g.GetCellData().AddArray(c)
g.BlankCell(2); g.BlankCell(7)
a = vtk.vtkAppendFilter(); a.AddInputData(g); a.Update()
u = vtk.vtkUnstructuredGrid(); u.DeepCopy(a.GetOutput())
print(' '.join(str(u.GetCellType(i)) for i in range(u.GetNumberOfCells())))
w = vtk.vtkXMLUnstructuredGridWriter(); w.SetInputData(u)
w.SetFileName(os.path.join(sys.argv[1], 'merged.vtu')); w.Write()
w = vtk.vtkUnstructuredGridWriter(); w.SetInputData(u); w.SetFileTypeToBinary()
w.SetFileName(os.path.join(sys.argv[1], 'merged.vtk')); w.Write()
"#;
    let types = common::vtk_python(script, &[dir.path().to_str().unwrap()]);
    let types: Vec<u8> = types
        .split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect();
    assert_eq!(
        types.iter().filter(|&&t| t == 0).count(),
        2,
        "VTK wrote empty cells"
    );
    let kept: Vec<f64> = (0..12)
        .filter(|&c| types[c] != 0)
        .map(|c| c as f64)
        .collect();
    for name in ["merged.vtu", "merged.vtk"] {
        let path = dir.path().join(name);
        let mut notes = Vec::new();
        let mesh = cylvol::io::read_file_logged(&path, &Default::default(), &mut |n| notes.push(n))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(mesh.cell_count(), 10, "{name}");
        let c = mesh.cell_data().iter().find(|a| a.name == "c").unwrap();
        assert_eq!(c.values, kept, "{name}: the other cells' values, in order");
        let note = format!(
            "{}: 2 empty cells were dropped (VTK type 0, without points, as blanked cells \
             become in an unstructured grid) with their cell data",
            path.display()
        );
        assert!(notes.contains(&note), "{name}: {notes:?}");
    }
}
