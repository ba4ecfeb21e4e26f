//! VTS (VTK XML structured grid) reader tests against VTK 9.1's own writer and reader: a
//! curvilinear grid with blanked points and cells in every encoding and compressor VTK
//! writes, and a grid in several pieces with and without a ghost level, read as the cells
//! VTK shows (`vtkStructuredGrid::IsCellVisible`), each with the point and cell values VTK
//! gives; a flat piece and a broken file are errors naming the format.

mod common;

use std::collections::HashMap;
use std::path::Path;

use cylvol::io::{self, vts, ReadOptions};
use cylvol::{Error, Mesh};

/// `gen DIR` writes the files; `summary FILE` prints, as VTK reads the file, every point
/// (coordinates and the point arrays' values) and every visible cell (its corners' mean and
/// the cell arrays' values), numbers as `repr` strings.
const SCRIPT: &str = r#"
import json, math, sys, os, vtk

def sector():
    ni, nj, nk = 7, 6, 5
    pts = vtk.vtkPoints(); pts.SetDataTypeToDouble()
    p = vtk.vtkDoubleArray(); p.SetName('p')
    u = vtk.vtkFloatArray(); u.SetName('U'); u.SetNumberOfComponents(3)
    for k in range(nk):
        for j in range(nj):
            for i in range(ni):
                r, t, z = 1 + 0.2 * i, 0.15 * j, 0.25 * k
                pts.InsertNextPoint(r * math.cos(t), r * math.sin(t), z)
                p.InsertNextValue(r * r - z + 0.1 * j)
                u.InsertNextTuple3(-math.sin(t), math.cos(t), 0.5 * z)
    g = vtk.vtkStructuredGrid(); g.SetDimensions(ni, nj, nk); g.SetPoints(pts)
    g.GetPointData().SetScalars(p); g.GetPointData().AddArray(u)
    c = vtk.vtkIntArray(); c.SetName('c')
    for i in range(g.GetNumberOfCells()): c.InsertNextValue(i)
    g.GetCellData().AddArray(c)
    # An interior point hides its 8 cells, a face point 4, a corner 1; a cell hidden alone.
    for (i, j, k) in [(3, 2, 2), (0, 3, 2), (6, 5, 4)]:
        g.BlankPoint(i + ni * (j + nj * k))
    g.BlankCell(1)
    return g

MODES = {"ascii": ("ascii", None), "binary": ("binary", None), "raw": ("appended", None),
         "raw-zlib": ("appended", "zlib"), "b64-lz4": ("appended64", "lz4"),
         "binary-lzma": ("binary", "lzma")}

def gen(out):
    g = sector()
    for name, (data, comp) in MODES.items():
        for header64 in (False, True):
            w = vtk.vtkXMLStructuredGridWriter(); w.SetInputData(g)
            w.SetFileName(os.path.join(out, "sector-%s-%d.vts" % (name, 64 if header64 else 32)))
            if data == "ascii": w.SetDataModeToAscii()
            elif data == "binary": w.SetDataModeToBinary()
            else:
                w.SetDataModeToAppended(); w.SetEncodeAppendedData(data == "appended64")
            {None: w.SetCompressorTypeToNone, "zlib": w.SetCompressorTypeToZLib,
             "lz4": w.SetCompressorTypeToLZ4, "lzma": w.SetCompressorTypeToLZMA}[comp]()
            if header64: w.SetHeaderTypeToUInt64()
            w.SetBlockSize(512)
            assert w.Write() == 1
    # A piece-aware source in three pieces, in one file, without and with a ghost level.
    src = vtk.vtkRTAnalyticSource(); src.SetWholeExtent(0, 8, 0, 6, 0, 5)
    sg = vtk.vtkImageDataToPointSet(); sg.SetInputConnection(src.GetOutputPort())
    for ghost in (0, 1):
        w = vtk.vtkXMLStructuredGridWriter(); w.SetInputConnection(sg.GetOutputPort())
        w.SetFileName(os.path.join(out, "pieces-ghost%d.vts" % ghost))
        w.SetNumberOfPieces(3); w.SetGhostLevel(ghost)
        assert w.Write() == 1
        w = vtk.vtkXMLPStructuredGridWriter(); w.SetInputConnection(sg.GetOutputPort())
        w.SetFileName(os.path.join(out, "parallel-ghost%d.pvts" % ghost))
        w.SetNumberOfPieces(3); w.SetStartPiece(0); w.SetEndPiece(2); w.SetGhostLevel(ghost)
        w.SetCompressorTypeToZLib()
        assert w.Write() == 1

