#!/usr/bin/python3
"""ParaView's "CylVol Volume" against ParaView's own "Volume" with each of its four mappers,
side by side in one run, then "CylVol Volume" on 1 and 2 MPI ranks.

Every renderer runs in its own pvbatch process (so that its peak memory is its own): read the
mesh (the point array drawn only), show it, pick the representation (and the mapper), render
a first frame (CylVol Volume gathers the volume cells and builds its structure inside it;
ParaView's Volume tetrahedralizes the grid inside it), then steady frames with the camera
turning by one degree a frame. The scene is the VTK CTest comparison's transfer function on
the array p, unit distance a tenth of the diagonal, black background, the camera turned by
azimuth 30 and elevation 20, SIZE x SIZE. The script prints each renderer's first frame,
median steady frame, peak resident memory (ru_maxrss of the process, of every rank under
MPI), its error against a converged reference (CylVol Volume at an eighth of its sample
distance, the same reference scripts/bench_vtk.py takes), and the ratios to CylVol Volume.

Usage (Debian's /usr/bin/python3, ParaView's Python unpacked by vtk_plugin/ParaView/run_tests.sh,
the plugin built in build/paraview; re-runs itself under xvfb-run when there is no display):
    /usr/bin/python3 scripts/bench_paraview.py                    # mixer:4 (2.15 M cells), 512
    /usr/bin/python3 scripts/bench_paraview.py --dataset mixer --size 256 --frames 2
Datasets: mixer (tests/data/mixer.vtk) or mixer:N (every hexahedron cut into N x N x N by
`cylvol gen tests/data/mixer.vtk --refine N`, written once into build/bench-paraview).
--only NAME[,NAME] runs some of: cylvol, "Projected tetra", "Z sweep", "Bunyk ray cast",
"Resample To Image", mpi1, mpi2 (the reference always runs). --json prints the results as
JSON as well.
"""
import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
DATA = os.path.join(REPO, "tests", "data")
CYLVOL = os.path.join(REPO, "target", "release", "cylvol")
PARAVIEW_MAPPERS = ["Projected tetra", "Z sweep", "Bunyk ray cast", "Resample To Image"]
COLORS = [(0.0, (0.1, 0.2, 0.9)), (0.35, (0.1, 0.8, 0.8)), (0.7, (0.95, 0.85, 0.2)),
          (1.0, (0.9, 0.1, 0.1))]
OPACITIES = [0.0, 0.1, 0.5, 1.0]


# ---------------------------------------------------------------------------------------
# worker side (pvbatch)


