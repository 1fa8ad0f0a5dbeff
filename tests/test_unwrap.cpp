// Tests of unwrap.hpp against invariants and closed forms: no two UV triangles overlap and charts
// keep their padding (checked by rasterising the UVs here, independently of the packer); every
// triangle keeps its winding; one texel density (UV area over 3D area); a planar chart's projection
// has stretch 1; a least-squares conformal map of a developable surface (a cylinder patch, a
// folded strip) has stretch 1; welding by position; degenerate triangles; pages; determinism
// across runs and thread counts; bad options and input.
#include "hemilight/bake.hpp"
#include "hemilight/reference_scenes.hpp"
#include "hemilight/unwrap.hpp"

#include "test_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <set>

using namespace hemilight;

namespace {

constexpr double pi = 3.14159265358979323846;

struct plain_mesh {
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
  std::size_t triangle_count() const { return indices.size() / 3; }
  unwrap_result unwrap(const unwrap_options& o) const {
    return unwrap_lightmap(positions.data(), positions.size(), indices.data(), triangle_count(), o);
  }
};

plain_mesh of(const scene_mesh& m) { return {m.positions, m.indices}; }

// Every triangle with its own three vertices, as levels are often exported.
plain_mesh unshared(const plain_mesh& m) {
  plain_mesh out;
  for (std::uint32_t i : m.indices) {
    out.indices.push_back(std::uint32_t(out.positions.size()));
    out.positions.push_back(m.positions[i]);
  }
  return out;
}

// A cylinder patch of radius r and height h over `degrees` of arc, as nu x nv quads, facing out.
plain_mesh cylinder_patch(double r, double h, double degrees, int nu, int nv) {
  plain_mesh m;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const double a = degrees * pi / 180.0 * i / nu;
      m.positions.emplace_back(float(r * std::cos(a)), float(h * j / nv), float(-r * std::sin(a)));
    }
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const auto p = std::uint32_t(j * (nu + 1) + i), q = p + std::uint32_t(nu + 1);
      m.indices.insert(m.indices.end(), {p, p + 1, q + 1, p, q + 1, q});
    }
  return m;
}

// A UV sphere of radius 1 (nu segments around, nv rings), facing out.
plain_mesh sphere(int nu, int nv) {
  plain_mesh m;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const double th = pi * j / nv, ph = 2.0 * pi * i / nu;
      m.positions.emplace_back(float(std::sin(th) * std::cos(ph)), float(std::cos(th)), float(std::sin(th) * std::sin(ph)));
    }
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const auto p = std::uint32_t(j * (nu + 1) + i), q = p + std::uint32_t(nu + 1);
      if (j > 0) m.indices.insert(m.indices.end(), {p, p + 1, q});
      if (j + 1 < nv) m.indices.insert(m.indices.end(), {p + 1, q + 1, q});
    }
  return m;
}

glm::dvec3 corner(const plain_mesh& m, std::size_t t, int k) { return glm::dvec3(m.positions[m.indices[3 * t + std::size_t(k)]]); }

double area3(const plain_mesh& m, std::size_t t) {
  return 0.5 * glm::length(glm::cross(corner(m, t, 1) - corner(m, t, 0), corner(m, t, 2) - corner(m, t, 0)));
}

// Twice the signed area of triangle t in texels.
double uv_area2(const unwrap_result& r, std::size_t t, int size) {
  const glm::dvec2 a = glm::dvec2(r.uvs[r.indices[3 * t]]) * double(size), b = glm::dvec2(r.uvs[r.indices[3 * t + 1]]) * double(size),
                   c = glm::dvec2(r.uvs[r.indices[3 * t + 2]]) * double(size);
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

bool is_degenerate(const plain_mesh& m, std::size_t t) {
  return is_degenerate_triangle(m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]], m.positions[m.indices[3 * t + 2]]);
}

