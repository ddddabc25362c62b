#!/usr/bin/env bash
# ThreadSanitizer over what runs in parallel: the render loop (tiles, the image and splat merges,
# checkpoints; tests/render), renders at once in one process as the Python package's threads make them
# (two renders, a render while a scene loads, a cancel from the progress listener;
# tests/render/test_concurrent_renders.cpp: the interpreter is not instrumented, so the Python threads'
# races are looked for here), NEE++'s map (per-thread learning merged between passes, seeding;
# tests/visibility) and the display's sending thread (tests/display). TSan must see the thread pool's
# synchronisation, so oneTBB is first rebuilt with
# -fsanitize=thread from Debian's own source package (build-tsan/tbb; about 30 s), and neepp's tests are
# built with clang against it (build-tsan/). Embree is Debian's (see tests/sanitizers/tsan.supp).
# scripts/test.sh runs it. Usage: scripts/test_tsan.sh
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
B="$ROOT/build-tsan"
"$ROOT/scripts/install_deps.sh" clang libclang-rt-14-dev dpkg-dev xz-utils >/dev/null
TBB_VERSION="$(dpkg-query -W -f='${source:Version}' libtbb12)"
if [ ! -f "$B/tbb/.built-$TBB_VERSION" ]; then
  # Debian's source of the installed libtbb12, through a deb-src list of our own (the system's lists
  # carry binary packages only).
  APT="$B/tbb-apt"
  rm -rf "$APT" "$B/tbb" && mkdir -p "$APT/lists/partial" "$APT/src"
  cat >"$APT/sources.sources" <<SRC
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: $(. /etc/os-release && echo "$VERSION_CODENAME") $(. /etc/os-release && echo "$VERSION_CODENAME")-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
  APTOPT=(-o Dir::Etc::SourceList=/dev/null -o Dir::Etc::SourceParts="$APT" -o Dir::State::Lists="$APT/lists")
  apt-get "${APTOPT[@]}" -q update >/dev/null
  (cd "$APT/src" && apt-get "${APTOPT[@]}" -q source --download-only "onetbb=$TBB_VERSION" >/dev/null 2>&1 ||
     apt-get "${APTOPT[@]}" -q source --download-only onetbb >/dev/null 2>&1)
  tar -xf "$APT"/src/onetbb_*.orig.tar.* -C "$APT/src"
  cmake -S "$(ls -d "$APT"/src/oneTBB-*/)" -B "$B/tbb-build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTBB_SANITIZE=thread -DTBB_TEST=OFF -DTBBMALLOC_BUILD=OFF -DTBB_EXAMPLES=OFF \
    -DTBB_STRICT=OFF -DCMAKE_INSTALL_PREFIX="$B/tbb" >/dev/null
  cmake --build "$B/tbb-build" -j"$(nproc)" >/dev/null
  cmake --install "$B/tbb-build" >/dev/null
  touch "$B/tbb/.built-$TBB_VERSION"
fi
cmake -S "$ROOT" -B "$B" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DNEEPP_PGO= -DNEEPP_MARCH=x86-64-v3 -DNEEPP_SANITIZE=thread \
  -DCMAKE_PREFIX_PATH="$B/tbb" >/dev/null
# test_display: TevDisplay's sending thread (--display-server) and the render's hand-over to it.
# test_guiding: the SD-tree's and the map guide's records arrive from four threads at once.
cmake --build "$B" --target test_render test_visibility test_display test_guiding -j"$(nproc)"
export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$ROOT/tests/sanitizers/tsan.supp"
for t in test_render test_visibility test_display test_guiding; do
  if [[ $t == test_render || $t == test_visibility ]]; then  # the display and the guides' tests use no TBB
    [[ "$(ldd "$B/$t")" == *"$B/tbb/lib/libtbb"* ]] || { echo "test_tsan: $t does not use the instrumented TBB"; exit 1; }
  fi
  "$B/$t" --gtest_brief=1
done
echo "test_tsan: no data race in the render loop's (concurrent renders included), the visibility map's, the display's or the guides' tests"
