#!/usr/bin/env bash
# Regenerates the benchmark CSVs and charts under docs/bench/ (one command for all of them):
#   bash benchmarks/run.sh            every benchmark and sweep
#   bash benchmarks/run.sh NAME...    only these (e.g. geometry raster)
#   bash benchmarks/run.sh bake_scaling       bake time and peak memory against triangles, lightmap size
#                                     and threads, on a heightfield and the stand-in levels
#                                     (benchmarks/sweep_bake_scaling.cpp; ~45-65 min, not run by default);
#                                     BAKE_SCALING_FLAGS="--quick" or "--studies closed,open --append" etc.
#   bash benchmarks/run.sh cache_resolution   the cache at hemicube N = 64..512 against a converged
#                                     reference (docs/cache.md; ~25-40 min on 2 cores, not run by default)
#   bash benchmarks/run.sh cache_weights      the cache's interpolation weights, ward against
#                                     ward_continuous, first order (docs/cache.md; 15-30 min; not run by default)
#   bash benchmarks/run.sh cache_second_order the cache's second-order term against first order, with
#                                     both weights (docs/cache.md; ~25 min; not run by default)
#   bash benchmarks/run.sh cache_levels       the cache on the stand-in levels: hemicube share, error against
#                                     converged, radius counters, before and after (docs/cache.md; ~1.5 h; not by default)
#   bash benchmarks/run.sh edge_downstream    what exact edge coverage buys downstream (docs/raster.md; ~2.5 min; also
#                                     in the default run); EDGE_DOWNSTREAM_FLAGS="--parts cost" etc. runs a subset
#   bash benchmarks/run.sh unwrap             the lightmap unwrapper: utilisation, stretch, seams, time, and bakes on its
#                                     UVs against converged references (docs/unwrap.md; ~10 min; also in the default run)
#   bash benchmarks/run.sh edge_downstream_open  the same (parts cost, n, cache) on the open scenes: the
#                                     pavilion, the street and a 10k-triangle terrain (~4.5 min; not run by default)
#   bash benchmarks/run.sh cycles             hemilight against Blender's Cycles on the arena at 1024²: error
#                                     against time (benchmarks/cycles_compare.py; needs Debian's blender;
#                                     ~30 min; CYCLES_FLAGS="--quick" for a few minutes; not run by default)
#   bash benchmarks/run.sh raster_levels      a hemicube's cost on the stand-in levels (default size and 1M
#                                     triangles) over the hexagon room's, culling on and off, paired rounds
#                                     (docs/raster.md; ~4 min; RASTER_LEVELS_FLAGS="--quick" etc.; in the default run)
#   bash benchmarks/run.sh seams              seam stitching: the step along coplanar seams before and after against
#                                     the bake's error, the change of the other texels, the cost (docs/bake.md, "Seams";
#                                     ~11 min the first time, ~6.5 with the references kept in build-bench/seams_truth; in the default
#                                     run); SEAMS_FLAGS="--scenes open_street --sizes 256" etc.
#   bash benchmarks/run.sh opacity            see-through surfaces' cost: foliage cards opaque, alpha-tested and
#                                     translucent, per hemicube and per shadow ray, and ambient occlusion's cost in bakes,
#                                     paired rounds (docs/materials.md, docs/bake.md; ~5 min; in the default run); OPACITY_FLAGS="--cards 250 --rounds 3" etc.
#   bash benchmarks/run.sh shards             the sharded bake on the stand-in levels: error, hemicubes and shard balance
#                                     against the shard count, set-up, merge and transfer (sweep_shards), the Dask driver's
#                                     speed-up against worker processes (benchmarks/dask_speedup.py), and the paper estimate
#                                     for a 32-page level (docs/distributed.md; ~25 min; not run by default);
#                                     SHARDS_FLAGS="--shards 1,4" DASK_SPEEDUP_FLAGS="--rounds 3" etc.
# What each program measures, what it writes and how long it takes: benchmarks/README.md.
# For each NAME: build-bench/benchmarks/bench_NAME runs as a Google Benchmark with repetitions
# (CSV of the medians etc.), build-bench/benchmarks/sweep_NAME (if any) writes its own CSV, and
# benchmarks/plot_NAME.py (if any) draws docs/bench/NAME.png from the CSV(s).
# Set-up: run `bash .ci/build.sh main` once first (installs the Debian packages).
set -euo pipefail
cd "$(dirname "$0")/.."
build=build-bench
# Examples on: the Cycles comparison (cycles) runs hemilight_make_level and hemilight_bake.
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DHEMILIGHT_BUILD_BENCHMARKS=ON \
      -DHEMILIGHT_BUILD_TESTS=OFF -DHEMILIGHT_BUILD_EXAMPLES=ON > /dev/null
