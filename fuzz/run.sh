#!/usr/bin/env bash
# Builds the libFuzzer harnesses of the C ABI with Clang (ASan + UBSan + libFuzzer) in
# build-fuzz/ and runs each on its corpus (fuzz/corpus/NAME):
#   bash fuzz/run.sh            each harness for 60 s, new inputs added to a copy of the corpus
#   bash fuzz/run.sh SECONDS    each for SECONDS
#   bash fuzz/run.sh --ci       each replays its corpus once, no mutation (what CI runs: the same
#                               inputs on every machine, so CI does not depend on where the
#                               coverage-guided search wanders)
# Installs clang and libclang-rt-14-dev (libFuzzer) when missing, as .ci/build.sh does for the rest.
# A finding stops the script with libFuzzer's report and the input saved as build-fuzz/crash-*.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-60}
missing=()
for p in clang libclang-rt-14-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHEMILIGHT_BUILD_FUZZERS=ON \
  -DHEMILIGHT_BUILD_TESTS=OFF -DHEMILIGHT_BUILD_EXAMPLES=OFF > /dev/null
cmake --build build-fuzz -j "$(nproc)" 2>&1 | grep -v "warning: loop not vectorized" | grep -E "error|Built target fuzz" || true
for name in points cache bake cubemap exr shards; do
  [ -x "build-fuzz/fuzz/fuzz_$name" ] || { echo "build-fuzz/fuzz/fuzz_$name was not built" >&2; exit 1; }
done
for name in points cache bake cubemap exr shards; do
  corpus=build-fuzz/corpus/$name
  mkdir -p "$corpus"
  cp -n fuzz/corpus/$name/* "$corpus"/ 2>/dev/null || true
  if [ "$mode" = --ci ]; then
    limits=(-runs=0)
    # fuzz_exr's corpus replays with no allocation over 64 MB: decoding
    # exr_load_capacity_checked_after_decode.exr before refusing its capacity would allocate 396 MB.
    # (The timed search keeps libFuzzer's default limit: OpenEXR's header reader itself allocates
    # up to about 2 GB, untouched, for some crafted headers before they fail.)
    if [ "$name" = exr ]; then limits+=(-malloc_limit_mb=64); fi
  else
    limits=(-max_total_time="$mode")
  fi
  echo "== fuzz_$name ${limits[*]}"
  (cd build-fuzz && ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=0 \
     "./fuzz/fuzz_$name" "corpus/$name" "${limits[@]}" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 2>&1 |
     grep -E "^#[0-9]+.*DONE|ERROR|SUMMARY|contract|Test unit written|Done [0-9]+ runs")
done
echo "all harnesses ran without a finding"
