"""Chart of the irradiance cache on the stand-in levels (sweep_cache_levels; docs/cache.md, "Levels").

  plot_cache_levels.py DIR   draws DIR/cache_levels.png from DIR/cache_levels.csv
                             (bash benchmarks/run.sh cache_levels)

Left: the share of the sampled texels given a hemicube, per level and lightmap size, before
(variant legacy) and now (default); the issue's target (25% at 1024²) as a line. Middle: the
relative RMS error against the converged reference (sqrt(sum dY^2 / sum Y^2)), the 1% target as a
line. Right: why the points given a hemicube (now) were open, as shares of the hemicubes
(cache_stats::hemicubes_by_reason).
"""
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_csv


def main():
    d = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
    rows = load_csv(os.path.join(d, "cache_levels.csv"))
    keys = []
    for r in rows:
        k = (r["level"], int(r["size"]))
        if k not in keys:
            keys.append(k)
    variants = ["legacy", "default"]
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8))
    width = 0.38
    labels = [f"{l}\n{s}²" for l, s in keys]
    for vi, v in enumerate(variants):
        share, err = [], []
        for k in keys:
            m = [r for r in rows if (r["level"], int(r["size"])) == k and r["variant"] == v]
            share.append(100 * m[0]["hemicube_share"] if m else 0)
            err.append(100 * m[0]["rel_rms_vs_converged"] if m else 0)
        x = [i + (vi - 0.5) * width for i in range(len(keys))]
        axes[0].bar(x, share, width, label=v)
        axes[1].bar(x, err, width, label=v)
    axes[0].axhline(25, color="k", ls="--", lw=0.8)
    axes[1].axhline(1, color="k", ls="--", lw=0.8)
    axes[0].set_ylabel("texels given a hemicube (%)")
    axes[1].set_ylabel("relative RMS vs converged (%)")
    for ax in axes[:2]:
        ax.set_xticks(range(len(keys)))
        ax.set_xticklabels(labels, fontsize=8)
        ax.legend()
    causes = [("open_uncovered", "uncovered"), ("open_disagree", "records disagree"), ("open_lone_change", "lone change"),
              ("open_lone_reach", "lone reach"), ("open_nearby", "nearby disagrees")]
    now = [next((r for r in rows if (r["level"], int(r["size"])) == k and r["variant"] == "default"), None) for k in keys]
    bottom = [0.0] * len(keys)
    for col, label in causes:
        vals = []
        for r in now:
            if not r or not r["hemicubes"]:
                vals.append(0)
                continue
            vals.append(100 * r[col] / r["hemicubes"])
        axes[2].bar(range(len(keys)), vals, 0.6, bottom=bottom, label=label)
        bottom = [b + v for b, v in zip(bottom, vals)]
    axes[2].set_xticks(range(len(keys)))
    axes[2].set_xticklabels(labels, fontsize=8)
    axes[2].set_ylabel("share of the hemicubes (%), now")
    axes[2].legend(fontsize=7)
    fig.suptitle("The irradiance cache on the stand-in levels (N = 64, a = 0.2, one bounce, sky)")
    fig.tight_layout()
    fig.savefig(os.path.join(d, "cache_levels.png"), dpi=110)


if __name__ == "__main__":
    main()