cmake --build "$build" -j "$(nproc)"
mkdir -p docs/bench
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for f in "$build"/benchmarks/bench_* "$build"/benchmarks/sweep_*; do
    [ -x "$f" ] || continue
    n=$(basename "$f"); n=${n#bench_}; n=${n#sweep_}
    [ "$n" = bake_scaling ] && continue  # long (a 1M-triangle bake, 4096^2 lightmaps): only when named
    [ "$n" = cache_levels ] && continue  # long (bakes of the levels up to 1024²): only when named
    [ "$n" = shards ] && continue  # long (per-texel references of three levels, the Dask rounds): only when named
    [[ " ${names[*]-} " == *" $n "* ]] || names+=("$n")
  done
fi
for n in "${names[@]}"; do
  if [ "$n" = cache_second_order ]; then
    # cache_options::second_order (on by default) against first order, each with
    # cache_weight::ward and ward_continuous, on the 128 grid with gradients: docs/cache.md, "The
    # defaults at N = 64-1024, and the two weights". The same records for all four; only the
    # interpolation differs. ~10 min on 2 cores with the per-point references of cache_weights
    # already in build-bench/cache_truth, ~25 min without.
    echo "== sweep_cache (second-order interpolation)"
    csv=docs/bench/cache_second_order.csv truth="$build/cache_truth"
    rm -f "$csv"; mkdir -p "$truth"
    for w in ward ward_continuous; do
      for so in no yes; do
        v=$w; [ "$so" = yes ] && v="$w+second_order"
        c=(--append --grid 128 --gradients yes --truth-cache "$truth" --rolls 4 --weight "$w" --second-order "$so"
           --variant "$v")
        "$build/benchmarks/sweep_cache" "$csv" "${c[@]}" --converged 1024 --stride 76 --scenes cornell --n 64,512 \
          --a 0.2,0.3,0.5,0.6,0.7,1.0
        "$build/benchmarks/sweep_cache" "$csv" "${c[@]}" --converged 1024 --stride 28 --scenes hexagon --n 64,512 \
          --a 0.2,0.3,0.5,0.7,1.0
        "$build/benchmarks/sweep_cache" "$csv" "${c[@]}" --converged 2048 --stride 76 --scenes cornell --n 1024 \
          --a 0.5,0.58,0.65
        "$build/benchmarks/sweep_cache" "$csv" "${c[@]}" --converged 512 --stride 7 --scenes sky --n 64 \
          --a 0.1,0.2,0.3,0.5
      done
    done
    PYTHONPATH=benchmarks /usr/bin/python3 benchmarks/plot_cache.py docs/bench
    continue
  fi
  if [ "$n" = cache_weights ]; then
    # cache_weight::ward against ward_continuous (and each with integrate_options::
    # extrapolate_wall_depth) on the 128 grid, with gradients, first order (--second-order no):
    # docs/cache.md. The same
    # records for both weights; only the interpolation differs. ~15 min on 2 cores here
    # (the per-point references at N = 512 and 1024 dominate; kept in build-bench/cache_truth).
    echo "== sweep_cache (interpolation weights)"
    csv=docs/bench/cache_weights.csv truth="$build/cache_truth"
    rm -f "$csv"; mkdir -p "$truth"
    for w in ward ward_continuous; do
      for x in no yes; do
        v=$w; [ "$x" = yes ] && v="$w+extrapolate"
        c=(--append --grid 128 --gradients yes --truth-cache "$truth" --rolls 4 --weight "$w"
           --extrapolate-wall-depth "$x" --variant "$v" --second-order no)
        "$build/benchmarks/sweep_cache" "$csv" "${c[@]}" --converged 1024 --stride 76 --scenes cornell --n 64,256,512 \
          --a 0.2,0.3,0.5,0.55,0.7,1.0
        "$build/benchmarks/sweep_cache" "$csv" "${c[@]}" --converged 1024 --stride 28 --scenes hexagon --n 64,256,512 \
          --a 0.2,0.3,0.5,1.0
        "$build/benchmarks/sweep_cache" "$csv" "${c[@]}" --converged 2048 --stride 76 --scenes cornell --n 1024 \
          --a 0.5,0.55,0.6
      done
      "$build/benchmarks/sweep_cache" "$csv" --append --grid 128 --gradients yes,no --truth-cache "$truth" --weight "$w" --second-order no \
        --converged 512 --stride 7 --scenes sky --n 64 --a 0.1,0.2,0.3,0.5 --variant "$w"
    done
    # the Cornell 1% target at N = 1024: the two a between the rows that bracket it
    "$build/benchmarks/sweep_cache" "$csv" --append --grid 128 --gradients yes --truth-cache "$truth" --rolls 4 --second-order no \
      --weight ward_continuous --variant ward_continuous --converged 2048 --stride 76 --scenes cornell --n 1024 --a 0.57,0.58
    PYTHONPATH=benchmarks /usr/bin/python3 benchmarks/plot_cache.py docs/bench
    continue
  fi
  if [ "$n" = cache_levels ]; then
    # The cache on the stand-in levels (docs/cache.md, "Levels"): hemicube share, error against a
    # converged reference (N = 256, 2 rolls, every 37th texel; every 97th at 1024²), the radius
    # counters, before (--legacy) and now; at 256² and 512² also the bake without the cache (time
    # ratio). ~1.5 h on 2 cores; the converged references are kept in build-bench/cache_levels_truth.
    echo "== sweep_cache_levels"
    csv=docs/bench/cache_levels.csv truth="$build/cache_levels_truth"
    rm -f "$csv"; mkdir -p "$truth"
    for v in legacy default; do
      flags=(--append --truth-cache "$truth" --variant "$v"); [ "$v" = legacy ] && flags+=(--legacy)
      "$build/benchmarks/sweep_cache_levels" "$csv" "${flags[@]}" --levels arena,keep --sizes 256,512 --no-cache-sizes 256,512
      "$build/benchmarks/sweep_cache_levels" "$csv" "${flags[@]}" --levels arena,keep --sizes 1024 --stride 97
    done
    "$build/benchmarks/sweep_cache_levels" "$csv" --append --truth-cache "$truth" --levels city_block,terrain_town --sizes 512
    PYTHONPATH=benchmarks /usr/bin/python3 benchmarks/plot_cache_levels.py docs/bench
    continue
  fi
  if [ "$n" = cache_resolution ]; then
    echo "== sweep_cache (resolution study)"
    csv=docs/bench/cache_resolution.csv truth="$build/cache_truth" a=0.05,0.1,0.2,0.3,0.5
    rm -f "$csv"; mkdir -p "$truth"
    common=(--append --grid 64 --a "$a" --truth-cache "$truth" --rolls 4 --second-order no)  # first order: the study compares resolutions, not interpolants
    "$build/benchmarks/sweep_cache" "$csv" "${common[@]}" --scenes hexagon --n 64,128,256,512 \
      --converged 1024 --stride 7 --check 2048 --check-stride 4
    "$build/benchmarks/sweep_cache" "$csv" "${common[@]}" --scenes cornell --n 64,128,256,512 \
      --converged 1024 --stride 19 --check 2048 --check-stride 6
    "$build/benchmarks/sweep_cache" "$csv" "${common[@]}" --scenes sky --n 64,128 \
      --converged 512 --stride 7 --check 1024 --check-stride 4
    # the hexagon room ceiling and the Cornell box on the default 128 x 128 grid (fractions depend on
    # the grid), with gradients, with and without cache_options::expert.lone_record_change_limit;
    # ~1.5 h more on 2 shared cores (the per-point references at N = 512 dominate: 65,536 hemicubes)
    k128=docs/bench/cache_resolution_k128.csv
    rm -f "$k128"
    for lc in 0.25 0; do
      kc=(--append --grid 128 --gradients yes --truth-cache "$truth" --rolls 4 --converged 1024 --check 2048 --second-order no
          --lone-record-change-limit "$lc" --variant "lone_record_change_limit=$lc")
      "$build/benchmarks/sweep_cache" "$k128" "${kc[@]}" --a 0.1,0.2,0.3,0.5,0.7,1.0 --scenes hexagon --n 256,512 \
        --stride 28 --check-stride 4
      "$build/benchmarks/sweep_cache" "$k128" "${kc[@]}" --a 0.1,0.2,0.3,0.5,0.7,1.0 --scenes cornell --n 256,512 \
        --stride 76 --check-stride 6
    done
    PYTHONPATH=benchmarks /usr/bin/python3 benchmarks/plot_cache.py docs/bench
    continue
  fi
  if [ "$n" = seams ]; then
    # Seam stitching on the built-in scenes (unwrapper's UVs) and the stand-in levels (docs/bake.md,
    # "Seams"): docs/bench/seams.csv and seams_cost.csv; the per-texel references (N = 128) are kept
    # in build-bench/seams_truth. The flags at the top of benchmarks/sweep_seams.cpp.
    echo "== sweep_seams"
    mkdir -p "$build/seams_truth"
    # shellcheck disable=SC2086  # the flags are words on purpose
    "$build/benchmarks/sweep_seams" docs/bench/seams.csv --truth-cache "$build/seams_truth" ${SEAMS_FLAGS-}
    PYTHONPATH=benchmarks /usr/bin/python3 benchmarks/plot_seams.py docs/bench
    continue
  fi
  if [ "$n" = edge_downstream ]; then
    # What exact edge coverage buys downstream (docs/raster.md): cost, the cache at a matched hemicube
    # budget, the N at which a hemicube per point reaches 1%. ~2.5 min on 2 cores. A subset:
    # EDGE_DOWNSTREAM_FLAGS="--parts n --scenes cornell" (flags at the top of sweep_edge_downstream.cpp).
    echo "== sweep_edge_downstream"
    # shellcheck disable=SC2086  # the flags are words on purpose
    "$build/benchmarks/sweep_edge_downstream" docs/bench/edge_downstream.csv ${EDGE_DOWNSTREAM_FLAGS-}
    PYTHONPATH=benchmarks /usr/bin/python3 benchmarks/plot_edge_downstream.py docs/bench
    continue
  fi
  if [ "$n" = edge_downstream_open ]; then
    # The same on open scenes like game content under a sky (open_pavilion, open_street, heightfield(10000)):
    # parts cost, n and cache; not in the default run (the silhouette part is edge_downstream's). ~4.5 min on
    # 2 cores. EDGE_DOWNSTREAM_FLAGS apply here too, after these (e.g. "--truth-cache build-bench/edge_truth").
    echo "== sweep_edge_downstream (open scenes)"
    # shellcheck disable=SC2086  # the flags are words on purpose
    "$build/benchmarks/sweep_edge_downstream" docs/bench/edge_downstream_open.csv --scenes pavilion,street,terrain \
      --parts cost,n,cache ${EDGE_DOWNSTREAM_FLAGS-}
    PYTHONPATH=benchmarks /usr/bin/python3 benchmarks/plot_edge_downstream.py docs/bench edge_downstream_open
    continue
  fi
  if [ "$n" = cycles ]; then
    # hemilight against Cycles (Blender 3.4.1, `apt-get install blender`): docs/levels.md. Each bake's
    # outputs are kept in build-bench/cycles/ and reused; the flags at the top of cycles_compare.py.
    echo "== cycles_compare"
    # shellcheck disable=SC2086  # the flags are words on purpose
    /usr/bin/python3 benchmarks/cycles_compare.py ${CYCLES_FLAGS-}
    continue
  fi
  if [ "$n" = bake_scaling ]; then
    # Each bake in its own process (peak memory); the flags at the top of sweep_bake_scaling.cpp.
    # Writes the CSV the docs cite (docs/bench/bake_scaling.csv; --append adds to it).
    echo "== sweep_bake_scaling"
    # shellcheck disable=SC2086  # the flags are words on purpose
    "$build/benchmarks/sweep_bake_scaling" docs/bench/bake_scaling.csv ${BAKE_SCALING_FLAGS-}
    PYTHONPATH=benchmarks /usr/bin/python3 benchmarks/plot_bake_scaling.py docs/bench
    continue
  fi
  if [ "$n" = shards ]; then
    echo "== sweep_shards"
    # shellcheck disable=SC2086  # the flags are words on purpose
    "$build/benchmarks/sweep_shards" docs/bench/shards.csv ${SHARDS_FLAGS-}
    echo "== dask_speedup"
    # shellcheck disable=SC2086
    /usr/bin/python3 benchmarks/dask_speedup.py --bake "$build/examples/hemilight_bake" \
      --make-level "$build/examples/hemilight_make_level" --out docs/bench/dask_speedup.csv ${DASK_SPEEDUP_FLAGS-}
    PYTHONPATH=benchmarks /usr/bin/python3 benchmarks/plot_shards.py docs/bench
    continue
  fi
  if [ "$n" = opacity ]; then
    echo "== sweep_opacity"
    # shellcheck disable=SC2086  # the flags are words on purpose
    "$build/benchmarks/sweep_opacity" docs/bench/opacity.csv docs/bench/ao_cost.csv ${OPACITY_FLAGS-}
    PYTHONPATH=benchmarks /usr/bin/python3 benchmarks/plot_opacity.py docs/bench
    continue
  fi
  if [ "$n" = raster_levels ]; then
    # The levels' ratio: cost per hemicube on each level / on hexagon_room(3), N = 64, in paired
    # interleaved rounds (benchmarks/sweep_raster_levels.cpp has the flags). ~4 min on 2 cores.
    echo "== sweep_raster_levels"
    # shellcheck disable=SC2086  # the flags are words on purpose
    "$build/benchmarks/sweep_raster_levels" docs/bench/raster_levels.csv ${RASTER_LEVELS_FLAGS-}
    PYTHONPATH=benchmarks /usr/bin/python3 benchmarks/plot_raster_levels.py docs/bench
    continue
  fi
  if [ "$n" = edge ]; then
    # Exact edge coverage against point sampling: accuracy and paired-round cost (docs/raster.md).
    echo "== sweep_edge"
    "$build/benchmarks/sweep_edge" docs/bench/edge_accuracy.csv docs/bench/edge_cost.csv 7
    PYTHONPATH=benchmarks /usr/bin/python3 benchmarks/plot_edge.py docs/bench
    continue
  fi
  if [ -x "$build/benchmarks/bench_$n" ]; then
    echo "== bench_$n"
    "$build/benchmarks/bench_$n" --benchmark_repetitions="${REPETITIONS:-5}" \
      --benchmark_report_aggregates_only=true \
      --benchmark_out="docs/bench/$n.csv" --benchmark_out_format=csv
  fi
  if [ -x "$build/benchmarks/sweep_$n" ]; then
    echo "== sweep_$n"
    "$build/benchmarks/sweep_$n" "docs/bench/${n}_sweep.csv"
  fi
  if [ -f "benchmarks/plot_$n.py" ]; then
    PYTHONPATH=benchmarks /usr/bin/python3 "benchmarks/plot_$n.py" docs/bench
  fi
done
