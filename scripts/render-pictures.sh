#!/usr/bin/env bash
# Renders one characteristic frame of each example run to docs/pictures/<example>.png (1200x800)
# with ParaView's pvbatch and scripts/render_frame.py:
#   tower-projectile        the moment the struck block has left the pier (speed)
#   mortared-wall-push      the last frame, broken mortar joints (cracks.pvd, by failure mode) over
#                           displacement
#   cantilever-sag          the lowest point of the first swing (von Mises stress)
#   brazilian-disc          the last frame, the split plane (cracks.pvd) over damage
#   arch-acceleration       collapse onset: a voussoir first faster than 0.5 m/s after 0.3 s (speed)
#   dry-stone-wall-seismic  the peak of the table's acceleration record (contact normal forces)
# The frame of each is found from the run's own bodies.csv (or the input record), so a changed
# scene still gets its characteristic moment.
#
# Usage: scripts/render-pictures.sh [--out DIR] [RUNDIR...]
#   RUNDIR   output directories of fdem runs; the example is read from their summary.json
#            ("scene"). Default: for every example, out/examples/<example>-n2 (the parallel
#            .pvtu output) or else out/examples/<example>-n1, as scripts/run-examples.sh writes.
#   --out    picture directory (default docs/pictures)
# Environment: PVBATCH (default: pvbatch on PATH, see scripts/install-paraview.sh). Without a
# display it starts its own Xvfb (package xvfb); --force-offscreen-rendering either way.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
pictures="$root/docs/pictures"
dirs=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) pictures="$2"; shift 2 ;;
    -h|--help) sed -n '2,20p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "render-pictures.sh: unknown option '$1'" >&2; exit 2 ;;
    *) dirs+=("$1"); shift ;;
  esac
