"""Charts of the irradiance cache (docs/cache.md): RMS relative error against the fraction of points
given a hemicube, one column per scene, curves per hemicube resolution N (solid: with gradients,
dashed: without). Top row: error against the converged reference (the cache's total error), with
the per-point reference's own error at each N as a dotted horizontal line in the same colour.
Bottom row: error against a hemicube at every point with the same N (the interpolation error
alone). The grey boxes are the cache's targets (<= 1% RMS at <= 10% of the points; previews:
<= 3% at <= 3%).

  plot_cache.py DIR      draws DIR/cache.png from DIR/cache_sweep.csv (bash benchmarks/run.sh cache)
                         and, if DIR/cache_resolution.csv exists (bash benchmarks/run.sh cache_resolution),
                         DIR/cache_resolution.png and DIR/cache_resolution.md (the table of
                         interpolated hemicube fractions at the targets and gradient savings);
                         the same for cache_resolution_k128.csv (hexagon ceiling and Cornell box,
                         128 x 128 grid), cache_weights.csv
                         (cache_weight::ward against ward_continuous; bash benchmarks/run.sh cache_weights)
                         and cache_second_order.csv (cache_options::second_order against first order;
                         bash benchmarks/run.sh cache_second_order). Rows may carry a `variant` column (sweep_cache --variant: which
                         cache options); with more than one variant, each gets its own curves (marker and
                         line style) and its own rows in the .md table.
"""
import math
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_csv

COLORS = {64: "C1", 128: "C0", 256: "C2", 512: "C3", 1024: "C4"}


def resolution(r):
    return int(r.get("resolution", 64) or 64)


def variant(r):
    return r.get("variant") or "default"


def variants(rows):
    return list(dict.fromkeys(variant(r) for r in rows))


def curve(rows, scene, n, grad, key, var=None):
    """(fraction, error) points of one curve, sorted by fraction (of one variant if given)."""
    return sorted((r["fraction"], r[key]) for r in rows
                  if r["scene"] == scene and resolution(r) == n and int(r["gradients"]) == grad
                  and (var is None or variant(r) == var))


def fraction_for(pts, target):
    """Smallest hemicube fraction at which the curve (piecewise linear in log-log, in order of
    fraction) reaches RMS <= target; None if it never does within the measured range."""
    for i, (f, e) in enumerate(pts):
        if e <= target:
            if i == 0:
                return f
            f0, e0 = pts[i - 1]
            if e0 <= target or e0 == e or e <= 0.0:
                return f
            t = (math.log(e0) - math.log(target)) / (math.log(e0) - math.log(e))
            return math.exp(math.log(f0) + t * (math.log(f) - math.log(f0)))
    return None


