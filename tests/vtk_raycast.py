"""Renders one scene with VTK's unstructured ray caster, as a VTK user gets it.

Run by Debian's /usr/bin/python3 (python3-vtk9) from tests/max_error_vtk.rs. The mesh (legacy
.vtk or .vtu) is tetrahedralized with vtkDataSetTriangleFilter and drawn by
vtkUnstructuredGridVolumeRayCastMapper with its default integrator, the camera and transfer
function given in SCENE.json; the window's RGB (black background) is written as little-endian
float32, rows bottom to top, values in [0, 1].

Usage: vtk_raycast.py MESH SCENE.json OUT.raw
SCENE.json: {"scalar", "size", "position", "focal", "up", "view_angle",
             "colors": [[s, r, g, b], ...], "opacities": [[s, a], ...], "unit_distance"}
"""
import json
import struct
import sys

import vtkmodules.vtkRenderingOpenGL2  # noqa: F401
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401
from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
from vtkmodules.vtkFiltersGeneral import vtkDataSetTriangleFilter
from vtkmodules.vtkIOLegacy import vtkUnstructuredGridReader
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
from vtkmodules.vtkRenderingCore import (
    vtkColorTransferFunction, vtkRenderer, vtkRenderWindow, vtkVolume, vtkVolumeProperty,
    vtkWindowToImageFilter)
from vtkmodules.vtkRenderingVolume import vtkUnstructuredGridVolumeRayCastMapper


def main():
    mesh, scene_file, out = sys.argv[1:4]
    with open(scene_file) as f:
        scene = json.load(f)
    if mesh.endswith(".vtu"):
        reader = vtkXMLUnstructuredGridReader()
    else:
        reader = vtkUnstructuredGridReader()
        reader.ReadAllScalarsOn()
    reader.SetFileName(mesh)
    reader.Update()
    grid = reader.GetOutput()
    grid.GetPointData().SetActiveScalars(scene["scalar"])
    tets = vtkDataSetTriangleFilter()
    tets.SetInputData(grid)
    tets.Update()
    mapper = vtkUnstructuredGridVolumeRayCastMapper()
    mapper.SetInputData(tets.GetOutput())
    mapper.SetScalarModeToUsePointFieldData()
    mapper.SelectScalarArray(scene["scalar"])
    color = vtkColorTransferFunction()
    for s, r, g, b in scene["colors"]:
        color.AddRGBPoint(s, r, g, b)
    opacity = vtkPiecewiseFunction()
    for s, a in scene["opacities"]:
        opacity.AddPoint(s, a)
    prop = vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(scene["unit_distance"])
    prop.SetInterpolationTypeToLinear()
    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    ren = vtkRenderer()
    ren.SetBackground(0, 0, 0)
    ren.AddVolume(volume)
    win = vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetMultiSamples(0)
    size = scene["size"]
    win.SetSize(size, size)
    win.AddRenderer(ren)
    cam = ren.GetActiveCamera()
    cam.SetPosition(*scene["position"])
    cam.SetFocalPoint(*scene["focal"])
    cam.SetViewUp(*scene["up"])
    cam.SetViewAngle(scene["view_angle"])
    ren.ResetCameraClippingRange()
    win.Render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.ShouldRerenderOff()
    grab.Update()
    image = grab.GetOutput()
    scalars = image.GetPointData().GetScalars()
    n = scalars.GetNumberOfTuples()
    values = []
    for k in range(n):
        values.extend(c / 255.0 for c in scalars.GetTuple3(k))
    with open(out, "wb") as f:
        f.write(struct.pack("<%df" % len(values), *values))


if __name__ == "__main__":
    main()