done
if ((${#dirs[@]} == 0)); then
  for name in tower-projectile mortared-wall-push cantilever-sag brazilian-disc arch-acceleration \
              dry-stone-wall-seismic; do
    for d in "$root/out/examples/$name-n2" "$root/out/examples/$name-n1"; do
      if [[ -f "$d/frames.pvd" ]]; then dirs+=("$d"); break; fi
    done
  done
  ((${#dirs[@]})) || { echo "render-pictures.sh: no runs in out/examples (run scripts/run-examples.sh)" >&2; exit 2; }
fi

pvbatch="${PVBATCH:-$(command -v pvbatch || true)}"
if [[ -z "$pvbatch" ]]; then
  echo "render-pictures.sh: no pvbatch; install it with scripts/install-paraview.sh" >&2
  exit 2
fi
launcher=("$pvbatch")
# The Debian pvbatch renders through X. Without a display, one virtual X server (Xvfb) serves
# every picture of this call, on the first free display number from :140, and is stopped at the end.
xvfb_pid=""
stop_xvfb() { [[ -n "$xvfb_pid" ]] && kill "$xvfb_pid" 2>/dev/null; wait "$xvfb_pid" 2>/dev/null || true; }
if [[ -z "${DISPLAY:-}" ]]; then
  if command -v Xvfb >/dev/null; then
    for display in $(seq 140 199); do
      [[ -e "/tmp/.X$display-lock" || -e "/tmp/.X11-unix/X$display" ]] && continue
      Xvfb ":$display" -screen 0 1920x1200x24 -nolisten tcp >/dev/null 2>&1 &
      xvfb_pid=$!
      for _ in $(seq 50); do
        [[ -e "/tmp/.X11-unix/X$display" ]] && break
        kill -0 "$xvfb_pid" 2>/dev/null || break
        sleep 0.1
      done
      if [[ -e "/tmp/.X11-unix/X$display" ]] && kill -0 "$xvfb_pid" 2>/dev/null; then
        export DISPLAY=":$display"
        break
      fi
      stop_xvfb
      xvfb_pid=""
    done
    trap stop_xvfb EXIT
  fi
  [[ -n "${DISPLAY:-}" ]] || echo "render-pictures.sh: no display and no Xvfb; pvbatch may fail" >&2
fi
mkdir -p "$pictures"

# time_of KIND RUNDIR [ARGS] -> simulated time of the characteristic frame (empty: the last).
time_of() {
  python3 - "$@" <<'PY'
import csv, sys
kind, run = sys.argv[1], sys.argv[2]

def pieces(body):
    rows = {}
    with open(f"{run}/bodies.csv") as f:
        for r in csv.DictReader(f):
            if r["body"] == body:
                rows.setdefault(int(r["piece"]), []).append(r)
    return rows

if kind == "knocked-out":  # first time a piece of `body` has moved by more than `distance`
    body, distance = sys.argv[3], float(sys.argv[4])
    first = None
    for piece, rows in pieces(body).items():
        x0 = [float(rows[0][k]) for k in "xyz"]
        for r in rows:
            if sum((float(r[k]) - a) ** 2 for k, a in zip("xyz", x0)) > distance ** 2:
                t = float(r["time"])
                first = t if first is None else min(first, t)
                break
    print("" if first is None else first)
elif kind == "lowest":  # time the body's centroid is lowest
    rows = [r for r in csv.DictReader(open(f"{run}/bodies.csv")) if r["body"] == sys.argv[3]]
    print(min(rows, key=lambda r: float(r["z"]))["time"])
elif kind == "faster":  # first time a piece of `body` is faster than `speed` after `after`
    body, speed, after = sys.argv[3], float(sys.argv[4]), float(sys.argv[5])
    first = None
    for piece, rows in pieces(body).items():
        for r in rows:
            v = sum(float(r[k]) ** 2 for k in ("vx", "vy", "vz")) ** 0.5
            if float(r["time"]) > after and v > speed:
                t = float(r["time"])
                first = t if first is None else min(first, t)
                break
    print("" if first is None else first)
elif kind == "peak-record":  # time of the largest |value| of a time,value record
    rows = [l.split(",") for l in open(sys.argv[3]) if l[:1].isdigit() or l[:1] == "-"]
    print(max(rows, key=lambda r: abs(float(r[1])))[0])
PY
}

render() {  # render RUNDIR EXAMPLE PNG ARGS...
  local run="$1" example="$2" png="$3"
  shift 3
  local ranks title attempt
  ranks="$(ranks_of "$run")"
  title="$example ($ranks rank$( ((ranks == 1)) || echo s))"
  echo "$example: $run -> $png"
  rm -f "$png"
  # Several tries: on this shared machine pvbatch sometimes fails to connect to the X server
  # (about one start in four, "bad X server connection"); a retry connects.
  for attempt in 1 2 3 4 5 6; do
    [[ -z "$xvfb_pid" ]] || kill -0 "$xvfb_pid" 2>/dev/null || echo "render-pictures.sh: Xvfb $DISPLAY has stopped" >&2
    # (In a subshell, so that the shell's note of a crashed pvbatch goes to the log too.)
    if ("${launcher[@]}" --force-offscreen-rendering "$root/scripts/render_frame.py" \
          "$run/frames.pvd" "$png" --title "$title" "$@") >"$png.log" 2>&1 && [[ -s "$png" ]]; then
      grep -v '^$' "$png.log" | tail -n 1
      rm -f "$png.log"
      return 0
    fi
    sleep 2
  done
  echo "render-pictures.sh: rendering $example failed (log: $png.log)" >&2
  return 1
}
json_field() { python3 -c "import json,sys; print(json.load(open(sys.argv[1])).get(sys.argv[2], ''))" "$1/summary.json" "$2"; }
ranks_of() { json_field "$1" ranks; }
time_args() { [[ -n "$1" ]] && echo "--time $1" || echo "--index -1"; }

status=0
for run in "${dirs[@]}"; do
  run="$(cd "$run" && pwd)"
  [[ -f "$run/frames.pvd" && -f "$run/summary.json" ]] ||
    { echo "render-pictures.sh: $run has no frames.pvd or summary.json" >&2; status=1; continue; }
  example="$(json_field "$run" scene)"
  [[ "$example" == default ]] && example=cantilever-sag
  png="$pictures/$example.png"
  case "$example" in
    tower-projectile)
      # shellcheck disable=SC2046
      render "$run" "$example" "$png" $(time_args "$(time_of knocked-out "$run" tower 0.3)") \
        --field velocity --field-title "speed (m/s)" --edges --view 1 2 -0.6 --zoom 1.4 --focus 0 0 1.0 || status=1 ;;
    mortared-wall-push)
      render "$run" "$example" "$png" --index -1 --field displacement \
        --field-title "displacement (m)" --opacity 0.35 --overlay "$run/cracks.pvd:mode" \
        --overlay-title "crack mode (1 tension, 3-4 mixed)" --overlay-width 4 \
        --view 0.15 1 -0.5 --zoom 1.1 || status=1 ;;
    cantilever-sag)
      # shellcheck disable=SC2046
      render "$run" "$example" "$png" $(time_args "$(time_of lowest "$run" beam)") \
        --field von_mises --field-title "von Mises stress (Pa)" --view 0.35 1 -0.25 \
        --zoom 0.85 || status=1 ;;
    brazilian-disc)
      render "$run" "$example" "$png" --index -1 --field damage --range 0 1 \
        --field-title "joint damage" --opacity 0.45 --overlay "$run/cracks.pvd" \
        --overlay-width 2 --view 0 0 -1 --up 0 1 0 --zoom 1.1 || status=1 ;;
    arch-acceleration)
      # shellcheck disable=SC2046
      render "$run" "$example" "$png" $(time_args "$(time_of faster "$run" arch 0.5 0.3)") \
        --field velocity --field-title "speed (m/s)" --edges --view 0 1 0 --zoom 1.25 || status=1 ;;
    dry-stone-wall-seismic)
      # shellcheck disable=SC2046
      render "$run" "$example" "$png" \
        $(time_args "$(time_of peak-record "$run" "$root/examples/records/synthetic-sweep.csv")") \
        --field none --edges --opacity 0.35 --overlay "$run/contacts.pvd:normal_force" \
        --overlay-points 0.02 --overlay-title "contact normal force (N)" --view 0.5 1 -0.3 \
        --zoom 1.2 || status=1 ;;
    *) echo "render-pictures.sh: no picture recipe for '$example' ($run)" >&2; status=1 ;;
  esac
done
exit "$status"