// The invariants of any result, checked by rasterising its UVs (independently of the packer):
// - the output's vertices copy their sources' positions and every UV lies in [0, 1];
// - every non-degenerate triangle keeps its winding (positive UV area);
// - no point strictly inside two UV triangles of one page: 8 x 8 sample points per texel, inside
//   meaning all three edge functions above 1e-9 of the triangle's doubled area (so points on a
//   shared edge count for neither);
// - a texel touched (exact clipped area > 0) by one chart is farther than `padding` texels
//   (Chebyshev) from every texel touched by another, and from the page border.
void check_layout(const plain_mesh& m, const unwrap_result& r, int size, int padding) {
  REQUIRE(r.indices.size() == m.indices.size());
  REQUIRE(r.vertex_source.size() == r.uvs.size());
  REQUIRE(r.uvs.size() <= 3 * m.triangle_count());
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) REQUIRE(r.vertex_source[r.indices[3 * t + std::size_t(k)]] == m.indices[3 * t + std::size_t(k)]);
  for (const glm::vec2& uv : r.uvs) REQUIRE((uv.x >= 0.0f && uv.x <= 1.0f && uv.y >= 0.0f && uv.y <= 1.0f));
  const std::size_t texels = std::size_t(size) * std::size_t(size);
  constexpr int s = 8;
  std::size_t overlaps = 0, flipped = 0, padding_breaks = 0;
  for (int page = 0; page < r.stats.pages; ++page) {
    std::vector<std::uint8_t> hits(texels * s * s, 0);
    std::vector<std::uint32_t> chart_at(texels, unwrap_result::no_chart);
    std::vector<std::uint8_t> shared(texels, 0);
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      if (int(r.triangle_page[t]) != page || is_degenerate(m, t)) continue;
      glm::dvec2 q[3];
      for (int k = 0; k < 3; ++k) q[k] = glm::dvec2(r.uvs[r.indices[3 * t + std::size_t(k)]]) * double(size);
      const double a2 = (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[1].y - q[0].y) * (q[2].x - q[0].x);
      if (!(a2 > 0.0)) {
        ++flipped;
        continue;
      }
      const int x0 = std::max(0, int(std::floor(std::min({q[0].x, q[1].x, q[2].x})))), x1 = std::min(size - 1, int(std::max({q[0].x, q[1].x, q[2].x})));
      const int y0 = std::max(0, int(std::floor(std::min({q[0].y, q[1].y, q[2].y})))), y1 = std::min(size - 1, int(std::max({q[0].y, q[1].y, q[2].y})));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const std::size_t k = std::size_t(y) * std::size_t(size) + std::size_t(x);
          if (clip_triangle_to_texel(glm::vec2(q[0]), glm::vec2(q[1]), glm::vec2(q[2]), x, y).area > 0.0f) {
            if (chart_at[k] != unwrap_result::no_chart && chart_at[k] != r.triangle_chart[t]) shared[k] = 1;
            chart_at[k] = r.triangle_chart[t];
          }
          for (int j = 0; j < s; ++j)
            for (int i = 0; i < s; ++i) {
              const glm::dvec2 p(x + (i + 0.5) / s, y + (j + 0.5) / s);
              bool inside = true;
              for (int e = 0; e < 3 && inside; ++e) {
                const glm::dvec2 a = q[e], b = q[(e + 1) % 3];
                inside = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x) > 1e-9 * a2;
              }
              if (inside && hits[k * s * s + std::size_t(j * s + i)]++ > 0) ++overlaps;
            }
        }
    }
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const std::uint32_t c = chart_at[std::size_t(y) * std::size_t(size) + std::size_t(x)];
        if (c == unwrap_result::no_chart) continue;
        if (shared[std::size_t(y) * std::size_t(size) + std::size_t(x)] || x < padding || y < padding || x >= size - padding ||
            y >= size - padding) {
          ++padding_breaks;
          continue;
        }
        for (int dy = -padding; dy <= padding; ++dy)
          for (int dx = -padding; dx <= padding; ++dx) {
            const std::uint32_t o = chart_at[std::size_t(y + dy) * std::size_t(size) + std::size_t(x + dx)];
            if (o != unwrap_result::no_chart && o != c) ++padding_breaks;
          }
      }
  }
  CHECK(flipped == 0);
  CHECK(overlaps == 0);
  CHECK(padding_breaks == 0);
}