def worker(args):
    from paraview import servermanager
    from paraview.simple import (
        ColorBy, CreateView, GetColorTransferFunction, GetOpacityTransferFunction,
        LegacyVTKReader, LoadPlugin, Render, SaveScreenshot, Show, XMLUnstructuredGridReader,
        _DisableFirstRenderCameraReset)
    _DisableFirstRenderCameraReset()
    rank = servermanager.vtkProcessModule.GetProcessModule().GetPartitionId()
    out = {"renderer": args.worker, "rank": rank}
    LoadPlugin(args.plugin, ns=globals())
    if args.mesh.endswith(".vtk"):
        reader = LegacyVTKReader(FileNames=[args.mesh])
    else:
        reader = XMLUnstructuredGridReader(FileName=[args.mesh])
        reader.PointArrayStatus = ["p"]
        reader.CellArrayStatus = []
    t = time.perf_counter()
    reader.UpdatePipeline()
    out["load_s"] = time.perf_counter() - t
    view = CreateView("RenderView")
    view.ViewSize = [args.size, args.size]
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = [0.0, 0.0, 0.0]
    display = Show(reader, view)
    ColorBy(display, ("POINTS", "p"))
    if args.worker in PARAVIEW_MAPPERS:
        display.SetRepresentationType("Volume")
        display.SelectMapper = args.worker
    else:
        display.SetRepresentationType("CylVol Volume")
        if args.step > 0.0:
            display.CylVolSampleDistance = args.step
    lo, hi = args.range
    w = hi - lo
    lut = GetColorTransferFunction("p")
    lut.ColorSpace = "RGB"
    lut.Discretize = 0
    lut.AutomaticRescaleRangeMode = "Never"
    lut.RGBPoints = [v for t, c in COLORS for v in (lo + t * w,) + c]
    pwf = GetOpacityTransferFunction("p")
    pwf.Points = [v for (t, _), a in zip(COLORS, OPACITIES) for v in (lo + t * w, a, 0.5, 0.0)]
    display.ScalarOpacityUnitDistance = 0.1 * args.diagonal
    camera = view.GetActiveCamera()
    view.ResetCamera()
    camera.Azimuth(30.0)
    camera.Elevation(20.0)
    camera.OrthogonalizeViewUp()
    view.ResetCamera()

    t = time.perf_counter()
    Render(view)
    out["first_frame_s"] = time.perf_counter() - t
    out["peak_rss_bytes"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    # What a renderer too slow for its steady frames still reports.
    print("PARTIAL " + json.dumps(out), flush=True)
    turned = 0
    steady = []
    for _ in range(args.frames):
        step = 1 if turned == 0 else -1
        camera.Azimuth(float(step))
        turned += step
        t = time.perf_counter()
        Render(view)
        steady.append(time.perf_counter() - t)
    out["steady_frames_s"] = steady
    out["steady_s"] = sorted(steady)[len(steady) // 2] if steady else None
    if turned:
        camera.Azimuth(-float(turned))
    if args.png:
        SaveScreenshot(args.png if rank == 0 else args.png + ".rank%d.png" % rank, view,
                       ImageResolution=[args.size, args.size], TransparentBackground=0)
    if args.worker not in PARAVIEW_MAPPERS:
        display.SMProxy.UpdatePropertyInformation()
        stats = list(display.GetPropertyValue("CylVolRenderStatistics"))
        whole = list(display.GetPropertyValue("CylVolWholeDataset"))
        out.update({"piece_cells": stats[0], "samples": stats[4], "step": stats[5],
                    "whole_dataset_step": whole[2], "last_render_s": stats[3],
                    "structure": display.GetPropertyValue("CylVolBuiltStructure")})
    out["peak_rss_bytes"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    print("RESULT " + json.dumps(out), flush=True)


# ---------------------------------------------------------------------------------------
# parent side (/usr/bin/python3 with VTK 9.1)


def mesh_file(spec, workdir):
    if ":" not in spec:
        return os.path.join(DATA, spec + ".vtk")
    name, refine = spec.split(":")
    path = os.path.join(workdir, "%s%s.vtu" % (name, refine))
    if not os.path.exists(path):
        print("writing %s (cylvol gen %s.vtk --refine %s)" % (path, name, refine), flush=True)
        subprocess.run([CYLVOL, "gen", os.path.join(DATA, name + ".vtk"), "--refine", refine,
                        "-o", path], check=True)
    return path


def figures_of(path):
    """The range of p and the bounds' diagonal (every rank needs the whole mesh's)."""
    if path.endswith(".vtk"):
        from vtkmodules.vtkIOLegacy import vtkUnstructuredGridReader
        r = vtkUnstructuredGridReader()
        r.ReadAllScalarsOn()
    else:
        from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
        r = vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    grid = r.GetOutput()
    return grid.GetPointData().GetArray("p").GetRange(), grid.GetLength()


def image_difference(png_a, png_b):
    from vtkmodules.vtkIOImage import vtkPNGReader
    images = []
    for p in (png_a, png_b):
        r = vtkPNGReader()
        r.SetFileName(p)
        r.Update()
        s = r.GetOutput().GetPointData().GetScalars()
        c = s.GetNumberOfComponents()
        raw = bytes(memoryview(s))
        images.append([raw[i:i + 3] for i in range(0, len(raw), c)])
    total, within = 0, 0
    for pa, pb in zip(*images):
        d = [abs(x - y) for x, y in zip(pa, pb)]
        total += sum(d)
        within += max(d) <= 8
    n = len(images[0])
    return total / (3.0 * n), 100.0 * within / n


def run_worker(name, args, mesh, figures, png, ranks=0, step=0.0, frames=None):
    """One renderer in its own pvbatch; `ranks` > 0: pvbatch --symmetric on that many MPI
    ranks."""
    env = dict(os.environ)
    env["PYTHONPATH"] = args.paraview_python
    if os.path.exists(png):
        os.remove(png)
    cmd = ["pvbatch"]
    if ranks > 0:
        cmd = ["mpiexec", "-n", str(ranks), "--oversubscribe"]
        if os.geteuid() == 0:
            cmd.append("--allow-run-as-root")
        cmd += ["-x", "DISPLAY", "-x", "PYTHONPATH"]
        if env.get("XAUTHORITY"):
            cmd += ["-x", "XAUTHORITY"]
        cmd += ["pvbatch", "--symmetric"]
    (lo, hi), diagonal = figures
    cmd += [os.path.abspath(__file__), "--worker", name, "--plugin", args.plugin, "--mesh", mesh,
            "--size", str(args.size), "--frames", str(args.frames if frames is None else frames),
            "--png", png, "--step", repr(step), "--range", repr(lo), repr(hi),
            "--diagonal", repr(diagonal)]
    t = time.perf_counter()
    try:
        proc = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              text=True, timeout=args.timeout)
        output = proc.stdout
    except subprocess.TimeoutExpired as e:
        output = e.stdout.decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
        partial = [json.loads(line[8:]) for line in output.splitlines()
                   if line.startswith("PARTIAL ")]
        if not partial:
            return {"renderer": name, "error": "no first frame in %d s" % args.timeout}
        r = dict(partial[0], steady_s=None, png=png, rank_peak_rss_bytes=[
            partial[0]["peak_rss_bytes"]], error_steady="no steady frame in %d s" % args.timeout)
        return r
    results = [json.loads(line[7:]) for line in output.splitlines()
               if line.startswith("RESULT ")]
    if not results:
        return {"renderer": name, "error": "exit status %d; output tail:\n%s"
                % (proc.returncode, output[-2000:])}
    results.sort(key=lambda r: r["rank"])
    r = dict(results[0])
    r["wall_s"] = time.perf_counter() - t
    r["png"] = png
    r["rank_peak_rss_bytes"] = [x["peak_rss_bytes"] for x in results]
    return r


def fmt_s(x):
    return "-" if x is None else ("%.3f" % x if x < 10 else "%.1f" % x)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--worker", help=argparse.SUPPRESS)
    p.add_argument("--mesh", help=argparse.SUPPRESS)
    p.add_argument("--png", default="", help=argparse.SUPPRESS)
    p.add_argument("--step", type=float, default=0.0, help=argparse.SUPPRESS)
    p.add_argument("--range", type=float, nargs=2, help=argparse.SUPPRESS)
    p.add_argument("--diagonal", type=float, help=argparse.SUPPRESS)
    p.add_argument("--dataset", default="mixer:4")
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--frames", type=int, default=3, help="steady frames per renderer")
    p.add_argument("--timeout", type=int, default=1800, help="seconds per renderer")
    p.add_argument("--only", default="")
    p.add_argument("--json", action="store_true")
    p.add_argument("--plugin", default="")
    p.add_argument("--paraview-python",
                   default=os.path.join(REPO, "build", "python3-paraview", "root", "usr", "lib",
                                        "python3", "dist-packages"))
    args = p.parse_args()
    if args.worker:
        worker(args)
        return 0
    if not os.environ.get("DISPLAY") and shutil.which("xvfb-run"):
        return subprocess.call(["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24 -noreset",
                                sys.executable] + sys.argv)
    if not args.plugin:
        with open(os.path.join(REPO, "build", "paraview", "plugin_path.txt")) as f:
            args.plugin = f.read().strip()
    workdir = os.path.join(REPO, "build", "bench-paraview")
    os.makedirs(workdir, exist_ok=True)
    mesh = mesh_file(args.dataset, workdir)
    figures = figures_of(mesh)
    only = [o for o in args.only.split(",") if o]

    def wanted(name):
        return not only or name in only

    def png(name):
        return os.path.join(workdir, name.replace(" ", "-").lower() + ".png")

    runs = {}
    if wanted("cylvol"):
        runs["CylVol Volume"] = run_worker("cylvol", args, mesh, figures, png("cylvol"))
    for mapper in PARAVIEW_MAPPERS:
        if wanted(mapper):
            runs["Volume, " + mapper] = run_worker(mapper, args, mesh, figures, png(mapper))
    for ranks in (1, 2):
        if wanted("mpi%d" % ranks):
            runs["CylVol Volume, %d MPI rank%s" % (ranks, "s" if ranks > 1 else "")] = run_worker(
                "cylvol", args, mesh, figures, png("mpi%d" % ranks), ranks=ranks)
    # The converged reference: CylVol Volume at an eighth of the whole dataset's step.
    base = next((r for r in runs.values() if r.get("whole_dataset_step")), None)
    if base is None:
        base = run_worker("cylvol", args, mesh, figures, png("cylvol"), frames=0)
    reference = run_worker("cylvol", args, mesh, figures, png("reference"),
                           step=base["whole_dataset_step"] / 8.0, frames=0)

    print("\n%s, %dx%d, %d steady frames each (one degree apart); pvbatch, ParaView 5.11"
          % (args.dataset, args.size, args.size, args.frames))
    print("%-34s %10s %10s %12s %22s" % ("renderer", "first s", "steady s", "peak MB",
                                         "vs reference (mean, %)"))
    ours = runs.get("CylVol Volume", {})
    for name, r in runs.items():
        if "error" in r:
            print("%-34s %s" % (name, r["error"].splitlines()[0]))
            continue
        mean = pct = None
        if "error" not in reference and os.path.exists(r["png"]):
            mean, pct = image_difference(reference["png"], r["png"])
            r["error_vs_reference"] = {"mean_abs_255": mean, "percent_within_8": pct}
        memory = "/".join("%.0f" % (b / 2 ** 20) for b in r["rank_peak_rss_bytes"])
        print("%-34s %10s %10s %12s %22s" % (
            name, fmt_s(r["first_frame_s"]), fmt_s(r["steady_s"]), memory,
            "-" if mean is None else "%.3f/255, %.2f" % (mean, pct)))
    if ours and "error" not in ours:
        print("\nratios, renderer / CylVol Volume:")
        for name, r in runs.items():
            if name == "CylVol Volume" or "error" in r:
                continue
            steady = ("%.2fx" % (r["steady_s"] / ours["steady_s"])
                      if r["steady_s"] and ours["steady_s"] else "-")
            print("  %-32s first frame %.2fx, steady frame %s, peak memory %.2fx%s" % (
                name, r["first_frame_s"] / ours["first_frame_s"], steady,
                r["rank_peak_rss_bytes"][0] / ours["rank_peak_rss_bytes"][0],
                " (%s)" % r["error_steady"] if "error_steady" in r else ""))
    if args.json:
        print(json.dumps({"dataset": args.dataset, "size": args.size, "runs": runs,
                          "reference": reference}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
