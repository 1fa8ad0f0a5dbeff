"""Chart of see-through surfaces' cost (docs/bench/opacity.png, from opacity.csv written by
sweep_opacity): on the foliage stand-in at N = 64, one thread, the time per hemicube and per shadow
ray against the number of cards, for opaque, alpha-tested and translucent cards (medians of paired
rounds), and the ratio to the opaque cards; and from ao_cost.csv, ambient occlusion's bake time
over the bake without it (the default rule, and AO riding on E's records)."""
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_csv

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
rows = load_csv(f"{out}/opacity.csv")
modes = list(dict.fromkeys(r["mode"] for r in rows))
fig, axes = plt.subplots(1, 4, figsize=(18, 4.2))
for mode in modes:
    sel = [r for r in rows if r["mode"] == mode]
    x = [r["cards"] for r in sel]
    axes[0].plot(x, [r["us_per_hemicube"] for r in sel], "o-", label=mode)
    axes[1].plot(x, [r["ratio_vs_opaque"] for r in sel], "o-", label=mode)
    axes[2].plot(x, [r["us_per_ray"] for r in sel], "o-", label=mode)
for ax, title in zip(axes[:3], ["time per hemicube (µs, N = 64)", "hemicube time / opaque cards (paired)",
                            "time per shadow ray (µs)"]):
    ax.set_xscale("log")
    ax.set_xlabel("cards (2 triangles each) over a 20 m x 20 m ground")
    ax.set_title(title)
    ax.legend()
axes[0].set_yscale("log")
ao_path = f"{out}/ao_cost.csv"
if os.path.exists(ao_path):
    ao = load_csv(ao_path)
    scenes = list(dict.fromkeys(r["scene"] for r in ao))
    variants = [v for v in dict.fromkeys(r["variant"] for r in ao) if v != "no_ao"]
    width = 0.8 / max(len(variants), 1)
    for k, v in enumerate(variants):
        ys = [next(r["ratio_vs_no_ao"] for r in ao if r["scene"] == sc and r["variant"] == v) for sc in scenes]
        axes[3].bar([i + k * width for i in range(len(scenes))], ys, width, label=v)
    axes[3].set_xticks([i + 0.4 - width / 2 for i in range(len(scenes))])
    axes[3].set_xticklabels(scenes)
    axes[3].axhline(1.0, color="grey", lw=0.8)
    axes[3].set_title("bake time with AO / without (128², paired)")
    axes[3].legend()
    for r in ao:
        print(f"{r['scene']:13s} {r['variant']:16s} {r['seconds']:.3f} s x{r['ratio_vs_no_ao']:.3f} {int(r['hemicubes'])} hemicubes")
axes[1].axhline(1.0, color="grey", lw=0.8)
fig.tight_layout()
fig.savefig(f"{out}/opacity.png", dpi=110)
for r in rows:
    print(f"{int(r['cards']):5d} {r['mode']:13s} {r['us_per_hemicube']:9.1f} us/hemicube x{r['ratio_vs_opaque']:.2f}  "
          f"{r['us_per_ray']:.3f} us/ray x{r['ray_ratio_vs_opaque']:.2f}  card texels {100 * r['card_texel_share']:.1f}%")