// UV area over 3D area of every non-degenerate triangle, in texels per scene unit squared:
// min and max over the triangles of the charts selected.
std::pair<double, double> density_range(const plain_mesh& m, const unwrap_result& r, int size) {
  double lo = 1e300, hi = 0.0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    if (is_degenerate(m, t)) continue;
    const double d = 0.5 * uv_area2(r, t, size) / area3(m, t);
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  return {lo, hi};
}

}  // namespace

TEST_CASE("unwrap: a plane is one planar chart, projected with stretch 1 at one density", "[unwrap]") {
  // A 3 x 2 grid plane, tilted by a rotation and moved: one planar region.
  scene_mesh grid;
  const glm::dmat3 rot = glm::dmat3(glm::dvec3(0.6, 0.0, -0.8), glm::dvec3(0.48, 0.6, 0.36), glm::dvec3(0.64, -0.8, 0.48));
  const auto place = [&](double x, double y) { return glm::vec3(rot * glm::dvec3(x, y, 0.0) + glm::dvec3(5, -2, 3)); };
  grid.add_grid(place(0, 0), place(3, 0), place(3, 2), place(0, 2), 12, 8, material{});
  const plain_mesh m = of(grid);
  unwrap_options o;
  o.page_size = 128;
  const unwrap_result r = m.unwrap(o);
  CHECK(r.stats.charts == 1);
  CHECK(r.stats.planar_charts == 1);
  CHECK(r.stats.pages == 1);
  CHECK(r.stats.seam_texels == 0.0);
  // Stretch 1 up to the float rounding of the UVs (6e-8 of the page, on triangles of ~10 texels:
  // ~1e-6 relative); 1e-5 leaves a margin.
  CHECK(r.stats.stretch_l2 == Approx(1.0).margin(1e-5));
  CHECK(r.stats.stretch_linf == Approx(1.0).margin(1e-5));
  const auto [lo, hi] = density_range(m, r, o.page_size);
  CHECK(hi / lo < 1.0 + 1e-5);
  CHECK(lo == Approx(double(r.stats.texels_per_unit) * r.stats.texels_per_unit).epsilon(1e-5));
  // It fills the page up to the padding along its longer side: 3 units wide in 128 - 4 texels
  // (the density's bisection ends within 2^-16 of its bound).
  CHECK(r.stats.texels_per_unit * 3.0f <= float(o.page_size - 2 * o.padding));
  CHECK(r.stats.texels_per_unit * 3.0f > 0.97f * float(o.page_size - 2 * o.padding));
  check_layout(m, r, o.page_size, o.padding);
}

TEST_CASE("unwrap: least-squares conformal maps flatten developable surfaces with stretch 1", "[unwrap]") {
  // A cylinder patch over 80 degrees (its normals within 40 of their mean) and a strip folded
  // along a line by 50 degrees: both developable, so the conformal map is an isometry up to
  // similarity, which the chart's scaling to its 3D area fixes. Tolerances: the solve is exact up
  // to double rounding and the UVs are floats (1e-6 relative on these triangles); 1e-4 leaves room.
  plain_mesh folded;
  for (int i = 0; i <= 8; ++i) {
    const double x = i * 0.25;
    folded.positions.emplace_back(float(x), 0.0f, 0.0f);
    folded.positions.emplace_back(float(x), float(std::cos(50.0 * pi / 180.0)), float(std::sin(50.0 * pi / 180.0)));
    folded.positions.emplace_back(float(x), -1.0f, 0.0f);
  }
  for (std::uint32_t i = 0; i < 8; ++i) {
    const std::uint32_t a = 3 * i, b = 3 * i + 3;
    folded.indices.insert(folded.indices.end(), {a, a + 1, b + 1, a, b + 1, b});      // the folded half
    folded.indices.insert(folded.indices.end(), {a + 2, a, b, a + 2, b, b + 2});      // the flat half
  }
  for (const plain_mesh& m : {cylinder_patch(1.0, 2.0, 80.0, 24, 8), folded}) {
    unwrap_options o;
    o.page_size = 256;
    const unwrap_result r = m.unwrap(o);
    CHECK(r.stats.charts == 1);
    CHECK(r.stats.planar_charts == 0);
    CHECK(r.stats.stretch_l2 == Approx(1.0).margin(1e-4));
    CHECK(r.stats.stretch_linf == Approx(1.0).margin(1e-4));
    const auto [lo, hi] = density_range(m, r, o.page_size);
    CHECK(hi / lo < 1.0 + 1e-4);  // isometric: every triangle at the one density
    check_layout(m, r, o.page_size, o.padding);
  }
}

