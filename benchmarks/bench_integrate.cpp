// Integration throughput: one hemicube buffer (the lit room of tests/integrate_scenes.hpp,
// rendered once by the reference ray caster) reduced again and again. items_per_second counts
// texels; hemicubes/s = items_per_second / (3 N^2). render_and_integrate_cornell counts hemicubes. Modes: 0 = irradiance and distances only,
// 1 = + rotation gradient, 2 = + great-arc translation gradient (the cache's default),
// 3 = + directional outputs (L1 SH, HL2).
#include "hemilight/integrate.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/reference_scenes.hpp"

#include "bench_points.hpp"
#include "integrate_scenes.hpp"

#include <benchmark/benchmark.h>

#include <cstdint>
#include <map>

using namespace hemilight;

static const hemicube_buffer& room_buffer(int n) {
  static std::map<int, hemicube_buffer> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    const test::closed_form_scene s = test::lit_room();
    it = cache.emplace(n, test::raycast_hemicube(s.tris, s.sky, s.position, test::rolled_frame(s.normal, 0.3), n)).first;
  }
  return it->second;
}

static void integrate_hemicube(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int mode = static_cast<int>(state.range(1));
  integrate_options o;
  o.rotation_gradient = mode >= 1;
  o.translation = mode >= 2 ? translation_estimator::great_arc : translation_estimator::none;
  o.directional = mode >= 3;
  hemicube_integrator integrator(n, o);
  const hemicube_buffer& buf = room_buffer(n);
  for (auto _ : state) benchmark::DoNotOptimize(integrator.integrate(buf));
  state.SetItemsProcessed(static_cast<std::int64_t>(hemicube_texel_count(n)) * state.iterations());
}
BENCHMARK(integrate_hemicube)->ArgsProduct({{16, 32, 64, 128, 256}, {0, 1, 2, 3}})->ArgNames({"N", "mode"});

static void integrate_estimator(benchmark::State& state) {
  const int n = 64;
  integrate_options o;
  o.translation = static_cast<translation_estimator>(state.range(0));
  hemicube_integrator integrator(n, o);
  const hemicube_buffer& buf = room_buffer(n);
  for (auto _ : state) benchmark::DoNotOptimize(integrator.integrate(buf));
  state.SetItemsProcessed(static_cast<std::int64_t>(hemicube_texel_count(n)) * state.iterations());
}
BENCHMARK(integrate_estimator)->DenseRange(1, 3)->ArgName("estimator");

static void build_table(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(integration_table(n).vz.data());
  state.SetItemsProcessed(static_cast<std::int64_t>(hemicube_texel_count(n)) * state.iterations());
}
BENCHMARK(build_table)->Arg(64)->Arg(256)->Unit(benchmark::kMillisecond);

// Render + integrate with gradients (great arc) at N = 64 on the Cornell box, one core, at the 128
// points of bench::cornell_floor_and_back_wall (bench_points.hpp), cycled: the target is 20k
// hemicubes/s (docs/integration.md).
static void render_and_integrate_cornell(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const scene_mesh mesh = cornell_box();
  const auto sc = scene::create(mesh.desc());
  hemicube_rasterizer raster(sc);
  hemicube_integrator integrator(n);
  hemicube_buffer buf;
  const bench::sample_points pts = bench::cornell_floor_and_back_wall();
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t k = i++ % pts.points.size();
    raster.render(pts.points[k], pts.frames[k], n, buf);
    benchmark::DoNotOptimize(integrator.integrate(buf));
  }
  state.SetItemsProcessed(state.iterations());  // hemicubes
}
BENCHMARK(render_and_integrate_cornell)->Arg(32)->Arg(64)->Arg(128);

BENCHMARK_MAIN();
