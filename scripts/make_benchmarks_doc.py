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
    /usr/bin/python3 scripts/make_benchmarks_doc.py --large        # also the 2 M-cell meshes
                                                                   # against VTK (~7 GB, hours)
    /usr/bin/python3 scripts/make_benchmarks_doc.py --only vtk --large mixer:4 \
        --large-mappers cylvol,vtk-raycast,projected-tetra,resample-smart
                                  # the VTK section with one 2 M-cell mesh and some mappers
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
               m["date"], " / ".join("%.1f" % x for x in m["load_average"])) + (
                   ", %s at the end" % " / ".join("%.1f" % x for x in m["load_average_end"])
                   if m.get("load_average_end") else ""))


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


# The mappers of scripts/bench_vtk.py, as the tables name them, and their colours in plots.
MAPPER_LABELS = {
    "cylvol": "cylvol (vtkCylVolMapper)",
    "vtk-raycast": "VTK ray caster",
    "zsweep": "Z-sweep",
    "projected-tetra": "projected tetrahedra",
    "resample-smart": "resample to image + smart mapper",
}
MAPPER_COLORS = {"cylvol": PALETTE[0], "vtk-raycast": PALETTE[3], "zsweep": PALETTE[4],
                 "projected-tetra": PALETTE[1], "resample-smart": PALETTE[2]}
# vtkSmartVolumeMapper's GetLastUsedRenderMode values.
SMART_RENDER_MODES = {1: "CPU ray cast", 2: "GPU ray cast", 3: "OSPRay"}
# Markers of cylvol's settings in the error-against-time plot: the default step, longer
# steps, then the error settings in the order they come.
STEP_MARKER = "square"
ERROR_MARKERS = ["triangle", "down", "diamond"]


def ordered_runs(entry):
    """(key, run) of a dataset's runs, reference left out: cylvol's default, its longer steps,
    its error settings, then the competitors in MAPPER_LABELS's order."""
    def rank(item):
        key, r = item
        mapper = r.get("mapper", key)
        order = list(MAPPER_LABELS).index(mapper) if mapper in MAPPER_LABELS else len(MAPPER_LABELS)
        kind = 0 if key == "cylvol" else 1 if key.startswith("cylvol@step") else 2
        return (order, kind, r.get("relative_step") or 0.0, r.get("max_error") or 0.0)

    return sorted(((k, r) for k, r in entry["runs"].items() if k != "reference"), key=rank)


