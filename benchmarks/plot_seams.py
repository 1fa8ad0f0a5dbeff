"""Draws docs/bench/seams.png from docs/bench/seams.csv and seams_cost.csv (benchmarks/sweep_seams.cpp):
per scene and size the coplanar seams' relative step RMS without and with stitching, the converged
reference's own, beside the bake's relative RMS error against that reference (left; scenes without
coplanar seams are labelled so); bake_stats::stitch_seconds and the stitching's parts timed apart against the stitched texels,
log-log, with least-squares slopes (right). Prints the table of
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
    clean = [i for i, r in enumerate(rows) if r["coplanar_pieces"] > 0]
    ax.scatter([max(rows[i]["rms_on_clean"], floor) for i in clean], [i for i in clean], marker="|", color="darkgreen", s=90,
               zorder=3, label="seam RMS on, pieces with a valid texel on both sides")
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
    ax.legend(fontsize=6, loc="upper right", framealpha=0.95)


def fit(x, y):
    """Least-squares slope and intercept of log10 y against log10 x."""
    return np.polyfit(np.log10(x), np.log10(y), 1)


def cost(ax, rows, cost_rows):
    """stitch_seconds (the bake's figure, filled) and the stitching's own parts timed apart (search +
    assembly + one solve, hollow) against seam_texels; slopes per scene with three sizes or more."""
    pts = [r for r in rows + cost_rows if r["seam_texels"] > 0]
    scenes = sorted({r["scene"] for r in pts})
    colors = dict(zip(scenes, plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    slopes = {}
    for s in scenes:
        q = sorted([r for r in pts if r["scene"] == s], key=lambda r: r["seam_texels"])
        x = np.array([r["seam_texels"] for r in q])
        y = np.array([r["stitch_seconds"] for r in q])
        parts = np.array([r["search_seconds"] + r["build_seconds"] + r["solve_seconds"] for r in q])
        lab = s
        if len(q) >= 3:
            k = fit(x, y)[0]
            kp = fit(x, parts)[0]
            slopes[s] = (k, kp)
            lab += f": slope {k:.2f} (parts {kp:.2f})"
        ax.plot(x, y, "o-", color=colors[s], lw=0.9, ms=5, label=lab)
        spread = [r for r in q if "stitch_seconds_min" in r and r["stitch_seconds_min"] != ""]
        if spread:  # the cost part's rows: min and max of the runs
            ax.errorbar([r["seam_texels"] for r in spread], [r["stitch_seconds"] for r in spread],
                        yerr=[[r["stitch_seconds"] - r["stitch_seconds_min"] for r in spread],
                              [r["stitch_seconds_max"] - r["stitch_seconds"] for r in spread]],
                        fmt="none", ecolor=colors[s], elinewidth=0.8, capsize=2)
        ax.plot(x, parts, "o--", color=colors[s], lw=0.7, ms=5, mfc="none")
        for r in q:
            ax.annotate(f"{int(r['size'])}²", (r["seam_texels"], r["stitch_seconds"]), fontsize=6, xytext=(3, 3),
                        textcoords="offset points")
    x = np.array([r["seam_texels"] for r in pts])
    y = np.array([r["stitch_seconds"] for r in pts])
    if len(pts) >= 2:
        k, c = fit(x, y)
        slopes["all"] = (k, fit(x, [r["search_seconds"] + r["build_seconds"] + r["solve_seconds"] for r in pts])[0])
        grid = np.geomspace(x.min(), x.max(), 16)
        ax.plot(grid, 10 ** c * grid ** k, ":", color="k", lw=1, label=f"fit over all rows: slope {k:.2f}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("texels set by stitching (bake_stats::seam_texels)")
    ax.set_ylabel("seconds")
    ax.set_title("Cost of stitching. Filled: bake_stats::stitch_seconds (median of 3, bars min-max;\n"
                 "every output's solves); hollow: search + assembly + one solve, timed apart", fontsize=8)
    ax.legend(fontsize=6, loc="upper left")
    return slopes


def table(rows):
    """The table of docs/bake.md, "Seams", and the targets per row."""
    pct = lambda v: f"{100 * v:.2f}%"  # noqa: E731
    print("| scene (UVs) | size | triangles | coplanar pieces (texels) | walled (texels) | seam RMS off → on "
          "| the same, pieces with a valid texel on both sides | reference's seam RMS | max off → on | over 2% off → on "
          "| bake's error vs reference off / on | change: interior / all sampled / stitched texels | seam texels "
          "| stitch_seconds (search) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        seams = r["coplanar_pieces"] > 0
        dash = lambda text: text if seams else "—"  # noqa: E731
        print(f"| {r['scene']} ({r['uvs']}) | {int(r['size'])}² | {int(r['triangles']):,} "
              f"| {int(r['coplanar_pieces'])} ({r['coplanar_length']:.0f}) | {int(r['walled_pieces'])} ({r['walled_length']:.0f}) "
              f"| {dash(pct(r['rms_off']) + ' → **' + pct(r['rms_on']) + '**')} "
              f"| {dash(str(int(r['clean_pieces'])) + ': ' + pct(r['rms_off_clean']) + ' → ' + pct(r['rms_on_clean']))} "
              f"| {dash(pct(r['rms_ref']))} | {dash(pct(r['max_off']) + ' → ' + pct(r['max_on']))} "
              f"| {dash(pct(r['step_fraction_off']) + ' → ' + pct(r['step_fraction_on']))} "
              f"| **{pct(r['error_off'])}** / {pct(r['error_on'])} "
              f"| {dash(pct(r['interior_change']) + ' / ' + pct(r['all_change']) + ' / ' + pct(r['seam_change']))} "
              f"| {int(r['seam_texels']):,} | {r['stitch_seconds']:.3f} ({r['search_seconds']:.3f}) |")
    print()
    for r in rows:
        if r["coplanar_pieces"] == 0:
            print(f"{label(r)}: no coplanar seams (nothing stitched)")
            continue
        t1 = r["rms_on"] <= r["error_off"]
        t1c = r["rms_on_clean"] <= r["error_off"]
        t2 = r["interior_change"] <= 0.005
        print(f"{label(r)}: seam RMS after {pct(r['rms_on'])} <= error {pct(r['error_off'])}: {'met' if t1 else 'NOT met'} "
              f"(clean pieces {pct(r['rms_on_clean'])}: {'met' if t1c else 'NOT met'}); interior change {pct(r['interior_change'])} "
              f"<= 0.5%: {'met' if t2 else 'NOT met'}; error {pct(r['error_off'])} -> {pct(r['error_on'])} with stitching")


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
    for s, (k, kp) in slopes.items():
        print(f"log-log slope against seam_texels, {s}: stitch_seconds {k:.2f}, search + assembly + solve {kp:.2f}")
    print(f"wrote {out}/seams.png")


main()
