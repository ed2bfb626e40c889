#!/usr/bin/env bash
# Makes ParaView's `pvbatch` (Debian 12 package paraview 5.11) available beside fdem's build
# dependencies, for scripts/render-pictures.sh.
#
# Debian's python3-paraview conflicts with python3-vtk9, which libvtk9-dev (needed to build fdem)
# depends on, so the two cannot be installed side by side. This script installs paraview once to
# pull in its dependencies, unpacks the paraview and python3-paraview packages into
# /opt/fdem-paraview, puts libvtk9-dev back, and writes /usr/local/bin/pvbatch, which runs the
# unpacked pvbatch (under xvfb-run when there is no display). Idempotent.
set -euo pipefail
prefix=/opt/fdem-paraview
if [[ -x "$prefix/usr/bin/pvbatch" && -x /usr/local/bin/pvbatch ]] &&
   dpkg -s libvtk9-dev >/dev/null 2>&1; then
  exit 0
fi
sudo=""
[[ $(id -u) -eq 0 ]] || sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq paraview xvfb xauth
work="$(mktemp -d)"
(cd "$work" && apt-get download paraview python3-paraview)
$sudo mkdir -p "$prefix"
for deb in "$work"/*.deb; do $sudo dpkg -x "$deb" "$prefix"; done
rm -rf "$work"
# Back to the packages the build needs (this removes python3-paraview, not paraview's libraries).
$sudo apt-get install -y -qq libvtk9-dev python3-vtk9
$sudo tee /usr/local/bin/pvbatch >/dev/null <<'WRAPPER'
#!/bin/sh
# ParaView's pvbatch from Debian's paraview package, unpacked into /opt/fdem-paraview
# (scripts/install-paraview.sh). Without a display it runs under xvfb-run.
root=/opt/fdem-paraview
export LD_LIBRARY_PATH="$root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export PYTHONPATH="$root/usr/lib/python3/dist-packages${PYTHONPATH:+:$PYTHONPATH}"
if [ -z "$DISPLAY" ] && command -v xvfb-run >/dev/null 2>&1; then
  exec xvfb-run -a -s "-screen 0 1920x1200x24" "$root/usr/bin/pvbatch" "$@"
fi
exec "$root/usr/bin/pvbatch" "$@"
WRAPPER
$sudo chmod +x /usr/local/bin/pvbatch
echo "pvbatch: /usr/local/bin/pvbatch -> $prefix/usr/bin/pvbatch"
