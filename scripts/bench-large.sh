#!/usr/bin/env bash
# A 10^7-tet elastic block (distributed start-up) on 4 ranks and on 2 ranks, a few steps each:
# start-up seconds, peak RSS per rank at start-up and in the step loop, state_hash (must be the
# same on both rank counts). Before running, estimates the memory of each run from the 1.5 M-tet
# block of docs/data/memory-scaling.csv (same rank count, distributed path, scaled by the tet
# count above the fixed overhead) and skips a run whose estimate exceeds MemAvailable.
# Writes OUT (default docs/data/large-block.txt) and the runs under RUNS (default out/large).
# Environment: CELLS (default 200,200,42 = 10,080,000 tets), STEPS (4), RANKS (default "4 2"),
#   OUT, RUNS, BUILD_DIR, FDEM, MPIEXEC, NICE (5). Several minutes on a shared 2-core machine.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
here="$root/benchmarks/scaling"
cells="${CELLS:-200,200,42}"
steps="${STEPS:-4}"
out="${OUT:-$root/docs/data/large-block.txt}"
runs="${RUNS:-$root/out/large}"
launcher="${MPIEXEC:-}"
fdem="${FDEM:-}"
# shellcheck source=lib-bench.sh
source "$root/scripts/lib-bench.sh"
ensure_fdem
mkdir -p "$runs"
runs="$(cd "$runs" && pwd)"

python3 "$here/make_scene.py" --kind block --cells 4,4,2 -o "$runs/small.yaml" >/dev/null
dt="$("$fdem" check "$runs/small.yaml" | sed -n 's/.*step \([0-9.eE+-]*\) s (auto.*/\1/p')"
end="$(python3 -c "print(repr(($steps - 0.5) * $dt))")"
tets="$(python3 "$here/make_scene.py" --kind block --cells "$cells" --end "$end" -o "$runs/block.yaml" |
  python3 -c 'import json, sys; print(json.load(sys.stdin)["tets"])')"

estimate() {  # estimate RANKS -> "startup_mib run_mib" per rank, or "? ?" without reference data
  python3 - "$root/docs/data/memory-scaling.csv" "$1" "$tets" <<'EOF'
import csv, sys
path, ranks, tets = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
try:
    rows = list(csv.DictReader(open(path)))
except OSError:
    print("? ?"); sys.exit()
tiny = next(r for r in rows if r["scene"] == "tiny")
ref = [r for r in rows if r["scene"] == "block" and int(r["ranks"]) == ranks
       and r["path"] in ("distributed", "serial")]
if not ref:
    print("? ?"); sys.exit()
r, k = ref[0], tets / int(ref[0]["elements"])
f = lambda key: float(tiny[key]) + (float(r[key]) - float(tiny[key])) * k
print(f"{f('startup_peak_rss_mib_max'):.0f} {f('run_peak_rss_mib_max'):.0f}")
EOF
}

{
  echo "# bench-large.sh: $tets tets (cells $cells), $steps steps, distributed start-up on N > 1 ranks"
  echo "# $(date -u +%Y-%m-%dT%H:%M:%SZ) fdem $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')"
  echo "# host $(hostname), $cores cores, MemAvailable $(awk '/MemAvailable/ {print int($2/1024)}' /proc/meminfo) MiB"
  echo "# uptime: $(uptime)"
} | tee "$out"
hashes=()
for n in ${RANKS:-4 2}; do
  read -r est_start est_run < <(estimate "$n")
  avail="$(awk '/MemAvailable/ {print int($2/1024)}' /proc/meminfo)"
  echo "$n ranks: estimated peak per rank (from the 1.5 M block) start-up $est_start MiB, step loop" \
    "$est_run MiB; x $n = $([[ $est_start == '?' ]] && echo '?' || echo $((est_start * n))) MiB of $avail MiB available" | tee -a "$out"
  if [[ "$est_start" != '?' ]] && ((est_start * n > avail * 9 / 10)); then
    echo "$n ranks: SKIPPED, the estimate does not fit in memory" | tee -a "$out"
    continue
  fi
  dir="$runs/n$n"
  rm -rf "$dir"
  # shellcheck disable=SC2207
  cmd=(nice -n "${NICE:-5}" $(launch "$n") "$fdem" run "$runs/block.yaml" -o "$dir" -q)
  echo "$n ranks, load $(cut -d' ' -f1-3 /proc/loadavg): ${cmd[*]}" | tee -a "$out"
  TIMEFORMAT='%R'
  { time "${cmd[@]}" 2>&3 3>&-; } 3>&2 2>"$dir.time"
  python3 - "$dir" "$(cat "$dir.time")" <<'EOF' | tee -a "$out"
import json, sys
s = json.load(open(sys.argv[1] + "/summary.json"))
m, el = s["memory"], float(sys.argv[2])
out = s["stages"].get("output", {}).get("seconds", 0)
print(f"  {s['ranks']} ranks: {s['elements']} tets, {s['nodes']} nodes, {s['steps']} steps, "
      f"elapsed {el:.1f} s, start-up {el - s['wall_seconds']:.1f} s (elapsed less the run's "
      f"wall_seconds), step loop {s['wall_seconds']:.1f} s of which output (first and last frame) "
      f"{out:.1f} s")
print(f"  peak RSS per rank: start-up max {m['startup_peak_rss_kib_max'] / 1024:.0f} MiB, mean "
      f"{m['startup_peak_rss_kib_mean'] / 1024:.0f} MiB; step loop max "
      f"{m['run_peak_rss_kib_max'] / 1024:.0f} MiB, mean {m['run_peak_rss_kib_mean'] / 1024:.0f} MiB")
print(f"  state_hash {s['state_hash']}")
EOF
  hashes+=("$(python3 -c "import json; print(json.load(open('$dir/summary.json'))['state_hash'])")")
done
echo "# uptime at the end: $(uptime)" | tee -a "$out"
if ((${#hashes[@]} > 1)); then
  if [[ "$(printf '%s\n' "${hashes[@]}" | sort -u | wc -l)" == 1 ]]; then
    echo "state_hash identical on all rank counts: ${hashes[0]}" | tee -a "$out"
  else
    echo "state_hash DIFFERS between rank counts: ${hashes[*]}" | tee -a "$out"
    exit 3
  fi
fi
