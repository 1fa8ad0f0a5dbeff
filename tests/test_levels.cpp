// Tests of the stand-in levels (fixtures/include/hemilight/levels.hpp) at their default sizes
// (50,000 and 150,000 triangles): counts, determinism, the lightmap charts (inside [0, 1], wound
// as their triangles, at one texel density, no texel shared by two charts, padding between them),
// the degenerate triangles (recounted here in double), closed surfaces, faces towards the air, and
// the sun.
#include "hemilight/levels.hpp"
#include "hemilight/rays.hpp"

#include "test_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

using namespace hemilight;

namespace {

bool is_degenerate(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::dvec3 pa(a), pb(b), pc(c);
  const double area = 0.5 * glm::length(glm::cross(pb - pa, pc - pa));
  const double longest = std::max({glm::dot(pb - pa, pb - pa), glm::dot(pc - pb, pc - pb), glm::dot(pa - pc, pa - pc)});
  return area <= 1e-10 * longest;
}

std::array<std::uint32_t, 3> bits(const glm::vec3& p) {
  std::array<std::uint32_t, 3> b;
  std::memcpy(b.data(), &p, sizeof b);
  return b;
}

// Every edge of the non-degenerate triangles, by the bits of its end points, must be used exactly
// once in each direction. Returns the number of edges that are not.
std::size_t open_edges(const level& l) {
  struct edge {
    std::array<std::uint32_t, 6> key;  // lower end point first
    int forward;
    bool operator<(const edge& o) const { return key < o.key || (key == o.key && forward < o.forward); }
  };
  std::vector<edge> edges;
  const scene_mesh& m = l.mesh;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const glm::vec3 p[3] = {m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]], m.positions[m.indices[3 * t + 2]]};
    if (is_degenerate(p[0], p[1], p[2])) continue;
    for (int e = 0; e < 3; ++e) {
      const auto a = bits(p[e]), b = bits(p[(e + 1) % 3]);
      const bool fwd = a < b;
      const auto& lo = fwd ? a : b;
      const auto& hi = fwd ? b : a;
      edges.push_back({{lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]}, fwd ? 1 : 0});
    }
  }
  std::sort(edges.begin(), edges.end());
  std::size_t bad = 0;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i, fwd = 0;
    while (j < edges.size() && edges[j].key == edges[i].key) fwd += static_cast<std::size_t>(edges[j++].forward);
    if (j - i != 2 || fwd != 1) ++bad;
    i = j;
  }
  return bad;
}

// Does the closed triangle (a, b, c) (texel units) touch the closed texel square [x, x+1] x [y, y+1]?
// Separating axes: the square's two and the triangle's edge normals (none for a zero-length edge).
bool touches(const glm::dvec2* t, int x, int y) {
  const glm::dvec2 sq[4] = {{x, y}, {x + 1, y}, {x, y + 1}, {x + 1, y + 1}};
  for (int e = 0; e < 3; ++e) {
    const glm::dvec2 d = t[(e + 1) % 3] - t[e];
    const glm::dvec2 n(-d.y, d.x);
    if (n == glm::dvec2(0.0)) continue;
    double tmin = glm::dot(n, t[0]), tmax = tmin;
    for (int k = 1; k < 3; ++k) {
      tmin = std::min(tmin, glm::dot(n, t[k]));
      tmax = std::max(tmax, glm::dot(n, t[k]));
    }
    double smin = glm::dot(n, sq[0]), smax = smin;
    for (int k = 1; k < 4; ++k) {
      smin = std::min(smin, glm::dot(n, sq[k]));
      smax = std::max(smax, glm::dot(n, sq[k]));
    }
    if (smax < tmin || tmax < smin) return false;
  }
  return true;  // the square's axes were settled by the caller's bounding box
}