TEST_CASE("unwrap: curved and boxy meshes keep winding, padding and one density per planar chart, without overlaps", "[unwrap]") {
  // A sphere (doubly curved: conformal maps stretch it, so only the invariants are checked, and that
  // charts are not cut smaller than the chart angle needs), the reference scenes, boxes.
  const plain_mesh ball = sphere(32, 16);
  unwrap_options o;
  o.page_size = 256;
  const unwrap_result r = ball.unwrap(o);
  CHECK(r.stats.charts >= 4);    // 60 degrees from a chart's mean normal: a sphere needs several
  CHECK(r.stats.charts <= 40);
  CHECK(r.stats.stretch_l2 < 1.2);  // what a 60-degree cap costs a conformal map (docs/unwrap.md)
  check_layout(ball, r, o.page_size, o.padding);
  for (const scene_mesh& sm : {cornell_box(), hexagon_room(2), many_boxes(30), open_pavilion(), heightfield(2000)}) {
    const plain_mesh m = of(sm);
    const unwrap_result ru = m.unwrap(o);
    check_layout(m, ru, o.page_size, o.padding);
    // Planar charts are projected: their triangles all at the one density (float UVs: 1e-4).
    double lo = 1e300, hi = 0.0;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      if (is_degenerate(m, t) || area3(m, t) < 1e-6) continue;
      const double d = 0.5 * uv_area2(ru, t, o.page_size) / area3(m, t);
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
    if (ru.stats.planar_charts == ru.stats.charts) CHECK(hi / lo < 1.0 + 1e-3);
  }
  // A crowded page: 151 charts in 64² with 3 texels of padding (at most 15 x 15 slots of 1 + 3
  // texels in 61): most charts are one texel; they keep their UV area, winding and padding.
  unwrap_options crowded;
  crowded.page_size = 64;
  crowded.padding = 3;
  const unwrap_result rc = of(many_boxes(30)).unwrap(crowded);
  CHECK(rc.stats.texels_per_unit > 0.0f);
  check_layout(of(many_boxes(30)), rc, crowded.page_size, crowded.padding);
  // Boxes: every face of every box is a planar chart of its own (90 degrees apart).
  const unwrap_result boxes = of(many_boxes(30)).unwrap(o);
  CHECK(boxes.stats.charts == 30 * 5 + 1);
  CHECK(boxes.stats.planar_charts == boxes.stats.charts);
  CHECK(boxes.stats.stretch_l2 == Approx(1.0).margin(1e-4));
}

TEST_CASE("unwrap: vertices at the same position weld, whatever their indices", "[unwrap]") {
  // The same meshes with every triangle's own three vertices: the same charts (a box's faces, one
  // cylinder patch), not one chart per triangle.
  unwrap_options o;
  o.page_size = 256;
  const plain_mesh patch = unshared(cylinder_patch(1.0, 2.0, 80.0, 12, 4));
  const unwrap_result r = patch.unwrap(o);
  CHECK(r.stats.charts == 1);
  CHECK(r.stats.stretch_l2 == Approx(1.0).margin(1e-4));
  check_layout(patch, r, o.page_size, o.padding);
  const plain_mesh box = unshared(of(many_boxes(1)));
  const unwrap_result rb = box.unwrap(o);
  CHECK(rb.stats.charts == 6);
  // Each input vertex appears once per chart that uses it: here every input vertex has one chart.
  CHECK(rb.uvs.size() == box.positions.size());
  // -0 and +0 weld too.
  plain_mesh signs;
  signs.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {-0.0f, 1, 0}};
  signs.indices = {0, 1, 2, 3, 4, 5};
  CHECK(signs.unwrap(o).stats.charts == 1);
}

