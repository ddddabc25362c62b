#!/usr/bin/env bash
# Builds the neepp CLI for x86-64-v3 (AVX2, FMA) into build-valgrind/, for valgrind (bench/instructions.py).
# The ordinary build is -march=native: on an AVX-512 CPU it contains AVX-512 instructions, which valgrind
# cannot run (it stops with SIGILL). This one runs under valgrind on any AVX2 or AVX-512 machine, so the
# instruction counts and their test are the same whatever CPU runs them. Usage: scripts/build_valgrind.sh
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cmake -S "$ROOT" -B "$ROOT/build-valgrind" -G Ninja -DCMAKE_BUILD_TYPE=Release -DNEEPP_PGO= \
  -DNEEPP_MARCH=x86-64-v3 -DNEEPP_TESTS=OFF >/dev/null
cmake --build "$ROOT/build-valgrind" --target neepp_cli -j"$(nproc)"
echo "build_valgrind: $ROOT/build-valgrind/neepp"
