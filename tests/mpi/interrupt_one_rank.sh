#!/bin/sh
# SIGNAL sent to ONE rank of a 2-rank run in the middle of its steps: every rank finishes the
# step, a checkpoint and summary.json (status interrupted) are written, and the run exits 5
# promptly.  The checkpoint then continues to the same state_hash as an uninterrupted run.
# usage: interrupt_one_rank.sh MPIEXEC FDEM SCENE WORK SIGNAL
set -u
MPIEXEC=$1 FDEM=$2 SCENE=$3 WORK=$4 SIGNAL=$5
rm -rf "$WORK"
mkdir -p "$WORK"
fail() { echo "FAIL: $*"; exit 1; }
hash_of() { sed -n 's/.*"state_hash": "\([0-9a-f]*\)".*/\1/p' "$1/summary.json"; }

"$MPIEXEC" -n 2 --oversubscribe "$FDEM" run "$SCENE" -o "$WORK/run" -q >"$WORK/run.log" 2>&1 &
launcher=$!
# Wait until the run is stepping (two energy rows written), at most 60 s.
i=0
while [ "$(wc -l <"$WORK/run/energy.csv" 2>/dev/null || echo 0)" -lt 3 ]; do
  i=$((i + 1))
  [ $i -gt 600 ] && fail "the run did not start stepping"
  sleep 0.1
done
rank=$(pgrep -P "$launcher" -f "$FDEM" | tail -n 1)
[ -n "$rank" ] || fail "no rank process found under the launcher $launcher"
start=$(date +%s)
kill "-$SIGNAL" "$rank"
wait "$launcher"
code=$?
elapsed=$(($(date +%s) - start))
cat "$WORK/run.log"
echo "exit code $code, ${elapsed} s after SIG$SIGNAL to rank pid $rank"
[ "$code" -eq 5 ] || fail "expected exit code 5 (interrupted), got $code"
[ "$elapsed" -le 20 ] || fail "took ${elapsed} s to stop"
grep -q '"status": "interrupted"' "$WORK/run/summary.json" || fail "summary.json status is not interrupted"
grep -q "continue with --restart" "$WORK/run/summary.json" || fail "summary.json names no checkpoint"
grep -q "interrupted by" "$WORK/run.log" || fail "no message on stderr"
ls "$WORK/run"/*.tmp "$WORK/run/frames"/*.tmp 2>/dev/null && fail "stale .tmp files"
checkpoint=$(ls "$WORK/run"/checkpoint_*.h5 | sort | tail -n 1)
steps=$(sed -n 's/.*"steps": \([0-9]*\).*/\1/p' "$WORK/run/summary.json")
case "$checkpoint" in *"$(printf '%08d' "$steps").h5") ;; *) fail "newest checkpoint $checkpoint is not of step $steps" ;; esac

"$MPIEXEC" -n 2 --oversubscribe "$FDEM" run "$SCENE" -o "$WORK/restart" -q --restart "$checkpoint" ||
  fail "the restart from $checkpoint failed"
"$MPIEXEC" -n 2 --oversubscribe "$FDEM" run "$SCENE" -o "$WORK/whole" -q || fail "the uninterrupted run failed"
[ "$(hash_of "$WORK/restart")" = "$(hash_of "$WORK/whole")" ] ||
  fail "restart state_hash $(hash_of "$WORK/restart") differs from uninterrupted $(hash_of "$WORK/whole")"
echo "interrupted at step $steps; restart and uninterrupted run agree: $(hash_of "$WORK/whole")"
