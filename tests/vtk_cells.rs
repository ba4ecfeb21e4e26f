//! Cells as VTK defines them: one cell of each kind cylvol reads, made by VTK itself from its
//! own cell classes' parametric vertices, in the orientation VTK documents and measures
//! (positive `vtkCellSizeFilter` volume, valid by `vtkCellValidator`), written by VTK's
//! writers, must be read without complaint and interpolate as VTK's shape functions do at
//! points VTK places inside each cell.

mod common;

use std::path::Path;

use cylvol::accel::{Accel, AccelParams, Counters, StructureKind};
use cylvol::axis::Axis;
use cylvol::io::{read_file, ReadOptions};
use cylvol::render::Interpolation;
use glam::DVec3;

/// Writes `cells.vtu`, `cells.vtk` (legacy 4.2, binary) and `probes.json` into the folder
/// given (VTK's validator prints to standard output): per probe the cell, the point VTK's `EvaluateLocation` puts at the parametric
/// coordinates, and the scalar VTK's interpolation weights give there.
const SCRIPT: &str = r#"
import json, os, sys
import vtk

out = sys.argv[1]
kinds = [vtk.vtkHexahedron, vtk.vtkVoxel, vtk.vtkWedge, vtk.vtkPyramid, vtk.vtkTetra]
# VTK 9.1's vtkWedge lists its parametric vertices in the winding its own documentation,
# vtkCellValidator and vtkCellSizeFilter call inverted (base normal into the cell); files
# written by the tools that follow the documentation number it mirrored, as here.
mirror = {vtk.VTK_WEDGE: [0, 2, 1, 3, 5, 4]}

def make(mirrored):
    points = vtk.vtkPoints()
    grid = vtk.vtkUnstructuredGrid()
    grid.SetPoints(points)
    for k, kind in enumerate(kinds):
        cell = kind()
        pc = cell.GetParametricCoords()
        ids = []
        for v in range(cell.GetNumberOfPoints()):
            r, s, t = pc[3 * v], pc[3 * v + 1], pc[3 * v + 2]
            # Apart along x; not quite the reference shape (but still a voxel's box).
            bent = kind is not vtk.vtkVoxel
            dx, dz = (0.1 * r * t - 0.05 * s * s, 0.1 * r * s) if bent else (0.0, 0.0)
            ids.append(points.InsertNextPoint(2.0 * k + r + dx, s, t + dz))
        order = mirror.get(cell.GetCellType()) if mirrored else None
        if order:
            ids = [ids[i] for i in order]
        grid.InsertNextCell(cell.GetCellType(), len(ids), ids)
    return grid

def volumes(grid):
    sizes = vtk.vtkCellSizeFilter()
    sizes.SetInputData(grid)
    sizes.Update()
    v = sizes.GetOutput().GetCellData().GetArray("Volume")
    return [v.GetValue(c) for c in range(grid.GetNumberOfCells())]

def states(grid):
    validator = vtk.vtkCellValidator()
    validator.SetInputData(grid)
    validator.Update()
    s = validator.GetOutput().GetCellData().GetArray("ValidityState")
    return [s.GetValue(c) for c in range(grid.GetNumberOfCells())]

# The quirk this works around is still there (else the mirror is no longer needed).
assert volumes(make(False))[2] < 0 and states(make(False))[2] != 0
grid = make(True)
# Well formed by VTK's measures: positive volume, and the validator's word (which VTK 9.1
# gives wrongly for a voxel among other cells, so not asked of it).
assert all(v > 0 for v in volumes(grid)), volumes(grid)
assert all(s == 0 for c, s in enumerate(states(grid)) if c != 1), states(grid)
points = grid.GetPoints()
scalar = vtk.vtkDoubleArray()
scalar.SetName("f")
for i in range(points.GetNumberOfPoints()):
    x, y, z = points.GetPoint(i)
    scalar.InsertNextValue(x + 2.0 * y * y - 3.0 * z + x * y * z)
