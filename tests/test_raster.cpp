// Tests of raster.hpp (and the hemicube cross of hemicube.hpp): the software hemicube rasterizer.
// References, all independent of the rasterizer: a ray caster written here (double precision,
// Moeller-Trumbore-free: plane intersection + edge planes through the eye), closed meshes built
// here whose every direction from an inside point crosses exactly one triangle, and closed forms.
#include "hemilight/raster.hpp"
#include "hemilight/integrate.hpp"
#include "hemilight/levels.hpp"
#include "hemilight/reference_scenes.hpp"
#include "hemilight/parallel.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <cstring>
#include <set>
#include <string>

using namespace hemilight;

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

// A frame with normal n rolled by `roll` radians about n (built here, not by make_frame).
frame rolled_frame(glm::dvec3 n, double roll) {
  n = glm::normalize(n);
  const glm::dvec3 helper = std::fabs(n.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 t0 = glm::normalize(glm::cross(helper, n));
  const glm::dvec3 b0 = glm::cross(n, t0);
  const glm::dvec3 t = std::cos(roll) * t0 + std::sin(roll) * b0;
  const glm::dvec3 b = glm::cross(n, t);
  return {glm::vec3(t), glm::vec3(b), glm::vec3(n)};
}

frame random_frame(std::mt19937& rng) {
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 6.283185307179586);
  glm::dvec3 n;
  do n = {g(rng), g(rng), g(rng)};
  while (glm::length(n) < 1e-3);
  return rolled_frame(n, u(rng));
}

// ---- the independent ray caster ------------------------------------------------------------------

struct ray_result {
  bool ambiguous = false;  // the ray passes within `edge_eps` of an edge of a front-most candidate
  long triangle = -1;      // scene_desc index, -1 for a miss
  double t = inf;          // distance along the unit ray
  bool back = false;       // hit the back of the triangle (winding)
  glm::dvec2 uv{0.0};      // lightmap UV of the hit (if the mesh has UVs)
};

// Nearest triangle along the unit ray origin + t dir whose hit point is in front of the near plane
// of the face with forward axis `forward` (the rasterizer clips w = forward . (p - origin) < near).
// Edge proximity: the sine of the angle between dir and the plane through the eye and an edge.
ray_result cast_ray(const scene_mesh& m, const glm::dvec3& origin, const glm::dvec3& dir, const glm::dvec3& forward,
                    double near, double edge_eps) {
  ray_result best;
  bool best_near_edge = false;
  const double fw = glm::dot(forward, dir);
  for (std::size_t i = 0; i < m.triangle_count(); ++i) {
    glm::dvec3 v[3];
    for (int k = 0; k < 3; ++k) v[k] = glm::dvec3(m.positions[m.indices[3 * i + static_cast<std::size_t>(k)]]) - origin;
    const glm::dvec3 nrm = glm::cross(v[1] - v[0], v[2] - v[0]);
    const double len = glm::length(nrm);
    if (len == 0.0) continue;
    const double denom = glm::dot(nrm, dir);
    if (denom == 0.0) continue;
    const double t = glm::dot(nrm, v[0]) / denom;
    if (!(t > 0.0)) continue;
    const double w = t * fw;
    if (w < near * (1 - 1e-4)) continue;  // clipped away for sure
    bool near_edge = std::fabs(w - near) <= 1e-4 * near;
    // Edge planes through the eye: inside when all signed sines agree.
    double s[3];
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 c = glm::cross(v[k], v[(k + 1) % 3]);
      const double cl = glm::length(c);
      s[k] = cl > 0 ? glm::dot(dir, c) / cl : 0.0;
    }
    const bool inside = (s[0] >= 0 && s[1] >= 0 && s[2] >= 0) || (s[0] <= 0 && s[1] <= 0 && s[2] <= 0);
    // Near an edge: inside the triangle grown by edge_eps, and within edge_eps of an edge's plane.
    const bool inside_grown = (s[0] >= -edge_eps && s[1] >= -edge_eps && s[2] >= -edge_eps) ||
                              (s[0] <= edge_eps && s[1] <= edge_eps && s[2] <= edge_eps);
    const double closest = std::min({std::fabs(s[0]), std::fabs(s[1]), std::fabs(s[2])});
    if (inside_grown && closest < edge_eps) near_edge = true;
    // Grazing: the plane seen almost edge-on (|cos| < 1e-3); the distance is ill-conditioned.
    if (std::fabs(denom) / len < 1e-3) near_edge = true;
    if (!inside && !near_edge) continue;
    if (t < best.t) {
      best.t = t;
      best_near_edge = near_edge;
      best.triangle = inside ? static_cast<long>(i) : -1;
      best.back = denom > 0;
      if (!m.lightmap_uvs.empty()) {
        const glm::dvec3 q = t * dir - v[0];
        const double nn = glm::dot(nrm, nrm);
        const double b1 = glm::dot(glm::cross(v[2] - v[0], nrm), q) / nn;
        const double b2 = glm::dot(glm::cross(nrm, v[1] - v[0]), q) / nn;
        const auto uv = [&](int k) { return glm::dvec2(m.lightmap_uvs[m.indices[3 * i + static_cast<std::size_t>(k)]]); };
        best.uv = uv(0) + b1 * (uv(1) - uv(0)) + b2 * (uv(2) - uv(0));
      }
    }
  }
  best.ambiguous = best_near_edge;
  if (best.ambiguous) best.triangle = -1;
  if (best.triangle < 0 && !best.ambiguous) best.t = inf;
  return best;
}

// Renders one hemicube and compares every unambiguous texel with the ray caster: the triangle
// seen, the distance (relative error 1e-4: float plane intersection is good to ~1e-6 away from
// grazing angles, which the caster excludes), the flags and the radiance (exact: copied).
// Returns the number of texels checked.
std::size_t compare_with_ray_caster(const scene_mesh& m, const glm::vec3& position, const frame& basis, int n,
                                    float near = 0.0f, double min_checked = 0.8) {
  const auto s = scene::create(m.desc());
  hemicube_rasterizer r(s, raster_options{near});
  hemicube_buffer buf;
  r.render(position, basis, n, buf);
  // Edge margin: 2% of a texel's angular size (the fixed-point snapping moves edges by at most
  // 1/512 texel, 10x less).
  const double edge_eps = 0.02 * 2.0 / n / std::sqrt(3.0);
  std::size_t checked = 0, ambiguous = 0, mismatches = 0;
  std::string first;
  for (std::size_t i = 0; i < hemicube_texel_count(n); ++i) {
    const glm::dvec3 d = glm::dvec3(hemicube_texel_direction(n, i));
    const glm::dvec3 a = glm::dvec3(hemicube_axes(hemicube_texel_from_index(n, i).face).forward);
    const glm::dvec3 wd = glm::normalize(glm::dvec3(basis.t) * d.x + glm::dvec3(basis.b) * d.y + glm::dvec3(basis.n) * d.z);
    const ray_result ref = cast_ray(m, glm::dvec3(position), wd, glm::dvec3(basis.t) * a.x + glm::dvec3(basis.b) * a.y + glm::dvec3(basis.n) * a.z,
                                    r.near_distance(), edge_eps);
    if (ref.ambiguous) {
      ++ambiguous;
      continue;
    }
    ++checked;
    const std::uint32_t seen = r.seen_triangle(i);
    bool ok;
    glm::vec3 expected_radiance;
    std::uint8_t expected_flags;
    if (ref.triangle < 0) {
      ok = seen == hemicube_rasterizer::no_triangle && std::isinf(buf.distance[i]);
      expected_radiance = m.sky_radiance;
      expected_flags = texel_miss;
    } else {
      const material& mat = m.materials[static_cast<std::size_t>(ref.triangle)];
      const bool back = ref.back && !mat.two_sided;
      expected_radiance = back ? glm::vec3(0.0f) : mat.emission;
      expected_flags = back ? texel_back_face : texel_hit_front;
      ok = seen == static_cast<std::uint32_t>(ref.triangle) && std::fabs(buf.distance[i] - ref.t) <= 1e-4 * ref.t;
    }
    ok = ok && buf.flags[i] == expected_flags && buf.radiance_at(i).x == expected_radiance.x &&
         buf.radiance_at(i).y == expected_radiance.y && buf.radiance_at(i).z == expected_radiance.z;
    if (!ok && mismatches++ == 0)
      first = "texel " + std::to_string(i) + ": rasterizer triangle " + std::to_string(static_cast<long>(seen == hemicube_rasterizer::no_triangle ? -1 : long(seen))) +
              " distance " + std::to_string(buf.distance[i]) + " flags " + std::to_string(buf.flags[i]) +
              "; ray caster triangle " + std::to_string(ref.triangle) + " distance " + std::to_string(ref.t);
  }
  INFO("N = " << n << ", checked " << checked << ", ambiguous " << ambiguous << ", first mismatch: " << first);
  CHECK(mismatches == 0);
  // Ambiguous texels are a thin set (near edges): most of the hemicube must be checked.
  CHECK(static_cast<double>(checked) >= min_checked * static_cast<double>(hemicube_texel_count(n)));
  return checked;
}

// ---- closed meshes -----------------------------------------------------------------------------

// Orients every triangle of m so its front faces the point `inside` (for a star-shaped mesh).
void face_towards(scene_mesh& m, const glm::vec3& inside) {
  for (std::size_t i = 0; i < m.triangle_count(); ++i) {
    std::uint32_t* idx = m.indices.data() + 3 * i;
    const glm::dvec3 a(m.positions[idx[0]]), b(m.positions[idx[1]]), c(m.positions[idx[2]]);
    if (glm::dot(glm::cross(b - a, c - a), glm::dvec3(inside) - a) < 0) std::swap(idx[1], idx[2]);
  }
}

// A unit sphere triangulated irregularly: rings at jittered polar angles with random vertex
// counts and phases, zipped together; pole fans. Every vertex is shared by index: closed.
scene_mesh irregular_sphere(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> count(5, 17);
  const double pi = 3.14159265358979323846;
  scene_mesh m;
  const int rings = 9;
  // Per ring: vertex indices and their azimuths (increasing, starting within half a segment of 0).
  std::vector<std::vector<std::uint32_t>> ring(rings);
  std::vector<std::vector<double>> azimuth(rings);
  m.positions.push_back({0, 0, 1});  // north pole
  for (std::size_t j = 0; j < rings; ++j) {
    const double theta = pi * (static_cast<double>(j) + 1.0 + 0.6 * (u(rng) - 0.5)) / (rings + 1);
    const int k = count(rng);
    const double seg = 2 * pi / k;
    const double phase = 0.5 * seg * u(rng);
    for (int i = 0; i < k; ++i) {
      const double phi = phase + seg * (i + 0.4 * u(rng));
      azimuth[j].push_back(phi);
      ring[j].push_back(static_cast<std::uint32_t>(m.positions.size()));
      m.positions.push_back(glm::vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)));
    }
  }
  const auto south = static_cast<std::uint32_t>(m.positions.size());
  m.positions.push_back({0, 0, -1});
  const material mat{glm::vec3(1.0f), glm::vec3(0.5f), false};
  const auto tri = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    m.indices.insert(m.indices.end(), {a, b, c});
    m.materials.push_back(mat);
  };
  const auto& first = ring.front();
  for (std::size_t i = 0; i < first.size(); ++i) tri(0, first[i], first[(i + 1) % first.size()]);
  const auto& last = ring.back();
  for (std::size_t i = 0; i < last.size(); ++i) tri(south, last[i], last[(i + 1) % last.size()]);
  // Zip ring j and j + 1 by azimuth: always advance the ring whose next vertex comes first.
  for (std::size_t j = 0; j + 1 < ring.size(); ++j) {
    const auto& A = ring[j];
    const auto& B = ring[j + 1];
    const auto next = [&](std::size_t r, std::size_t i) {
      const auto& az = azimuth[r];
      return i + 1 < az.size() ? az[i + 1] : az[0] + 2 * pi;
    };
    std::size_t ia = 0, ib = 0;
    while (ia < A.size() || ib < B.size()) {
      const double fa = ia < A.size() ? next(j, ia) : 1e9;
      const double fb = ib < B.size() ? next(j + 1, ib) : 1e9;
      if (fa <= fb) {
        tri(A[ia % A.size()], A[(ia + 1) % A.size()], B[ib % B.size()]);
        ++ia;
      } else {
        tri(A[ia % A.size()], B[(ib + 1) % B.size()], B[ib % B.size()]);
        ++ib;
      }
    }
  }
  face_towards(m, glm::vec3(0.0f));
  return m;
}

