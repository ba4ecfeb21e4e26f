#!/usr/bin/python3
"""Reading meshes as VTK writes them: cylvol's reader beside VTK's, for each file format.

VTK writes the mesh once per format: with vtkXMLUnstructuredGridWriter once per compressor
ParaView offers (none, ZLib, LZ4, LZMA; appended raw data, VTK's default block size), and with
vtkUnstructuredGridWriter as a binary legacy file in both layouts of its cell list (`legacy
4.2`: a count before each cell's ids, as foamToVTK and older VTK write it; `legacy 5.1`:
OFFSETS and CONNECTIVITY arrays, VTK 9's default). Each file is then read by VTK's reader for
it (vtkXMLUnstructuredGridReader, vtkUnstructuredGridReader; in a fresh Python process,
`Update()` timed) and by `cylvol info FILE` (its own load time, printed on standard error,
validation included), fastest of `--repeats` runs each, alternating. Prints the file sizes,
both readers' seconds, VTK ÷ cylvol, and the peak memory of each: for VTK what its process's
peak resident set grew by during `Update()` (Python and VTK's libraries excluded), for cylvol
the whole `cylvol info` process's peak (its load and the axis detection `info` runs after it).

Usage (Debian's python3-vtk9; the cylvol command is built first unless --no-build):
    /usr/bin/python3 scripts/bench_read.py FILE [--repeats 3] [--formats vtu,legacy] [--keep DIR]
FILE is any mesh VTK's XML or legacy reader reads (`cylvol gen pump-rotor -o rotor.vtu` makes
one); --formats picks the XML files (`vtu`), the legacy ones (`legacy`) or both (the default).
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
CYLVOL = os.path.join(REPO, "target", "release", "cylvol")
# (row name, file name, how VTK writes it): an XML compressor, or a legacy file version.
FORMATS = {
    "vtu": [(c, "mesh-%s.vtu" % c.lower(), ("xml", c)) for c in ["None", "ZLib", "LZ4", "LZMA"]],
    "legacy": [("legacy 4.2", "mesh-42.vtk", ("legacy", 42)),
               ("legacy 5.1", "mesh-51.vtk", ("legacy", 51))],
}


# Each VTK step runs in its own Python process, so that this one stays small: a child's peak
# resident set (`ru_maxrss`) starts from its parent's when it is spawned.
VTK_READ = """
import sys, time
from vtkmodules.vtkIOLegacy import vtkUnstructuredGridReader
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

def high_water_kb():
    status = open("/proc/self/status").read()
    return int(status.split("VmHWM:")[1].split()[0])

legacy = sys.argv[1].endswith(".vtk")
r = vtkUnstructuredGridReader() if legacy else vtkXMLUnstructuredGridReader()
r.SetFileName(sys.argv[1])
before = high_water_kb()
t = time.perf_counter()
r.Update()
seconds = time.perf_counter() - t
print(seconds, r.GetOutput().GetNumberOfCells(), high_water_kb() - before)
"""

VTK_WRITE = """
import sys
from vtkmodules.vtkIOLegacy import vtkUnstructuredGridReader, vtkUnstructuredGridWriter
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader, vtkXMLUnstructuredGridWriter
r = vtkUnstructuredGridReader() if sys.argv[1].endswith(".vtk") else vtkXMLUnstructuredGridReader()
r.SetFileName(sys.argv[1])
r.Update()
grid = r.GetOutput()
for how, path in zip(sys.argv[2::2], sys.argv[3::2]):
    kind, setting = how.split(":")
    if kind == "xml":
        w = vtkXMLUnstructuredGridWriter()
        w.SetDataModeToAppended()
        w.EncodeAppendedDataOff()
        getattr(w, "SetCompressorTypeTo" + setting)()
    else:
        w = vtkUnstructuredGridWriter()
        w.SetFileTypeToBinary()
        w.SetFileVersion(int(setting))
    w.SetInputData(grid)
    w.SetFileName(path)
    if w.Write() != 1:
        sys.exit("VTK could not write %s" % path)
