#!/bin/sh
# A run whose output cannot be written (a file size limit stands in for a full disk: writes fail
# with EFBIG as they would with ENOSPC): every rank stops with exit code 4 (I/O failure),
# summary.json says status failed with the reason, and no partial .tmp file is left.
# usage: expect_io_failure.sh MPIEXEC FDEM SCENE WORK RANKS LIMIT_KB EXPECT [fdem arguments...]
set -u
MPIEXEC=$1 FDEM=$2 SCENE=$3 WORK=$4 RANKS=$5 LIMIT=$6 EXPECT=$7
shift 7
rm -rf "$WORK"
mkdir -p "$WORK"
fail() { echo "FAIL: $*"; exit 1; }
# The limit applies to the ranks only (mpiexec's own files stay unlimited); SIGXFSZ is ignored so
# that an oversized write fails with EFBIG instead of killing the rank.
"$MPIEXEC" -n "$RANKS" --oversubscribe sh -c \
  "trap '' XFSZ; ulimit -f $LIMIT; exec \"\$0\" \"\$@\"" \
  "$FDEM" run "$SCENE" -o "$WORK/out" -q "$@" >"$WORK/log" 2>&1
code=$?
cat "$WORK/log"
echo "exit code $code"
[ "$code" -eq 4 ] || fail "expected exit code 4 (I/O failure), got $code"
grep -q "fdem: I/O failure: .*$EXPECT" "$WORK/log" || fail "no 'I/O failure: ... $EXPECT' message"
grep -q '"status": "failed"' "$WORK/out/summary.json" || fail "summary.json status is not failed"
grep -q "\"reason\": \"I/O failure: .*$EXPECT" "$WORK/out/summary.json" ||
  fail "summary.json gives no I/O failure reason"
leftover=$(find "$WORK/out" -name '*.tmp')
[ -z "$leftover" ] || fail "stale temporary files: $leftover"
echo "exit code 4, summary.json failed with the reason, no .tmp left"
