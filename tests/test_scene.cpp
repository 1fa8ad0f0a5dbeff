// Tests of scene.hpp and reference_scenes.hpp: validation messages, bounds, the BVH's invariants,
// and the reference scenes' documented sizes, winding and closedness. References: counts and
// closed forms written here, and edge-incidence counting done in the test.
#include "hemilight/reference_scenes.hpp"
#include "hemilight/scene.hpp"
#include "scene/scene_access.hpp"  // the SIMD vertex arrays (src/)

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <tuple>

using namespace hemilight;

namespace {

scene_mesh one_triangle() {
  scene_mesh m;
  m.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, material{glm::vec3(1.0f), glm::vec3(0.5f), false});
  return m;
}

void fails_with(const scene_desc& d, status code, const char* text) {
  try {
    (void)scene::create(d);
    FAIL("no error; expected " << text);
  } catch (const error& e) {
    CHECK(e.code() == code);
    CHECK_THAT(e.what(), Catch::Contains(text));
  }
}

glm::dvec3 normal_of(const scene_mesh& m, std::size_t i) {
  const glm::dvec3 a(m.positions[m.indices[3 * i]]), b(m.positions[m.indices[3 * i + 1]]), c(m.positions[m.indices[3 * i + 2]]);
  return glm::cross(b - a, c - a);
}

glm::dvec3 centroid_of(const scene_mesh& m, std::size_t i) {
  return (glm::dvec3(m.positions[m.indices[3 * i]]) + glm::dvec3(m.positions[m.indices[3 * i + 1]]) +
          glm::dvec3(m.positions[m.indices[3 * i + 2]])) / 3.0;
}

// Number of directed edges (by position, not index) without an opposite partner: 0 for a closed,
// consistently wound mesh without T-junctions.
std::size_t open_edges(const scene_mesh& m) {
  using key = std::tuple<float, float, float, float, float, float>;
  std::map<key, int> edges;
  for (std::size_t i = 0; i < m.triangle_count(); ++i)
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 a = m.positions[m.indices[3 * i + static_cast<std::size_t>(k)]];
      const glm::vec3 b = m.positions[m.indices[3 * i + static_cast<std::size_t>((k + 1) % 3)]];
      const key fwd{a.x, a.y, a.z, b.x, b.y, b.z}, rev{b.x, b.y, b.z, a.x, a.y, a.z};
      auto it = edges.find(rev);
      if (it != edges.end() && --it->second == 0)
        edges.erase(it);
      else if (it == edges.end())
        ++edges[fwd];
    }
  std::size_t open = 0;
  for (const auto& e : edges) open += static_cast<std::size_t>(e.second);
  return open;
}

}  // namespace

TEST_CASE("scene: validation names the argument and the index", "[scene]") {
  scene_mesh m = one_triangle();
  scene_desc d = m.desc();

  m.positions[1].y = std::numeric_limits<float>::quiet_NaN();
  fails_with(m.desc(), status::invalid_argument, "positions[1].y is nan");
  m.positions[1].y = 0;
  m.positions[2].z = -std::numeric_limits<float>::infinity();
  fails_with(m.desc(), status::invalid_argument, "positions[2].z is -inf");
  m.positions[2].z = 0;

  m.indices[2] = 900;
  fails_with(m.desc(), status::invalid_argument, "indices[2] = 900 is out of range: 3 vertices");
  m.indices[2] = 2;

  m.materials[0].emission.y = -1.0f;
  fails_with(m.desc(), status::invalid_argument, "materials[0].emission.g is -1");
  m.materials[0].emission.y = 0.0f;
  m.materials[0].albedo.z = std::numeric_limits<float>::quiet_NaN();
  fails_with(m.desc(), status::invalid_argument, "materials[0].albedo.b is nan");
  m.materials[0].albedo.z = 0.5f;
  m.sky_radiance.x = -0.5f;
  fails_with(m.desc(), status::invalid_argument, "sky_radiance.r is -0.5");
  m.sky_radiance.x = 0.0f;
  m.lightmap_uvs = {{0, 0}, {1, std::numeric_limits<float>::infinity()}, {0, 1}};
  fails_with(m.desc(), status::invalid_argument, "lightmap_uvs[1].v is inf");
  m.lightmap_uvs.clear();

  d = m.desc();
  d.positions = nullptr;
  fails_with(d, status::invalid_argument, "positions is null but vertex_count is 3");
  d = m.desc();
  d.indices = nullptr;
  fails_with(d, status::invalid_argument, "indices is null but triangle_count is 1");
  d = m.desc();
  d.triangle_count = std::numeric_limits<std::size_t>::max() / 2;  // 3 * count would overflow
  fails_with(d, status::out_of_memory, "triangle_count");
  d = m.desc();
  d.vertex_count = max_scene_elements + 1;
  fails_with(d, status::out_of_memory, "vertex_count");

  // Without materials every triangle is black and one-sided.
  d = m.desc();
  d.materials = nullptr;
  const auto s = scene::create(d);
  CHECK(s->triangle_material(0).emission == glm::vec3(0.0f));
  CHECK_FALSE(s->triangle_material(0).two_sided);
}

