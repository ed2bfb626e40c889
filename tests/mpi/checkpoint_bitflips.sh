#!/bin/sh
# Damaged checkpoints: single-bit flips spread over the file and zeroed 4 KiB pages.  Every
# restart from a damaged copy must either refuse it (exit 2, a "checkpoint" message, no HDF5
# error dump) or, when the damage hit bytes the file does not use, continue to exactly the
# state_hash of the undamaged restart.  Never exit 0 with another state, 1, 3, or hang.
# usage: checkpoint_bitflips.sh FDEM SCENE WORK FLIPS
set -u
FDEM=$1 SCENE=$2 WORK=$3 FLIPS=$4
rm -rf "$WORK"
mkdir -p "$WORK"
fail() { echo "FAIL: $*"; exit 1; }
hash_of() { sed -n 's/.*"state_hash": "\([0-9a-f]*\)".*/\1/p' "$1/summary.json"; }

"$FDEM" run "$SCENE" -o "$WORK/first" -q || fail "the first run failed"
checkpoint=$(ls "$WORK/first"/checkpoint_*.h5 | sort | head -n 1)
"$FDEM" run "$SCENE" -o "$WORK/good" -q --restart "$checkpoint" || fail "the undamaged restart failed"
good=$(hash_of "$WORK/good")
size=$(wc -c <"$checkpoint")
refused=0 unharmed=0

# Restarts from the damaged copy $WORK/bad.h5 as damage number $1 ($2 describes it).
try_restart() {
  out="$WORK/restart$1"
  timeout 60 "$FDEM" run "$SCENE" -o "$out" -q --restart "$WORK/bad.h5" >"$out.log" 2>&1
  code=$?
  if [ "$code" -eq 2 ]; then
    grep -q "checkpoint" "$out.log" || fail "$2: exit 2 without naming the checkpoint: $(cat "$out.log")"
    grep -q "HDF5-DIAG\|infinite loop" "$out.log" && fail "$2: HDF5 error dump: $(cat "$out.log")"
    [ "$(wc -l <"$out.log")" -le 2 ] || fail "$2: more than one message: $(cat "$out.log")"
    refused=$((refused + 1))
  elif [ "$code" -eq 0 ] && [ "$(hash_of "$out")" = "$good" ]; then
    unharmed=$((unharmed + 1))
  else
    fail "$2: exit $code, state_hash $(hash_of "$out" 2>/dev/null) (undamaged: $good): $(cat "$out.log")"
  fi
  echo "$2: exit $code"
}

k=0
while [ $k -lt "$FLIPS" ]; do
  offset=$(( (k * 2654435761 + 977) % size ))
  bit=$(( k % 8 ))
  cp "$checkpoint" "$WORK/bad.h5"
  byte=$(od -An -tu1 -j "$offset" -N1 "$WORK/bad.h5" | tr -d ' ')
  flipped=$(( byte ^ (1 << bit) ))
  printf "$(printf '\\%03o' "$flipped")" | dd of="$WORK/bad.h5" bs=1 seek="$offset" conv=notrunc 2>/dev/null
  try_restart "$k" "bit $bit of byte $offset"
  k=$((k + 1))
done
pages=$(( (size + 4095) / 4096 ))
p=0
while [ $p -lt "$pages" ]; do
  cp "$checkpoint" "$WORK/bad.h5"
  dd if=/dev/zero of="$WORK/bad.h5" bs=4096 seek="$p" count=1 conv=notrunc 2>/dev/null
  try_restart "page$p" "zeroed page $p of $pages"
  p=$((p + 1))
done
echo "$FLIPS bit flips and $pages zeroed pages of a $size-byte checkpoint: $refused refused" \
     "(exit 2), $unharmed unharmed (same state_hash), none silently different"
