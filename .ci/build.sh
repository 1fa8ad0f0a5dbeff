#!/usr/bin/env bash
# The README's two commands. On a fresh Debian 12 machine (as root, or with sudo) it installs
# what is missing, configures and builds in ./build, then:
#   bash .ci/build.sh main   runs the main job (the most complete example; see README)
#   bash .ci/build.sh test   runs every test (CTest: Catch2 tests, the C99 ABI test, install test)
# Environment: HEMILIGHT_WERROR=ON makes warnings errors (CI sets it); BUILD_DIR (default build).
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-}
case "$mode" in main|test) ;; *) echo "usage: bash .ci/build.sh main|test" >&2; exit 2 ;; esac

# Debian packages the build, tests, examples and benchmarks need (Debian packages only: no vendored copies).
packages=(cmake g++ make pkg-config libglm-dev libeigen3-dev catch2 libopenexr-dev libbenchmark-dev python3-matplotlib
          glslang-tools libassimp-dev nlohmann-json3-dev python3-distributed python3-dask libpng-dev libstb-dev libembree-dev libmeshoptimizer-dev clang libclang-rt-14-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

build=${BUILD_DIR:-build}
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DHEMILIGHT_WERROR="${HEMILIGHT_WERROR:-OFF}" \
      -DHEMILIGHT_BUILD_TESTS=ON -DHEMILIGHT_BUILD_EXAMPLES=ON
cmake --build "$build" -j "$jobs"

if [ "$mode" = main ]; then
  "$build/examples/hemilight_bake" --out out
else
  ctest --test-dir "$build" --output-on-failure -j "$jobs"
fi
