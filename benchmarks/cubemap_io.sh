#!/usr/bin/env bash
# EXR writing of a 256^2 RGB cube map (the SH9 irradiance of the procedural sky, written by
# write_exr_cubemap with ZIP compression) in paired rounds: 32-bit floats or half floats, without
# or with OpenEXR's thread pool (2 threads). The filter is timed apart (cubemap_run's filter_s).
#
#   bash benchmarks/cubemap_io.sh CUBEMAP_RUN OUT.csv [ROUNDS=5] [SCRATCH_DIR=/tmp]
set -euo pipefail
run=${1:?usage: cubemap_io.sh CUBEMAP_RUN OUT.csv [ROUNDS] [SCRATCH_DIR]}
out=${2:?usage: cubemap_io.sh CUBEMAP_RUN OUT.csv [ROUNDS] [SCRATCH_DIR]}
rounds=${3:-5}
scratch=${4:-/tmp}
echo "round,type,exr_threads,load1,filter_s,write_s,bytes" > "$out"
for ((r = 0; r < rounds; ++r)); do
  for cfg in "float32 0" "half16 0" "float32 2" "half16 2"; do
    set -- $cfg
    half=()
    [ "$1" = half16 ] && half=(--half)
    file="$scratch/hemilight_cubemap_io_$$.exr"
    load=$(cut -d' ' -f1 /proc/loadavg)
    line=$("$run" --job sh9 --out-size 256 --threads 1 --output "$file" "${half[@]}" --exr-threads "$2")
    IFS=, read -r _ _ _ _ _ filter_s _ write_s <<< "$line"
    echo "$r,$1,$2,$load,$filter_s,$write_s,$(stat -c %s "$file")" >> "$out"
    rm -f "$file"
  done
done
/usr/bin/python3 - "$out" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
base = {r["round"]: float(r["write_s"]) for r in rows if r["type"] == "float32" and r["exr_threads"] == "0"}
for t in ("float32", "half16"):
    for k in ("0", "2"):
        sel = [r for r in rows if r["type"] == t and r["exr_threads"] == k]
        w = [float(r["write_s"]) for r in sel]
        ratio = statistics.median(base[r["round"]] / float(r["write_s"]) for r in sel)
        print(f"{t} exr_threads {k}: write median {statistics.median(w):.3f} s, {sel[0]['bytes']} bytes, "
              f"{ratio:.2f}x faster than float32 without threads (median of per-round ratios), "
              f"load {statistics.median(float(r['load1']) for r in sel):.1f}")
PY
