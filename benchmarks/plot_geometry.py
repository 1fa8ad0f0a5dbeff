"""Chart of the geometry microbenchmarks: weight-table build time against resolution."""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from bench_csv import load_gbench, medians

out = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
m = medians(load_gbench(f"{out}/geometry.csv"))
ns, ms = [], []
for name, row in sorted(m.items()):
    if name.startswith("table_build/"):
        ns.append(int(name.split("/")[1]))
        ms.append(row["real_time"])
order = sorted(range(len(ns)), key=lambda i: ns[i])
fig, ax = plt.subplots(figsize=(5, 3.5))
ax.loglog([ns[i] for i in order], [ms[i] for i in order], "o-")
ax.set_xlabel("hemicube resolution N")
ax.set_ylabel("weight table build, ms (median)")
ax.set_title("hemicube_table build time (3N² texels, all cores)")
ax.grid(True, which="both", alpha=0.3)
fig.tight_layout()
fig.savefig(f"{out}/geometry.png", dpi=120)
print(f"wrote {out}/geometry.png")