void check_level(const level& l, std::size_t target) {
  const scene_mesh& m = l.mesh;
  const std::size_t T = m.triangle_count(), V = m.positions.size();
  INFO(l.name << ": " << T << " triangles, " << l.charts << " charts, " << l.degenerate_triangles << " degenerate");
  // The count: within 10% of the target (rooms, buildings and terrain cells are whole).
  CHECK(static_cast<double>(T) >= 0.9 * static_cast<double>(target));
  CHECK(static_cast<double>(T) <= 1.1 * static_cast<double>(target));
  REQUIRE(m.indices.size() == 3 * T);
  REQUIRE(m.materials.size() == T);
  REQUIRE(m.lightmap_uvs.size() == V);
  REQUIRE(l.triangle_charts.size() == T);
  for (std::uint32_t i : m.indices) REQUIRE(i < V);
  for (std::uint32_t c : l.triangle_charts) REQUIRE(c < l.charts);
  // Many small charts (thousands at the default sizes), a few albedos in [0.2, 0.8], nothing
  // emits, a sky.
  CHECK(l.charts * 25 >= T);
  for (const material& mat : m.materials) {
    REQUIRE(mat.emission == glm::vec3(0.0f));
    REQUIRE(glm::all(glm::greaterThanEqual(mat.albedo, glm::vec3(0.2f))));
    REQUIRE(glm::all(glm::lessThanEqual(mat.albedo, glm::vec3(0.8f))));
  }
  CHECK(m.sky_radiance == glm::vec3(1.0f));

  // Degenerate triangles: recounted here, 1-2% of the triangles.
  std::size_t degenerate = 0;
  for (std::size_t t = 0; t < T; ++t)
    degenerate +=
        is_degenerate(m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]], m.positions[m.indices[3 * t + 2]]);
  CHECK(degenerate == l.degenerate_triangles);
  CHECK(static_cast<double>(degenerate) >= 0.01 * static_cast<double>(T));
  CHECK(static_cast<double>(degenerate) <= 0.02 * static_cast<double>(T));

  // Closed: every edge of the non-degenerate triangles has exactly one partner of opposite
  // orientation (bit-identical end points).
  CHECK(open_edges(l) == 0);

  // UVs inside [0, 1]; every non-degenerate triangle keeps its winding in UV space (so no chart
  // folds over itself), at the level's texel density: sqrt(UV area / 3D area) is the density
  // (planar charts) or a little less (terrain patches and rocks, projected onto their mean
  // plane, never more). The tolerance 1e-3 covers the float rounding of the UVs of triangles of
  // at least one texel; smaller ones are not weighed.
  const double S = l.lightmap_size;
  for (const glm::vec2& uv : m.lightmap_uvs) {
    REQUIRE(uv.x >= 0.0f);
    REQUIRE(uv.x <= 1.0f);
    REQUIRE(uv.y >= 0.0f);
    REQUIRE(uv.y <= 1.0f);
  }
  double covered = 0.0, weighted = 0.0, weight = 0.0;
  std::size_t reversed = 0, too_dense = 0, too_sparse = 0;
  for (std::size_t t = 0; t < T; ++t) {
    const std::uint32_t i0 = m.indices[3 * t], i1 = m.indices[3 * t + 1], i2 = m.indices[3 * t + 2];
    const glm::dvec2 a(m.lightmap_uvs[i0]), e1 = glm::dvec2(m.lightmap_uvs[i1]) - a, e2 = glm::dvec2(m.lightmap_uvs[i2]) - a;
    const double uv_area = 0.5 * (e1.x * e2.y - e1.y * e2.x);
    covered += std::fabs(uv_area);
    if (is_degenerate(m.positions[i0], m.positions[i1], m.positions[i2])) continue;
    if (!(uv_area > 0.0)) ++reversed;
    const glm::dvec3 p0(m.positions[i0]);
    const double area = 0.5 * glm::length(glm::cross(glm::dvec3(m.positions[i1]) - p0, glm::dvec3(m.positions[i2]) - p0));
    const double texels = uv_area * S * S;
    if (texels < 1.0) continue;
    const double ratio = std::sqrt(texels / area) / static_cast<double>(l.texels_per_metre);
    too_dense += ratio > 1.001;
    too_sparse += ratio < 0.5;
    weighted += ratio * area;
    weight += area;
  }
  CHECK(reversed == 0);
  CHECK(too_dense == 0);
  CHECK(too_sparse == 0);
  CHECK(weighted / weight > 0.97);  // nearly all the area is planar charts at exactly the density
  CHECK(std::fabs(covered - l.utilisation) <= 1e-9);
  CHECK(l.utilisation > 0.3);
  CHECK(l.utilisation < 1.0);

  // No texel touched by two charts: every triangle (degenerate ones too) marks the texels its
  // closed shape touches (a conservative rasterisation).
  const auto N = static_cast<std::size_t>(l.lightmap_size);
  std::vector<std::uint32_t> owner(N * N, UINT32_MAX);
  std::size_t shared = 0;
  for (std::size_t t = 0; t < T; ++t) {
    glm::dvec2 p[3];
    for (int k = 0; k < 3; ++k) p[k] = glm::dvec2(m.lightmap_uvs[m.indices[3 * t + static_cast<std::size_t>(k)]]) * S;
    const int x0 = static_cast<int>(std::floor(std::min({p[0].x, p[1].x, p[2].x}))),
              x1 = static_cast<int>(std::floor(std::max({p[0].x, p[1].x, p[2].x})));
    const int y0 = static_cast<int>(std::floor(std::min({p[0].y, p[1].y, p[2].y}))),
              y1 = static_cast<int>(std::floor(std::max({p[0].y, p[1].y, p[2].y})));
    for (int y = std::max(0, y0); y <= std::min(y1, l.lightmap_size - 1); ++y)
      for (int x = std::max(0, x0); x <= std::min(x1, l.lightmap_size - 1); ++x) {
        if (!touches(p, x, y)) continue;
        std::uint32_t& o = owner[static_cast<std::size_t>(y) * N + static_cast<std::size_t>(x)];
        if (o != UINT32_MAX && o != l.triangle_charts[t]) ++shared;
        o = l.triangle_charts[t];
      }
  }
  CHECK(shared == 0);
  // Padding: the charts' UV bounding boxes (texel units) are at least `padding` texels apart
  // along x or y (1e-3 texel for the float rounding of the UVs). Sweep over x.
  std::vector<glm::dvec4> box(l.charts, glm::dvec4(1e30, 1e30, -1e30, -1e30));
  for (std::size_t t = 0; t < T; ++t)
    for (int k = 0; k < 3; ++k) {
      const glm::dvec2 q = glm::dvec2(m.lightmap_uvs[m.indices[3 * t + static_cast<std::size_t>(k)]]) * S;
      glm::dvec4& b = box[l.triangle_charts[t]];
      b = {std::min(b.x, q.x), std::min(b.y, q.y), std::max(b.z, q.x), std::max(b.w, q.y)};
    }
  std::vector<std::size_t> order(l.charts);
  for (std::size_t c = 0; c < l.charts; ++c) order[c] = c;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return box[a].x < box[b].x; });
  const double gap = l.padding - 1e-3;
  std::size_t crowded = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    const glm::dvec4& a = box[order[i]];
    for (std::size_t j = i + 1; j < order.size() && box[order[j]].x < a.z + gap; ++j) {
      const glm::dvec4& b = box[order[j]];
      if (b.y < a.w + gap && a.y < b.w + gap) ++crowded;
    }
  }
  CHECK(crowded == 0);
  // The packer wastes little: the charts' boxes grown by the padding (the least room each
  // needs) cover at least 75% of the atlas (81-91% at the default sizes).
  double needed = 0.0;
  for (const glm::dvec4& b : box) needed += (b.z - b.x + l.padding) * (b.w - b.y + l.padding);
  INFO("padded chart boxes cover " << needed / (S * S) << " of the atlas");
  CHECK(needed / (S * S) >= 0.75);

  // The sun: one valid directional light shining downwards.
  REQUIRE(l.lights.size() == 1);
  CHECK_NOTHROW(validate_lights(l.lights.data(), l.lights.size()));
  CHECK(l.lights[0].type == light_type::directional);
  CHECK(l.lights[0].direction.y < -0.5f);
}

