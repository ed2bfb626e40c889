#!/usr/bin/env bash
# Parallel scaling benchmark of fdem: strong scaling (one fixed scene on 1..N ranks) and weak
# scaling (the scene grown with the rank count, fixed elements per rank), for two scenes:
#   block  one elastic block (internal forces, integration, halo exchange; no contact)
#   wall   a dry-stone running-bond wall settling under gravity (contact-dominated)
# Writes OUT/scaling.csv (one row per run), OUT/runs.log (machine, load, command and CPU time of
# every run), the scenes and run directories, OUT/scaling.png (with gnuplot), and prints a table.
# For strong scaling it checks that the final state_hash is the same on every rank count (fdem is
# bit-identical on any rank count) and exits with status 3 if not.
#
# Usage: scripts/bench-scaling.sh [--ranks "1 2"] [--mode weak|strong|both] [--scenes "block wall"]
#          [--size S | --size block=S,wall=S] [--steps K | --steps block=K,wall=K]
#          [--mpiexec "mpiexec ..."] [--out DIR] [--fdem PATH] [--set key.path=value ...]
#   --ranks    rank counts to run, in any order (default "1 2"); the smallest is the reference
#              of the efficiency
#   --size     target tetrahedra: of the whole scene (strong), per rank (weak)
#              (default block=160000, wall=6000)
#   --steps    time steps per run (default block=1500, wall=1000)
#   --mpiexec  launcher; "-n N" is appended, or write {n} where the rank count goes
#              (e.g. --mpiexec "srun --ntasks={n} --cpu-bind=cores"). Default: mpiexec, with
#              --oversubscribe when N exceeds the cores of this machine. Every run goes through the
#              launcher, 1 rank included.
#   --set      passed to every fdem run (e.g. --set parallel.rebalance_threshold=1.05)
# Environment: BUILD_DIR (default ./build): the fdem binary is BUILD_DIR/drivers/fdem. With the
# default build dir a missing binary is built by scripts/build.sh; an existing one is brought up
# to date (target fdem only).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
here="$root/benchmarks/scaling"

ranks_list="1 2"
mode="both"
scenes="block wall"
size_spec=""
steps_spec=""
launcher=""
out="$root/out/scaling"
fdem=""
extra=()
usage() { sed -n '2,26p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
while [[ $# -gt 0 ]]; do
  case "$1" in
    --ranks) ranks_list="$2"; shift 2 ;;
    --mode) mode="$2"; shift 2 ;;
    --scenes) scenes="$2"; shift 2 ;;
    --size) size_spec="$2"; shift 2 ;;
    --steps) steps_spec="$2"; shift 2 ;;
    --mpiexec) launcher="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --fdem) fdem="$2"; shift 2 ;;
    --set) extra+=(--set "$2"); shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "bench-scaling.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
done
case "$mode" in
  weak) modes="weak" ;; strong) modes="strong" ;; both) modes="strong weak" ;;
  *) echo "bench-scaling.sh: --mode must be weak, strong or both" >&2; exit 2 ;;
esac
for s in $scenes; do
  [[ "$s" == block || "$s" == wall ]] || { echo "bench-scaling.sh: unknown scene '$s'" >&2; exit 2; }
done
ranks_sorted="$(tr ' ' '\n' <<<"$ranks_list" | grep -v '^$' | sort -n | uniq | tr '\n' ' ')"
for n in $ranks_sorted; do
  [[ "$n" =~ ^[1-9][0-9]*$ ]] || { echo "bench-scaling.sh: bad rank count '$n'" >&2; exit 2; }
done

# Per-scene value of a "--size"/"--steps" spec: "X" for all scenes or "block=X,wall=Y".
pick() {  # pick SPEC SCENE DEFAULT
  local spec="$1" scene="$2" value="$3" item
  if [[ -n "$spec" ]]; then
    if [[ "$spec" != *=* ]]; then
      value="$spec"
    else
      IFS=',' read -ra items <<<"$spec"
      for item in "${items[@]}"; do [[ "${item%%=*}" == "$scene" ]] && value="${item#*=}"; done
    fi
  fi
  echo "$value"
}


