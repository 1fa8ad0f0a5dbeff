"""Draws docs/bench/seams.png from docs/bench/seams.csv and seams_cost.csv (benchmarks/sweep_seams.cpp):
per scene and size the coplanar seams' relative step RMS without and with stitching, the converged
reference's own, beside the bake's relative RMS error against that reference (left; scenes without
coplanar seams are labelled so); stitch_seconds against the stitched texels, log-log, with the
least-squares slope over the rows of the scenes that have seams (right). Prints the table of
docs/bake.md, "Seams", and the fitted slopes.

usage: plot_seams.py [folder]   (default docs/bench)
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from bench_csv import load_csv  # noqa: E402


def label(r):
    return f"{r['scene']} ({r['uvs']}) {int(r['size'])}²"


def steps(ax, rows):
    y = np.arange(len(rows))
    floor = 1e-4  # where a value of 0 is drawn (no coplanar seams)
    val = lambda k: [max(r[k], floor) for r in rows]  # noqa: E731
    ax.barh(y - 0.27, val("rms_off"), 0.27, color="tab:red", label="seam RMS, stitching off")
    ax.barh(y, val("rms_on"), 0.27, color="tab:green", label="seam RMS, stitching on")
    ax.barh(y + 0.27, val("rms_ref"), 0.27, color="tab:gray", label="seam RMS of the reference (N = 128 per texel)")
    ax.scatter(val("error_off"), y, marker="D", color="k", s=22, zorder=3, label="bake's error vs the reference (off)")
    ax.scatter(val("error_on"), y, marker="x", color="tab:purple", s=30, zorder=3, label="bake's error vs the reference (on)")
    for i, r in enumerate(rows):
        if int(r["coplanar_pieces"]) == 0:
            ax.annotate("no coplanar seams", (floor * 1.3, i), fontsize=6, va="center", color="0.3")
    ax.set_xscale("log")
    ax.set_xlim(floor, 3)
    ax.set_yticks(y)
    ax.set_yticklabels([f"{label(r)}: {int(r['coplanar_pieces'])} pcs, {r['coplanar_length']:.0f} tx" for r in rows], fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel("relative step RMS along coplanar seams; relative RMS error (log)")
    ax.set_title("Coplanar seams before and after stitching, against the bake's own error", fontsize=9)
    ax.legend(fontsize=6, loc="lower right")


def fit(x, y):
    """Least-squares slope and intercept of log10 y against log10 x."""
    return np.polyfit(np.log10(x), np.log10(y), 1)


def cost(ax, rows, cost_rows):
    pts = [(r["scene"], r["seam_texels"], r["stitch_seconds"], r["search_seconds"], int(r["size"])) for r in rows + cost_rows
           if r["seam_texels"] > 0]
    scenes = sorted({p[0] for p in pts})
    markers = dict(zip(scenes, "osD^v<>p*h"))
    for s in scenes:
        q = sorted([p for p in pts if p[0] == s], key=lambda p: p[1])
        ax.plot([p[1] for p in q], [p[2] for p in q], marker=markers[s], ls="-", lw=0.8, label=s)
        for p in q:
            ax.annotate(f"{p[4]}²", (p[1], p[2]), fontsize=6, xytext=(3, -8), textcoords="offset points")
    x = np.array([p[1] for p in pts])
    y = np.array([p[2] for p in pts])
    slopes = {}
    if len(pts) >= 2:
        k, c = fit(x, y)
        slopes["all"] = k
        grid = np.geomspace(x.min(), x.max(), 16)
        ax.plot(grid, 10 ** c * grid ** k, ":", color="k", lw=1, label=f"fit, all rows: slope {k:.2f}")
    for s in scenes:  # per scene over its sizes: the order in the seams' texels at a fixed mesh
        q = [p for p in pts if p[0] == s]
        if len({p[4] for p in q}) >= 3:
            slopes[s] = fit([p[1] for p in q], [p[2] for p in q])[0]
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("texels set by stitching (bake_stats::seam_texels)")
    ax.set_ylabel("stitch_seconds (median of 3; seam search + solves)")
    ax.set_title("Cost of stitching: " + ", ".join(f"{s} slope {k:.2f}" for s, k in slopes.items() if s != "all"), fontsize=9)
    ax.legend(fontsize=6, loc="upper left")
    return slopes


def table(rows):
    print("| scene (UVs) | size | triangles | coplanar pieces (texels) | walled pieces (texels) | seam RMS off → on (reference) "
          "| p95 off → on | max off → on | over 2% off → on | bake's error vs reference off / on | interior change "
          "| all sampled / stitched texels change | seam texels | stitch (s) of bake (s) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    pct = lambda v: f"{100 * v:.2f}%"  # noqa: E731
    for r in rows:
        print(f"| {r['scene']} ({r['uvs']}) | {int(r['size'])}² | {int(r['triangles']):,} "
              f"| {int(r['coplanar_pieces'])} ({r['coplanar_length']:.0f}) | {int(r['walled_pieces'])} ({r['walled_length']:.0f}) "
              f"| {pct(r['rms_off'])} → **{pct(r['rms_on'])}** ({pct(r['rms_ref'])}) | {pct(r['p95_off'])} → {pct(r['p95_on'])} "
              f"| {pct(r['max_off'])} → {pct(r['max_on'])} | {pct(r['step_fraction_off'])} → {pct(r['step_fraction_on'])} "
              f"| **{pct(r['error_off'])}** / {pct(r['error_on'])} | {pct(r['interior_change'])} "
              f"| {pct(r['all_change'])} / {pct(r['seam_change'])} | {int(r['seam_texels']):,} "
              f"| {r['stitch_seconds']:.3f} of {r['seconds_on']:.2f} |")


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
    rows = load_csv(os.path.join(out, "seams.csv"))
    cost_path = os.path.join(out, "seams_cost.csv")
    cost_rows = load_csv(cost_path) if os.path.exists(cost_path) else []
    fig, (a, b) = plt.subplots(1, 2, figsize=(15, 6.5), gridspec_kw={"width_ratios": [1.25, 1]})
    steps(a, rows)
    slopes = cost(b, rows, cost_rows)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "seams.png"), dpi=110)
    table(rows)
    for s, k in slopes.items():
        print(f"log-log slope of stitch_seconds against seam_texels, {s}: {k:.2f}")
    print(f"wrote {out}/seams.png")


main()
