// The table cache (memory.hpp): the budget bounds what is retained, a table in use survives
// eviction, release frees, and results are bitwise the same after eviction and rebuild.
// References: tables built privately (the constructors, bypassing the cache) and results
// computed before the cache let go of anything.
#include "hemilight/cubemap.hpp"
#include "hemilight/geometry.hpp"
#include "hemilight/integrate.hpp"
#include "hemilight/memory.hpp"
#include "hemilight/probes.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/reference_scenes.hpp"

#include "test_support.hpp"

#include <atomic>
#include <cstring>
#include <thread>
#include <vector>

using namespace hemilight;

namespace {

// Restores the default budget and empties the cache when a test ends (tests share the process).
struct budget_guard {
  ~budget_guard() {
    set_table_budget(default_table_budget);
    release_tables();
  }
};

// Every float of two integration tables, compared bitwise.
bool same_tables(const integration_table& a, const integration_table& b) {
  auto same = [](const std::vector<float>& x, const std::vector<float>& y) {
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0;
  };
  return same(a.vx, b.vx) && same(a.vy, b.vy) && same(a.vz, b.vz) && same(a.simple_x, b.simple_x) &&
         same(a.simple_y, b.simple_y) && same(a.hl2[0], b.hl2[0]) && same(a.hl2[1], b.hl2[1]) &&
         same(a.hl2[2], b.hl2[2]) && same(a.solid_angle, b.solid_angle) && same(a.up_great_arc_x, b.up_great_arc_x) &&
         same(a.right_classified_y, b.right_classified_y) && a.border_walls.size() == b.border_walls.size() &&
         a.extrapolation_neighbours == b.extrapolation_neighbours;
}

// Bytes of an integration table of resolution n by the documented layout (integrate.hpp: 69 bytes
// per texel, 24-byte walls, 6 N of them), independent of the cache's own accounting.
std::size_t documented_integration_bytes(int n) {
  const std::size_t texels = 3 * std::size_t(n) * std::size_t(n);
  return 69 * texels + 24 * 6 * std::size_t(n);
}

}  // namespace

TEST_CASE("memory: the default budget is 256 MiB and the cache counts a table's documented bytes", "[memory]") {
  budget_guard guard;
  CHECK(table_budget() == default_table_budget);
  CHECK(default_table_budget == std::size_t(256) << 20);
  release_tables();
  CHECK(table_cache_stats().retained_bytes == 0);
  const auto t = integration_table::get(64);
  // The counted bytes are the vectors' capacities: at least the documented size, and not more
  // than the walls' growth slack (push_back doubling: at most 2x the 6 N walls) above it.
  const std::size_t counted = table_cache_stats().retained_bytes, doc = documented_integration_bytes(64);
  CHECK(counted >= doc);
  CHECK(counted <= doc + 24 * 6 * 64);
}

TEST_CASE("memory: the retained tables never exceed the budget across many resolutions", "[memory]") {
  budget_guard guard;
  release_tables();
  const std::size_t budget = std::size_t(4) << 20;  // 4 MiB: holds a few tables of N <= 96
  set_table_budget(budget);
  const std::size_t evictions_before = table_cache_stats().evictions;
  std::size_t largest = 0;
  for (int n = 2; n <= 160; n += 2) {
    // A sampler's tables: the integrator's weights and the hemicube's.
    hemicube_integrator integrator(n);
    (void)hemicube_table::get(n);
    const table_cache_statistics s = table_cache_stats();
    INFO("N = " << n << ": " << s.retained_bytes << " bytes retained in " << s.retained_tables << " tables");
    CHECK(s.retained_bytes <= budget);
    largest = std::max(largest, s.retained_bytes);
  }
  // The tables of N = 160 alone (5.3 MB) exceed the budget: they were not retained; smaller ones
  // filled it: more than half the budget was in use at some point, and tables were evicted.
  CHECK(largest > budget / 2);
  CHECK(table_cache_stats().evictions > evictions_before);
  // Budget 0: nothing is retained.
  set_table_budget(0);
  CHECK(table_cache_stats().retained_bytes == 0);
  CHECK(table_cache_stats().retained_tables == 0);
  (void)integration_table::get(32);
  CHECK(table_cache_stats().retained_bytes == 0);
}

