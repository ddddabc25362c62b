#!/usr/bin/env bash
# The C++ test suite under AddressSanitizer + UndefinedBehaviorSanitizer: out-of-bounds reads and writes,
# use after free, leaks, signed overflow, misaligned or null accesses, bad shifts and casts each fail
# the test that trips them. One clang build (build-sanitize/) serves this and the fuzz targets
# (scripts/fuzz.sh): for x86-64-v3, so it runs alike on any AVX2 or AVX-512 machine (the optimization
# level: scripts/build_sanitized.sh). scripts/test.sh runs it. Usage: scripts/test_sanitizers.sh [ctest arguments]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$ROOT/scripts/build_sanitized.sh"
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# Six statistical tests that render for long (a minute or more each under the sanitizers) are left to the
# optimized build's ctest, which runs them in full: their code (PSSMLT's chains, BDPT with NEE++ selection,
# a PSSMLT checkpoint cut short, the map's guide and both guides learning over many seeds) runs here
# through shorter tests of the same paths (PSSMLT's bitwise-reproducibility and resume tests,
# BDPT.NeeppLightPathSelectionIsUnbiased, Checkpoint.PssmltResumes..., MapGuiding.UnbiasedWithAWrongGuide,
# MapGuiding.SameImageToTheBit..., BothGuides.SameImageToTheBit..., the guided furnace and resume cases).
LONG='^(PSSMLT\.AgreesWithPathTracingOnAGlossyRoom|PSSMLT\.AgreesWithPathTracingWithNeeppRouletteInTheChain|'
LONG+='PathModes/Furnace\.InnerSphereMatchesGeometricSeries/bdpt_neepp( .*)?|Checkpoint\.PssmltPassCutShortIsNotInItsCheckpoint|'
LONG+='MapGuiding\.UnbiasedAgainstPlainNee|BothGuides\.UnbiasedAgainstPlainNee)$'
ctest --test-dir "$ROOT/build-sanitize" --output-on-failure -j"$(nproc)" -E "$LONG" "$@"
