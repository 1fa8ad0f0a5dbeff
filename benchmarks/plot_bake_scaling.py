"""Draws docs/bench/bake_scaling.png from docs/bench/bake_scaling.csv (benchmarks/sweep_bake_scaling.cpp):
bake wall time (left axes, blue) and peak memory (right axes, red) of the heightfield bake against
the triangle count (log-log), the lightmap texels (log-log) and the thread count, with labelled
reference slopes and the measured log-log slopes of every series; below, the same against the
triangle count for the closed and the open stand-in levels (studies closed, open; one line per
level), and the cost per hemicube of every triangle series. Prints the level series' slopes per
step (the exponent per decade, or per half decade).

usage: plot_bake_scaling.py [folder]   (default docs/bench; reads FOLDER/bake_scaling.csv, or
FOLDER/bake_scaling_sweep.csv, the name benchmarks/run.sh gives sweep CSVs, if the first is missing)
"""
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from bench_csv import load_csv  # noqa: E402

TIME, MEMORY = "tab:blue", "tab:red"
TIME_REFERENCE, MEMORY_REFERENCE = "#7fa7cc", "#e08f8f"  # lighter: reference curves of each axis


def csv_path(folder):
    """The sweep's CSV in `folder`: bake_scaling.csv, else run.sh's bake_scaling_sweep.csv."""
    path = os.path.join(folder, "bake_scaling.csv")
    alt = os.path.join(folder, "bake_scaling_sweep.csv")
    return path if os.path.exists(path) or not os.path.exists(alt) else alt


def study(rows, name, key):
    """The rows of one study, sorted by `key`."""
    return sorted((r for r in rows if r["study"] == name), key=lambda r: r[key])


def loglog_slope(xs, ys):
    """Least-squares slope of log y against log x (None with fewer than two distinct x)."""
    if len(set(xs)) < 2:
        return None
    return float(np.polyfit(np.log(xs), np.log(ys), 1)[0])


def fmt_slope(s):
    """A measured slope for a legend label."""
    return "n/a" if s is None else f"{s:.2f}"


def step_slopes(xs, ys):
    """The log-log slopes between consecutive points, formatted ("0.33, 0.86")."""
    return ", ".join(f"{math.log(y1 / y0) / math.log(x1 / x0):.2f}"
                     for x0, x1, y0, y1 in zip(xs, xs[1:], ys, ys[1:]) if x1 != x0 and y0 > 0 and y1 > 0)


def reference(ax, xs, x0, y0, kind, style, color, label):
    """Draws the reference curve y = y0 * f(x) / f(x0) over the range of xs for f = x ('n'),
    log x ('log n') or 1 / x ('1/n') in `color`, labelled with `label`."""
    f = {"n": lambda x: x, "log n": math.log, "1/n": lambda x: 1.0 / x}[kind]
    grid = np.geomspace(min(xs), max(xs), 64) if kind != "1/n" else np.linspace(min(xs), max(xs), 64)
    return ax.plot(grid, [y0 * f(x) / f(x0) for x in grid], style, color=color, lw=1.2, label=label)[0]


def us_per_hemicube(r):
    """Thread-microseconds of bake per hemicube (wall seconds x threads / hemicubes)."""
    return 1e6 * r["seconds"] * r["threads"] / max(r["hemicubes"], 1.0)


def bytes_per(rows, x_key):
    """Marginal peak memory in bytes per unit of `x_key` between the two largest points."""
    if len(rows) < 2 or rows[-1][x_key] == rows[-2][x_key]:
        return None
    return (rows[-1]["peak_mib"] - rows[-2]["peak_mib"]) * 2**20 / (rows[-1][x_key] - rows[-2][x_key])


def finish(ax, mem_ax, handles, note):
    """Legend of both axes' handles under the panel, and under it a box with the measured numbers."""
    leg = ax.legend(handles=handles, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)
    ax.annotate(note, xy=(0.5, 0.0), xycoords=leg, xytext=(0, -6), textcoords="offset points", fontsize=7,
                ha="center", va="top", bbox=dict(boxstyle="round", fc="white", ec="0.7"))
    ax.set_ylabel("bake wall time (s)", color=TIME)
    mem_ax.set_ylabel("peak memory, VmHWM (MiB)", color=MEMORY)


