#!/usr/bin/env bash
# README command 2: install, build, and run the test suite with CTest.  Without arguments the
# tests whose labels match `long` (each over ~20 s: the long verification runs and the 3–4 rank
# runs of the fracture and bonded scenes; ~18 min of test time together) are left out;
# `scripts/test.sh -L long` runs only them, `scripts/test.sh -LE none` everything.  Other
# arguments go to ctest.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
cd "$root/build"
if [ "$#" -eq 0 ]; then set -- -LE long; fi
ctest --output-on-failure -j "$(nproc 2>/dev/null || echo 2)" "$@"