// Faces towards the air: just behind a face (1 mm) is the inside of a solid, so there the
// winding number of all the closed surfaces is at least 1. It is counted along a ray to the
// outside: +1 for each face left through (its back is met), -1 for each entered. A solid turned
// inside out would give 0 behind its faces (they face its inside, behind them is the air around
// it). Returns the fraction of the sampled faces (about 4,000) behind which it is below 1;
// rays that graze an edge may miscount, so a few per thousand are tolerated.
double outside_fraction(const level& l) {
  const auto s = scene::create(l.mesh.desc());
  const scene_mesh& m = l.mesh;
  std::size_t samples = 0, outside = 0;
  const std::size_t step = std::max<std::size_t>(1, m.triangle_count() / 4000);
  for (std::size_t t = 0; t < m.triangle_count(); t += step) {
    const glm::vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
                    c = m.positions[m.indices[3 * t + 2]];
    if (is_degenerate(a, b, c)) continue;
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    // A direction that is no axis, different per sample.
    const float u = static_cast<float>(t % 97) / 97.0f;
    const glm::vec3 d = glm::normalize(glm::vec3(0.31f + u, 0.83f - 0.5f * u, 0.47f - u));
    glm::vec3 o = (a + b + c) / 3.0f - 1e-3f * n;
    int winding = 0;
    ray_hit hit;
    for (int k = 0; k < 1000 && intersect(*s, o, d, 1e7f, hit); ++k) {
      winding += hit.front_face ? -1 : 1;
      o += (hit.distance + 1e-4f) * d;
    }
    ++samples;
    outside += winding < 1;
  }
  return static_cast<double>(outside) / static_cast<double>(samples);
}

