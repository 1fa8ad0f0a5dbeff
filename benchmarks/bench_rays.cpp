// Shadow rays per second (rays.hpp occluded(), one thread), on the reference scenes, beside
// Embree 3's rtcOccluded1 on the same rays, and the cost of the Embree scene rays.hpp builds.
// items_per_second = rays per second.
//   name: rays/<method>/<scene>   method: ours (occluded(): Embree behind our checks and lazy build),
//         ours_closest (intersect(), closest hit), fallback and fallback_closest (the traversal of
//         the scene's own BVH that the queries use when Embree fails, src/rays_bvh.cpp),
//         embree (rtcOccluded1 on a scene of our settings), embree_closest (rtcIntersect1),
//         embree_not_robust (rtcOccluded1 without RTC_SCENE_FLAG_ROBUST)
//   name: rays/build/<scene>: prepare_rays() on a new scene (wall time: Embree builds on its own
//         threads); counter bytes_per_triangle from Embree's memory monitor.
// Rays: 4096 per scene, fixed (seed 2024): from 256 area-weighted surface points
// (bench_points.hpp, lifted by 1e-4 of the scene size along the normal, the light module's ray
// offset) towards pseudo-random points of a light, 16 per surface point, stopping 1e-4 of the
// scene size short of the light point:
//   cornell_box      its ceiling light (0.13 x 0.105 m at y = 0.5478)
//   hexagon_room_3   a 0.3 m cube around (0, 2.5, 0) under the ceiling (a point light's sphere)
//   open_pavilion    a sun 0.2 rad across around the direction (0.3, 1, 0.2) (rays of unbounded length)
// Counters: occluded = fraction of the rays blocked (the same for every method of a scene, up to
// rays that graze an edge); steal (host_steal.hpp). Timed in CPU time of the benchmark thread.
#include "hemilight/rays.hpp"
#include "hemilight/reference_scenes.hpp"

#include "bench_points.hpp"
#include "host_steal.hpp"
#include "rays/ray_accel.hpp"

#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace hemilight;

struct ray {
  glm::vec3 origin, direction;
  float t_max;
};

struct bench_scene {
  std::string name;
  std::function<scene_mesh()> build;
  scene_mesh mesh;
  std::shared_ptr<const scene> built;
  std::vector<ray> rays;
};

std::vector<bench_scene>& scenes() {
  static std::vector<bench_scene> list = {
      {"cornell_box", [] { return cornell_box(); }, {}, nullptr, {}},
      {"hexagon_room_3", [] { return hexagon_room(3); }, {}, nullptr, {}},
      {"open_pavilion", [] { return open_pavilion(); }, {}, nullptr, {}},
  };
  return list;
}

void make_rays(bench_scene& b) {
  b.mesh = b.build();
  b.built = scene::create(b.mesh.desc());
  const float eps = 1e-4f * b.built->size();
  const bench::sample_points p = bench::surface_points(b.mesh, 256, eps);
  std::mt19937 rng(2024);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (std::size_t i = 0; i < p.points.size(); ++i)
    for (int k = 0; k < 16; ++k) {
      const glm::vec3 o = p.points[i];
      if (b.name == "open_pavilion") {
        const frame f = make_frame(glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f)));
        const float h = u(rng) * (1.0f - std::cos(0.1f)), phi = 6.2831853f * u(rng);
        const float sg = std::sqrt(h * (2.0f - h));
        b.rays.push_back({o, f.to_world({sg * std::cos(phi), sg * std::sin(phi), 1.0f - h}),
                          std::numeric_limits<float>::infinity()});
        continue;
      }
      glm::vec3 q;
      if (b.name == "cornell_box")
        q = {0.278f + 0.13f * (u(rng) - 0.5f), 0.5478f, 0.2795f + 0.105f * (u(rng) - 0.5f)};
      else
        q = glm::vec3(0.0f, 2.5f, 0.0f) + 0.3f * (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f);
      const glm::vec3 d = q - o;
      b.rays.push_back({o, d, 1.0f - eps / glm::length(d)});
    }
}

bench_scene& get_scene(std::size_t index) {
  bench_scene& b = scenes()[index];
  if (!b.built) make_rays(b);  // outside the timed loop
  return b;
}

