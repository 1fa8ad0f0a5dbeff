"""Chart of the rasterizer's level of detail (docs/bench/lod.png, from lod_sweep.csv written by
sweep_lod): per stand-in level, the relative RMS error of the irradiance against the exact render
and the time ratio (LOD / exact, median of paired rounds) against the threshold lod_texels, one
line per hemicube resolution N."""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_csv

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
rows = load_csv(f"{out}/lod_sweep.csv")
levels = list(dict.fromkeys(r["level"] for r in rows))
fig, axes = plt.subplots(2, len(levels), figsize=(4.2 * len(levels), 7), squeeze=False)
for j, level in enumerate(levels):
    for n in sorted({r["N"] for r in rows if r["level"] == level}):
        sel = [r for r in rows if r["level"] == level and r["N"] == n]
        x = [r["lod_texels"] for r in sel]
        axes[0][j].plot(x, [100 * r["rms_error"] for r in sel], "o-", label=f"N = {int(n)}")
        axes[1][j].plot(x, [r["time_ratio"] for r in sel], "o-", label=f"N = {int(n)}")
    axes[0][j].set_title(level)
    axes[0][j].set_xscale("log", base=2)
    axes[1][j].set_xscale("log", base=2)
    axes[0][j].set_ylabel("RMS error of E vs exact (%)")
    axes[1][j].set_ylabel("time, LOD / exact")
    axes[1][j].axhline(1.0, color="grey", lw=0.8)
    axes[1][j].set_xlabel("lod_texels")
    axes[0][j].legend()
fig.tight_layout()
fig.savefig(f"{out}/lod.png", dpi=110)
for r in rows:
    print(f"{r['level']:13s} N={int(r['N']):4d} lod={r['lod_texels']:4g}: RMS {100 * r['rms_error']:.4f}% "
          f"max {100 * r['max_error']:.3f}% proxies {r['lod_nodes']:.1f} time x{r['time_ratio']:.3f}")
