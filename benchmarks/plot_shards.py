"""Charts and the paper estimate of the sharded bake (docs/distributed.md).

Reads docs/bench/shards.csv (sweep_shards: error, hemicubes, set-up, merge and transfer against the
shard count on the stand-in levels) and, when present, docs/bench/dask_speedup.csv
(benchmarks/dask_speedup.py: the Dask driver's wall time against worker processes). Writes
docs/bench/shards.png and docs/bench/dask_estimate.csv: the time of a 32-page, 2048^2,
three-bounce bake on 1, 8 and 64 machines, from the measured per-hemicube cost, hemicubes per
texel, a job's set-up and a merge's cost per texel, and the transfer per pass.

The estimate's model, per pass, M machines of C cores (C = the measured machine's threads), S = 4 M
shards (4 jobs per machine and pass):
  compute  = samples x hemicubes per sample x core-seconds per hemicube / (M x C)
  set-up   = (S / M) x a job's set-up (it scales with the atlas's texels: every job makes it)
  merge    = atlas texels x merge seconds per texel (one process)
  transfer = the state (16 bytes per atlas texel) sent to each of the M machines from the driver,
             plus the shards' values back, over the driver's link (1 and 10 Gbit/s)
Everything measured on the closed stand-in (arena) at S = 8 (or the nearest shard count swept):
shards of ~1,500 samples, big enough to keep a job's threads busy."""
import csv
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_csv

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
rows = load_csv(f"{out}/shards.csv")
levels = list(dict.fromkeys(r["level"] for r in rows))

speed_path = f"{out}/dask_speedup.csv"
speed = load_csv(speed_path) if os.path.exists(speed_path) else []
fig, axes = plt.subplots(1, 4 if speed else 3, figsize=(20 if speed else 15, 4.2))
for name in levels:
    sel = [r for r in rows if r["level"] == name]
    x = [r["shards"] for r in sel]
    label = f"{name} ({int(sel[0]['triangles'])} tris, {int(sel[0]['size'])}²)"
    axes[0].plot(x, [100 * r["rel_rms_vs_per_texel"] for r in sel], "o-", label=label)
    axes[0].axhline(100 * sel[0]["own_rel_rms_vs_per_texel"], ls=":", color=axes[0].lines[-1].get_color())
    axes[1].plot(x, [r["hemicubes"] / sel[0]["hemicubes"] for r in sel], "o-", label=label)
    axes[2].plot(x, [r["shard_imbalance"] for r in sel], "o-", label=label)
axes[0].set_title("relative RMS vs a hemicube per texel (%)\n(dotted: the unsharded bake's own)")
axes[1].set_title("hemicubes / unsharded")
axes[2].set_title("largest shard's hemicubes / mean shard's")
for ax in axes[:3]:
    ax.set_xscale("log", base=2)
    ax.set_xlabel("shards S")
    ax.legend(fontsize=7)
if speed:
    ax = axes[3]
    for model in dict.fromkeys(r["model"] for r in speed):
        sel = [r for r in speed if r["model"] == model and r["runner"] == "dask"]
        if sel:
            ax.plot([r["workers"] for r in sel], [r["speedup"] for r in sel], "o-", label=f"Dask, {model}")
    ax.plot([1, 2], [1, 2], "k:", label="linear")
    ax.set_xlabel("worker processes (one thread each)")
    ax.set_title("speed-up of the Dask bake (median wall time,\npaired rounds) over one worker")
    ax.legend(fontsize=7)
fig.tight_layout()
fig.savefig(f"{out}/shards.png", dpi=110)

# The paper estimate from the closed stand-in's row at S = 8.
base = [r for r in rows if r["level"] == "arena"] or rows
r = min(base, key=lambda x: abs(x["shards"] - 8))
threads = r["threads"]
atlas = r["size"] ** 2
# The share of a production page's texels that carry samples: the default arena (51k triangles,
# 1024²) covers 41.3% of its lightmap (hemilight_make_level's summary); the small sweep level
# (256²) only ~19%, most of it padding.
sampled_share = 0.413
hemicubes_per_sample = r["hemicubes"] / r["bounces"] / r["sampled_texels"]
core_seconds_per_hemicube = (r["job_seconds"] - r["shards"] * r["bounces"] * r["setup_seconds"]) * threads / r["hemicubes"]
setup_per_texel = r["setup_seconds"] / atlas
merge_per_texel = r["merge_seconds"] / r["bounces"] / atlas
shard_bytes_per_sample = r["shard_bytes_per_pass"] / r["sampled_texels"]
pages, page_size, bounces = 32, 2048, 3
texels = pages * page_size * page_size
samples = texels * sampled_share
with open(f"{out}/dask_estimate.csv", "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["machines", "cores_per_machine", "shards", "link_gbit", "compute_s", "setup_s", "merge_s", "transfer_s",
                "total_s", "state_gb_per_machine_per_pass", "shard_gb_per_pass", "compute_share"])
    for link in (1, 10):
        for m in (1, 8, 64):
            s = 4 * m
            compute = samples * hemicubes_per_sample * core_seconds_per_hemicube / (m * threads)
            setup = (s / m) * setup_per_texel * texels
            merge = merge_per_texel * texels
            state_bytes = 16 * texels
            shard_bytes = shard_bytes_per_sample * samples
            transfer = ((m if m > 1 else 0) * state_bytes + (shard_bytes if m > 1 else 0)) / (link * 1e9 / 8)
            per_pass = compute + setup + merge + transfer
            total = bounces * per_pass
            w.writerow([m, int(threads), s, link, round(bounces * compute), round(bounces * setup), round(bounces * merge),
                        round(bounces * transfer), round(total), round(state_bytes / 1e9, 2), round(shard_bytes / 1e9, 2),
                        round(compute / per_pass, 3)])
print(f"estimate inputs (arena, S = {int(r['shards'])}): sampled share (assumed) {sampled_share:.3f}, hemicubes per sample and pass "
      f"{hemicubes_per_sample:.3f}, {1e3 * core_seconds_per_hemicube:.3f} core-ms per hemicube, set-up "
      f"{1e9 * setup_per_texel:.1f} ns per atlas texel, merge {1e9 * merge_per_texel:.1f} ns per texel and pass, "
      f"{shard_bytes_per_sample:.1f} bytes per sample and pass")