def summary(path):
    if path.endswith('.pvts'): r = vtk.vtkXMLPStructuredGridReader()
    else: r = vtk.vtkXMLStructuredGridReader()
    r.SetFileName(path); r.Update()
    g = r.GetOutput()
    s = lambda v: [repr(x) for x in v]
    def values(d, i):
        out = {}
        for a in range(d.GetNumberOfArrays()):
            arr = d.GetArray(a)
            if arr is None or arr.GetName() == 'vtkGhostType': continue
            out[arr.GetName()] = s(arr.GetTuple(i))
        return out
    points = [{"at": s(g.GetPoint(i)), "values": values(g.GetPointData(), i)}
              for i in range(g.GetNumberOfPoints())]
    cells = []
    for c in range(g.GetNumberOfCells()):
        if not g.IsCellVisible(c): continue
        ids = g.GetCell(c).GetPointIds()
        corners = [g.GetPoint(ids.GetId(k)) for k in range(ids.GetNumberOfIds())]
        cells.append({"centre": [repr(sum(p[a] for p in corners) / 8) for a in range(3)],
                      "values": values(g.GetCellData(), c)})
    print(json.dumps({"points": points, "cells": cells}))

if sys.argv[1] == "gen": gen(sys.argv[2])
else: summary(sys.argv[2])
"#;

/// A value as the script prints it.
fn number(v: &serde_json::Value) -> f64 {
    v.as_str().unwrap().parse().unwrap()
}

/// The files VTK writes, in a new folder; `None` without VTK's Python.
fn vtk_files() -> Option<tempfile::TempDir> {
    if !common::vtk_python_available() {
        return None;
    }
    let dir = tempfile::tempdir().unwrap();
    common::vtk_python(SCRIPT, &["gen", dir.path().to_str().unwrap()]);
    Some(dir)
}

/// A point's coordinates as a key (exact: both sides read the same doubles).
fn key(p: [f64; 3]) -> [u64; 3] {
    p.map(f64::to_bits)
}

/// `mesh` has the cells VTK shows of `path` (the same cells by their corners' mean, with the
/// same cell values) and at each point VTK's point values.
fn assert_matches_vtk(mesh: &Mesh, path: &Path) {
    let name = path.file_name().unwrap().to_string_lossy();
    let out = common::vtk_python(SCRIPT, &["summary", path.to_str().unwrap()]);
    let vtk: serde_json::Value = serde_json::from_str(&out).unwrap();
    let mut vtk_points: HashMap<[u64; 3], &serde_json::Value> = HashMap::new();
    for p in vtk["points"].as_array().unwrap() {
        let at: Vec<f64> = p["at"].as_array().unwrap().iter().map(number).collect();
        vtk_points.insert(key([at[0], at[1], at[2]]), &p["values"]);
    }
    for (i, p) in mesh.points().iter().enumerate() {
        let theirs = vtk_points
            .get(&key(p.to_array()))
            .unwrap_or_else(|| panic!("{name}: point {i} {p} is not VTK's"));
        for a in mesh.point_data() {
            let want: Vec<f64> = theirs[&a.name]
                .as_array()
                .unwrap()
                .iter()
                .map(number)
                .collect();
            let k = a.components;
            assert_eq!(
                &a.values[i * k..(i + 1) * k],
                &want[..],
                "{name}: {} at {i}",
                a.name
            );
        }
    }
    let vtk_cells = vtk["cells"].as_array().unwrap();
    assert_eq!(
        mesh.cell_count(),
        vtk_cells.len(),
        "{name}: the cells VTK shows"
    );
    let mut theirs: Vec<(Vec<f64>, Vec<f64>)> = vtk_cells
        .iter()
        .map(|c| {
            let centre = c["centre"].as_array().unwrap().iter().map(number).collect();
            let values = mesh
                .cell_data()
                .iter()
                .flat_map(|a| c["values"][&a.name].as_array().unwrap().iter().map(number))
                .collect();
            (centre, values)
        })
        .collect();
    let mut ours: Vec<(Vec<f64>, Vec<f64>)> = (0..mesh.cell_count())
        .map(|c| {
            let corners = mesh.cell_corners(c);
            let centre = (0..3)
                .map(|a| corners.iter().map(|p| p[a]).sum::<f64>() / 8.0)
                .collect();
            let values = mesh
                .cell_data()
                .iter()
                .flat_map(|a| a.values[c * a.components..(c + 1) * a.components].to_vec())
                .collect();
            (centre, values)
        })
        .collect();
    let order = |a: &(Vec<f64>, Vec<f64>), b: &(Vec<f64>, Vec<f64>)| a.partial_cmp(b).unwrap();
    theirs.sort_by(order);
    ours.sort_by(order);
    for (o, t) in ours.iter().zip(&theirs) {
        let close =
            o.0.iter()
                .zip(&t.0)
                .all(|(a, b)| (a - b).abs() <= 1e-12 * (1.0 + a.abs()));
        assert!(
            close && o.1 == t.1,
            "{name}: cell {o:?} against VTK's {t:?}"
        );
    }
}

