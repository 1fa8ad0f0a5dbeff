"""Draws docs/bench/lights.png from docs/bench/lights_{direct,penumbra,cornell}.csv
(benchmarks/sweep_lights.cpp): the direct-light stage of the 654² hexagon-room bake against its
1 s target (left), the penumbra error of each light against a 4096-sample reference (middle), and
the cache's error on the Cornell box's indirect light against the fraction of texels given a
hemicube, with its light as an emissive quad and as a RECT light, per lightmap size (right)."""
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from bench_csv import load_csv  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
direct = load_csv(f"{out}/lights_direct.csv")
penumbra = load_csv(f"{out}/lights_penumbra.csv")
cornell = load_csv(f"{out}/lights_cornell.csv")
fig, (a, b, c) = plt.subplots(1, 3, figsize=(16, 4.8))

d = statistics.median(r["direct_seconds"] for r in direct)
t = statistics.median(r["bake_seconds"] for r in direct)
a.bar(["direct light", "whole bake"], [d, t], color=["tab:orange", "tab:gray"])
a.axhline(1.0, color="k", linestyle="--", linewidth=1)
a.text(1.45, 1.02, "direct-light target 1 s", ha="right", fontsize=8)
a.set_ylabel("wall time (s), median of runs, 2 threads")
a.set_title(f"Hexagon room t3, 654², 7 lights ({int(direct[0]['sampled_texels'])} texels)")

rows = [r for r in penumbra if int(r["penumbra_points"]) > 0]
labels = [f"{r['scene'][:12]} {r['type']} {r['radius']:g}" for r in rows]
b.barh(range(len(rows)), [100 * r["rms_error"] for r in rows], color="tab:blue", label="RMS")
b.scatter([100 * r["max_error"] for r in rows], range(len(rows)), color="tab:red", marker="|", s=80, label="max")
b.axvline(1.0, color="k", linestyle="--", linewidth=1)
b.set_yticks(range(len(rows)))
b.set_yticklabels([f"{lab} ({int(r['penumbra_points'])})" for lab, r in zip(labels, rows)], fontsize=7)
b.invert_yaxis()
b.set_xlabel("error in penumbrae (% of the unoccluded E)")
b.set_title("Soft shadows, default sampling vs 4096 samples")
b.legend(fontsize=8)

sizes = sorted({int(r["size"]) for r in cornell})
styles = dict(zip(sizes, ("-", "--", "-.", ":")))
for light, marker in (("emissive_quad", "o"), ("rect", "s")):
    for size in sizes:
        for n, color in ((64, "tab:blue"), (256, "tab:green")):
            pts = sorted((r for r in cornell if r["light"] == light and int(r["resolution"]) == n and int(r["size"]) == size),
                         key=lambda r: r["hemicube_fraction"])
            if not pts:
                continue
            c.plot([100 * r["hemicube_fraction"] for r in pts], [100 * r["rms_error"] for r in pts], marker=marker, color=color,
                   linestyle=styles[size] if light == "rect" else ":", alpha=1.0 if light == "rect" else 0.5,
                   label=f"{light.replace('_', ' ')}, {size}², N = {n}")
c.scatter([3, 10], [3, 1], marker="*", s=150, color="k", zorder=5, label="targets (3% at 3%, 1% at 10%)")
c.set_xscale("log")
c.set_yscale("log")
c.set_xlabel("hemicubes per sampled texel and bounce (%)")
c.set_ylabel("relative RMS of the indirect part (%)")
c.set_title("Cornell indirect (3 bounces) vs per texel N = 256")
c.legend(fontsize=7)
fig.tight_layout()
fig.savefig(f"{out}/lights.png", dpi=110)
print(f"wrote {out}/lights.png")
