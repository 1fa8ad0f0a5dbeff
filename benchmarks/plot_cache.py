"""Charts of the irradiance cache: RMS relative error against the fraction of points given a
hemicube, one panel per scene (docs/bench/cache.png, from cache_sweep.csv). Solid: error against
a hemicube at every point (same N); dashed: error against a converged reference (N = 256), with
the N = 64 hemicube-at-every-point's own error as a grey line."""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_csv

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
rows = load_csv(f"{out}/cache_sweep.csv")
scenes = list(dict.fromkeys(r["scene"] for r in rows))
fig, axes = plt.subplots(1, len(scenes), figsize=(4.6 * len(scenes), 3.9))
for ax, scene in zip(axes, scenes):
    for grad, color in ((1, "C0"), (0, "C3")):
        pts = sorted((r["fraction"], r["rms_rel_err"], r["rms_rel_err_converged"]) for r in rows
                     if r["scene"] == scene and r["gradients"] == grad)
        label = "gradients" if grad else "no gradients"
        ax.plot([100 * p[0] for p in pts], [100 * p[1] for p in pts], "o-", color=color, label=f"{label}: vs hemicube per point")
        ax.plot([100 * p[0] for p in pts], [100 * p[2] for p in pts], "s--", color=color, alpha=0.7,
                label=f"{label}: vs converged (N=256)")
    ref = [r["reference_rms_rel_err_converged"] for r in rows if r["scene"] == scene][0]
    ax.axhline(100 * ref, color="grey", lw=1, label="hemicube per point (N=64) vs converged")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_title(scene, fontsize=10)
    ax.set_xlabel("points given a hemicube (%)")
    ax.grid(True, which="both", alpha=0.3)
axes[0].set_ylabel("RMS relative error (%)")
axes[0].legend(fontsize=6.5)
fig.tight_layout()
fig.savefig(f"{out}/cache.png", dpi=110)
print(f"wrote {out}/cache.png")