class VtkSection(Section):
    name = "vtk"
    title = "Against VTK's and ParaView's unstructured volume mappers"
    # The meshes every run compares, and cylvol's settings on them.
    SMALL = ("mixer", "rotor:200000")
    SMALL_SETTINGS = ["--relative-steps", "1,4", "--max-errors", "1,4"]
    # The 2 M-cell meshes (--large): cylvol's default step is a quarter of the unrefined
    # mixer's there, so the longer steps compared are longer too.
    LARGE = ("mixer:4", "rotor:2100000")
    LARGE_SETTINGS = ["--relative-steps", "1,8", "--max-errors", "1,4"]
    # Long enough for VTK's ray caster on 2 M cells (a first frame of minutes).
    TIMEOUT = 900

    def run(self, opts, commands):
        keep = tempfile.mkdtemp(prefix="cylvol-benchmarks-vtk-")
        common = ["--timeout", str(self.TIMEOUT)]
        runs = [list(self.SMALL) + self.SMALL_SETTINGS + common]
        for dataset in opts.large or []:
            extra = ["--mappers", opts.large_mappers] if opts.large_mappers else []
            runs.append([dataset] + self.LARGE_SETTINGS + extra + common)
        results = []
        for i, args in enumerate(runs):
            # The module is built (if need be) by the first run only.
            extra = ["--no-build"] if (opts.no_build or i > 0) else []
            results += run_bench_vtk(args + extra, commands, keep)
        return results

    @staticmethod
    def name_of(dataset):
        name = {"mixer": "mixer", "rotor": "pump-rotor", "post": "LOX post", "comb": "combustor",
                "hexa": "Cartesian cube"}[dataset.split(":")[0]]
        if dataset.startswith(("mixer:", "hexa:")):
            name += ", refined ×%s³" % dataset.split(":")[1]
        return name

    @staticmethod
    def cells_of(entry):
        return next((r["cells"] for r in entry["runs"].values() if r.get("cells")), None)

    def mesh_label(self, entry):
        cells = self.cells_of(entry)
        return "%s (%s)" % (self.name_of(entry["dataset"]),
                            "{:,}".format(cells) if cells else entry["dataset"])

    @staticmethod
    def setting(key, r, entry):
        if key.startswith("cylvol@error"):
            return "max error %g/255" % r["max_error"]
        if key.startswith("cylvol@step"):
            return "%g × default step" % r["relative_step"]
        if key == "cylvol":
            return "default step"
        if key == "resample-smart":
            n = entry.get("resample_dims", 100)
            mode = SMART_RENDER_MODES.get(r.get("render_mode"))
            return "%d³ points" % n + (", %s" % mode if mode else "")
        if key in ("vtk-raycast", "zsweep", "projected-tetra"):
            tets = r.get("tetrahedra")
            return "{:,} tetrahedra".format(tets) if tets else "tetrahedra"
        return ""

    @staticmethod
    def status(r, timeout):
        if r.get("skipped"):
            return r["skipped"]
        if r.get("unavailable"):
            return r["unavailable"]
        if r.get("timed_out"):
            if "first_frame_s" in r:
                return "steady frame > %d s, not finished" % timeout
            return "> %d s, not finished" % timeout
        if "error" in r:
            return "failed: " + r["error"].splitlines()[0]
        return None

    def runs_table(self, entry):
        rows = []
        timeout = entry.get("timeout_s", self.TIMEOUT)
        for key, r in ordered_runs(entry):
            head = [MAPPER_LABELS.get(r.get("mapper"), r.get("mapper", key)),
                    self.setting(key, r, entry)]
            why = self.status(r, timeout)
            if "first_frame_s" not in r:
                rows.append(head + [why or "–"] + [""] * 5)
                continue
            e = r.get("error_vs_reference") or {}
            steady = r.get("steady_s")
            # cylvol prepares nothing before its first frame: its structure build, inside that
            # frame, takes the column.
            prepare = r.get("build_s") if r.get("mapper") == "cylvol" else r.get("prepare_s")
            rows.append(head + [
                "–" if prepare is None else "%.2f" % prepare,
                "%.2f" % r["first_frame_s"],
                "%.3f" % steady if steady is not None else why,
                "{:,.0f}".format(r["peak_rss_bytes"] / 1e6),
                "%s / %s / %s" % (fmt_err(e.get("mean_abs_255")), fmt_num(e.get("p99_255")),
                                  fmt_num(e.get("max_255"))),
                pct(e.get("percent_within_8"))])
        return table(["mapper", "setting", "prepare s (cylvol: build)", "first frame s", "steady frame s",
                      "peak memory MB", "error /255: mean / p99 / max", "pixels within 8/255"],
                     rows)

    def ratios_table(self, entry):
        cyl = [k for k, r in ordered_runs(entry) if k.startswith("cylvol") and "first_frame_s" in r]
        header = ["competitor ÷ cylvol: first / steady frame, memory"] + [
            "cylvol " + self.setting(k, entry["runs"][k], entry) for k in cyl]
        rows = []
        for comp in MAPPER_LABELS:
            per = entry.get("ratios", {}).get(comp)
            if per is None:
                continue
            rows.append([MAPPER_LABELS[comp]] + [
                "**%s** / **%s**, %s" % (ratio(per[k]["first_frame"]), ratio(per[k]["steady"]),
                                          ratio(per[k]["peak_rss"])) if k in per else "–"
                for k in cyl])
        return table(header, rows) if rows and cyl else ""

    def points(self, entry):
        """(series label, colour, marker, steady frame s, mean error /255) of every run with
        both figures."""
        out = []
        errors = iter(ERROR_MARKERS * 4)
        for key, r in ordered_runs(entry):
            mapper = r.get("mapper", key)
            shape = ("circle" if key == "cylvol" or mapper != "cylvol"
                     else STEP_MARKER if key.startswith("cylvol@step") else next(errors))
            err = (r.get("error_vs_reference") or {}).get("mean_abs_255")
            if r.get("steady_s") is None or err is None:
                continue
            label = MAPPER_LABELS[mapper] if mapper != "cylvol" else "cylvol, " + self.setting(key, r, entry)
            out.append((label, MAPPER_COLORS[mapper], shape, r["steady_s"], err))
        return out

    def markdown(self, data):
        plot = os.path.join(OUT_DIR, "vtk-error-time.svg")
        error_time_plot(plot, "Error against steady frame time (%d×%d; lower left is better)"
                        % ((data[0]["size"],) * 2 if data else (512, 512)),
                        [(self.mesh_label(e), self.points(e)) for e in data])
        size = data[0]["size"] if data else 512
        dims = data[0].get("resample_dims", 100) if data else 100
        text = [
            "`scripts/bench_vtk.py` renders one scene, %d×%d, with `vtkCylVolMapper` and with "
            "each of VTK's unstructured volume mappers, each in its own process (Debian's VTK "
            "9.1, off screen under `xvfb-run`, Mesa's llvmpipe for the OpenGL mappers):" % (size, size),
            "",
            "- **VTK ray caster**: `vtkUnstructuredGridVolumeRayCastMapper`,",
            "- **Z-sweep**: `vtkUnstructuredGridVolumeZSweepMapper`,",
            "- **projected tetrahedra**: `vtkProjectedTetrahedraMapper` (OpenGL; ParaView's "
            "default for unstructured volumes),",
            "  all three on `vtkDataSetTriangleFilter`'s tetrahedra (six per hexahedron), as "
            "they need and as ParaView's Volume representation makes them; the two CPU ray "
            "casters render every pixel (`AutoAdjustSampleDistancesOff`);",
            "- **resample to image + smart mapper**: ParaView's usual workaround, "
            "`vtkResampleToImage` onto %d×%d×%d points over the mesh's bounds (the default "
            "`SamplingDimensions` of ParaView's *Resample To Image* filter; the Volume "
            "representation's own *Resample To Image* mapper takes 128³), then "
            "`vtkSmartVolumeMapper` (OpenGL)." % (dims, dims, dims),
            "",
            "The same camera, transfer function and unit distance for all. The *first frame* "
            "runs from the loaded mesh to the first image: it includes the tetrahedralization "
            "or the resampling (*prepare*, also shown apart) and cylvol's structure build (shown "
            "in its place). The "
            "*steady frame* is the median of the frames that follow, the camera turning a "
            "degree a frame. *Peak memory* is the worker process's peak resident memory. The "
            "*error* of each mapper's first image is measured against a converged reference, cylvol at ⅛ of "
            "its default step: the mean difference over the channels, and, per pixel the "
            "largest channel difference, its 99th percentile and maximum, all in /255; and the "
            "share of pixels within 8/255. A worker that runs past %d s is stopped and its row "
            "says so; a mapper whose estimated memory exceeds what the machine has free is "
            "skipped. cylvol runs at its default step (half the mean cell size), at a longer "
            "step (`SetRelativeSampleDistance`) and at error settings (`SetMaximumError`, the "
            "largest colour error allowed in /255)."
            % (data[0].get("timeout_s", self.TIMEOUT) if data else self.TIMEOUT),
        ]
        for entry in data:
            text += ["", "### %s" % self.mesh_label(entry), "", self.runs_table(entry)]
            ratios = self.ratios_table(entry)
            if ratios:
                text += ["", "Ratios, competitor ÷ cylvol (above 1: cylvol faster or smaller):",
                         "", ratios]
        text += [
            "",
            "![mean error against steady frame time, per mesh](%s)" % rel(plot),
            "",
            "A refined mixer is the OpenFOAM mixer with every hexahedron cut into N × N × N "
            "(`cylvol gen tests/data/mixer.vtk --refine N`). The plot shows the runs that "
            "finished their steady frames, on log scales. VTK's ray caster integrates once per "
            "tetrahedron crossed, projected tetrahedra sorts and draws every tetrahedron each "
            "frame, Z-sweep sweeps their faces; cylvol samples at steps and inverts the "
            "trilinear map of a hexahedron at each sample. So on small meshes VTK's ray caster "
            "and projected tetrahedra can be faster than cylvol's default step, and cylvol's "
            "lead grows with the mesh (set-up, frame and memory of the tetrahedral mappers grow "
            "with the six tetrahedra of each hexahedron). The resampled image renders fast at "
            "any mesh size, at the price of its error (%d³ points are coarser than the mesh "
            "where its cells are small), and the resampling is paid in the first frame." % dims,
        ]
        return "\n".join(text)

    def blocks(self, data):
        rows = []
        for entry in data:
            for comp, per in entry.get("ratios", {}).items():
                x = per.get("cylvol")
                if not x:
                    continue
                e = (entry["runs"][comp].get("error_vs_reference") or {}).get("mean_abs_255")
                ce = (entry["runs"]["cylvol"].get("error_vs_reference") or {}).get("mean_abs_255")
                rows.append([self.mesh_label(entry), MAPPER_LABELS[comp],
                             "**%s**" % ratio(x["first_frame"]), "**%s**" % ratio(x["steady"]),
                             ratio(x["peak_rss"]), "%s; %s" % (fmt_err(ce), fmt_err(e))])
        return {("README.md", "vtk-table"): (table(
            ["mesh (cells)", "competitor", "competitor ÷ cylvol: first frame", "steady frame",
             "peak memory", "error /255 cylvol; competitor"], rows), True)}

    def rerun_options(self, data):
        large = [e for e in data if e["dataset"] not in self.SMALL]
        if not large:
            return ""
        out = " --large %s" % ",".join(e["dataset"] for e in large)
        mappers = large[0].get("mappers")
        if mappers and len(mappers) < len(MAPPER_LABELS):
            out += " --large-mappers %s" % ",".join(mappers)
        return out