/// The blanked sector in every encoding, compressor and header width VTK's writer offers:
/// the cells VTK shows (the 8, 4 and 1 cells about the hidden points and the hidden cell
/// gone, and the load note says 14), the point and cell values VTK gives, no ghost array
/// kept; the file's active scalar.
#[test]
fn blanked_grids_vtk_writes_read_as_vtk_shows_them() {
    let Some(dir) = vtk_files() else {
        return;
    };
    let mut seen = 0;
    for entry in std::fs::read_dir(dir.path()).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if !name.starts_with("sector-") {
            continue;
        }
        let mut notes = Vec::new();
        let mesh = io::read_file_logged(&path, &ReadOptions::default(), &mut |n| notes.push(n))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(
            notes,
            [format!(
                "{}: 14 blanked cells were dropped (hidden in vtkGhostType, or with a hidden \
                 corner point), as VTK hides them",
                path.display()
            )]
        );
        assert_eq!(mesh.point_count(), 7 * 6 * 5, "{name}");
        assert_eq!(mesh.cell_count(), 6 * 5 * 4 - 8 - 4 - 1 - 1, "{name}");
        assert!(mesh
            .point_data()
            .iter()
            .chain(mesh.cell_data())
            .all(|a| a.name != "vtkGhostType"));
        assert_eq!(mesh.active_array().unwrap().name, "p", "{name}");
        assert_matches_vtk(&mesh, &path);
        seen += 1;
    }
    assert_eq!(seen, 12);
}

/// A grid in three pieces in one file: their cells once each (with a ghost level, the ghost
/// copies dropped), the points on shared faces each piece's own, values as VTK reads them.
#[test]
fn several_pieces_vtk_writes_are_joined_without_their_ghost_cells() {
    let Some(dir) = vtk_files() else {
        return;
    };
    for ghost in [0, 1] {
        let path = dir.path().join(format!("pieces-ghost{ghost}.vts"));
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.matches("<Piece").count(), 3, "three pieces");
        let mut notes = Vec::new();
        let mesh =
            vts::read_file_logged(&path, &mut |n| notes.push(n)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(mesh.cell_count(), 8 * 6 * 5, "ghost level {ghost}");
        let said = notes.iter().any(|n| n.contains("ghost cells were dropped"));
        assert_eq!(said, ghost == 1, "{notes:?}");
        assert_eq!(mesh.active_array().unwrap().name, "RTData");
        assert_matches_vtk(&mesh, &path);
    }
}

/// A parallel index (`.pvts`) and its three `.vts` pieces, without and with a ghost level:
/// read through the index, each cell once, VTK's values at every point.
#[test]
fn parallel_index_and_its_pieces_read_as_vtk_reads_them() {
    let Some(dir) = vtk_files() else {
        return;
    };
    for ghost in [0, 1] {
        let path = dir.path().join(format!("parallel-ghost{ghost}.pvts"));
        let mesh = io::read_file(&path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(mesh.cell_count(), 8 * 6 * 5, "ghost level {ghost}");
        assert_matches_vtk(&mesh, &path);
    }
    // A piece that is missing is an error naming it, under the index's name.
    let index = dir.path().join("parallel-ghost0.pvts");
    let text = std::fs::read_to_string(&index).unwrap();
    let piece = text
        .split("Source=\"")
        .nth(1)
        .unwrap()
        .split('"')
        .next()
        .unwrap();
    std::fs::remove_file(dir.path().join(piece)).unwrap();
    let msg = message(vts::read_parallel_file(&index));
    assert!(
        msg.starts_with(&index.display().to_string()) && msg.contains(piece),
        "{msg}"
    );
}

fn message(r: Result<Mesh, Error>) -> String {
    match r {
        Ok(m) => panic!("a mesh of {} cells", m.cell_count()),
        Err(e) => e.to_string(),
    }
}

/// A flat piece (a 2-D grid) and a file cut short are errors that name the format; an
/// unstructured grid is not taken for a structured one.
#[test]
fn flat_and_broken_files_are_errors() {
    let flat = br#"<VTKFile type="StructuredGrid"><StructuredGrid WholeExtent="0 1 0 1 0 0">
<Piece Extent="0 1 0 1 0 0"><Points><DataArray type="Float32" NumberOfComponents="3"
format="ascii">0 0 0 1 0 0 0 1 0 1 1 0</DataArray></Points></Piece></StructuredGrid></VTKFile>"#;
    let msg = message(vts::read(flat));
    assert!(
        msg.starts_with("VTS: the piece's Extent") && msg.contains("flat"),
        "{msg}"
    );
    let cut = &flat[..flat.len() - 40];
    assert!(message(vts::read(cut)).starts_with("VTS: "));
    let vtu =
        br#"<VTKFile type="UnstructuredGrid"><UnstructuredGrid></UnstructuredGrid></VTKFile>"#;
    let msg = message(vts::read(vtu));
    assert!(msg.contains("only StructuredGrid (.vts)"), "{msg}");
}

/// The fuzzing seeds in `fuzz/seeds/read_vts/` (small grids VTK wrote) read: the blanked
/// 2×2×2-cell grid without its hidden cell, the two pieces with a ghost level as one grid of
/// 3×2×2 cells.
#[test]
fn fuzz_seeds_are_valid_files() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/fuzz/seeds/read_vts");
    let mut seen = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let mesh = vts::read(&std::fs::read(&path).unwrap())
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let cells = if path.to_string_lossy().contains("pieces") {
            12
        } else {
            7
        };
        assert_eq!(mesh.cell_count(), cells, "{}", path.display());
        seen += 1;
    }
    assert_eq!(seen, 4);
}
