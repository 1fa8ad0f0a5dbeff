"""Chart of what exact edge coverage buys downstream (docs/bench/edge_downstream.png, from
edge_downstream.csv written by sweep_edge_downstream), and the tables docs/raster.md quotes.

Top row, per scene: RMS relative error of per-point hemicubes against the converged reference
against the time per hemicube (median of the paired one-thread rounds), N = 16 ... 128, point
sampling and edge coverage; the 1% line, and the first N under it marked. Bottom row, per scene:
the cache's RMS error against the hemicubes it rendered, point sampling at each threshold a and
edge coverage at the threshold matched to the same count, with the per-point hemicube's own error
at the cache's N as dotted lines (what the cache cannot beat). The silhouette rows (closed boxes
against their front faces only) are printed, not drawn.

usage: plot_edge_downstream.py [DIR [NAME]]   (DIR holds NAME.csv, by default edge_downstream.csv; the
       chart is written there as NAME.png. The open scenes: NAME = edge_downstream_open, the CSV of
       `benchmarks/run.sh edge_downstream_open`; the same chart, a column per scene.)
"""
import sys
from collections import defaultdict
from statistics import median

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_csv

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
csv_name = sys.argv[2] if len(sys.argv) > 2 else "edge_downstream"
rows = load_csv(f"{out}/{csv_name}.csv")
scenes = list(dict.fromkeys(r["scene"] for r in rows if r["part"] in ("cost", "per_point", "cache")))
MODES = (("point", "point sampling", "s--", "tab:orange"), ("edge", "edge coverage", "o-", "tab:blue"))


def part(name, **match):
    return [r for r in rows if r["part"] == name and all(r[k] == v for k, v in match.items())]


def paired_ratios(part_rows):
    """Per-round time ratios edge / point (seconds per hemicube), rounds paired by index."""
    by_round = defaultdict(dict)
    for r in part_rows:
        by_round[int(r["round"])][r["mode"]] = r["seconds"] / r["hemicubes"]
    return [v["edge"] / v["point"] for v in by_round.values() if "edge" in v and "point" in v]


# ---- tables ---------------------------------------------------------------------------------
print("cost (render + integrate, one thread): median hemicubes/s per way and the median of the paired rounds' time ratios")
for s in scenes:
    c = part("cost", scene=s)
    if not c:
        continue
    rate = {m: median(r["hemicubes_per_s"] for r in c if r["mode"] == m) for m, *_ in MODES}
    ratios = paired_ratios(c)
    print(f"| {s} | {int(c[0]['N'])} | {rate['point']:.0f} | {rate['edge']:.0f} | {median(ratios):.1f}x "
          f"({min(ratios):.1f}-{max(ratios):.1f}, {len(ratios)} rounds) |")

print("\nconverged reference checks")
for r in part("reference"):
    print(f"  {r['scene']}: edge N = {int(r['N'])} at {int(r['points'])} points, {r['seconds']:.1f} s")
for r in part("check"):
    print(f"  {r['scene']}: reference vs {r['mode']} N = {int(r['N'])} on {int(r['points'])} points: "
          f"RMS {100 * r['rms_rel_err']:.3f}%, max {100 * r['max_rel_err']:.2f}%")

first_under = {}  # (scene, mode) -> (N, time per hemicube in us, rms)
time_of = {}      # (scene, N, mode) -> median seconds per hemicube
ratio_of = {}     # (scene, N) -> median paired ratio
print("\nper-point hemicubes against the reference: RMS % (max %), time per hemicube (us), time ratio edge/point")
for s in scenes:
    pp = part("per_point", scene=s)
    if not pp:
        continue
    ns = sorted({int(r["N"]) for r in pp})
    for n in ns:
        t = part("time", scene=s, N=n)
        for m, *_ in MODES:
            time_of[(s, n, m)] = median(r["seconds"] / r["hemicubes"] for r in t if r["mode"] == m)
        ratio_of[(s, n)] = median(paired_ratios(t))
        cells = []
        for m, *_ in MODES:
            r = next(r for r in pp if int(r["N"]) == n and r["mode"] == m)
            cells.append(f"{100 * r['rms_rel_err']:.2f} ({100 * r['max_rel_err']:.1f})")
            if r["rms_rel_err"] < 0.01 and (s, m) not in first_under:
                first_under[(s, m)] = (n, 1e6 * time_of[(s, n, m)], r["rms_rel_err"])
        print(f"| {s} | {n} | {cells[0]} | {cells[1]} | {1e6 * time_of[(s, n, 'point')]:.0f} | "
              f"{1e6 * time_of[(s, n, 'edge')]:.0f} | {ratio_of[(s, n)]:.1f}x |")
