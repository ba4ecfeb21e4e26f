#!/usr/bin/python3
"""Reading VTU files as VTK writes them: cylvol's reader beside VTK's, for each compressor.

VTK's vtkXMLUnstructuredGridWriter writes the mesh once per compressor ParaView offers (none,
ZLib, LZ4, LZMA; appended raw data, VTK's default block size), then each file is read by VTK's
vtkXMLUnstructuredGridReader (in this process, `Update()` timed) and by `cylvol info FILE`
(its own load time, printed on standard error, validation included), fastest of `--repeats`
runs each, alternating. Prints the file sizes, both readers' seconds and VTK ÷ cylvol.

Usage (Debian's python3-vtk9; the cylvol command is built first unless --no-build):
    /usr/bin/python3 scripts/bench_read.py FILE.vtu [--repeats 3] [--keep DIR]
FILE is any mesh VTK's XML reader reads (`cylvol gen pump-rotor -o rotor.vtu` makes one).
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
CYLVOL = os.path.join(REPO, "target", "release", "cylvol")
COMPRESSORS = ["None", "ZLib", "LZ4", "LZMA"]


def vtk_read(path):
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    t = time.perf_counter()
    r.Update()
    seconds = time.perf_counter() - t
    return seconds, r.GetOutput().GetNumberOfCells()


def cylvol_read(path):
    p = subprocess.run([CYLVOL, "info", path], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("cylvol info %s failed: %s" % (path, p.stderr.strip()))
    m = re.search(r"loaded .*: (\d+) cells, \d+ points in ([0-9.]+) s", p.stderr)
    if not m:
        sys.exit("no load time in cylvol's output: %s" % p.stderr.strip())
    return float(m.group(2)), int(m.group(1))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("file")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--keep", help="folder for the written files (default: a temp dir, removed)")
    p.add_argument("--no-build", action="store_true", help="use target/release/cylvol as it is")
    args = p.parse_args()
    if not args.no_build:
        subprocess.run(["cargo", "build", "--release", "--quiet", "--manifest-path",
                        os.path.join(REPO, "Cargo.toml")], check=True)
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader, vtkXMLUnstructuredGridWriter

    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(args.file)
    r.Update()
    grid = r.GetOutput()
    print("%s: %d cells, %d points" % (args.file, grid.GetNumberOfCells(), grid.GetNumberOfPoints()))
    tmp = None if args.keep else tempfile.TemporaryDirectory()
    folder = args.keep or tmp.name
    os.makedirs(folder, exist_ok=True)
    print("%-10s %10s %12s %12s %10s" % ("compressor", "MB", "VTK read s", "cylvol s", "VTK/cylvol"))
    for name in COMPRESSORS:
        path = os.path.join(folder, "mesh-%s.vtu" % name.lower())
        w = vtkXMLUnstructuredGridWriter()
        w.SetInputData(grid)
        w.SetFileName(path)
        w.SetDataModeToAppended()
        w.EncodeAppendedDataOff()
        getattr(w, "SetCompressorTypeTo" + name)()
        if w.Write() != 1:
            sys.exit("VTK could not write %s" % path)
        vtk_s, ours_s = [], []
        for _ in range(args.repeats):
            s, n = vtk_read(path)
            vtk_s.append(s)
            assert n == grid.GetNumberOfCells(), (path, n)
            s, n = cylvol_read(path)
            ours_s.append(s)
            assert n == grid.GetNumberOfCells(), (path, n)
        a, b = min(vtk_s), min(ours_s)
        print("%-10s %10.1f %12.2f %12.2f %9.1fx" % (name, os.path.getsize(path) / 1e6, a, b, a / b))
        if tmp:
            os.remove(path)
    if tmp:
        tmp.cleanup()


if __name__ == "__main__":
    main()
