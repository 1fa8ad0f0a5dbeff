// Tests of rays.hpp against the independent double-precision ray caster of
// tests/raycast_reference.hpp (brute force over all triangles, Moeller-Trumbore), and against
// rays whose answers are known by construction (shared edges, t_max, both faces). Each runs twice
// (GENERATE): through rays.hpp (Embree) and through the fallback traversal of the scene's BVH
// (src/rays_internal.hpp), which the queries use when the Embree scene cannot be built.
#include "hemilight/rays.hpp"
#include "hemilight/reference_scenes.hpp"

#include "raycast_reference.hpp"
#include "rays/ray_accel.hpp"

#include <catch2/catch.hpp>
#include <embree3/rtcore.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace hemilight;
using namespace hemilight::test;

namespace {

constexpr float inf = std::numeric_limits<float>::infinity();

std::vector<ref_triangle> reference_triangles(const scene_mesh& m) {
  std::vector<ref_triangle> out;
  for (std::size_t i = 0; i < m.triangle_count(); ++i)
    out.push_back({glm::dvec3(m.positions[m.indices[3 * i]]), glm::dvec3(m.positions[m.indices[3 * i + 1]]),
                   glm::dvec3(m.positions[m.indices[3 * i + 2]]), glm::vec3(0.0f), true});
  return out;
}

// Whether the ray o + t d (0 < t < t_max) passes within `eps` (barycentric) of an edge of some
// triangle it crosses, or crosses a triangle within eps (relative) of t_max: the rays on which a
// float caster may legitimately answer differently from the double reference.
bool near_an_edge(const std::vector<ref_triangle>& tris, const glm::dvec3& o, const glm::dvec3& d, double t_max,
                  double eps) {
  for (const ref_triangle& t : tris) {
    const glm::dvec3 e1 = t.b - t.a, e2 = t.c - t.a, p = glm::cross(d, e2);
    const double det = glm::dot(e1, p);
    if (std::fabs(det) < 1e-300) continue;
    const glm::dvec3 s = o - t.a, q = glm::cross(s, e1);
    const double u = glm::dot(s, p) / det, v = glm::dot(d, q) / det, dist = glm::dot(e2, q) / det;
    if (dist < -eps * (1.0 + t_max) || (std::isfinite(t_max) && dist > t_max * (1.0 + eps))) continue;
    const double w = 1.0 - u - v;
    const bool inside = u >= -eps && v >= -eps && w >= -eps;
    const bool near_edge = std::fabs(u) < eps || std::fabs(v) < eps || std::fabs(w) < eps;
    const bool near_ends = std::fabs(dist) < eps * (1.0 + t_max) ||
                           (std::isfinite(t_max) && std::fabs(dist - t_max) < eps * t_max);
    if (inside && (near_edge || near_ends)) return true;
  }
  return false;
}

// The two implementations of the queries' contract.
struct backend {
  const char* name;
  bool (*occluded)(const scene&, const glm::vec3&, const glm::vec3&, float);
  bool (*intersect)(const scene&, const glm::vec3&, const glm::vec3&, float, ray_hit&);
};
const backend backends[] = {{"embree (rays.hpp)", hemilight::occluded, hemilight::intersect},
                            {"fallback (scene BVH)", detail::occluded_bvh, detail::intersect_bvh}};

struct named_mesh {
  const char* name;
  scene_mesh mesh;
};

}  // namespace