grid.GetPointData().SetScalars(scalar)

probes = []
inside = [(0.2, 0.2, 0.2), (0.1, 0.3, 0.4), (0.3, 0.1, 0.5), (0.05, 0.6, 0.3)]
for c in range(grid.GetNumberOfCells()):
    cell = grid.GetCell(c)
    for pc in inside:
        x = [0.0, 0.0, 0.0]
        w = [0.0] * cell.GetNumberOfPoints()
        cell.EvaluateLocation(vtk.reference(0), pc, x, w)
        value = sum(w[v] * scalar.GetValue(cell.GetPointId(v)) for v in range(len(w)))
        probes.append({"cell": c, "x": x, "value": value})

writer = vtk.vtkXMLUnstructuredGridWriter()
writer.SetInputData(grid)
writer.SetFileName(os.path.join(out, "cells.vtu"))
assert writer.Write() == 1
legacy = vtk.vtkUnstructuredGridWriter()
legacy.SetInputData(grid)
legacy.SetFileTypeToBinary()
if hasattr(legacy, "SetFileVersion"):
    legacy.SetFileVersion(42)
legacy.SetFileName(os.path.join(out, "cells.vtk"))
assert legacy.Write() == 1
with open(os.path.join(out, "probes.json"), "w") as f:
    json.dump(probes, f)
"#;

/// VTK's cells, read from its VTU and legacy files: every kind is accepted (none reported
/// inverted), counted under its own name, and each probe VTK placed in a cell is located in
/// that cell by every structure, where our interpolation gives VTK's value.
#[test]
fn cells_vtk_makes_read_and_interpolate_as_in_vtk() {
    if !common::vtk_python_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    common::vtk_python(SCRIPT, &[dir.path().to_str().unwrap()]);
    let probes = std::fs::read(dir.path().join("probes.json")).unwrap();
    let probes: serde_json::Value = serde_json::from_slice(&probes).unwrap();
    let probes: Vec<(u32, DVec3, f64)> = probes
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let x: Vec<f64> = p["x"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            (
                p["cell"].as_u64().unwrap() as u32,
                DVec3::new(x[0], x[1], x[2]),
                p["value"].as_f64().unwrap(),
            )
        })
        .collect();
    assert_eq!(probes.len(), 20);
    for name in ["cells.vtu", "cells.vtk"] {
        let path = dir.path().join(name);
        let mesh = read_file(Path::new(&path), &ReadOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let counts: Vec<(String, usize)> = mesh
            .kind_counts()
            .iter()
            .map(|(k, n)| (k.name().to_string(), *n))
            .collect();
        assert_eq!(
            counts,
            [
                ("hexahedron".to_string(), 2),
                ("wedge".to_string(), 1),
                ("pyramid".to_string(), 1),
                ("tetrahedron".to_string(), 1)
            ],
            "{name}"
        );
        let scalars = &mesh.point_data()[0].values;
        let axis = Axis::new(DVec3::new(4.0, 0.5, 0.5), DVec3::X).unwrap();
        for kind in StructureKind::ALL {
            let accel = Accel::build(&mesh, kind, &axis, &AccelParams::default()).unwrap();
            let mut counters = Counters::default();
            for &(cell, x, value) in &probes {
                let (found, param) = accel
                    .locate(&mesh, x, &mut counters)
                    .unwrap_or_else(|| panic!("{name}, {kind}: {x} of cell {cell} not found"));
                assert_eq!(found, cell, "{name}, {kind}: {x}");
                let values = mesh.cells()[cell as usize].map(|i| scalars[i as usize]);
                let ours = Interpolation::Linear.sample(&values, param);
                assert!(
                    (ours - value).abs() <= 1e-9 * (1.0 + value.abs()),
                    "{name}, {kind}, cell {cell} at {x}: {ours} here, {value} in VTK"
                );
            }
        }
    }
}
