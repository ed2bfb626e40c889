#!/usr/bin/env bash
# Runs every example scene of examples/ on each rank count, one run at a time, and compares them:
# wall time, steps, elements, element-steps per second (total and per core = per rank), speed-up
# over the smallest rank count, the final state_hash (fdem is bit-identical on any rank count, so
# it must be the same on every rank count) and the decomposition numbers of the parallel runs.
# Writes OUT/examples.csv (one row per run), OUT/runs.log (machine, load before and after, command,
# elapsed and CPU time of every run) and the run directories OUT/<example>-n<N>/, and prints a
# table. Exits with status 3 if a state_hash differs between rank counts, 1 if a run failed.
#
# Usage: scripts/run-examples.sh [--ranks "1 2"] [--out DIR] [--only NAME...] [--fdem PATH]
#          [--mpiexec "mpiexec ..."] [--set key.path=value ...]
#   --ranks    rank counts (default "1 2"); the smallest is the reference of speed-up and hash
#   --out      output directory (default out/examples)
#   --only     example names (scene file names without .yaml) to run, e.g. --only tower-projectile
#              arch-acceleration; every example by default
#   --fdem     the fdem binary (default BUILD_DIR/drivers/fdem, BUILD_DIR defaults to ./build)
#   --mpiexec  launcher; "-n N" is appended, or write {n} where the rank count goes. Default:
#              mpiexec, with --oversubscribe when N exceeds the cores of this machine.
#   --set      passed to every fdem run, e.g. --set time.end=0.5 for shortened runs (the scene's
#              own settings otherwise)
# Every run goes through the launcher, 1 rank included, with -q (no progress output).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

# Every example, in order of run time (the cantilever scene was once examples/default.yaml).
all_examples="tower-projectile triaxial-jointed-prism mortared-wall-push cantilever-sag brazilian-disc arch-acceleration
dry-stone-wall-seismic"
ranks_list="1 2"
out="$root/out/examples"
only=()
fdem=""
launcher=""
extra=()
usage() { sed -n '2,21p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
while [[ $# -gt 0 ]]; do
  case "$1" in
    --ranks) ranks_list="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --fdem) fdem="$2"; shift 2 ;;
    --mpiexec) launcher="$2"; shift 2 ;;
    --set) extra+=(--set "$2"); shift 2 ;;
    --only)
      shift
      while [[ $# -gt 0 && "$1" != --* ]]; do only+=("${1%.yaml}"); shift; done ;;
    -h|--help) usage; exit 0 ;;
    *) echo "run-examples.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
done
ranks_sorted="$(tr ' ' '\n' <<<"$ranks_list" | grep -v '^$' | sort -n | uniq | tr '\n' ' ')"
for n in $ranks_sorted; do
  [[ "$n" =~ ^[1-9][0-9]*$ ]] || { echo "run-examples.sh: bad rank count '$n'" >&2; exit 2; }
done

