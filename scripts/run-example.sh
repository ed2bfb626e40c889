#!/usr/bin/env bash
# README command 1: install, build, and run the default example — a pier of stacked stone blocks
# hit by a projectile (examples/tower-projectile.yaml) — on 2 MPI ranks; results in out/example.
#   scripts/run-example.sh [SCENE] [OUTDIR] [RANKS]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh"
scene="${1:-$root/examples/tower-projectile.yaml}"
out="${2:-$root/out/example}"
ranks="${3:-2}"
# Open MPI refuses to run as root unless told; more ranks than cores need --oversubscribe.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mpiexec -n "$ranks" --oversubscribe "$root/build/drivers/fdem" run "$scene" -o "$out"
echo "Open $out/frames.pvd in ParaView."
