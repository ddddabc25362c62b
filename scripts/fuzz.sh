#!/usr/bin/env bash
# Runs the libFuzzer targets of fuzz/ (see fuzz/README.md), as many at a time as there are cores
# (NEEPP_FUZZ_JOBS to choose), each for SECONDS (default 30):
# the scene loader, the OBJ, PLY, .serialized, .vol and curve readers, image reading, visibility-map files and
# integrator options.
# Each target starts from its built-in seeds plus the project's and the shared scenes' files, keeps the
# corpus it grows in build-sanitize/fuzz/corpus/, and writes any crashing, hanging or leaking input to
# build-sanitize/fuzz/artifacts/. Fails if any target finds one. scripts/test.sh runs it for 30 s.
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SECONDS_EACH="${1:-30}"
shift || true
TARGETS=("$@")
[ ${#TARGETS[@]} -eq 0 ] && TARGETS=(scene obj ply serialized volume_grid curves image map_file integrator_options)
SHARED="$ROOT/../shared/scenes"
B="$ROOT/build-sanitize"
W="$B/fuzz"
"$ROOT/scripts/build_sanitized.sh"
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

# The project's and the shared scenes' files of a kind, small enough to be mutated quickly (< 64 KB).
external_seeds() {
  local target=$1 dest=$2 files=()
  case $target in
    scene) mapfile -t files < <(find "$ROOT/scenes" "$SHARED" -name '*.xml' -size -64k 2>/dev/null) ;;
    obj) mapfile -t files < <(find "$SHARED" -name '*.obj' -size -64k 2>/dev/null | sort) ;;
    image) mapfile -t files < <(find "$SHARED" \( -name '*.jpg' -o -name '*.png' -o -name '*.exr' -o -name '*.hdr' \) \
                                  -size -64k 2>/dev/null) ;;
  esac
  local f
  for f in "${files[@]:0:40}"; do cp "$f" "$dest/$(echo "$f" | md5sum | cut -c1-12)-$(basename "$f")"; done
}

run_target() {
  local t=$1 seeds="$W/seeds/$1" corpus="$W/corpus/$1" artifacts="$W/artifacts/$1" dict=()
  rm -rf "$seeds" && mkdir -p "$seeds" "$corpus" "$artifacts"
  NEEPP_FUZZ_WRITE_SEED="$seeds" "$B/fuzz_$t" >/dev/null 2>&1 || true
  external_seeds "$t" "$seeds"
  case $t in scene) dict=(-dict="$ROOT/fuzz/scene.dict") ;; obj | ply) dict=(-dict="$ROOT/fuzz/mesh.dict") ;; esac
  # -timeout: an input taking 10 s is a hang; -rss_limit_mb: memory out of proportion to a small input
  # is a bug (a header claiming 10^9 vertices must be refused, not allocated).
  if "$B/fuzz_$t" "$corpus" "$seeds" "${dict[@]}" -max_total_time="$SECONDS_EACH" -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$artifacts/" -print_final_stats=1 >"$W/$t.log" 2>&1; then
    echo "fuzz: $t: $(grep -o 'stat::number_of_executed_units: *[0-9]*' "$W/$t.log" | grep -o '[0-9]*$') runs," \
         "$(grep -Eo 'cov: [0-9]+' "$W/$t.log" | tail -n1), corpus $(ls "$corpus" | wc -l), no crash, hang or leak"
  else
    echo "fuzz: $t FAILED: see $W/$t.log and the input in $artifacts/"; tail -n 40 "$W/$t.log"; return 1
  fi
}

mkdir -p "$W"
status=0
running=0
for t in "${TARGETS[@]}"; do
  run_target "$t" &
  running=$((running + 1))
  if [ "$running" -ge "${NEEPP_FUZZ_JOBS:-$(nproc)}" ]; then wait -n || status=1; running=$((running - 1)); fi
done
while [ "$running" -gt 0 ]; do wait -n || status=1; running=$((running - 1)); done
exit $status
