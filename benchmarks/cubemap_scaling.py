#!/usr/bin/env python3
"""Thread scaling of the cube-map radiance chain in paired rounds (docs/cubemap.md).

Each round runs cubemap_run (the 256^2 procedural sky, cmft's lobes, 9 levels) with 1 thread and
then with 2 threads, in turn, each as a fresh process filtering 3 times (the median kept), and
records the 1-minute load average before the pair. Wall time, the process's CPU time during the
filter and their ratio (the cores it actually had) are written per run; the summary gives the
medians and the median of the per-round ratios t(1) / t(2).

On a machine shared with other users the kernel's autogroup scheduling gives each process group
(one per terminal) an equal share of the cores: once the load is above the core count, a second thread gets no second
core and the wall-time ratio says nothing about the filter. Read the ratio together with
cpu/wall (the cores had) and the load.

  python3 benchmarks/cubemap_scaling.py CUBEMAP_RUN ROUNDS OUT.csv [JOB]
"""
import statistics
import subprocess
import sys


def run(binary, threads, job):
    out = subprocess.run([binary, "--job", job, "--threads", str(threads), "--repeat", "3"],
                         capture_output=True, text=True, check=True).stdout
    rows = [line.split(",") for line in out.strip().splitlines()]
    wall = statistics.median(float(r[5]) for r in rows)
    cpu = statistics.median(float(r[6]) for r in rows)
    return wall, cpu


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    binary, rounds, path = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    job = sys.argv[4] if len(sys.argv) > 4 else "radiance"
    lines = ["round,threads,load1,wall_s,cpu_s,cores_had"]
    ratios, loads, walls = [], [], {1: [], 2: []}
    for r in range(rounds):
        with open("/proc/loadavg") as f:
            load = float(f.read().split()[0])
        loads.append(load)
        got = {}
        for t in (1, 2):
            wall, cpu = run(binary, t, job)
            got[t] = wall
            walls[t].append(wall)
            lines.append(f"{r},{t},{load:.2f},{wall:.4f},{cpu:.4f},{cpu / wall:.2f}")
        ratios.append(got[1] / got[2])
        print(f"round {r}: load {load:.2f}, 1 thread {got[1]:.3f} s, 2 threads {got[2]:.3f} s, "
              f"ratio {ratios[-1]:.2f}", flush=True)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"median: 1 thread {statistics.median(walls[1]):.3f} s, 2 threads {statistics.median(walls[2]):.3f} s, "
          f"ratio {statistics.median(ratios):.2f} (range {min(ratios):.2f}-{max(ratios):.2f}), "
          f"load {statistics.median(loads):.1f} (range {min(loads):.1f}-{max(loads):.1f})")


if __name__ == "__main__":
    main()