TEST_CASE("rays: random rays on reference scenes agree with the reference caster", "[rays]") {
  const backend& q = backends[GENERATE(0, 1)];
  INFO("backend " << q.name);
  for (const named_mesh& nm : {named_mesh{"cornell_box", cornell_box()}, named_mesh{"hexagon_room_3", hexagon_room(3)},
                               named_mesh{"open_pavilion", open_pavilion()},
                               named_mesh{"sky_and_occluders", sky_and_occluders()}}) {
    INFO("scene " << nm.name);
    const auto s = scene::create(nm.mesh.desc());
    const std::vector<ref_triangle> tris = reference_triangles(nm.mesh);
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    const glm::vec3 lo = s->bounds_lo(), hi = s->bounds_hi();
    int rays = 0, near_edge = 0;
    for (int k = 0; k < 1500; ++k) {
      // Origins over the scene's box grown by 10%, directions uniform, t_max from 0.05 to 1.0 of
      // the scene size, or +inf (every fourth ray).
      const glm::vec3 o = lo + (hi - lo) * glm::vec3(u01(rng), u01(rng), u01(rng)) * 1.2f - 0.1f * (hi - lo);
      glm::vec3 d(gauss(rng), gauss(rng), gauss(rng));
      if (glm::length(d) < 1e-3f) continue;
      d = glm::normalize(d) * (0.5f + 2.0f * u01(rng));  // not unit: t is in units of |d|
      const float t_max = k % 4 == 0 ? inf : s->size() * (0.05f + 0.95f * u01(rng)) / glm::length(d);
      ++rays;
      int ref_hit;
      bool back;
      const double t_ref = cast(tris, glm::dvec3(o), glm::dvec3(d), ref_hit, back);
      const bool ref_any = ref_hit >= 0 && t_ref < double(t_max);
      ray_hit h;
      const bool any = q.occluded(*s, o, d, t_max);
      const bool found = q.intersect(*s, o, d, t_max, h);
      // Disagreements are allowed only within 1e-5 (barycentric, or relative in t) of an edge
      // or of the segment's ends: float rounding of the vertices' shear is ~1e-7 relative, so
      // 1e-5 leaves two orders of margin, and the scenes' edges are exact in float.
      if (any != ref_any || found != ref_any ||
          (found && ref_any && (std::fabs(double(h.distance) - t_ref) > 1e-5 * (t_ref + double(s->size())) ||
                                (h.triangle != std::uint32_t(ref_hit) &&
                                 std::fabs(double(h.distance) - t_ref) > 1e-5 * (t_ref + double(s->size())))))) {
        const bool allowed = near_an_edge(tris, glm::dvec3(o), glm::dvec3(d), double(t_max), 1e-5);
        INFO("ray " << k << ": any " << any << " found " << found << " reference " << ref_any << " t " << h.distance
                    << " t_ref " << t_ref);
        CHECK(allowed);
        ++near_edge;
      } else if (found) {
        // The same triangle, or one at the same distance (touching parts, shared edges).
        CHECK(std::fabs(double(h.distance) - t_ref) <= 1e-5 * (t_ref + double(s->size())));
      }
    }
    INFO(near_edge << " of " << rays << " rays near an edge disagree");
    CHECK(near_edge <= rays / 100);
  }
}

