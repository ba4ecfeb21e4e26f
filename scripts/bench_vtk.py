#!/usr/bin/python3
"""cylvol's vtkCylVolMapper against VTK's unstructured volume mappers, side by side.

Mappers (--mappers, default all):
    cylvol           vtkCylVolMapper on the hexahedra, at its default step, at multiples of it
                     (--relative-steps) and at error settings (--max-errors, SetMaximumError)
    vtk-raycast      vtkUnstructuredGridVolumeRayCastMapper on vtkDataSetTriangleFilter's
                     tetrahedra (VTK needs them)
    zsweep           vtkUnstructuredGridVolumeZSweepMapper on the same tetrahedra
    projected-tetra  vtkProjectedTetrahedraMapper on the same tetrahedra (OpenGL; ParaView's
                     default for unstructured volumes)
    resample-smart   vtkResampleToImage onto a regular grid of N x N x N points (--resample-dims,
                     default 100: the default SamplingDimensions of ParaView's Resample To Image
                     filter), then vtkSmartVolumeMapper (OpenGL): ParaView's usual workaround
For each dataset, each mapper runs in its own subprocess (so that its peak memory is its own):
load the mesh, prepare what the mapper needs (tetrahedralize or resample; cylvol builds its
structure inside its first render), render the first frame, then steady frames with the camera
turning by one degree a frame. The first frame is counted from the loaded mesh to the first
image: it includes the tetrahedralization or the resampling (also reported apart as
prepare_s). The steady frame is the median of the steady frames. The same camera, transfer
function and unit distance as the CTest comparison are used; VTK's two CPU ray casters render
every pixel (AutoAdjustSampleDistances off). Each mapper's first image is compared with a
converged reference, cylvol at 1/8 of its default step: per pixel, the largest of the R, G, B
differences; reported are the mean difference over the channels, the 99th percentile and the
maximum of the per-pixel difference (all in 1/255) and the share of pixels within 8/255. The
script prints, per dataset, every run's times, peak resident memory (ru_maxrss of the worker)
and error, and the ratios competitor / cylvol (first frame, steady frame, peak memory) for
cylvol's default and each of its settings.

A worker that does not finish within --timeout seconds is stopped and reported as not finished
(with its first frame if it had one). A mapper whose memory need, estimated from the cells
(MEMORY_MODEL, from this benchmark's own runs), exceeds the memory available at its start is
skipped, and the report says so.

Usage (Debian's python3-vtk9 and the build tree's cylvol package; re-runs itself under
xvfb-run when there is no display, as the OpenGL mappers need one):
    /usr/bin/python3 scripts/bench_vtk.py                      # mixer and rotor:200000, all mappers
    /usr/bin/python3 scripts/bench_vtk.py mixer:4 --mappers cylvol,vtk-raycast --timeout 600
    /usr/bin/python3 scripts/bench_vtk.py mixer --max-errors 1,4 --relative-steps 1,4
Before measuring, the script brings what it measures up to date with the sources: `cargo build
--release` (the cylvol command that generates meshes) and `cmake --build build/vtk_plugin`
(configured first if need be; it rebuilds libcylvol.a through cargo and relinks the module), so
the figures are never those of a stale module. --no-build skips both; with --pythonpath the
package given is used as it is (only the cylvol command is built).
Datasets: mixer, hexa, comb, post (from tests/data), mixer:N or hexa:N (that mesh with every
hexahedron cut into N x N x N by `cylvol gen FILE --refine N`; mixer:4 is the 2.15 M-cell refined
mixer) or rotor[:CELLS] (generated with `cylvol gen pump-rotor:CELLS`; rotor alone is
rotor:2100000).
--only vtk (or cylvol) runs that one mapper without the reference. --keep DIR keeps the
generated meshes and the images. --json prints, after the text report and
the line naming that folder, the results as a JSON array (one object per dataset: `runs` per
mapper and setting, each with its `error_vs_reference`, and `ratios`, competitor / cylvol);
scripts/make_benchmarks_doc.py reads it to write docs/benchmarks.md. Times depend on the
machine and on what else runs on it: compare the ratios of one run, in which the mappers ran
side by side.
"""
import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
DATA = os.path.join(REPO, "tests", "data")
BUILD = os.path.join(REPO, "build", "vtk_plugin")
CYLVOL = os.path.join(REPO, "target", "release", "cylvol")
# vtkCylVolMapper's StructureType values.
STRUCTURES = {"auto": 0, "cart-grid": 1, "cyl-grid": 2, "cart-bvh": 3, "cyl-bvh": 4}
MAPPERS = ["cylvol", "vtk-raycast", "zsweep", "projected-tetra", "resample-smart"]
COMPETITORS = MAPPERS[1:]
# The mappers that render VTK's tetrahedralization of the mesh.
ON_TETRAHEDRA = ("vtk-raycast", "zsweep", "projected-tetra")
# A worker's memory need: (bytes, bytes per hexahedron of the mesh), rounded up from the peak
# resident memory this benchmark measured on the 2.15 M-cell refined mixer (cylvol 1.27 GB,
# VTK's ray caster 6.15 GB, Z-sweep 8.1 GB when stopped, projected tetrahedra 2.9 GB, resample
# and smart mapper 0.85 GB).
MEMORY_MODEL = {
    "cylvol": (200e6, 650),
    "vtk-raycast": (250e6, 3000),
    "zsweep": (250e6, 4000),
    "projected-tetra": (250e6, 1500),
    "resample-smart": (250e6, 450),
}
# A cylvol run whose error setting this build of the module cannot take.
UNAVAILABLE = "not available in this build (vtkCylVolMapper has no SetMaximumError)"


