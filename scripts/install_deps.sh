#!/usr/bin/env bash
# Install the Debian packages needed to build and run neepp (Debian 12, as root or via sudo).
# Idempotent: if every package is already installed, apt is not touched at all.
# Extra packages may be passed as arguments (e.g. `install_deps.sh libllvm19`).
set -euo pipefail

PKGS=(cmake ninja-build g++ pkg-config libembree-dev libtbb-dev libopenexr-dev libimath-dev libpugixml-dev
      libjpeg-dev zlib1g-dev libcli11-dev libfmt-dev libstb-dev nlohmann-json3-dev libgtest-dev
      libopenvdb-dev libboost-iostreams-dev python3-venv "$@")
# libboost-iostreams-dev: OpenVDB's headers include Boost's and Debian's FindOpenVDB.cmake asks for Boost's
# iostreams, but libopenvdb-dev does not depend on either.

missing=()
for p in "${PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PKGS[@]} packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
echo "install_deps: installing ${missing[*]}"
# Update the package lists once (skip when they were refreshed in the last hour).
lists_fresh=0
if [ -n "$(find /var/lib/apt/lists -maxdepth 1 -name '*Packages*' -mmin -60 2>/dev/null | head -n1)" ]; then
  lists_fresh=1
fi
if [ "$lists_fresh" -eq 0 ]; then
  $SUDO apt-get update -q
fi
if ! $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"; then
  # The lists may have been stale after all: refresh and retry once.
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
echo "install_deps: done"
