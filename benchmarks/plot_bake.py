"""Draws docs/bench/bake.png from docs/bench/bake_sweep.csv (benchmarks/sweep_bake.cpp):
bake time per configuration (left) and the cache's error against a hemicube at every texel
against the fraction of texels given a hemicube (right)."""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from bench_csv import load_csv  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
rows = load_csv(f"{out}/bake_sweep.csv")
fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5))
labels, times, colors = [], [], []
for r in rows:
    labels.append(f"{r['scene'][:7]} {int(r['size'])}² b{int(r['bounces'])} t{int(r['threads'])}")
    times.append(r["seconds"])
    colors.append("tab:blue" if r["scene"] == "hexagon_room" else "tab:red")
a.barh(range(len(rows)), times, color=colors)
a.set_yticks(range(len(rows)))
a.set_yticklabels(labels, fontsize=7)
a.invert_yaxis()
a.set_xlabel("bake wall time (s), N = 64, a = 0.2")
a.set_title("End-to-end bake (blue: hexagon room, red: Cornell box)")
for scene, marker in (("hexagon_room", "o"), ("cornell_box", "s")):
    pts = [r for r in rows if r["scene"] == scene and int(r["threads"]) == 2]
    b.scatter([100 * r["hemicube_fraction"] for r in pts], [100 * r["rms_error"] for r in pts], marker=marker, label=scene)
    for r in pts:
        b.annotate(f"{int(r['size'])}² b{int(r['bounces'])}", (100 * r["hemicube_fraction"], 100 * r["rms_error"]), fontsize=7)
b.set_xlabel("hemicubes per sampled texel and bounce (%)")
b.set_ylabel("relative RMS error vs a hemicube per texel (%)")
b.set_title("Cache error against the per-texel hemicube bake")
b.legend()
fig.tight_layout()
fig.savefig(f"{out}/bake.png", dpi=110)
print(f"wrote {out}/bake.png")