def default_pythonpath():
    dest_file = os.path.join(BUILD, "python_destination.txt")
    if os.path.exists(dest_file):
        with open(dest_file) as f:
            return os.path.join(BUILD, f.read().strip())
    return ""


# ---------------------------------------------------------------------------------------
# worker side


def load(spec, workdir):
    """Returns (vtkUnstructuredGrid, scalar name)."""
    from vtkmodules.vtkFiltersCore import vtkAppendFilter
    from vtkmodules.vtkIOLegacy import vtkUnstructuredGridReader
    from vtkmodules.vtkIOParallel import vtkMultiBlockPLOT3DReader
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    name = spec.split(":")[0]
    if name == "wheel":
        r = vtkXMLUnstructuredGridReader()
        r.SetFileName(wheel_file(spec, workdir))
        r.Update()
        return r.GetOutput(), "p"
    if name in ("mixer", "hexa") and ":" in spec:
        r = vtkXMLUnstructuredGridReader()
        r.SetFileName(refined_file(spec, workdir))
        r.Update()
        return r.GetOutput(), ("p" if name == "mixer" else "scalars")
    if name in ("mixer", "hexa"):
        r = vtkUnstructuredGridReader()
        r.SetFileName(os.path.join(DATA, name + ".vtk"))
        r.ReadAllScalarsOn()
        r.Update()
        return r.GetOutput(), ("p" if name == "mixer" else "scalars")
    if name in ("comb", "post"):
        r = vtkMultiBlockPLOT3DReader()
        r.SetFileName(os.path.join(DATA, name + "xyz.bin"))
        r.SetQFileName(os.path.join(DATA, name + "q.bin"))
        r.AutoDetectFormatOn()
        r.Update()
        a = vtkAppendFilter()
        a.AddInputData(r.GetOutput().GetBlock(0))
        a.Update()
        return a.GetOutput(), ("Density" if name == "comb" else "StagnationEnergy")
    if name == "rotor":
        r = vtkXMLUnstructuredGridReader()
        r.SetFileName(rotor_file(spec, workdir))
        r.Update()
        return r.GetOutput(), "pressure"
    raise SystemExit("unknown dataset " + spec)


def refined_file(spec, workdir):
    name, n = spec.split(":")
    return os.path.join(workdir, "%s-refined-%s.vtu" % (name, n))


def wheel_file(spec, workdir):
    """wheel:mixer[:N]: the replicated wheel of that sector (`cylvol gen --periodic auto`)."""
    return os.path.join(workdir, "wheel-%s.vtu" % spec.split(":", 1)[1].replace(":", "-"))


