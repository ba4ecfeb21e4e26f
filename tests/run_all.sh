#!/usr/bin/env bash
# The one command that runs every cylvol test, on a fresh Debian 12 machine or a developer's.
# It installs what the tests need (Debian's VTK 9.1 with Python, Xvfb, CMake, ParaView 5.11
# with its development files and Open MPI) when missing, then checks formatting and lints,
# runs the Rust unit, integration and doc tests (some of which drive VTK's own Python readers to
# cross-check our files), and the C ABI's test program (built through the CMake package, then
# run under valgrind or AddressSanitizer), the VTK mapper's CTest suite (against VTK's own
# unstructured ray caster, baselines, Python), and the ParaView plugin's (pvbatch serial and
# over MPI, pvserver with a pvpython client, the GUI).
#
# ParaView comes without its recommended python3-paraview, which conflicts with python3-vtk9
# (both install Python's vtkmodules): the ParaView stage unpacks that package beside the
# system instead (vtk_plugin/ParaView/run_tests.sh), so both suites run, now and again.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(libvtk9-dev python3-vtk9 vtk9-examples xvfb xauth cmake g++
  paraview paraview-dev qtbase5-dev qttools5-dev libqt5svg5-dev libqt5opengl5-dev openmpi-bin)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "== installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
/usr/bin/python3 -c "import sys, vtk; print('== VTK', vtk.vtkVersion.GetVTKVersion(), 'with Python', sys.version.split()[0])"

echo "== cargo fmt --check"
cargo fmt --all -- --check
echo "== cargo clippy (all targets: the benchmarks are checked here and run with cargo bench)"
cargo clippy --all-targets --locked -- -D warnings
echo "== cargo test"
cargo test --locked --lib --bins --tests
echo "== doc tests"
cargo test --locked --doc
echo "== release build (the CMake package's libcylvol.a, and the cylvol program the VTK tests run)"
cargo build --locked --release
echo "== C ABI (tests/c_api through find_package(CylVol))"
bash tests/c_api/run.sh
echo "== VTK mapper (vtk_plugin: build, CTest under xvfb-run, install, import cylvol)"
bash vtk_plugin/run_tests.sh
echo "== ParaView plugin (vtk_plugin/ParaView: built against Debian's ParaView 5.11, CTest under Xvfb)"
paraview_start=$(date +%s)
bash vtk_plugin/ParaView/run_tests.sh
echo "== ParaView stage: $(( $(date +%s) - paraview_start )) s"
