"""Chart of see-through surfaces' cost (docs/bench/opacity.png, from opacity.csv written by
sweep_opacity): on the foliage stand-in at N = 64, one thread, the time per hemicube and per shadow
ray against the number of cards, for opaque, alpha-tested and translucent cards (medians of paired
rounds), and the ratio to the opaque cards."""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_csv

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
rows = load_csv(f"{out}/opacity.csv")
modes = list(dict.fromkeys(r["mode"] for r in rows))
fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
for mode in modes:
    sel = [r for r in rows if r["mode"] == mode]
    x = [r["cards"] for r in sel]
    axes[0].plot(x, [r["us_per_hemicube"] for r in sel], "o-", label=mode)
    axes[1].plot(x, [r["ratio_vs_opaque"] for r in sel], "o-", label=mode)
    axes[2].plot(x, [r["us_per_ray"] for r in sel], "o-", label=mode)
for ax, title in zip(axes, ["time per hemicube (µs, N = 64)", "hemicube time / opaque cards (paired)",
                            "time per shadow ray (µs)"]):
    ax.set_xscale("log")
    ax.set_xlabel("cards (2 triangles each) over a 20 m x 20 m ground")
    ax.set_title(title)
    ax.legend()
axes[0].set_yscale("log")
axes[1].axhline(1.0, color="grey", lw=0.8)
fig.tight_layout()
fig.savefig(f"{out}/opacity.png", dpi=110)
for r in rows:
    print(f"{int(r['cards']):5d} {r['mode']:13s} {r['us_per_hemicube']:9.1f} us/hemicube x{r['ratio_vs_opaque']:.2f}  "
          f"{r['us_per_ray']:.3f} us/ray x{r['ray_ratio_vs_opaque']:.2f}  card texels {100 * r['card_texel_share']:.1f}%")