def rotor_file(spec, workdir):
    cells = spec.split(":")[1] if ":" in spec else "2100000"
    return os.path.join(workdir, "pump-rotor-%s.vtu" % cells)


def make_property(lo, hi, diagonal):
    from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
    from vtkmodules.vtkRenderingCore import vtkColorTransferFunction, vtkVolumeProperty

    w = hi - lo
    color = vtkColorTransferFunction()
    color.AddRGBPoint(lo, 0.1, 0.2, 0.9)
    color.AddRGBPoint(lo + 0.35 * w, 0.1, 0.8, 0.8)
    color.AddRGBPoint(lo + 0.7 * w, 0.95, 0.85, 0.2)
    color.AddRGBPoint(hi, 0.9, 0.1, 0.1)
    opacity = vtkPiecewiseFunction()
    # The same abscissae as the colours: VTK 9.1's unstructured ray integrators only see the
    # first control point of the opacity function (see vtk_plugin/Testing/Cxx/TestCylVolSlab.cxx).
    opacity.AddPoint(lo, 0.0)
    opacity.AddPoint(lo + 0.35 * w, 0.1)
    opacity.AddPoint(lo + 0.7 * w, 0.5)
    opacity.AddPoint(hi, 1.0)
    prop = vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(0.1 * diagonal)
    prop.SetInterpolationTypeToLinear()
    return prop


def tetrahedralize(grid, out):
    """VTK's tetrahedralization of the mesh, as VTK's unstructured mappers need (and as
    ParaView's Volume representation does before them)."""
    from vtkmodules.vtkFiltersGeneral import vtkDataSetTriangleFilter

    tets = vtkDataSetTriangleFilter()
    tets.SetInputData(grid)
    tets.Update()
    tet_grid = tets.GetOutput()
    out["tetrahedra"] = tet_grid.GetNumberOfCells()
    return tet_grid


def resample(grid, scalar, dims, out):
    """The mesh resampled onto a regular grid of dims^3 points over its bounds (the points
    outside every cell are blanked by vtkResampleToImage)."""
    from vtkmodules.vtkFiltersCore import vtkResampleToImage

    r = vtkResampleToImage()
    r.SetInputDataObject(grid)
    r.UseInputBoundsOn()
    r.SetSamplingDimensions(dims, dims, dims)
    r.Update()
    image = r.GetOutput()
    image.GetPointData().SetActiveScalars(scalar)
    out["resample_dims"] = [dims, dims, dims]
    mask = image.GetPointData().GetArray(r.GetMaskArrayName())
    if mask is not None:
        from vtkmodules.util.numpy_support import vtk_to_numpy

        out["resample_valid_points"] = int(vtk_to_numpy(mask).astype(bool).sum())
    return image


def make_mapper(args, grid, scalar, out):
    """The mapper args.worker names, on what it renders (prepared here)."""
    kind = "vtk-raycast" if args.worker == "vtk" else args.worker
    if kind in ON_TETRAHEDRA:
        from vtkmodules.vtkRenderingVolume import (
            vtkProjectedTetrahedraMapper,
            vtkUnstructuredGridVolumeRayCastMapper,
            vtkUnstructuredGridVolumeZSweepMapper,
        )

        tet_grid = tetrahedralize(grid, out)
        if kind == "projected-tetra":
            mapper = vtkProjectedTetrahedraMapper()
        else:
            mapper = (vtkUnstructuredGridVolumeRayCastMapper() if kind == "vtk-raycast"
                      else vtkUnstructuredGridVolumeZSweepMapper())
            # Every pixel rendered, as cylvol does (no interactive coarsening).
            mapper.AutoAdjustSampleDistancesOff()
            mapper.SetImageSampleDistance(1.0)
        mapper.SetInputData(tet_grid)
        out["class"] = mapper.GetClassName()
        return mapper
    if kind == "resample-smart":
        from vtkmodules.vtkRenderingVolumeOpenGL2 import vtkSmartVolumeMapper

        mapper = vtkSmartVolumeMapper()
        mapper.SetInputData(resample(grid, scalar, args.resample_dims, out))
        out["class"] = mapper.GetClassName()
        return mapper
    import cylvol

    mapper = cylvol.vtkCylVolMapper()
    mapper.SetInputData(grid)
    mapper.SetRelativeSampleDistance(args.relative_step)
    if args.max_error > 0.0:
        mapper.SetMaximumError(args.max_error)
    mapper.SetStructure(STRUCTURES[args.structure])
    if args.periodic:
        mapper.SetPeriodicCopies(args.periodic)
    out["class"] = mapper.GetClassName()
    return mapper