// An axis-aligned box [lo, hi] whose 12 edges carry random extra vertices (shared by the two
// faces of the edge) and whose faces are fans from a random interior point: irregular, closed,
// no T-junctions. Faces towards the inside unless `outward`.
scene_mesh fan_box(std::mt19937& rng, const glm::vec3& lo, const glm::vec3& hi, bool outward = false) {
  std::uniform_real_distribution<float> u(0.05f, 0.95f);
  std::uniform_int_distribution<int> extra(0, 3);
  scene_mesh m;
  const auto corner = [&](int c) { return glm::vec3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z); };
  for (int c = 0; c < 8; ++c) m.positions.push_back(corner(c));
  // Edge (a, b) with a < b -> its interior vertices in order from a to b.
  std::vector<std::vector<std::uint32_t>> edge_points(64);
  for (int a = 0; a < 8; ++a)
    for (int bit = 1; bit < 8; bit <<= 1) {
      if (a & bit) continue;
      const int b = a | bit;
      std::vector<float> ts(static_cast<std::size_t>(extra(rng)));
      for (float& t : ts) t = u(rng);
      std::sort(ts.begin(), ts.end());
      for (float t : ts) {
        edge_points[static_cast<std::size_t>(a * 8 + b)].push_back(static_cast<std::uint32_t>(m.positions.size()));
        m.positions.push_back((1.0f - t) * corner(a) + t * corner(b));
      }
    }
  const auto edge = [&](int a, int b) {
    std::vector<std::uint32_t> pts = edge_points[static_cast<std::size_t>(std::min(a, b) * 8 + std::max(a, b))];
    if (a > b) std::reverse(pts.begin(), pts.end());
    return pts;
  };
  const int faces[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  const material mat{glm::vec3(0.25f, 0.5f, 1.0f), glm::vec3(0.5f), false};
  for (const auto& f : faces) {
    std::vector<std::uint32_t> loop;
    for (int k = 0; k < 4; ++k) {
      loop.push_back(static_cast<std::uint32_t>(f[k]));
      for (std::uint32_t p : edge(f[k], f[(k + 1) % 4])) loop.push_back(p);
    }
    const float s = u(rng), t = u(rng);
    const glm::vec3 centre = (1 - t) * ((1 - s) * corner(f[0]) + s * corner(f[1])) + t * ((1 - s) * corner(f[3]) + s * corner(f[2]));
    const auto ci = static_cast<std::uint32_t>(m.positions.size());
    m.positions.push_back(centre);
    for (std::size_t k = 0; k < loop.size(); ++k) {
      m.indices.insert(m.indices.end(), {ci, loop[k], loop[(k + 1) % loop.size()]});
      m.materials.push_back(mat);
    }
  }
  face_towards(m, 0.5f * (lo + hi));
  if (outward)
    for (std::size_t i = 0; i < m.triangle_count(); ++i) std::swap(m.indices[3 * i + 1], m.indices[3 * i + 2]);
  return m;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

TEST_CASE("raster: closed irregular meshes around the point cover every texel exactly once", "[raster]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int mesh = 0; mesh < 6; ++mesh) {
    const bool sphere = mesh % 2 == 0;
    const scene_mesh m = sphere ? irregular_sphere(rng) : fan_box(rng, {-0.7f, -1.1f, -0.9f}, {1.3f, 0.8f, 1.0f});
    const auto s = scene::create(m.desc());
    hemicube_rasterizer r(s);
    std::vector<std::uint32_t> counts;
    hemicube_buffer buf;
    for (int k = 0; k < 12; ++k) {
      // A random point well inside (the sphere's inscribed polyhedron contains the ball of
      // radius 0.6; the box contains [-0.6, 0.7]^3).
      glm::vec3 p(u(rng), u(rng), u(rng));
      p *= 0.55f / std::max(1.0f, glm::length(p));
      const frame f = random_frame(rng);
      const int n = k % 3 == 0 ? 64 : (k % 3 == 1 ? 16 : 6);
      r.render_coverage(p, f, n, counts);
      std::size_t wrong = 0;
      for (std::uint32_t c : counts) wrong += c != 1;
      INFO("mesh " << mesh << " (" << (sphere ? "sphere" : "box") << ", " << m.triangle_count() << " triangles), N = " << n);
      CHECK(wrong == 0);
      r.render(p, f, n, buf);
      std::size_t sky = 0, back = 0;
      for (std::uint8_t fl : buf.flags) {
        sky += (fl & texel_miss) != 0;
        back += (fl & texel_back_face) != 0;
      }
      CHECK(sky == 0);
      CHECK(back == 0);
    }
  }
}

TEST_CASE("raster: agrees with an independent ray caster on the reference scenes", "[raster]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  {
    const scene_mesh m = cornell_box();
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 p(0.05f + 0.45f * u(rng), 0.02f + 0.5f * u(rng), 0.03f + 0.5f * u(rng));
      compare_with_ray_caster(m, p, random_frame(rng), 24);
    }
    // On the floor, looking up (the baker's case).
    compare_with_ray_caster(m, {0.4f, 0.0f, 0.1f}, rolled_frame({0, 1, 0}, 0.3), 32);
  }
  {
    const scene_mesh m = hexagon_room(2);
    compare_with_ray_caster(m, {0.5f, 1.5f, -0.3f}, random_frame(rng), 24);
    compare_with_ray_caster(m, {1.0f, 3.0f, 0.5f}, rolled_frame({0, -1, 0}, 1.0), 24);  // on the ceiling
  }
  {
    const scene_mesh m = sky_and_occluders();
    compare_with_ray_caster(m, {0.0f, 0.0f, 0.0f}, rolled_frame({0, 1, 0}, 0.0), 24);
    compare_with_ray_caster(m, {1.5f, 0.5f, -0.5f}, random_frame(rng), 24);
  }
}

TEST_CASE("raster: hemicube resolutions N = 2 and N = 512", "[raster]") {
  std::mt19937 rng(3);
  const scene_mesh box = fan_box(rng, {-1, -1, -1}, {1, 2, 1.5f});
  compare_with_ray_caster(box, {0.1f, 0.2f, -0.3f}, random_frame(rng), 2);
  compare_with_ray_caster(cornell_box(), {0.3f, 0.2f, 0.25f}, random_frame(rng), 2);
  const auto s = scene::create(box.desc());
  hemicube_rasterizer r(s);
  std::vector<std::uint32_t> counts;
  r.render_coverage({0.1f, 0.2f, -0.3f}, random_frame(rng), 512, counts);
  CHECK(std::count(counts.begin(), counts.end(), 1u) == static_cast<std::ptrdiff_t>(counts.size()));
  compare_with_ray_caster(cornell_box(), {0.2f, 0.1f, 0.3f}, rolled_frame({0.3, 1, -0.2}, 0.7), 512);
}

