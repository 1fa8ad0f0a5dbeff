// Cube-map filtering speed and accuracy: the radiance mip chain of a 256^2 input (9 levels,
// gloss mapping of cubemap.hpp), the same chain with cmft's default lobes, irradiance (SH fast
// path and cosine filter), for 1 and 2 threads, with the maximum relative error against the
// brute-force reference (filter_reference: every input texel, no cutoff, double) as counters.
// items_per_second counts output texels (or lookups).
//
// Target: 10x faster than cmft on the 256^2 radiance chain and SH irradiance, at <= 1% max error.
// cmft itself is measured beside hemilight by benchmarks/cmft_compare.sh (docs/cubemap.md, "Beside
// cmft, measured"); this benchmark times the filters alone (no file is read or written).
#include "hemilight/cubemap.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

namespace {

using namespace hemilight;

const cubemap& input_256() {
  static const cubemap env = cubemap::from_image(procedural_environment(256), false);
  return env;
}

// cmft's default gloss mapping (glossScale 10, glossBias 1): p = 2^(10 (1 - l / 8) + 1).
float cmft_power(int level) { return std::exp2(10.0f * (1.0f - static_cast<float>(level) / 8.0f) + 1.0f); }

std::int64_t chain_texels(int size) {
  std::int64_t t = 0;
  for (int s = size; s >= 1; s /= 2) t += 6LL * s * s;
  return t;
}

// Max relative error (over channels) of `level` against brute force at 150 random texels
// (all of them when there are fewer). Brute force over 393k input texels per output texel.
double max_error_vs_reference(const cube_image& level, float power, edge_fixup fixup) {
  const std::size_t count = 6u * std::size_t(level.size) * std::size_t(level.size);
  std::vector<std::size_t> texels;
  std::mt19937 rng(11);
  if (count <= 150) {
    for (std::size_t i = 0; i < count; ++i) texels.push_back(i);
  } else {
    for (int k = 0; k < 150; ++k) texels.push_back(rng() % count);
  }
  const std::vector<float> ref = filter_reference(input_256().levels[0], power, level.size, fixup, texels);
  double worst = 0;
  for (std::size_t k = 0; k < texels.size(); ++k)
    for (std::size_t c = 0; c < 3; ++c) {
      const double r = ref[k * 3 + c], v = level.pixels[texels[k] * 3 + c];
      worst = std::max(worst, std::fabs(v - r) / std::fabs(r));
    }
  return worst;
}

// Errors are computed once per configuration (brute force is slow) and reported as counters.
double chain_error(bool cmft_lobes, float texels_per_sigma) {
  static std::map<std::pair<bool, float>, double> cache;
  const auto key = std::make_pair(cmft_lobes, texels_per_sigma);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  filter_options o;
  o.texels_per_sigma = texels_per_sigma;
  double worst = 0;
  for (int l = 0; l < 9; ++l) {
    const float p = cmft_lobes ? cmft_power(l) : gloss_power(256, l);
    worst = std::max(worst, max_error_vs_reference(filter_cosine_power(input_256(), p, 256 >> l, o), p, o.fixup));
  }
  return cache[key] = worst;
}

void radiance_chain(benchmark::State& state) {
  filter_options o;
  o.thread_count = static_cast<int>(state.range(0));
  const cubemap& in = input_256();  // built before the timed loop
  for (auto _ : state) benchmark::DoNotOptimize(filter_mip_chain(in, 256, o).levels.data());
  state.SetItemsProcessed(chain_texels(256) * state.iterations());
  state.counters["threads"] = static_cast<double>(o.thread_count);
  state.counters["max_rel_error"] = chain_error(false, o.texels_per_sigma);
}
BENCHMARK(radiance_chain)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// The same chain at texels_per_sigma = 1.5 (faster, up to ~1.5% max error on this sky).
void radiance_chain_fast(benchmark::State& state) {
  filter_options o;
  o.thread_count = static_cast<int>(state.range(0));
  o.texels_per_sigma = 1.5f;
  const cubemap& in = input_256();
  for (auto _ : state) benchmark::DoNotOptimize(filter_mip_chain(in, 256, o).levels.data());
  state.SetItemsProcessed(chain_texels(256) * state.iterations());
  state.counters["threads"] = static_cast<double>(o.thread_count);
  state.counters["max_rel_error"] = chain_error(false, o.texels_per_sigma);
}
BENCHMARK(radiance_chain_fast)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// The default chain with the previous method (lobe evaluated per tap, no precomputed weights):
// the ratio to radiance_chain under the same machine load.
void radiance_chain_per_tap(benchmark::State& state) {
  filter_options o;
  o.thread_count = static_cast<int>(state.range(0));
  o.precomputed_weights = false;
  const cubemap& in = input_256();
  for (auto _ : state) benchmark::DoNotOptimize(filter_mip_chain(in, 256, o).levels.data());
  state.SetItemsProcessed(chain_texels(256) * state.iterations());
  state.counters["threads"] = static_cast<double>(o.thread_count);
}
BENCHMARK(radiance_chain_per_tap)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// The same chain with cmft's lobes (much wider at the top level: p = 2048 instead of 16384), for
// a like-for-like comparison with the 3.4 s reference. One input, its mips built once.
std::vector<float> cmft_powers() {
  std::vector<float> p;
  for (int l = 0; l < 9; ++l) p.push_back(cmft_power(l));
  return p;
}

void radiance_chain_cmft_lobes(benchmark::State& state) {
  filter_options o;
  o.thread_count = static_cast<int>(state.range(0));
  const cubemap& in = input_256();
  const std::vector<float> powers = cmft_powers();
  for (auto _ : state) benchmark::DoNotOptimize(filter_mip_chain_powers(in, 256, powers, o).levels.data());
  state.SetItemsProcessed(chain_texels(256) * state.iterations());
  state.counters["threads"] = static_cast<double>(o.thread_count);
  state.counters["max_rel_error"] = chain_error(true, o.texels_per_sigma);
}
BENCHMARK(radiance_chain_cmft_lobes)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);