print(grid.GetNumberOfCells(), grid.GetNumberOfPoints())
"""


def vtk_read(path):
    """VTK's read of `path` in a fresh process: seconds, cells, MB its peak grew by."""
    p = subprocess.run([sys.executable, "-c", VTK_READ, path], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("VTK could not read %s: %s" % (path, p.stderr.strip()))
    seconds, cells, kb = p.stdout.split()
    return float(seconds), int(cells), int(kb) / 1024


def cylvol_read(path, cylvol=CYLVOL):
    """`cylvol info path`: its load seconds, cells, and the process's peak MB."""
    p = subprocess.Popen([cylvol, "info", path], stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE, text=True)
    stderr = p.stderr.read()
    _, status, usage = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        sys.exit("cylvol info %s failed: %s" % (path, stderr.strip()))
    m = re.search(r"loaded .*: (\d+) cells, \d+ points in ([0-9.]+) s", stderr)
    if not m:
        sys.exit("no load time in cylvol's output: %s" % stderr.strip())
    return float(m.group(2)), int(m.group(1)), usage.ru_maxrss / 1024


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("file")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--keep", help="folder for the written files (default: a temp dir, removed)")
    p.add_argument("--formats", default="vtu,legacy",
                   help="comma-separated: vtu (one file per compressor), legacy (4.2 and 5.1)")
    p.add_argument("--no-build", action="store_true", help="use target/release/cylvol as it is")
    p.add_argument("--cylvol", default=CYLVOL,
                   help="the cylvol program to measure (default: the build's; implies --no-build)")
    args = p.parse_args()
    try:
        formats = [f for name in args.formats.split(",") for f in FORMATS[name]]
    except KeyError as e:
        sys.exit("unknown format %s (known: %s)" % (e, ", ".join(FORMATS)))
    if not args.no_build and args.cylvol == CYLVOL:
        subprocess.run(["cargo", "build", "--release", "--quiet", "--manifest-path",
                        os.path.join(REPO, "Cargo.toml")], check=True)
    tmp = None if args.keep else tempfile.TemporaryDirectory()
    folder = args.keep or tmp.name
    os.makedirs(folder, exist_ok=True)
    paths = [os.path.join(folder, file) for _, file, _ in formats]
    pairs = [x for (_, _, how), path in zip(formats, paths) for x in ("%s:%s" % how, path)]
    p = subprocess.run([sys.executable, "-c", VTK_WRITE, args.file] + pairs,
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("VTK could not read or write: %s" % p.stderr.strip())
    cells, points = map(int, p.stdout.split())
    print("%s: %d cells, %d points" % (args.file, cells, points))
    print("%-10s %8s %11s %9s %10s %11s %10s" % ("format", "file MB", "VTK read s", "cylvol s",
                                                  "VTK/cylvol", "VTK peak MB", "cylvol MB"))
    for (name, _, _), path in zip(formats, paths):
        vtk_runs, our_runs = [], []
        for _ in range(args.repeats):
            for read, runs in ((vtk_read, vtk_runs),
                               (lambda f: cylvol_read(f, args.cylvol), our_runs)):
                seconds, n, mb = read(path)
                assert n == cells, (path, n)
                runs.append((seconds, mb))
        a, b = min(s for s, _ in vtk_runs), min(s for s, _ in our_runs)
        vtk_mb, our_mb = max(m for _, m in vtk_runs), max(m for _, m in our_runs)
        print("%-10s %8.1f %11.2f %9.2f %9.1fx %11.0f %10.0f"
              % (name, os.path.getsize(path) / 1e6, a, b, a / b, vtk_mb, our_mb))
        if tmp:
            os.remove(path)
    if tmp:
        tmp.cleanup()


if __name__ == "__main__":
    main()