def empty(ax, title):
    """Marks a panel whose study has no rows in the CSV."""
    ax.set_title(title)
    ax.text(0.5, 0.5, "no rows in the CSV", transform=ax.transAxes, ha="center")


def finish_loglog(ax, mem_ax, handles, note, xlabel, title):
    """Log-log axes for both the time and the memory axis, labels, then finish()."""
    for a in (ax, mem_ax):
        a.set_xscale("log")
        a.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_title(title)
    finish(ax, mem_ax, handles, note)


def triangles_panel(ax, rows):
    """Time and peak memory against the triangle count (log-log), references O(T) and O(log T)."""
    title = "(a) against triangles"
    if not rows:
        return empty(ax, title)
    size, threads = int(rows[0]["size"]), int(rows[0]["threads"])
    t = [r["triangles"] for r in rows]
    sec = [r["seconds"] for r in rows]
    mem = [r["peak_mib"] for r in rows]
    mem_ax = ax.twinx()
    h = [ax.plot(t, sec, "o-", color=TIME, label=f"time (slope {fmt_slope(loglog_slope(t, sec))})")[0],
         reference(ax, t, t[0], sec[0], "n", "--", TIME_REFERENCE, "time O(T) from the first point"),
         reference(ax, t, t[0], sec[0], "log n", ":", TIME_REFERENCE, "time O(log T) from the first point"),
         mem_ax.plot(t, mem, "s-", color=MEMORY, label=f"peak memory (slope {fmt_slope(loglog_slope(t, mem))})")[0],
         mem_ax.plot(t, [r["scene_mib"] for r in rows], "s:", color=MEMORY, alpha=0.6, mfc="none",
                     label="memory after building the scene")[0],
         reference(mem_ax, t[-2:], t[-1], mem[-1], "n", "-.", MEMORY_REFERENCE, "memory O(T), last step")]
    for r in rows:
        ax.annotate(f"{us_per_hemicube(r):.0f} µs/hc", (r["triangles"], r["seconds"]), fontsize=6,
                    textcoords="offset points", xytext=(4, -9), color=TIME)
    hc = [r["hemicubes"] for r in rows]
    per_t = bytes_per(rows, "triangles")
    note = (f"time slope per step: {step_slopes(t, sec)}; peak memory: {step_slopes(t, mem)}\n"
            f"hemicubes {int(min(hc))}-{int(max(hc))} (slope {fmt_slope(loglog_slope(t, hc))})\n"
            f"µs/hc = thread-µs per hemicube, slope per step: {step_slopes(t, [us_per_hemicube(r) for r in rows])}"
            + (f"\nmarginal peak memory {per_t:.0f} B/triangle (last two points)" if per_t is not None else ""))
    finish_loglog(ax, mem_ax, h, note, f"triangles (heightfield, {size}² lightmap, {threads} threads)", title)


def texels_panel(ax, rows):
    """Time and peak memory against the lightmap texels (log-log), references O(texels)."""
    title = "(b) against lightmap texels"
    if not rows:
        return empty(ax, title)
    tri, threads = int(rows[0]["triangles"]), int(rows[0]["threads"])
    n = [r["size"] ** 2 for r in rows]
    sec = [r["seconds"] for r in rows]
    mem = [r["peak_mib"] for r in rows]
    hc = [r["hemicubes"] for r in rows]
    cov = [r["coverage_seconds"] for r in rows]
    mem_ax = ax.twinx()
    h = [ax.plot(n, sec, "o-", color=TIME, label=f"time (slope {fmt_slope(loglog_slope(n, sec))})")[0],
         ax.plot(n, cov, "o:", color=TIME, alpha=0.6, mfc="none",
                 label=f"coverage step (slope {fmt_slope(loglog_slope(n, cov))})")[0],
         reference(ax, n, n[0], sec[0], "n", "--", TIME_REFERENCE, "time O(texels) from the first point"),
         mem_ax.plot(n, mem, "s-", color=MEMORY, label=f"peak memory (slope {fmt_slope(loglog_slope(n, mem))})")[0],
         reference(mem_ax, n, n[-1], mem[-1], "n", "-.", MEMORY_REFERENCE, "memory O(texels) through the last point")]
    for r in rows:
        ax.annotate(f"{r['hemicubes'] / 1000:.1f}k hc", (r["size"] ** 2, r["seconds"]), fontsize=6,
                    textcoords="offset points", xytext=(4, -9), color=TIME)
    per_texel = bytes_per([dict(r, texels=r["size"] ** 2) for r in rows], "texels")
    note = (f"time slope per step: {step_slopes(n, sec)}; peak memory: {step_slopes(n, mem)}\n"
            f"hemicubes: slope {fmt_slope(loglog_slope(n, hc))} "
            f"({100 * hc[0] / n[0]:.1f}% -> {100 * hc[-1] / n[-1]:.1f}% of texels)"
            + (f"\nmarginal peak memory {per_texel:.0f} B/texel (last two points)" if per_texel is not None else ""))
    finish_loglog(ax, mem_ax, h, note, f"lightmap texels = sampled texels ({tri} triangles, {threads} threads)", title)


