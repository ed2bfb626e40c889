#!/usr/bin/env bash
# Memory of fdem at start-up and in the step loop on 1, 2 and 4 ranks (peak RSS per rank, from
# summary.json "memory"), for both start-up paths on N > 1 ranks:
#   distributed  parallel.distributed_start: true  (each rank generates only its chunks)
#   whole        parallel.distributed_start: false (every rank builds the whole model first)
# Scenes (templates in benchmarks/scaling/, filled by make_scene.py):
#   block  elastic box, no contact: BLOCK_CELLS cells of 6 tets (default 80,80,40 = 1,536,000)
#   wall   dry running-bond wall on a footing under gravity (contact): WALL_UNITS units per course,
#          WALL_COURSES courses, WALL_UNIT_CELLS cells per unit (default 50, 62, 4,2,2 = 298,206)
#   tiny   TINY_CELLS block (default 3,3,2 = 108 tets) on each rank count: the fixed overhead per
#          rank F (MPI, VTK, HDF5, the binary), which grows a little with the rank count
# Each run takes STEPS steps (default 5); frames: first and last only (output.every 0).
# Writes OUT/memory-scaling.{csv,txt} (OUT default docs/data), the runs under RUNS (default
# out/memory), prints the table and the issue's criterion at the largest rank count
# (max per-rank peak <= FACTOR x 1-rank peak + F; FACTOR default 0.35).
#
# Environment: RANKS (default "1 2 4"), STEPS, BLOCK_CELLS, WALL_UNITS, WALL_COURSES,
#   WALL_UNIT_CELLS, TINY_CELLS, SCENES (default "block wall"), FACTOR, OUT, RUNS, BUILD_DIR,
#   FDEM (binary), MPIEXEC (launcher; "-n N" appended, or {n} where N goes), NICE (default 5).
# ~4 minutes on a shared 2-core machine with the defaults. Exit status: 3 if a scene's state_hash
# differs between runs, 4 if the criterion fails on the distributed path, 0 otherwise.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
here="$root/benchmarks/scaling"
ranks_list="${RANKS:-1 2 4}"
steps="${STEPS:-5}"
scenes="${SCENES:-block wall}"
out="${OUT:-$root/docs/data}"
runs="${RUNS:-$root/out/memory}"
launcher="${MPIEXEC:-}"
fdem="${FDEM:-}"
[[ "${1:-}" == -h || "${1:-}" == --help ]] && { sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 0; }

# shellcheck source=lib-bench.sh
source "$root/scripts/lib-bench.sh"
ensure_fdem
mkdir -p "$out" "$runs/scenes"
runs="$(cd "$runs" && pwd)"
manifest="$runs/manifest.tsv"
: >"$manifest"
log="$runs/runs.log"
{
  echo "# $(date -u +%Y-%m-%dT%H:%M:%SZ) fdem $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')"
  echo "# host $(hostname), cpu: $(lscpu 2>/dev/null | sed -n 's/^Model name: *//p'), $cores cores, $(free -g | awk '/^Mem:/ {print $2}') GiB"
  echo "# uptime: $(uptime)"
} | tee "$log"

scene_args() {  # scene_args SCENE -> make_scene.py arguments of its full size
  case "$1" in
    block) echo "--kind block --cells ${BLOCK_CELLS:-80,80,40}" ;;
    wall) echo "--kind wall --units ${WALL_UNITS:-50} --courses ${WALL_COURSES:-62} --unit-cells ${WALL_UNIT_CELLS:-4,2,2}" ;;
    tiny) echo "--kind block --cells ${TINY_CELLS:-3,3,2}" ;;
  esac
}
small_args() {  # the same cells and units in a small scene: the same automatic time step
  case "$1" in
    wall) echo "--kind wall --units 4 --courses 4 --unit-cells ${WALL_UNIT_CELLS:-4,2,2}" ;;
    *) echo "--kind block --cells 4,4,2" ;;
  esac
}

run() {  # run SCENE RANKS PATH
  local scene="$1" n="$2" path="$3" file="$runs/scenes/$1.yaml" dir="$runs/$1-n$2-$3" cmd
  # shellcheck disable=SC2207
  cmd=(nice -n "${NICE:-5}" $(launch "$n") "$fdem" run "$file" -o "$dir" -q)
  [[ "$path" == whole ]] && cmd+=(--set parallel.distributed_start=false)
  local load; load="$(cut -d' ' -f1-3 /proc/loadavg)"
  echo "$scene $n rank(s) $path, load $load: ${cmd[*]}" | tee -a "$log"
  rm -rf "$dir"
  TIMEFORMAT='%R %U %S'
  { time "${cmd[@]}" 2>&3 3>&-; } 3>&2 2>"$dir.time" || { echo "bench-memory.sh: run failed" >&2; exit 1; }
  echo "  elapsed, user, system seconds: $(cat "$dir.time")" >>"$log"
  printf '%s\t%s\t%s\t%s\t%s\n' "$scene" "$n" "$path" "$dir" "$load" >>"$manifest"
}

for scene in tiny $scenes; do
  # time.end for exactly `steps` steps of the automatic step (fdem check of a small scene with
  # the same cells: building the full scene serially just for its step would cost its memory).
  # shellcheck disable=SC2046
  python3 "$here/make_scene.py" $(small_args "$scene") -o "$runs/scenes/$scene-small.yaml" >/dev/null
  dt="$("$fdem" check "$runs/scenes/$scene-small.yaml" | sed -n 's/.*step \([0-9.eE+-]*\) s (auto.*/\1/p')"
  end="$(python3 -c "print(repr(($steps - 0.5) * $dt))")"
  # shellcheck disable=SC2046
  python3 "$here/make_scene.py" $(scene_args "$scene") --end "$end" -o "$runs/scenes/$scene.yaml" >/dev/null
  if [[ "$scene" == tiny ]]; then  # the fixed overhead of a rank, at each rank count
    for n in $ranks_list; do if ((n == 1)); then run tiny 1 serial; else run tiny "$n" distributed; fi; done
    continue
  fi
  for n in $ranks_list; do
    if ((n == 1)); then run "$scene" 1 serial; else run "$scene" "$n" distributed; run "$scene" "$n" whole; fi
  done
done
echo "# uptime at the end: $(uptime)" | tee -a "$log"

set +e
{
  grep '^#' "$log" | sed 's/^# //'
  python3 "$here/collect_memory.py" "$manifest" "$out/memory-scaling.csv" "${FACTOR:-0.35}"
} | tee "$out/memory-scaling.txt"
status=${PIPESTATUS[0]}
exit "$status"
