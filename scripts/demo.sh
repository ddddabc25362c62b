#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to the demo image: installs the build dependencies,
# builds neepp and renders the built-in demos (a room lit through a door ajar; an office of 30 lights) into demo-output/
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$ROOT/scripts/install_deps.sh"
"$ROOT/scripts/build.sh"
"$ROOT/build/neepp" demo -o "${1:-$ROOT/demo-output}"