TEST_CASE("memory: a table in use survives eviction and is shared, not rebuilt", "[memory]") {
  budget_guard guard;
  release_tables();
  std::shared_ptr<const integration_table> held = integration_table::get(48);
  const integration_table reference(48);  // private, outside the cache
  set_table_budget(0);                    // evicts everything the cache retained
  CHECK(table_cache_stats().retained_bytes == 0);
  REQUIRE(same_tables(*held, reference));  // still there, unchanged (ASan would flag a free)
  const std::size_t builds = table_cache_stats().builds;
  CHECK(integration_table::get(48) == held);  // found through the holder, not built again
  CHECK(table_cache_stats().builds == builds);
  release_tables();
  CHECK(same_tables(*held, reference));
  CHECK(integration_table::get(48) == held);
}

TEST_CASE("memory: release_tables frees every table no one holds", "[memory]") {
  budget_guard guard;
  release_tables();
  std::weak_ptr<const integration_table> w32 = integration_table::get(32);
  std::weak_ptr<const hemicube_table> h32 = hemicube_table::get(32);
  std::shared_ptr<const integration_table> held = integration_table::get(40);
  CHECK(!w32.expired());  // retained by the cache (well within the default budget)
  CHECK(!h32.expired());
  const std::size_t retained = table_cache_stats().retained_bytes;
  CHECK(retained >= documented_integration_bytes(32) + documented_integration_bytes(40) + 24 * 32 * 32);  // hemicube_table: 8 B x 3 N^2
  CHECK(release_tables() == retained);
  CHECK(w32.expired());  // freed: no one else held them
  CHECK(h32.expired());
  CHECK(held->resolution() == 40);  // held: alive
  const table_cache_statistics s = table_cache_stats();
  CHECK(s.retained_bytes == 0);
  CHECK(s.retained_tables == 0);
}

TEST_CASE("memory: results are bitwise the same after eviction and rebuild", "[memory]") {
  budget_guard guard;
  const std::shared_ptr<const scene> s = scene::create(cornell_box().desc());
  const glm::vec3 p(0.1f, 0.2f, 0.3f);
  // One hemicube sample (rasterizer + integrator tables) and a probe (SH9 table) at N = 32, a
  // cube-map filter (face tables) of a 16^3 map.
  auto sample = [&] {
    hemicube_rasterizer r(s);
    hemicube_integrator integrator(32);
    hemicube_buffer buf;
    r.render(p, make_frame({0.0f, 0.6f, 0.8f}), 32, buf);
    return integrator.integrate(buf);
  };
  auto probe = [&] {
    probe_options o;
    o.resolution = 32;
    o.thread_count = 1;
    return sample_probes(s, &p, 1, o).probes[0];
  };
  cube_image top = cube_image::make(16, 3);
  for (std::size_t i = 0; i < top.pixels.size(); ++i) top.pixels[i] = float(i % 97) / 97.0f;
  const cubemap map = cubemap::from_image(top, true);
  auto filtered = [&] { return filter_cosine_power(map, 20.0f, 8).pixels; };

  const irradiance_sample a = sample();
  const sh9_rgb pa = probe();
  const std::vector<float> fa = filtered();
  release_tables();
  CHECK(table_cache_stats().retained_bytes == 0);
  set_table_budget(0);  // every table is rebuilt by the calls below
  const std::size_t builds = table_cache_stats().builds;
  const irradiance_sample b = sample();
  const sh9_rgb pb = probe();
  const std::vector<float> fb = filtered();
  CHECK(table_cache_stats().builds > builds);
  CHECK(std::memcmp(&a.irradiance, &b.irradiance, sizeof a.irradiance) == 0);
  CHECK(std::memcmp(&a.rotation_gradient, &b.rotation_gradient, sizeof a.rotation_gradient) == 0);
  CHECK(std::memcmp(&a.translation_gradient, &b.translation_gradient, sizeof a.translation_gradient) == 0);
  CHECK(std::memcmp(&pa, &pb, sizeof pa) == 0);
  REQUIRE(fa.size() == fb.size());
  CHECK(std::memcmp(fa.data(), fb.data(), fa.size() * sizeof(float)) == 0);
}

TEST_CASE("memory: concurrent callers of one resolution share one build", "[memory]") {
  budget_guard guard;
  release_tables();
  const std::size_t builds = table_cache_stats().builds;
  std::vector<std::shared_ptr<const integration_table>> got(4);
  std::vector<std::thread> threads;
  std::atomic<int> ready{0};
  for (std::size_t t = 0; t < got.size(); ++t)
    threads.emplace_back([&, t] {
      ++ready;
      while (ready.load() < int(got.size())) std::this_thread::yield();
      got[t] = integration_table::get(96);
    });
  for (std::thread& th : threads) th.join();
  for (const auto& g : got) CHECK(g == got[0]);
  CHECK(table_cache_stats().builds == builds + 1);
}
