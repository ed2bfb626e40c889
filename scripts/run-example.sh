#!/usr/bin/env bash
# README command 1: install, build, and run the default example scene; results in out/example.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh"
scene="${1:-$root/examples/default.yaml}"
out="${2:-$root/out/example}"
"$root/build/drivers/fdem" run "$scene" -o "$out"
echo "Open $out/frames.pvd in ParaView."
