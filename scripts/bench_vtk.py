#!/usr/bin/python3
"""VTK's unstructured ray caster and cylvol's vtkCylVolMapper, side by side.

For each dataset, each mapper runs in its own subprocess (so that its peak memory can be
read on its own): load the mesh, (for VTK) tetrahedralize it with vtkDataSetTriangleFilter,
render a first frame (cylvol builds its structure inside it), then steady frames with the
camera turning by one degree per frame (each frame's wall time and the process's CPU time over
it, `steady_frames_s` and `steady_cpu_s`). The same camera, transfer function and unit
distance as the CTest comparison are used. The script prints, per dataset, both mappers'
times, their peak resident memory (ru_maxrss of the worker), the image difference between
the two final frames, and the ratios VTK ÷ cylvol.

Usage (Debian's python3-vtk9 and the build tree's cylvol package):
    /usr/bin/python3 scripts/bench_vtk.py                      # mixer and rotor:200000
    /usr/bin/python3 scripts/bench_vtk.py mixer rotor:2100000 --size 512 --frames 3
Before measuring, the script brings what it measures up to date with the sources: `cargo build
--release` (the cylvol command that generates meshes) and `cmake --build build/vtk_plugin`
(configured first if need be; it rebuilds libcylvol.a through cargo and relinks the module), so
the figures are never those of a stale module. --no-build skips both; with --pythonpath the
package given is used as it is (only the cylvol command is built).
Datasets: mixer, hexa, comb, post (from tests/data), mixer:N or hexa:N (that mesh with every
hexahedron cut into N x N x N by `cylvol gen FILE --refine N`; mixer:4 is the 2.15 M-cell refined mixer)
or rotor[:CELLS] (generated with `cylvol gen pump-rotor:CELLS`).
--relative-steps F1,F2,... runs cylvol at those multiples of its default step (the mapper's
SetRelativeSampleDistance), each compared with VTK; --only runs one mapper; --keep DIR keeps the
generated meshes and the images. --json prints, after the text report and the line naming that
folder, the results as a JSON array (one object per dataset: `runs` per mapper and step,
`comparisons` with the ratios and image errors); scripts/make_benchmarks_doc.py reads it to
write docs/benchmarks.md and the README's table. Times depend on the machine and on what else
runs on it: compare the ratios of one run, in which both mappers ran side by side.
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


def worker(args):
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401
    import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401
    from vtkmodules.vtkIOImage import vtkPNGWriter
    from vtkmodules.vtkRenderingCore import (
        vtkRenderer,
        vtkRenderWindow,
        vtkVolume,
        vtkWindowToImageFilter,
    )

    out = {"mapper": args.worker, "dataset": args.dataset}
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t = time.perf_counter()
    grid, scalar = load(args.dataset, args.workdir)
    out["load_s"] = time.perf_counter() - t
    out["cells"] = grid.GetNumberOfCells()
    grid.GetPointData().SetActiveScalars(scalar)
    lo, hi = grid.GetPointData().GetArray(scalar).GetRange()

    t = time.perf_counter()
    if args.worker == "vtk":
        from vtkmodules.vtkFiltersGeneral import vtkDataSetTriangleFilter
        from vtkmodules.vtkRenderingVolume import vtkUnstructuredGridVolumeRayCastMapper

        tets = vtkDataSetTriangleFilter()
        tets.SetInputData(grid)
        tets.Update()
        tet_grid = tets.GetOutput()
        out["tetrahedra"] = tet_grid.GetNumberOfCells()
        del tets
        mapper = vtkUnstructuredGridVolumeRayCastMapper()
        mapper.SetInputData(tet_grid)
    else:
        import cylvol

        mapper = cylvol.vtkCylVolMapper()
        mapper.SetInputData(grid)
        mapper.SetRelativeSampleDistance(args.relative_step)
        mapper.SetStructure(STRUCTURES[args.structure])
        if args.periodic:
            mapper.SetPeriodicCopies(args.periodic)
    out["prepare_s"] = time.perf_counter() - t
    mapper.SetScalarModeToUsePointFieldData()
    mapper.SelectScalarArray(scalar)
    # The scene's size: the drawn box's diagonal (the wheel's, with periodic copies).
    b = mapper.GetBounds()
    prop = make_property(lo, hi, sum((b[2 * k + 1] - b[2 * k]) ** 2 for k in range(3)) ** 0.5)

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

    t = time.perf_counter()
    win.Render()
    out["first_frame_s"] = time.perf_counter() - t
    # The camera turns one degree each frame, back and forth; `turned` is the net turn.
    turned = 0

    def next_frame():
        nonlocal turned
        step = 1 if turned == 0 else -1
        cam.Azimuth(float(step))
        turned += step
        t = time.perf_counter()
        c = time.process_time()
        win.Render()
        return time.perf_counter() - t, time.process_time() - c

    steady, steady_cpu = [], []
    for _ in range(args.frames):
        wall, cpu = next_frame()
        steady.append(wall)
        steady_cpu.append(cpu)
    out["steady_frames_s"] = steady
    out["steady_cpu_s"] = steady_cpu
    out["steady_s"] = sorted(steady)[len(steady) // 2] if steady else None
    if args.worker == "cylvol":
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
    # Back to the first frame's view for the image comparison.
    if turned != 0:
        cam.Azimuth(-float(turned))
        win.Render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.ShouldRerenderOff()
    grab.Update()
    writer = vtkPNGWriter()
    writer.SetFileName(args.png)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()
    out["peak_rss_bytes"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    out["rss_before_load_bytes"] = rss0 * 1024
    print("RESULT " + json.dumps(out), flush=True)


# ---------------------------------------------------------------------------------------
# parent side


def image_difference(png_a, png_b):
    from vtkmodules.vtkIOImage import vtkPNGReader

    arrays = []
    for p in (png_a, png_b):
        r = vtkPNGReader()
        r.SetFileName(p)
        r.Update()
        arrays.append(r.GetOutput().GetPointData().GetScalars())
    sa, sb = arrays
    n = sa.GetNumberOfTuples()
    total = 0
    within = 0
    for i in range(n):
        ta = sa.GetTuple(i)
        tb = sb.GetTuple(i)
        m = 0
        for ch in range(3):
            d = abs(ta[ch] - tb[ch])
            total += d
            m = max(m, d)
        within += m <= 8
    return total / (3.0 * n), 100.0 * within / n


def run_worker(mapper, dataset, args, workdir, png, relative_step=1.0, frames=None, periodic=0):
    env = dict(os.environ)
    if args.pythonpath:
        env["PYTHONPATH"] = args.pythonpath + (":" + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    cmd = [sys.executable, os.path.abspath(__file__), "--worker", mapper, "--dataset", dataset,
           "--size", str(args.size), "--frames", str(args.frames if frames is None else frames),
           "--workdir", workdir, "--png", png, "--relative-step", str(relative_step),
           "--structure", args.structure, "--periodic", str(periodic)]
    t = time.perf_counter()
    try:
        proc = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              timeout=args.timeout)
    except subprocess.TimeoutExpired:
        return {"mapper": mapper, "dataset": dataset, "error": "timed out after %d s" % args.timeout}
    wall = time.perf_counter() - t
    for line in proc.stdout.splitlines():
        if line.startswith("RESULT "):
            r = json.loads(line[7:])
            r["wall_s"] = wall
            return r
    tail = (proc.stderr or "")[-2000:]
    return {"mapper": mapper, "dataset": dataset,
            "error": "exit status %d; stderr tail:\n%s" % (proc.returncode, tail)}


def build_what_is_measured(args):
    """Brings the cylvol command and the build tree's VTK module up to date with the sources
    (cargo and CMake rebuild only what changed), so that a stale module is never measured.
    Exits with a message if a build fails."""
    steps = [["cargo", "build", "--release", "--quiet", "--manifest-path",
              os.path.join(REPO, "Cargo.toml")]]
    if args.only != "vtk" and args.pythonpath == default_pythonpath():
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
    if args.pythonpath == "" and args.only != "vtk":
        # Configured just now: the package's folder is known only after the first build.
        args.pythonpath = default_pythonpath()


def fmt_s(x):
    return "-" if x is None else ("%.3f s" % x)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("datasets", nargs="*", default=["mixer", "rotor:200000"])
    p.add_argument("--size", type=int, default=512, help="image size (square), default 512")
    p.add_argument("--frames", type=int, default=3, help="steady frames after the first, default 3")
    p.add_argument("--timeout", type=int, default=7200, help="seconds per worker, default 7200")
    p.add_argument("--pythonpath", default=default_pythonpath(),
                   help="folder holding the cylvol package (default: the build tree's)")
    p.add_argument("--only", choices=["vtk", "cylvol"], help="run one mapper only")
    p.add_argument("--relative-steps", default="1",
                   help="cylvol runs at these multiples of its default step, comma-separated (default 1)")
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
    p.add_argument("--periodic", type=int, default=0, help=argparse.SUPPRESS)
    p.add_argument("--structure", choices=sorted(STRUCTURES), default="auto",
                   help="cylvol's structure (the mapper's SetStructure), default auto")
    args = p.parse_args()
    if not os.environ.get("DISPLAY") and not os.environ.get("CYLVOL_BENCH_NO_XVFB"):
        # VTK's render windows need an X server: run under xvfb-run (Mesa, off screen).
        os.environ["CYLVOL_BENCH_NO_XVFB"] = "1"
        os.execvp("xvfb-run", ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", sys.executable,
                               os.path.abspath(__file__)] + sys.argv[1:])
    if args.worker:
        worker(args)
        return 0
    if not args.no_build:
        build_what_is_measured(args)

    workdir = args.keep or tempfile.mkdtemp(prefix="cylvol-bench-vtk-")
    os.makedirs(workdir, exist_ok=True)
    results = []
    for dataset in args.datasets:
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
        runs = {}
        factors = [float(f) for f in args.relative_steps.split(",") if f]
        jobs = []
        if args.only != "vtk":
            jobs += [("cylvol@%g" % f, "cylvol", f, None) for f in factors]
        if args.only != "cylvol":
            jobs.append(("vtk", "vtk", 1.0, None))
        if not args.no_reference and not args.only:
            jobs.append(("reference", "cylvol", 0.125, 0))
        for key, mapper, factor, frames in jobs:
            png = os.path.join(workdir, "%s-%s.png" % (dataset.replace(":", "-"), key.replace("@", "-")))
            print("%s: %s ..." % (dataset, key), file=sys.stderr, flush=True)
            runs[key] = run_worker(mapper, dataset, args, workdir, png, factor, frames)
            runs[key]["png"] = png
        entry = {"dataset": dataset, "size": args.size, "runs": runs}
        print("\n== %s at %dx%d" % (dataset, args.size, args.size))
        for name, r in runs.items():
            if "error" in r:
                print("  %-12s ERROR: %s" % (name, r["error"]))
                continue
            if name == "vtk":
                extra = ", tetrahedralize %s (%d tets)" % (fmt_s(r["prepare_s"]), r.get("tetrahedra", 0))
            else:
                extra = ", step %.4g, build %s, structure %s, %.1f MB, last frame's rays %s of %s" % (
                    r.get("step", 0.0), fmt_s(r.get("build_s")), r.get("structure"),
                    r.get("structure_bytes", 0) / 1e6, fmt_s(r.get("last_ray_s")),
                    fmt_s(r.get("last_render_s")))
            print("  %-12s %d cells: load %s%s, first frame %s, steady %s (frames %s; CPU %s), "
                  "peak RSS %.0f MB"
                  % (name, r["cells"], fmt_s(r["load_s"]), extra, fmt_s(r["first_frame_s"]),
                     fmt_s(r["steady_s"]), ", ".join("%.3f" % x for x in r["steady_frames_s"]),
                     ", ".join("%.3f" % x for x in r.get("steady_cpu_s", [])),
                     r["peak_rss_bytes"] / 1e6))
        v = runs.get("vtk", {})
        ref = runs.get("reference", {})
        have_ref = ref and "error" not in ref
        if v and "error" not in v and have_ref:
            mean, pct = image_difference(v["png"], ref["png"])
            entry["vtk_error_vs_reference"] = {"mean_abs_255": mean, "percent_within_8": pct}
            print("  VTK vs converged cylvol reference: mean abs %.3f/255, %.2f %% within 8/255" % (mean, pct))
        entry["comparisons"] = {}
        for key, c in runs.items():
            if not key.startswith("cylvol@") or "error" in c or not v or "error" in v:
                continue
            comp = {}
            mean, pct = image_difference(c["png"], v["png"])
            comp["difference_vs_vtk"] = {"mean_abs_255": mean, "percent_within_8": pct}
            line = "  %s vs VTK: mean abs %.3f/255, %.2f %% within 8/255" % (key, mean, pct)
            if have_ref:
                rmean, rpct = image_difference(c["png"], ref["png"])
                comp["error_vs_reference"] = {"mean_abs_255": rmean, "percent_within_8": rpct}
                line += "; vs converged reference: mean abs %.3f/255, %.2f %% within" % (rmean, rpct)
            print(line)
            vtk_first = v["prepare_s"] + v["first_frame_s"]
            ratios = {
                "first_frame": v["first_frame_s"] / c["first_frame_s"],
                "first_frame_incl_tetrahedralize": vtk_first / c["first_frame_s"],
                "steady": v["steady_s"] / c["steady_s"] if c["steady_s"] else None,
                "peak_rss_cylvol_over_vtk": c["peak_rss_bytes"] / v["peak_rss_bytes"],
            }
            comp["ratios"] = ratios
            print("    VTK / %s: first frame %.2fx (%.2fx counting tetrahedralization), steady %.2fx;"
                  " peak RSS = %.3f of VTK's"
                  % (key, ratios["first_frame"], ratios["first_frame_incl_tetrahedralize"],
                     ratios["steady"] or 0.0, ratios["peak_rss_cylvol_over_vtk"]))
            entry["comparisons"][key] = comp
        results.append(entry)
    print("\nimages and meshes in", workdir)
    if args.json:
        print(json.dumps(results, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