TEST_CASE("rays: a ray through a shared edge or vertex of a closed grid is always caught (watertight)", "[rays]") {
  const backend& q = backends[GENERATE(0, 1)];
  INFO("backend " << q.name);
  // A skewed 16 x 16 grid of quads (512 triangles sharing edges and vertices, add_grid) in the
  // tilted plane z = 0.1 x + 0.2 y + 0.05 (planar, so every ray towards a point of it crosses it
  // there: on a bent grid a grazing ray may touch a ridge without crossing). Rays aim at points on
  // the interior edges (the segment's own float points, so exactly on or within an ulp of the
  // edge) and at the interior vertices, from origins on both sides and at grazing angles. A ray
  // through the grid's interior must hit some triangle: none may slip through.
  const auto on_plane = [](float x, float y) { return glm::vec3(x, y, 0.1f * x + 0.2f * y + 0.05f); };
  scene_mesh m;
  m.add_grid(on_plane(-1.0f, -0.9f), on_plane(1.1f, -1.0f), on_plane(0.9f, 1.2f), on_plane(-1.05f, 1.0f), 16, 16,
             material{});
  const auto s = scene::create(m.desc());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  int misses = 0, rays = 0, vertex_misses = 0, vertex_rays = 0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    for (int e = 0; e < 3; ++e) {
      const glm::vec3 a = m.positions[m.indices[3 * t + std::size_t(e)]];
      const glm::vec3 b = m.positions[m.indices[3 * t + std::size_t((e + 1) % 3)]];
      for (int k = 0; k < 4; ++k) {
        const float f = k == 0 ? 0.0f : u01(rng);  // k = 0: the vertex itself
        const glm::vec3 target = a + f * (b - a);
        if (std::fabs(target.x) > 0.85f || std::fabs(target.y) > 0.85f) continue;  // interior only
        const float side = (k % 2) ? 1.0f : -1.0f;
        // grazing (k = 3: about 3 degrees from the plane) to steep
        const glm::vec3 normal = glm::normalize(glm::vec3(-0.1f, -0.2f, 1.0f));
        glm::vec3 along(u01(rng) - 0.5f, u01(rng) - 0.5f, 0.0f);
        along = glm::normalize(along - glm::dot(along, normal) * normal);
        const glm::vec3 dir_in = along + normal * (k == 3 ? 0.05f : 0.3f + u01(rng));
        const glm::vec3 o = target + side * glm::normalize(dir_in) * (0.5f + 3.0f * u01(rng));
        int& missed = k == 0 ? vertex_misses : misses;
        ++(k == 0 ? vertex_rays : rays);
        if (!q.occluded(*s, o, target - o, 2.0f)) ++missed;
        ray_hit h;
        if (!q.intersect(*s, o, target - o, 2.0f, h)) ++missed;
      }
    }
  INFO(misses << " of " << rays << " rays through shared edges, " << vertex_misses << " of " << vertex_rays
              << " through shared vertices missed (counted twice: occluded and intersect)");
  CHECK(rays > 3000);
  CHECK(vertex_rays > 1000);
  CHECK(misses == 0);
  if (q.occluded == detail::occluded_bvh) {
    CHECK(vertex_misses == 0);  // exact edge functions (double) when one is 0 in float
  } else {
    // Embree's robust (Pluecker) test is watertight along shared edges but, in float only with a
    // tolerance of one ulp of the sum of the edge functions, not exactly at a shared vertex: about
    // 1% of the rays aimed exactly at one slip through (AVX2 kernels; fewer with SSE). A random ray
    // passes that close to a vertex with a chance of ~1e-14 (rays.hpp).
    CHECK(vertex_misses <= 2 * vertex_rays / 50);
  }
}

TEST_CASE("rays: t_max is respected (exclusive) and t is in units of |direction|", "[rays]") {
  const backend& q = backends[GENERATE(0, 1)];
  INFO("backend " << q.name);
  scene_mesh m;
  m.add_quad({-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}, material{});  // z = 1, facing +z
  const auto s = scene::create(m.desc());
  const glm::vec3 o(0.1f, 0.2f, 0.0f);
  CHECK(q.occluded(*s, o, {0, 0, 1}, 1.0001f));
  CHECK_FALSE(q.occluded(*s, o, {0, 0, 1}, 0.9999f));
  CHECK_FALSE(q.occluded(*s, o, {0, 0, 1}, 1.0f));  // t = 1 exactly is not below t_max = 1
  CHECK(q.occluded(*s, o, {0, 0, 1}, inf));
  CHECK_FALSE(q.occluded(*s, o, {0, 0, -1}, inf));  // pointing away
  ray_hit h;
  REQUIRE(q.intersect(*s, o, {0, 0, 2}, inf, h));
  CHECK(h.distance == Approx(0.5).epsilon(1e-6));  // float rounding of the shear: ~1e-7
  CHECK_FALSE(q.intersect(*s, o, {0, 0, 2}, 0.5f, h));
  // Degenerate queries answer "no hit".
  CHECK_FALSE(q.occluded(*s, o, {0, 0, 0}, inf));
  CHECK_FALSE(q.occluded(*s, o, {0, 0, 1}, 0.0f));
  CHECK_FALSE(q.occluded(*s, o, {0, 0, 1}, std::numeric_limits<float>::quiet_NaN()));
  CHECK_FALSE(q.occluded(*s, o, {0, inf, 1}, 10.0f));
  // An origin exactly on the triangle: t = 0 is not a hit.
  CHECK_FALSE(q.occluded(*s, {0.1f, 0.2f, 1.0f}, {0, 0, 1}, inf));
  const auto empty = scene::create(scene_mesh{}.desc());
  CHECK_FALSE(q.occluded(*empty, o, {0, 0, 1}, inf));
  CHECK_FALSE(q.intersect(*empty, o, {0, 0, 1}, inf, h));
}

