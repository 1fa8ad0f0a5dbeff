// Cost of the geometry primitives: building a weight table, texel directions, cube-face lookup.
// items_per_second counts texels (or lookups).
#include "hemilight/geometry.hpp"

#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>

static void table_build(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  for (auto _ : state) {
    hemilight::hemicube_table table(n);
    benchmark::DoNotOptimize(table.solid_angle());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(hemilight::hemicube_texel_count(n)) * state.iterations());
}
BENCHMARK(table_build)->Arg(16)->Arg(64)->Arg(256)->Unit(benchmark::kMillisecond)->UseRealTime();  // threads inside

static void texel_direction(benchmark::State& state) {
  const int n = 64;
  const std::size_t count = hemilight::hemicube_texel_count(n);
  for (auto _ : state)
    for (std::size_t i = 0; i < count; ++i) benchmark::DoNotOptimize(hemilight::hemicube_texel_direction(n, i));
  state.SetItemsProcessed(static_cast<std::int64_t>(count) * state.iterations());
}
BENCHMARK(texel_direction);

static void cube_face_lookup(benchmark::State& state) {
  std::mt19937 rng(1);
  std::normal_distribution<float> g;
  std::vector<glm::vec3> dirs(4096);
  for (glm::vec3& d : dirs) d = {g(rng), g(rng), g(rng)};
  for (auto _ : state)
    for (const glm::vec3& d : dirs) benchmark::DoNotOptimize(hemilight::cube_face_from_direction(d));
  state.SetItemsProcessed(static_cast<std::int64_t>(dirs.size()) * state.iterations());
}
BENCHMARK(cube_face_lookup);

BENCHMARK_MAIN();