def threads_panel(ax, rows):
    """Time and peak memory against the thread count, reference O(1/threads) from one thread."""
    title = "(c) against threads"
    if not rows:
        return empty(ax, title)
    tri, size = int(rows[0]["triangles"]), int(rows[0]["size"])
    p = [r["threads"] for r in rows]
    sec = [r["seconds"] for r in rows]
    mem = [r["peak_mib"] for r in rows]
    mem_ax = ax.twinx()
    h = [ax.plot(p, sec, "o-", color=TIME, label="time")[0],
         reference(ax, p, p[0], sec[0], "1/n", "--", TIME_REFERENCE, "time O(1/threads) from the first point")]
    h.append(mem_ax.plot(p, mem, "s-", color=MEMORY, label="peak memory")[0])
    note = "\n".join(f"{int(r['threads'])} thread(s): {r['seconds']:.2f} s, speed-up {sec[0] / r['seconds']:.2f}x, "
                     f"{r['peak_mib']:.0f} MiB" for r in rows)
    ax.set_xticks(sorted(set(p)))
    ax.set_ylim(0, max(sec) * 1.15)
    mem_ax.set_ylim(0, max(mem) * 1.3)
    ax.set_xlabel(f"threads ({tri} triangles, {size}² lightmap)")
    ax.set_title(title)
    finish(ax, mem_ax, h, note)


LEVEL_STYLES = ["o-", "D--"]


def levels_panel(ax, rows, title, kind):
    """Time and peak memory of each level of one study (closed or open) against its triangles
    (log-log), one line per level, with the O(T) and O(log T) references from the first point."""
    if not rows:
        return empty(ax, title)
    size, threads = int(rows[0]["size"]), int(rows[0]["threads"])
    mem_ax = ax.twinx()
    h, notes = [], []
    levels = sorted({r["scene"] for r in rows}, key=lambda s: min(r["triangles"] for r in rows if r["scene"] == s))
    for i, name in enumerate(levels):
        lr = sorted((r for r in rows if r["scene"] == name), key=lambda r: r["triangles"])
        t = [r["triangles"] for r in lr]
        sec = [r["seconds"] for r in lr]
        mem = [r["peak_mib"] for r in lr]
        style = LEVEL_STYLES[i % len(LEVEL_STYLES)]
        h.append(ax.plot(t, sec, style, color=TIME, label=f"{name}: time (slope {fmt_slope(loglog_slope(t, sec))})")[0])
        h.append(mem_ax.plot(t, mem, style.replace("o", "s"), color=MEMORY, mfc="none",
                             label=f"{name}: peak memory (slope {fmt_slope(loglog_slope(t, mem))})")[0])
        for r in lr:
            ax.annotate(f"{us_per_hemicube(r):.0f} µs/hc", (r["triangles"], r["seconds"]), fontsize=6,
                        textcoords="offset points", xytext=(4, -9 if i == 0 else 5), color=TIME)
        per_t = bytes_per(lr, "triangles")
        hc = [r["hemicubes"] for r in lr]
        notes.append(f"{name}: time slope per step {step_slopes(t, sec)}; µs/hc {step_slopes(t, [us_per_hemicube(r) for r in lr])}; "
                     f"memory {step_slopes(t, mem)}\n  hemicubes {int(min(hc))}-{int(max(hc))}"
                     + (f", marginal peak memory {per_t:.0f} B/triangle" if per_t is not None else ""))
        if i == 0:
            h.append(reference(ax, t, t[0], sec[0], "n", "--", TIME_REFERENCE, "time O(T) from the first point"))
            h.append(reference(ax, t, t[0], sec[0], "log n", ":", TIME_REFERENCE, "time O(log T) from the first point"))
    finish_loglog(ax, mem_ax, h, "\n".join(notes),
                  f"triangles ({kind} levels, {size}² lightmap whatever T, with their sun, {threads} threads)", title)


