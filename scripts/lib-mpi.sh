# Sourced by the benchmark scripts: how to launch fdem on N ranks.
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