TEST_CASE("scene: bounds, size and an empty scene", "[scene]") {
  const auto s = scene::create(one_triangle().desc());
  CHECK(s->bounds_lo() == glm::vec3(0, 0, 0));
  CHECK(s->bounds_hi() == glm::vec3(1, 1, 0));
  CHECK(s->size() == Approx(std::sqrt(2.0)));
  CHECK(s->drawable_triangle_count() == 1);
  const auto e = scene::create(scene_desc{});
  CHECK(e->triangle_count() == 0);
  CHECK(e->size() == 0.0f);
  CHECK(e->bvh().empty());
}

TEST_CASE("scene: the BVH holds every drawable triangle once, inside its nodes' boxes", "[scene]") {
  for (const scene_mesh& m : {heightfield(2000), many_boxes(50), cornell_box()}) {
    const auto s = scene::create(m.desc());
    const auto& nodes = s->bvh();
    const auto& tris = s->triangles();
    REQUIRE(tris.size() == m.triangle_count());  // none of these has degenerate triangles
    std::vector<int> seen(tris.size(), 0);
    std::vector<std::pair<std::uint32_t, int>> stack{{0u, 0}};
    while (!stack.empty()) {
      const auto [ni, depth] = stack.back();
      stack.pop_back();
      REQUIRE(ni < nodes.size());
      REQUIRE(depth < 64);
      const bvh_node& node = nodes[ni];
      if (node.count == 0) {
        for (std::uint32_t c : {node.first, node.first + 1}) {
          REQUIRE(c < nodes.size());
          CHECK(glm::all(glm::lessThanEqual(node.lo, nodes[c].lo)));
          CHECK(glm::all(glm::greaterThanEqual(node.hi, nodes[c].hi)));
          stack.push_back({c, depth + 1});
        }
        continue;
      }
      CHECK(node.count <= scene::max_leaf_triangles);
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
        ++seen[k];
        for (const glm::vec3& v : {tris[k].v0, tris[k].v1, tris[k].v2}) {
          CHECK(glm::all(glm::lessThanEqual(node.lo, v)));
          CHECK(glm::all(glm::greaterThanEqual(node.hi, v)));
        }
      }
    }
    CHECK(std::count(seen.begin(), seen.end(), 1) == static_cast<std::ptrdiff_t>(seen.size()));
  }
}

TEST_CASE("reference scenes: sizes and triangle counts as documented", "[scene]") {
  CHECK(cornell_box().triangle_count() == 32);
  CHECK(hexagon_room(1).triangle_count() == 142);
  CHECK(hexagon_room(2).triangle_count() == 496);
  CHECK(hexagon_room(3).triangle_count() == 1062);
  CHECK(sky_and_occluders().triangle_count() == 42);
  CHECK(heightfield(10000).triangle_count() == 2 * 71 * 71);
  CHECK(many_boxes(100).triangle_count() == 1002);
  CHECK_THROWS_AS(hexagon_room(0), error);
  const auto c = scene::create(cornell_box().desc());
  CHECK(c->bounds_hi().x == Approx(0.556f));
  CHECK(c->bounds_hi().y == Approx(0.5488f));
  CHECK(c->bounds_hi().z == Approx(0.5592f));
  // Deterministic: two builds are identical.
  CHECK(many_boxes(30).positions == many_boxes(30).positions);
  CHECK(open_pavilion().triangle_count() == 708);
  const scene_mesh street = open_street();
  CHECK((street.triangle_count() - 2) % 12 == 0);
  CHECK(street.triangle_count() > 2 + 12 * 32);  // some buildings besides the 32 post boxes
  CHECK(street.positions == open_street().positions);
}