# Scene file of an example name; the cantilever has two possible names.
scene_of() {
  local name="$1"
  if [[ -f "$root/examples/$name.yaml" ]]; then echo "$root/examples/$name.yaml"; return; fi
  case "$name" in
    cantilever-sag) [[ -f "$root/examples/default.yaml" ]] && echo "$root/examples/default.yaml" ;;
    default) [[ -f "$root/examples/cantilever-sag.yaml" ]] && echo "$root/examples/cantilever-sag.yaml" ;;
  esac
}
examples=()
if ((${#only[@]})); then
  for name in "${only[@]}"; do
    [[ -n "$(scene_of "$name")" ]] || { echo "run-examples.sh: no scene examples/$name.yaml" >&2; exit 2; }
    examples+=("$name")
  done
else
  for name in $all_examples; do [[ -n "$(scene_of "$name")" ]] && examples+=("$name"); done
fi


# shellcheck source=lib-bench.sh
source "$root/scripts/lib-bench.sh"
ensure_fdem
loadavg() { cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo '? ? ?'; }

mkdir -p "$out"
out="$(cd "$out" && pwd)"
log="$out/runs.log"
manifest="$out/manifest.tsv"
{
  echo "# $(date -u +%Y-%m-%dT%H:%M:%SZ) fdem $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')"
  echo "# host $(hostname), cpu: $(lscpu 2>/dev/null | sed -n 's/^Model name: *//p'), $cores cores"
  echo "# ranks: $ranks_sorted; examples: ${examples[*]}; fdem: $fdem ${extra[*]+${extra[*]}}"
} | tee -a "$log"
# The manifest keeps the runs of earlier invocations on the same OUT (the last run of an example on
# a rank count counts), so examples can be run in several goes.
[[ -s "$manifest" ]] ||
  printf 'example\tranks\trun\tscene\tload1\tload5\tload15\telapsed\tcpu_user\tcpu_system\texit\n' >"$manifest"

failed=0
for name in "${examples[@]}"; do
  scene="$(scene_of "$name")"
  for n in $ranks_sorted; do
    run="$out/$name-n$n"
    rm -rf "$run"
    # shellcheck disable=SC2207
    cmd=($(launch "$n") "$fdem" run "$scene" -o "$run" -q ${extra[@]+"${extra[@]}"})
    read -r l1 l5 l15 <<<"$(loadavg)"
    echo "$name on $n rank(s), load $l1 $l5 $l15: ${cmd[*]}" | tee -a "$log"
    echo "  uptime before: $(uptime)" >>"$log"
    # Elapsed and CPU seconds of the launcher and the ranks it waited for: with a local mpiexec
    # CPU/elapsed is the number of cores the run really got on a shared machine.
    TIMEFORMAT='%R %U %S'
    status=0
    { time "${cmd[@]}" 2>&3 3>&-; } 3>&2 2>"$run.time" || status=$?
    read -r elapsed user sys <"$run.time"
    rm -f "$run.time"
    echo "  exit $status, elapsed $elapsed s, cpu $user s user + $sys s system" | tee -a "$log"
    echo "  uptime after: $(uptime)" >>"$log"
    ((status == 0)) || failed=1
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$name" "$n" "$run" "$scene" \
      "$l1" "$l5" "$l15" "$elapsed" "$user" "$sys" "$status" >>"$manifest"
  done
done

set +e
python3 - "$manifest" "$out/examples.csv" <<'PY' | tee "$out/examples.txt"
# Reads the manifest and each run's summary.json, writes the CSV and prints a table; exit 3 when a
# state_hash differs from the one of the smallest rank count of the same example.
import csv, json, os, sys

manifest, csv_path = sys.argv[1], sys.argv[2]
runs = {}
with open(manifest) as f:
    for row in csv.DictReader(f, delimiter="\t"):
        runs[(row["example"], int(row["ranks"]))] = row  # the last run counts
order = []
for example, _ in runs:
    if example not in order:
        order.append(example)

decomposition_keys = ["imbalance", "max_imbalance", "redistributions", "rebalances",
                      "migrated_elements", "halo_elements_max", "ghost_nodes_max",
                      "ghost_nodes_mean", "neighbours_max", "communication_seconds"]
columns = ["example", "ranks", "status", "elements", "joints", "steps", "end_time",
           "wall_seconds", "elapsed_seconds", "cpu_seconds", "cores_used",
           "element_steps_per_second", "element_steps_per_second_per_core", "speedup",
           "efficiency", "state_hash", "hash_equal", "load1_before", "load5_before",
           "load15_before"] + decomposition_keys
rows, hash_mismatch = [], False
for example in order:
    counts = sorted(n for e, n in runs if e == example)
    reference = None
    for n in counts:
        m = runs[(example, n)]
        out = {"example": example, "ranks": n, "load1_before": m["load1"],
               "load5_before": m["load5"], "load15_before": m["load15"],
               "elapsed_seconds": m["elapsed"]}
        cpu = float(m["cpu_user"]) + float(m["cpu_system"])
        out["cpu_seconds"] = f"{cpu:.1f}"
        out["cores_used"] = f"{cpu / float(m['elapsed']):.2f}" if float(m["elapsed"]) > 0 else ""
        try:
            with open(os.path.join(m["run"], "summary.json")) as f:
                s = json.load(f)
        except (OSError, ValueError):
            s = {"status": f"no summary (exit {m['exit']})"}
        out["status"] = s.get("status", "?")
        for k in ["elements", "joints", "steps", "end_time", "wall_seconds", "state_hash"]:
            out[k] = s.get(k, "")
        rate = s.get("throughput", {}).get("element_steps_per_second", 0.0)
        out["element_steps_per_second"] = f"{rate:.0f}"
        out["element_steps_per_second_per_core"] = f"{rate / n:.0f}"
        for k in decomposition_keys:
            out[k] = s.get("decomposition", {}).get(k, "")
        if reference is None:
            reference = out
        ok = out["state_hash"] != "" and out["state_hash"] == reference["state_hash"]
        out["hash_equal"] = "yes" if ok else "NO"
        hash_mismatch |= not ok
        w0, w = reference.get("wall_seconds") or 0, out.get("wall_seconds") or 0
        out["speedup"] = f"{w0 / w:.2f}" if w else ""
        out["efficiency"] = f"{w0 / w / (n / reference['ranks']):.2f}" if w else ""
        rows.append(out)

with open(csv_path, "w", newline="") as f:
    writer = csv.DictWriter(f, fieldnames=columns)
    writer.writeheader()
    for r in rows:
        writer.writerow({k: r.get(k, "") for k in columns})

def fmt(v, spec):
    try:
        return format(float(v), spec)
    except (TypeError, ValueError):
        return str(v)
header = ("example", "ranks", "elements", "steps", "wall s", "el-steps/s", "per core",
          "speed-up", "hash", "load", "imbalance", "halo max", "migrated", "comm s")
table = [header]
for r in rows:
    table.append((r["example"], str(r["ranks"]), str(r["elements"]), str(r["steps"]),
                  fmt(r["wall_seconds"], ".1f"), fmt(r["element_steps_per_second"], ".3g"),
                  fmt(r["element_steps_per_second_per_core"], ".3g"), r["speedup"],
                  r["hash_equal"], r["load1_before"], fmt(r["imbalance"], ".3f"),
                  str(r["halo_elements_max"]), str(r["migrated_elements"]),
                  fmt(r["communication_seconds"], ".1f")))
widths = [max(len(t[i]) for t in table) for i in range(len(header))]
for t in table:
    print("  ".join(c.ljust(w) for c, w in zip(t, widths)).rstrip())
print(f"csv: {csv_path}")
if hash_mismatch:
    print("state_hash DIFFERS between rank counts (or a run has none)", file=sys.stderr)
    sys.exit(3)
PY
status=${PIPESTATUS[0]}
set -e
((status != 0)) && exit "$status"
exit "$failed"
