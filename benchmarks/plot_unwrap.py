"""Draws docs/bench/unwrap.png from docs/bench/unwrap_sweep.csv and unwrap_sweep_bake.csv
(benchmarks/sweep_unwrap.cpp): atlas utilisation per case (the stand-in levels' own shelf-packed
UVs beside, where they are at the same size), Sander's L2 and L-infinity stretch per case, the
unwrap's wall time against the triangle count (log-log, median of the runs, min-max as error
bars), and the bakes' relative RMS error against their converged references on generated UVs and on
the built-in scenes' shelf charts.

usage: plot_unwrap.py [folder]   (default docs/bench)
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from bench_csv import load_csv  # noqa: E402


def utilisation(ax, rows):
    names = [r["scene"] for r in rows]
    y = np.arange(len(rows))
    ax.barh(y - 0.2, [100 * r["utilisation"] for r in rows], 0.4, color="tab:blue", label="unwrap_lightmap")
    own = [100 * r["own_utilisation"] if r["own_utilisation"] >= 0 else 0 for r in rows]
    ax.barh(y + 0.2, own, 0.4, color="tab:gray", label="the level's own UVs (same size)")
    ax.axvline(70, color="k", lw=0.8, ls=":")
    ax.set_yticks(y)
    ax.set_yticklabels([f"{n} ({int(r['triangles']):,} tris, {int(r['pages'])}x{int(r['page_size'])}²)" for n, r in zip(names, rows)],
                       fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel("atlas utilisation, % (texels covered / texels of the pages)")
    ax.set_xlim(0, 100)
    ax.legend(fontsize=7, loc="lower right")


def stretch(ax, rows):
    y = np.arange(len(rows))
    ax.barh(y - 0.2, [r["stretch_l2"] - 1 for r in rows], 0.4, color="tab:green", label="L2 - 1")
    ax.barh(y + 0.2, [r["stretch_linf"] - 1 for r in rows], 0.4, color="tab:orange", label="L∞ - 1")
    ax.set_xscale("symlog", linthresh=1e-4)
    ax.set_yticks(y)
    ax.set_yticklabels([r["scene"] for r in rows], fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel("stretch - 1 (Sander et al.; 0 = isometric)")
    ax.legend(fontsize=7, loc="lower right")


def timing(ax, rows):
    t = np.array([r["triangles"] for r in rows])
    med = np.array([r["seconds_median"] for r in rows])
    lo = med - np.array([r["seconds_min"] for r in rows])
    hi = np.array([r["seconds_max"] for r in rows]) - med
    ax.errorbar(t, med, yerr=[lo, hi], fmt="o", color="tab:blue", ms=4, capsize=2)
    for r in rows:
        ax.annotate(r["scene"], (r["triangles"], r["seconds_median"]), fontsize=6, xytext=(3, 3), textcoords="offset points")
    grid = np.geomspace(max(t.min(), 10), t.max(), 32)
    k = np.median(med[t >= 1e4] / t[t >= 1e4]) if np.any(t >= 1e4) else med[-1] / t[-1]
    ax.plot(grid, k * grid, ":", color="gray", lw=1, label="∝ T")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("triangles")
    ax.set_ylabel("unwrap_lightmap wall time, s (median; min-max)")
    ax.legend(fontsize=7)


def bake_error(ax, rows):
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    x = np.arange(len(scenes))
    for i, (uvs, color) in enumerate((("unwrap", "tab:blue"), ("shelf", "tab:gray"))):
        vals = [next((100 * r["rms_error"] for r in rows if r["scene"] == s and r["uvs"] == uvs), 0) for s in scenes]
        inval = [next((int(r["invalid_texels"]) for r in rows if r["scene"] == s and r["uvs"] == uvs), 0) for s in scenes]
        bars = ax.bar(x + (i - 0.5) * 0.4, vals, 0.4, color=color, label=f"{uvs} UVs")
        for b, n in zip(bars, inval):
            ax.annotate(f"{n} inv.", (b.get_x() + b.get_width() / 2, b.get_height()), fontsize=6, ha="center", va="bottom")
    ax.set_xticks(x)
    sizes = {r["scene"]: int(r["size"]) for r in rows}
    ax.set_xticklabels([f"{s} {sizes[s]}²" for s in scenes], fontsize=7, rotation=20, ha="right")
    ax.set_ylabel("relative RMS vs N = 256 per texel, % (cache a = 0.2, N = 64, 2 bounces)")
    ax.legend(fontsize=7)


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
    rows = load_csv(os.path.join(folder, "unwrap_sweep.csv"))
    bake_path = os.path.join(folder, "unwrap_sweep_bake.csv")
    bake = load_csv(bake_path) if os.path.exists(bake_path) else []
    fig, axes = plt.subplots(2, 2, figsize=(14, 10))
    utilisation(axes[0][0], rows)
    stretch(axes[0][1], rows)
    timing(axes[1][0], rows)
    if bake:
        bake_error(axes[1][1], bake)
    fig.suptitle("Lightmap UVs (unwrap.hpp): utilisation, stretch, time; bakes on them against converged references")
    fig.tight_layout()
    fig.savefig(os.path.join(folder, "unwrap.png"), dpi=110)


if __name__ == "__main__":
    main()
