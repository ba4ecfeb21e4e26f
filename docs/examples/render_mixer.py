"""Renders the OpenFOAM mixer (tests/data/mixer.vtk) with cylvol's VTK mapper, off screen, to
mixer.png: a VTK pipeline in which vtkCylVolMapper takes the place of VTK's unstructured volume
mappers. Run from the repository's root, with Debian's VTK and the module built:

    PYTHONPATH=build/vtk_plugin/lib/python3/dist-packages \
        xvfb-run -a /usr/bin/python3 docs/examples/render_mixer.py
"""
import sys

import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 (the render window's implementation)
from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
from vtkmodules.vtkIOImage import vtkPNGWriter
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

path = sys.argv[1] if len(sys.argv) > 1 else "tests/data/mixer.vtk"
reader = vtkUnstructuredGridReader()
reader.SetFileName(path)
reader.ReadAllScalarsOn()
reader.Update()
lo, hi = reader.GetOutput().GetPointData().GetArray("p").GetRange()

mapper = cylvol.vtkCylVolMapper()  # the structure and the machine's axis are chosen for you
mapper.SetInputConnection(reader.GetOutputPort())
mapper.SetScalarModeToUsePointFieldData()
mapper.SelectScalarArray("p")

color = vtkColorTransferFunction()
color.AddRGBPoint(lo, 0.1, 0.2, 0.9)
color.AddRGBPoint(0.5 * (lo + hi), 0.1, 0.8, 0.8)
color.AddRGBPoint(hi, 0.9, 0.2, 0.1)
opacity = vtkPiecewiseFunction()
opacity.AddPoint(lo, 0.2)
opacity.AddPoint(hi, 1.0)
prop = vtkVolumeProperty()
prop.SetColor(color)
prop.SetScalarOpacity(opacity)
prop.SetScalarOpacityUnitDistance(0.02)
prop.ShadeOn()

volume = vtkVolume()
volume.SetMapper(mapper)
volume.SetProperty(prop)
renderer = vtkRenderer()
renderer.AddVolume(volume)
window = vtkRenderWindow()
window.SetOffScreenRendering(1)
window.SetSize(400, 400)
window.AddRenderer(renderer)
renderer.ResetCamera()
renderer.GetActiveCamera().Azimuth(30)
renderer.GetActiveCamera().Elevation(20)
window.Render()

grab = vtkWindowToImageFilter()
grab.SetInput(window)
grab.ReadFrontBufferOff()
writer = vtkPNGWriter()
writer.SetFileName("mixer.png")
writer.SetInputConnection(grab.GetOutputPort())
writer.Write()
structures = {1: "cart-grid", 2: "cyl-grid", 3: "cart-bvh", 4: "cyl-bvh"}
print("%s: %d cells, %s built in %.2f s, %d samples; wrote mixer.png"
      % (path, reader.GetOutput().GetNumberOfCells(), structures.get(mapper.GetBuiltStructure()),
         mapper.GetLastBuildSeconds(), mapper.GetLastSamples()))
