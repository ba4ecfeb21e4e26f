#!/usr/bin/python3
"""The whole wheel from one sector against the wheel replicated as one mesh, side by side.

On the mixer refined x N^3 (mixer:4 is the 2.15 M-cell sector, its wheel 8.6 M cells), each in
its own process through vtkCylVolMapper at SIZE x SIZE (scripts/bench_vtk.py's worker: the
same camera, transfer function and turning steady frames):
  - cylvol drawing the 90-degree sector's four periodic copies (SetPeriodicCopies(4));
  - cylvol drawing the wheel replicated as one mesh (`cylvol gen SECTOR --periodic auto`);
  - with --vtk, VTK's unstructured ray caster on the replicated wheel (its tetrahedralization of
    8.6 M hexahedra needs more memory than a 24 GB machine has).
Printed per run: the cells handed to the mapper, the structure's build time and bytes, the
first and the steady frame, peak memory, and the image difference between the two cylvol
images; then the ratios replicated / periodic. --json prints the results as JSON too.

Usage: /usr/bin/python3 scripts/bench_periodic.py [mixer:4] [--size 512] [--frames 3]
       [--vtk] [--keep DIR] [--no-build]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import bench_vtk  # noqa: E402


def main():
    p = argparse.ArgumentParser()
    p.add_argument("sector", nargs="?", default="mixer:4", help="mixer or mixer:N (default mixer:4)")
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--frames", type=int, default=3)
    p.add_argument("--timeout", type=int, default=7200)
    p.add_argument("--vtk", action="store_true", help="also run VTK's ray caster on the wheel")
    p.add_argument("--keep", help="folder for the generated meshes and images")
    p.add_argument("--no-build", action="store_true")
    p.add_argument("--json", action="store_true")
    args = p.parse_args()
    args.pythonpath = bench_vtk.default_pythonpath()
    args.structure = "auto"
    args.only = None
    if not args.no_build:
        bench_vtk.build_what_is_measured(args)
    workdir = args.keep or tempfile.mkdtemp(prefix="cylvol-bench-periodic-")
    os.makedirs(workdir, exist_ok=True)
    name = args.sector.split(":")[0]
    if name != "mixer":
        sys.exit("bench_periodic.py: the sector is the mixer (mixer or mixer:N)")
    if ":" in args.sector:
        sector_file = bench_vtk.refined_file(args.sector, workdir)
        if not os.path.exists(sector_file):
            n = args.sector.split(":")[1]
            print("refining the mixer by %s ..." % n, file=sys.stderr, flush=True)
            subprocess.run([bench_vtk.CYLVOL, "gen", os.path.join(bench_vtk.DATA, "mixer.vtk"),
                            "--refine", n, "-o", sector_file], check=True)
    else:
        sector_file = os.path.join(bench_vtk.DATA, "mixer.vtk")
    wheel = "wheel:" + args.sector
    wheel_path = bench_vtk.wheel_file(wheel, workdir)
    if not os.path.exists(wheel_path):
        print("replicating the wheel ...", file=sys.stderr, flush=True)
        subprocess.run([bench_vtk.CYLVOL, "gen", sector_file, "--periodic", "auto", "-o",
                        wheel_path], check=True)
    png = lambda tag: os.path.join(workdir, tag + ".png")  # noqa: E731
    runs = {
        "periodic": bench_vtk.run_worker("cylvol", args.sector, args, workdir, png("periodic"),
                                         periodic=4),
        "replicated": bench_vtk.run_worker("cylvol", wheel, args, workdir, png("replicated")),
    }
    if args.vtk:
        runs["vtk"] = bench_vtk.run_worker("vtk", wheel, args, workdir, png("vtk"))
    print("%-11s %10s %9s %10s %10s %10s %9s" % ("run", "cells", "build s", "MB struct",
                                                "first s", "steady s", "peak MB"))
    for tag, r in runs.items():
        if "error" in r:
            print("%-11s error: %s" % (tag, r["error"]))
            continue
        print("%-11s %10d %9s %10s %10.3f %10.3f %9.0f" % (
            tag, r["cells"], "%.3f" % r["build_s"] if "build_s" in r else "-",
            "%.0f" % (r["structure_bytes"] / 1e6) if "structure_bytes" in r else "-",
            r["first_frame_s"], r["steady_s"], r["peak_rss_bytes"] / 1e6))
    a, b = runs["periodic"], runs["replicated"]
    if "error" not in a and "error" not in b:
        mean, within = bench_vtk.image_difference(png("periodic"), png("replicated"))
        print("periodic vs replicated image: mean %.3f/255, %.2f %% within 8/255" % (mean, within))
        ratios = {k: b[k] / a[k] for k in ("build_s", "structure_bytes", "first_frame_s",
                                           "steady_s", "peak_rss_bytes") if a.get(k)}
        print("replicated / periodic: " + ", ".join("%s %.2fx" % kv for kv in ratios.items()))
        runs["ratios"] = ratios
        runs["image"] = {"mean": mean, "within_8": within}
    if args.json:
        print(json.dumps(runs, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