TEST_CASE("rays: origins and directions beyond Embree's range (1.8e18) are answered, not asserted on", "[rays]") {
  // Embree's ray.valid() wants |origin|, |direction| components <= 1.844e18 (Debian's build
  // aborts on others). Scenes and points stop at max_coordinate = 1e18, but a shadow ray's
  // direction (to a light up to 1e18 away, from a point up to 1e18 the other way) can reach 2e18:
  // such rays are scaled to a unit direction (and t_max by the inverse). A quad at z = 0, 2e9 wide:
  scene_mesh m;
  m.add_quad({-1e9f, -1e9f, 0}, {1e9f, -1e9f, 0}, {1e9f, 1e9f, 0}, {-1e9f, 1e9f, 0}, material{});
  const auto s = scene::create(m.desc());
  const glm::vec3 far_origin(5e8f, 0.0f, 1e9f), down(0, 0, -2e18f);
  CHECK(occluded(*s, far_origin, down, inf));                 // hits the quad at t = 5e-10
  CHECK_FALSE(occluded(*s, far_origin, -down, inf));          // away from it
  CHECK_FALSE(occluded(*s, far_origin, down, 4e-10f));        // t_max before it
  CHECK(occluded(*s, far_origin, down, 6e-10f));
  ray_hit h;
  REQUIRE(intersect(*s, far_origin, down, inf, h));
  CHECK(h.distance == Approx(5e-10).epsilon(1e-5));
  glm::vec3 dirs[6];
  float t[6];
  bool out[6];
  for (int i = 0; i < 6; ++i) {
    dirs[i] = i % 2 ? -down : down;
    t[i] = inf;
  }
  occluded_many(*s, far_origin, dirs, t, 6, out);
  for (int i = 0; i < 6; ++i) CHECK(out[i] == (i % 2 == 0));
}

TEST_CASE("rays: both faces are hit, and the closest of several is reported", "[rays]") {
  const backend& q = backends[GENERATE(0, 1)];
  INFO("backend " << q.name);
  scene_mesh m;
  m.add_quad({-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}, material{});  // triangles 0, 1: z = 1, front +z
  m.add_quad({-1, -1, 3}, {-1, 1, 3}, {1, 1, 3}, {1, -1, 3}, material{});  // triangles 2, 3: z = 3, front -z
  const auto s = scene::create(m.desc());
  ray_hit h;
  REQUIRE(q.intersect(*s, {0.3f, -0.2f, 0.0f}, {0, 0, 1}, inf, h));  // from below: the back of z = 1
  CHECK(h.distance == Approx(1.0).epsilon(1e-6));
  CHECK(h.triangle < 2);
  CHECK_FALSE(h.front_face);
  REQUIRE(q.intersect(*s, {0.3f, -0.2f, 2.0f}, {0, 0, 1}, inf, h));  // the front of z = 3
  CHECK(h.distance == Approx(1.0).epsilon(1e-6));
  CHECK(h.triangle >= 2);
  CHECK(h.front_face);
  REQUIRE(q.intersect(*s, {0.3f, -0.2f, 2.0f}, {0, 0, -1}, inf, h));  // the front of z = 1
  CHECK(h.triangle < 2);
  CHECK(h.front_face);
  REQUIRE(q.intersect(*s, {0.3f, -0.2f, 5.0f}, {0, 0, -1}, inf, h));  // the back of z = 3, nearer than z = 1
  CHECK(h.distance == Approx(2.0).epsilon(1e-6));
  CHECK(h.triangle >= 2);
  CHECK_FALSE(h.front_face);
  CHECK(q.occluded(*s, {0.3f, -0.2f, 0.0f}, {0, 0, 1}, inf));
  CHECK(q.occluded(*s, {0.3f, -0.2f, 5.0f}, {0, 0, -1}, inf));
}