bool same_bytes(const level& a, const level& b) {
  const auto eq = [](const auto& x, const auto& y) {
    return x.size() == y.size() && (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof x[0]) == 0);
  };
  bool materials = a.mesh.materials.size() == b.mesh.materials.size();
  for (std::size_t t = 0; materials && t < a.mesh.materials.size(); ++t)
    materials = std::memcmp(&a.mesh.materials[t].albedo, &b.mesh.materials[t].albedo, sizeof(glm::vec3)) == 0;
  return eq(a.mesh.positions, b.mesh.positions) && eq(a.mesh.indices, b.mesh.indices) &&
         eq(a.mesh.lightmap_uvs, b.mesh.lightmap_uvs) && eq(a.triangle_charts, b.triangle_charts) && materials &&
         a.degenerate_triangles == b.degenerate_triangles && a.charts == b.charts && a.texels_per_metre == b.texels_per_metre &&
         a.utilisation == b.utilisation && std::memcmp(&a.lights[0].direction, &b.lights[0].direction, sizeof(glm::vec3)) == 0;
}

void check_default(const std::string& name, std::size_t target) {
  const level l = make_level(name);
  CHECK(l.name == name);
  CHECK(l.lightmap_size == (target <= 75000 ? 1024 : 2048));
  check_level(l, target);
  CHECK(l.charts >= 2000);
  const double outside = outside_fraction(l);
  INFO(name << ": behind " << outside << " of the sampled faces is no solid");
  CHECK(outside <= 0.005);
  CHECK(same_bytes(l, make_level(name)));  // deterministic
}

}  // namespace

TEST_CASE("Levels: the names, and errors for bad names and options", "[levels]") {
  CHECK(level_names() == std::vector<std::string>{"arena", "keep", "city_block", "terrain_town"});
  test::require_error([] { make_level("dungeon"); }, status::invalid_argument, "unknown level 'dungeon'");
  level_options o;
  o.target_triangles = 9999;
  test::require_error([&] { make_level("arena", o); }, status::invalid_argument, "target_triangles 9999");
  o.target_triangles = 20000;  // fine for a closed level, too few for an open one
  test::require_error([&] { make_level("city_block", o); }, status::invalid_argument, "[50000, 4000000]");
  o = {};
  o.lightmap_size = 100;
  test::require_error([&] { make_level("keep", o); }, status::invalid_argument, "lightmap_size 100");
  o = {};
  o.padding = 0;
  test::require_error([&] { make_level("keep", o); }, status::invalid_argument, "padding 0");
  o = {};
  o.lightmap_size = 256;  // 34,000 charts need more than 256^2 / 9 texels
  test::require_error([&] { make_level("city_block", o); }, status::invalid_argument, "use a larger lightmap_size");
}

TEST_CASE("Levels: arena at its default size", "[levels]") { check_default("arena", 50000); }
TEST_CASE("Levels: keep at its default size", "[levels]") { check_default("keep", 50000); }
TEST_CASE("Levels: city_block at its default size", "[levels]") { check_default("city_block", 150000); }
TEST_CASE("Levels: terrain_town at its default size", "[levels]") { check_default("terrain_town", 150000); }

TEST_CASE("Levels: the count follows the target, other seeds and paddings pack as well", "[levels]") {
  for (const auto& [name, target] :
       {std::pair<const char*, std::size_t>{"arena", 20000}, {"keep", 100000}, {"terrain_town", 60000}}) {
    level_options o;
    o.target_triangles = target;
    o.seed = 7;
    o.padding = 4;
    const level l = make_level(name, o);
    check_level(l, target);
  }
}

TEST_CASE("Levels: without degenerate triangles, the same level minus them", "[levels]") {
  level_options o;
  const level with = make_level("arena", o);
  o.degenerate_triangles = false;
  const level without = make_level("arena", o);
  CHECK(without.degenerate_triangles == 0);
  REQUIRE(without.mesh.triangle_count() + with.degenerate_triangles == with.mesh.triangle_count());
  // The triangles that are not degenerate, in order, at the same positions and UVs.
  std::size_t k = 0, differ = 0;
  for (std::size_t t = 0; t < with.mesh.triangle_count(); ++t) {
    const std::uint32_t* w = &with.mesh.indices[3 * t];
    if (is_degenerate(with.mesh.positions[w[0]], with.mesh.positions[w[1]], with.mesh.positions[w[2]])) continue;
    const std::uint32_t* o2 = &without.mesh.indices[3 * k++];
    for (int v = 0; v < 3; ++v)
      differ += with.mesh.positions[w[v]] != without.mesh.positions[o2[v]] ||
                with.mesh.lightmap_uvs[w[v]] != without.mesh.lightmap_uvs[o2[v]];
  }
  CHECK(k == without.mesh.triangle_count());
  CHECK(differ == 0);
}