def fmt_err(x):
    """A mean error in /255: three decimals, four below 0.01."""
    return "–" if x is None else ("%.3f" % x if x >= 0.01 else "%.4f" % x)


def fmt_num(x):
    return "–" if x is None else ("%.0f" % x if x >= 10 or float(x).is_integer() else "%.1f" % x)


def marker_svg(shape, x, y, color, r=5):
    """One marker of a scatter plot."""
    if shape == "square":
        return '<rect x="%.1f" y="%.1f" width="%d" height="%d" fill="%s"/>' % (x - r, y - r, 2 * r, 2 * r, color)
    if shape in ("diamond", "triangle", "down"):
        pts = {"diamond": [(0, -r - 1), (r + 1, 0), (0, r + 1), (-r - 1, 0)],
               "triangle": [(0, -r - 1), (r + 1, r), (-r - 1, r)],
               "down": [(0, r + 1), (r + 1, -r), (-r - 1, -r)]}[shape]
        return '<polygon points="%s" fill="%s"/>' % (
            " ".join("%.1f,%.1f" % (x + dx, y + dy) for dx, dy in pts), color)
    return '<circle cx="%.1f" cy="%.1f" r="%d" fill="%s"/>' % (x, y, r, color)


def log_range(values):
    """Decades that hold the values: (lowest power of ten, highest), at least one apart."""
    lo = math.floor(math.log10(min(values)))
    hi = math.ceil(math.log10(max(values)))
    return lo, max(hi, lo + 1)


