"""Chart of the rasterizer benchmark: hemicubes per second against N, per scene, one thread
(solid) and all threads (dashed), with the targets at N = 64 marked."""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_gbench, medians

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
m = medians(load_gbench(f"{out}/raster.csv"))
# name: raster/<scene>/N:<n>/threads:<t>[/...]; items_per_second is per CPU second for one thread,
# per wall-clock second for all threads./real_time
# The stand-in levels' rows (raster/<level>/N:64/threads:<t>/culling:<on|off>, N = 64 only) are left
# out: docs/raster.md tables them, and plot_raster_levels.py charts their paired-round ratios.
series = {}
for name, row in m.items():
    parts = name.split("/")
    if any(p.startswith("culling:") for p in parts):
        continue
    scene, n, threads = parts[1], int(parts[2].split(":")[1]), int(parts[3].split(":")[1])
    series.setdefault((scene, threads), []).append((n, row["items_per_second"]))

fig, ax = plt.subplots(figsize=(7.5, 5))
scenes = sorted({s for s, _ in series}, key=lambda s: [k for k in series if k[0] == s][0][0])
order = ["cornell_box_32", "hexagon_room_496", "hexagon_room_1062", "heightfield_10k", "heightfield_100k", "heightfield_1M"]
scenes = [s for s in order if s in scenes] + [s for s in scenes if s not in order]
colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
max_threads = max(t for _, t in series)
for i, scene in enumerate(scenes):
    for threads in sorted({t for s, t in series if s == scene}):
        pts = sorted(series[(scene, threads)])
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-" if threads == 1 else "s--",
                  color=colors[i % len(colors)], label=f"{scene}, {threads} thread{'s' if threads > 1 else ''}")
# The targets and the reference figure are for N = 64: mark them there.
ax.plot([64], [30000], marker="*", ms=12, color="black", ls="none")
ax.annotate("target: Cornell box, 1 core (30k/s)", (64, 30000), (70, 45000), fontsize=7)
ax.plot([64], [20 * 1400], marker="*", ms=12, color="grey", ls="none")
ax.annotate("target: ~1k triangles, 2 cores (20 x 1,400/s)", (64, 28000), (70, 19000), fontsize=7, color="grey")
ax.plot([64, 64], [1400, 2200], color="grey", lw=6, alpha=0.5)
ax.annotate("GPU lightmapper via Mesa, 731 triangles", (64, 1800), (70, 2300), fontsize=7, color="grey")
ns = sorted({p[0] for pts in series.values() for p in pts})
ax.set_xticks(ns)
ax.set_xticklabels([str(n) for n in ns])
ax.minorticks_off()
ax.set_xlabel("hemicube resolution N (3 N² texels)")
ax.set_ylabel("hemicubes per second (median; 1 thread: per CPU second)")
ax.set_title("hemicube_rasterizer::render, render only")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=6.5, ncol=2, loc="lower left")
fig.tight_layout()
fig.savefig(f"{out}/raster.png", dpi=120)
print(f"wrote {out}/raster.png")