print("\nfirst N under 1% RMS")
for s in scenes:
    for m, *_ in MODES:
        f = first_under.get((s, m))
        print(f"  {s} {m}: " + (f"N = {f[0]}, {f[1]:.0f} us per hemicube (RMS {100 * f[2]:.2f}%)" if f else "none"))

print("\ncache at a fixed hemicube budget: a, hemicubes, RMS % (max %), seconds (all threads)")
for s in scenes:
    pts = part("cache", scene=s, mode="point")
    eds = [r for r in part("cache", scene=s, mode="edge") if r["matched"] == 1]
    for p, e in zip(pts, eds):
        print(f"| {s} | {p['a']:.2f} / {e['a']:.3f} | {int(p['hemicubes'])} / {int(e['hemicubes'])} | "
              f"{100 * p['rms_rel_err']:.2f} ({100 * p['max_rel_err']:.1f}) | {100 * e['rms_rel_err']:.2f} "
              f"({100 * e['max_rel_err']:.1f}) | {p['seconds']:.1f} / {e['seconds']:.1f} |")

print("\nsilhouettes of closed meshes: 8 boxes under a sky of 1 against the closed form, RMS % (mean signed %)")
sil = part("silhouette")
for shape in dict.fromkeys(r["scene"] for r in sil):
    for m, *_ in MODES:
        cells = [f"{100 * r['rms_rel_err']:.3f} ({100 * r['mean_rel_err']:+.3f})"
                 for r in sorted((r for r in sil if r["scene"] == shape and r["mode"] == m), key=lambda r: r["N"])]
        print(f"| {shape} | {m} | " + " | ".join(cells) + " |")

# ---- chart ----------------------------------------------------------------------------------
if not scenes:
    sys.exit(f"plot_edge_downstream: no rows in {csv_name}.csv")
fig, axes = plt.subplots(2, len(scenes), figsize=(5.2 * len(scenes), 8.4), squeeze=False)
for col, s in enumerate(scenes):
    ax = axes[0][col]
    pp = part("per_point", scene=s)
    for m, label, style, colour in MODES:
        pts = sorted((int(r["N"]), r["rms_rel_err"]) for r in pp if r["mode"] == m)
        if not pts:
            continue
        xs = [1e6 * time_of[(s, n, m)] for n, _ in pts]
        ax.loglog(xs, [100 * e for _, e in pts], style, color=colour, ms=4, label=label)
        for x, (n, e) in zip(xs, pts):
            ax.annotate(str(n), (x, 100 * e), fontsize=6, xytext=(3, 3), textcoords="offset points", color=colour)
        f = first_under.get((s, m))
        if f:
            ax.plot([f[1]], [100 * f[2]], "*", color=colour, ms=14, mec="k",
                    label=f"{label}: first under 1% at N = {f[0]}")
    ax.axhline(1.0, color="k", lw=0.8, ls=":")
    ns_here = sorted({int(r["N"]) for r in pp})
    if ns_here:
        ax.set_title(f"{s}: a hemicube per point, N = {ns_here[0]}-{ns_here[-1]}", fontsize=9)
    ax.set_xlabel("time per hemicube (us, render + integrate, one thread)")
    ax.set_ylabel("RMS relative error vs converged (%)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)

    ax = axes[1][col]
    cache_n = None
    for m, label, style, colour in MODES:
        cr = [r for r in part("cache", scene=s, mode=m) if r["matched"] == 1]
        if not cr:
            continue
        cache_n = int(cr[0]["N"])
        cr.sort(key=lambda r: r["a"])  # in the order of the thresholds (the count need not fall monotonically)
        ax.loglog([r["hemicubes"] for r in cr], [100 * r["rms_rel_err"] for r in cr], style, color=colour, ms=4,
                  label=f"cache, {label}")
        for r in cr:
            ax.annotate(f"a={r['a']:.2g}", (r["hemicubes"], 100 * r["rms_rel_err"]), fontsize=6, xytext=(3, 3),
                        textcoords="offset points", color=colour)
        own = [r for r in part("per_point", scene=s, mode=m) if int(r["N"]) == cache_n]
        if own:
            ax.axhline(100 * own[0]["rms_rel_err"], color=colour, lw=0.8, ls=":",
                       label=f"a hemicube per point, {label}")
    ax.axhline(1.0, color="k", lw=0.8, ls=":")
    ax.set_title(f"{s}: the cache at N = {cache_n}, thresholds matched per way", fontsize=9)
    ax.set_xlabel("hemicubes rendered")
    ax.set_ylabel("RMS relative error vs converged (%)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
fig.tight_layout()
fig.savefig(f"{out}/{csv_name}.png", dpi=110)
print(f"\nwrote {out}/{csv_name}.png")
