#!/usr/bin/python3
"""Runs cylvol's benchmarks and writes docs/benchmarks.md from their JSON.

Each section of docs/benchmarks.md is one benchmark: the commands it runs (all of them print
JSON), the tables and SVG plots made from that JSON, the machine and the date. The raw JSON is
kept in docs/benchmarks/results.json, so the documents can be rewritten without a rerun, and
one section can be rerun while the others keep their results. The script also fills the
generated blocks of README.md (the table against VTK) and docs/accuracy.md (the step's price),
between `<!-- generated:NAME -->` and `<!-- /generated:NAME -->`.

Usage (Debian's /usr/bin/python3 with python3-vtk9, from anywhere):
    /usr/bin/python3 scripts/make_benchmarks_doc.py                # every section, ~15 min on 2 cores
    /usr/bin/python3 scripts/make_benchmarks_doc.py --only vtk     # one section (vtk, structures,
                                                                   # render, accuracy)
    /usr/bin/python3 scripts/make_benchmarks_doc.py --from-json    # rewrite the docs, run nothing
    /usr/bin/python3 scripts/make_benchmarks_doc.py --large        # also the 2.1 M-cell meshes
                                                                   # against VTK (~7 GB, long)
It builds what it measures first (`cargo build --release`; scripts/bench_vtk.py builds the VTK
module); --no-build skips that.

Adding a benchmark: write a Section subclass (its name, title, commands, `run` returning the
JSON to keep, `markdown` turning that JSON into the section's text and plots) and add it to
SECTIONS. Times on a shared machine are noisy: give ratios of runs made side by side, and
counters, rather than absolute seconds.
"""
import argparse
import datetime
import html
import json
import math
import os
import platform
import shlex
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
DOCS = os.path.join(REPO, "docs")
OUT_DIR = os.path.join(DOCS, "benchmarks")
RESULTS = os.path.join(OUT_DIR, "results.json")
CYLVOL = "target/release/cylvol"
PYTHON = "/usr/bin/python3"

# The meshes the structure and render benchmarks run on: the real ones the tests carry, then
# the synthetic pumps at a size a 2-core machine renders in seconds.
REAL_MESHES = [
    ("tests/data/mixer.vtk", "mixer"),
    ("tests/data/postxyz.bin", "LOX post"),
    ("tests/data/combxyz.bin", "combustor"),
    ("tests/data/hexa.vtk", "Cartesian cube"),
]
PUMPS = [
    ("pump-inlet:200000", "pump-inlet"),
    ("pump-rotor:200000", "pump-rotor"),
    ("pump-diffuser:200000", "pump-diffuser"),
]
MESHES = PUMPS + REAL_MESHES
STRUCTURES = ["cart-grid", "cyl-grid", "cart-bvh", "cyl-bvh"]

# The talk's cylindrical ÷ Cartesian ratios (centrifugal pump: diffuser, inlet, rotor), for
# comparison; its weakest case is the largest of the three.
TALK = {
    "grid references": (0.61, 0.74, 0.64),
    "grid memory": (0.69, 0.82, 0.69),
    "grid hexahedra visited": (0.59, 0.59, 0.89),
    "grid frames per second": (1.36, 1.21, 1.09),
    "BVH surface area": (0.56, 0.75, 0.80),
    "BVH internal nodes visited": (0.55, 0.46, 0.88),
    "BVH leaf nodes visited": (0.64, 0.68, 0.86),
    "BVH frames per second": (1.51, 1.74, 1.14),
}
TALK_CITATION = ("J. Wang, M. Elshehaly and Y. Cao, *Cylindrical Acceleration Structures for "
                 "Large Hexahedral Volume Visualization*, IEEE Symposium on Large Data Analysis "
                 "and Visualization (LDAV), 2015")


def weakest(measure):
    """The talk's weakest ratio of a measure over its three meshes (the largest where less is
    better, the smallest for frames per second), or a dash where it gives none."""
    if measure is None:
        return "–"
    values = TALK[measure]
    return "%.2f" % (min(values) if "per second" in measure else max(values))


# ---------------------------------------------------------------------------------------
# running commands


def run_json(cmd, log):
    """Runs a command from the repository root; returns its standard output parsed as JSON."""
    log.append(" ".join(shlex.quote(c) for c in cmd))
    print("running: %s" % log[-1], file=sys.stderr, flush=True)
    done = subprocess.run(cmd, cwd=REPO, stdout=subprocess.PIPE, text=True)
    if done.returncode != 0:
        sys.exit("make_benchmarks_doc.py: '%s' failed (exit %d)" % (log[-1], done.returncode))
    return json.loads(done.stdout)