TEST_CASE("reference scenes: the open pavilion and street are closed solids that meet (every part closed, facing out)", "[scene]") {
  // Every part is a closed solid with outward faces: no open edge (the street's ground quad,
  // its two triangles, adds its four border edges), and each triangle faces away from its
  // part's inside (a point just behind it is inside some part; one just in front is not
  // necessarily outside, where parts meet).
  CHECK(open_edges(open_pavilion()) == 0);
  CHECK(open_edges(open_street()) == 4);
  // Outward faces: the signed volume (divergence theorem) is the sum of the parts' volumes,
  // positive: slabs 14 x 10 x 0.32 + 12 x 8 x 0.3 + 13 x 9 x 0.4 m, and 8 x three regular
  // octagonal prisms (area 2 sqrt2 r^2) of r = 0.35, 0.12, 0.25 m and heights 0.22, 3.2, 0.22 m.
  const scene_mesh m = open_pavilion();
  double volume = 0.0;
  for (std::size_t i = 0; i < m.triangle_count(); ++i) {
    const glm::dvec3 a(m.positions[m.indices[3 * i]]), b(m.positions[m.indices[3 * i + 1]]), c(m.positions[m.indices[3 * i + 2]]);
    volume += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  const double octagon = 2.0 * std::sqrt(2.0);
  const double expected = 14.0 * 10.0 * 0.32 + 12.0 * 8.0 * 0.3 + 13.0 * 9.0 * 0.4 +
                          8.0 * octagon * (0.35 * 0.35 * 0.22 + 0.12 * 0.12 * 3.2 + 0.25 * 0.25 * 0.22);
  CHECK(volume == Approx(expected).epsilon(1e-5));
}

TEST_CASE("reference scenes: rooms face inwards, boxes outwards, ground up", "[scene]") {
  {
    // Hexagon room: every triangle faces the room's axis (walls) or its middle height (floor up,
    // ceiling down), and the room is closed except for the window's four edges.
    const scene_mesh m = hexagon_room(2);
    for (std::size_t i = 0; i < m.triangle_count(); ++i) {
      const glm::dvec3 c = centroid_of(m, i);
      CHECK(glm::dot(normal_of(m, i), glm::dvec3(0, 1.5, 0) - c) > 0);
    }
    // Window hole: 4 sides of 2 cells' quads each... counted as directed edges without partner:
    // the hole's boundary has (2 t) segments on each side with t = 2.
    CHECK(open_edges(m) == 4 * 2);
  }
  {
    const scene_mesh m = cornell_box();
    const glm::dvec3 middle(0.278, 0.2744, 0.2796);
    std::size_t emitters = 0;
    for (std::size_t i = 0; i < m.triangle_count(); ++i) {
      const glm::dvec3 n = normal_of(m, i), c = centroid_of(m, i);
      if (i < 10) CHECK(glm::dot(n, middle - c) > 0);  // floor, ceiling, back, left, right face in
      if (m.materials[i].emission.x > 0) {
        ++emitters;
        CHECK(n.y < 0);  // the light faces down
      }
      if (i >= 12) {
        // Box faces point away from their box's vertical axis or up.
        // Triangles 12..21 are the short box, 22..31 the tall one (footprint centres below).
        const glm::dvec3 axis = i >= 22 ? glm::dvec3(0.3685, c.y, 0.35125) : glm::dvec3(0.1855, c.y, 0.169);
        CHECK((n.y > 0 || glm::dot(n, c - axis) > 0));
      }
    }
    CHECK(emitters == 2);
    CHECK(m.materials[6].albedo.x > m.materials[6].albedo.y);  // left wall (x = 0.556) is red
  }
  {
    const scene_mesh m = heightfield(500);
    for (std::size_t i = 0; i < m.triangle_count(); ++i) CHECK(normal_of(m, i).y > 0);
    const scene_mesh g = sky_and_occluders();
    CHECK(normal_of(g, 0).y > 0);
    scene_mesh box;
    box.add_box({-1, -2, -3}, {1, 2, 3}, material{}, true);
    CHECK(open_edges(box) == 0);
    for (std::size_t i = 0; i < box.triangle_count(); ++i) CHECK(glm::dot(normal_of(box, i), -centroid_of(box, i)) > 0);
  }
}

TEST_CASE("scene: emissions() holds each distinct emission once, bit for bit, and emission_index() points to it", "[scene]") {
  // Materials chosen here: a repeated emission, +0 and -0 (both valid, different bits), and an
  // emission that differs from another in the last bit of one channel.
  const float next = std::nextafter(1.0f, 2.0f);
  const std::vector<glm::vec3> emission = {{1, 2, 3}, {0, 0, 0}, {1, 2, 3}, {-0.0f, 0, 0}, {1, 2, next}, {0, 0, 0}};
  scene_mesh m;
  for (std::size_t i = 0; i < emission.size(); ++i) {
    const float x = static_cast<float>(i);
    m.add_triangle({x, 0, 0}, {x + 1, 0, 0}, {x, 1, 0}, material{emission[i], glm::vec3(0.5f), false});
  }
  m.add_triangle({0, 0, 0}, {0, 0, 0}, {1, 1, 1}, material{{7, 7, 7}, glm::vec3(0.0f), false});  // zero area: still indexed
  const auto s = scene::create(m.desc());
  const auto bits = [](const glm::vec3& v) {
    std::array<std::uint32_t, 3> b;
    std::memcpy(b.data(), &v, sizeof b);
    return b;
  };
  REQUIRE(s->emissions().size() == 5);  // (1,2,3), (0,0,0), (-0,0,0), (1,2,next), (7,7,7)
  for (std::size_t i = 0; i < s->triangle_count(); ++i) {
    REQUIRE(s->emission_index(i) < s->emissions().size());
    CHECK(bits(s->emissions()[s->emission_index(i)]) == bits(s->triangle_material(i).emission));
  }
  CHECK(s->emission_index(0) == s->emission_index(2));
  CHECK(s->emission_index(1) == s->emission_index(5));
  CHECK(s->emission_index(1) != s->emission_index(3));
  CHECK(s->emission_index(0) != s->emission_index(4));
}

TEST_CASE("scene: the SIMD vertex arrays (scene_access::vertex_coordinates) repeat triangles() per coordinate, padded by eight zeros", "[scene]") {
  for (const scene_mesh& m : {heightfield(500), cornell_box(), scene_mesh{}}) {
    const auto s = scene::create(m.desc());
    const auto& tris = s->triangles();
    for (int v = 0; v < 3; ++v)
      for (int a = 0; a < 3; ++a) {
        const float* c = detail::scene_access::vertex_coordinates(*s, v, a);
        for (std::size_t t = 0; t < tris.size(); ++t) {
          const glm::vec3& p = v == 0 ? tris[t].v0 : (v == 1 ? tris[t].v1 : tris[t].v2);
          REQUIRE(std::memcmp(&c[t], &p[a], sizeof(float)) == 0);
        }
        for (std::size_t t = tris.size(); t < tris.size() + 8; ++t) CHECK(c[t] == 0.0f);
      }
  }
}

// ---- degenerate triangles (is_degenerate_triangle) ---------------------------------------------

namespace {

// Exactly collinear points p + s d, moved by a rotation about an oblique axis and a translation
// in float, as a node transform in an exporter does: the result is collinear only up to the
// rounding of its coordinates.
std::array<glm::vec3, 3> collinear_after_transform(const glm::dvec3& p, const glm::dvec3& d, double s1, double s2, double s3) {
  const glm::dvec3 axis = glm::normalize(glm::dvec3(1, 2, 3));
  const double angle = 0.7;
  const auto rotate = [&](const glm::dvec3& v) {  // Rodrigues, in double, then rounded once
    return v * std::cos(angle) + glm::cross(axis, v) * std::sin(angle) + axis * glm::dot(axis, v) * (1.0 - std::cos(angle));
  };
  const glm::dvec3 t(12.5, -3.25, 40.0);
  return {glm::vec3(rotate(p + s1 * d) + t), glm::vec3(rotate(p + s2 * d) + t), glm::vec3(rotate(p + s3 * d) + t)};
}

}  // namespace

TEST_CASE("scene: degenerate triangles are those without area at float precision, and are never drawn", "[scene]") {
  const glm::vec3 o(0.0f), x(1.0f, 0.0f, 0.0f);
  CHECK(is_degenerate_triangle(o, o, x));                              // a zero-length edge
  CHECK(is_degenerate_triangle(o, o, o));                              // a point
  CHECK(is_degenerate_triangle(o, x, {0.5f, 0.0f, 0.0f}));            // exactly collinear
  CHECK(is_degenerate_triangle(o, x, {std::nanf(""), 0.0f, 0.0f}));  // non-finite: no area to use
  CHECK_FALSE(is_degenerate_triangle(o, x, {0.0f, 1.0f, 0.0f}));
  // A thin but real sliver: height 1e-6 with coordinates of magnitude 1, 4 ulps being 2.4e-7.
  CHECK_FALSE(is_degenerate_triangle(o, x, {0.5f, 1e-6f, 0.0f}));
  CHECK(is_degenerate_triangle(o, x, {0.5f, 2e-7f, 0.0f}));
  // Collinear triangles after a transform, at several sizes: degenerate here, although the
  // area-only rule (area < 1e-10 x longest edge^2) misses most of them, which is why the rule is
  // relative to the coordinates' precision (scene.hpp, degenerate_height_tolerance).
  int missed_by_area_rule = 0;
  for (int k = 0; k < 200; ++k) {
    const double size = std::pow(10.0, -2.0 + 4.0 * k / 199.0);  // 0.01 .. 100 units
    const auto t = collinear_after_transform(glm::dvec3(0.3 * k, -0.1 * k, 0.05 * k), glm::dvec3(0.6, 0.3, -0.2) * size, 0.0,
                                             0.37, 1.0);
    CHECK(is_degenerate_triangle(t[0], t[1], t[2]));
    const glm::dvec3 a(t[0]), b(t[1]), c(t[2]);
    const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
    const double longest2 = std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
    if (area >= 1e-10 * longest2) ++missed_by_area_rule;
  }
  CHECK(missed_by_area_rule > 100);
  // scene::create skips them: they are neither drawn nor hit.
  scene_mesh m;
  const material lit{glm::vec3(1.0f), glm::vec3(0.5f), false};
  const auto t = collinear_after_transform(glm::dvec3(1, 2, 3), glm::dvec3(0.5, 0.1, 0.2), 0.0, 0.5, 1.0);
  m.add_triangle(t[0], t[1], t[2], lit);
  m.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, lit);
  m.add_triangle({0, 0, 0}, {0, 0, 0}, {0, 1, 0}, lit);
  const auto s = scene::create(m.desc());
  CHECK(s->triangle_count() == 3);
  REQUIRE(s->drawable_triangle_count() == 1);
  CHECK(s->triangles()[0].index == 1);
}

TEST_CASE("scene: the reference scenes have no degenerate triangle (their drawn sets do not change with the rule)", "[scene]") {
  const scene_mesh scenes[] = {cornell_box(), hexagon_room(1), hexagon_room(3), sky_and_occluders(), heightfield(20000),
                               many_boxes(200), open_pavilion(), open_street(), hexagon_room_sunlit(2).mesh,
                               cornell_box_rect_light().mesh};
  for (const scene_mesh& m : scenes) {
    std::size_t degenerate = 0;
    for (std::size_t i = 0; i < m.triangle_count(); ++i)
      if (is_degenerate_triangle(m.positions[m.indices[3 * i]], m.positions[m.indices[3 * i + 1]], m.positions[m.indices[3 * i + 2]]))
        ++degenerate;
    CHECK(degenerate == 0);
    CHECK(scene::create(m.desc())->drawable_triangle_count() == m.triangle_count());
  }
}
