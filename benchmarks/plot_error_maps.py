"""Draws docs/bench/error_maps.png from docs/bench/error_maps_sweep.csv and the maps
benchmarks/sweep_error_maps.cpp writes (build-bench/error_maps/error_map_NAME.f32, or the
directory given as the second argument): per built-in scene, the signed relative error of the
cached bake against a hemicube per texel, texel by texel in lightmap space, in false colour on a
symmetric scale (grey: not valid in both, or no texel), so where the cache errs can be seen."""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from bench_csv import load_csv  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
maps = sys.argv[2] if len(sys.argv) > 2 else "build-bench/error_maps"
rows = load_csv(f"{out}/error_maps_sweep.csv")
scale = 5.0  # percent: the colour scale's ends, +-5%
fig, axes = plt.subplots(1, len(rows), figsize=(4.2 * len(rows), 4.6))
if len(rows) == 1:
    axes = [axes]
cmap = plt.get_cmap("RdBu_r").copy()
cmap.set_bad("0.75")
for ax, r in zip(axes, rows):
    size = int(r["size"])
    m = np.fromfile(f"{maps}/error_map_{r['scene']}.f32", dtype=np.float32).reshape(size, size) * 100.0
    im = ax.imshow(np.ma.masked_invalid(m), cmap=cmap, vmin=-scale, vmax=scale, origin="lower", interpolation="nearest")
    ax.set_title(f"{r['scene']}\nRMS {100 * r['rms_rel_err']:.2f}%, p99 {100 * r['p99_abs_rel_err']:.1f}%, "
                 f"max {100 * r['max_abs_rel_err']:.0f}%\nhemicubes {100 * r['hemicube_fraction']:.1f}% of texels x bounces",
                 fontsize=9)
    ax.set_xticks([])
    ax.set_yticks([])
fig.colorbar(im, ax=axes, shrink=0.8, label="(Y - Y_ref) / max(Y_ref, 5% of mean), %")
fig.suptitle(f"Where the cache errs: {int(rows[0]['size'])}² lightmaps, N = 64, a = 0.2, 3 bounces (lightmap space)")
fig.savefig(f"{out}/error_maps.png", dpi=110, bbox_inches="tight")
print(f"wrote {out}/error_maps.png")
