#!/usr/bin/env bash
# Fuzzes the scene and Gmsh readers with libFuzzer (clang, ASan + UBSan with float-cast-overflow)
# for SECONDS each (default 60), starting from the seed corpus (tests/fuzz/corpus, the examples,
# the test scenes and meshes).  Exits non-zero on a finding (the crashing input is kept in
# build-fuzz/findings/).  Prints one result line per harness: inputs run, inputs/s, corpus size.
#   scripts/fuzz.sh [SECONDS]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-60}"
build="$root/build-fuzz"

if ! command -v clang++ >/dev/null; then
  if [ "$(id -u)" -eq 0 ]; then
    apt-get install -y --no-install-recommends clang >/dev/null
  else
    echo "fuzz.sh: needs clang (Debian: apt-get install clang)" >&2
    exit 2
  fi
fi
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
      -DCMAKE_CXX_COMPILER=clang++ -DFDEM_FUZZ=ON -DFDEM_BUILD_TESTS=OFF \
      -DFDEM_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j2 --target fuzz_scene_reader fuzz_gmsh_reader >/dev/null

mkdir -p "$build/findings"
status=0
run() {  # name dictionary seed-directories...
  local name=$1 dict=$2
  shift 2
  local corpus="$build/corpus/$name"
  mkdir -p "$corpus"
  local log="$build/$name.log"
  # -rss_limit_mb and -timeout turn memory blow-ups and hangs into findings as well.
  if ! (cd "$build/findings" && "$build/tests/fuzz/$name" -max_total_time="$seconds" \
        -dict="$dict" -timeout=10 -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
        "$corpus" "$@" >"$log" 2>&1); then
    status=1
    echo "$name: FINDING (see $log and $build/findings/)"
    tail -n 30 "$log"
  fi
  local runs rate
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
  echo "$name: ${runs:-?} inputs in ${seconds} s (${rate:-?} inputs/s), corpus $(ls "$corpus" | wc -l) files"
}
run fuzz_scene_reader "$root/tests/fuzz/scene.dict" "$root/tests/fuzz/corpus/scene" \
    "$root/examples" "$root/tests/data/scenes" "$root/tests/mpi/scenes"
run fuzz_gmsh_reader "$root/tests/fuzz/gmsh.dict" \
    "$root/tests/data/gmsh"
exit $status
