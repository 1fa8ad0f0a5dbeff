#!/usr/bin/env bash
# Paired timing rounds of two builds on the bake target (sweep_bake --target --bake-only): each
# round runs OLD then NEW once per scene, and the medians over rounds of the bake time, the cache's
# placement time and placement's share of the bake are printed per build, with the paired ratio
# of the medians. Machines drift; alternating the two builds makes the ratio fair.
#   usage: bash benchmarks/paired_bake.sh ROUNDS OLD_SWEEP_BAKE NEW_SWEEP_BAKE [--scenes a,b]
# OLD_SWEEP_BAKE / NEW_SWEEP_BAKE: sweep_bake binaries of the two builds (both must know --bake-only).
set -euo pipefail
[ $# -ge 3 ] || { echo "usage: bash benchmarks/paired_bake.sh ROUNDS OLD_SWEEP_BAKE NEW_SWEEP_BAKE [--scenes a,b]" >&2; exit 2; }
rounds=$1 old=$2 new=$3
shift 3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for r in $(seq "$rounds"); do
  for which in old new; do
    bin=$old; [ "$which" = new ] && bin=$new
    "$bin" --target "$tmp/$which-$r.csv" 1 --bake-only "$@" > /dev/null
  done
done
/usr/bin/python3 - "$tmp" "$rounds" <<'PY'
import csv, statistics, sys, os
tmp, rounds = sys.argv[1], int(sys.argv[2])
rows = {}
for which in ("old", "new"):
    for r in range(1, rounds + 1):
        for row in csv.DictReader(open(os.path.join(tmp, f"{which}-{r}.csv"))):
            rows.setdefault((row["scene"], which), []).append(row)
print("scene,build,rounds,bake_s,placement_s,placement_share,hemicubes")
for scene in sorted({k[0] for k in rows}):
    med = {}
    for which in ("old", "new"):
        rs = rows[(scene, which)]
        bake = statistics.median(float(x["seconds"]) for x in rs)
        place = statistics.median(float(x["placement_seconds"]) for x in rs)
        share = statistics.median(float(x["placement_seconds"]) / float(x["seconds"]) for x in rs)
        med[which] = (bake, place)
        print(f"{scene},{which},{len(rs)},{bake:.3f},{place:.3f},{100 * share:.1f}%,{rs[0]['hemicubes']}")
    print(f"{scene},new/old,,{med['new'][0] / med['old'][0]:.3f},{med['new'][1] / med['old'][1]:.3f},,")
PY
