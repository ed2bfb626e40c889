#!/usr/bin/env bash
# Builds the internal-force benchmark (Release, in ./build) and runs it on one core.  Writes the
# CSV to docs/data/bench_internal_forces.csv and the printed table, with the machine and its load,
# to docs/data/bench_internal_forces.txt.
# Usage: scripts/bench-internal-forces.sh [benchmark options, e.g. --no-1e6 or --sizes 1e4,1e5]
# Environment: BUILD_DIR (default ./build), OUT (CSV path, default docs/data/bench_internal_forces.csv)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build}"
out="${OUT:-$root/docs/data/bench_internal_forces.csv}"
log="${out%.csv}.txt"
mkdir -p "$(dirname "$out")"

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --target bench_internal_forces -j "$(nproc 2>/dev/null || echo 2)"

{
  echo "# $(date -u +%Y-%m-%dT%H:%M:%SZ) $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')"
  echo "# cpu: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores"
  echo "# load before: $(cut -d' ' -f1-3 /proc/loadavg)"
  echo "# command: bench_internal_forces --csv ${out#"$root"/} $*"
} >"$log"
"$build/benchmarks/bench_internal_forces" --csv "$out" "$@" | tee -a "$log"
echo "# load after: $(cut -d' ' -f1-3 /proc/loadavg)" >>"$log"
echo "table: $log"
