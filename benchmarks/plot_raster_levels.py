"""Draws docs/bench/raster_levels.png from docs/bench/raster_levels.csv (benchmarks/sweep_raster_levels.cpp):
left, a hemicube's cost on each stand-in level over the 1,062-triangle hexagon room's (the median of
the paired rounds' ratios, the bar; the rounds' range, the whisker), occlusion culling on and off,
one and two threads, with the targets (3x on the ~50k-triangle closed levels, 10x at 1M);
right, per hemicube, the triangles tested and the (triangle, face) pairs drawn against the distinct
triangles seen. Prints the table docs/raster.md shows.

usage: plot_raster_levels.py [folder]   (default docs/bench; reads FOLDER/raster_levels.csv, or
FOLDER/raster_levels_sweep.csv, the name benchmarks/run.sh gives sweep CSVs, if the first is missing)
"""
import os
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from bench_csv import load_csv  # noqa: E402

ORDER = ["arena", "keep", "city_block", "terrain_town", "arena_1M", "keep_1M", "city_block_1M", "terrain_town_1M"]
CLOSED = {"arena", "keep"}


def csv_path(folder):
    path = os.path.join(folder, "raster_levels.csv")
    alt = os.path.join(folder, "raster_levels_sweep.csv")
    return path if os.path.exists(path) or not os.path.exists(alt) else alt


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
    rows = load_csv(csv_path(folder))
    cases = {}
    for r in rows:
        cases.setdefault((r["scene"], r["culling"], int(r["threads"])), []).append(r)
    scenes = [s for s in ORDER if any(k[0] == s for k in cases)] + sorted({k[0] for k in cases} - set(ORDER))
    threads = sorted({k[2] for k in cases})
    rounds = max(len(v) for v in cases.values())

    print(f"{rounds} paired rounds; ratio = a hemicube's cost on the level / on hexagon_room_1062 (N = 64, render only)")
    print("| level | triangles | culling | " + " | ".join(f"{t} thread{'s' if t > 1 else ''}: ratio (range), µs" for t in threads)
          + " | tested | drawn | seen | inside |")
    print("| --- | --- | --- | " + " | ".join("---" for _ in threads) + " | --- | --- | --- | --- |")
    for s in scenes:
        for cull in ("on", "off"):
            cells, first = [], None
            for t in threads:
                v = cases.get((s, cull, t))
                if not v:
                    cells.append("")
                    continue
                first = first or v[0]
                ratios = [x["ratio"] for x in v]
                cells.append(f"**{statistics.median(ratios):.1f}x** ({min(ratios):.1f}-{max(ratios):.1f}), "
                             f"{statistics.median(x['us_per_hemicube'] for x in v):.0f} µs")
            if first is None:
                continue
            print(f"| {s} | {int(first['triangles']):,} | {cull} | " + " | ".join(cells)
                  + f" | {first['triangles_tested']:,.0f} | {first['face_triangles']:,.0f} | {first['seen']:,.0f} | "
                  f"{100 * first['inside']:.0f}% |")
    room = [r["room_us_per_hemicube"] for r in rows if int(r["threads"]) == 1]
    if room:
        print(f"hexagon_room_1062, one thread: {min(room):.0f}-{max(room):.0f} µs per hemicube over the rounds, "
              f"median {statistics.median(room):.0f}")
    steal = [r["steal"] for r in rows if r["steal"] >= 0]
    loads = [r["load1"] for r in rows]
    print(f"steal: median {statistics.median(steal):.1%}, max {max(steal):.1%}; load average {min(loads):.2f}-{max(loads):.2f}")

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(15, 6), gridspec_kw={"width_ratios": [3, 2]})
    variants = [(cull, t) for cull in ("on", "off") for t in threads]
    width = 0.8 / len(variants)
    colors = {"on": ["tab:blue", "tab:cyan"], "off": ["tab:red", "tab:orange"]}
    for j, (cull, t) in enumerate(variants):
        xs, ys, lo, hi = [], [], [], []
        for i, s in enumerate(scenes):
            v = cases.get((s, cull, t))
            if not v:
                continue
            ratios = [x["ratio"] for x in v]
            m = statistics.median(ratios)
            xs.append(i + (j - (len(variants) - 1) / 2) * width)
            ys.append(m)
            lo.append(m - min(ratios))
            hi.append(max(ratios) - m)
        ax.bar(xs, ys, width, yerr=[lo, hi], capsize=2, color=colors[cull][threads.index(t) % 2],
               label=f"culling {cull}, {t} thread{'s' if t > 1 else ''}")
        for x, y in zip(xs, ys):
            ax.annotate(f"{y:.1f}", (x, y), textcoords="offset points", xytext=(0, 2), ha="center", fontsize=6)
    for i, s in enumerate(scenes):
        target = 3 if s in CLOSED else (10 if s.endswith("_1M") else None)
        if target:
            ax.plot([i - 0.45, i + 0.45], [target, target], "k--", lw=1.2)
            ax.annotate(f"target {target}x", (i, target), textcoords="offset points", xytext=(0, 3), ha="center", fontsize=7)
    tri = {s: int(next(r["triangles"] for r in rows if r["scene"] == s)) for s in scenes}
    ax.set_xticks(range(len(scenes)))
    ax.set_xticklabels([f"{s}\n{tri[s]:,}" for s in scenes], fontsize=7)
    ax.set_yscale("log")
    ax.set_ylabel("cost per hemicube / hexagon room's (1,062 triangles)")
    ax.set_title(f"Cost per hemicube over the room's, N = 64, render only\n(bars: median of {rounds} paired rounds; "
                 "whiskers: the rounds' range)", fontsize=9)
    ax.grid(True, axis="y", which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")

    xs = range(len(scenes))
    for cull, marker, color in (("off", "s", "tab:red"), ("on", "o", "tab:blue")):
        pts = [(i, cases[(s, cull, threads[0])][0]) for i, s in enumerate(scenes) if (s, cull, threads[0]) in cases]
        ax2.plot([p[0] for p in pts], [p[1]["triangles_tested"] for p in pts], marker + "-", color=color,
                 label=f"triangles tested, culling {cull}")
        ax2.plot([p[0] for p in pts], [p[1]["face_triangles"] for p in pts], marker + ":", color=color, mfc="none",
                 label=f"(triangle, face) pairs drawn, culling {cull}")
    seen = [(i, cases[k][0]["seen"]) for i, s in enumerate(scenes) for k in [(s, "on", threads[0]), (s, "off", threads[0])]
            if k in cases][::1]
    seen = sorted(dict(seen).items())
    ax2.plot([p[0] for p in seen], [p[1] for p in seen], "k^-", label="distinct triangles seen (texel centres)")
    ax2.set_xticks(list(xs))
    ax2.set_xticklabels([f"{s}\n{tri[s]:,}" for s in scenes], fontsize=7, rotation=30)
    ax2.set_yscale("log")
    ax2.set_ylabel("per hemicube (mean over the 256 points)")
    ax2.set_title("What a hemicube draws against what it shows", fontsize=9)
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=7)
    fig.tight_layout()
    out = os.path.join(folder, "raster_levels.png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
