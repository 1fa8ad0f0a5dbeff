"""Chart: irradiance RMS relative error against time per point, hemicubes (N = 8 ... 256) beside
cosine-weighted and stratified Embree rays (docs/bench/hemicube_vs_rays.png)."""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_csv

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
rows = load_csv(f"{out}/hemicube_vs_rays_sweep.csv")
scenes = list(dict.fromkeys(r["scene"] for r in rows))
fig, axes = plt.subplots(1, len(scenes), figsize=(4.4 * len(scenes), 3.8), sharey=True)
for ax, scene in zip(axes, scenes):
    for method, style, label in (("hemicube", "o-", "hemicube (N)"), ("rays", "s--", "Embree, cosine-weighted (rays)"),
                                 ("rays_stratified", "^-.", "Embree, stratified (rays)")):
        pts = sorted((r["seconds_per_point"], r["rms_rel_err"], r["budget"]) for r in rows
                     if r["scene"] == scene and r["method"] == method)
        ax.loglog([1e6 * p[0] for p in pts], [100 * p[1] for p in pts], style, label=label)
        for p in pts:
            ax.annotate(str(int(p[2])), (1e6 * p[0], 100 * p[1]), fontsize=6, alpha=0.7)
    ax.set_title(scene, fontsize=10)
    ax.set_xlabel("time per point, one core (us)")
    ax.grid(True, which="both", alpha=0.3)
axes[0].set_ylabel("RMS relative error of E (%)")
axes[0].legend(fontsize=7)
fig.tight_layout()
fig.savefig(f"{out}/hemicube_vs_rays.png", dpi=110)
print(f"wrote {out}/hemicube_vs_rays.png")