double irradiance_error(const cube_image& e, bool sh) {
  static std::map<std::pair<int, bool>, double> cache;
  const auto key = std::make_pair(e.size, sh);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  return cache[key] = max_error_vs_reference(e, 0.0f, edge_fixup::none);
}

// SH fast path: projection of the 256^2 input plus evaluation at every texel of a 256^2 output.
void irradiance_sh(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0)), out = static_cast<int>(state.range(1));
  const cubemap& in = input_256();
  cube_image e;
  for (auto _ : state) {
    e = irradiance_from_sh9(project_sh9(in.levels[0], threads), out, edge_fixup::none, 3, threads);
    benchmark::DoNotOptimize(e.pixels.data());
  }
  state.SetItemsProcessed(6LL * out * out * state.iterations());
  state.counters["threads"] = threads;
  state.counters["max_rel_error"] = irradiance_error(e, true);
}
BENCHMARK(irradiance_sh)->Args({1, 256})->Args({2, 256})->Args({1, 32})->Args({2, 32})->Unit(benchmark::kMillisecond)->UseRealTime();

// SH to band 4 (cmft's irradiance method): projection of the 256^2 input and evaluation.
void irradiance_sh25(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0)), out = static_cast<int>(state.range(1));
  const cubemap& in = input_256();
  cube_image e;
  for (auto _ : state) {
    e = irradiance_from_sh25(project_sh25(in.levels[0], threads), out, edge_fixup::none, 3, threads);
    benchmark::DoNotOptimize(e.pixels.data());
  }
  state.SetItemsProcessed(6LL * out * out * state.iterations());
  state.counters["threads"] = threads;
  state.counters["max_rel_error"] = max_error_vs_reference(e, 0.0f, edge_fixup::none);
}
BENCHMARK(irradiance_sh25)->Args({1, 32})->Args({2, 32})->Unit(benchmark::kMillisecond)->UseRealTime();

// The cosine-lobe filter (quadrature over the 16^2 mip, exact hemisphere).
void irradiance_filter(benchmark::State& state) {
  filter_options o;
  o.thread_count = static_cast<int>(state.range(0));
  const int out = static_cast<int>(state.range(1));
  const cubemap& in = input_256();
  cube_image e;
  for (auto _ : state) {
    e = filter_irradiance(in, out, o);
    benchmark::DoNotOptimize(e.pixels.data());
  }
  state.SetItemsProcessed(6LL * out * out * state.iterations());
  state.counters["threads"] = static_cast<double>(o.thread_count);
  state.counters["max_rel_error"] = irradiance_error(e, false);
}
BENCHMARK(irradiance_filter)->Args({1, 32})->Args({2, 32})->Unit(benchmark::kMillisecond)->UseRealTime();

// The sky lookup the rasterizer will call per texel that hits nothing.
void sky_sample(benchmark::State& state) {
  std::mt19937 rng(1);
  std::normal_distribution<float> g;
  std::vector<glm::vec3> dirs(4096);
  for (glm::vec3& d : dirs) d = {g(rng), g(rng), g(rng)};
  const cubemap& in = input_256();
  for (auto _ : state)
    for (const glm::vec3& d : dirs) benchmark::DoNotOptimize(in.sample(d));
  state.SetItemsProcessed(static_cast<std::int64_t>(dirs.size()) * state.iterations());
}
BENCHMARK(sky_sample);

void lookup_fixup(benchmark::State& state) {
  std::mt19937 rng(2);
  std::normal_distribution<float> g;
  std::vector<glm::vec3> dirs(4096);
  for (glm::vec3& d : dirs) d = {g(rng), g(rng), g(rng)};
  for (auto _ : state)
    for (const glm::vec3& d : dirs) benchmark::DoNotOptimize(fixup_lookup(d, 256, 2.5f));
  state.SetItemsProcessed(static_cast<std::int64_t>(dirs.size()) * state.iterations());
}
BENCHMARK(lookup_fixup);

}  // namespace

BENCHMARK_MAIN();
