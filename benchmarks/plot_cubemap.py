"""Charts of the cube-map benchmark and sweeps (docs/bench/cubemap*.png):
  cubemap.png           filtering times (1 and 2 threads) against the cmft reference figures
  cubemap_seams.png     seam size against interior distortion per method, one panel per size
  cubemap_accuracy.png  radiance-chain time against max relative error (texels_per_sigma, cutoff)
  cubemap_warp.png      how far the runtime fixup lands from the mapping's direction (texels)
  cubemap_irradiance.png  irradiance methods' error against brute force vs CPU time
                        (sweep_cubemap_irradiance: SH9, SH25, the cosine filter per input size)
"""
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_csv, load_gbench, medians

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"

# ---- timings ---------------------------------------------------------------------------------
if os.path.exists(f"{out}/cubemap.csv"):
    m = medians(load_gbench(f"{out}/cubemap.csv"))
    rows = [  # (label, benchmark name with {t} = threads, cmft's time in ms or None)
        ("radiance chain 256\n(gloss mapping)", "radiance_chain/{t}/iterations:3/real_time", 3400.0),
        ("radiance chain 256\ntexels_per_sigma 1.5", "radiance_chain_fast/{t}/iterations:3/real_time", 3400.0),
        ("radiance chain 256\nper-tap weights\n(previous method)", "radiance_chain_per_tap/{t}/iterations:3/real_time", 3400.0),
        ("radiance chain 256\n(cmft lobes)", "radiance_chain_cmft_lobes/{t}/iterations:2/real_time", 3400.0),
        ("irradiance SH\n256 in, 256 out", "irradiance_sh/{t}/256/real_time", 180.0),
        ("irradiance SH\n256 in, 32 out", "irradiance_sh/{t}/32/real_time", 180.0),
        ("irradiance filter\n256 in, 32 out", "irradiance_filter/{t}/32/real_time", None),
    ]

    def find(key, threads):
        return m.get(key.format(t=threads))

    fig, ax = plt.subplots(figsize=(8, 4))
    labels, one, two, refs = [], [], [], []
    for label, key, ref in rows:
        r1, r2 = find(key, 1), find(key, 2)
        if r1 is None or r2 is None:
            continue
        labels.append(label)
        one.append(r1["real_time"])
        two.append(r2["real_time"])
        refs.append(ref)
    x = range(len(labels))
    ax.bar([i - 0.2 for i in x], one, 0.4, label="1 thread")
    ax.bar([i + 0.2 for i in x], two, 0.4, label="2 threads")
    for i, ref in enumerate(refs):
        if ref:
            ax.plot([i - 0.45, i + 0.45], [ref, ref], "k--", lw=1)
            ax.plot([i - 0.45, i + 0.45], [ref / 10, ref / 10], "r:", lw=1)
    ax.plot([], [], "k--", label="cmft, 2 threads (reference)")
    ax.plot([], [], "r:", label="target: 10x faster")
    ax.set_yscale("log")
    ax.set_xticks(list(x))
    ax.set_xticklabels(labels, fontsize=8)
    ax.set_ylabel("ms (median)")
    ax.set_title("cube-map filtering, 256² input")
    ax.legend(fontsize=7)
    ax.grid(True, axis="y", which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(f"{out}/cubemap.png", dpi=120)
    print(f"wrote {out}/cubemap.png")

# ---- seams -----------------------------------------------------------------------------------
seams = load_csv(f"{out}/cubemap_sweep.csv")
sizes = sorted({int(r["size"]) for r in seams})
methods = ["none", "stretch", "warp", "stretch_fixup", "stretch_fixup_lod", "seamless"]
markers = {"none": "o", "stretch": "s", "warp": "^", "stretch_fixup": "D", "stretch_fixup_lod": "x", "seamless": "*"}
floor = 1e-7
fig, axes = plt.subplots(2, len(sizes), figsize=(2.3 * len(sizes), 5.2), sharey="row", sharex=True)
for col, n in enumerate(sizes):
    for row, (key, title) in enumerate([("edge_jump", "zero-order jump"), ("edge_kink", "first-order kink")]):
        ax = axes[row][col]
        for meth in methods:
            pts = [r for r in seams if int(r["size"]) == n and r["method"] == meth]
            xs = [max(r["distortion_rms"], 1e-4) for r in pts]
            ys = [max(r[key], floor) for r in pts]
            ax.scatter(xs, ys, marker=markers[meth], label=meth, s=22)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
        if row == 0:
            ax.set_title(f"size {n}", fontsize=9)
        if col == 0:
            ax.set_ylabel(f"{title}\n(/ same inside the face)", fontsize=8)
        if row == 1:
            ax.set_xlabel("interior distortion\n(RMS / mean)", fontsize=8)
        ax.tick_params(labelsize=7)
axes[0][0].legend(fontsize=6, loc="lower left")
fig.suptitle("Seams (12 edges, per-face sampling unless seamless) against interior distortion; "
             "lobes of 1, 2, 4 texels; values at 1e-4 / 1e-7 are zero", fontsize=9)
fig.tight_layout()
fig.savefig(f"{out}/cubemap_seams.png", dpi=120)
print(f"wrote {out}/cubemap_seams.png")

# ---- speed against accuracy -----------------------------------------------------------------
if os.path.exists(f"{out}/cubemap_accuracy.csv"):
    acc = load_csv(f"{out}/cubemap_accuracy.csv")
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for cutoff in sorted({r["cutoff"] for r in acc}, reverse=True):
        pts = sorted([r for r in acc if r["cutoff"] == cutoff], key=lambda r: r["texels_per_sigma"])
        ax.plot([r["seconds_2_threads"] for r in pts], [100 * r["max_rel_error"] for r in pts], "o-",
                label=f"cutoff {cutoff:g}")
        for r in pts:
            ax.annotate(f"{r['texels_per_sigma']:g}", (r["seconds_2_threads"], 100 * r["max_rel_error"]),
                        fontsize=6, xytext=(3, 3), textcoords="offset points")
    ax.axvline(0.34, color="r", ls=":", label="10x faster than cmft (0.34 s)")
    ax.axhline(1.0, color="k", ls="--", lw=1, label="1% max error")
    ax.set_xlabel("256² radiance chain, s (2 threads, best of 2)")
    ax.set_ylabel("max relative error vs brute force, %")
    ax.set_yscale("log")
    ax.set_title("speed against accuracy (labels: texels_per_sigma)", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(f"{out}/cubemap_accuracy.png", dpi=120)
    print(f"wrote {out}/cubemap_accuracy.png")

# ---- warp fixup exactness --------------------------------------------------------------------
if os.path.exists(f"{out}/cubemap_warp.csv"):
    warp = load_csv(f"{out}/cubemap_warp.csv")
    fig, ax = plt.subplots(figsize=(5, 3.5))
    for mapping in ["warp", "stretch"]:
        pts = [r for r in warp if r["mapping"] == mapping]
        ax.semilogx([r["size"] for r in pts], [max(r["max_error_texels"], 1e-16) for r in pts], "o-",
                    label=mapping, base=2)
    ax.set_yscale("symlog", linthresh=1e-3)
    ax.set_xlabel("face size")
    ax.set_ylabel("max landing error, texels")
    ax.set_title("runtime fixup (n-1)/n: where per-face sampling lands", fontsize=9)
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(f"{out}/cubemap_warp.png", dpi=120)
    print(f"wrote {out}/cubemap_warp.png")

# ---- irradiance methods against brute force ------------------------------------------------------
if os.path.exists(f"{out}/cubemap_irradiance.csv"):
    import csv
    rows = list(csv.DictReader(open(f"{out}/cubemap_irradiance.csv")))
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for kind, style in (("sh", "s"), ("filter", "o-")):
        sel = [r for r in rows if r["method"].startswith(kind)]
        t = [1e3 * float(r["cpu_1t_s"]) for r in sel]
        for key, fill in (("max_rel_error", None), ("rms_rel_error", "none")):
            ax.plot(t, [100 * float(r[key]) for r in sel], style, mfc=fill,
                    label=f"{'SH' if kind == 'sh' else 'cosine filter'}: {'max' if fill is None else 'RMS'}")
        for r, x in zip(sel, t):
            ax.annotate(r["method"].replace("filter_", "in "), (x, 100 * float(r["max_rel_error"])), fontsize=7,
                        xytext=(3, 3), textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("CPU time, 1 thread (ms; median of 7): 256^2 sky in, 32^2 irradiance out")
    ax.set_ylabel("relative error vs brute force (%), all texels")
    ax.set_title("Irradiance: SH bands 0-2 / 0-4 against the cosine filter per input mip")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(f"{out}/cubemap_irradiance.png", dpi=120)
    print(f"wrote {out}/cubemap_irradiance.png")


# ---- markdown tables for docs/cubemap.md (docs/bench/cubemap_tables.md) ------------------------
lines = ["# Cube-map tables (generated by benchmarks/plot_cubemap.py from the CSVs here)", ""]
lines += ["## Seams (per-face sampling unless seamless)", "",
          "Jump and kink are per edge point, normalised by the same measure inside the faces (mean / max over "
          "the 12 edges); corner: spread of the 3 faces at the 8 corners; distortion: RMS difference from the "
          "plain centre map inside the faces, relative to the mean.", ""]
for lobe in sorted({r["lobe_texels"] for r in seams}):
    lines += [f"### lobe {lobe:g} texel(s)", "",
              "| method | size | jump mean | jump max | kink mean | kink max | corner mean | distortion RMS |",
              "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for n in sizes:
        for meth in methods:
            for r in seams:
                if int(r["size"]) == n and r["method"] == meth and r["lobe_texels"] == lobe:
                    lines.append(f"| {meth} | {n} | {r['edge_jump']:.2g} | {r['edge_jump_max']:.2g} | "
                                 f"{r['edge_kink']:.2g} | {r['edge_kink_max']:.2g} | {r['corner_jump']:.2g} | "
                                 f"{r['distortion_rms']:.2g} |")
    lines.append("")
if os.path.exists(f"{out}/cubemap_accuracy.csv"):
    lines += ["## Speed against accuracy: 256² radiance chain (9 levels)", "",
              "| texels_per_sigma | cutoff | 1 thread, s | 2 threads, s | max relative error |",
              "| --- | --- | --- | --- | --- |"]
    for r in acc:
        lines.append(f"| {r['texels_per_sigma']:g} | {r['cutoff']:g} | {r['seconds_1_thread']:.3f} | "
                     f"{r['seconds_2_threads']:.3f} | {100 * r['max_rel_error']:.2f}% |")
    lines.append("")
if os.path.exists(f"{out}/cubemap.csv"):
    lines += ["## Benchmarks (medians)", "", "| benchmark | ms | max relative error vs brute force |",
              "| --- | --- | --- |"]
    for name, row in sorted(m.items()):
        err = row.get("max_rel_error", "")
        err = f"{100 * err:.2f}%" if isinstance(err, float) else ""
        lines.append(f"| {name} | {row['real_time']:.3g} | {err} |")
    lines.append("")
with open(f"{out}/cubemap_tables.md", "w") as f:
    f.write("\n".join(lines))
print(f"wrote {out}/cubemap_tables.md")