def cost_panel(ax, rows):
    """Thread-µs of bake per hemicube against triangles for every triangle series (log-log)."""
    title = "(f) bake time per hemicube"
    series = [("heightfield", study(rows, "triangles", "triangles"))]
    for st in ("closed", "open"):
        lr = study(rows, st, "triangles")
        for name in sorted({r["scene"] for r in lr}):
            series.append((name, [r for r in lr if r["scene"] == name]))
    series = [(n, s) for n, s in series if s]
    if not series:
        return empty(ax, title)
    for name, lr in series:
        t = [r["triangles"] for r in lr]
        us = [us_per_hemicube(r) for r in lr]
        ax.plot(t, us, "o-", label=f"{name} (slope {fmt_slope(loglog_slope(t, us))})")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("triangles")
    ax.set_ylabel("bake thread-µs per hemicube (wall x threads / hemicubes)")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)


def print_levels(rows):
    """The level series as docs/bake.md tables them, with the slope of each step."""
    for st in ("closed", "open"):
        lr = study(rows, st, "triangles")
        for name in sorted({r["scene"] for r in lr}):
            s = [r for r in lr if r["scene"] == name]
            t = [r["triangles"] for r in s]
            print(f"{st} {name} ({int(s[0]['size'])}², {int(s[0]['threads'])} threads): triangles "
                  + " / ".join(f"{int(x):,}" for x in t))
            print("  bake s " + " / ".join(f"{r['seconds']:.1f}" for r in s) + f"  (slope per step {step_slopes(t, [r['seconds'] for r in s])})")
            print("  hemicubes " + " / ".join(f"{r['hemicubes'] / 1000:.1f}k" for r in s)
                  + "  sampled " + " / ".join(f"{r['sampled_texels'] / 1000:.0f}k" for r in s))
            us = [us_per_hemicube(r) for r in s]
            print("  thread-µs per hemicube " + " / ".join(f"{u:.0f}" for u in us) + f"  (slope per step {step_slopes(t, us)})")
            if all("render_seconds" in r and r["render_seconds"] != "" for r in s):
                print("  hemicube share of the bake " + " / ".join(f"{100 * r['render_seconds'] / r['seconds']:.0f}%" for r in s))
            print("  peak MiB " + " / ".join(f"{r['peak_mib']:.0f}" for r in s)
                  + f"  (slope per step {step_slopes(t, [r['peak_mib'] for r in s])})")


def main():
    """Reads the CSV named by the first argument's folder and writes bake_scaling.png next to it."""
    folder = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
    rows = load_csv(csv_path(folder))
    has_levels = any(r["study"] in ("closed", "open") for r in rows)
    fig, axes = plt.subplots(2 if has_levels else 1, 3, figsize=(18, 15 if has_levels else 7.5), squeeze=False)
    triangles_panel(axes[0][0], study(rows, "triangles", "triangles"))
    texels_panel(axes[0][1], study(rows, "size", "size"))
    threads_panel(axes[0][2], study(rows, "threads", "threads"))
    if has_levels:
        levels_panel(axes[1][0], study(rows, "closed", "triangles"), "(d) closed levels against triangles", "closed")
        levels_panel(axes[1][1], study(rows, "open", "triangles"), "(e) open levels against triangles", "open")
        cost_panel(axes[1][2], rows)
        print_levels(rows)
    fig.suptitle("Lightmap bake scaling (N = 64, 1 bounce, default cache a = 0.2; heightfield with planar UVs"
                 + ("; stand-in levels with their sun" if has_levels else "")
                 + "; one bake per point, each in its own process; measured slopes in the legends)", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(folder, "bake_scaling.png"), dpi=110)
    print(f"wrote {os.path.join(folder, 'bake_scaling.png')}")


if __name__ == "__main__":
    main()