void ours(benchmark::State& state, std::size_t scene_index, bool closest, bool fallback) {
  bench_scene& b = get_scene(scene_index);
  prepare_rays(*b.built);  // the lazy build, outside the timed loop
  std::size_t k = 0, blocked = 0, total = 0;
  const bench::cpu_ticks before = bench::read_cpu_ticks();
  for (auto _ : state) {
    const ray& r = b.rays[k];
    bool hit;
    if (closest) {
      ray_hit h;
      hit = fallback ? detail::intersect_bvh(*b.built, r.origin, r.direction, r.t_max, h)
                     : intersect(*b.built, r.origin, r.direction, r.t_max, h);
    } else {
      hit = fallback ? detail::occluded_bvh(*b.built, r.origin, r.direction, r.t_max)
                     : occluded(*b.built, r.origin, r.direction, r.t_max);
    }
    benchmark::DoNotOptimize(hit);
    blocked += hit ? 1 : 0;
    ++total;
    k = (k + 1) % b.rays.size();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
  state.counters["occluded"] = total ? double(blocked) / double(total) : 0.0;
  state.counters["steal"] = bench::steal_fraction(before, bench::read_cpu_ticks());
}

// prepare_rays() on a fresh copy of the scene each iteration (scene::create is not timed).
void build(benchmark::State& state, std::size_t scene_index) {
  const bench_scene& b = get_scene(scene_index);
  double bytes = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    std::shared_ptr<const scene> s = scene::create(b.mesh.desc());
    const std::int64_t before = detail::embree_device_bytes();
    state.ResumeTiming();
    prepare_rays(*s);
    state.PauseTiming();
    bytes = double(detail::embree_device_bytes() - before);
    s.reset();
    state.ResumeTiming();
  }
  state.counters["bytes_per_triangle"] = bytes / double(b.built->drawable_triangle_count());
  state.counters["triangles"] = double(b.built->drawable_triangle_count());
}

// Raw Embree with rays.hpp's settings (robust, medium quality), single-threaded device; or without
// RTC_SCENE_FLAG_ROBUST (what robustness costs).
struct embree_scene {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
};

embree_scene& get_embree(std::size_t index, bool robust) {
  static std::vector<embree_scene> list(2 * scenes().size());
  embree_scene& e = list[2 * index + (robust ? 1 : 0)];
  if (e.scene) return e;
  const bench_scene& b = get_scene(index);
  e.device = rtcNewDevice("threads=1");
  e.scene = rtcNewScene(e.device);
  RTCGeometry geom = rtcNewGeometry(e.device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), b.mesh.positions.size()));
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                            3 * sizeof(unsigned), b.mesh.triangle_count()));
  for (std::size_t i = 0; i < b.mesh.positions.size(); ++i)
    for (int c = 0; c < 3; ++c) vb[3 * i + std::size_t(c)] = b.mesh.positions[i][c];
  for (std::size_t i = 0; i < b.mesh.indices.size(); ++i) ib[i] = b.mesh.indices[i];
  rtcCommitGeometry(geom);
  rtcSetSceneFlags(e.scene, robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
  rtcSetSceneBuildQuality(e.scene, RTC_BUILD_QUALITY_MEDIUM);
  rtcAttachGeometry(e.scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(e.scene);
  return e;
}

void embree(benchmark::State& state, std::size_t scene_index, bool closest, bool robust) {
  const bench_scene& b = get_scene(scene_index);
  embree_scene& e = get_embree(scene_index, robust);
  std::size_t k = 0, blocked = 0, total = 0;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  const bench::cpu_ticks before = bench::read_cpu_ticks();
  for (auto _ : state) {
    const ray& r = b.rays[k];
    RTCRayHit rh;
    RTCRay& ry = rh.ray;
    ry.org_x = r.origin.x;
    ry.org_y = r.origin.y;
    ry.org_z = r.origin.z;
    ry.dir_x = r.direction.x;
    ry.dir_y = r.direction.y;
    ry.dir_z = r.direction.z;
    ry.tnear = 0.0f;
    ry.tfar = r.t_max;
    ry.time = 0.0f;
    ry.mask = 0xffffffffu;
    ry.id = 0;
    ry.flags = 0;
    bool hit;
    if (closest) {
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(e.scene, &context, &rh);
      hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    } else {
      rtcOccluded1(e.scene, &context, &ry);
      hit = ry.tfar < 0.0f;  // -inf when occluded
    }
    benchmark::DoNotOptimize(hit);
    blocked += hit ? 1 : 0;
    ++total;
    k = (k + 1) % b.rays.size();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
  state.counters["occluded"] = total ? double(blocked) / double(total) : 0.0;
  state.counters["steal"] = bench::steal_fraction(before, bench::read_cpu_ticks());
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  for (std::size_t s = 0; s < scenes().size(); ++s) {
    const std::string scene_name = scenes()[s].name;
    benchmark::RegisterBenchmark(("rays/ours/" + scene_name).c_str(), ours, s, false, false);
    benchmark::RegisterBenchmark(("rays/ours_closest/" + scene_name).c_str(), ours, s, true, false);
    benchmark::RegisterBenchmark(("rays/fallback/" + scene_name).c_str(), ours, s, false, true);
    benchmark::RegisterBenchmark(("rays/fallback_closest/" + scene_name).c_str(), ours, s, true, true);
    benchmark::RegisterBenchmark(("rays/embree/" + scene_name).c_str(), embree, s, false, true);
    benchmark::RegisterBenchmark(("rays/embree_closest/" + scene_name).c_str(), embree, s, true, true);
    benchmark::RegisterBenchmark(("rays/embree_not_robust/" + scene_name).c_str(), embree, s, false, false);
    benchmark::RegisterBenchmark(("rays/build/" + scene_name).c_str(), build, s)->UseRealTime();
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