def make_scene(args, mapper, prop):
    """A window of args.size^2 with the volume, the camera turned by azimuth 30 and
    elevation 20."""
    from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow, vtkVolume

    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    ren = vtkRenderer()
    ren.AddVolume(volume)
    win = vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetMultiSamples(0)
    win.SetSize(args.size, args.size)
    win.AddRenderer(ren)
    ren.ResetCamera()
    cam = ren.GetActiveCamera()
    cam.Azimuth(30)
    cam.Elevation(20)
    cam.OrthogonalizeViewUp()
    cam.Zoom(1.0)
    ren.ResetCameraClippingRange()
    return win, cam


def save_image(win, path):
    from vtkmodules.vtkIOImage import vtkPNGWriter
    from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter

    grab = vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.ShouldRerenderOff()
    grab.Update()
    writer = vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()


def peak_rss():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def cylvol_counters(mapper, out):
    out["builds"] = mapper.GetBuildCount()
    out["build_s"] = mapper.GetLastBuildSeconds()
    out["structure_bytes"] = mapper.GetLastBuildBytes()
    out["structure"] = mapper.GetBuiltStructure()
    out["step"] = mapper.GetLastSampleDistance()
    out["samples"] = mapper.GetLastSamples()
    out["hex_tests"] = mapper.GetLastHexTests()
    # The last frame: cylvol's own ray casting, and the mapper's whole Render().
    out["last_ray_s"] = mapper.GetLastRaySeconds()
    out["last_render_s"] = mapper.GetLastRenderSeconds()


