#!/usr/bin/env bash
# The one command that runs every cylvol test, on a fresh Debian 12 machine or a developer's.
# It installs what the tests need (Debian's VTK 9.1 with Python, Xvfb, CMake) when missing,
# then checks formatting and lints, runs the Rust unit, integration and doc tests (some of
# which drive VTK's own Python readers to cross-check our files), and the C ABI's test program
# (built through the CMake package, then run under valgrind or AddressSanitizer).
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(libvtk9-dev python3-vtk9 vtk9-examples xvfb xauth cmake)
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
echo "== C ABI (tests/c_api through find_package(CylVol))"
bash tests/c_api/run.sh
