// Hemicubes per second of the software rasterizer (render only: culling, visibility, resolve),
// on the reference scenes, for N in {16, 32, 64, 128, 256}, on one thread and on all threads.
// items_per_second = hemicubes per second. Each benchmark renders hemicubes at a fixed set of 256
// pseudo-random surface points of its scene (area-weighted, with the surface normal, lifted by
// 1e-4 of the scene size), one after another, the way a baker visits lightmap texels.
//   name: raster/<scene>/N:<n>/threads:<t>
// One-thread runs are timed in CPU time of the benchmark thread (the machine may be shared).
// Multi-threaded runs hand batches of hemicubes (256 for the small scenes, 64 for 10k triangles,
// 16 above) to hemilight::parallel_for (one rasterizer per worker) and are timed in real time. The 1M-triangle scene uses 3 repetitions (a full run with
// the default 5 takes several minutes), whatever --benchmark_repetitions says.
// Counter `steal`: the fraction of all CPU time that the hypervisor gave to other guests during
// the run (/proc/stat; -1 where unknown). Two-thread rows with steal over a few percent measure
// the host more than the library (docs/raster.md).
#include "hemilight/parallel.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/reference_scenes.hpp"

#include "bench_points.hpp"
#include "host_steal.hpp"

#include <benchmark/benchmark.h>

#include <cstdint>
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
};

// Area-weighted random points on the front faces of a scene (bench_points.hpp).
void make_points(bench_scene& b) {
  const scene_mesh m = b.build();
  b.built = scene::create(m.desc());
  bench::sample_points p = bench::surface_points(m, 256, 1e-4f * b.built->size());
  b.points = std::move(p.points);
  b.frames = std::move(p.frames);
}

std::vector<bench_scene>& scenes() {
  static std::vector<bench_scene> list = {
      {"cornell_box_32", [] { return cornell_box(); }, nullptr, {}, {}},
      {"hexagon_room_496", [] { return hexagon_room(2); }, nullptr, {}, {}},
      {"hexagon_room_1062", [] { return hexagon_room(3); }, nullptr, {}, {}},
      {"heightfield_10k", [] { return heightfield(10000); }, nullptr, {}, {}},
      {"heightfield_100k", [] { return heightfield(100000); }, nullptr, {}, {}},
      {"heightfield_1M", [] { return heightfield(1000000); }, nullptr, {}, {}},
  };
  return list;
}

bench_scene& get_scene(std::size_t index) {
  bench_scene& b = scenes()[index];
  if (!b.built) make_points(b);  // built on first use, outside the timed loop
  return b;
}

void render_one_thread(benchmark::State& state, std::size_t scene_index, int n) {
  bench_scene& b = get_scene(scene_index);
  hemicube_rasterizer r(b.built);
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
}

void render_all_threads(benchmark::State& state, std::size_t scene_index, int n) {
  bench_scene& b = get_scene(scene_index);
  const int workers = resolve_thread_count(0);
  std::vector<hemicube_rasterizer> rasterizers(static_cast<std::size_t>(workers), hemicube_rasterizer(b.built));
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
  benchmark::Initialize(&argc, argv);
  const int all = hemilight::resolve_thread_count(0);
  for (std::size_t s = 0; s < scenes().size(); ++s)
    for (int n : {16, 32, 64, 128, 256})
      for (int threads : {1, all}) {
        const std::string name = "raster/" + scenes()[s].name + "/N:" + std::to_string(n) + "/threads:" + std::to_string(threads);
        benchmark::internal::Benchmark* bm =
            threads == 1 ? benchmark::RegisterBenchmark(name.c_str(), render_one_thread, s, n)
                         : benchmark::RegisterBenchmark(name.c_str(), render_all_threads, s, n);
        // One thread: CPU time of the benchmark thread (robust when other jobs share the cores);
        // all threads: wall-clock time.
        bm->Unit(benchmark::kMicrosecond);
        if (threads != 1) bm->UseRealTime();
        if (scenes()[s].name == "heightfield_1M") bm->Repetitions(3)->MinTime(0.5);
        if (threads == all && all == 1) break;  // one core: the "all threads" run is the same
      }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