def chart(rows, path):
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    ns = sorted({resolution(r) for r in rows})
    has_converged = "rms_rel_err_converged" in rows[0]
    keys = [("rms_rel_err_converged", "RMS error vs converged (%)")] if has_converged else []
    keys.append(("rms_rel_err", "RMS error vs hemicube per point (%)"))
    fig, axes = plt.subplots(len(keys), len(scenes), figsize=(4.8 * len(scenes), 3.9 * len(keys)), squeeze=False)
    for col, scene in enumerate(scenes):
        sr = [r for r in rows if r["scene"] == scene]
        for row, (key, ylabel) in enumerate(keys):
            ax = axes[row][col]
            for n in ns:
                if not any(resolution(r) == n for r in sr):
                    continue
                c = COLORS.get(n, "k")
                vs = variants(sr)
                for vi, var in enumerate(vs):
                    for grad, style in ((1, "o-"), (0, "s--")):
                        if len(vs) > 1:
                            style = ("o-", "^:", "s-.", "d--")[vi % 4] if grad else style
                        pts = [p for p in curve(rows, scene, n, grad, key, var) if p[1] > 0]  # 0: every point rendered
                        if pts:
                            label = f"N={n} {'gradients' if grad else 'no gradients'}"
                            if len(vs) > 1:
                                label += f", {var}"
                            ax.plot([100 * p[0] for p in pts], [100 * p[1] for p in pts], style, color=c, ms=3.5,
                                    alpha=1.0 if grad else 0.6, label=label)
                if key == "rms_rel_err_converged":
                    ref = [r["reference_rms_rel_err_converged"] for r in sr if resolution(r) == n][0]
                    ax.axhline(100 * ref, color=c, ls=":", lw=1.2, label=f"N={n} hemicube per point")
            r0 = sr[0]
            title = f"{scene} ({int(r0['points'])} points"
            if "grid" in r0:
                title += f", grid {int(r0['grid'])}"
            title += ")"
            if key == "rms_rel_err_converged" and "converged_resolution" in r0:
                title += f"\nconverged: N={int(r0['converged_resolution'])}"
                if "converged_rolls" in r0 and int(r0["converged_rolls"]) > 1:
                    title += f" x {int(r0['converged_rolls'])} rolls"
                title += f" at {int(r0['converged_points'])} points"
            ax.set_title(title, fontsize=8.5)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlim(0.8, 110)
            lo, hi = ax.get_ylim()
            lo = min(lo, 0.5)
            for x1, y in ((10.0, 1.0), (3.0, 3.0)):  # the targets
                ax.fill_between([0.8, x1], [lo, lo], [y, y], color="0.6", alpha=0.2, lw=0)
            ax.set_ylim(lo, max(hi, 3.5))
            ax.set_xlabel("points given a hemicube (%)")
            if col == 0:
                ax.set_ylabel(ylabel)
            ax.grid(True, which="both", alpha=0.3)
    handles, labels = axes[0][0].get_legend_handles_labels()
    if len(labels) > 10:
        # Many curves (several variants): the legend goes below the panels, where it hides none of them.
        rows_of_legend = math.ceil(len(labels) / 4)
        bottom = min(0.45, 0.03 * rows_of_legend + 0.02)
        fig.set_size_inches(fig.get_size_inches()[0], fig.get_size_inches()[1] / (1 - bottom))
        fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=7, frameon=False)
        fig.tight_layout(rect=(0, bottom, 1, 1))
    else:
        axes[0][0].legend(fontsize=6, ncol=2)
        fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


def table(rows, path):
    """Markdown: per scene and N, the per-point reference's own error, the hemicube fraction at
    which the curves reach 1% and 3% RMS, and the gradient savings at equal RMS."""
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    out = ["| scene | N | variant | per-point vs converged (RMS) | error vs | fraction for 1% (grad / no grad) | "
           "fraction for 3% (grad / no grad) | gradient savings at equal RMS (no-grad fraction / grad fraction) |",
           "| --- | --- | --- | --- | --- | --- | --- | --- |"]

    def fmt(f):
        return "not reached" if f is None else f"{100 * f:.1f}%"

    for scene in scenes:
        for n in sorted({resolution(r) for r in rows if r["scene"] == scene}):
            ref = [r["reference_rms_rel_err_converged"] for r in rows
                   if r["scene"] == scene and resolution(r) == n][0]
            for var, key, what in [(v, k, w) for v in variants([r for r in rows if r["scene"] == scene])
                                   for k, w in (("rms_rel_err", "per point"), ("rms_rel_err_converged", "converged"))]:
                g = curve(rows, scene, n, 1, key, var)
                ng = curve(rows, scene, n, 0, key, var)
                if not g and not ng:
                    continue
                savings = []
                for f, e in g:
                    if e <= 0.0 or not ng:  # every point rendered, or no no-gradient run: nothing to compare
                        continue
                    f_ng = fraction_for(ng, e)
                    if f_ng is None:
                        savings.append(f"{100 * e:.2f}%: > {max(p[0] for p in ng) / f:.1f}x")
                    else:
                        savings.append(f"{100 * e:.2f}%: {f_ng / f:.1f}x")
                out.append(f"| {scene} | {n} | {var} | {100 * ref:.2f}% | {what} | {fmt(fraction_for(g, 0.01))} / "
                           f"{fmt(fraction_for(ng, 0.01)) if ng else '-'} | {fmt(fraction_for(g, 0.03))} / {fmt(fraction_for(ng, 0.03)) if ng else '-'} | "
                           + ("; ".join(savings) or "(not measured)") + " |")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")
    print(f"wrote {path}")


out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
if os.path.exists(f"{out}/cache_sweep.csv"):
    chart(load_csv(f"{out}/cache_sweep.csv"), f"{out}/cache.png")
for name in ("cache_resolution", "cache_resolution_k128", "cache_weights", "cache_second_order"):
    if os.path.exists(f"{out}/{name}.csv"):
        rows = load_csv(f"{out}/{name}.csv")
        if not rows:
            continue
        chart(rows, f"{out}/{name}.png")
        table(rows, f"{out}/{name}.md")
