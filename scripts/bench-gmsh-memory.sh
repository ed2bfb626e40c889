#!/usr/bin/env bash
# Memory of starting a Gmsh model of ~10^6 tets on 1, 2 and 4 ranks, old path against new:
#   whole     N ranks, --set parallel.distributed_start=false: every rank reads the .msh and
#             builds the whole model (the only path for Gmsh meshes before model files)
#   msh       N ranks from the .msh: rank 0 prepares it into the output directory, then every rank
#             reads its slice of the model file (distributed start)
#   h5        N ranks from a model file made beforehand with `fdem prepare`
#   serial    1 rank from the .msh (read whole) and from the model file
# Per run: peak RSS of every rank from /usr/bin/time -f %M (the whole process: start-up, STEPS
# steps of a fixed body, first and last frame as xdmf) and summary.json's start-up peak (VmHWM at
# the end of start-up); state_hash must agree.  Also `fdem prepare` alone on this mesh and on one
# four times larger (its peak should not grow).
# The mesh: scripts/make-gmsh-mesh.py, two boxes of CELLS cells (default 50,50,34: 2 × 510,000
# tets), one body of two pieces (fixed, so that no contact stage runs).
# Environment: RANKS (default "1 2 4"), CELLS, STEPS (default 4), OUT (default out/gmsh-memory),
#   DOC (table, default docs/data/gmsh-memory.txt), FDEM, MPIEXEC (default mpiexec), NICE (5).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ranks_list="${RANKS:-1 2 4}"
cells="${CELLS:-50,50,34}"
steps="${STEPS:-4}"
out="${OUT:-$root/out/gmsh-memory}"
doc="${DOC:-$root/docs/data/gmsh-memory.txt}"
fdem="${FDEM:-$root/build/drivers/fdem}"
mpiexec="${MPIEXEC:-mpiexec}"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mkdir -p "$out" "$(dirname "$doc")"
out="$(cd "$out" && pwd)"
log="$out/runs.log"
IFS=, read -r nx ny nz <<<"$cells"
box() {  # box Z0 -> the --box argument of a 1 x 1 x (nz/50) m box of the cells starting at z0
  python3 -c "z0=$1; h=$nz/50; print(f'0,0,{z0},1.0,1.0,{z0+h},$nx,$ny,$nz')"
}
gap_z="$(python3 -c "print($nz/50 + 0.02)")"
mesh="$out/blocks.msh"
python3 "$root/scripts/make-gmsh-mesh.py" "$mesh" --box "$(box 0)" --box "$(box "$gap_z")"
cat >"$out/scene.yaml" <<EOF
name: gmsh-memory
time: {end: $(python3 -c "print(($steps - 0.5) * 1e-6)"), step: 1.0e-6}
gravity: [0, 0, -9.81]
materials:
  rubber: {density: 1100, elastic: {model: neo-hookean, young: 5.0e6, poisson: 0.3}}
bodies:
  - {name: pair, mesh: {file: blocks.msh, physical: all}, material: rubber, fixed: true}
output: {every: 0, format: xdmf}
EOF
{
  echo "# $(date -u +%Y-%m-%dT%H:%M:%SZ) fdem $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')"
  echo "# host $(hostname), cpu: $(lscpu 2>/dev/null | sed -n 's/^Model name: *//p'), $(nproc) cores, $(free -g | awk '/^Mem:/ {print $2}') GiB"
  echo "# mesh: $(basename "$mesh") ($(du -h "$mesh" | cut -f1)), 2 boxes of $cells cells"
  echo "# uptime: $(uptime)"
} | tee "$log"

prepare() {  # prepare MSH H5 LABEL
  local load; load="$(cut -d' ' -f1-3 /proc/loadavg)"
  /usr/bin/time -f "%M %e" -o "$out/prepare.time" nice -n "${NICE:-5}" "$fdem" prepare "$1" -o "$2" >/dev/null
  read -r kib seconds <"$out/prepare.time"
  echo "prepare $3: peak $((kib / 1024)) MiB, $seconds s, load $load" | tee -a "$log"
}
prepare "$mesh" "$out/blocks.h5" "$(basename "$mesh") ($(du -h "$mesh" | cut -f1))"

run() {  # run RANKS PATH
  local n="$1" path="$2" dir="$out/run-n$1-$2" load
  local args=(run "$out/scene.yaml" -o "$dir" -q)
  case "$path" in
    whole) args+=(--set parallel.distributed_start=false) ;;
    h5 | serial-h5) args+=(--set "bodies.0.mesh.file=$out/blocks.h5") ;;
  esac
  rm -rf "$dir"
  mkdir -p "$dir"
  load="$(cut -d' ' -f1-3 /proc/loadavg)"
  local start; start="$(date +%s.%N)"
  nice -n "${NICE:-5}" "$mpiexec" -n "$n" --oversubscribe sh -c \
    '/usr/bin/time -f %M -o "$0/rss.$OMPI_COMM_WORLD_RANK" "$@"' "$dir" "$fdem" "${args[@]}"
  local seconds; seconds="$(python3 -c "import time; print(round(time.time() - $start, 1))")"
  python3 - "$dir" "$n" "$path" "$load" "$seconds" <<'PY' | tee -a "$log"
import glob, json, re, sys
d, n, path, load, seconds = sys.argv[1:]
rss = [int(open(f).read().split()[-1]) / 1024 for f in sorted(glob.glob(d + "/rss.*"))]
s = json.load(open(d + "/summary.json"))
m = s["memory"]
print(f"{n}\t{path}\t{max(rss):.0f}\t{sum(rss)/len(rss):.0f}\t"
      f"{m['startup_peak_rss_kib_max']/1024:.0f}\t{m['startup_peak_rss_kib_mean']/1024:.0f}\t"
      f"{seconds}\t{s['state_hash']}\t{load}")
PY
}
echo -e "ranks\tpath\ttime %M max MiB\tmean\tstart-up peak max MiB\tmean\tseconds\tstate_hash\tload" | tee -a "$log"
for n in $ranks_list; do
  if ((n == 1)); then
    run 1 serial
    run 1 serial-h5
  else
    run "$n" whole
    run "$n" msh
    run "$n" h5
  fi
done
# Prepare of a mesh four times larger (twice the cells along x and y): the same peak.
IFS=, read -r nx ny nz <<<"$cells"
nx=$((2 * nx)) ny=$((2 * ny))
python3 "$root/scripts/make-gmsh-mesh.py" "$out/blocks4.msh" --box "$(box 0)" --box "$(box "$gap_z")"
prepare "$out/blocks4.msh" "$out/blocks4.h5" "$(basename "$out/blocks4.msh") ($(du -h "$out/blocks4.msh" | cut -f1), 4x the tets)"
rm -f "$out/blocks4.msh" "$out/blocks4.h5"
echo "# uptime at the end: $(uptime)" | tee -a "$log"
cp "$log" "$doc"
hashes="$(awk -F'\t' 'NF == 9 && $8 != "state_hash" {print $8}' "$log" | sort -u | wc -l)"
if ((hashes != 1)); then
  echo "bench-gmsh-memory.sh: state_hash differs between runs" >&2
  exit 3
fi