TEST_CASE("unwrap: degenerate triangles join no chart and get no UV area", "[unwrap]") {
  // A floor grid with a collinear sliver along an edge, a zero-length edge and a point, plus one
  // degenerate triangle far from everything.
  scene_mesh g;
  g.add_grid({0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}, 4, 4, material{});
  plain_mesh m = of(g);
  const auto add = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    const auto base = std::uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), {a, b, c});
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
  };
  add({0, 0, 0}, {0.125f, 0, 0}, {0.25f, 0, 0});
  add({0.5f, 0, 0.5f}, {0.5f, 0, 0.5f}, {0.75f, 0, 0.5f});
  add({0.5f, 0, 0.5f}, {0.5f, 0, 0.5f}, {0.5f, 0, 0.5f});
  add({9, 9, 9}, {9, 9, 9}, {10, 9, 9});
  unwrap_options o;
  o.page_size = 64;
  const unwrap_result r = m.unwrap(o);
  CHECK(r.stats.degenerate_triangles == 4);
  CHECK(r.stats.charts == 1);
  for (std::size_t t = 32; t < 36; ++t) {
    CHECK(std::fabs(uv_area2(r, t, o.page_size)) < 1e-3);  // collapsed onto a chart (rounding of float UVs)
    CHECK(r.triangle_page[t] == 0);
  }
  CHECK(r.triangle_chart[35] == unwrap_result::no_chart);
  CHECK(r.triangle_chart[32] == 0);
  check_layout(m, r, o.page_size, o.padding);
  // Only degenerate triangles: nothing to chart, one page, UVs at the origin.
  plain_mesh junk;
  junk.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  junk.indices = {0, 1, 2};
  const unwrap_result rj = junk.unwrap(o);
  CHECK(rj.stats.charts == 0);
  CHECK(rj.stats.pages == 1);
  CHECK(rj.uvs == std::vector<glm::vec2>(3, glm::vec2(0.0f)));
  CHECK(plain_mesh{}.unwrap(o).uvs.empty());
}

TEST_CASE("unwrap: a fixed texel density spills into pages, each laid out like one", "[unwrap]") {
  // 200 boxes at 2 texels per metre in 128^2 pages: more than one page (the ground alone, 42 m
  // wide, takes 85^2 texels; 1000 box faces of 1 to 4 texels with their padding about as much);
  // every triangle at the density asked (UV area / 3D area = 4; float UVs: 1e-3).
  const plain_mesh m = of(many_boxes(200));
  unwrap_options o;
  o.page_size = 128;
  o.texels_per_unit = 2.0f;
  const unwrap_result r = m.unwrap(o);
  CHECK(r.stats.pages > 1);
  CHECK(r.stats.texels_per_unit == 2.0f);
  for (std::uint32_t page : r.triangle_page) CHECK(int(page) < r.stats.pages);
  const auto [lo, hi] = density_range(m, r, o.page_size);
  CHECK(lo == Approx(4.0).epsilon(1e-3));
  CHECK(hi == Approx(4.0).epsilon(1e-3));
  check_layout(m, r, o.page_size, o.padding);
  o.max_pages = 1;
  test::require_error([&] { m.unwrap(o); }, status::invalid_argument, "the charts need more than max_pages = 1 pages");
  // A chart larger than a page is split into pieces that fit (a 200 x 50 m grid at 2 texels per
  // metre: 400 texels wide); a triangle larger than a page cannot be.
  scene_mesh wide;
  wide.add_grid({0, 0, 0}, {0, 0, 50}, {200, 0, 50}, {200, 0, 0}, 40, 10, material{});
  o.max_pages = 64;
  const unwrap_result rw = of(wide).unwrap(o);
  CHECK(rw.stats.charts >= 4);
  CHECK(rw.stats.planar_charts == rw.stats.charts);
  check_layout(of(wide), rw, o.page_size, o.padding);
  plain_mesh big;
  big.positions = {{0, 0, 0}, {100, 0, 0}, {0, 100, 0}};
  big.indices = {0, 1, 2};
  test::require_error([&] { big.unwrap(o); }, status::invalid_argument, "unwrap_lightmap: triangle 0 is");
}

