#!/usr/bin/env bash
# Measures the inputs of the cost model (scripts/cost-model.py) on this machine, into OUT
# (default out/cost-model):
#   mpi_latency.csv   MPI_Allreduce and ping-pong latency/bandwidth on 2 ranks (bench_mpi_latency)
#   block-n1, wall-n1 one-rank runs: seconds per tet-step of each stage (summary.json "stages")
#   block-n4, wall-n4 four-rank runs under the PMPI interposer (tests/mpi/comm_budget, target
#                     fdem_comm_budget): halo sizes (summary.json "decomposition"), bytes received
#                     and blocking collectives per step and per redistribution (budget/rank<R>.json)
# Sizes (environment): BLOCK_CELLS (default 40,40,40 = 384,000 tets), BLOCK_STEPS (20),
# WALL_UNITS, WALL_COURSES, WALL_UNIT_CELLS (default 24, 12, 4,2,2 = 27,792 tets), WALL_STEPS
# (300), WALL_REDISTRIBUTE_EVERY (20: the 4-rank wall redistributes this often, as an impact's
# detections would; 0: only when the settling wall detects). BUILD_DIR, MPIEXEC,
# NICE as in bench-memory.sh. Under a minute on a shared 2-core machine.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
here="$root/benchmarks/scaling"
out="${OUT:-$root/out/cost-model}"
launcher="${MPIEXEC:-}"
fdem="${FDEM:-}"
# shellcheck source=lib-bench.sh
source "$root/scripts/lib-bench.sh"
ensure_fdem
build="$(dirname "$(dirname "$fdem")")"
cmake --build "$build" --target bench_mpi_latency fdem_comm_budget -j "$cores" >/dev/null
interposer="$build/tests/libfdem_comm_budget.so"
mkdir -p "$out/scenes"
out="$(cd "$out" && pwd)"
echo "# $(date -u +%Y-%m-%dT%H:%M:%SZ) fdem $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?'); uptime: $(uptime)" | tee "$out/runs.log"

# shellcheck disable=SC2046
nice -n "${NICE:-5}" $(launch 2) "$build/benchmarks/bench_mpi_latency" "$out/mpi_latency.csv" | tee -a "$out/runs.log"

scene() {  # scene NAME STEPS MAKE_SCENE_ARGS... (time.end for STEPS steps of the automatic step)
  local name="$1" steps="$2" dt end; shift 2
  python3 "$here/make_scene.py" "$@" -o "$out/scenes/$name.yaml" >/dev/null
  dt="$("$fdem" check "$out/scenes/$name.yaml" | sed -n 's/.*step \([0-9.eE+-]*\) s (auto.*/\1/p')"
  end="$(python3 -c "print(repr(($steps - 0.5) * $dt))")"
  python3 "$here/make_scene.py" "$@" --end "$end" -o "$out/scenes/$name.yaml" >/dev/null
}
run() {  # run NAME RANKS [budget [--set ...]]
  local dir="$out/$1-n$2" extra=("${@:4}")
  rm -rf "$dir" "$dir.budget"
  echo "$1 on $2 rank(s), load $(cut -d' ' -f1-3 /proc/loadavg)" | tee -a "$out/runs.log"
  if [[ "${3:-}" == budget ]]; then
    mkdir -p "$dir.budget"
    # shellcheck disable=SC2046
    nice -n "${NICE:-5}" $(launch "$2") env LD_PRELOAD="$interposer" \
      FDEM_COMM_BUDGET_OUT="$dir.budget" "$fdem" run "$out/scenes/$1.yaml" -o "$dir" -q "${extra[@]}"
  else
    # shellcheck disable=SC2046
    nice -n "${NICE:-5}" $(launch "$2") "$fdem" run "$out/scenes/$1.yaml" -o "$dir" -q
  fi
}

scene block "${BLOCK_STEPS:-20}" --kind block --cells "${BLOCK_CELLS:-40,40,40}"
scene wall "${WALL_STEPS:-300}" --kind wall --units "${WALL_UNITS:-24}" --courses "${WALL_COURSES:-12}" \
  --unit-cells "${WALL_UNIT_CELLS:-4,2,2}"
run block 1
run block 4 budget
run wall 1
# The settling wall rarely detects; an impact detects every few tens of steps, and each detection
# redistributes: force one every WALL_REDISTRIBUTE_EVERY steps (0: as the scene goes).
run wall 4 budget --set "parallel.redistribute_every=${WALL_REDISTRIBUTE_EVERY:-20}"
echo "# uptime at the end: $(uptime)" | tee -a "$out/runs.log"
echo "measured into $out; next: python3 scripts/cost-model.py $out"
