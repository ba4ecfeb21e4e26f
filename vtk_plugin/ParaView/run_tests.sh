#!/usr/bin/env bash
# Builds and tests cylvol's ParaView plugin (vtk_plugin/ParaView) against Debian's ParaView
# 5.11 (paraview, paraview-dev): unpacks ParaView's Python beside the system, configures and
# builds the plugin under build/paraview, and runs its CTest suite under Xvfb.
#
# ParaView's Python (package python3-paraview: pvpython, pvbatch's modules, and the wrapping
# hierarchy files the build reads) conflicts with Debian's python3-vtk9, which the VTK 9.1
# module's tests need; it is never installed. Its package is downloaded once (apt-get
# download, the version of the installed paraview) and unpacked with dpkg -x into
# build/python3-paraview/root; ParaView's programs find it through PYTHONPATH.
#
# Needs: the packages tests/run_all.sh installs, the Rust release build (cargo build
# --release) and the VTK module's build tree (bash vtk_plugin/run_tests.sh), whose cylvol
# package draws the reference images. Exits non-zero on any failure.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
build="${CYLVOL_PARAVIEW_BUILD_DIR:-$repo/build/paraview}"
python_root="${CYLVOL_PARAVIEW_PYTHON_ROOT:-$repo/build/python3-paraview/root}"
jobs="${CYLVOL_PARAVIEW_JOBS:-2}"
vtk_build="${CYLVOL_VTK_BUILD_DIR:-$repo/build/vtk_plugin}"

if [ ! -e "$vtk_build/python_destination.txt" ]; then
  echo "run_tests.sh: $vtk_build is missing: run 'bash vtk_plugin/run_tests.sh' first" >&2
  exit 1
fi
vtk_python="$vtk_build/$(head -n1 "$vtk_build/python_destination.txt")"

# ParaView's Python, unpacked beside the system.
version="$(dpkg-query -W -f='${Version}' paraview)"
stamp="$python_root/.python3-paraview-$version"
if [ ! -e "$stamp" ]; then
  echo "== unpacking python3-paraview $version into $python_root"
  download="$(dirname "$python_root")"
  mkdir -p "$download"
  rm -rf "$python_root" "$download"/python3-paraview_*.deb
  (cd "$download" && apt-get download -q "python3-paraview=$version" 2>&1 | grep -v "unsandboxed" || true)
  deb="$(ls "$download"/python3-paraview_*.deb)"
  dpkg -x "$deb" "$python_root"
  touch "$stamp"
fi

cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -Wno-dev \
  -DCYLVOL_PARAVIEW_PYTHON_ROOT="$python_root" -DCYLVOL_VTK_PYTHONPATH="$vtk_python" >/dev/null
cmake --build "$build" -j "$jobs"
echo "plugin: $(cat "$build/plugin_path.txt")"
# -noreset: the tests' processes (mpiexec's ranks, pvserver, the GUI) open and close their
# connections to one X server; without it Xvfb resets between them and a rank fails now and
# then with "bad X server connection".
xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" \
  ctest --test-dir "$build" --output-on-failure -j "$jobs"
echo "vtk_plugin/ParaView: all tests passed"
