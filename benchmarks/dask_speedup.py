#!/usr/bin/python3
"""The Dask driver's speed-up against worker processes (docs/distributed.md).

For each stand-in level (made with hemilight_make_level), S shards, two bounces, a sun and the sky:
in each round, in a rotating order, `tools/dask_bake.py --workers W` (a LocalCluster of W worker
processes of one thread each) for W = 1 and 2, and the one-process sharded bake
`hemilight_bake --shards S --threads 1`; wall times, medians over the rounds, and per round the
ratio to the one-worker Dask bake (paired: the machine's drift cancels). The outputs of every run
are checked byte for byte against the one-process bake's.

Usage: dask_speedup.py --bake PATH --make-level PATH --out CSV [--rounds R] [--shards S]
                       [--levels arena:20000:256,keep:20000:256,city_block:50000:512] [--append]
"""
import argparse
import filecmp
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
DRIVER = os.path.join(HERE, "..", "tools", "dask_bake.py")


def make_level(make_level_path, name, triangles, size, directory):
    """The level as glb and the bake options hemilight_make_level prints for its sun and sky."""
    path = os.path.join(directory, f"{name}.glb")
    out = subprocess.run([make_level_path, name, path, "--triangles", str(triangles), "--lightmap-size", str(size)],
                         check=True, capture_output=True, text=True).stdout
    line = next(l for l in out.splitlines() if l.startswith("bake:"))
    options = line.split()[3:]  # after "bake: hemilight_bake MODEL"
    return path, options


def timed(cmd):
    t0 = time.monotonic()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    return time.monotonic() - t0


def same_files(a, b):
    names = sorted(os.listdir(a))
    if names != sorted(os.listdir(b)):
        return False
    match, mismatch, errors = filecmp.cmpfiles(a, b, names, shallow=False)
    return not mismatch and not errors


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--bake", required=True)
    p.add_argument("--make-level", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--shards", type=int, default=8)
    p.add_argument("--levels", default="arena:20000:256,keep:20000:256,city_block:50000:512")
    p.add_argument("--append", action="store_true", help="add rows to an existing CSV")
    a = p.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for spec in a.levels.split(","):
            name, triangles, size = spec.split(":")
            model, options = make_level(a.make_level, name, int(triangles), int(size), tmp)
            common = options + ["--bounces", "2", "--quiet", "--threads", "1"]
            runs = {
                ("one_process", 1): lambda d: [a.bake, model] + common + ["--shards", str(a.shards), "--out", d],
                ("dask", 1): lambda d: [sys.executable, DRIVER, model] + common + ["--shards", str(a.shards), "--workers", "1",
                                                                                  "--hemilight-bake", a.bake, "--out", d],
                ("dask", 2): lambda d: [sys.executable, DRIVER, model] + common + ["--shards", str(a.shards), "--workers", "2",
                                                                                  "--hemilight-bake", a.bake, "--out", d],
            }
            keys = list(runs)
            times = {k: [] for k in keys}
            ratios = {k: [] for k in keys}
            reference = os.path.join(tmp, f"{name}_reference")
            subprocess.run(runs[("one_process", 1)](reference), check=True, stdout=subprocess.DEVNULL)
            for r in range(a.rounds):
                order = keys[r % len(keys):] + keys[:r % len(keys)]
                got = {}
                for k in order:
                    d = os.path.join(tmp, f"{name}_{k[0]}_{k[1]}_{r}")
                    got[k] = timed(runs[k](d))
                    if not same_files(reference, d):
                        sys.exit(f"dask_speedup: {k} on {name} did not write the one-process bake's files")
                    subprocess.run(["rm", "-rf", d], check=True)
                for k in keys:
                    times[k].append(got[k])
                    ratios[k].append(got[("dask", 1)] / got[k])
                print(f"{name} round {r + 1}: " + ", ".join(f"{k[0]} x{k[1]} {got[k]:.1f} s" for k in keys), flush=True)
            for k in keys:
                rows.append([name, int(triangles), int(size), a.shards, k[0], k[1], round(statistics.median(times[k]), 3),
                             round(statistics.median(ratios[k]), 3), a.rounds])
    with open(a.out, "a" if a.append else "w") as f:
        if not a.append:
            f.write("model,triangles,size,shards,runner,workers,median_seconds,speedup,rounds\n")
        for row in rows:
            f.write(",".join(str(x) for x in row) + "\n")


if __name__ == "__main__":
    main()
