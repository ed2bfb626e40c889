#!/usr/bin/env bash
# Installs the Debian packages fdem needs, only those that are missing.  Safe to run repeatedly.
# python3-matplotlib: scripts/plot.py (and its test).  ccache: repeated builds (CI) reuse objects.
set -euo pipefail
packages=(g++ make cmake libeigen3-dev libopenmpi-dev openmpi-bin libmetis-dev libhdf5-openmpi-dev
          libvtk9-dev zlib1g-dev catch2 libyaml-cpp-dev libtrilinos-zoltan-dev python3-matplotlib
          ccache)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "fdem: installing ${missing[*]}" >&2
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
