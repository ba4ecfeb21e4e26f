"""Renders test scenes in ParaView and writes their images and figures.

Run by pvbatch, serial or under MPI (--symmetric, so that every rank reports its own
figures), by pvpython connected to a pvserver (--connect), or by the paraview GUI (whose
script takes its functions); see cylvol_paraview_test.py, which runs it. A scene is the VTK
CTest comparison's: the dataset's scalar through four colour and opacity points on the same
abscissae, unit distance a tenth of the diagonal, 200x200, black background, the camera
ResetCamera sets turned by azimuth 30 and elevation 20 (or a parallel view along +x).

For each scene of --scenes, writes OUT.png (the view; the first rank's under MPI) and
OUT.rank<R>.json on every rank: the representations offered, the camera, the transfer
function's range and unit distance, and the representation's figures (structure and axis
built, cells by type, the rank's box, clipping planes, samples, sample distance, the whole
dataset's figures, the error bound and its work). "pv_scene: begin OUT" and "pv_scene: end OUT" frame what ParaView prints
while it draws the scene.
"""
import argparse
import json
import os
import sys

# pvpython (not pvbatch) puts its system dist-packages ahead of PYTHONPATH; where Debian's
# python3-vtk9 is installed, that folder's vtkmodules is VTK 9.1's, which ParaView cannot
# load. ParaView's Python comes first.
_FIRST = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
sys.path[:] = _FIRST + [p for p in sys.path if p not in _FIRST]

import paraview.simple  # noqa: E402
from paraview import servermanager  # noqa: E402
from paraview.simple import (  # noqa: E402
    ColorBy, CreateView, GetColorTransferFunction, GetOpacityTransferFunction,
    LegacyVTKReader, LoadPlugin, MergeBlocks, PLOT3DReader, Render, SaveScreenshot, SetActiveView,
    Show, Sphere, Wavelet, XMLMultiBlockDataReader, XMLUnstructuredGridReader)

# The VTK CTest's transfer function (CylVolTestUtilities.h, MakeProperty): colour and opacity
# points on the same abscissae, fractions of the scalar range.
COLORS = [(0.0, (0.1, 0.2, 0.9)), (0.35, (0.1, 0.8, 0.8)), (0.7, (0.95, 0.85, 0.2)),
          (1.0, (0.9, 0.1, 0.1))]
OPACITIES = [0.0, 0.1, 0.5, 1.0]
SIZE = 200
FIGURES = ["BuiltStructure", "BuiltAxis", "CellTypeCounts", "PieceBox", "RenderStatistics",
           "WholeDataset", "BuiltPeriodicCopies", "ErrorBounded"]


def parse():
    p = argparse.ArgumentParser()
    p.add_argument("--plugin", required=True)
    p.add_argument("--data", required=True, help="tests/data")
    p.add_argument("--work", required=True, help="the folder of the files the driver wrote")
    p.add_argument("--scenes", required=True,
                   help="a JSON file: a list of scenes, each {out, dataset, representation "
                        "(default CylVol Volume), mapper (ParaView's Volume's SelectMapper), "
                        "step_factor (the CylVol sample distance as a multiple of the whole "
                        "dataset's default step), max_error (the CylVol maximum error), opacity (a constant opacity: the slab), "
                        "merge_blocks (Merge Blocks first), range and diagonal (the scalar "
                        "range and the bounds' diagonal, else ParaView's data information), view "
                        "(x: a parallel view along +x; else turned by azimuth 30 and elevation "
                        "20)}")
    p.add_argument("--connect", default="", help="HOST:PORT of a pvserver")
    return p.parse_args()


def reader(name, data, work):
    """The source and the (association, array) drawn."""
    if name == "mixer":
        return LegacyVTKReader(FileNames=[os.path.join(data, "mixer.vtk")]), ("POINTS", "p")
    if name in ("post", "comb"):
        r = PLOT3DReader(FileName=os.path.join(data, name + "xyz.bin"),
                         QFileName=[os.path.join(data, name + "q.bin")])
        r.AutoDetectFormat = 1
        return r, ("POINTS", "StagnationEnergy" if name == "post" else "Density")
    if name in ("blocks", "tiny-blocks"):
        return XMLMultiBlockDataReader(FileName=[os.path.join(work, name + ".vtm")]), ("POINTS", "p")
    if name == "wavelet":
        return Wavelet(), ("POINTS", "RTData")
    if name == "sphere":
        return Sphere(), ("POINTS", "Normals")
    # Unstructured grids the driver wrote: slab, polyhedron, quadratic.
    return XMLUnstructuredGridReader(FileName=[os.path.join(work, name + ".vtu")]), ("POINTS", "s")


def set_transfer_function(display, array, lo, hi, diagonal, opacity):
    if hi <= lo:
        lo, hi = lo - 1.0, hi + 1.0
    w = hi - lo
    lut = GetColorTransferFunction(array)
    lut.ColorSpace = "RGB"
    lut.Discretize = 0
    lut.AutomaticRescaleRangeMode = "Never"
    pwf = GetOpacityTransferFunction(array)
    if opacity > 0.0:
        lut.RGBPoints = [lo, 1.0, 1.0, 1.0, hi, 1.0, 1.0, 1.0]
        pwf.Points = [lo, opacity, 0.5, 0.0, hi, opacity, 0.5, 0.0]
        display.ScalarOpacityUnitDistance = 1.0
    else:
        lut.RGBPoints = [v for t, c in COLORS for v in (lo + t * w,) + c]
        pwf.Points = [v for (t, _), a in zip(COLORS, OPACITIES) for v in (lo + t * w, a, 0.5, 0.0)]
        display.ScalarOpacityUnitDistance = 0.1 * diagonal
    display.LookupTable = lut
    display.ScalarOpacityFunction = pwf