def run_bench_vtk(args, log, keep):
    """scripts/bench_vtk.py prints its text report, then the JSON after the line naming the
    folder of its images."""
    shown = [PYTHON, "scripts/bench_vtk.py"] + args + ["--json"]
    log.append(" ".join(shlex.quote(c) for c in shown))
    print("running: %s" % log[-1], file=sys.stderr, flush=True)
    done = subprocess.run(shown + ["--keep", keep], cwd=REPO, stdout=subprocess.PIPE, text=True)
    if done.returncode != 0:
        sys.exit("make_benchmarks_doc.py: '%s' failed (exit %d)" % (log[-1], done.returncode))
    text = done.stdout
    marker = text.rfind("images and meshes in")
    return json.loads(text[text.index("\n", marker) + 1:])


def machine():
    """The machine, the software and the code measured."""
    cpu = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
        with open("/proc/meminfo") as f:
            mem_kb = int(f.readline().split()[1])
    except OSError:
        mem_kb = 0
    os_name = platform.platform()
    try:
        with open("/etc/os-release") as f:
            for line in f:
                if line.startswith("PRETTY_NAME="):
                    os_name = line.split("=", 1)[1].strip().strip('"')
    except OSError:
        pass

    def out(cmd):
        try:
            return subprocess.run(cmd, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                  text=True).stdout.strip()
        except OSError:
            return ""

    try:
        import vtkmodules.vtkCommonCore as core
        vtk_version = core.vtkVersion.GetVTKVersion()
    except ImportError:
        vtk_version = "not found"
    commit = out(["git", "rev-parse", "--short", "HEAD"])
    if out(["git", "status", "--porcelain", "--untracked-files=no", "--", "src", "Cargo.toml",
            "Cargo.lock", "vtk_plugin", "scripts/bench_vtk.py"]):
        commit += " with uncommitted changes"
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "memory_gb": round(mem_kb / 1024 / 1024, 1),
        "os": os_name,
        "rustc": out(["rustc", "--version"]),
        "vtk": vtk_version,
        "commit": commit,
        "load_average": [round(x, 2) for x in os.getloadavg()],
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
    }


def machine_line(m):
    return ("%s, %d cores, %.0f GB, %s; %s, VTK %s; code %s; %s, load average %s at the start"
            % (m["cpu"], m["cores"], m["memory_gb"], m["os"], m["rustc"], m["vtk"], m["commit"],
               m["date"], " / ".join("%.1f" % x for x in m["load_average"])))


# ---------------------------------------------------------------------------------------
# SVG plots (plain SVG, no plotting library)


PALETTE = ["#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3", "#937860"]


