#!/usr/bin/env bash
# scripts/plot.py on a short run's output: every PNG it should draw exists and is a PNG.  Skipped
# (exit 77) when no python3 has matplotlib (scripts/install-deps.sh installs python3-matplotlib).
# Usage: plot_test.sh FDEM SOURCE_DIR WORK
set -euo pipefail
fdem="$1" source="$2" work="$3"
python=""
for candidate in /usr/bin/python3 python3; do
  if command -v "$candidate" >/dev/null && "$candidate" -c "import matplotlib" 2>/dev/null; then
    python="$candidate"
    break
  fi
done
if [ -z "$python" ]; then
  echo "plot_test: skipped: no python3 with matplotlib (apt-get install python3-matplotlib)"
  exit 77
fi
rm -rf "$work"
"$fdem" run "$source/tests/mpi/scenes/histories.yaml" -o "$work" -q --set time.end=0.0005 \
  --set output.checkpoint_every=0
"$python" "$source/scripts/plot.py" "$work"
for stem in energy balance histories_load_left histories_load_right histories_load_press \
            histories_body_beam histories_body_ram histories_monitor_mid histories_monitor_quarter; do
  file="$work/$stem.png"
  if [ "$(head -c 8 "$file" 2>/dev/null | od -An -tx1 | tr -d ' \n')" != "89504e470d0a1a0a" ]; then
    echo "plot_test: $file is missing or not a PNG" >&2
    exit 1
  fi
done
# A load's stress-strain curve (--specimen) with a reference line; an unknown load is exit 2.
"$python" "$source/scripts/plot.py" "$work" --specimen press 0.0048 0.06 --line "limit=1.5" \
  >/dev/null
file="$work/stress_strain_press.png"
if [ "$(head -c 8 "$file" 2>/dev/null | od -An -tx1 | tr -d ' \n')" != "89504e470d0a1a0a" ]; then
  echo "plot_test: $file is missing or not a PNG" >&2
  exit 1
fi
set +e
"$python" "$source/scripts/plot.py" "$work" --specimen nosuch 1 1 2>/dev/null >/dev/null
code=$?
set -e
[ "$code" -eq 2 ] || { echo "plot_test: --specimen nosuch gave exit code $code, not 2" >&2; exit 1; }
# A directory without the CSVs is refused with exit code 2.
mkdir -p "$work/empty"
set +e
"$python" "$source/scripts/plot.py" "$work/empty" 2>/dev/null
code=$?
set -e
[ "$code" -eq 2 ] || { echo "plot_test: an empty directory gave exit code $code, not 2" >&2; exit 1; }
echo "plot_test: 10 PNGs drawn with $python"
