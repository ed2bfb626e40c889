# Sourced by the benchmark scripts: how to launch fdem on N ranks, and the fdem binary.
# Needs `launcher` set by the caller ("" = mpiexec; a string with {n} = N substituted; else "-n N"
# appended).  Open MPI refuses to run as root unless told (containers, CI).
export OMPI_ALLOW_RUN_AS_ROOT="${OMPI_ALLOW_RUN_AS_ROOT:-1}"
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="${OMPI_ALLOW_RUN_AS_ROOT_CONFIRM:-1}"
cores="$(nproc 2>/dev/null || echo 1)"
launch() {  # launch N -> the launcher words for N ranks
  local n="$1"
  if [[ -z "$launcher" ]]; then
    if ((n > cores)); then echo "mpiexec --oversubscribe -n $n"; else echo "mpiexec -n $n"; fi
  elif [[ "$launcher" == *"{n}"* ]]; then
    echo "${launcher//\{n\}/$n}"
  else
    echo "$launcher -n $n"
  fi
}

# The fdem binary: `fdem` if set (--fdem), else BUILD_DIR/drivers/fdem (default ./build), built
# if needed (scripts/build.sh for ./build, else the fdem target only).  Needs `root` and `fdem`.
ensure_fdem() {
  local build="${BUILD_DIR:-$root/build}" type
  [[ "$build" == /* ]] || build="$PWD/$build"
  if [[ -z "$fdem" ]]; then
    fdem="$build/drivers/fdem"
    if [[ ! -x "$fdem" && "$build" == "$root/build" ]]; then
      "$root/scripts/build.sh"
    else
      [[ -f "$build/CMakeCache.txt" ]] || cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
      cmake --build "$build" --target fdem -j "$(nproc 2>/dev/null || echo 2)" >/dev/null
    fi
    type="$(sed -n 's/^CMAKE_BUILD_TYPE:STRING=//p' "$build/CMakeCache.txt" 2>/dev/null || true)"
    [[ "$type" == Release ]] || echo "$(basename "$0"): warning: $build is a '$type' build, not Release" >&2
  fi
  [[ -x "$fdem" ]] || { echo "$(basename "$0"): no fdem binary at $fdem" >&2; exit 2; }
}
