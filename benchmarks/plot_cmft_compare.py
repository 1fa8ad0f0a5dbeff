"""Summary and chart of benchmarks/cmft_compare.sh: OUT_DIR/cmft_compare.csv (times) and
OUT_DIR/cmft_compare_errors.csv (errors against brute force) -> OUT_DIR/cmft_compare.png and a
markdown table on stdout (medians over the rounds; ratios are medians of per-round ratios).

  /usr/bin/python3 benchmarks/plot_cmft_compare.py [OUT_DIR=docs/bench]
"""
import csv
import statistics
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
rows = list(csv.DictReader(open(f"{out}/cmft_compare.csv")))
errors = list(csv.DictReader(open(f"{out}/cmft_compare_errors.csv")))


def runs(tool, job, threads):
    return {r["round"]: r for r in rows if r["tool"] == tool and r["job"] == job and r["threads"] == str(threads)}


def med(sel, key):
    return statistics.median(float(r[key]) for r in sel.values())


def ratio(a, b, key):  # median over rounds of a / b
    return statistics.median(float(a[k][key]) / float(b[k][key]) for k in a if k in b and float(b[k][key]) > 0)


def worst(tool, job):
    sel = [r for r in errors if r["tool"] == tool and r["job"] == job]
    return max(float(r["max_rel_error"]) for r in sel), max(float(r["rms_rel_error"]) for r in sel)


print("| job | threads | hemilight filter | cmft filter | hemilight process wall / cpu | cmft process wall / cpu |"
      " cmft / hemilight (wall, per round) | load |")
print("| --- | --- | --- | --- | --- | --- | --- | --- |")
pairs = [("radiance", "radiance", "radiance"), ("irradiance SH 0-4", "irradiance_sh25", "irradiance_sh25"),
         ("irradiance: hemilight cosine filter vs cmft SH 0-4", "irradiance_irradiance_filter", "irradiance_sh25")]
for label, hjob, cjob in pairs:
    for t in (1, 2):
        h, c = runs("hemilight", hjob, t), runs("cmft", cjob, t)
        if not h or not c:
            continue
        loads = [float(r["load1"]) for r in list(h.values()) + list(c.values())]
        print(f"| {label} | {t} | {med(h, 'filter_s'):.3f} s | {med(c, 'filter_s'):.3f} s | "
              f"{med(h, 'process_wall_s'):.2f} / {med(h, 'process_cpu_s'):.2f} s | "
              f"{med(c, 'process_wall_s'):.2f} / {med(c, 'process_cpu_s'):.2f} s | "
              f"{ratio(c, h, 'process_wall_s'):.1f}x (filter {ratio(c, h, 'filter_s'):.1f}x, "
              f"cpu {ratio(c, h, 'process_cpu_s'):.1f}x) | {statistics.median(loads):.1f} |")
print()
print("| radiance level | p | hemilight max (RMS) | cmft max (RMS) |")
print("| --- | --- | --- | --- |")
for level in sorted({int(r["level"]) for r in errors if r["job"] == "radiance"}):
    cells = []
    for tool in ("hemilight", "cmft"):
        sel = [r for r in errors if r["tool"] == tool and r["job"] == "radiance" and int(r["level"]) == level]
        cells.append(f"{100 * float(sel[0]['max_rel_error']):.2f}% ({100 * float(sel[0]['rms_rel_error']):.2f}%)"
                     if sel else "-")
    print(f"| {level} | {2 ** (10 * (1 - level / 8) + 1):.4g} | {cells[0]} | {cells[1]} |")
print()
print("| tool, job | max relative error | RMS (worst level) |")
print("| --- | --- | --- |")
for tool, job in [("hemilight", "radiance"), ("cmft", "radiance"), ("hemilight", "irradiance_sh25"),
                  ("cmft", "irradiance_sh25"), ("hemilight", "irradiance_irradiance_filter")]:
    m, r = worst(tool, job)
    print(f"| {tool}, {job} | {100 * m:.2f}% | {100 * r:.2f}% |")

fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5))
labels, hv, cv = [], [], []
for label, hjob, cjob in pairs[:2]:
    for t in (1, 2):
        h, c = runs("hemilight", hjob, t), runs("cmft", cjob, t)
        if h and c:
            labels.append(f"{label}\n{t} thread{'s' if t > 1 else ''}")
            hv.append(med(h, "process_cpu_s"))
            cv.append(med(c, "process_cpu_s"))
x = range(len(labels))
a.bar([i - 0.2 for i in x], hv, 0.4, label="hemilight")
a.bar([i + 0.2 for i in x], cv, 0.4, label="cmft")
a.set_xticks(list(x))
a.set_xticklabels(labels, fontsize=8)
a.set_yscale("log")
a.set_ylabel("process CPU time (s), median of rounds")
a.set_title("256^2 sky: CPU time per job (wall depends on the machine's load)")
a.legend()
for tool, style in (("hemilight", "o-"), ("cmft", "s--")):
    sel = sorted((int(r["level"]), float(r["max_rel_error"])) for r in errors if r["tool"] == tool and r["job"] == "radiance")
    b.plot([s[0] for s in sel], [100 * s[1] for s in sel], style, label=f"{tool} radiance")
b.set_yscale("log")
b.set_xlabel("mip level (cmft lobes p = 2^(10 (1 - i/8) + 1))")
b.set_ylabel("max relative error vs brute force (%)")
b.set_title("Accuracy, 300 random texels per level")
b.axhline(0.75, color="grey", lw=0.8, ls=":")
b.legend()
fig.tight_layout()
fig.savefig(f"{out}/cmft_compare.png", dpi=110)
