"""Table and chart of the stand-in levels' bakes (sweep_bake --target ... --scenes arena,keep,...):
reads FOLDER/bake_target_levels.csv and FOLDER/bake_target_levels_converged.csv, prints the table of
docs/bake.md (per level, size and bounce count: triangles, sampled texels, hemicube share of the
sampled texels and of the bake's time, the cached bake's time against a hemicube per texel, and both
bakes' error against the converged reference per texel class) and draws bake_target_levels.png
(left: bake time, cached and per texel; right: relative RMS and mean relative error against the
converged reference, cached and per texel, per texel class).

usage: plot_bake_levels.py [folder] [name]   (default docs/bench bake_target_levels)
"""
import os
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from bench_csv import load_csv  # noqa: E402


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
    name = sys.argv[2] if len(sys.argv) > 2 else "bake_target_levels"
    rows = load_csv(os.path.join(folder, f"{name}.csv"))
    conv = load_csv(os.path.join(folder, f"{name}_converged.csv"))
    cases = []
    for r in rows:
        key = (r["scene"], int(r["size"]), int(r["bounces"]))
        if key not in cases:
            cases.append(key)
    print("| level | size | bounces | triangles | sampled texels (invalid) | hemicubes / (texels x bounces) | cached bake "
          "(hemicube share) | a hemicube per texel | cached / per texel | RMS vs converged, valid: cached / per texel | "
          "mean rel., valid | RMS near contacts | mean rel. near contacts | load |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    summary = []
    for scene, size, bounces in cases:
        rs = [r for r in rows if r["scene"] == scene and int(r["size"]) == size and int(r["bounces"]) == bounces]
        cached = [r for r in rs if str(r["run"]) != "reference" and int(r["directional"]) == 0]
        ref = next((r for r in rs if str(r["run"]) == "reference"), None)
        if not cached:
            continue
        t = statistics.median(r["seconds"] for r in cached)
        share = statistics.median(r["hemicube_share"] for r in cached)
        c0 = cached[0]
        label = f"{scene}_{size}"

        def err(bake, cls, key):
            for c in conv:
                if c["scene"] == label and int(c["bounces"]) == bounces and c["bake"].startswith(bake) and c["class"] == cls:
                    return c[key]
            return None

        def pct(x):
            return "—" if x is None else f"{100 * x:.2f}%"

        cells = [scene, f"{size}²", str(bounces), f"{int(c0['triangles']):,}",
                 f"{int(c0['sampled_texels']):,} ({int(c0['invalid_texels']):,})", f"{100 * c0['hemicube_fraction']:.1f}%",
                 f"**{t:.1f} s** ({100 * share:.0f}%)", f"{ref['seconds']:.1f} s" if ref else "—",
                 f"{t / ref['seconds']:.2f}" if ref else "—"]
        for cls in ("valid", "near_contact"):
            for key in ("rms_error", "mean_error"):
                cells.append(f"{pct(err('cache', cls, key))} / {pct(err('per_texel', cls, key))}")
        loads = [r["load1"] for r in rs]
        cells.append(f"{min(loads):.1f}-{max(loads):.1f}")
        print("| " + " | ".join(cells) + " |")
        summary.append(dict(label=f"{scene} {size}² {bounces}b", cached=t, per_texel=ref["seconds"] if ref else None,
                            rms=[err("cache", "valid", "rms_error"), err("per_texel", "valid", "rms_error"),
                                 err("cache", "near_contact", "rms_error"), err("per_texel", "near_contact", "rms_error")],
                            mean=[err("cache", "valid", "mean_error"), err("per_texel", "valid", "mean_error"),
                                  err("cache", "near_contact", "mean_error"), err("per_texel", "near_contact", "mean_error")]))
    if not summary:
        sys.exit("no rows")
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(15, 6))
    x = range(len(summary))
    ax.bar([i - 0.2 for i in x], [s["cached"] for s in summary], 0.4, label="cached bake (default a = 0.2)")
    ax.bar([i + 0.2 for i in x], [s["per_texel"] or 0 for s in summary], 0.4, label="a hemicube per texel")
    ax.set_xticks(list(x))
    ax.set_xticklabels([s["label"] for s in summary], rotation=30, fontsize=8)
    ax.set_ylabel("bake wall time, 2 threads (s)")
    ax.set_title("Bake time, N = 64, with the level's sun")
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=8)
    labels = ["cached, valid", "per texel, valid", "cached, near contacts", "per texel, near contacts"]
    for k, (lab, marker) in enumerate(zip(labels, "os^v")):
        ax2.plot(list(x), [s["rms"][k] if s["rms"][k] is not None else float("nan") for s in summary], marker + "-",
                 label=f"relative RMS, {lab}")
        ax2.plot(list(x), [s["mean"][k] if s["mean"][k] is not None else float("nan") for s in summary], marker + ":",
                 mfc="none", label=f"mean relative error, {lab}")
    ax2.axhline(0.01, color="k", ls=":", lw=1)
    ax2.set_yscale("log")
    ax2.set_xticks(list(x))
    ax2.set_xticklabels([s["label"] for s in summary], rotation=30, fontsize=8)
    ax2.set_ylabel("error against the converged reference (N = 256, 4 rolls)")
    ax2.set_title("Error per texel class")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=7)
    fig.tight_layout()
    out = os.path.join(folder, f"{name}.png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
