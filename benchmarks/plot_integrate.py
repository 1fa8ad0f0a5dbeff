"""Charts of hemicube integration: translation-gradient error against N per scene and estimator
(docs/bench/integrate_accuracy.png, from integrate_sweep.csv), and integration throughput
against N per mode (docs/bench/integrate.png, from integrate.csv)."""
import sys
from collections import defaultdict

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_csv, load_gbench, medians

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"

rows = load_csv(f"{out}/integrate_sweep.csv")
scenes = list(dict.fromkeys(r["scene"] for r in rows))
fig, axes = plt.subplots(1, len(scenes), figsize=(4 * len(scenes), 3.6), sharey=True)
for ax, scene in zip(axes, scenes):
    for est, style in (("simple", "s:"), ("classified", "^--"), ("great_arc", "o-"), ("great_arc_extrapolated", "D-")):
        pts = sorted((r["N"], r["g_t_rel_err"]) for r in rows if r["scene"] == scene and r["estimator"] == est)
        ax.loglog([p[0] for p in pts], [max(p[1], 1e-6) for p in pts], style, label=f"g_t {est}")
    pts = sorted((r["N"], r["E_rel_err"]) for r in rows if r["scene"] == scene and r["estimator"] == "great_arc")
    ax.loglog([p[0] for p in pts], [max(p[1], 1e-7) for p in pts], "k-", lw=0.8, label="E")
    ax.set_title(scene, fontsize=9)
    ax.set_xlabel("hemicube resolution N")
    ax.grid(True, which="both", alpha=0.3)
axes[0].set_ylabel("relative error vs closed form")
axes[0].legend(fontsize=7)
fig.tight_layout()
fig.savefig(f"{out}/integrate_accuracy.png", dpi=110)
print(f"wrote {out}/integrate_accuracy.png")

m = medians(load_gbench(f"{out}/integrate.csv"))
series = defaultdict(list)
for name, r in m.items():
    if name.startswith("integrate_hemicube/"):
        parts = dict(p.split(":") for p in name.split("/")[1:])
        n = int(parts["N"])
        series[int(parts["mode"])].append((n, r["items_per_second"] / (3 * n * n)))
labels = {0: "E + distances", 1: "+ rotation gradient", 2: "+ translation gradient (great arc)", 3: "+ directional (SH, HL2)"}
fig, ax = plt.subplots(figsize=(5.5, 3.8))
for mode, pts in sorted(series.items()):
    pts.sort()
    ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=labels[mode])
ax.set_xlabel("hemicube resolution N")
ax.set_ylabel("hemicubes integrated per second (1 core, median)")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(f"{out}/integrate.png", dpi=110)
print(f"wrote {out}/integrate.png")
