#!/usr/bin/env bash
# hemilight's cube-map filters beside cmft's on the same input, in paired rounds (docs/cubemap.md).
#
#   bash benchmarks/cmft_compare.sh CMFT_SOURCE [BENCH_BUILD=build-bench] [OUT_DIR=docs/bench]
#                                   [ROUNDS=3] [WORK_DIR=/tmp/hemilight-cmft]
#
# CMFT_SOURCE is a checkout of cmft (https://github.com/dariomanesku/cmft; measured at cad5f31).
# It is never vendored nor built inside hemilight's tree: this script compiles its sources
# (src/main.cpp, src/cmft/*.cpp, src/cmft/common/*.cpp; no OpenCL at run time) with the system
# g++ at -O3 -msse2 (what its release build uses) into WORK_DIR, without running the prebuilt
# genie binary its own makefile needs. BENCH_BUILD is a build of hemilight with
# -DHEMILIGHT_BUILD_BENCHMARKS=ON and the cubemap_run target built.
#
# Input: the 256^2 procedural sky (procedural_environment), written by cubemap_run as an RGBA32F
# DDS (the same floats) for cmft; hemilight filters it in memory. Jobs:
#   radiance    cmft's default lobes p_i = 2^(10 (1 - i/8) + 1), 9 levels, 256^2 out, edge fixup
#               none, cmft's phong model; hemilight filter_mip_chain_powers with the same powers
#   irradiance  32^2 out: cmft's SH bands 0-4; hemilight SH bands 0-4 (sh25) and the cosine filter
#               (irradiance_input_size 16, the default)
# Each round runs every (tool, job, threads) once, in turn; threads 1 and 2 (cmft starts N - 1
# workers for --numCpuProcessingThreads N, so it gets N = threads + 1). Timed: hemilight's
# filter call (cubemap_run's filter_s, the input in memory, no file written) and cmft's own
# "Total time" of its filter (its file reading and writing excluded), plus both processes' wall
# and CPU time (/usr/bin/time) including cmft's DDS reading and writing. The 1-minute load
# average is recorded per run: on a shared machine read the times with it.
# Accuracy: each tool's output against filter_reference (brute force) at 300 random texels per
# level (cubemap_run --errors / --compare-dds; cmft's irradiance is E / pi, scaled back).
#
# Writes OUT_DIR/cmft_compare.csv (times), OUT_DIR/cmft_compare_errors.csv and, with
# benchmarks/plot_cmft_compare.py, OUT_DIR/cmft_compare.png.
set -euo pipefail
usage="usage: cmft_compare.sh CMFT_SOURCE [BENCH_BUILD] [OUT_DIR] [ROUNDS] [WORK_DIR]"
src=${1:?$usage}
bench=${2:-build-bench}
out=${3:-docs/bench}
rounds=${4:-3}
work=${5:-/tmp/hemilight-cmft}
run="$bench/benchmarks/cubemap_run"
here=$(cd "$(dirname "$0")" && pwd)
[ -x /usr/bin/time ] || { echo "cmft_compare.sh: needs /usr/bin/time (Debian package time)" >&2; exit 1; }
[ -x "$run" ] || { echo "cmft_compare.sh: $run is missing: build the cubemap_run target of $bench" >&2; exit 1; }
[ -f "$src/src/cmft/cubemapfilter.cpp" ] || { echo "cmft_compare.sh: $src is not a cmft source tree" >&2; exit 1; }
mkdir -p "$work" "$out"

