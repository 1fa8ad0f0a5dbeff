"""Charts of exact edge coverage against point sampling (docs/bench/edge.png, from
edge_accuracy.csv and edge_cost.csv written by sweep_edge): worst |relative error| of E against
Lambert's formula per polygon family and N; the rectangle's signed error; and the cost,
as the median of the paired rounds' time ratios per scene and N, with worst error against time
per hemicube on the Cornell box. Also prints the tables docs/raster.md quotes."""
import sys
from collections import defaultdict
from statistics import median

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_csv

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
acc = load_csv(f"{out}/edge_accuracy.csv")
cost = load_csv(f"{out}/edge_cost.csv")

worst = defaultdict(float)  # (family, N, mode) -> worst |relative error|
for r in acc:
    k = (r["family"], r["N"], r["mode"])
    worst[k] = max(worst[k], abs(r["rel_err"]))
families = list(dict.fromkeys(r["family"] for r in acc))
ns = sorted({r["N"] for r in acc})

fig, axes = plt.subplots(1, 4, figsize=(18, 4.2))
ax = axes[0]
colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
for i, fam in enumerate(families):
    c = colours[i % len(colours)]
    for mode, style in (("point", "--"), ("edge", "-")):
        ax.loglog(ns, [max(worst[(fam, n, mode)], 1e-7) for n in ns], style, color=c, marker="o", ms=3,
                  label=f"{fam} ({mode})" if mode == "edge" else None)
ax.axhline(2e-3, color="k", lw=0.6, ls=":")
ax.set_title("worst |error| per family: point sampling dashed, edge coverage solid", fontsize=8)
ax.set_xlabel("hemicube resolution N")
ax.set_ylabel("|E - E_Lambert| / E_Lambert")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=6)

ax = axes[1]
for mode, style in (("point", "s--"), ("edge", "o-")):
    pts = sorted((r["N"], r["rel_err"]) for r in acc if r["family"] == "rectangle" and r["mode"] == mode)
    ax.semilogx([p[0] for p in pts], [100 * p[1] for p in pts], style, label=mode)
ax.axhline(0, color="k", lw=0.6)
ax.set_title("rectangle [-0.5,0.5]x[0.3,0.9], z = 1 (E = 0.285808)", fontsize=8)
ax.set_xlabel("hemicube resolution N")
ax.set_ylabel("signed error (%)")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=7)

# time_ratio = point hemicubes/s over edge hemicubes/s of one round: the time with edge coverage
# over the time without.
ratios = defaultdict(list)   # (scene, N) -> per-round time ratios
rates = defaultdict(list)    # (scene, N, mode) -> hemicubes/s
for r in cost:
    ratios[(r["scene"], r["N"])].append(r["time_ratio"])
    rates[(r["scene"], r["N"], "point")].append(r["point_hemicubes_per_s"])
    rates[(r["scene"], r["N"], "edge")].append(r["edge_hemicubes_per_s"])
ratios = {k: median(v) for k, v in ratios.items()}
scenes = list(dict.fromkeys(r["scene"] for r in cost))
cns = sorted({r["N"] for r in cost})
ax = axes[2]
width = 0.8 / len(cns)
for j, n in enumerate(cns):
    ax.bar([i + j * width for i in range(len(scenes))], [ratios[(s, n)] for s in scenes], width, label=f"N = {int(n)}")
ax.axhline(1.5, color="k", lw=0.6, ls=":")
ax.set_xticks([i + 0.4 - width / 2 for i in range(len(scenes))])
ax.set_xticklabels(scenes, fontsize=7, rotation=15)
ax.set_ylabel("time ratio, edge / point (median of rounds)")
ax.set_title("cost: render + integrate per hemicube", fontsize=8)
ax.legend(fontsize=7)

ax = axes[3]
for mode, style in (("point", "s--"), ("edge", "o-")):
    xs, ys = [], []
    for n in cns:
        if ("cornell_box_32", n, mode) not in rates:
            continue
        xs.append(1e6 / median(rates[("cornell_box_32", n, mode)]))
        ys.append(max(worst[(f, n, mode)] for f in families))
        ax.annotate(f"N={int(n)}", (xs[-1], ys[-1]), fontsize=6)
    ax.loglog(xs, ys, style, label=mode)
ax.set_xlabel("us per hemicube (Cornell box, render + integrate)")
ax.set_ylabel("worst |error| over all families")
ax.set_title("error against time", fontsize=8)
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=7)
fig.tight_layout()
fig.savefig(f"{out}/edge.png", dpi=100)

print("worst |relative error| (%) by family, N =", " ".join(str(int(n)) for n in ns))
for fam in families:
    for mode in ("point", "edge"):
        print(f"| {fam} | {mode} | " + " | ".join(f"{100 * worst[(fam, n, mode)]:.3g}" for n in ns) + " |")
print("time ratio (edge / point), median of paired rounds")
for s in scenes:
    print(f"| {s} | " + " | ".join(f"{ratios[(s, n)]:.2f}" for n in cns) + " | " +
          " | ".join(f"{median(rates[(s, n, 'point')]):.0f} / {median(rates[(s, n, 'edge')]):.0f}" for n in cns) + " |")