def bar_chart(path, title, categories, series, y_label, log_scale=False, lines=()):
    """Grouped vertical bars: `series` is [(label, [value per category])]; `lines` are
    horizontal reference lines [(value, label)]. Writes the SVG to `path`."""
    width, height = 760, 360
    left, right, top, bottom = 64, 16, 40, 100
    values = [v for _, vs in series for v in vs if v is not None] + [v for v, _ in lines]
    if log_scale:
        lo = 10 ** math.floor(math.log10(min(values)))
        hi = 10 ** math.ceil(math.log10(max(values)))
        ticks = [10 ** e for e in range(int(round(math.log10(lo))), int(round(math.log10(hi))) + 1)]

        def y(v):
            f = (math.log10(v) - math.log10(lo)) / (math.log10(hi) - math.log10(lo))
            return top + (height - top - bottom) * (1 - f)
    else:
        lo = 0.0
        hi = max(values) * 1.1
        step = nice_step(hi / 5)
        hi = math.ceil(hi / step) * step
        ticks = [i * step for i in range(int(round(hi / step)) + 1)]

        def y(v):
            return top + (height - top - bottom) * (1 - (v - lo) / (hi - lo))

    plot_w = width - left - right
    group_w = plot_w / len(categories)
    bar_w = group_w * 0.8 / len(series)
    s = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" viewBox="0 0 %d %d" '
         'font-family="sans-serif" font-size="12">' % (width, height, width, height),
         '<rect width="100%" height="100%" fill="white"/>',
         '<text x="%d" y="22" font-size="14" font-weight="bold">%s</text>' % (left, html.escape(title))]
    for t in ticks:
        s.append('<line x1="%d" x2="%d" y1="%.1f" y2="%.1f" stroke="#ddd"/>' % (left, width - right, y(t), y(t)))
        s.append('<text x="%d" y="%.1f" text-anchor="end">%s</text>' % (left - 6, y(t) + 4, fmt_tick(t)))
    s.append('<text transform="translate(16,%d) rotate(-90)" text-anchor="middle">%s</text>'
             % ((top + height - bottom) // 2, html.escape(y_label)))
    base = y(lo)
    for i, cat in enumerate(categories):
        x0 = left + i * group_w + group_w * 0.1
        for j, (label, vs) in enumerate(series):
            v = vs[i]
            if v is None:
                continue
            x = x0 + j * bar_w
            s.append('<rect x="%.1f" y="%.1f" width="%.1f" height="%.1f" fill="%s"><title>%s, %s: %s</title></rect>'
                     % (x, y(v), bar_w - 1, base - y(v), PALETTE[j % len(PALETTE)],
                        html.escape(cat), html.escape(label), fmt_tick(v)))
        # A label of several parts ("mesh, step") goes on one line a part.
        cx = left + (i + 0.5) * group_w
        parts = "".join('<tspan x="%.1f" dy="%d">%s</tspan>' % (cx, 0 if k == 0 else 14, html.escape(part))
                        for k, part in enumerate(cat.split(", ")))
        s.append('<text x="%.1f" y="%d" text-anchor="middle">%s</text>' % (cx, height - bottom + 16, parts))
    for v, label in lines:
        s.append('<line x1="%d" x2="%d" y1="%.1f" y2="%.1f" stroke="black" stroke-dasharray="5,3"/>'
                 % (left, width - right, y(v), y(v)))
        s.append('<text x="%d" y="%.1f" text-anchor="end" font-size="11">%s</text>'
                 % (width - right - 2, y(v) - 4, html.escape(label)))
    lx = left
    for j, (label, _) in enumerate(series):
        s.append('<rect x="%d" y="%d" width="12" height="12" fill="%s"/>'
                 % (lx, height - 30, PALETTE[j % len(PALETTE)]))
        s.append('<text x="%d" y="%d">%s</text>' % (lx + 16, height - 20, html.escape(label)))
        lx += 24 + 7 * len(label)
    s.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(s) + "\n")


def nice_step(x):
    e = 10 ** math.floor(math.log10(x))
    for m in (1, 2, 2.5, 5, 10):
        if m * e >= x:
            return m * e
    return 10 * e


def fmt_tick(v):
    if v == 0:
        return "0"
    if abs(v) >= 100:
        return "%.0f" % v
    if abs(v) >= 1:
        return ("%.1f" % v).rstrip("0").rstrip(".")
    return ("%.2f" % v).rstrip("0").rstrip(".") if abs(v) >= 0.01 else "%.0e" % v


# ---------------------------------------------------------------------------------------
# formatting


def f2(x):
    return "–" if x is None else "%.2f" % x


def ratio(x):
    return "–" if x is None else ("%.1f×" % x if x >= 10 else "%.2f×" % x)


def sci(x):
    if x is None:
        return "–"
    m, e = ("%.1e" % x).split("e")
    return "%s·10<sup>%d</sup>" % (m, int(e))


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def commands_block(commands):
    return "```sh\n" + "\n".join(commands) + "\n```"


def rel(path):
    return os.path.relpath(path, DOCS)


def step_label(f):
    return {2.0: "2", 1.0: "1", 0.5: "½", 0.25: "¼", 0.125: "⅛"}.get(f, "%g" % f)


# ---------------------------------------------------------------------------------------
# sections


class Section:
    """One benchmark of docs/benchmarks.md. `run` returns the JSON kept in results.json;
    `markdown` turns it into the section's text (and writes its plots)."""
    name = ""
    title = ""

    def run(self, opts, commands):
        raise NotImplementedError

    def markdown(self, data):
        raise NotImplementedError

    def blocks(self, data):
        """Generated blocks of other documents: {(document, block name): (markdown, whether
        the machine and date follow it)}."""
        return {}

    def rerun_options(self, data):
        """The options beyond `--only NAME` that rerun this section as it was run."""
        return ""


class VtkSection(Section):
    name = "vtk"
    title = "Against VTK's unstructured ray caster"
    # The meshes every run compares; --large adds the 2.15 M-cell refined mixer.
    SMALL = ("mixer", "rotor:200000")

    def run(self, opts, commands):
        keep = tempfile.mkdtemp(prefix="cylvol-benchmarks-vtk-")
        runs = [list(self.SMALL) + ["--relative-steps", "1,4"]]
        if opts.large:
            # The 2.15 M-cell refined mixer (VTK renders 12.9 M tetrahedra).
            runs.append(["mixer:4", "--relative-steps", "8,12"])
        results = []
        for i, args in enumerate(runs):
            # The module is built (if need be) by the first run only.
            extra = ["--no-build"] if (opts.no_build or i > 0) else []
            results += run_bench_vtk(args + extra, commands, keep)
        return results

    def rows(self, data):
        rows = []
        for entry in data:
            v = entry["runs"].get("vtk", {})
            for key, comp in entry.get("comparisons", {}).items():
                c = entry["runs"][key]
                r = comp["ratios"]
                err = comp.get("error_vs_reference", {})
                verr = entry.get("vtk_error_vs_reference", {})
                rows.append({
                    "dataset": entry["dataset"], "cells": c["cells"], "tets": v.get("tetrahedra"),
                    "factor": float(key.split("@")[1]), "structure": c.get("structure"),
                    "c_first": c["first_frame_s"], "c_steady": c["steady_s"],
                    "v_first": v["first_frame_s"], "v_steady": v["steady_s"],
                    "v_tets_s": v.get("prepare_s"),
                    "r_first": r["first_frame"], "r_first_tets": r["first_frame_incl_tetrahedralize"],
                    "r_steady": r["steady"], "mem": r["peak_rss_cylvol_over_vtk"],
                    "c_mem": c["peak_rss_bytes"], "v_mem": v["peak_rss_bytes"],
                    "c_err": err.get("mean_abs_255"), "c_within": err.get("percent_within_8"),
                    "v_err": verr.get("mean_abs_255"), "v_within": verr.get("percent_within_8"),
                    "size": entry["size"],
                })
        # Per mesh, coarse steps after fine ones (JSON keeps the comparisons in name order).
        order = {e["dataset"]: i for i, e in enumerate(data)}
        return sorted(rows, key=lambda r: (order[r["dataset"]], r["factor"]))

    @staticmethod
    def name_of(dataset):
        name = {"mixer": "mixer", "rotor": "pump-rotor", "post": "LOX post", "comb": "combustor",
                "hexa": "Cartesian cube"}[dataset.split(":")[0]]
        if dataset.startswith(("mixer:", "hexa:")):
            name += ", refined ×%s³" % dataset.split(":")[1]
        return name

    def table(self, rows, compact=False):
        header = ["mesh (cells)", "cylvol step", "VTK ÷ cylvol: first frame", "steady frame",
                  "peak memory cylvol ÷ VTK", "error /255 cylvol; VTK (pixels within 8/255)"]
        if not compact:
            header[2:2] = ["cylvol first / steady", "VTK first / steady"]
        out = []
        for r in rows:
            row = ["%s (%s)" % (self.name_of(r["dataset"]), "{:,}".format(r["cells"])),
                   "%g × default" % r["factor"],
                   "**%s**" % ratio(r["r_first"]), "**%s**" % ratio(r["r_steady"]),
                   "%.2f" % r["mem"],
                   "%s; %s (%s; %s)" % (f3(r["c_err"]), f3(r["v_err"]), pct(r["c_within"]),
                                        pct(r["v_within"]))]
            if not compact:
                row[2:2] = ["%.2f / %.3f s" % (r["c_first"], r["c_steady"]),
                            "%.2f / %.3f s" % (r["v_first"], r["v_steady"])]
            out.append(row)
        return table(header, out)

    def markdown(self, data):
        rows = self.rows(data)
        plot = os.path.join(OUT_DIR, "vtk-ratios.svg")
        cats = ["%s, %g×" % (self.name_of(r["dataset"]), r["factor"]) for r in rows]
        bar_chart(plot, "VTK's frame time ÷ cylvol's (above 1: cylvol faster)", cats,
                  [("first frame", [r["r_first"] for r in rows]),
                   ("steady frame", [r["r_steady"] for r in rows])],
                  "VTK ÷ cylvol", log_scale=True, lines=[(1.0, "equal")])
        size = rows[0]["size"] if rows else 512
        text = [
            "`scripts/bench_vtk.py` renders one scene with VTK's own "
            "`vtkUnstructuredGridVolumeRayCastMapper` (on `vtkDataSetTriangleFilter`'s tetrahedra, "
            "as VTK requires) and with `vtkCylVolMapper`, each in its own process, at %d×%d: the "
            "same camera, transfer function and unit distance; a first frame (cylvol builds its "
            "structure in it, VTK's tetrahedralization is timed apart), then steady frames with the "
            "camera turning a degree a frame (the median is shown); peak resident memory of each "
            "process; and each image's error against cylvol at ⅛ of its default step, a converged "
            "reference (mean difference in /255, and the share of pixels within 8/255). cylvol "
            "runs at its default step (half the mean cell size) and at multiples of it "
            "(`SetRelativeSampleDistance`): the longer step trades accuracy for speed." % (size, size),
            "",
            self.table(rows),
            "",
            "![VTK ÷ cylvol](%s)" % rel(plot),
            "",
            "A refined mixer is the OpenFOAM mixer with every hexahedron cut into N × N × N "
            "(`cylvol gen tests/data/mixer.vtk --refine N`); VTK renders six tetrahedra for each. "
            "A longer step is a fair comparison as long as cylvol's error stays at or below "
            "VTK's (the last column).",
            "",
            "VTK integrates once per tetrahedron crossed; cylvol samples at steps and inverts the "
            "trilinear map of a hexahedron at each sample, so on small meshes VTK can be faster, "
            "and cylvol's lead grows with the mesh (VTK's set-up and memory grow with the six "
            "tetrahedra it makes of each hexahedron).",
        ]
        return "\n".join(text)

    def blocks(self, data):
        rows = self.rows(data)
        return {("README.md", "vtk-table"): (self.table(rows, compact=True), True)}

    def rerun_options(self, data):
        return " --large" if any(e["dataset"] not in self.SMALL for e in data) else ""


def f3(x):
    return "–" if x is None else "%.3f" % x


def pct(x):
    return "–" if x is None else ("%.2f %%" % x if x < 100 else "100 %")


class StructuresSection(Section):
    name = "structures"
    title = "The four structures: size and point location"

    def run(self, opts, commands):
        return [run_json([CYLVOL, "stats", mesh, "--json"], commands) for mesh, _ in MESHES]

    def markdown(self, data):
        rows = []
        for (mesh, label), d in zip(MESHES, data):
            g, b = d["ratios"]["grid"], d["ratios"]["bvh"]
            rows.append(["%s (%s)" % (label, "{:,}".format(d["cells"])),
                         f2(g["references"]), f2(g["bytes"]), f2(g["hex_tests"]), f2(g["candidates"]),
                         f2(b["surface_area"]), f2(b["hex_tests"]), f2(b["internal_visits"]),
                         f2(b["leaf_visits"])])
        talk = ["the talk's weakest case"] + [weakest(k) for k in (
            "grid references", "grid memory", "grid hexahedra visited", None, "BVH surface area",
            None, "BVH internal nodes visited", "BVH leaf nodes visited")]
        plot = os.path.join(OUT_DIR, "structures-ratios.svg")
        labels = [label for _, label in MESHES]
        bar_chart(plot, "Cylindrical ÷ Cartesian, per point located (cylvol stats)", labels,
                  [("grid: references", [d["ratios"]["grid"]["references"] for d in data]),
                   ("grid: hexahedra tested", [d["ratios"]["grid"]["hex_tests"] for d in data]),
                   ("BVH: surface area", [d["ratios"]["bvh"]["surface_area"] for d in data]),
                   ("BVH: hexahedra tested", [d["ratios"]["bvh"]["hex_tests"] for d in data])],
                  "cylindrical ÷ Cartesian", lines=[(1.0, "equal")])
        rotor = next(d for (m, _), d in zip(MESHES, data) if m.startswith("pump-rotor"))
        per = []
        for k in STRUCTURES:
            s = rotor["structures"][k]
            per.append([k, "{:,}".format(s.get("grid_cells", s.get("nodes"))),
                        "{:,}".format(s["references"]), "%.1f" % (s["bytes"] / rotor["cells"]),
                        f2(s.get("surface_area")) if "surface_area" in s else "–",
                        "%.2f" % s["hex_tests"], "%.1f / %.2f" % (s["internal_visits"], s["leaf_visits"]),
                        "%.2f" % s["candidates"]])
        text = [
            "`cylvol stats` builds the four structures with their default parameters and locates "
            "100,000 seeded points inside cells through each. The counters are exact and the same "
            "on any machine; the build times vary with the machine and are left out here. Each "
            "column is cylindrical ÷ Cartesian (below 1: the cylindrical structure needs less), "
            "beside the weakest of the talk's three pump meshes:",
            "",
            table(["mesh (cells)", "grid: references", "grid: memory", "grid: hexahedra tested",
                   "grid: candidates", "BVH: surface area", "BVH: hexahedra tested",
                   "BVH: internal nodes", "BVH: leaf nodes"], rows + [talk]),
            "",
            "![cylindrical ÷ Cartesian](%s)" % rel(plot),
            "",
            "The rotor's structures (per look-up: hexahedra tested with the inverse map, nodes or "
            "grid cells visited, candidates offered):",
            "",
            table(["structure", "grid cells / BVH nodes", "references", "bytes per mesh cell",
                   "surface area", "hexahedra tested", "internal / leaf visits", "candidates"], per),
            "",
            "The Cartesian cube is where a cylindrical structure has no reason to win, and does "
            "not; `--structure auto` takes the Cartesian BVH there and the cylindrical one on "
            "every turbomachine.",
        ]
        return "\n".join(text)


class RenderSection(Section):
    name = "render"
    title = "Rendering: the talk's measure and the fast path"
    size = 256
    frames = 3

    def run(self, opts, commands):
        return run_json([CYLVOL, "bench"] + [m for m, _ in MESHES]
                        + ["--size", str(self.size), "--frames", str(self.frames), "--json"], commands)

    def markdown(self, data):
        rows, fast_rows = [], []
        for (mesh, label), d in zip(MESHES, data):
            g, b = d["ratios"]["grid"], d["ratios"]["bvh"]
            inv = lambda x: None if not x else 1.0 / x  # noqa: E731 (fps ratio = inverse frame ratio)
            rows.append(["%s (%s)" % (label, "{:,}".format(d["cells"])),
                         f2(g["paper"]["hex_tests"]), f2(inv(g["paper"]["frame_s"])),
                         f2(b["paper"]["hex_tests"]), f2(b["paper"]["internal_visits"]),
                         f2(b["paper"]["leaf_visits"]), f2(inv(b["paper"]["frame_s"]))])
            st = d["structures"]
            cells = []
            for k in STRUCTURES:
                f = st[k]["fast"]
                located = f["samples_located"] or 1
                cells.append("%.2f" % (f["hex_tests"] / located))
            speed = [st[k]["paper"]["frame_s"] / st[k]["fast"]["frame_s"] for k in STRUCTURES]
            fast_rows.append(["%s" % label, "{:,}".format(d["structures"]["cyl-bvh"]["fast"]["samples"]),
                              " / ".join(cells), "%.1f–%.1f×" % (min(speed), max(speed))])
        talk = ["the talk's weakest case"] + [weakest(k) for k in (
            "grid hexahedra visited", "grid frames per second", None, "BVH internal nodes visited",
            "BVH leaf nodes visited", "BVH frames per second")]
        labels = [label for _, label in MESHES]
        plot = os.path.join(OUT_DIR, "render-ratios.svg")
        bar_chart(plot, "Cylindrical ÷ Cartesian on the paper path (cylvol bench)", labels,
                  [("grid: hexahedra tested", [d["ratios"]["grid"]["paper"]["hex_tests"] for d in data]),
                   ("BVH: hexahedra tested", [d["ratios"]["bvh"]["paper"]["hex_tests"] for d in data]),
                   ("BVH: internal nodes", [d["ratios"]["bvh"]["paper"]["internal_visits"] for d in data])],
                  "cylindrical ÷ Cartesian", lines=[(1.0, "equal")])
        text = [
            "`cylvol bench` renders each mesh with each structure along two paths, %d×%d, from "
            "the default view, each frame time the fastest of %d renders made in rounds (one "
            "render per structure and path a round, so that the machine's drifts fall on all "
            "alike). The *paper* path locates every sample from scratch through the structure, "
            "as the talk measured; the *fast* path, cylvol's own, walks from cell to cell through "
            "face neighbours and asks the structure only where the walk cannot go (the VTK mapper "
            "always takes it)." % (self.size, self.size, self.frames),
            "",
            "The talk's per-frame measures on the paper path, cylindrical ÷ Cartesian (frames per "
            "second: Cartesian frame time ÷ cylindrical; above 1, the cylindrical structure is "
            "faster):",
            "",
            table(["mesh (cells)", "grid: hexahedra tested", "grid: frames per second",
                   "BVH: hexahedra tested", "BVH: internal nodes", "BVH: leaf nodes",
                   "BVH: frames per second"], rows + [talk]),
            "",
            "![cylindrical ÷ Cartesian, paper path](%s)" % rel(plot),
            "",
            "The fast path: hexahedra tested per sample located (cart-grid / cyl-grid / cart-bvh "
            "/ cyl-bvh), and how much faster than the paper path each structure's frame is:",
            "",
            table(["mesh", "samples", "hexahedra tested per sample located", "paper ÷ fast frame"],
                  fast_rows),
        ]
        return "\n".join(text)


class AccuracySection(Section):
    name = "accuracy"
    title = "Accuracy: the price of the step"
    # Larger than `cylvol accuracy`'s default 128, so that a frame's time is more than its
    # fixed costs and the machine's noise.
    size = 256
    runs = [
        ("pump-rotor:200000", [], "pump-rotor, boundary segments (default)", "accuracy-rotor.svg"),
        ("pump-rotor:200000", ["--whole-steps"], "pump-rotor, `--whole-steps`", "accuracy-rotor-whole-steps.svg"),
        ("tests/data/mixer.vtk", ["--scalar", "p"], "mixer, pressure", "accuracy-mixer.svg"),
    ]

    def run(self, opts, commands):
        out = []
        for mesh, extra, _, svg in self.runs:
            plot = os.path.relpath(os.path.join(OUT_DIR, svg), REPO)
            out.append(run_json([CYLVOL, "accuracy", mesh, "--structure", "cyl-bvh",
                                 "--size", str(self.size)] + extra
                                + ["--plot", plot, "--json"], commands))
        return out

    def table(self, data):
        """One table per study: per step, its samples, time and errors; the time also as a
        multiple of the default step's (½), measured in the same run."""
        out = []
        for (_, _, label, _), d in zip(self.runs, data):
            half = next(r for r in d["runs"] if r["factor"] == 0.5)
            rows = [[step_label(r["factor"]) + (" (default)" if r["factor"] == 0.5 else ""),
                     "{:,}".format(r["samples"]), "%.3f" % r["time_s"],
                     "%.2f" % (r["time_s"] / half["time_s"]), sci(r["rmse"]), sci(r["max_err"])]
                    for r in d["runs"]]
            out += ["**%s** (%s cells; fitted order %.2f; reference at 1/32 ×: %s samples, %.2f s)"
                    % (label, "{:,}".format(d["cells"]), d["order_fit"],
                       "{:,}".format(d["reference"]["samples"]), d["reference"]["time_s"]), "",
                    table(["step (× mean cell size)", "samples", "time s", "time ÷ default",
                           "rmse", "max error"], rows), ""]
        return "\n".join(out).rstrip()

    def markdown(self, data):
        text = [
            "`cylvol accuracy` renders one view at steps of 2, 1, ½, ¼ and ⅛ × the mean cell "
            "size and compares each image with a reference at 1/32 × composited in `f64` (errors "
            "in [0, 1] premultiplied RGBA, %d×%d images, cylindrical BVH, fast path). "
            "[accuracy.md](accuracy.md) explains the settings; its plots are these runs'." %
            (data[0]["width"], data[0]["height"]),
            "",
            self.table(data),
        ]
        return "\n".join(text)

    def blocks(self, data):
        plots = "\n\n".join("![%s](benchmarks/%s)" % (label.replace("`", ""), svg)
                            for _, _, label, svg in self.runs)
        return {("docs/accuracy.md", "accuracy-table"): (self.table(data), True),
                ("docs/accuracy.md", "accuracy-plots"): (plots, False)}


SECTIONS = [VtkSection(), StructuresSection(), RenderSection(), AccuracySection()]


# ---------------------------------------------------------------------------------------
# the documents


def write_benchmarks_md(results):
    parts = [
        "# Benchmarks",
        "",
        "<!-- Written by scripts/make_benchmarks_doc.py from docs/benchmarks/results.json: "
        "edit the script, not this file. -->",
        "",
        "Every table and plot here is written by `/usr/bin/python3 scripts/make_benchmarks_doc.py` "
        "from the JSON the commands below print; `--only SECTION` reruns one section, "
        "`--from-json` rewrites this file from `benchmarks/results.json` without running "
        "anything. Each section names the machine it ran on and when.",
        "",
        "The machine was shared with other builds while these ran, so absolute times are noisy "
        "(tens of per cent from one run to the next). What is compared is measured side by side: "
        "the ratios come from runs made by one script minutes apart (the render benchmark's in "
        "rounds that alternate the structures), and the counters "
        "(hexahedra tested, nodes visited, samples, references, bytes) are exact and the same on "
        "any machine. Read the ratios and counters; treat the seconds as indications.",
        "",
        "The cylindrical structures and the talk's measures come from %s." % TALK_CITATION,
        "",
    ]
    for section in SECTIONS:
        entry = results["sections"].get(section.name)
        parts += ["## " + section.title, ""]
        if not entry:
            parts += ["Not run yet: `/usr/bin/python3 scripts/make_benchmarks_doc.py --only %s`."
                      % section.name, ""]
            continue
        parts += [section.markdown(entry["data"]), "",
                  "Machine: %s." % machine_line(entry["machine"]), "",
                  "Commands (run by `/usr/bin/python3 scripts/make_benchmarks_doc.py --only %s%s`):"
                  % (section.name, section.rerun_options(entry["data"])), "",
                  commands_block(entry["commands"]), ""]
    with open(os.path.join(DOCS, "benchmarks.md"), "w") as f:
        f.write("\n".join(parts).rstrip() + "\n")


def fill_blocks(results):
    for section in SECTIONS:
        entry = results["sections"].get(section.name)
        if not entry:
            continue
        for (document, name), (text, with_machine) in section.blocks(entry["data"]).items():
            path = os.path.join(REPO, document)
            with open(path) as f:
                content = f.read()
            begin, end = "<!-- generated:%s -->" % name, "<!-- /generated:%s -->" % name
            if begin not in content or end not in content:
                print("note: %s has no %s block; left as it is" % (document, name), file=sys.stderr)
                continue
            head, rest = content.split(begin, 1)
            _, tail = rest.split(end, 1)
            note = "Machine: %s.\n\nCommands (`/usr/bin/python3 scripts/make_benchmarks_doc.py --only %s%s` runs them):\n\n%s" % (
                machine_line(entry["machine"]), section.name, section.rerun_options(entry["data"]),
                commands_block(entry["commands"]))
            if document == "README.md":
                m = entry["machine"]
                note = ("%s, %d cores, %s; %s. Regenerate: `/usr/bin/python3 "
                        "scripts/make_benchmarks_doc.py --only %s%s`."
                        % (m["cpu"], m["cores"], m["os"], m["date"].split()[0], section.name,
                           section.rerun_options(entry["data"])))
            body = text + ("\n\n" + note if with_machine else "")
            with open(path, "w") as f:
                f.write(head + begin + "\n" + body + "\n" + end + tail)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--only", action="append", choices=[s.name for s in SECTIONS],
                   help="run this section only (repeatable); the others keep their results")
    p.add_argument("--from-json", action="store_true", help="run nothing: rewrite the documents")
    p.add_argument("--large", action="store_true",
                   help="also run the 2.1 M-cell meshes against VTK (minutes, ~7 GB for VTK)")
    p.add_argument("--no-build", action="store_true", help="measure the build as it is")
    opts = p.parse_args()
    os.makedirs(OUT_DIR, exist_ok=True)
    results = {"sections": {}}
    if os.path.exists(RESULTS):
        with open(RESULTS) as f:
            results = json.load(f)
    if not opts.from_json:
        if not opts.no_build:
            subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=REPO, check=True)
        for section in SECTIONS:
            if opts.only and section.name not in opts.only:
                continue
            commands = []
            where = machine()
            data = section.run(opts, commands)
            results["sections"][section.name] = {"machine": where, "commands": commands, "data": data}
            with open(RESULTS, "w") as f:
                json.dump(results, f, indent=1, sort_keys=True)
                f.write("\n")
    write_benchmarks_md(results)
    fill_blocks(results)
    print("wrote docs/benchmarks.md, its plots in docs/benchmarks/ and the generated blocks",
          file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
