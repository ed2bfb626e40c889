#!/usr/bin/env bash
# Builds fdem and its tests with ASan + UBSan (-DFDEM_SANITIZE=ON, float-cast-overflow included)
# into build-asan/ and runs the unit tests and the MPI tests under them (the verification suite
# is left to the Release build: under the sanitizers it takes longer than CI allows).  A sanitizer
# report stops the program, so it fails its test.  Extra arguments go to ctest.
#   scripts/sanitize.sh [ctest arguments...]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build-asan"
"$root/scripts/install-deps.sh"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFDEM_SANITIZE=ON \
      -DFDEM_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j "$(nproc 2>/dev/null || echo 2)"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# Open MPI, HDF5 and VTK keep allocations until exit that LeakSanitizer would report as leaks of
# fdem; leaks are not checked here (memory errors and undefined behaviour are).
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd "$build"
ctest --output-on-failure -j "$(nproc 2>/dev/null || echo 2)" -LE "verification|mpi-many" "$@"
