// Hemicubes per second of the software rasterizer (render only: culling, visibility, resolve),
// on the reference scenes, for N in {16, 32, 64, 128, 256}, on one thread and on all threads.
// items_per_second = hemicubes per second. Each benchmark renders hemicubes at a fixed set of 256
// pseudo-random surface points of its scene (area-weighted, with the surface normal, lifted by
// 1e-4 of the scene size), one after another, the way a baker visits lightmap texels.
//   name: raster/<scene>/N:<n>/threads:<t>
// The stand-in levels (levels.hpp, docs/levels.md: arena and keep at their default ~50k
// triangles, city_block and terrain_town at ~150k) at N = 64 only, with occlusion culling on (its
// default there) and off (raster_options::diagnostics.occlusion_culling), the same 256 points
// placed the same way (some of them lie on faces hidden inside other solids, as a bake's texels
// do):
//   name: raster/<level>/N:64/threads:<t>/culling:<on|off>
// With --levels_1m (not a Google Benchmark flag; taken out of argv before it parses the rest) the
// closed levels at ~1M triangles too (arena_1M, keep_1M; ~2 s each to build, 3 repetitions).
// Counters on the level rows (one thread): triangles_tested, face_triangles and
// triangles_occluded per hemicube (raster_statistics), averaged over the 256 points.
// One-thread runs are timed in CPU time of the benchmark thread (the machine may be shared).
// Multi-threaded runs hand batches of hemicubes (256 for the small scenes, 64 for 10k triangles,
// 16 above) to hemilight::parallel_for (one rasterizer per worker) and are timed in real time. The 1M-triangle scene uses 3 repetitions (a full run with
// the default 5 takes several minutes), whatever --benchmark_repetitions says.
// Counter `steal`: the fraction of all CPU time that the hypervisor gave to other guests during
// the run (/proc/stat; -1 where unknown). Two-thread rows with steal over a few percent measure
// the host more than the library (docs/raster.md).
#include "hemilight/levels.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/reference_scenes.hpp"

#include "bench_points.hpp"
#include "host_steal.hpp"

#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace hemilight;

struct bench_scene {
  std::string name;
  std::function<scene_mesh()> build;
  std::shared_ptr<const scene> built;
  std::vector<glm::vec3> points;
  std::vector<frame> frames;
  // The levels' raster_statistics per hemicube (tested, drawn, occluded), culling off [0] and on [1];
  // -1 until measured.
  std::array<std::array<double, 3>, 2> counters{{{-1, -1, -1}, {-1, -1, -1}}};
};

// Area-weighted random points on the front faces of a scene (bench_points.hpp).
void make_points(bench_scene& b) {
  const scene_mesh m = b.build();
  b.built = scene::create(m.desc());
  bench::sample_points p = bench::surface_points(m, 256, 1e-4f * b.built->size());
  b.points = std::move(p.points);
  b.frames = std::move(p.frames);
}

// The stand-in levels (levels.hpp) by name, at a target triangle count (0: the level's default).
bench_scene level_scene(const std::string& label, const std::string& level, std::size_t triangles) {
  return {label,
          [level, triangles] {
            level_options o;
            o.target_triangles = triangles;
            return make_level(level, o).mesh;
          },
          nullptr,
          {},
          {}};
}

// The levels' entries of scenes(), after the reference scenes.
constexpr std::size_t first_level = 6;

std::vector<bench_scene>& levels_1m() {
  static std::vector<bench_scene> list = {level_scene("arena_1M", "arena", 1000000), level_scene("keep_1M", "keep", 1000000)};
  return list;
}

std::vector<bench_scene>& scenes() {
  static std::vector<bench_scene> list = {
      {"cornell_box_32", [] { return cornell_box(); }, nullptr, {}, {}},
      {"hexagon_room_496", [] { return hexagon_room(2); }, nullptr, {}, {}},
      {"hexagon_room_1062", [] { return hexagon_room(3); }, nullptr, {}, {}},
      {"heightfield_10k", [] { return heightfield(10000); }, nullptr, {}, {}},
      {"heightfield_100k", [] { return heightfield(100000); }, nullptr, {}, {}},
      {"heightfield_1M", [] { return heightfield(1000000); }, nullptr, {}, {}},
      level_scene("arena", "arena", 0),
      level_scene("keep", "keep", 0),
      level_scene("city_block", "city_block", 0),
      level_scene("terrain_town", "terrain_town", 0),
  };
  return list;
}

bench_scene& get_scene(std::size_t index) {
  bench_scene& b = scenes()[index];
  if (!b.built) make_points(b);  // built on first use, outside the timed loop
  return b;
}

raster_options culling(bool on) {
  raster_options o;
  o.diagnostics.occlusion_culling = on;
  return o;
}