TEST_CASE("rays: Debian's Embree hits both faces (no backface culling) and backs the queries", "[rays]") {
  // rays.hpp promises hits from either side; an Embree built with EMBREE_BACKFACE_CULLING would
  // silently drop back faces (hemilight then refuses it: prepare_rays throws unsupported).
  RTCDevice device = rtcNewDevice(nullptr);
  REQUIRE(device != nullptr);
  INFO("Embree " << rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION));
  CHECK(rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED) == 0);
  rtcReleaseDevice(device);
  const auto s = scene::create(cornell_box().desc());
  REQUIRE_NOTHROW(prepare_rays(*s));
  CHECK(detail::rays_use_embree(*s));
  prepare_rays(*s);  // idempotent
}

TEST_CASE("rays: the Embree scene is built on the first query, not by scene::create", "[rays]") {
  const auto first = scene::create(open_pavilion().desc());
  CHECK(detail::rays_use_embree(*first));  // the device exists from here on
  const std::int64_t before = detail::embree_device_bytes();
  const auto s = scene::create(hexagon_room(3).desc());
  CHECK(detail::embree_device_bytes() == before);
  CHECK(occluded(*s, {0.0f, 1.0f, 0.0f}, {0.0f, 100.0f, 0.0f}, 1.0f));  // through the ceiling
  const std::int64_t after = detail::embree_device_bytes();
  INFO("Embree scene: " << (after - before) << " bytes for " << s->drawable_triangle_count() << " triangles");
  CHECK(after > before);
  // An empty scene never reaches Embree.
  const auto empty = scene::create(scene_mesh{}.desc());
  REQUIRE_NOTHROW(prepare_rays(*empty));
  CHECK_FALSE(detail::rays_use_embree(*empty));
  CHECK(detail::embree_device_bytes() == after);
}

