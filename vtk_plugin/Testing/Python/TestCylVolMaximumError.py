"""The mapper's error bound (SetMaximumError) against a converged reference, on the mixer.

The reference is the fixed step at 1/16 of cylvol's default step (SetRelativeSampleDistance)
with no early termination: what every render converges to as its samples get denser. Its own
error is bounded per pixel by its difference from the render at twice its step (the fixed
step's error falls at least linearly with the step): the reference's uncertainty there. The
images are the window's RGB over a black background (the premultiplied colour), 8 bits a
channel; a pixel's error is its largest channel difference in 1/255.

At SetMaximumError(2) every pixel is within 2/255 plus the allowance (the reference's
uncertainty there and 1/255 for rounding both images to 8 bits), but for at most 0.5 % of the
pixels (rays grazing the mesh's silhouette), and those within twice that; the bound does work
the fixed step does not (refined samples, slopes, integrated stretches), and
SetMaximumError(1) takes more samples than SetMaximumError(4).

Run with Debian's /usr/bin/python3 (python3-vtk9) and PYTHONPATH pointing at the folder that
holds the `cylvol` package.
"""
import argparse
import os
import sys

from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
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

SIDE = 160
SETTING = 2.0
ROUNDING = 1.0
SILHOUETTE_SHARE = 0.005
REFERENCE_FRACTION = 1.0 / 16.0


class Scene:
    """The mixer seen obliquely through one mapper, rendered off screen."""

    def __init__(self, data):
        reader = vtkUnstructuredGridReader()
        reader.SetFileName(os.path.join(data, "mixer.vtk"))
        reader.ReadAllScalarsOn()
        reader.Update()
        lo, hi = reader.GetOutput().GetPointData().GetArray("p").GetRange()
        bounds = reader.GetOutput().GetBounds()
        diagonal = sum((bounds[2 * k + 1] - bounds[2 * k]) ** 2 for k in range(3)) ** 0.5

        self.mapper = cylvol.vtkCylVolMapper()
        self.mapper.SetInputConnection(reader.GetOutputPort())
        self.mapper.SetScalarModeToUsePointFieldData()
        self.mapper.SelectScalarArray("p")

        color = vtkColorTransferFunction()
        color.AddRGBPoint(lo, 0.1, 0.2, 0.9)
        color.AddRGBPoint(0.5 * (lo + hi), 0.2, 0.9, 0.3)
        color.AddRGBPoint(hi, 0.9, 0.2, 0.1)
        opacity = vtkPiecewiseFunction()
        opacity.AddPoint(lo, 0.0)
        opacity.AddPoint(hi, 0.8)
        prop = vtkVolumeProperty()
        prop.SetColor(color)
        prop.SetScalarOpacity(opacity)
        prop.SetScalarOpacityUnitDistance(0.05 * diagonal)

        volume = vtkVolume()
        volume.SetMapper(self.mapper)
        volume.SetProperty(prop)
        self.renderer = vtkRenderer()
        self.renderer.SetBackground(0.0, 0.0, 0.0)
        self.renderer.AddVolume(volume)
        self.window = vtkRenderWindow()
        self.window.SetOffScreenRendering(1)
        self.window.SetSize(SIDE, SIDE)
        self.window.AddRenderer(self.renderer)
        self.renderer.ResetCamera()
        self.renderer.GetActiveCamera().Azimuth(30)
        self.renderer.GetActiveCamera().Elevation(20)

    def image(self, max_error, relative=1.0, early_termination=0.99):
        """The window's RGB pixels with these settings, and the mapper's counters."""
        m = self.mapper
        m.SetMaximumError(max_error)
        m.SetRelativeSampleDistance(relative)
        m.SetEarlyTermination(early_termination)
        self.window.Render()
        grab = vtkWindowToImageFilter()
        grab.SetInput(self.window)
        grab.ReadFrontBufferOff()
        grab.Update()
        rgb = grab.GetOutput().GetPointData().GetScalars()
        pixels = [rgb.GetTuple3(i) for i in range(rgb.GetNumberOfTuples())]
        counters = {
            "samples": m.GetLastSamples(),
            "refined_samples": m.GetLastRefinedSamples(),
            "slopes": m.GetLastSlopes(),
            "integrated_stretches": m.GetLastIntegratedStretches(),
            "seconds": m.GetLastRenderSeconds(),
        }
        return pixels, counters


def errors(image, reference):
    """Per pixel, the largest channel difference in 1/255."""
    return [max(abs(a - b) for a, b in zip(p, q)) for p, q in zip(image, reference)]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--data", required=True, help="the shared data folder")
    args = parser.parse_args()

    scene = Scene(args.data)
    failures = []
    if scene.mapper.GetMaximumError() != 0.0:
        failures.append("the default MaximumError is %g, not 0" % scene.mapper.GetMaximumError())
    fixed, fixed_work = scene.image(0.0)
    reference, _ = scene.image(0.0, REFERENCE_FRACTION, 1.0)
    coarser, _ = scene.image(0.0, 2.0 * REFERENCE_FRACTION, 1.0)
    uncertainty = errors(coarser, reference)
    bounded, work = scene.image(SETTING)
    error = errors(bounded, reference)
    allowed = [SETTING + ROUNDING + u for u in uncertainty]
    beyond = sum(1 for e, a in zip(error, allowed) if e > a)
    far_beyond = sum(1 for e, a in zip(error, allowed) if e > 2.0 * a)
    visible = sum(1 for p in reference if max(p) > 5)
    n = len(reference)
    print("reference: %d of %d pixels visible, uncertainty largest %.0f mean %.3f"
          % (visible, n, max(uncertainty), sum(uncertainty) / n))
    print("fixed step: largest error %.0f mean %.3f, %s"
          % (max(errors(fixed, reference)), sum(errors(fixed, reference)) / n, fixed_work))
    print("max error %g: largest error %.0f mean %.3f, %d pixels beyond the setting and the "
          "allowance, %d beyond twice, %s"
          % (SETTING, max(error), sum(error) / n, beyond, far_beyond, work))
    if visible * 4 < n:
        failures.append("only %d of %d pixels show the mixer" % (visible, n))
    if beyond > SILHOUETTE_SHARE * n:
        failures.append("%d pixels beyond %g/255 and the allowance" % (beyond, SETTING))
    if far_beyond:
        failures.append("%d pixels beyond twice %g/255 and the allowance" % (far_beyond, SETTING))
    if fixed_work["refined_samples"] or fixed_work["slopes"] or fixed_work["integrated_stretches"]:
        failures.append("the fixed step did error-bounded work: %s" % fixed_work)
    if not (work["refined_samples"] > 0 and work["slopes"] > 0 and work["integrated_stretches"] > 0):
        failures.append("the error-bounded render did no error-bounded work: %s" % work)
    _, tight = scene.image(1.0)
    _, loose = scene.image(4.0)
    print("max error 1: %s; max error 4: %s" % (tight, loose))
    if not tight["samples"] > loose["samples"]:
        failures.append("max error 1 took %d samples, 4 took %d"
                        % (tight["samples"], loose["samples"]))
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