void render_one_thread(benchmark::State& state, std::size_t scene_index, int n, raster_options options) {
  bench_scene& b = get_scene(scene_index);
  hemicube_rasterizer r(b.built, options);
  hemicube_buffer buf;
  std::size_t k = 0;
  const bench::cpu_ticks before = bench::read_cpu_ticks();
  for (auto _ : state) {
    r.render(b.points[k], b.frames[k], n, buf);
    benchmark::DoNotOptimize(buf.radiance.data());
    k = (k + 1) % b.points.size();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
  state.counters["steal"] = bench::steal_fraction(before, bench::read_cpu_ticks());
  if (scene_index >= first_level) {  // the culling's counters: one pass over the points, after the timed loop, once
    const std::size_t key = options.diagnostics.occlusion_culling ? 1 : 0;
    if (b.counters[key][0] < 0) {
      double tested = 0, drawn = 0, occluded = 0;
      for (std::size_t i = 0; i < b.points.size(); ++i) {
        r.render(b.points[i], b.frames[i], n, buf);
        const raster_statistics& st = r.statistics();
        tested += double(st.triangles_tested);
        drawn += double(st.face_triangles);
        occluded += double(st.triangles_occluded);
      }
      const double count = double(b.points.size());
      b.counters[key] = {tested / count, drawn / count, occluded / count};
    }
    state.counters["triangles_tested"] = b.counters[key][0];
    state.counters["face_triangles"] = b.counters[key][1];
    state.counters["triangles_occluded"] = b.counters[key][2];
  }
}

void render_all_threads(benchmark::State& state, std::size_t scene_index, int n, raster_options options) {
  bench_scene& b = get_scene(scene_index);
  const int workers = resolve_thread_count(0);
  std::vector<hemicube_rasterizer> rasterizers(static_cast<std::size_t>(workers), hemicube_rasterizer(b.built, options));
  std::vector<hemicube_buffer> buffers(static_cast<std::size_t>(workers));
  // Batches long enough to amortise the thread starts of parallel_for (~20 us per worker).
  const std::size_t batch = b.built->drawable_triangle_count() < 5000 ? 256 : (b.built->drawable_triangle_count() < 50000 ? 64 : 16);
  std::size_t offset = 0;
  const bench::cpu_ticks before = bench::read_cpu_ticks();
  for (auto _ : state) {
    parallel_for(batch, 0, 1, [&](int worker, std::size_t begin, std::size_t end) {
      const auto w = static_cast<std::size_t>(worker);
      for (std::size_t i = begin; i < end; ++i) {
        const std::size_t k = (offset + i) % b.points.size();
        rasterizers[w].render(b.points[k], b.frames[k], n, buffers[w]);
      }
    });
    offset = (offset + batch) % b.points.size();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(batch));
  state.counters["steal"] = bench::steal_fraction(before, bench::read_cpu_ticks());
}

}  // namespace

int main(int argc, char** argv) {
  // --levels_1m: our flag, removed before Google Benchmark sees the arguments.
  bool with_1m = false;
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--levels_1m") == 0)
      with_1m = true;
    else
      argv[kept++] = argv[i];
  }
  argc = kept;
  argv[argc] = nullptr;
  benchmark::Initialize(&argc, argv);
  if (with_1m)
    for (bench_scene& b : levels_1m()) scenes().push_back(b);
  const int all = hemilight::resolve_thread_count(0);
  // One core: the "all threads" run would be the one-thread run again.
  const std::vector<int> thread_counts = all == 1 ? std::vector<int>{1} : std::vector<int>{1, all};
  for (std::size_t s = 0; s < scenes().size(); ++s) {
    const bool level = s >= first_level;
    for (int n : {16, 32, 64, 128, 256}) {
      if (level && n != 64) continue;  // the levels at N = 64 only
      for (int threads : thread_counts)
        for (int cull = 1; cull >= (level ? 0 : 1); --cull) {
          std::string name = "raster/" + scenes()[s].name + "/N:" + std::to_string(n) + "/threads:" + std::to_string(threads);
          if (level) name += cull ? "/culling:on" : "/culling:off";
          const raster_options options = culling(cull == 1);
          benchmark::internal::Benchmark* bm =
              threads == 1 ? benchmark::RegisterBenchmark(name.c_str(), render_one_thread, s, n, options)
                           : benchmark::RegisterBenchmark(name.c_str(), render_all_threads, s, n, options);
          // One thread: CPU time of the benchmark thread (robust when other jobs share the cores);
          // all threads: wall-clock time.
          bm->Unit(benchmark::kMicrosecond);
          if (threads != 1) bm->UseRealTime();
          if (scenes()[s].name.find("_1M") != std::string::npos)  // heightfield_1M, arena_1M, keep_1M
            bm->Repetitions(3)->MinTime(0.5);
        }
    }
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
