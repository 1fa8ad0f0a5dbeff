"""Chart of the rasterizer benchmark: hemicubes per second against N, per scene, one thread
(solid) and all threads (dashed), with the targets at N = 64 marked."""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_gbench, medians

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
m = medians(load_gbench(f"{out}/raster.csv"))
# name: raster/<scene>/N:<n>/threads:<t>/real_time
series = {}
for name, row in m.items():
    parts = name.split("/")
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
ax.axhline(30000, color="grey", lw=0.8, ls=":")
ax.text(16, 30000 * 1.08, "target: Cornell box, N = 64, 1 core (30k/s)", fontsize=7, color="grey")
ax.axhline(20 * 1400, color="grey", lw=0.8, ls="-.")
ax.text(16, 28000 * 0.80, "target: ~1k triangles, N = 64, 2 cores (20 x 1,400/s)", fontsize=7, color="grey")
ax.axhspan(1400, 2200, color="grey", alpha=0.15)
ax.text(16, 1500, "GPU lightmapper via Mesa, 731 triangles, N = 64", fontsize=7, color="grey")
ax.set_xlabel("hemicube resolution N (3 N² texels)")
ax.set_ylabel("hemicubes per second (median)")
ax.set_title("hemicube_rasterizer::render, render only")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=6.5, ncol=2, loc="lower left")
fig.tight_layout()
fig.savefig(f"{out}/raster.png", dpi=120)
print(f"wrote {out}/raster.png")