def plain(value):
    """A property's value as JSON takes it."""
    return [v for v in value] if hasattr(value, "__iter__") and not isinstance(value, str) else value


def rank():
    return servermanager.vtkProcessModule.GetProcessModule().GetPartitionId()


def render(scene, args):
    """Renders one scene, writes its image and figures."""
    out = scene["out"]
    representation = scene.get("representation", "CylVol Volume")
    opacity = scene.get("opacity", 0.0)
    print("pv_scene: begin %s" % out, flush=True)
    source, (association, array) = reader(scene["dataset"], args.data, args.work)
    if scene.get("merge_blocks"):
        # ParaView's own Volume draws one unstructured grid (not a PLOT3D multiblock, nor
        # several blocks): Merge Blocks first, as its users do.
        source = MergeBlocks(Input=source)
    view = CreateView("RenderView")
    SetActiveView(view)
    view.ViewSize = [SIZE, SIZE]
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = [0.0, 0.0, 0.0]
    display = Show(source, view)
    offered = list(display.Representation.Available)
    result = {"offered": offered, "representation_offered": representation in offered}
    if representation in offered:
        ColorBy(display, (association, array))
        display.SetRepresentationType(representation)
        if scene.get("mapper"):
            display.SelectMapper = scene["mapper"]
        if "max_error" in scene:
            display.CylVolMaximumError = scene["max_error"]
        if "periodic" in scene:
            display.CylVolPeriodicCopies = scene["periodic"]
            display.CylVolCopyRange = scene.get("copy_range", [0, 0])
        if "range" in scene:
            # Under MPI with --symmetric each rank's data information is its own piece's:
            # the driver gives the whole dataset's figures.
            (lo, hi), diagonal = scene["range"], scene["diagonal"]
        else:
            bounds = source.GetDataInformation().GetBounds()
            diagonal = sum((bounds[2 * k + 1] - bounds[2 * k]) ** 2 for k in range(3)) ** 0.5
            values = source.PointData[array] if association == "POINTS" else source.CellData[array]
            lo, hi = values.GetRange(0)
        set_transfer_function(display, array, lo, hi, diagonal, opacity)
        result.update({"array": array, "range": [lo, hi], "diagonal": diagonal,
                       "unit_distance": plain(display.GetPropertyValue("ScalarOpacityUnitDistance")),
                       "opacity": opacity})
    camera = view.GetActiveCamera()
    view.ResetCamera()
    if scene.get("view") == "x":
        # Along +x, through every rank's box: parallel rays, each crossing the whole slab.
        focal = camera.GetFocalPoint()
        camera.SetPosition(focal[0] - 10.0, focal[1], focal[2])
        camera.SetViewUp(0.0, 0.0, 1.0)
        view.CameraParallelProjection = 1
        view.ResetCamera()
        camera.SetParallelScale(0.6)
    else:
        camera.Azimuth(30.0)
        camera.Elevation(20.0)
        camera.OrthogonalizeViewUp()
        view.ResetCamera()
    cylvol = representation == "CylVol Volume" and result["representation_offered"]
    if cylvol and scene.get("step_factor"):
        Render(view)
        display.SMProxy.UpdatePropertyInformation()
        step = display.GetPropertyValue("CylVolWholeDataset")[2]
        display.CylVolSampleDistance = step * scene["step_factor"]
    Render(view)
    SaveScreenshot(out + (".png" if rank() == 0 else ".rank%d.png" % rank()), view,
                   ImageResolution=[SIZE, SIZE], TransparentBackground=0)
    result["camera"] = {
        "position": list(camera.GetPosition()), "focal_point": list(camera.GetFocalPoint()),
        "view_up": list(camera.GetViewUp()), "view_angle": camera.GetViewAngle(),
        "clipping_range": list(camera.GetClippingRange()),
        "parallel": camera.GetParallelProjection(), "parallel_scale": camera.GetParallelScale()}
    if cylvol:
        display.SMProxy.UpdatePropertyInformation()
        result["figures"] = {n: plain(display.GetPropertyValue("CylVol" + n)) for n in FIGURES}
    result["rank"] = rank()
    with open("%s.rank%d.json" % (out, rank()), "w") as f:
        json.dump(result, f, indent=1)
    print("pv_scene: end %s" % out, flush=True)


def main():
    args = parse()
    # The camera is the one each scene sets, not one the first render resets.
    paraview.simple._DisableFirstRenderCameraReset()
    if args.connect:
        host, port = args.connect.split(":")
        paraview.simple.Connect(host, int(port))
        LoadPlugin(args.plugin, remote=True, ns=globals())
    LoadPlugin(args.plugin, remote=False, ns=globals())
    with open(args.scenes) as f:
        scenes = json.load(f)
    for scene in scenes:
        render(scene, args)


if __name__ == "__main__":
    main()
    sys.stdout.flush()
