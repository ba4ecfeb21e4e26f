#!/usr/bin/env bash
# Builds and runs the C ABI's test project (tests/c_api) against the CylVol CMake package
# (CylVol_DIR = <repo>/cmake; the package builds libcylvol.a with cargo in release mode),
# runs it with CTest, then once more under valgrind (definite leaks and memory errors fail),
# or, without valgrind, as a second build with AddressSanitizer. Exits non-zero on any failure.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${CYLVOL_C_API_BUILD:-$root/target/c_api}"
jobs="${CYLVOL_C_API_JOBS:-2}"

echo "== c_api: configure and build ($build/default)"
cmake -S "$here" -B "$build/default" -DCylVol_DIR="$root/cmake" -DCMAKE_BUILD_TYPE=Debug >/dev/null
cmake --build "$build/default" -j "$jobs"

echo "== c_api: ctest"
ctest --test-dir "$build/default" --output-on-failure

if command -v valgrind >/dev/null 2>&1; then
  echo "== c_api: valgrind"
  valgrind --quiet --leak-check=full --show-leak-kinds=definite --errors-for-leak-kinds=definite \
    --error-exitcode=1 \
    "$build/default/test_c_api" >/dev/null
  echo "valgrind: no memory errors, no definite leaks"
else
  echo "== c_api: AddressSanitizer (valgrind not installed)"
  cmake -S "$here" -B "$build/asan" -DCylVol_DIR="$root/cmake" -DCMAKE_BUILD_TYPE=Debug \
    -DCYLVOL_C_API_ASAN=ON >/dev/null
  cmake --build "$build/asan" -j "$jobs"
  ASAN_OPTIONS=detect_leaks=1 "$build/asan/test_c_api" >/dev/null
  echo "AddressSanitizer: clean"
fi
echo "c_api: all passed"