TEST_CASE("unwrap: the same bytes for every run and thread count", "[unwrap]") {
  const plain_mesh m = of(heightfield(20000));
  unwrap_options o;
  o.page_size = 512;
  o.thread_count = 1;
  const unwrap_result a = m.unwrap(o);
  o.thread_count = 2;
  const unwrap_result b = m.unwrap(o), c = m.unwrap(o);
  CHECK(a.stats.charts > 1);
  for (const unwrap_result* x : {&b, &c}) {
    CHECK(x->vertex_source == a.vertex_source);
    CHECK(x->indices == a.indices);
    CHECK(x->triangle_page == a.triangle_page);
    CHECK(x->triangle_chart == a.triangle_chart);
    CHECK(std::memcmp(x->uvs.data(), a.uvs.data(), a.uvs.size() * sizeof(glm::vec2)) == 0);
  }
}

TEST_CASE("unwrap: bad options and input name the field or the index, and change nothing", "[unwrap]") {
  const plain_mesh m = of(cornell_box());
  const auto fails = [&](const unwrap_options& o, const std::string& needle) {
    test::require_error([&] { m.unwrap(o); }, status::invalid_argument, needle);
  };
  unwrap_options o;
  o.page_size = 8;
  fails(o, "unwrap_lightmap: options: page_size 8 is not in [16, 8192]");
  o = {};
  o.padding = 300;
  fails(o, "padding 300 is not in [0, 64]");
  o = {};
  o.texels_per_unit = -1.0f;
  fails(o, "texels_per_unit -1.000000 must be finite and >= 0");
  o = {};
  o.max_chart_angle = 95.0f;
  fails(o, "max_chart_angle 95.000000 is not in [1, 89]");
  o = {};
  o.max_pages = 0;
  fails(o, "max_pages 0 is not in [1, 4096]");
  o = {};
  plain_mesh bad = m;
  bad.positions[4].y = std::nanf("");
  test::require_error([&] { bad.unwrap(o); }, status::invalid_argument, "unwrap_lightmap: positions[4].y is nan");
  bad = m;
  bad.indices[17] = 900;
  test::require_error([&] { bad.unwrap(o); }, status::invalid_argument, "indices[17] = 900 is out of range");
  test::require_error([&] { unwrap_lightmap(nullptr, 3, m.indices.data(), 1, o); }, status::invalid_argument,
                      "positions is null with vertex_count 3");
  // Too many charts for one page even at a texel each.
  o.page_size = 16;
  o.padding = 3;
  test::require_error([&] { of(many_boxes(30)).unwrap(o); }, status::invalid_argument, "do not fit one page of 16 x 16 texels");
  // generate_lightmap_uvs leaves the mesh as it was on error.
  scene_mesh sm = many_boxes(30);
  const scene_mesh before = sm;
  test::require_error([&] { generate_lightmap_uvs(sm, o); }, status::invalid_argument, "do not fit");
  CHECK(sm.positions == before.positions);
  CHECK(sm.indices == before.indices);
}

TEST_CASE("unwrap: generate_lightmap_uvs gives a mesh the baker bakes without overlaps", "[unwrap][bake]") {
  scene_mesh room = hexagon_room(2);
  const std::size_t triangles = room.triangle_count();
  unwrap_options o;
  o.page_size = 64;
  const unwrap_result r = generate_lightmap_uvs(room, o);
  REQUIRE(room.triangle_count() == triangles);
  REQUIRE(room.lightmap_uvs.size() == room.positions.size());
  bake_input in;
  in.scene = room.desc();
  const lightmap_samples s = compute_lightmap_samples(in, o.page_size, o.page_size);
  CHECK(s.overlapping_texels == 0);
  CHECK(s.no_uv_area_triangles == 0);
  std::size_t covered = 0;
  for (float c : s.coverage) covered += c > 0.0f ? 1 : 0;
  CHECK(double(covered) > 0.5 * o.page_size * o.page_size);  // most of the page holds texels
  CHECK(r.stats.pages == 1);
}