# shellcheck source=lib-bench.sh
source "$root/scripts/lib-bench.sh"
ensure_fdem

mkdir -p "$out/scenes" "$out/runs"
out="$(cd "$out" && pwd)"
log="$out/runs.log"
manifest="$out/manifest.tsv"
: >"$manifest"
{
  echo "# $(date -u +%Y-%m-%dT%H:%M:%SZ) fdem $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')"
  echo "# host $(hostname), cpu: $(lscpu 2>/dev/null | sed -n 's/^Model name: *//p'), $cores cores"
  echo "# ranks: $ranks_sorted; modes: $modes; scenes: $scenes; fdem: $fdem"
} >"$log"
cat "$log"

declare -A done_runs  # scene file checksum + ranks -> run dir (weak on 1 rank = strong on 1 rank)
for m in $modes; do
  for scene in $scenes; do
    case "$scene" in block) dsize=160000; dsteps=1500 ;; wall) dsize=6000; dsteps=1000 ;; esac
    size="$(pick "$size_spec" "$scene" "$dsize")"
    steps="$(pick "$steps_spec" "$scene" "$dsteps")"
    for n in $ranks_sorted; do
      file="$out/scenes/$m-$scene-n$n.yaml"
      python3 "$here/make_scene.py" --kind "$scene" --mode "$m" --ranks "$n" --size "$size" \
        -o "$file" >/dev/null
      # time.end for exactly `steps` steps of the automatic time step (as fdem check computes it).
      dt="$("$fdem" check "$file" "${extra[@]}" | sed -n 's/.*step \([0-9.eE+-]*\) s (auto.*/\1/p')"
      [[ -n "$dt" ]] || { echo "bench-scaling.sh: fdem check $file gave no time step" >&2; exit 2; }
      end="$(python3 -c "print(repr(($steps - 0.5) * $dt))")"
      python3 "$here/make_scene.py" --kind "$scene" --mode "$m" --ranks "$n" --size "$size" \
        --end "$end" -o "$file" >/dev/null
      key="$(grep -v '^#' "$file" | cksum | cut -d' ' -f1)-n$n"  # the scene without its comments
      if [[ -n "${done_runs[$key]:-}" ]]; then
        run="${done_runs[$key]}"
        echo "$m $scene $n ranks: same scene and rank count as $(basename "$run"), reused"
      else
        run="$out/runs/$m-$scene-n$n"
        rm -rf "$run"
        # shellcheck disable=SC2207
        cmd=($(launch "$n") "$fdem" run "$file" -o "$run" -q "${extra[@]}")
        echo "$m $scene $n ranks: ${cmd[*]}" | tee -a "$log"
        echo "  load before: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo '?')" >>"$log"
        # Elapsed and CPU seconds (user, system) of the launcher and the processes it waited for:
        # with a local mpiexec that is every rank, so CPU/elapsed = cores the run really got.
        TIMEFORMAT='%R %U %S'
        { time "${cmd[@]}" 2>&3 3>&-; } 3>&2 2>"$run.time" ||
          { echo "bench-scaling.sh: run failed: ${cmd[*]}" >&2; exit 1; }
        read -r elapsed user sys <"$run.time"
        echo "  elapsed $elapsed s, cpu $user s user + $sys s system" >>"$log"
        echo "  load after: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo '?')" >>"$log"
        done_runs[$key]="$run"
      fi
      printf '%s\t%s\t%s\t%s\n' "$m" "$scene" "$n" "$run" >>"$manifest"
    done
  done
done

set +e
python3 "$here/collect.py" "$manifest" "$out/scaling.csv" | tee "$out/scaling.txt"
status=${PIPESTATUS[0]}
set -e
if command -v gnuplot >/dev/null; then
  gnuplot -e "csv='$out/scaling.csv'; png='$out/scaling.png'" "$here/plot.gp" && echo "plot: $out/scaling.png"
fi
exit "$status"