def error_time_plot(path, title, panels):
    """A scatter plot per mesh, log-log: steady frame time (x) against mean error (y).
    `panels` is [(mesh label, [(series label, colour, marker, x, y)])]; one legend for all.
    Errors below 0.001/255 are drawn at 0.001. Writes the SVG to `path`."""
    floor = 1e-3
    panels = [(t, pts) for t, pts in panels if pts]
    cols = 2 if len(panels) > 1 else 1
    rows_n = max(1, (len(panels) + cols - 1) // cols)
    pw, ph = 380, 280
    left, top, bottom = 60, 40, 44
    series = []
    for _, pts in panels:
        for label, color, shape, _, _ in pts:
            if (label, color, shape) not in series:
                series.append((label, color, shape))
    legend_h = 20 * ((len(series) + 1) // 2) + 10
    width = cols * pw + 20
    height = top + rows_n * ph + legend_h
    s = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" viewBox="0 0 %d %d" '
         'font-family="sans-serif" font-size="12">' % (width, height, width, height),
         '<rect width="100%" height="100%" fill="white"/>',
         '<text x="%d" y="22" font-size="14" font-weight="bold">%s</text>' % (left, html.escape(title))]
    for i, (mesh, pts) in enumerate(panels):
        ox, oy = (i % cols) * pw, top + (i // cols) * ph
        x0, x1 = ox + left, ox + pw - 16
        y0, y1 = oy + 24, oy + ph - bottom
        xlo, xhi = log_range([p[3] for p in pts])
        ylo, yhi = log_range([max(p[4], floor) for p in pts])

        def px(v, xlo=xlo, xhi=xhi, x0=x0, x1=x1):
            return x0 + (x1 - x0) * (math.log10(v) - xlo) / (xhi - xlo)

        def py(v, ylo=ylo, yhi=yhi, y0=y0, y1=y1):
            return y1 - (y1 - y0) * (math.log10(max(v, floor)) - ylo) / (yhi - ylo)

        s.append('<text x="%d" y="%d" font-weight="bold">%s</text>' % (x0, oy + 16, html.escape(mesh)))
        s.append('<rect x="%d" y="%d" width="%d" height="%d" fill="none" stroke="#999"/>'
                 % (x0, y0, x1 - x0, y1 - y0))
        for e in range(xlo, xhi + 1):
            x = px(10.0 ** e)
            s.append('<line x1="%.1f" x2="%.1f" y1="%d" y2="%d" stroke="#ddd"/>' % (x, x, y0, y1))
            s.append('<text x="%.1f" y="%d" text-anchor="middle">%g</text>' % (x, y1 + 14, 10.0 ** e))
        for e in range(ylo, yhi + 1):
            y = py(10.0 ** e)
            s.append('<line x1="%d" x2="%d" y1="%.1f" y2="%.1f" stroke="#ddd"/>' % (x0, x1, y, y))
            s.append('<text x="%d" y="%.1f" text-anchor="end">%g</text>' % (x0 - 4, y + 4, 10.0 ** e))
        s.append('<text x="%.1f" y="%d" text-anchor="middle">steady frame (s)</text>'
                 % ((x0 + x1) / 2, y1 + 30))
        s.append('<text transform="translate(%d,%d) rotate(-90)" text-anchor="middle">mean error /255</text>'
                 % (ox + 16, (y0 + y1) // 2))
        for label, color, shape, x, y in pts:
            s.append(marker_svg(shape, px(x), py(y), color).replace(
                "/>", "><title>%s: %.3g s, %.3g/255</title></%s>" % (
                    html.escape(label), x, y, marker_tag(shape)), 1))
    ly = top + rows_n * ph + 4
    for j, (label, color, shape) in enumerate(series):
        lx = left + (j % 2) * (width // 2)
        y = ly + 20 * (j // 2)
        s.append(marker_svg(shape, lx, y, color))
        s.append('<text x="%d" y="%d">%s</text>' % (lx + 12, y + 4, html.escape(label)))
    s.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(s) + "\n")


def marker_tag(shape):
    return {"square": "rect", "circle": "circle"}.get(shape, "polygon")


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
    p.add_argument("--large", nargs="?", const=",".join(VtkSection.LARGE), default="",
                   type=lambda v: [d for d in v.split(",") if d],
                   help="also run these 2 M-cell meshes against VTK's mappers, comma-separated "
                        "(default %s; an hour or more, ~7 GB for VTK's ray caster)"
                        % ",".join(VtkSection.LARGE))
    p.add_argument("--large-mappers", default="",
                   help="the mappers run on the --large meshes (bench_vtk.py's --mappers; "
                        "default all)")
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
            where["load_average_end"] = [round(x, 2) for x in os.getloadavg()]
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