# 1. cmft, built outside hemilight's tree.
cmft="$work/cmft"
if [ ! -x "$cmft" ]; then
  echo "building cmft from $src into $work ..."
  g++ -O3 -msse2 -std=c++11 -w -I "$src/dependency" -I "$src/include" -I "$src/src/cmft" -I "$src/src" \
    "$src/src/main.cpp" "$src"/src/cmft/*.cpp "$src"/src/cmft/common/*.cpp -o "$cmft" -ldl -lpthread
fi

# 2. The same input for both.
"$run" --write-dds "$work/sky256.dds"

# 3. Paired rounds.
csv="$out/cmft_compare.csv"
echo "round,tool,job,threads,load1,filter_s,process_wall_s,process_cpu_s" > "$csv"
timed() {  # timed <output prefix> <command...>: prints "wall cpu" of the command; its output in <prefix>.out
  local prefix=$1
  shift
  /usr/bin/time -f "%e %U %S" -o "$work/time.txt" "$@" > "$prefix.out" 2>&1 || { cat "$prefix.out" >&2; exit 1; }
  awk '{printf "%s %.3f", $1, $2 + $3}' "$work/time.txt"
}
for ((r = 0; r < rounds; ++r)); do
  for threads in 1 2; do
    workers=$((threads + 1))
    # hemilight radiance
    load=$(cut -d' ' -f1 /proc/loadavg)
    read -r wall cpu <<< "$(timed "$work/h" "$run" --job radiance --threads "$threads")"
    filter=$(cut -d, -f6 "$work/h.out")
    echo "$r,hemilight,radiance,$threads,$load,$filter,$wall,$cpu" >> "$csv"
    # cmft radiance
    load=$(cut -d' ' -f1 /proc/loadavg)
    read -r wall cpu <<< "$(timed "$work/c" "$cmft" --input "$work/sky256.dds" --filter radiance --srcFaceSize 256 \
      --excludeBase false --mipCount 9 --glossScale 10 --glossBias 1 --lightingModel phong --edgeFixup none \
      --dstFaceSize 256 --numCpuProcessingThreads "$workers" --useOpenCL false --outputNum 1 \
      --output0 "$work/cmft_radiance" --output0params dds,rgba32f,cubemap)"
    filter=$(grep -o 'Radiance -> Total time: [0-9.]*' "$work/c.out" | awk '{print $NF}')
    echo "$r,cmft,radiance,$threads,$load,$filter,$wall,$cpu" >> "$csv"
    # hemilight irradiance (SH bands 0-4 and the cosine filter)
    for job in sh25 irradiance_filter; do
      load=$(cut -d' ' -f1 /proc/loadavg)
      read -r wall cpu <<< "$(timed "$work/h" "$run" --job "$job" --out-size 32 --threads "$threads")"
      filter=$(cut -d, -f6 "$work/h.out")
      echo "$r,hemilight,irradiance_$job,$threads,$load,$filter,$wall,$cpu" >> "$csv"
    done
    # cmft irradiance (SH bands 0-4)
    load=$(cut -d' ' -f1 /proc/loadavg)
    read -r wall cpu <<< "$(timed "$work/c" "$cmft" --input "$work/sky256.dds" --filter irradiance --dstFaceSize 32 \
      --numCpuProcessingThreads "$workers" --useOpenCL false --outputNum 1 --output0 "$work/cmft_irradiance" \
      --output0params dds,rgba32f,cubemap)"
    filter=$(grep -o 'Irradiance -> Done! Total time: [0-9.]*' "$work/c.out" | awk '{print $NF}')
    echo "$r,cmft,irradiance_sh25,$threads,$load,$filter,$wall,$cpu" >> "$csv"
    echo "round $r, $threads thread(s): done"
  done
done

# 4. Accuracy against brute force.
errors="$out/cmft_compare_errors.csv"
echo "tool,job,level,max_rel_error,rms_rel_error" > "$errors"
"$run" --job radiance --threads 0 --errors | grep '^error' | sed 's/^error,/hemilight,radiance,/' >> "$errors"
"$run" --job radiance --compare-dds "$work/cmft_radiance.dds" | sed 's/^error,/cmft,radiance,/' >> "$errors"
"$run" --job sh25 --threads 0 --errors | grep '^error' | sed 's/^error,/hemilight,irradiance_sh25,/' >> "$errors"
"$run" --job irradiance_filter --threads 0 --errors | grep '^error' | sed 's/^error,/hemilight,irradiance_irradiance_filter,/' >> "$errors"
"$run" --job sh25 --compare-dds "$work/cmft_irradiance.dds" --dds-scale 3.14159265358979 |
  sed 's/^error,/cmft,irradiance_sh25,/' >> "$errors"

# 5. Summary and chart.
/usr/bin/python3 "$here/plot_cmft_compare.py" "$out"