TEST_CASE("raster: near-plane clipping of a wall crossing it and of a triangle through the point", "[raster]") {
  const material grey{glm::vec3(0.5f), glm::vec3(0.5f), false};
  // A wall x = 0.03 (local = world here) crossing the near plane 0.05: on the +x face it is entirely
  // clipped, on the top face only where z >= 0.05 survives. The ray caster applies the same rule.
  scene_mesh wall;
  wall.add_quad({0.03f, -5, -1}, {0.03f, -5, 5}, {0.03f, 5, 5}, {0.03f, 5, -1}, grey);
  wall.add_quad({5, -5, 4}, {5, 5, 4}, {-5, 5, 4}, {-5, -5, 4}, grey);  // a ceiling behind it
  const frame identity{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  compare_with_ray_caster(wall, {0, 0, 0}, identity, 32, 0.05f);
  {
    const auto s = scene::create(wall.desc());
    hemicube_rasterizer r(s, raster_options{0.05f});
    hemicube_buffer buf;
    r.render({0, 0, 0}, identity, 32, buf);
    std::size_t on_wall_top = 0, on_wall_pos_x = 0;
    for (std::size_t i = 0; i < buf.texel_count(); ++i) {
      const hemicube_face face = hemicube_texel_from_index(32, i).face;
      if (r.seen_triangle(i) < 2 && face == hemicube_face::top) ++on_wall_top;
      if (r.seen_triangle(i) < 2 && face == hemicube_face::pos_x) ++on_wall_pos_x;
    }
    CHECK(on_wall_top > 0);     // the wall is seen above z = near on the top face...
    CHECK(on_wall_pos_x == 0);  // ...and clipped away on the +x face (x = 0.03 < near)
  }
  // A triangle through the point, tilted 30 degrees from the tangent plane, plus surroundings.
  scene_mesh through;
  through.add_triangle({-1, -1, -0.577f}, {1, -1, -0.577f}, {0, 2, 1.155f}, grey);
  through.add_quad({-3, -3, 2}, {3, -3, 2}, {3, 3, 2}, {-3, 3, 2}, grey);
  std::mt19937 rng(5);
  compare_with_ray_caster(through, {0, 0, 0}, identity, 32);
  compare_with_ray_caster(through, {0, 0, 0}, random_frame(rng), 32, 0.01f);
}

TEST_CASE("raster: geometry entirely behind the tangent plane is culled and never seen", "[raster]") {
  std::mt19937 rng(9);
  scene_mesh m = fan_box(rng, {-2, -2, -3}, {2, 2, -0.5f}, true);
  m.sky_radiance = {0.5f, 0.25f, 2.0f};
  const auto s = scene::create(m.desc());
  hemicube_rasterizer r(s);
  hemicube_buffer buf;
  r.render({0, 0, 0}, frame{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, 16, buf);
  for (std::size_t i = 0; i < buf.texel_count(); ++i) {
    REQUIRE(buf.flags[i] == texel_miss);
    REQUIRE(std::isinf(buf.distance[i]));
    REQUIRE((buf.radiance_at(i).x == 0.5f && buf.radiance_at(i).y == 0.25f && buf.radiance_at(i).z == 2.0f));
  }
  CHECK(r.statistics().triangles_tested == 0);  // the BVH root is rejected: no triangle is touched
  CHECK(r.statistics().nodes_visited == 1);
}

TEST_CASE("raster: culling makes the cost follow what the hemicube can see", "[raster]") {
  // Many boxes on a ground; a point on the ground sees everything above it, but a point facing
  // down from above the boxes sees nothing: only a few BVH nodes are visited.
  const auto s = scene::create(many_boxes(400).desc());
  hemicube_rasterizer r(s);
  hemicube_buffer buf;
  r.render({0, 2.5f, 0}, rolled_frame({0, 1, 0}, 0.0), 16, buf);
  CHECK(r.statistics().triangles_tested == 0);
  r.render({0, 0.5f, 0}, rolled_frame({1, 0, 0}, 0.0), 16, buf);
  // Facing +x from the middle: about half the scene lies behind the tangent plane.
  CHECK(r.statistics().triangles_tested < s->drawable_triangle_count() * 6 / 10);
  CHECK(r.statistics().triangles_tested > 0);
}

TEST_CASE("raster: a point inside an outward-facing box sees back faces on every texel", "[raster]") {
  std::mt19937 rng(13);
  const scene_mesh m = fan_box(rng, {-1, -1, -1}, {1, 1, 1}, true);
  const auto s = scene::create(m.desc());
  hemicube_rasterizer r(s);
  hemicube_buffer buf;
  for (int k = 0; k < 4; ++k) {
    const frame f = random_frame(rng);
    const glm::vec3 p(0.1f * static_cast<float>(k), -0.2f, 0.3f);
    r.render(p, f, 16, buf);
    for (std::size_t i = 0; i < buf.texel_count(); ++i) {
      REQUIRE(buf.flags[i] == texel_back_face);
      REQUIRE((buf.radiance_at(i).x == 0 && buf.radiance_at(i).y == 0 && buf.radiance_at(i).z == 0));
      // Closed form: distance to the box [-1, 1]^3 along d (float intersection, 1e-5 relative).
      const glm::dvec3 d = glm::dvec3(f.to_world(hemicube_texel_direction(16, i)));
      double t = inf;
      for (int c = 0; c < 3; ++c)
        if (d[c] != 0) t = std::min(t, ((d[c] > 0 ? 1.0 : -1.0) - p[c]) / d[c]);
      REQUIRE(buf.distance[i] == Approx(t).epsilon(1e-5));
    }
    compare_with_ray_caster(m, p, f, 16);
  }
}

TEST_CASE("raster: two-sided triangles look the same from both sides", "[raster]") {
  scene_mesh m;
  m.add_quad({-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}, {glm::vec3(2.0f, 3.0f, 4.0f), glm::vec3(0.5f), true});
  const auto s = scene::create(m.desc());
  hemicube_rasterizer r(s);
  hemicube_buffer buf;
  r.render({0, 0, 0}, frame{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, 8, buf);  // sees its back
  const std::size_t centre = hemicube_texel_index(8, {hemicube_face::top, 4, 4});
  CHECK(buf.flags[centre] == texel_hit_front);
  CHECK(buf.radiance_at(centre).z == 4.0f);
  CHECK(buf.distance[centre] == Approx(std::sqrt(1.0 + 2 * (0.125 * 0.125))).epsilon(1e-6));
}

TEST_CASE("raster: every texel gets the emission of the triangle it sees, with few or many distinct emissions", "[raster]") {
  // Texels carry a shade key: packed into the texel's id when the scene has few distinct
  // emissions, looked up per draw when keys and draws do not fit 31 bits together. 49,928
  // triangles with distinct emissions need 16 key bits and over 2^15 draws: the lookup. 5 distinct
  // emissions: packed. Reference: the material of seen_triangle(), on every path.
  scene_mesh base = heightfield(50000);
  REQUIRE(base.triangle_count() > 46341);  // (T + 2) * (T + 1) > 2^31 when every emission differs
  for (const int kinds : {5, 0}) {
    scene_mesh m = base;
    for (std::size_t i = 0; i < m.materials.size(); ++i) {
      const auto k = static_cast<float>(kinds ? i % static_cast<std::size_t>(kinds) : i);
      m.materials[i] = material{glm::vec3(k + 1.0f, 0.5f * k, 0.25f), glm::vec3(0.5f), i % 3 == 0};
    }
    m.sky_radiance = glm::vec3(0.125f, 0.25f, 0.5f);
    const auto s = scene::create(m.desc());
    CHECK(s->emissions().size() == (kinds ? 5u : m.triangle_count()));
    raster_options scalar, sse2;
    scalar.diagnostics.simd = false;
    sse2.diagnostics.avx2 = false;
    hemicube_rasterizer paths[] = {hemicube_rasterizer(s), hemicube_rasterizer(s, sse2), hemicube_rasterizer(s, scalar)};
    const glm::vec3 centre = 0.5f * (s->bounds_lo() + s->bounds_hi());
    const float height = 0.2f * s->size();
    for (const float side : {1.0f, -1.0f}) {  // above the surface (fronts), below it (backs)
      const glm::vec3 p = centre + glm::vec3(0.0f, side * height, 0.0f);
      const frame f = make_frame(glm::normalize(glm::vec3(0.3f, -side, 0.2f)));
      for (hemicube_rasterizer& r : paths) {
        hemicube_buffer buf;
        r.render(p, f, 64, buf);
        std::size_t front = 0, back = 0, wrong = 0;
        for (std::size_t i = 0; i < buf.texel_count(); ++i) {
          const glm::vec3 l = buf.radiance_at(i);
          const std::uint32_t t = r.seen_triangle(i);
          if (buf.flags[i] == texel_miss) {
            wrong += t != hemicube_rasterizer::no_triangle || l != m.sky_radiance;
          } else if (buf.flags[i] == texel_hit_front) {
            ++front;
            wrong += t >= m.triangle_count() || std::memcmp(&l, &m.materials[t].emission, sizeof l) != 0;
          } else {
            ++back;
            wrong += buf.flags[i] != texel_back_face || t >= m.triangle_count() || m.materials[t].two_sided ||
                     l != glm::vec3(0.0f);
          }
        }
        CHECK(wrong == 0);
        CHECK(front > 1000);            // the surface fills much of the view from either side:
        if (side < 0) CHECK(back > 1000);  // two-sided fronts, one-sided backs
      }
    }
  }
}

TEST_CASE("raster: degenerate triangles are accepted and never drawn", "[raster]") {
  scene_mesh m;
  const material lit{glm::vec3(1.0f), glm::vec3(0.5f), false};
  m.add_triangle({0, 0, 1}, {0, 0, 1}, {1, 0, 1}, lit);            // two equal vertices
  m.add_triangle({-1, -1, 1}, {0, 0, 1}, {1, 1, 1}, lit);          // collinear
  m.add_triangle({0.2f, 0.2f, 1}, {0.2f, 0.2f, 1}, {0.2f, 0.2f, 1}, lit);  // a point
  m.add_quad({-2, -2, 2}, {2, -2, 2}, {2, 2, 2}, {-2, 2, 2}, lit);  // a real ceiling behind them
  m.indices.insert(m.indices.end(), {3, 3, 4});                    // repeated index
  m.materials.push_back(lit);
  const auto s = scene::create(m.desc());
  CHECK(s->triangle_count() == 6);
  CHECK(s->drawable_triangle_count() == 2);
  hemicube_rasterizer r(s);
  hemicube_buffer buf;
  r.render({0, 0, 0}, frame{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, 32, buf);
  std::set<std::uint32_t> seen;
  for (std::size_t i = 0; i < buf.texel_count(); ++i) seen.insert(r.seen_triangle(i));
  for (std::uint32_t t : seen) CHECK((t == 3 || t == 4 || t == hemicube_rasterizer::no_triangle));
  compare_with_ray_caster(m, {0, 0, 0}, frame{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, 32);
}

TEST_CASE("raster: an empty scene is all sky", "[raster]") {
  scene_mesh m;
  m.sky_radiance = {1.0f, 2.0f, 3.0f};
  const auto s = scene::create(m.desc());
  CHECK(s->size() == 0.0f);
  hemicube_rasterizer r(s);
  CHECK(r.near_distance() == 1e-4f);
  hemicube_buffer buf;
  r.render({0, 0, 0}, frame{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, 4, buf);
  for (std::size_t i = 0; i < buf.texel_count(); ++i) {
    CHECK(buf.flags[i] == texel_miss);
    CHECK(std::isinf(buf.distance[i]));
    CHECK(buf.radiance_at(i).y == 2.0f);
    CHECK(r.seen_triangle(i) == hemicube_rasterizer::no_triangle);
  }
}

TEST_CASE("raster: perspective-correct UVs on a textured quad at a grazing angle", "[raster]") {
  // A long ceiling strip 0.2 above the point, seen at grazing angles far away. The texture's R
  // and G are the continuous texel coordinates x, y: bilinear filtering reproduces a linear
  // function exactly, so the radiance read back is the UV the rasterizer computed, and can be
  // compared with the ray caster's UV. Affine (screen-space) interpolation would be off by
  // many texels here.
  scene_mesh m;
  const material mat{glm::vec3(0.0f), glm::vec3(0.5f), false};
  m.add_quad({-1, 0.5f, 0.2f}, {-1, 20, 0.2f}, {1, 20, 0.2f}, {1, 0.5f, 0.2f}, mat);  // faces down (-z)
  m.lightmap_uvs = {{0, 0}, {0, 1}, {1, 0}, {1, 1}};  // add_quad's vertex order: a, b, d, c
  const int w = 32, h = 64;
  image tex = image::make(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      tex.at(x, y)[0] = static_cast<float>(x);
      tex.at(x, y)[1] = static_cast<float>(y);
    }
  const auto s = scene::create(m.desc());
  hemicube_rasterizer r(s);
  hemicube_buffer buf;
  const frame identity{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const radiance_texture view(tex);
  const int n = 64;
  r.render({0, 0, 0}, identity, n, buf, &view);
  std::size_t checked = 0, grazing = 0;
  double worst = 0;
  for (std::size_t i = 0; i < buf.texel_count(); ++i) {
    const glm::dvec3 d(hemicube_texel_direction(n, i));
    const ray_result ref = cast_ray(m, {0, 0, 0}, d, glm::dvec3(hemicube_axes(hemicube_texel_from_index(n, i).face).forward),
                                    r.near_distance(), 0.02 * 2.0 / n / std::sqrt(3.0));
    if (ref.ambiguous || ref.triangle < 0) continue;
    ++checked;
    if (d.z < 0.1) ++grazing;
    // Expected continuous texel coordinates, clamped like clamp-to-edge filtering.
    const double ex = std::clamp(ref.uv.x * w - 0.5, 0.0, w - 1.0), ey = std::clamp(ref.uv.y * h - 0.5, 0.0, h - 1.0);
    worst = std::max({worst, std::fabs(buf.radiance_at(i).x - ex), std::fabs(buf.radiance_at(i).y - ey)});
  }
  INFO("checked " << checked << " texels (" << grazing << " at cos < 0.1), worst error " << worst << " texels");
  CHECK(grazing > 20);
  // 0.01 texel: float barycentrics at cos ~ 0.01 lose ~1e-5 of the quad's 64 texels.
  CHECK(worst < 0.01);
}

TEST_CASE("raster: bad arguments give clear errors and leave the buffer untouched", "[raster]") {
  const auto s = scene::create(cornell_box().desc());
  hemicube_rasterizer r(s);
  hemicube_buffer buf;
  const frame identity{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const auto fails_with = [&](const glm::vec3& p, const frame& f, int n, const radiance_texture* tex, const char* text) {
    try {
      r.render(p, f, n, buf, tex);
      FAIL("no error for " << text);
    } catch (const error& e) {
      CHECK(e.code() == status::invalid_argument);
      CHECK_THAT(e.what(), Catch::Contains(text));
    }
    CHECK(buf.resolution == 0);
  };
  fails_with({std::nanf(""), 0, 0}, identity, 16, nullptr, "position.x is nan");
  fails_with({0, std::numeric_limits<float>::infinity(), 0}, identity, 16, nullptr, "position.y is inf");
  fails_with({0, 0, 0}, frame{{1, 0, 0}, {0, 1, 0}, {0, 0, 1.1f}}, 16, nullptr, "basis.n has length");
  fails_with({0, 0, 0}, frame{{1, 0, 0}, {0.1f, 0.995f, 0}, {0, 0, 1}}, 16, nullptr, "basis t . b");
  fails_with({0, 0, 0}, frame{{0, 1, 0}, {1, 0, 0}, {0, 0, 1}}, 16, nullptr, "left-handed");
  fails_with({0, 0, 0}, identity, 15, nullptr, "resolution 15");
  fails_with({0, 0, 0}, identity, 0, nullptr, "resolution 0");
  const radiance_texture no_pixels;
  fails_with({0, 0, 0}, identity, 16, &no_pixels, "pixels is null");
  const float px[3] = {0, 0, 0};
  const radiance_texture two_channels(px, 1, 1, 2);
  fails_with({0, 0, 0}, identity, 16, &two_channels, "channels is 2");
  CHECK_THROWS_WITH(hemicube_rasterizer(nullptr), Catch::Contains("scene is null"));
  CHECK_THROWS_WITH(hemicube_rasterizer(s, raster_options{-1.0f}), Catch::Contains("near_distance is -1"));
  CHECK_THROWS_WITH(hemicube_rasterizer(s, raster_options{std::nanf("")}), Catch::Contains("near_distance is nan"));
  // The default near distance is 1e-4 of the scene's diagonal.
  CHECK(r.near_distance() == Approx(1e-4 * std::sqrt(0.556 * 0.556 + 0.5488 * 0.5488 + 0.5592 * 0.5592)).epsilon(1e-5));
}

TEST_CASE("raster: rasterizers on several threads share one scene and agree with one thread", "[raster]") {
  const auto s = scene::create(hexagon_room(2).desc());
  std::mt19937 rng(17);
  std::vector<glm::vec3> points(16);
  std::vector<frame> frames(16);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  for (std::size_t i = 0; i < points.size(); ++i) {
    points[i] = {u(rng), 1.5f + 0.5f * u(rng), u(rng)};
    frames[i] = random_frame(rng);
  }
  std::vector<hemicube_buffer> serial(points.size()), threaded(points.size());
  hemicube_rasterizer one(s);
  for (std::size_t i = 0; i < points.size(); ++i) one.render(points[i], frames[i], 16, serial[i]);
  std::vector<hemicube_rasterizer> per_worker(static_cast<std::size_t>(resolve_thread_count(2)), hemicube_rasterizer(s));
  parallel_for(points.size(), 2, 1, [&](int worker, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      per_worker[static_cast<std::size_t>(worker)].render(points[i], frames[i], 16, threaded[i]);
  });
  for (std::size_t i = 0; i < points.size(); ++i) {
    CHECK(serial[i].radiance == threaded[i].radiance);
    CHECK(serial[i].distance == threaded[i].distance);
    CHECK(serial[i].flags == threaded[i].flags);
  }
}

TEST_CASE("raster: bind() to another scene renders bitwise as a new rasterizer; unbind() drops the scene", "[raster]") {
  const auto room = scene::create(hexagon_room(2).desc());
  const auto box = scene::create(cornell_box().desc());
  const glm::vec3 p_room{0.3f, 1.2f, -0.4f}, p_box{0.28f, 0.1f, 0.25f};
  std::mt19937 rng(5);
  const frame f = random_frame(rng);
  hemicube_buffer fresh_room, fresh_box, reused;
  hemicube_rasterizer(room).render(p_room, f, 32, fresh_room);
  hemicube_rasterizer(box).render(p_box, f, 32, fresh_box);
  // Renders at another N in between, so the reused one's tables and scratch have been resized.
  hemicube_rasterizer r(room);
  r.render(p_room, f, 16, reused);
  r.bind(box);
  r.render(p_box, f, 32, reused);
  CHECK(reused.radiance == fresh_box.radiance);
  CHECK(reused.distance == fresh_box.distance);
  CHECK(reused.flags == fresh_box.flags);
  r.bind(room);
  r.render(p_room, f, 32, reused);
  CHECK(reused.radiance == fresh_room.radiance);
  CHECK(reused.flags == fresh_room.flags);
  // The scene is no longer held after unbind(); render() then fails with a clear error.
  std::weak_ptr<const scene> held = box;
  {
    hemicube_rasterizer only(scene::create(cornell_box().desc()));
    held = only.scene_ptr();
    only.unbind();
    CHECK(held.expired());
    CHECK_THROWS_WITH(only.render(p_box, f, 16, reused), Catch::Contains("no scene"));
  }
  // A failed bind changes nothing.
  CHECK_THROWS_WITH(r.bind(nullptr), Catch::Contains("scene is null"));
  CHECK_THROWS_WITH(r.bind(box, raster_options{-1.0f}), Catch::Contains("near_distance is -1"));
  CHECK(r.scene_ptr() == room);
  r.render(p_room, f, 32, reused);
  CHECK(reused.radiance == fresh_room.radiance);
}

TEST_CASE("raster: a copy renders bitwise as its original; a moved-from rasterizer fails until bound", "[raster]") {
  const auto room = scene::create(hexagon_room(2).desc());
  const glm::vec3 p{0.3f, 1.2f, -0.4f};
  std::mt19937 rng(9);
  const frame f = random_frame(rng);
  // The reference: a fresh rasterizer (bitwise equality: the same code on the same inputs).
  hemicube_buffer fresh, copied, moved, revived;
  hemicube_rasterizer(room).render(p, f, 32, fresh);
  hemicube_rasterizer original(room);
  original.render(p, f, 16, copied);  // scratch sized for another N, copied with the state
  hemicube_rasterizer copy(original);
  copy.render(p, f, 32, copied);
  CHECK(copied.radiance == fresh.radiance);
  CHECK(copied.distance == fresh.distance);
  CHECK(copied.flags == fresh.flags);
  hemicube_rasterizer reference(room);
  hemicube_buffer again;
  reference.render(p, f, 32, again);
  std::size_t same_triangle = 0;
  for (std::size_t i = 0; i < hemicube_texel_count(32); ++i)
    same_triangle += copy.seen_triangle(i) == reference.seen_triangle(i) ? 1u : 0u;
  CHECK(same_triangle == hemicube_texel_count(32));
  hemicube_rasterizer target(std::move(original));
  target.render(p, f, 32, moved);
  CHECK(moved.radiance == fresh.radiance);
  CHECK(moved.flags == fresh.flags);
  // The moved-from one holds nothing: no scene, and render() fails with a clear error.
  CHECK(original.scene_ptr() == nullptr);  // NOLINT(bugprone-use-after-move): the documented state
  CHECK(original.near_distance() == 0.0f);
  CHECK_THROWS_WITH(original.render(p, f, 32, revived), Catch::Contains("moved from"));
  std::vector<std::uint32_t> counts;
  CHECK_THROWS_WITH(original.render_coverage(p, f, 32, counts), Catch::Contains("moved from"));
  // bind() gives it a scene again; it then renders as a new rasterizer.
  original.bind(room);
  original.render(p, f, 32, revived);
  CHECK(revived.radiance == fresh.radiance);
  CHECK(revived.distance == fresh.distance);
  // Assignments: copy and move.
  hemicube_rasterizer assigned(scene::create(cornell_box().desc()));
  assigned = copy;
  assigned.render(p, f, 32, revived);
  CHECK(revived.radiance == fresh.radiance);
  assigned = std::move(copy);
  assigned.render(p, f, 32, revived);
  CHECK(revived.radiance == fresh.radiance);
}

TEST_CASE("hemicube cross: every texel has its own pixel and the EXR files round-trip", "[raster]") {
  for (int n : {2, 8}) {
    std::set<std::pair<int, int>> used;
    for (std::size_t i = 0; i < hemicube_texel_count(n); ++i) {
      const glm::ivec2 p = hemicube_cross_pixel(n, hemicube_texel_from_index(n, i));
      REQUIRE((p.x >= 0 && p.x < 2 * n && p.y >= 0 && p.y < 2 * n));
      REQUIRE(used.insert({p.x, p.y}).second);
    }
  }
  // Top face texel (0, 0) (towards -x, -y) is at the picture's lower left of the centre square;
  // +x side face is to the right of the top face.
  CHECK(hemicube_cross_pixel(8, {hemicube_face::top, 0, 0}) == glm::ivec2(4, 11));
  CHECK(hemicube_cross_pixel(8, {hemicube_face::pos_x, 0, 0}).x == 12);

  const auto s = scene::create(cornell_box().desc());
  hemicube_rasterizer r(s);
  hemicube_buffer buf;
  r.render({0.3f, 0.25f, 0.05f}, rolled_frame({0, 0, 1}, 0.0), 8, buf);
  const std::string prefix = std::string(HEMILIGHT_TEST_TMPDIR) + "/cross";
  write_hemicube_exr(prefix, buf);
  const image rad = read_exr(prefix + "_radiance.exr"), dist = read_exr(prefix + "_distance.exr"),
              flags = read_exr(prefix + "_flags.exr");
  REQUIRE((rad.width == 16 && rad.height == 16));
  for (std::size_t i = 0; i < buf.texel_count(); ++i) {
    const glm::ivec2 p = hemicube_cross_pixel(8, hemicube_texel_from_index(8, i));
    CHECK(rad.at(p.x, p.y)[1] == buf.radiance_at(i).y);
    CHECK(dist.at(p.x, p.y)[0] == (std::isinf(buf.distance[i]) ? 0.0f : buf.distance[i]));
    CHECK(flags.at(p.x, p.y)[0] == ((buf.flags[i] & texel_miss) ? 1.0f : 0.0f));
    CHECK(flags.at(p.x, p.y)[2] == 1.0f);
  }
  CHECK(flags.at(0, 0)[2] == 0.0f);  // a corner outside the cross
  hemicube_buffer bad;
  CHECK_THROWS_AS(write_hemicube_exr(prefix, bad), error);
}

TEST_CASE("raster: the SIMD paths (AVX-512 and AVX2 where the CPU has them, SSE2) give bit-identical buffers to the scalar reference", "[raster]") {
  std::mt19937 rng(23);
  const scene_mesh scenes[] = {cornell_box(), hexagon_room(2), sky_and_occluders(), heightfield(3000),
                               fan_box(rng, {-1, -1, -1}, {1, 1, 1})};
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  for (const scene_mesh& m : scenes) {
    const auto s = scene::create(m.desc());
    raster_options scalar, sse2, avx2;
    scalar.diagnostics.simd = false;
    sse2.diagnostics.avx2 = false;     // the SSE2 kernels even on an AVX2 machine
    avx2.diagnostics.avx512 = false;   // the AVX2 build of the set-up even on an AVX-512 machine
    hemicube_rasterizer best(s), sse2_only(s, sse2), reference(s, scalar), avx2_only(s, avx2);
    hemicube_buffer a, b, c, e;
    std::vector<std::uint32_t> ca, cb, cc, ce;
    for (int k = 0; k < 7; ++k) {
      const glm::vec3 p = 0.5f * (s->bounds_lo() + s->bounds_hi()) + glm::vec3(u(rng), u(rng), u(rng)) * 0.2f * s->size();
      const frame f = random_frame(rng);
      // 30: spans whose length is not a multiple of 4 or 8; 256: triangles over 64 texels across
      // next to small ones (the AVX2 box scan's limit).
      const int n = k == 6 ? 256 : (k % 2 ? 30 : 64);
      best.render(p, f, n, a);
      sse2_only.render(p, f, n, b);
      reference.render(p, f, n, c);
      avx2_only.render(p, f, n, e);
      // Bitwise: compare the bytes (so NaN or -0 differences would show).
      CHECK(std::memcmp(a.distance.data(), c.distance.data(), a.distance.size() * sizeof(float)) == 0);
      CHECK(std::memcmp(a.radiance.data(), c.radiance.data(), a.radiance.size() * sizeof(float)) == 0);
      CHECK(a.flags == c.flags);
      CHECK(std::memcmp(b.distance.data(), c.distance.data(), b.distance.size() * sizeof(float)) == 0);
      CHECK(std::memcmp(b.radiance.data(), c.radiance.data(), b.radiance.size() * sizeof(float)) == 0);
      CHECK(b.flags == c.flags);
      CHECK(std::memcmp(e.distance.data(), c.distance.data(), e.distance.size() * sizeof(float)) == 0);
      CHECK(std::memcmp(e.radiance.data(), c.radiance.data(), e.radiance.size() * sizeof(float)) == 0);
      CHECK(e.flags == c.flags);
      std::size_t same_triangle = 0;
      for (std::size_t i = 0; i < a.texel_count(); ++i)
        same_triangle += best.seen_triangle(i) == reference.seen_triangle(i) ? 1u : 0u;
      CHECK(same_triangle == a.texel_count());
      // The coverage counts (the SIMD small-triangle kernels have a counting mode).
      // A rasterizer that rendered before gives what a fresh one gives (the resolve clears the
      // depths it reads for the next render).
      hemicube_rasterizer fresh(s, scalar);
      hemicube_buffer d;
      fresh.render(p, f, n, d);
      CHECK(std::memcmp(d.distance.data(), c.distance.data(), d.distance.size() * sizeof(float)) == 0);
      CHECK(d.flags == c.flags);
      best.render_coverage(p, f, n, ca);
      sse2_only.render_coverage(p, f, n, cb);
      reference.render_coverage(p, f, n, cc);
      avx2_only.render_coverage(p, f, n, ce);
      CHECK(ca == cc);
      CHECK(cb == cc);
      CHECK(ce == cc);
    }
  }
}

TEST_CASE("raster: culling of small far nodes between texel centres changes no texel", "[raster]") {
  // A fine heightfield seen at N = 16 from just above it: most BVH leaves far away are smaller
  // than a texel and many fall between texel centres. The ray caster sees every triangle, so any
  // texel lost to over-eager culling would show as a mismatch.
  // Near the horizon the texels look at many tiny triangles, one of whose edges is usually
  // within 2% of a texel: those texels are ambiguous, so only 30% of the hemicube (the sky and
  // the nearer ground) is required to be checked here.
  const scene_mesh m = heightfield(12000);
  const glm::vec3 p(0.3f, 0.4f, -0.2f);
  const frame f = rolled_frame({0.05, 1, 0.02}, 0.4);
  compare_with_ray_caster(m, p, f, 16, 0.0f, 0.3);
  const auto s = scene::create(m.desc());
  hemicube_rasterizer r(s);
  hemicube_buffer buf;
  r.render(p, f, 16, buf);
  std::size_t above = 0;  // triangles with a vertex above the tangent plane (counted here)
  for (std::size_t i = 0; i < m.triangle_count(); ++i) {
    bool up = false;
    for (int k = 0; k < 3; ++k) up = up || glm::dot(m.positions[m.indices[3 * i + static_cast<std::size_t>(k)]] - p, f.n) > 0;
    above += up;
  }
  INFO("triangles above the tangent plane " << above << ", tested " << r.statistics().triangles_tested);
  // The cost follows the visible part, not the scene. (BVH leaves hold up to 32 triangles: the
  // AVX2 set-up tests eight at a time for less than one node visit costs, so leaves are coarse
  // and far leaves are bigger than the between-centres test's few texels; the tested triangles
  // are bounded by a small multiple of those above the plane. With leaves of 8 this was 0.8x,
  // at 1.5x the instructions per hemicube on this heightfield at N = 16: docs/raster.md.)
  CHECK(r.statistics().triangles_tested < above * 5 / 2);
  CHECK(r.statistics().triangles_tested < m.triangle_count() / 5);
}

TEST_CASE("raster: edges through texel centres (exact ties) give the same coverage on every path", "[raster]") {
  // A plane z = 1 seen straight up at N = 256: a vertex at u = (2k + 1) / N - 1 projects exactly
  // onto the centre of texel column k (every step is exact in float and in the fixed point), so
  // the grid's edges and the cells' diagonals pass through texel centres: every tie of the
  // top-left rule is exercised. Cells of 37 texels go through the small-triangle kernels, cells of
  // 100 texels through the big-triangle ones. The mesh covers the whole top face, so each of its
  // texels must be covered exactly once, and every path must agree with the scalar reference.
  const int n = 256;
  for (const int cell : {37, 100}) {
    scene_mesh m;
    const material grey{{0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}, false};  // emission, albedo
    const auto at = [&](int k) { return static_cast<float>(2 * k + 1) / static_cast<float>(n) - 1.0f; };
    const int first = -2 * cell, last = n + 2 * cell;
    for (int j = first; j < last; j += cell)
      for (int i = first; i < last; i += cell) {
        const glm::vec3 a(at(i), at(j), 1.0f), b(at(i + cell), at(j), 1.0f), c(at(i + cell), at(j + cell), 1.0f),
            d(at(i), at(j + cell), 1.0f);
        // Facing down (towards the point); the diagonal alternates between the cells.
        if (((i - first) / cell + (j - first) / cell) % 2)
          m.add_quad(a, d, c, b, grey);
        else
          m.add_quad(b, a, d, c, grey);
      }
    const auto s = scene::create(m.desc());
    raster_options scalar, sse2, avx2;
    scalar.diagnostics.simd = false;
    sse2.diagnostics.avx2 = false;
    avx2.diagnostics.avx512 = false;
    hemicube_rasterizer best(s), sse2_only(s, sse2), reference(s, scalar), avx2_only(s, avx2);
    const frame f{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    std::vector<std::uint32_t> ca, cb, cc, ce;
    best.render_coverage({0, 0, 0}, f, n, ca);
    sse2_only.render_coverage({0, 0, 0}, f, n, cb);
    reference.render_coverage({0, 0, 0}, f, n, cc);
    avx2_only.render_coverage({0, 0, 0}, f, n, ce);
    INFO("cell " << cell);
    CHECK(ca == cc);
    CHECK(cb == cc);
    CHECK(ce == cc);
    std::size_t once = 0;
    for (std::size_t i = 0; i < static_cast<std::size_t>(n) * n; ++i) once += cc[i] == 1 ? 1u : 0u;  // top face first
    CHECK(once == static_cast<std::size_t>(n) * n);
    hemicube_buffer a, c, e;
    best.render({0, 0, 0}, f, n, a);
    reference.render({0, 0, 0}, f, n, c);
    avx2_only.render({0, 0, 0}, f, n, e);
    CHECK(std::memcmp(a.distance.data(), c.distance.data(), a.distance.size() * sizeof(float)) == 0);
    CHECK(std::memcmp(e.distance.data(), c.distance.data(), e.distance.size() * sizeof(float)) == 0);
    std::size_t same_triangle = 0;
    for (std::size_t i = 0; i < a.texel_count(); ++i) same_triangle += best.seen_triangle(i) == reference.seen_triangle(i);
    CHECK(same_triangle == a.texel_count());
  }
}

// ---- exact edge coverage (raster_options::edge_coverage) ----------------------------------------

namespace {

// Lambert's formula, written here: the projected solid angle (the irradiance under radiance 1)
// of the convex polygon `poly` (relative to the point) after clipping it to z >= 0.
double lambert_polygon(const std::vector<glm::dvec3>& poly) {
  std::vector<glm::dvec3> clipped;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec3 &a = poly[i], &b = poly[(i + 1) % poly.size()];
    if (a.z >= 0) clipped.push_back(a);
    if ((a.z >= 0) != (b.z >= 0)) clipped.push_back(a + (a.z / (a.z - b.z)) * (b - a));
  }
  double sum = 0;
  for (std::size_t i = 0; i < clipped.size(); ++i) {
    const glm::dvec3 u = glm::normalize(clipped[i]), v = glm::normalize(clipped[(i + 1) % clipped.size()]);
    const glm::dvec3 g = glm::cross(u, v);
    const double len = glm::length(g);
    if (len > 0) sum += std::atan2(len, glm::dot(u, v)) * g.z / len;
  }
  return 0.5 * std::fabs(sum);
}

// E of a two-sided polygon of radiance 1 under a black sky, seen from the origin with normal +z.
double rendered_irradiance(const std::vector<glm::dvec3>& poly, int n, bool edge) {
  scene_mesh m;
  const material emitter{glm::vec3(1.0f), glm::vec3(0.0f), true};
  for (std::size_t k = 1; k + 1 < poly.size(); ++k)
    m.add_triangle(glm::vec3(poly[0]), glm::vec3(poly[k]), glm::vec3(poly[k + 1]), emitter);
  raster_options o;
  o.edge_coverage = edge;
  hemicube_rasterizer r(scene::create(m.desc()), o);
  hemicube_buffer buf;
  r.render({0, 0, 0}, frame{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, n, buf);
  return integrate(buf).irradiance.x;
}

}  // namespace

TEST_CASE("raster: exact edge coverage gives polygons' irradiance to Lambert's formula", "[raster]") {
  // The rectangle of docs/raster.md's edge-coverage figures: [-0.5, 0.5] x [0.3, 0.9] at z = 1,
  // seen from (0.05, -0.02, 0). Point sampling is off by -17.6% at N = 16 and +2.1% at N = 128
  // (the sign and size depend on where the edges fall); with exact coverage only the texel
  // weights' linearisation within partial texels (second order) and float sums remain: measured
  // <= 2e-5 for every N >= 16, asserted 1e-4.
  const glm::dvec3 eye(0.05, -0.02, 0.0);
  const std::vector<glm::dvec3> rect = {glm::dvec3(-0.5, 0.3, 1) - eye, glm::dvec3(0.5, 0.3, 1) - eye,
                                        glm::dvec3(0.5, 0.9, 1) - eye, glm::dvec3(-0.5, 0.9, 1) - eye};
  const double ref = lambert_polygon(rect);
  CHECK(std::fabs(ref - 0.285808) < 1e-6);  // its E to six digits (checks the formula here)
  for (const int n : {16, 32, 48, 64, 128, 256}) {
    INFO("N = " << n);
    CHECK(std::fabs(rendered_irradiance(rect, n, true) - ref) <= 1e-4 * ref);
  }
  CHECK(std::fabs(rendered_irradiance(rect, 16, false) - ref) > 0.1 * ref);  // what the option fixes

  // Random triangles and rotated, tilted rectangles anywhere above the horizon, thin slivers,
  // and walls crossing the horizon: at N = 64 the sweep (benchmarks/sweep_edge.cpp) measures
  // <= 0.005% over its families; asserted 0.05% here (point sampling: 0.4% to 60%).
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.0, 1.0);
  double worst = 0;
  for (int k = 0; k < 24; ++k) {
    std::vector<glm::dvec3> poly;
    const double h = 0.6 + 0.8 * pos(rng);
    if (k % 4 == 0) {
      for (int i = 0; i < 3; ++i) poly.push_back({h * u(rng), h * u(rng), h * (1 + 0.3 * u(rng))});
    } else if (k % 4 == 1) {
      const double a = 3.14159 * pos(rng), tilt = 0.6 * u(rng);
      const glm::dvec3 du(std::cos(a), std::sin(a), 0), dv(-std::sin(a) * std::cos(tilt), std::cos(a) * std::cos(tilt), std::sin(tilt));
      const glm::dvec3 c(0.8 * h * u(rng), 0.8 * h * u(rng), h);
      const glm::dvec3 su = (0.05 + 0.3 * pos(rng)) * du, sv = (0.05 + 0.3 * pos(rng)) * dv;
      poly = {c - su - sv, c + su - sv, c + su + sv, c - su + sv};
    } else if (k % 4 == 2) {
      const double a = 3.14159 * pos(rng), len = 0.3 + 0.5 * pos(rng), w = 0.005 + 0.02 * pos(rng);
      const glm::dvec3 d(std::cos(a), std::sin(a), 0), side(-std::sin(a), std::cos(a), 0), c(0.6 * h * u(rng), 0.6 * h * u(rng), h);
      poly = {c - 0.5 * len * d - w * side, c - 0.5 * len * d + w * side, c + 0.5 * len * d};
    } else {
      const double a = 6.28318 * pos(rng), d = 0.5 + pos(rng), z0 = -0.05 - 0.3 * pos(rng), z1 = 0.1 + 0.8 * pos(rng);
      const glm::dvec3 toward(std::cos(a), std::sin(a), 0), side(-std::sin(a), std::cos(a), 0), c = d * toward;
      const double w = 0.1 + 0.5 * pos(rng);
      poly = {c - w * side + glm::dvec3(0, 0, z0), c + w * side + glm::dvec3(0, 0, z0), c + w * side + glm::dvec3(0, 0, z1),
              c - w * side + glm::dvec3(0, 0, z1)};
    }
    const double want = lambert_polygon(poly);
    worst = std::max(worst, std::fabs(rendered_irradiance(poly, 64, true) - want) / want);
  }
  INFO("worst relative error at N = 64: " << worst);
  CHECK(worst <= 5e-4);
}

TEST_CASE("raster: with exact edge coverage, triangles sharing edges sum to one on every texel of a closed mesh", "[raster]") {
  // Closed meshes around the point (irregular spheres and fan boxes, whose fans put several
  // vertices and many edges inside single texels), one emission everywhere and a bright sky:
  // every texel is covered by the mesh, in part by several triangles whose coverages must sum
  // to one, so every texel's radiance is the emission. A gap would let the sky (radiance 2, one
  // more than the emission's blue) in; an overlap is capped by the front-to-back rule. 4e-6
  // relative: each coverage is a float (6e-8) from a double area (1e-15), up to a few dozen per
  // texel, and the blend sums in float; a gap of 4e-6 of a texel's weight would show.
  std::mt19937 rng(31);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  raster_options o;
  o.edge_coverage = true;
  for (int mesh = 0; mesh < 4; ++mesh) {
    const bool sphere = mesh % 2 == 0;
    scene_mesh m = sphere ? irregular_sphere(rng) : fan_box(rng, {-0.7f, -1.1f, -0.9f}, {1.3f, 0.8f, 1.0f});
    // Two-sided: where an irregular sphere folds, a triangle may be seen from behind past a
    // nearer one (a non-convex mesh); only gaps are to be measured here.
    for (material& mat : m.materials) {
      mat.emission = glm::vec3(0.25f, 0.5f, 1.0f);
      mat.two_sided = true;
    }
    m.sky_radiance = glm::vec3(2.0f);
    hemicube_rasterizer r(scene::create(m.desc()), o);
    hemicube_buffer buf;
    for (int k = 0; k < 6; ++k) {
      glm::vec3 p(u(rng), u(rng), u(rng));
      p *= 0.55f / std::max(1.0f, glm::length(p));
      const int n = k % 3 == 0 ? 64 : (k % 3 == 1 ? 16 : 6);
      r.render(p, random_frame(rng), n, buf);
      double worst = 0;
      std::size_t at = 0;
      for (std::size_t i = 0; i < buf.texel_count(); ++i) {
        const glm::vec3 l = buf.radiance_at(i);
        const double e = std::max({std::fabs(l.x / 0.25 - 1.0), std::fabs(l.y / 0.5 - 1.0), std::fabs(l.z - 1.0)});
        if (e > worst) {
          worst = e;
          at = i;
        }
      }
      const hemicube_texel t = hemicube_texel_from_index(n, at);
      INFO("mesh " << mesh << " (" << (sphere ? "sphere" : "box") << "), N = " << n << "; worst texel: face "
                   << static_cast<int>(t.face) << " (" << t.x << ", " << t.y << "), blue " << buf.radiance_at(at).z);
      CHECK(worst <= 4e-6);
    }
  }
  // A grid of quads at z = 1 whose edges pass exactly through texel centres and texel corners
  // (N = 256, cells of 37 texels; see the exact-ties test above): the top face sums to one.
  const int n = 256, cell = 37;
  scene_mesh g;
  // Neighbouring quads differ in albedo (not seen: the emission is the same), so every edge
  // between quads is hard and its texels are covered exactly, in parts; the quads' diagonals
  // are not (point sampled).
  const material grey{{0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}, false}, grey2{{0.5f, 0.5f, 0.5f}, {0.25f, 0.25f, 0.25f}, false};
  const auto at = [&](int k) { return static_cast<float>(k) / static_cast<float>(n) - 1.0f; };  // half-texel grid
  for (int j = -2 * cell; j < 2 * n + 2 * cell; j += cell)
    for (int i = -2 * cell; i < 2 * n + 2 * cell; i += cell)
      g.add_quad({at(i), at(j), 1}, {at(i), at(j + cell), 1}, {at(i + cell), at(j + cell), 1}, {at(i + cell), at(j), 1},
                 ((i + j) / cell) % 2 ? grey : grey2);
  g.sky_radiance = glm::vec3(2.0f);
  hemicube_rasterizer r(scene::create(g.desc()), o);
  hemicube_buffer buf;
  r.render({0, 0, 0}, frame{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, n, buf);
  CHECK(r.statistics().edge_fragments > 10000);  // the quads' edges: about 2 x 2 x 256 x 256 / 37 texels
  double worst = 0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(n) * n; ++i) worst = std::max(worst, std::fabs(buf.radiance_at(i).x / 0.5 - 1.0));
  CHECK(worst <= 4e-6);
}

TEST_CASE("raster: exact edge coverage of triangles smaller than a texel sums to one and gives Lambert's formula", "[raster]") {
  // A rectangle at z = 1 cut into cells of 0.23 texels at N = 64 (two triangles each; the cells'
  // albedos alternate, so every edge is hard and every texel under the rectangle is covered in
  // parts): most triangles lie within one texel (their covered weight is their area times the
  // density at the centroid, with no clipping), the others are cut by one, two or three texel
  // lines (the clipping paths). Under a sky of 2 and an emission of 1, a texel inside the
  // rectangle is 1 only if its parts sum to one (4e-6 as in the closed-mesh test: float
  // coverages and sums, dozens of parts a texel); under a black sky, E is Lambert's formula for
  // the rectangle (1e-4 as for the single rectangle of the Lambert's-formula test above: the
  // density's linearisation within partial texels, measured 1e-5).
  const int n = 64;
  const double texel = 2.0 / n, cell = 0.23 * texel;
  const double x0 = -0.31, y0 = 0.07;
  const int cols = 90, rows = 70;  // about 21 x 16 texels
  scene_mesh m;
  const material a{glm::vec3(1.0f), glm::vec3(0.5f), true}, b{glm::vec3(1.0f), glm::vec3(0.25f), true};
  const auto at = [&](int i, int j) { return glm::vec3(float(x0 + i * cell), float(y0 + j * cell), 1.0f); };
  // Triangles within one texel, by their vertices' texel coordinates on the top face (counted
  // here from the geometry, so the test knows that path is exercised).
  const auto texel_of = [&](const glm::vec3& v) { return std::make_pair(int(std::floor((v.x + 1.0) / texel)), int(std::floor((v.y + 1.0) / texel))); };
  int within_one = 0;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i) {
      const glm::vec3 p00 = at(i, j), p10 = at(i + 1, j), p11 = at(i + 1, j + 1), p01 = at(i, j + 1);
      const material& mat = (i + j) % 2 ? a : b;
      m.add_triangle(p00, p10, p11, mat);
      m.add_triangle(p00, p11, p01, mat);
      within_one += texel_of(p00) == texel_of(p10) && texel_of(p10) == texel_of(p11) ? 1 : 0;
      within_one += texel_of(p00) == texel_of(p11) && texel_of(p11) == texel_of(p01) ? 1 : 0;
    }
  CHECK(within_one > cols * rows);  // more than half of the 2 x 90 x 70 triangles
  raster_options o;
  o.edge_coverage = true;
  const frame up{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  hemicube_buffer buf;
  {
    scene_mesh lit = m;
    lit.sky_radiance = glm::vec3(2.0f);
    hemicube_rasterizer r(scene::create(lit.desc()), o);
    r.render({0, 0, 0}, up, n, buf);
    CHECK(r.statistics().edge_fragments > 10000);
    double worst = 0;
    int inside = 0;
    for (int ty = 0; ty < n; ++ty)
      for (int tx = 0; tx < n; ++tx) {
        // Texels whose square lies inside the rectangle (a cell's margin: float vertices).
        const double u0 = -1.0 + tx * texel, v0 = -1.0 + ty * texel;
        if (u0 < x0 + cell || u0 + texel > x0 + cols * cell - cell || v0 < y0 + cell || v0 + texel > y0 + rows * cell - cell) continue;
        ++inside;
        worst = std::max(worst, std::fabs(double(buf.radiance_at(static_cast<std::size_t>(ty * n + tx)).x) - 1.0));
      }
    INFO("texels inside the rectangle: " << inside);
    CHECK(inside > 200);
    CHECK(worst <= 4e-6);
  }
  hemicube_rasterizer r(scene::create(m.desc()), o);
  r.render({0, 0, 0}, up, n, buf);
  const double x1 = double(float(x0 + cols * cell)), y1 = double(float(y0 + rows * cell));
  const double want = lambert_polygon({{double(float(x0)), double(float(y0)), 1.0}, {x1, double(float(y0)), 1.0}, {x1, y1, 1.0}, {double(float(x0)), y1, 1.0}});
  CHECK(std::fabs(integrate(buf).irradiance.x - want) <= 1e-4 * want);
}

TEST_CASE("raster: exact edge coverage leaves a closed room of one material as point sampling gives it, bit for bit", "[raster]") {
  // Seen from inside a closed, consistently wound mesh of one material, no edge is hard (no
  // boundary, no silhouette, no change of material): exact coverage has nothing to correct,
  // and the render is the centre samples' (docs/raster.md, "Hard edges"). Irregular fan boxes
  // put many vertices and edges inside texels.
  std::mt19937 rng(41);
  std::uniform_real_distribution<float> u(-0.4f, 0.4f);
  for (int k = 0; k < 4; ++k) {
    const auto s = scene::create(fan_box(rng, {-1.0f, -0.8f, -1.2f}, {1.1f, 0.9f, 0.7f}).desc());
    raster_options on;
    on.edge_coverage = true;
    hemicube_rasterizer point(s), edge(s, on);
    hemicube_buffer a, b;
    const glm::vec3 p(u(rng), u(rng), u(rng));
    const frame f = random_frame(rng);
    const int n = k % 2 ? 64 : 30;
    point.render(p, f, n, a);
    edge.render(p, f, n, b);
    INFO("box " << k << ", N = " << n);
    CHECK(edge.statistics().edge_hard_edges == 0);
    CHECK(edge.statistics().edge_fragments == 0);
    CHECK(std::memcmp(a.radiance.data(), b.radiance.data(), a.radiance.size() * sizeof(float)) == 0);
    CHECK(std::memcmp(a.distance.data(), b.distance.data(), a.distance.size() * sizeof(float)) == 0);
    CHECK(a.flags == b.flags);
  }
}

TEST_CASE("raster: exact edge coverage finds silhouettes and material changes of welded meshes", "[raster]") {
  // A closed box seen from outside (welded: its edges are shared) emits radiance 1 under a black
  // sky: its silhouette runs along creases between faces that face the point and faces that do
  // not, which must be found hard. Lambert's formula over the faces that face the point gives
  // the irradiance (the box is convex: they do not overlap). Exact coverage: what remains is the
  // linearisation of the texel weight within partial texels (second order in the texel size;
  // this box is near and large: 5e-4 measured at N = 16, 4e-5 at N = 64, and the same bits as
  // with every edge made hard), asserted 1e-3 and 1e-4; point sampling is off by 3% at N = 16.
  std::mt19937 rng(43);
  const glm::vec3 lo(0.2f, -0.3f, 0.3f), hi(1.0f, 0.4f, 1.1f);
  scene_mesh box = fan_box(rng, lo, hi, true);
  for (material& m : box.materials) m.emission = glm::vec3(1.0f);
  const auto s = scene::create(box.desc());
  const auto face = [&](int axis, bool upper) {
    std::vector<glm::dvec3> q;
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (int k = 0; k < 4; ++k) {
      glm::dvec3 v;
      v[axis] = upper ? hi[axis] : lo[axis];
      v[a] = (k == 1 || k == 2) ? hi[a] : lo[a];
      v[b] = (k >= 2) ? hi[b] : lo[b];
      q.push_back(v);
    }
    return q;
  };
  // Facing the origin: the bottom (z = 0.3) and the -x face (x = 0.2); the others face away.
  const double want = lambert_polygon(face(2, false)) + lambert_polygon(face(0, false));
  raster_options on;
  on.edge_coverage = true;
  hemicube_rasterizer edge(s, on), point(s);
  hemicube_buffer buf;
  const frame up{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const int n : {16, 64}) {
    edge.render({0, 0, 0}, up, n, buf);
    INFO("N = " << n << ", hard edges " << edge.statistics().edge_hard_edges);
    CHECK(edge.statistics().edge_hard_edges > 0);
    CHECK(std::fabs(integrate(buf).irradiance.x - want) <= (n == 16 ? 1e-3 : 1e-4) * want);
  }
  point.render({0, 0, 0}, up, 16, buf);
  CHECK(std::fabs(integrate(buf).irradiance.x - want) > 1e-2 * want);  // what the silhouette test fixes

  // The same box black under a sky of 1: E = pi - (the front faces' projected solid angle). At its
  // silhouette the back faces lie behind the front faces over the same part of each texel; the
  // blend must not give them a share of what is the sky's (taken as side by side, they made the
  // box 3% too big at N = 16, 0.55% at 64). Measured: 8e-6 at N = 16, 2e-7 at 64; asserted 1e-4
  // (the density's linearisation, as above).
  scene_mesh black = box;
  for (material& m : black.materials) m.emission = glm::vec3(0.0f);
  black.sky_radiance = glm::vec3(1.0f);
  hemicube_rasterizer rb(scene::create(black.desc()), on);
  const double pi = 3.14159265358979323846, want_sky = pi - want;
  for (const int n : {16, 64}) {
    rb.render({0, 0, 0}, up, n, buf);
    INFO("black box under the sky, N = " << n);
    CHECK(std::fabs(integrate(buf).irradiance.x - want_sky) <= 1e-4 * want_sky);
  }

  // One quad of two triangles sharing its diagonal, of two emissions: the diagonal is hard (a
  // change of material). E = e1 L(t1) + e2 L(t2).
  const glm::dvec3 c0(-0.4, 0.2, 1.0), c1(0.5, 0.1, 0.9), c2(0.6, 0.8, 1.1), c3(-0.3, 0.7, 1.0);
  scene_mesh quad;
  quad.add_triangle(glm::vec3(c0), glm::vec3(c1), glm::vec3(c2), material{glm::vec3(0.5f), glm::vec3(0.5f), true});
  quad.add_triangle(glm::vec3(c0), glm::vec3(c2), glm::vec3(c3), material{glm::vec3(1.5f), glm::vec3(0.5f), true});
  const double want2 = 0.5 * lambert_polygon({glm::dvec3(glm::vec3(c0)), glm::dvec3(glm::vec3(c1)), glm::dvec3(glm::vec3(c2))}) +
                       1.5 * lambert_polygon({glm::dvec3(glm::vec3(c0)), glm::dvec3(glm::vec3(c2)), glm::dvec3(glm::vec3(c3))});
  hemicube_rasterizer rq(scene::create(quad.desc()), on);
  for (const int n : {16, 64}) {
    rq.render({0, 0, 0}, up, n, buf);
    INFO("quad, N = " << n);
    CHECK(std::fabs(integrate(buf).irradiance.x - want2) <= 1e-4 * want2);
  }
}

TEST_CASE("raster: exact edge coverage hides a partial triangle behind another over the same part of a texel", "[raster]") {
  // Two black quads under a sky of 1, seen from the origin with normal +z: a near one, and behind
  // it at twice the distance the same quad grown 1% about its centre and scaled by 2 about the
  // origin, so that its outline projects just outside the near one's, into the same texels. Both
  // partial in those texels, the far one behind the near one over the near one's part: taken as
  // side by side, the far one's share counted again over what the near one covers, and the sky
  // lost it (1.6% at N = 16, 0.34% at 64 on these quads). E = pi - L(the grown quad) (Lambert's formula; the
  // projections are nested). What remains is the density's linearisation within partial texels,
  // as for the black box above: measured 2e-6 at N = 16, 5e-8 at 64; asserted 1e-4.
  std::mt19937 rng(59);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  raster_options on;
  on.edge_coverage = true;
  const frame up{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const double pi = 3.14159265358979323846;
  hemicube_buffer buf;
  double worst[2] = {0.0, 0.0}, worst_point = 0.0;
  for (int k = 0; k < 8; ++k) {
    // A quad at height ~1 with a random turn about z, tilt and place (above the horizon).
    const double turn = 2.0 * pi * u(rng), w = 0.2 + 0.4 * u(rng), h = 0.2 + 0.4 * u(rng);
    const glm::dvec3 centre(-0.4 + 0.8 * u(rng), -0.4 + 0.8 * u(rng), 0.8 + 0.4 * u(rng));
    const glm::dvec3 a(std::cos(turn), std::sin(turn), 0.3 * (u(rng) - 0.5)), b(-std::sin(turn), std::cos(turn), 0.3 * (u(rng) - 0.5));
    std::vector<glm::dvec3> near_quad, grown;
    for (int c = 0; c < 4; ++c) {
      const double su = (c == 1 || c == 2) ? 0.5 : -0.5, sv = c >= 2 ? 0.5 : -0.5;
      near_quad.push_back(centre + su * w * a + sv * h * b);
      grown.push_back(centre + 1.01 * (su * w * a + sv * h * b));
    }
    scene_mesh m;
    const material black{glm::vec3(0.0f), glm::vec3(0.5f), true};
    for (double scale : {1.0, 2.0}) {
      const std::vector<glm::dvec3>& q = scale == 1.0 ? near_quad : grown;
      const glm::vec3 v0(q[0] * scale), v1(q[1] * scale), v2(q[2] * scale), v3(q[3] * scale);
      m.add_triangle(v0, v1, v2, black);
      m.add_triangle(v0, v2, v3, black);
    }
    m.sky_radiance = glm::vec3(1.0f);
    // The grown quad as the float vertices the scene holds (scaled back: the projection is the same).
    std::vector<glm::dvec3> held;
    for (const glm::dvec3& g : grown) held.push_back(glm::dvec3(glm::vec3(g * 2.0)) * 0.5);
    const double want = pi - lambert_polygon(held);
    const auto s = scene::create(m.desc());
    hemicube_rasterizer edge(s, on), point(s);
    for (int i = 0; i < 2; ++i) {
      edge.render({0, 0, 0}, up, i == 0 ? 16 : 64, buf);
      worst[i] = std::max(worst[i], std::fabs(integrate(buf).irradiance.x - want) / want);
    }
    point.render({0, 0, 0}, up, 16, buf);
    worst_point = std::max(worst_point, std::fabs(integrate(buf).irradiance.x - want) / want);
  }
  INFO("worst relative error: edge coverage N = 16 " << worst[0] << ", N = 64 " << worst[1] << "; point sampling N = 16 " << worst_point);
  CHECK(worst[0] <= 1e-4);
  CHECK(worst[1] <= 1e-4);
}

TEST_CASE("raster: exact edge coverage keeps the texel centres' flags and triangle, bitwise on every path", "[raster]") {
  // flags and seen_triangle() are documented as what the texel centre sees: bit for bit what a
  // render without the option gives; the distance is the centre's, or nearer where a nearer
  // triangle covers part of the texel (never farther). The buffers must be the same bits on
  // every SIMD path and in repeated renders (deterministic resolve), and differ from point
  // sampling only on texels an edge crosses (checked loosely: at most a third of the texels).
  std::mt19937 rng(37);
  const scene_mesh scenes[] = {cornell_box(), hexagon_room(2), sky_and_occluders(), fan_box(rng, {-1, -1, -1}, {1, 1, 1})};
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  for (const scene_mesh& m : scenes) {
    const auto s = scene::create(m.desc());
    raster_options point, edge, scalar, sse2, avx2;
    edge.edge_coverage = scalar.edge_coverage = sse2.edge_coverage = avx2.edge_coverage = true;
    scalar.diagnostics.simd = false;
    sse2.diagnostics.avx2 = false;
    avx2.diagnostics.avx512 = false;
    hemicube_rasterizer rp(s, point), re(s, edge), rs(s, scalar), r2(s, sse2), ra(s, avx2);
    hemicube_buffer bp, be, bs, b2, ba, again;
    for (int k = 0; k < 5; ++k) {
      const glm::vec3 p = 0.5f * (s->bounds_lo() + s->bounds_hi()) + glm::vec3(u(rng), u(rng), u(rng)) * 0.2f * s->size();
      const frame f = random_frame(rng);
      const int n = k == 4 ? 256 : (k % 2 ? 30 : 64);
      rp.render(p, f, n, bp);
      re.render(p, f, n, be);
      rs.render(p, f, n, bs);
      r2.render(p, f, n, b2);
      ra.render(p, f, n, ba);
      re.render(p, f, n, again);
      INFO("N = " << n);
      CHECK(be.flags == bp.flags);
      std::size_t same_triangle = 0, changed = 0, nearer = 0, farther = 0;  // nearer: reported only
      for (std::size_t i = 0; i < be.texel_count(); ++i) {
        same_triangle += re.seen_triangle(i) == rp.seen_triangle(i) ? 1u : 0u;
        changed += be.radiance_at(i) != bp.radiance_at(i) || be.distance[i] != bp.distance[i] ? 1u : 0u;
        nearer += be.distance[i] < bp.distance[i] ? 1u : 0u;
        farther += !(be.distance[i] <= bp.distance[i]) ? 1u : 0u;  // (NaN counts as farther)
      }
      CHECK(same_triangle == be.texel_count());
      CHECK(changed * 3 <= be.texel_count());
      CHECK(farther == 0);
      INFO("texels with a nearer partial triangle: " << nearer);
      for (const hemicube_buffer* other : {&bs, &b2, &ba, &again}) {
        CHECK(std::memcmp(other->radiance.data(), be.radiance.data(), be.radiance.size() * sizeof(float)) == 0);
        CHECK(std::memcmp(other->distance.data(), be.distance.data(), be.distance.size() * sizeof(float)) == 0);
        CHECK(other->flags == be.flags);
      }
      for (float v : be.radiance) CHECK(std::isfinite(v));
    }
  }
}

TEST_CASE("raster: exact edge coverage blends textured triangles like emissive ones", "[raster]") {
  // A quad with lightmap UVs under a constant texture (0.7, 0.2, 0.4) must render exactly like
  // the same quad emitting that radiance (the texture path of the partial texels samples the
  // texture at the texel centre's perspective-correct UV; a constant texture makes that any
  // UV), both with edge coverage, against a sky of 3: the blends match to float rounding (1e-6).
  const glm::vec3 value(0.7f, 0.2f, 0.4f);
  scene_mesh textured, emissive;
  textured.add_quad({-0.7f, -0.3f, 1}, {-0.5f, 0.9f, 1.1f}, {0.6f, 0.7f, 0.9f}, {0.4f, -0.5f, 1}, material{glm::vec3(0.0f), glm::vec3(0.5f), true});
  textured.lightmap_uvs = {{0, 0}, {0, 1}, {1, 0}, {1, 1}};
  emissive.add_quad({-0.7f, -0.3f, 1}, {-0.5f, 0.9f, 1.1f}, {0.6f, 0.7f, 0.9f}, {0.4f, -0.5f, 1}, material{value, glm::vec3(0.5f), true});
  textured.sky_radiance = emissive.sky_radiance = glm::vec3(3.0f);
  image tex = image::make(4, 4, 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c) tex.at(x, y)[c] = value[c];
  const radiance_texture view(tex);
  raster_options o;
  o.edge_coverage = true;
  hemicube_rasterizer rt(scene::create(textured.desc()), o), re(scene::create(emissive.desc()), o);
  hemicube_buffer bt, be;
  const frame f = rolled_frame({0.1, -0.2, 1.0}, 0.4);
  rt.render({0, 0, 0}, f, 64, bt, &view);
  re.render({0, 0, 0}, f, 64, be);
  double worst = 0;
  std::size_t blended = 0;
  for (std::size_t i = 0; i < be.texel_count(); ++i) {
    const glm::vec3 a = bt.radiance_at(i), b = be.radiance_at(i);
    worst = std::max({worst, double(std::fabs(a.x - b.x)), double(std::fabs(a.y - b.y)), double(std::fabs(a.z - b.z))});
    blended += b.x != value.x && b.x != 3.0f ? 1u : 0u;
  }
  CHECK(blended > 100);  // the quad's outline crosses a few hundred texels at N = 64
  CHECK(worst <= 1e-6);
}

namespace {

// Renders at `points` with occlusion culling on and off (both otherwise the fastest paths, and the
// scalar path with culling) and checks the buffers and the seen triangles (ties settled in the
// reference order's favour) bit for bit. Returns the culled renders' statistics summed.
raster_statistics check_occlusion_is_exact(const scene_mesh& m, const std::vector<std::pair<glm::vec3, frame>>& points, int n,
                                           const radiance_texture* texture = nullptr) {
  const auto s = scene::create(m.desc());
  raster_options on, off, scalar;
  on.diagnostics.occlusion_min_triangles = 0;  // culling in scenes of every size
  off.diagnostics.occlusion_culling = false;
  scalar.diagnostics.simd = false;
  scalar.diagnostics.occlusion_min_triangles = 0;
  hemicube_rasterizer culled(s, on), reference(s, off), culled_scalar(s, scalar);
  hemicube_buffer a, b, c;
  raster_statistics sum;
  for (const auto& [p, f] : points) {
    culled.render(p, f, n, a, texture);
    reference.render(p, f, n, b, texture);
    culled_scalar.render(p, f, n, c, texture);
    CHECK(std::memcmp(a.distance.data(), b.distance.data(), a.distance.size() * sizeof(float)) == 0);
    CHECK(std::memcmp(a.radiance.data(), b.radiance.data(), a.radiance.size() * sizeof(float)) == 0);
    CHECK(a.flags == b.flags);
    CHECK(std::memcmp(c.distance.data(), b.distance.data(), c.distance.size() * sizeof(float)) == 0);
    CHECK(std::memcmp(c.radiance.data(), b.radiance.data(), c.radiance.size() * sizeof(float)) == 0);
    std::size_t same = 0;
    for (std::size_t i = 0; i < a.texel_count(); ++i)
      same += culled.seen_triangle(i) == reference.seen_triangle(i) && culled_scalar.seen_triangle(i) == reference.seen_triangle(i);
    CHECK(same == a.texel_count());
    CHECK(reference.statistics().nodes_occluded == 0);
    const raster_statistics& st = culled.statistics();
    sum.nodes_visited += st.nodes_visited;
    sum.triangles_tested += st.triangles_tested;
    sum.face_triangles += st.face_triangles;
    sum.nodes_occluded += st.nodes_occluded;
    sum.triangles_occluded += st.triangles_occluded;
    sum.occlusion_redraws += st.occlusion_redraws;
    sum.occlusion_ties_settled += st.occlusion_ties_settled;
  }
  return sum;
}

// Points on the scene's surfaces (a random triangle, a random point on it, lifted along its normal
// by 1e-4 of the scene's size, as a bake's samples are) with frames rolled at random about the
// triangle's normal.
std::vector<std::pair<glm::vec3, frame>> surface_points(const scene_mesh& m, std::size_t count, std::mt19937& rng) {
  std::vector<std::pair<glm::vec3, frame>> out;
  std::uniform_int_distribution<std::size_t> pick(0, m.triangle_count() - 1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto s = scene::create(m.desc());
  while (out.size() < count) {
    const std::size_t t = pick(rng);
    const glm::dvec3 a(m.positions[m.indices[3 * t]]), b(m.positions[m.indices[3 * t + 1]]), c(m.positions[m.indices[3 * t + 2]]);
    const glm::dvec3 nrm = glm::cross(b - a, c - a);
    if (glm::length(nrm) < 1e-12) continue;
    double r1 = u(rng), r2 = u(rng);
    if (r1 + r2 > 1.0) r1 = 1.0 - r1, r2 = 1.0 - r2;
    const glm::dvec3 p = a + r1 * (b - a) + r2 * (c - a) + 1e-4 * double(s->size()) * glm::normalize(nrm);
    out.emplace_back(glm::vec3(p), rolled_frame(glm::normalize(nrm), 6.283 * u(rng)));
  }
  return out;
}

}  // namespace

TEST_CASE("raster: occlusion culling leaves every buffer bitwise what the unculled render gives", "[raster]") {
  // Reference scenes of every kind (closed rooms, open scenes with parts set into each other, a
  // terrain, a field of boxes), points on their surfaces as a bake places them, N = 16 and 64.
  // The unculled render (diagnostics.occlusion_culling = false) is the reference; the scalar path
  // with culling must agree too.
  std::mt19937 rng(41);
  const scene_mesh scenes[] = {cornell_box(), hexagon_room(3), sky_and_occluders(), open_pavilion(), open_street(),
                               heightfield(20000), many_boxes(400)};
  std::size_t occluded = 0;
  for (const scene_mesh& m : scenes) {
    const auto points = surface_points(m, 24, rng);
    for (int n : {16, 64}) occluded += check_occlusion_is_exact(m, points, n).nodes_occluded;
  }
  CHECK(occluded > 0);  // and the culling did cull
}

TEST_CASE("raster: occlusion culling leaves the stand-in levels' buffers bitwise the unculled ones", "[raster]") {
  // The closed and open stand-in levels at their smallest sizes, points on their surfaces (some
  // inside the solids that overlap where parts meet, where coplanar faces tie), N = 64.
  std::mt19937 rng(43);
  for (const char* name : {"arena", "keep", "city_block", "terrain_town"}) {
    level_options o;
    o.target_triangles = std::string(name) == "arena" || std::string(name) == "keep" ? 10000 : 50000;
    const scene_mesh m = make_level(name, o).mesh;
    INFO(name);
    const auto points = surface_points(m, 16, rng);
    const raster_statistics st = check_occlusion_is_exact(m, points, 64);
    CHECK(st.triangles_occluded > 0);
    // Textured (a bounce pass): tied fragments are compared by the texture values they read.
    std::vector<float> pixels(3 * 256 * 256);
    for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = float(i * 2654435761u % 1000u) / 1000.0f;
    const radiance_texture texture(pixels.data(), 256, 256);
    check_occlusion_is_exact(m, points, 64, &texture);
  }
}

TEST_CASE("raster: occlusion culling skips what lies behind a wall and counts it", "[raster]") {
  // A point in front of a closed wall, behind which stand 2,000 boxes: from the point's side the
  // wall hides every box. The wall's leaves are the nearest nodes and drawn first (best-first
  // order), so nearly everything behind it is culled before it is tested: without culling all
  // 24,012 triangles are tested at each point.
  scene_mesh m;
  m.add_box({-20.0f, -20.0f, 1.0f}, {20.0f, 20.0f, 1.2f}, {glm::vec3(0.0f), glm::vec3(0.5f), false});
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-15.0f, 15.0f);
  for (int k = 0; k < 2000; ++k) {
    const glm::vec3 c(u(rng), u(rng), 5.0f + 0.5f * u(rng) + 8.0f);
    m.add_box(c - 0.3f, c + 0.3f, {glm::vec3(1.0f), glm::vec3(0.5f), false});
  }
  const std::vector<std::pair<glm::vec3, frame>> points = {{{0.1f, 0.2f, 0.0f}, rolled_frame({0, 0, 1}, 0.3)},
                                                           {{3.0f, -2.0f, 0.5f}, rolled_frame({0.2, 0.1, 1}, 1.1)}};
  const raster_statistics st = check_occlusion_is_exact(m, points, 64);
  INFO("nodes occluded " << st.nodes_occluded << ", triangles occluded " << st.triangles_occluded << ", tested "
                         << st.triangles_tested);
  CHECK(st.triangles_occluded > 2 * 12 * 1000);  // most boxes skipped by the occlusion test itself
  CHECK(st.triangles_tested < 2 * 12 * 50);       // (the rest by the frustum and tangent-plane tests)
}

TEST_CASE("raster: occlusion culling keeps the reference order's choice between equal depths", "[raster]") {
  // Two coplanar quads of different emission over the same area (z-fighting), the far one listed
  // first, and a third quad in front of part of them. The reference order draws the first-listed
  // quad first, which then keeps the texels where both have the same depth; front to back the
  // other may come first. The culled render must settle the ties in place (no redraw) and give the
  // reference's texels and seen triangles.
  scene_mesh m;
  const material red{glm::vec3(1, 0, 0), glm::vec3(0.5f), false}, blue{glm::vec3(0, 0, 1), glm::vec3(0.5f), false},
      green{glm::vec3(0, 1, 0), glm::vec3(0.5f), false};
  for (int k = 0; k < 40; ++k) {  // enough triangles for several BVH leaves
    const float x = -2.0f + 0.1f * float(k);
    m.add_quad({x, -2, 1}, {x, 2, 1}, {x + 0.1f, 2, 1}, {x + 0.1f, -2, 1}, red);
  }
  for (int k = 0; k < 40; ++k) {
    const float x = -2.0f + 0.1f * float(k);
    m.add_quad({x, -2, 1}, {x, 2, 1}, {x + 0.1f, 2, 1}, {x + 0.1f, -2, 1}, blue);
  }
  m.add_quad({-0.5f, -0.5f, 0.6f}, {-0.5f, 0.5f, 0.6f}, {0.5f, 0.5f, 0.6f}, {0.5f, -0.5f, 0.6f}, green);
  const std::vector<std::pair<glm::vec3, frame>> point = {{{0.05f, 0.03f, 0.0f}, rolled_frame({0, 0, 1}, 0.0)}};
  const raster_statistics st = check_occlusion_is_exact(m, point, 64);
  CHECK(st.occlusion_redraws == 0);
  CHECK(st.occlusion_ties_settled > 0);

  // The same with one material for both layers, and textured with lightmap UVs that differ between
  // the layers (a texture that tells them apart, and one that gives both the same value).
  scene_mesh same = m;
  for (material& mat : same.materials)
    if (mat.emission.z == 1.0f) mat = red;
  CHECK(check_occlusion_is_exact(same, point, 64).occlusion_ties_settled > 0);
  same.lightmap_uvs.resize(same.positions.size());
  for (std::size_t v = 0; v < same.positions.size(); ++v)
    same.lightmap_uvs[v] = {v < same.positions.size() / 2 ? 0.1f : 0.9f, 0.5f};
  std::vector<float> pixels = {1.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f};  // 2 x 1: red left, blue right
  const radiance_texture texture(pixels.data(), 2, 1);
  const raster_statistics st_textured = check_occlusion_is_exact(same, point, 64, &texture);
  CHECK(st_textured.occlusion_redraws == 0);
  CHECK(st_textured.occlusion_ties_settled > 0);
  std::vector<float> flat_pixels = {1.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f};
  const radiance_texture flat(flat_pixels.data(), 2, 1);
  CHECK(check_occlusion_is_exact(same, point, 64, &flat).occlusion_redraws == 0);

  // With level of detail the ties are not settled in place (proxies have no place in the order):
  // the render is drawn again where the tied fragments differ (the quads are too near for proxies,
  // so the buffers are still the unculled ones).
  const auto s = scene::create(m.desc());
  raster_options lod_on, lod_off;
  lod_on.diagnostics.occlusion_min_triangles = 0;
  lod_on.lod_texels = 1.0f;
  lod_off.diagnostics.occlusion_culling = false;
  lod_off.lod_texels = 1.0f;
  hemicube_rasterizer culled(s, lod_on), reference(s, lod_off);
  hemicube_buffer a, b;
  culled.render(point[0].first, point[0].second, 64, a);
  reference.render(point[0].first, point[0].second, 64, b);
  CHECK(culled.statistics().occlusion_redraws == 1);
  CHECK(culled.statistics().lod_nodes == 0);
  CHECK(std::memcmp(a.radiance.data(), b.radiance.data(), a.radiance.size() * sizeof(float)) == 0);
}

TEST_CASE("raster: level of detail draws far nodes from proxies, deterministic and close to the exact render", "[raster]") {
  // The open stand-in level (dense far geometry), every material emitting its albedo under a sky
  // of 1, points on its surfaces, N = 64, lod_texels = 16 (the largest: many proxies, up to whole
  // buildings far away): proxies keep their shape to 2% of their size (src/raster/lod.cpp), so
  // each moves few texels. Measured: 2,942 proxies drawn at 64 points, relative RMS of E 0.028%,
  // worst 0.14%; the bounds leave ~4x room and fail when proxies are drawn wrong (of the wrong
  // material or at the wrong place they change whole texels: several percent).
  level_options lo;
  lo.target_triangles = 50000;
  scene_mesh m = make_level("city_block", lo).mesh;
  for (material& mat : m.materials) mat.emission = mat.albedo;
  m.sky_radiance = glm::vec3(1.0f);
  const auto s = scene::create(m.desc());
  std::mt19937 rng(47);
  const auto points = surface_points(m, 64, rng);
  raster_options on;
  on.lod_texels = 16.0f;
  hemicube_rasterizer exact(s), lod(s, on), again(s, on);
  hemicube_buffer a, b, c;
  std::vector<double> ea, eb;
  std::size_t proxies = 0;
  const auto lum = [](const glm::vec3& e) { return 0.2126 * e.x + 0.7152 * e.y + 0.0722 * e.z; };
  for (const auto& [p, f] : points) {
    exact.render(p, f, 64, a);
    lod.render(p, f, 64, b);
    again.render(p, f, 64, c);
    CHECK(std::memcmp(b.radiance.data(), c.radiance.data(), b.radiance.size() * sizeof(float)) == 0);  // deterministic
    proxies += lod.statistics().lod_nodes;
    ea.push_back(lum(integrate(a).irradiance));
    eb.push_back(lum(integrate(b).irradiance));
  }
  // Relative to max(E, 5% of the mean) (points inside the solids see only back faces: E = 0).
  double mean = 0.0, sum = 0.0, worst = 0.0;
  for (double e : ea) mean += e / double(ea.size());
  for (std::size_t i = 0; i < ea.size(); ++i) {
    const double err = std::fabs(eb[i] - ea[i]) / std::max(ea[i], 0.05 * mean);
    sum += err * err;
    worst = std::max(worst, err);
  }
  INFO("proxies drawn " << proxies << ", RMS " << std::sqrt(sum / double(points.size())) << ", worst " << worst);
  CHECK(proxies > 0);
  CHECK(std::sqrt(sum / double(points.size())) < 1e-3);
  CHECK(worst < 5e-3);
  CHECK(sum > 0.0);  // (and the proxies did change something: they were drawn)
  // Textured renders read the proxies' own vertices' lightmap UVs: finite, the same bits twice.
  std::vector<float> pixels(3 * 64 * 64);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = float(i % 7) / 7.0f;
  const radiance_texture texture(pixels.data(), 64, 64);
  lod.render(points[0].first, points[0].second, 64, b, &texture);
  again.render(points[0].first, points[0].second, 64, c, &texture);
  CHECK(std::memcmp(b.radiance.data(), c.radiance.data(), b.radiance.size() * sizeof(float)) == 0);
  for (float v : b.radiance) CHECK(std::isfinite(v));
  // Bad thresholds are refused by name.
  for (float bad : {-1.0f, 17.0f, NAN}) {
    raster_options o;
    o.lod_texels = bad;
    CHECK_THROWS_WITH(hemicube_rasterizer(s, o), Catch::Contains("lod_texels"));
  }
}
