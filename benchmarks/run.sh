#!/usr/bin/env bash
# Regenerates the benchmark CSVs and charts under docs/bench/ (one command for all of them):
#   bash benchmarks/run.sh            every benchmark and sweep
#   bash benchmarks/run.sh NAME...    only these (e.g. geometry raster)
# For each NAME: build-bench/benchmarks/bench_NAME runs as a Google Benchmark with repetitions
# (CSV of the medians etc.), build-bench/benchmarks/sweep_NAME (if any) writes its own CSV, and
# benchmarks/plot_NAME.py (if any) draws docs/bench/NAME.png from the CSV(s).
# Set-up: run `bash .ci/build.sh main` once first (installs the Debian packages).
set -euo pipefail
cd "$(dirname "$0")/.."
build=build-bench
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DHEMILIGHT_BUILD_BENCHMARKS=ON \
      -DHEMILIGHT_BUILD_TESTS=OFF -DHEMILIGHT_BUILD_EXAMPLES=OFF > /dev/null
cmake --build "$build" -j "$(nproc)"
mkdir -p docs/bench
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for f in "$build"/benchmarks/bench_* "$build"/benchmarks/sweep_*; do
    [ -x "$f" ] || continue
    n=$(basename "$f"); n=${n#bench_}; n=${n#sweep_}
    [[ " ${names[*]-} " == *" $n "* ]] || names+=("$n")
  done
fi
for n in "${names[@]}"; do
  if [ -x "$build/benchmarks/bench_$n" ]; then
    echo "== bench_$n"
    "$build/benchmarks/bench_$n" --benchmark_repetitions="${REPETITIONS:-5}" \
      --benchmark_report_aggregates_only=true \
      --benchmark_out="docs/bench/$n.csv" --benchmark_out_format=csv
  fi
  if [ -x "$build/benchmarks/sweep_$n" ]; then
    echo "== sweep_$n"
    "$build/benchmarks/sweep_$n" "docs/bench/${n}_sweep.csv"
  fi
  if [ -f "benchmarks/plot_$n.py" ]; then
    PYTHONPATH=benchmarks /usr/bin/python3 "benchmarks/plot_$n.py" docs/bench
  fi
done