def worker(args):
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401
    import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401

    out = {"mapper": args.worker, "dataset": args.dataset, "relative_step": args.relative_step,
           "max_error": args.max_error or None}
    if args.worker == "cylvol" and args.max_error > 0.0:
        import cylvol

        if not hasattr(cylvol.vtkCylVolMapper, "SetMaximumError"):
            out["unavailable"] = UNAVAILABLE
            print("RESULT " + json.dumps(out), flush=True)
            return
    rss0 = peak_rss()
    t = time.perf_counter()
    grid, scalar = load(args.dataset, args.workdir)
    out["load_s"] = time.perf_counter() - t
    out["cells"] = grid.GetNumberOfCells()
    grid.GetPointData().SetActiveScalars(scalar)
    lo, hi = grid.GetPointData().GetArray(scalar).GetRange()

    t = time.perf_counter()
    mapper = make_mapper(args, grid, scalar, out)
    out["prepare_s"] = time.perf_counter() - t
    mapper.SetScalarModeToUsePointFieldData()
    mapper.SelectScalarArray(scalar)
    # The scene's size: the drawn box's diagonal (the wheel's, with periodic copies).
    b = mapper.GetBounds()
    prop = make_property(lo, hi, sum((b[2 * k + 1] - b[2 * k]) ** 2 for k in range(3)) ** 0.5)
    win, cam = make_scene(args, mapper, prop)

    t = time.perf_counter()
    win.Render()
    out["render_first_s"] = time.perf_counter() - t
    # From the loaded mesh to the first image: tetrahedralization or resampling included.
    out["first_frame_s"] = out["prepare_s"] + out["render_first_s"]
    if args.worker == "resample-smart":
        out["render_mode"] = mapper.GetLastUsedRenderMode()
    # The first frame's image is the one compared with the reference (the view every mapper
    # renders first); its figures are what a worker too slow for its steady frames reports.
    save_image(win, args.png)
    out["peak_rss_bytes"] = peak_rss()
    print("PARTIAL " + json.dumps(out), flush=True)
    # The camera turns one degree each frame, back and forth.
    steady, steady_cpu = [], []
    for i in range(args.frames):
        cam.Azimuth(1.0 if i % 2 == 0 else -1.0)
        t = time.perf_counter()
        c = time.process_time()
        win.Render()
        steady.append(time.perf_counter() - t)
        steady_cpu.append(time.process_time() - c)
    out["steady_frames_s"] = steady
    out["steady_cpu_s"] = steady_cpu
    out["steady_s"] = sorted(steady)[len(steady) // 2] if steady else None
    if args.worker == "cylvol":
        cylvol_counters(mapper, out)
    out["peak_rss_bytes"] = peak_rss()
    out["rss_before_load_bytes"] = rss0 * 1024
    print("RESULT " + json.dumps(out), flush=True)


# ---------------------------------------------------------------------------------------
# parent side


def read_rgb(png):
    """The image's pixels as an (n, 3) array of int16."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOImage import vtkPNGReader

    r = vtkPNGReader()
    r.SetFileName(png)
    r.Update()
    a = vtk_to_numpy(r.GetOutput().GetPointData().GetScalars())
    return a.reshape(a.shape[0], -1)[:, :3].astype("int16")


def image_error(png, reference_png):
    """An image against the reference, in 1/255: the mean difference over the channels; per
    pixel the largest channel difference, its 99th percentile and maximum; the share of
    pixels within 8/255 (per cent)."""
    import numpy

    d = numpy.abs(read_rgb(png) - read_rgb(reference_png))
    per_pixel = d.max(axis=1)
    return {"mean_abs_255": float(d.mean()),
            "p99_255": float(numpy.percentile(per_pixel, 99)),
            "max_255": int(per_pixel.max()),
            "percent_within_8": 100.0 * float((per_pixel <= 8).mean())}


def image_difference(png_a, png_b):
    """(mean difference /255, per cent of pixels within 8/255) of two images."""
    e = image_error(png_a, png_b)
    return e["mean_abs_255"], e["percent_within_8"]


def run_worker(mapper, dataset, args, workdir, png, relative_step=1.0, frames=None, periodic=0,
               max_error=0.0):
    """One mapper in its own process; its RESULT, or what it had reported (PARTIAL) when it
    ran past args.timeout, or an error."""
    env = dict(os.environ)
    if args.pythonpath:
        env["PYTHONPATH"] = args.pythonpath + (":" + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    cmd = [sys.executable, os.path.abspath(__file__), "--worker", mapper, "--dataset", dataset,
           "--size", str(args.size), "--frames", str(args.frames if frames is None else frames),
           "--workdir", workdir, "--png", png, "--relative-step", repr(relative_step),
           "--max-error", repr(max_error), "--structure", args.structure,
           "--periodic", str(periodic),
           "--resample-dims", str(getattr(args, "resample_dims", 100))]
    if os.path.exists(png):
        os.remove(png)
    t = time.perf_counter()
    try:
        proc = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              timeout=args.timeout)
        stdout = proc.stdout
    except subprocess.TimeoutExpired as e:
        stdout = e.stdout.decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
        partial = [json.loads(line[8:]) for line in stdout.splitlines() if line.startswith("PARTIAL ")]
        r = partial[0] if partial else {"mapper": mapper, "dataset": dataset}
        r.update({"timed_out": True, "timeout_s": args.timeout, "steady_s": None,
                  "not_finished": ("steady frames not finished in %d s" % args.timeout) if partial
                  else ("> %d s, not finished (no first frame)" % args.timeout)})
        return r
    wall = time.perf_counter() - t
    for line in stdout.splitlines():
        if line.startswith("RESULT "):
            r = json.loads(line[7:])
            r["wall_s"] = wall
            return r
    tail = (proc.stderr or "")[-2000:]
    return {"mapper": mapper, "dataset": dataset,
            "error": "exit status %d; stderr tail:\n%s" % (proc.returncode, tail)}


def wants_cylvol_module(args):
    """Whether the runs need the cylvol module (the converged reference is a cylvol run)."""
    mappers = getattr(args, "mappers", None)
    if isinstance(mappers, list):
        return "cylvol" in mappers or not getattr(args, "no_reference", False)
    return getattr(args, "only", None) != "vtk"


def build_what_is_measured(args):
    """Brings the cylvol command and the build tree's VTK module up to date with the sources
    (cargo and CMake rebuild only what changed), so that a stale module is never measured.
    Exits with a message if a build fails."""
    steps = [["cargo", "build", "--release", "--quiet", "--manifest-path",
              os.path.join(REPO, "Cargo.toml")]]
    if wants_cylvol_module(args) and args.pythonpath == default_pythonpath():
        if not os.path.exists(os.path.join(BUILD, "CMakeCache.txt")):
            steps.append(["cmake", "-S", os.path.join(REPO, "vtk_plugin"), "-B", BUILD,
                          "-DCMAKE_BUILD_TYPE=Release", "-Wno-dev"])
        steps.append(["cmake", "--build", BUILD, "-j", str(os.cpu_count() or 2)])
    for cmd in steps:
        print("building: %s" % " ".join(cmd), file=sys.stderr, flush=True)
        done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if done.returncode != 0:
            sys.stderr.write(done.stdout[-4000:])
            sys.exit("bench_vtk.py: '%s' failed (exit %d); --no-build measures the build tree "
                     "as it is" % (" ".join(cmd), done.returncode))
    if args.pythonpath == "" and wants_cylvol_module(args):
        # Configured just now: the package's folder is known only after the first build.
        args.pythonpath = default_pythonpath()


def prepare_dataset(dataset, workdir):
    """Generates the mesh a dataset name stands for, once, into workdir."""
    if dataset.startswith("rotor"):
        path = rotor_file(dataset, workdir)
        if not os.path.exists(path):
            cells = dataset.split(":")[1] if ":" in dataset else "2100000"
            print("generating pump-rotor:%s ..." % cells, file=sys.stderr, flush=True)
            subprocess.run([CYLVOL, "gen", "pump-rotor:" + cells, "-o", path], check=True)
    if dataset.split(":")[0] in ("mixer", "hexa") and ":" in dataset:
        path = refined_file(dataset, workdir)
        if not os.path.exists(path):
            name, n = dataset.split(":")
            print("refining %s by %s ..." % (name, n), file=sys.stderr, flush=True)
            subprocess.run([CYLVOL, "gen", os.path.join(DATA, name + ".vtk"), "--refine", n,
                            "-o", path], check=True)


def estimated_cells(dataset):
    """The mesh's cells, from its name (before any worker has read it)."""
    name, _, n = dataset.partition(":")
    if name == "rotor":
        return int(n or 2100000)
    base = {"mixer": 33600, "hexa": 1000}.get(name, 100000)
    return base * (int(n) ** 3 if n else 1)


def available_memory():
    """MemAvailable of /proc/meminfo in bytes, or None where it cannot be read."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def memory_shortfall(mapper, cells):
    """A sentence when the mapper's estimated need exceeds the memory available now."""
    base, per_cell = MEMORY_MODEL[mapper]
    need = base + per_cell * cells
    free = available_memory()
    if free is not None and need > free:
        return ("skipped: needs about %.1f GB for %s cells, %.1f GB available"
                % (need / 1e9, "{:,}".format(cells), free / 1e9))
    return None


def jobs_of(args):
    """(key, mapper, relative step, max error, frames) of every run on a dataset: cylvol at
    its default and each setting, the competitors, then the converged reference."""
    jobs = []
    if "cylvol" in args.mappers:
        factors = [float(f) for f in args.relative_steps.split(",") if f] or [1.0]
        for f in factors:
            jobs.append(("cylvol" if f == 1.0 else "cylvol@step%g" % f, "cylvol", f, 0.0, None))
        for e in [float(e) for e in args.max_errors.split(",") if e]:
            jobs.append(("cylvol@error%g" % e, "cylvol", 1.0, e, None))
    jobs += [(m, m, 1.0, 0.0, None) for m in COMPETITORS if m in args.mappers]
    if not args.no_reference:
        jobs.append(("reference", "cylvol", 0.125, 0.0, 0))
    return jobs


def run_dataset(dataset, args, workdir):
    """Every run on one dataset, their errors against the reference and the ratios."""
    prepare_dataset(dataset, workdir)
    runs = {}
    cells = estimated_cells(dataset)
    for key, mapper, factor, max_error, frames in jobs_of(args):
        png = os.path.join(workdir, "%s-%s.png" % (dataset.replace(":", "-"), key.replace("@", "-")))
        short = memory_shortfall(mapper, cells)
        if short:
            runs[key] = {"mapper": mapper, "dataset": dataset, "skipped": short}
            print("%s: %s %s" % (dataset, key, short), file=sys.stderr, flush=True)
            continue
        print("%s: %s ..." % (dataset, key), file=sys.stderr, flush=True)
        r = run_worker(mapper, dataset, args, workdir, png, factor, frames, max_error=max_error)
        if os.path.exists(png):
            r["png"] = png
        r.setdefault("relative_step", factor)
        r.setdefault("max_error", max_error or None)
        cells = r.get("cells", cells)
        runs[key] = r
    ref = runs.get("reference", {})
    if ref.get("png"):
        for key, r in runs.items():
            if key != "reference" and r.get("png"):
                r["error_vs_reference"] = image_error(r["png"], ref["png"])
    return {"dataset": dataset, "size": args.size, "frames": args.frames,
            "timeout_s": args.timeout, "resample_dims": args.resample_dims,
            "mappers": args.mappers, "runs": runs, "ratios": ratios_of(runs)}


def finished(r):
    return r and "first_frame_s" in r and not r.get("unavailable")


def ratios_of(runs):
    """competitor / cylvol for each competitor and each cylvol run (first frame, steady frame,
    peak memory); None where either did not give the figure."""
    def div(a, b):
        return a / b if a is not None and b else None

    out = {}
    for comp in COMPETITORS:
        c = runs.get(comp)
        if not finished(c):
            continue
        out[comp] = {}
        for key, r in runs.items():
            if not key.startswith("cylvol") or not finished(r):
                continue
            out[comp][key] = {
                "first_frame": div(c["first_frame_s"], r["first_frame_s"]),
                "steady": div(c.get("steady_s"), r.get("steady_s")),
                "peak_rss": div(c.get("peak_rss_bytes"), r.get("peak_rss_bytes")),
            }
    return out


def fmt_s(x):
    return "-" if x is None else ("%.3f s" % x if x < 10 else "%.1f s" % x)


def status_of(r):
    """Why a run has no figures (or no steady frame), or None."""
    for k in ("skipped", "unavailable", "not_finished"):
        if r.get(k):
            return r[k]
    if "error" in r:
        return "ERROR: " + r["error"]
    return None


def setting_of(key, r):
    if key == "reference":
        return "1/8 step (reference)"
    if key.startswith("cylvol@error"):
        return "max error %g/255" % r["max_error"]
    if key.startswith("cylvol@step"):
        return "step x%g" % r["relative_step"]
    if key == "cylvol":
        return "default step"
    if key == "resample-smart":
        return "%d^3 points" % r.get("resample_dims", [0])[0] if r.get("resample_dims") else ""
    return ""


def report(entry):
    print("\n== %s at %dx%d" % (entry["dataset"], entry["size"], entry["size"]))
    print("  %-16s %-22s %10s %10s %10s %9s  %s" % ("mapper", "setting", "prepare", "first",
                                                    "steady", "peak MB", "error /255: mean, p99, "
                                                    "max; within 8/255"))
    for key, r in entry["runs"].items():
        mapper = r.get("mapper", key)
        line = "  %-16s %-22s " % (mapper, setting_of(key, r))
        why = status_of(r)
        if why and not finished(r):
            print(line + why.splitlines()[0] + ("" if "error" not in r else "\n" + r["error"]))
            continue
        e = r.get("error_vs_reference")
        err = ("%.3f, %.0f, %d; %.2f %%" % (e["mean_abs_255"], e["p99_255"], e["max_255"],
                                             e["percent_within_8"]) if e else "-")
        print(line + "%10s %10s %10s %9.0f  %s%s" % (
            fmt_s(r.get("prepare_s")), fmt_s(r["first_frame_s"]), fmt_s(r.get("steady_s")),
            r["peak_rss_bytes"] / 1e6, err, "  (%s)" % why if why else ""))
    for comp, per in entry["ratios"].items():
        if not per:
            continue
        print("  %s / cylvol: " % comp + "; ".join(
            "%s first %s, steady %s, memory %s" % (key, fx(x["first_frame"]), fx(x["steady"]),
                                                   fx(x["peak_rss"])) for key, x in per.items()))


def fx(x):
    return "-" if x is None else "%.2fx" % x


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("datasets", nargs="*", default=["mixer", "rotor:200000"])
    p.add_argument("--size", type=int, default=512, help="image size (square), default 512")
    p.add_argument("--frames", type=int, default=3, help="steady frames after the first, default 3")
    p.add_argument("--timeout", type=int, default=7200,
                   help="seconds per worker (a mapper, on a dataset), default 7200")
    p.add_argument("--pythonpath", default=default_pythonpath(),
                   help="folder holding the cylvol package (default: the build tree's)")
    p.add_argument("--mappers", default=",".join(MAPPERS),
                   help="comma-separated, of %s (default all)" % ", ".join(MAPPERS))
    p.add_argument("--only", choices=["vtk", "cylvol"],
                   help="one mapper only (vtk: vtk-raycast), without the reference")
    p.add_argument("--relative-steps", default="1",
                   help="cylvol runs at these multiples of its default step, comma-separated (default 1)")
    p.add_argument("--max-errors", default="",
                   help="cylvol also runs at these error settings (SetMaximumError, in 1/255), "
                        "comma-separated")
    p.add_argument("--resample-dims", type=int, default=100,
                   help="resample-smart's points along each axis (default 100, ParaView's "
                        "Resample To Image default)")
    p.add_argument("--no-reference", action="store_true",
                   help="skip the converged cylvol reference (1/8 of the default step) used to measure "
                        "each image's error")
    p.add_argument("--no-build", action="store_true",
                   help="measure the build tree as it is (default: cargo build --release and "
                        "cmake --build build/vtk_plugin first)")
    p.add_argument("--json", action="store_true", help="also print all results as JSON")
    p.add_argument("--keep", help="folder for the generated meshes and the images (default: a temp dir)")
    p.add_argument("--worker", help=argparse.SUPPRESS)
    p.add_argument("--dataset", help=argparse.SUPPRESS)
    p.add_argument("--workdir", help=argparse.SUPPRESS)
    p.add_argument("--png", help=argparse.SUPPRESS)
    p.add_argument("--relative-step", type=float, default=1.0, help=argparse.SUPPRESS)
    p.add_argument("--max-error", type=float, default=0.0, help=argparse.SUPPRESS)
    p.add_argument("--periodic", type=int, default=0, help=argparse.SUPPRESS)
    p.add_argument("--structure", choices=sorted(STRUCTURES), default="auto",
                   help="cylvol's structure (the mapper's SetStructure), default auto")
    args = p.parse_args()
    if not os.environ.get("DISPLAY") and not os.environ.get("CYLVOL_BENCH_NO_XVFB"):
        # VTK's render windows need an X server: run under xvfb-run (Mesa, off screen).
        os.environ["CYLVOL_BENCH_NO_XVFB"] = "1"
        os.execvp("xvfb-run", ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24 -noreset",
                               sys.executable, os.path.abspath(__file__)] + sys.argv[1:])
    if args.worker:
        worker(args)
        return 0
    args.mappers = [m for m in args.mappers.split(",") if m]
    if args.only:
        # One mapper's figures alone, without the reference.
        args.mappers = ["vtk-raycast" if args.only == "vtk" else "cylvol"]
        args.no_reference = True
    unknown = [m for m in args.mappers if m not in MAPPERS]
    if unknown:
        p.error("unknown mapper(s) %s; known: %s" % (", ".join(unknown), ", ".join(MAPPERS)))
    if not args.no_build:
        build_what_is_measured(args)

    workdir = args.keep or tempfile.mkdtemp(prefix="cylvol-bench-vtk-")
    os.makedirs(workdir, exist_ok=True)
    results = []
    for dataset in args.datasets:
        entry = run_dataset(dataset, args, workdir)
        report(entry)
        results.append(entry)
    print("\nimages and meshes in", workdir)
    if args.json:
        print(json.dumps(results, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
