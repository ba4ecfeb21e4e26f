"""Renders a scene pv_scene.py drew in ParaView again with the VTK 9.1 module's mapper.

Run by Debian's /usr/bin/python3 with the build tree's cylvol package on PYTHONPATH (see
cylvol_paraview_test.py). The grid is read with VTK's own readers as the VTK CTest reads it
(the PLOT3D block through vtkAppendFilter; a multiblock's volume blocks appended one after
another), the camera and transfer function are the ones pv_scene.py wrote, the mapper keeps
its defaults (cylvol's default step for the mesh): the image a VTK user gets for the scene.

Usage: vtk_scene.py DATASET SCENE.json OUT.png --data tests/data --work FOLDER
"""
import argparse
import json
import os

import cylvol
from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction, vtkPolyData
from vtkmodules.vtkFiltersCore import vtkAppendFilter
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkIOLegacy import vtkUnstructuredGridReader
from vtkmodules.vtkIOParallel import vtkMultiBlockPLOT3DReader
from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataReader, vtkXMLUnstructuredGridReader
from vtkmodules.vtkRenderingCore import (
    vtkColorTransferFunction, vtkRenderer, vtkRenderWindow, vtkVolume, vtkVolumeProperty,
    vtkWindowToImageFilter)

# pv_scene.py's transfer function.
COLORS = [(0.0, (0.1, 0.2, 0.9)), (0.35, (0.1, 0.8, 0.8)), (0.7, (0.95, 0.85, 0.2)),
          (1.0, (0.9, 0.1, 0.1))]
OPACITIES = [0.0, 0.1, 0.5, 1.0]


def load(name, data, work):
    if name == "mixer":
        r = vtkUnstructuredGridReader()
        r.SetFileName(os.path.join(data, "mixer.vtk"))
        r.ReadAllScalarsOn()
        r.Update()
        return r.GetOutput()
    if name in ("post", "comb"):
        r = vtkMultiBlockPLOT3DReader()
        r.SetFileName(os.path.join(data, name + "xyz.bin"))
        r.SetQFileName(os.path.join(data, name + "q.bin"))
        r.AutoDetectFormatOn()
        r.Update()
        blocks = [r.GetOutput().GetBlock(0)]
    elif name.endswith("blocks"):
        r = vtkXMLMultiBlockDataReader()
        r.SetFileName(os.path.join(work, name + ".vtm"))
        r.Update()
        output = r.GetOutput()
        it = output.NewIterator()
        it.InitTraversal()
        blocks = []
        while not it.IsDoneWithTraversal():
            block = it.GetCurrentDataObject()
            if not isinstance(block, vtkPolyData):
                blocks.append(block)
            it.GoToNextItem()
    else:
        r = vtkXMLUnstructuredGridReader()
        r.SetFileName(os.path.join(work, name + ".vtu"))
        r.Update()
        return r.GetOutput()
    append = vtkAppendFilter()
    for block in blocks:
        append.AddInputData(block)
    append.Update()
    return append.GetOutput()


def main():
    p = argparse.ArgumentParser()
    p.add_argument("dataset")
    p.add_argument("scene")
    p.add_argument("out")
    p.add_argument("--data", required=True)
    p.add_argument("--work", required=True)
    args = p.parse_args()
    with open(args.scene) as f:
        scene = json.load(f)
    grid = load(args.dataset, args.data, args.work)
    lo, hi = scene["range"]
    w = hi - lo
    color = vtkColorTransferFunction()
    opacity = vtkPiecewiseFunction()
    if scene["opacity"] > 0.0:
        color.AddRGBPoint(lo, 1.0, 1.0, 1.0)
        color.AddRGBPoint(hi, 1.0, 1.0, 1.0)
        opacity.AddPoint(lo, scene["opacity"])
        opacity.AddPoint(hi, scene["opacity"])
    else:
        for (t, c), a in zip(COLORS, OPACITIES):
            color.AddRGBPoint(lo + t * w, *c)
            opacity.AddPoint(lo + t * w, a)
    prop = vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(scene["unit_distance"])
    prop.SetInterpolationTypeToLinear()
    mapper = cylvol.vtkCylVolMapper()
    mapper.SetInputData(grid)
    mapper.SetScalarModeToUsePointFieldData()
    mapper.SelectScalarArray(scene["array"])
    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    ren = vtkRenderer()
    ren.SetBackground(0.0, 0.0, 0.0)
    ren.AddVolume(volume)
    win = vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetMultiSamples(0)
    win.SetSize(200, 200)
    win.AddRenderer(ren)
    cam = ren.GetActiveCamera()
    c = scene["camera"]
    cam.SetPosition(*c["position"])
    cam.SetFocalPoint(*c["focal_point"])
    cam.SetViewUp(*c["view_up"])
    cam.SetViewAngle(c["view_angle"])
    cam.SetParallelProjection(c["parallel"])
    cam.SetParallelScale(c["parallel_scale"])
    cam.SetClippingRange(*c["clipping_range"])
    win.Render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.ShouldRerenderOff()
    grab.Update()
    writer = vtkPNGWriter()
    writer.SetFileName(args.out)
    writer.SetInputData(grab.GetOutput())
    writer.Write()
    print(json.dumps({"sample_distance": mapper.GetLastSampleDistance(),
                      "built_structure": mapper.GetBuiltStructure(),
                      "hexahedra": mapper.GetBuiltCellCount(12)}))


if __name__ == "__main__":
    main()