TEST_CASE("rays: a failed Embree build is reported by prepare_rays and the queries fall back", "[rays]") {
  detail::fail_embree_builds_for_testing(true);
  const auto s = scene::create(hexagon_room(3).desc());
  const bool blocked = occluded(*s, {0.0f, 1.0f, 0.0f}, {0.0f, 100.0f, 0.0f}, 1.0f);  // the lazy build fails here
  detail::fail_embree_builds_for_testing(false);
  CHECK(blocked);
  CHECK_FALSE(detail::rays_use_embree(*s));  // not retried
  try {
    prepare_rays(*s);
    FAIL("prepare_rays did not throw");
  } catch (const error& e) {
    CHECK(e.code() == status::out_of_memory);
    CHECK(std::string(e.what()).find("Embree") != std::string::npos);
  }
  ray_hit h;
  REQUIRE(intersect(*s, {0.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, inf, h));
  ray_hit ref;
  REQUIRE(detail::intersect_bvh(*s, {0.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, inf, ref));
  CHECK(h.distance == ref.distance);
  CHECK(h.drawable == ref.drawable);
  // A scene made afterwards gets Embree again.
  CHECK(detail::rays_use_embree(*scene::create(cornell_box().desc())));
}

TEST_CASE("rays: occluded_many answers as occluded() ray by ray, invalid rays and count 0 included", "[rays]") {
  for (const named_mesh& nm : {named_mesh{"cornell_box", cornell_box()}, named_mesh{"hexagon_room_3", hexagon_room(3)},
                               named_mesh{"open_pavilion", open_pavilion()},
                               named_mesh{"sky_and_occluders", sky_and_occluders()}}) {
    INFO("scene " << nm.name);
    const auto s = scene::create(nm.mesh.desc());
    const std::vector<ref_triangle> tris = reference_triangles(nm.mesh);
    std::mt19937 rng(23);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    const glm::vec3 lo = s->bounds_lo(), hi = s->bounds_hi();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    int rays = 0, differ = 0;
    for (int bundle = 0; bundle < 300; ++bundle) {
      const glm::vec3 o = lo + (hi - lo) * glm::vec3(u01(rng), u01(rng), u01(rng)) * 1.2f - 0.1f * (hi - lo);
      const std::size_t count = std::size_t(bundle % 21);  // 0 to 20: packets of 8, the last of 1 to 8
      glm::vec3 dirs[20];
      float t_max[20];
      bool out[20];
      for (std::size_t i = 0; i < count; ++i) {
        dirs[i] = glm::normalize(glm::vec3(gauss(rng), gauss(rng), gauss(rng))) * (0.5f + 2.0f * u01(rng));
        t_max[i] = i % 4 == 0 ? inf : s->size() * (0.05f + 0.95f * u01(rng)) / glm::length(dirs[i]);
        switch ((bundle + int(i)) % 11) {  // invalid rays among the valid ones
          case 0: dirs[i] = glm::vec3(0.0f); break;
          case 1: dirs[i].y = nan; break;
          case 2: dirs[i].x = inf; break;
          case 3: t_max[i] = 0.0f; break;
          case 4: t_max[i] = nan; break;
          case 5: t_max[i] = -1.0f; break;
          default: break;
        }
        out[i] = !occluded(*s, o, dirs[i], t_max[i]);  // overwritten: every entry must be written
      }
      occluded_many(*s, o, dirs, t_max, count, out);
      for (std::size_t i = 0; i < count; ++i) {
        ++rays;
        const bool one = occluded(*s, o, dirs[i], t_max[i]);
        if (out[i] != one) {
          INFO("bundle " << bundle << " ray " << i << ": batch " << out[i] << " single " << one);
          CHECK(near_an_edge(tris, glm::dvec3(o), glm::dvec3(dirs[i]), double(t_max[i]), 1e-5));
          ++differ;
        }
        if (!std::isfinite(dirs[i].x) || !std::isfinite(dirs[i].y) || dirs[i] == glm::vec3(0.0f) ||
            !(t_max[i] > 0.0f))
          CHECK_FALSE(out[i]);
      }
    }
    CHECK(differ <= rays / 100);
    // A non-finite origin: every answer false; count 0 with null pointers does nothing.
    glm::vec3 d[3] = {{0.0f, 1.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}};
    float t[3] = {inf, inf, inf};
    bool out[3] = {true, true, true};
    occluded_many(*s, glm::vec3(nan, 0.0f, 0.0f), d, t, 3, out);
    CHECK_FALSE((out[0] || out[1] || out[2]));
    occluded_many(*s, glm::vec3(0.0f), nullptr, nullptr, 0, nullptr);
  }
}

TEST_CASE("rays: occluded_many through the fallback answers as occluded_bvh", "[rays]") {
  detail::fail_embree_builds_for_testing(true);
  const auto s = scene::create(hexagon_room(3).desc());
  try {
    prepare_rays(*s);
  } catch (const error&) {
  }
  detail::fail_embree_builds_for_testing(false);
  REQUIRE_FALSE(detail::rays_use_embree(*s));
  std::mt19937 rng(5);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  for (int bundle = 0; bundle < 50; ++bundle) {
    const glm::vec3 o(0.3f * gauss(rng), 1.0f + 0.3f * gauss(rng), 0.3f * gauss(rng));
    glm::vec3 dirs[12];
    float t_max[12];
    bool out[12];
    for (int i = 0; i < 12; ++i) {
      dirs[i] = glm::vec3(gauss(rng), gauss(rng), gauss(rng));
      t_max[i] = i == 5 ? 0.0f : (i % 3 == 0 ? inf : 2.0f);
    }
    occluded_many(*s, o, dirs, t_max, 12, out);
    for (int i = 0; i < 12; ++i) CHECK(out[i] == (t_max[i] > 0.0f && detail::occluded_bvh(*s, o, dirs[i], t_max[i])));
  }
}
