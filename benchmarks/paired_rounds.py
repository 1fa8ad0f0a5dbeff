#!/usr/bin/env python3
"""Paired rounds of two (or more) builds of a Google Benchmark binary, in turn, in the same minutes.

On a shared VM whose speed drifts from minute to minute, figures taken at different times compare
badly; builds run in turn compare well. Each round runs every binary once (3 repetitions, the
median kept) on the benchmarks matching FILTER; the summary gives each binary's range and median
per benchmark, the median of the per-round ratios to the first binary, and the host's steal (the
`steal` counter of bench_raster: CPU time the hypervisor gave to other guests) where reported.

  python3 benchmarks/paired_rounds.py ROUNDS FILTER BINARY_A BINARY_B [...]
  e.g. python3 benchmarks/paired_rounds.py 10 'raster/(hexagon_room_1062|cornell_box_32)/N:64/' \\
           /tmp/old/build-bench/benchmarks/bench_raster build-bench/benchmarks/bench_raster
"""
import json
import statistics
import subprocess
import sys


def run(binary, pattern):
    out = subprocess.run([binary, f"--benchmark_filter={pattern}", "--benchmark_repetitions=3",
                          "--benchmark_report_aggregates_only=true", "--benchmark_format=json"],
                         capture_output=True, text=True, check=True).stdout
    rows = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("aggregate_name") != "median":
            continue
        rows[b["run_name"]] = (b["items_per_second"], b.get("steal", -1.0))
    return rows


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    rounds, pattern, binaries = int(sys.argv[1]), sys.argv[2], sys.argv[3:]
    results = []  # results[round][binary] = {name: (items/s, steal)}
    for r in range(rounds):
        results.append([run(b, pattern) for b in binaries])
        line = "; ".join(
            " ".join(f"{name.split('/', 1)[1]} {v[0] / 1e3:.1f}k (steal {v[1]:.0%})" for name, v in sorted(res.items()))
            for res in results[-1])
        print(f"round {r + 1}: {line}", flush=True)
    names = sorted(results[0][0])
    print()
    for name in names:
        print(name)
        base = [res[0][name][0] for res in results]
        for i, b in enumerate(binaries):
            v = [res[i][name][0] for res in results]
            steal = [res[i][name][1] for res in results]
            ratio = statistics.median(x / y for x, y in zip(v, base))
            print(f"  {b}: {min(v) / 1e3:.1f}-{max(v) / 1e3:.1f}k/s, median {statistics.median(v) / 1e3:.1f}k/s, "
                  f"ratio to the first {ratio:.3f}, steal median {statistics.median(steal):.1%} max {max(steal):.1%}")


if __name__ == "__main__":
    main()
