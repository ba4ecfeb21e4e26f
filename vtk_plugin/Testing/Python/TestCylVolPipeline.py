"""A pure-Python VTK pipeline: reader -> cylvol.vtkCylVolMapper -> off-screen window -> PNG.

Run with Debian's /usr/bin/python3 (python3-vtk9) and PYTHONPATH pointing at the folder that
holds the `cylvol` package (the build tree's or an install prefix's site dir).
"""
import argparse
import os
import sys

from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
from vtkmodules.vtkIOImage import vtkPNGReader, vtkPNGWriter
from vtkmodules.vtkIOLegacy import vtkUnstructuredGridReader
from vtkmodules.vtkRenderingCore import (
    vtkColorTransferFunction,
    vtkRenderer,
    vtkRenderWindow,
    vtkVolume,
    vtkVolumeProperty,
    vtkWindowToImageFilter,
)

import cylvol


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--data", required=True, help="the shared data folder")
    parser.add_argument("--output", required=True, help="the PNG to write")
    args = parser.parse_args()

    reader = vtkUnstructuredGridReader()
    reader.SetFileName(os.path.join(args.data, "mixer.vtk"))
    reader.ReadAllScalarsOn()
    reader.Update()
    lo, hi = reader.GetOutput().GetPointData().GetArray("p").GetRange()

    mapper = cylvol.vtkCylVolMapper()
    mapper.SetInputConnection(reader.GetOutputPort())
    mapper.SetScalarModeToUsePointFieldData()
    mapper.SelectScalarArray("p")

    color = vtkColorTransferFunction()
    color.AddRGBPoint(lo, 0.1, 0.2, 0.9)
    color.AddRGBPoint(hi, 0.9, 0.2, 0.1)
    opacity = vtkPiecewiseFunction()
    opacity.AddPoint(lo, 0.0)
    opacity.AddPoint(hi, 1.0)
    prop = vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(0.05)
    prop.ShadeOn()

    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    ren = vtkRenderer()
    ren.AddVolume(volume)
    win = vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(200, 200)
    win.AddRenderer(ren)
    ren.ResetCamera()
    ren.GetActiveCamera().Azimuth(30)
    ren.GetActiveCamera().Elevation(20)
    win.Render()
    ren.GetActiveCamera().Azimuth(10)
    win.Render()

    grab = vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.ReadFrontBufferOff()
    grab.Update()
    writer = vtkPNGWriter()
    writer.SetFileName(args.output)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()

    # Read the PNG back: it must exist and show the volume.
    check = vtkPNGReader()
    check.SetFileName(args.output)
    check.Update()
    scalars = check.GetOutput().GetPointData().GetScalars()
    lit = sum(1 for i in range(scalars.GetNumberOfTuples()) if max(scalars.GetTuple(i)[:3]) > 0)
    print("cylvol", cylvol.vtkCylVolMapper.GetCylVolVersion(), "module", cylvol.__file__)
    print("builds", mapper.GetBuildCount(), "samples", mapper.GetLastSamples(),
          "hex tests", mapper.GetLastHexTests(), "lit pixels", lit,
          "render s %.3f" % mapper.GetLastRenderSeconds())
    failures = []
    if mapper.GetBuildCount() != 1:
        failures.append("built %d times over two frames" % mapper.GetBuildCount())
    if mapper.GetLastSamples() <= 0:
        failures.append("no samples")
    if lit < 1000:
        failures.append("only %d lit pixels in %s" % (lit, args.output))
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
