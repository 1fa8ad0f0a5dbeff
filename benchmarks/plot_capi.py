"""Draws docs/bench/capi.png from docs/bench/capi_sweep.csv and capi_probes.csv
(benchmarks/sweep_capi.cpp): hemicubes per second through the C ABI's point entries beside the C++
rasterizer + integrator on the same points, per scene and hemicube resolution (medians over paired
rounds; left), and light probes per second with the error of their SH9 irradiance against the
hemicube's (right)."""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from bench_csv import load_csv  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
rows = load_csv(f"{out}/capi_sweep.csv")
probes = load_csv(f"{out}/capi_probes.csv")
modes = ["cpp", "sample", "sampler", "batch_1", "batch_2"]
labels = {"cpp": "C++ render + integrate", "sample": "hemilight_sample_irradiance", "sampler": "hemilight_sampler_irradiance",
          "batch_1": "batch, 1 thread", "batch_2": "batch, 2 threads"}
groups = sorted({(r["scene"], int(r["resolution"])) for r in rows})
fig, (ax, bx) = plt.subplots(1, 2, figsize=(16, 4.8), gridspec_kw={"width_ratios": [2, 1]})
width = 0.8 / len(modes)
for k, mode in enumerate(modes):
    values = []
    for scene, n in groups:
        match = [r for r in rows if r["scene"] == scene and int(r["resolution"]) == n and r["mode"] == mode]
        values.append(match[0]["hemicubes_per_second"] / 1000.0 if match else 0.0)
    ax.bar([g + (k - 2) * width for g in range(len(groups))], values, width, label=labels[mode])
ax.axhline(20.0, color="k", linestyle="--", linewidth=1)
ax.text(len(groups) - 0.5, 20.5, "target: 20k/s, Cornell box, N = 64, one thread", ha="right", fontsize=8)
ax.set_xticks(range(len(groups)))
ax.set_xticklabels([f"{s.replace('_', ' ')}\nN = {n}" for s, n in groups])
ax.set_ylabel("thousand hemicubes per second")
ax.set_title("Point irradiance through the C ABI (from C) and the C++ API, same points, medians of paired rounds")
ax.legend(fontsize=8)

pgroups = sorted({(r["scene"], int(r["resolution"])) for r in probes})
for k, threads in enumerate((1, 2)):
    values = []
    for scene, n in pgroups:
        match = [r for r in probes if r["scene"] == scene and int(r["resolution"]) == n and int(r["threads"]) == threads]
        values.append(match[0]["probes_per_second"] / 1000.0 if match else 0.0)
    bx.bar([g + (k - 0.5) * 0.4 for g in range(len(pgroups))], values, 0.4, label=f"{threads} thread{'s' if threads > 1 else ''}")
labels_p = []
for scene, n in pgroups:
    match = [r for r in probes if r["scene"] == scene and int(r["resolution"]) == n]
    labels_p.append(f"{scene.replace('_', ' ')}\nN = {n}\nSH9 E: {100 * match[0]['sh9_rms_error']:.0f}% RMS")
bx.set_xticks(range(len(pgroups)))
bx.set_xticklabels(labels_p, fontsize=7)
bx.set_ylabel("thousand probes per second (2 hemicubes each)")
bx.set_title("hemilight_sample_probes")
bx.legend(fontsize=8)
fig.tight_layout()
fig.savefig(f"{out}/capi.png", dpi=110)
print(f"wrote {out}/capi.png")
