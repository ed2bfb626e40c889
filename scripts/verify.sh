#!/usr/bin/env bash
# Verification suite: builds bench_verification (Release, in ./build), runs every reference problem
# of the design notes at several mesh sizes, time-step fractions and penalty ratios, and writes
#   docs/data/verification.csv   one row per (run, quantity): wall time, value, reference, error,
#                                tolerance, pass
#   docs/data/verification.txt   the printed table, with the machine and its load
#   docs/verification/*.png      error against wall time per problem (log-log, gnuplot)
# Usage: scripts/verify.sh [--quick] [--only NAME[,NAME...]] | --plot-only
#   --quick      one cheap setting per problem (coarsest mesh); the CI test
#                tests/verification/test_verification_suite.cpp covers the problems no other test does
#   --plot-only  only redraw the PNGs from the existing CSV
# Environment: BUILD_DIR (default ./build), OUT (CSV path, default docs/data/verification.csv)
# Exit status: 0 when every run completed, 1 when a run failed (see the table).  Rows outside
# their tolerance are reported in the table and the CSV (pass = no); they do not change the status.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build}"
out="${OUT:-$root/docs/data/verification.csv}"
log="${out%.csv}.txt"
plots="$root/docs/verification"
mkdir -p "$(dirname "$out")" "$plots"

status=0
if [ "${1:-}" != "--plot-only" ]; then
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --target bench_verification -j "$(nproc 2>/dev/null || echo 2)"

{
  echo "# $(date -u +%Y-%m-%dT%H:%M:%SZ) $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')"
  echo "# cpu: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores"
  echo "# load before: $(cut -d' ' -f1-3 /proc/loadavg)"
  echo "# command: bench_verification --csv ${out#"$root"/} $*"
} >"$log"
set +e
"$build/benchmarks/bench_verification" --csv "$out" "$@" | tee -a "$log"
status=${PIPESTATUS[0]}
set -e
echo "# load after: $(cut -d' ' -f1-3 /proc/loadavg)" >>"$log"
fi

if ! command -v gnuplot >/dev/null 2>&1; then
  echo "gnuplot not found: installing gnuplot-nox"
  if [ "$(id -u)" = 0 ]; then apt-get install -y gnuplot-nox >/dev/null; else sudo apt-get install -y gnuplot-nox >/dev/null; fi
fi
# One PNG per problem: every (quantity, swept parameter) series, error against wall time.  Each
# series (its rows plus the base run, sorted by wall time) goes to a small data file.
series="$(mktemp -d)"
trap 'rm -rf "$series"' EXIT
for problem in $(tail -n +2 "$out" | cut -d, -f1 | sort -u); do
  rm -f "$series"/*
  awk -F, -v p="$problem" -v dir="$series" 'NR > 1 && $1 == p {
      print $6, $9, $10 > (dir "/" $2 "." $12 ".dat") }' "$out"
  quantities=$(awk -F, -v p="$problem" 'NR > 1 && $1 == p { print $2 }' "$out" | awk '!seen[$0]++' | tr '\n' ' ')
  sweeps=$(awk -F, -v p="$problem" 'NR > 1 && $1 == p && $12 != "base" { print $12 }' "$out" | awk '!seen[$0]++' | tr '\n' ' ')
  for q in $quantities; do
    for s in ${sweeps:-base}; do
      cat "$series/$q.$s.dat" "$series/$q.base.dat" 2>/dev/null | sort -g -u > "$series/$q.$s.series"
    done
  done
  gnuplot -e "dir='$series'; problem='$problem'; quantities='$quantities'; sweeps='${sweeps:-base}'; png='$plots/$problem.png'" \
    "$root/scripts/plot-verification.gp"
done
echo "table: $log"
echo "plots: $plots/"
exit "$status"
