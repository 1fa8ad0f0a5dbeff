"""Draws docs/bench/visibility.png from docs/bench/visibility_sweep.csv (benchmarks/sweep_visibility.cpp):
per stand-in level, against the cluster's half side r, left the share of a held-out hemicube's
texels whose triangle none of the cluster's K hemicubes saw (solid) or that lies outside their BVH
leaves (dashed), right the triangles the cluster saw (its union) against those the culled render
tests, per hemicube.

usage: plot_visibility.py [folder]   (default docs/bench)
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from bench_csv import load_csv  # noqa: E402


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
    rows = load_csv(os.path.join(folder, "visibility_sweep.csv"))
    levels = list(dict.fromkeys(r["level"] for r in rows))
    ks = sorted({int(r["cluster_points"]) for r in rows})
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for li, level in enumerate(levels):
        for ki, k in enumerate(ks):
            sel = sorted((r for r in rows if r["level"] == level and int(r["cluster_points"]) == k),
                         key=lambda r: float(r["radius_m"]))
            radius = [float(r["radius_m"]) for r in sel]
            colour = colours[(li * len(ks) + ki) % len(colours)]
            axes[0].plot(radius, [100 * float(r["miss_texels"]) for r in sel], "o-", color=colour,
                         label=f"{level}, K = {k}")
            axes[0].plot(radius, [100 * float(r["miss_texels_leaves"]) for r in sel], "o--", color=colour, alpha=0.6)
            axes[1].plot(radius, [float(r["union"]) for r in sel], "o-", color=colour, label=f"{level}, K = {k}: union")
        tested = sorted((r for r in rows if r["level"] == level), key=lambda r: float(r["radius_m"]))
        axes[1].axhline(sum(float(r["tested"]) for r in tested) / len(tested), color=colours[li * len(ks) % len(colours)],
                        linestyle=":", label=f"{level}: triangles the culled render tests")
    axes[0].set_xscale("log")
    axes[0].set_yscale("log")
    axes[0].set_xlabel("half side r of the cluster's square on the tangent plane (m)")
    axes[0].set_ylabel("held-out texels whose triangle is missing (%)\nsolid: from the triangles, dashed: from their leaves")
    axes[0].set_title("what a render from the cluster's visible set gets wrong")
    axes[0].grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7, ncol=2)
    axes[1].set_xscale("log")
    axes[1].set_yscale("log")
    axes[1].set_xlabel("half side r (m)")
    axes[1].set_ylabel("triangles per hemicube")
    axes[1].set_title("what it would draw, against the culled render")
    axes[1].grid(True, which="both", alpha=0.3)
    axes[1].legend(fontsize=6, ncol=2)
    fig.suptitle("Sharing visibility between neighbouring hemicubes on the stand-in levels (N = 64; not built)")
    fig.tight_layout()
    out = os.path.join(folder, "visibility.png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
