// Tests of geometry.hpp: hemicube layout and exact weights, GL cube faces, frames.
// References: closed forms (2 pi, pi, 4 pi / 6), the GL specification's face table written out
// here by hand, and Monte-Carlo-free numeric integration done independently in the test.
#include "hemilight/geometry.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <set>

using namespace hemilight;

namespace {
constexpr double pi = 3.14159265358979323846;
}

TEST_CASE("hemicube layout: index <-> (face, x, y) round-trips and covers 3 N^2 texels", "[geometry]") {
  for (int n : {2, 4, 6, 16, 64}) {
    REQUIRE(hemicube_texel_count(n) == std::size_t(3 * n * n));
    std::size_t expected = 0;
    for (int f = 0; f < hemicube_face_count; ++f) {
      const auto face = static_cast<hemicube_face>(f);
      REQUIRE(hemicube_face_offset(n, face) == expected);
      for (int y = 0; y < hemicube_face_height(n, face); ++y)
        for (int x = 0; x < n; ++x) {
          const std::size_t i = hemicube_texel_index(n, {face, x, y});
          REQUIRE(i == expected++);
          const hemicube_texel t = hemicube_texel_from_index(n, i);
          REQUIRE((t.face == face && t.x == x && t.y == y));
        }
    }
    REQUIRE(expected == hemicube_texel_count(n));
  }
}

TEST_CASE("hemicube layout: documented orientation of texel (0, 0) and of the rows", "[geometry]") {
  const int n = 8;
  // Top face texel (0, 0) is the corner (-1, -1); rows go towards +y.
  glm::vec3 d = hemicube_texel_direction(n, hemicube_texel_index(n, {hemicube_face::top, 0, 0}));
  CHECK((d.x < 0 && d.y < 0 && d.z > 0));
  d = hemicube_texel_direction(n, hemicube_texel_index(n, {hemicube_face::top, 0, n - 1}));
  CHECK((d.x < 0 && d.y > 0));
  // Side faces: row 0 at the horizon, columns along z x forward.
  struct expect { hemicube_face face; glm::vec3 forward, column; };
  for (const expect& e : {expect{hemicube_face::pos_x, {1, 0, 0}, {0, 1, 0}}, expect{hemicube_face::neg_x, {-1, 0, 0}, {0, -1, 0}},
                          expect{hemicube_face::pos_y, {0, 1, 0}, {-1, 0, 0}}, expect{hemicube_face::neg_y, {0, -1, 0}, {1, 0, 0}}}) {
    const glm::vec3 low = hemicube_texel_direction(n, hemicube_texel_index(n, {e.face, n - 1, 0}));
    const glm::vec3 high = hemicube_texel_direction(n, hemicube_texel_index(n, {e.face, n - 1, n / 2 - 1}));
    CHECK(glm::dot(low, e.forward) > 0.5f);
    CHECK(glm::dot(low, e.column) > 0.5f);  // last column lies towards +column
    CHECK(low.z < high.z);
    CHECK(low.z > 0.0f);
    CHECK(glm::cross(e.column, glm::vec3(0, 0, 1)) == e.forward);  // c x r = a
  }
}

TEST_CASE("rectangle solid angle: a full cube face is 4 pi / 6", "[geometry]") {
  CHECK(rectangle_solid_angle(-1, -1, 1, 1) == Approx(4 * pi / 6).epsilon(1e-14));
  // Half a face above the horizon: pi / 3, so 1 + 4 halves = 2 pi.
  CHECK(rectangle_solid_angle(-1, 0, 1, 1) == Approx(pi / 3).epsilon(1e-14));
}

TEST_CASE("hemicube weights: solid angles sum to 2 pi and projected solid angles to pi", "[geometry]") {
  // Tolerance 1e-6 relative (docs/conventions.md): the weights are exact in double and rounded to
  // float (relative error 6e-8 each); summed in double the rounding errors largely cancel.
  for (int n : {2, 4, 16, 64, 256, 1024}) {
    const auto table = hemicube_table::get(n);
    double sa = 0, psa = 0;
    for (std::size_t i = 0; i < table->size(); ++i) {
      REQUIRE(table->solid_angle()[i] > 0.0f);
      REQUIRE(table->projected_solid_angle()[i] > 0.0f);
      REQUIRE(table->projected_solid_angle()[i] < table->solid_angle()[i]);  // cos < 1 inside a texel
      sa += table->solid_angle()[i];
      psa += table->projected_solid_angle()[i];
    }
    INFO("N = " << n);
    CHECK(std::fabs(sa / (2 * pi) - 1) <= 1e-6);
    CHECK(std::fabs(psa / pi - 1) <= 1e-6);
  }
}

TEST_CASE("hemicube weights: projected solid angle matches numeric integration of cos(theta)", "[geometry]") {
  // Independent reference: midpoint rule on a 64 x 64 sub-grid of the texel of
  // cos(theta) dOmega = z / |p|^4 du dv on the face plane (p = a + u c + v r, |a| = 1), whose
  // error for smooth integrands over a tiny texel is ~1e-7 relative.
  const int n = 8;
  for (std::size_t i : {std::size_t(0), std::size_t(27), std::size_t(64), std::size_t(64 + 5), std::size_t(64 + 32 + 31),
                        std::size_t(191)}) {
    const hemicube_texel t = hemicube_texel_from_index(n, i);
    const glm::dvec2 c0 = hemicube_texel_min_corner(n, t);
    const double s = 2.0 / n;
    const int m = 64;
    double omega = 0, proj = 0;
    for (int a = 0; a < m; ++a)
      for (int b = 0; b < m; ++b) {
        const glm::dvec3 p = hemicube_face_point(t.face, c0.x + (a + 0.5) * s / m, c0.y + (b + 0.5) * s / m);
        const double r2 = glm::dot(p, p);
        const double dom = (s / m) * (s / m) / (r2 * std::sqrt(r2));  // dA cos(at plane) / r^2
        omega += dom;
        proj += dom * p.z / std::sqrt(r2);
      }
    INFO("texel " << i);
    CHECK(hemicube_texel_solid_angle(n, i) == Approx(omega).epsilon(1e-5));
    CHECK(hemicube_texel_projected_solid_angle(n, i) == Approx(proj).epsilon(1e-5));
  }
}

TEST_CASE("hemicube weights: symmetric under the 90 degree rotations and mirrors", "[geometry]") {
  // The weights are computed independently per texel from different corner coordinates, so the
  // symmetry is a property of the formulas, checked to float rounding (relative 1e-6).
  const int n = 16;
  const auto table = hemicube_table::get(n);
  const float* w = table->projected_solid_angle();
  const float* o = table->solid_angle();
  auto idx = [&](hemicube_face f, int x, int y) { return hemicube_texel_index(n, {f, x, y}); };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const std::size_t i = idx(hemicube_face::top, x, y);
      // 90 degree rotation of the top face: (x, y) -> (n-1-y, x); mirrors in x, in y, diagonal.
      for (std::size_t j : {idx(hemicube_face::top, n - 1 - y, x), idx(hemicube_face::top, n - 1 - x, y),
                            idx(hemicube_face::top, x, n - 1 - y), idx(hemicube_face::top, y, x)}) {
        CHECK(w[j] == Approx(w[i]).epsilon(1e-6));
        CHECK(o[j] == Approx(o[i]).epsilon(1e-6));
      }
    }
  for (int y = 0; y < n / 2; ++y)
    for (int x = 0; x < n; ++x) {
      const std::size_t i = idx(hemicube_face::pos_x, x, y);
      for (std::size_t j : {idx(hemicube_face::neg_x, x, y), idx(hemicube_face::pos_y, x, y),
                            idx(hemicube_face::neg_y, x, y), idx(hemicube_face::pos_x, n - 1 - x, y)}) {
        CHECK(w[j] == Approx(w[i]).epsilon(1e-6));
        CHECK(o[j] == Approx(o[i]).epsilon(1e-6));
      }
    }
  // Across the top/side border: the top row y = n-1 of the top face and the side face's upper
  // row mirror each other about the cube edge; their solid angles match (same plane distance).
  for (int x = 0; x < n; ++x)
    CHECK(o[idx(hemicube_face::top, x, n - 1)] == Approx(o[idx(hemicube_face::pos_y, n - 1 - x, n / 2 - 1)]).epsilon(1e-6));
}

TEST_CASE("hemicube table: shared per resolution, invalid resolutions rejected with a message", "[geometry]") {
  REQUIRE(hemicube_table::get(32).get() == hemicube_table::get(32).get());
  for (int bad : {0, 1, 3, -2, 4097, 4098, 8192}) {
    INFO("N = " << bad);
    CHECK_THROWS_MATCHES(hemicube_table::get(bad), error, Catch::Matchers::Predicate<error>([](const error& e) {
                           return e.code() == status::invalid_argument &&
                                  std::string(e.what()).find("even") != std::string::npos;
                         }));
  }
}

TEST_CASE("hemicube corners: the texel direction is inside the corners and weights agree", "[geometry]") {
  const int n = 6;
  for (std::size_t i = 0; i < hemicube_texel_count(n); ++i) {
    const auto c = hemicube_texel_corners(n, i);
    const glm::dvec3 d = glm::dvec3(hemicube_texel_direction(n, i));
    REQUIRE(std::fabs(glm::length(d) - 1.0) < 1e-6);
    REQUIRE(d.z > 0.0);
    for (std::size_t k = 0; k < 4; ++k) {  // d on the inner side of every edge plane (CCW seen from outside)
      REQUIRE(glm::dot(glm::cross(c[k], c[(k + 1) % 4]), d) > 0.0);
    }
  }
}

// ---------------------------------------------------------------------------------------------

namespace {
// The GL specification's table, written out independently of the code under test:
// face, major axis, sc, tc.
struct gl_row {
  cube_face face;
  glm::vec3 axis;
  int sc_axis; float sc_sign;
  int tc_axis; float tc_sign;
};
const gl_row gl_table[6] = {
    {cube_face::pos_x, {1, 0, 0}, 2, -1, 1, -1}, {cube_face::neg_x, {-1, 0, 0}, 2, +1, 1, -1},
    {cube_face::pos_y, {0, 1, 0}, 0, +1, 2, +1}, {cube_face::neg_y, {0, -1, 0}, 0, +1, 2, -1},
    {cube_face::pos_z, {0, 0, 1}, 0, +1, 1, -1}, {cube_face::neg_z, {0, 0, -1}, 0, -1, 1, -1},
};
}  // namespace

TEST_CASE("cube faces: the GL table on axis and off-axis directions", "[geometry]") {
  for (const gl_row& row : gl_table) {
    const cube_coord c = cube_face_from_direction(row.axis * 3.0f);
    CHECK(c.face == row.face);
    CHECK(c.s == 0.5f);
    CHECK(c.t == 0.5f);
    // An off-axis direction: major axis plus 0.25 and 0.5 of the two others.
    glm::vec3 d = row.axis;
    d[row.sc_axis] += 0.25f;
    d[row.tc_axis] += 0.5f;
    const cube_coord e = cube_face_from_direction(d);
    CHECK(e.face == row.face);
    CHECK(e.s == Approx(0.5 * (row.sc_sign * 0.25 + 1)));
    CHECK(e.t == Approx(0.5 * (row.tc_sign * 0.5 + 1)));
  }
}

TEST_CASE("cube faces: diagonal directions follow the documented tie rule x, then y, then z", "[geometry]") {
  for (float sx : {-1.f, 1.f})
    for (float sy : {-1.f, 1.f})
      for (float sz : {-1.f, 1.f}) {
        CHECK(cube_face_from_direction({sx, sy, sz}).face == (sx > 0 ? cube_face::pos_x : cube_face::neg_x));
        CHECK(cube_face_from_direction({0, sy, sz}).face == (sy > 0 ? cube_face::pos_y : cube_face::neg_y));
        CHECK(cube_face_from_direction({sx, 0, sz}).face == (sx > 0 ? cube_face::pos_x : cube_face::neg_x));
        const cube_coord c = cube_face_from_direction({sx, sy, sz});  // a corner: s, t in {0, 1}
        CHECK((c.s == 0.0f || c.s == 1.0f));
        CHECK((c.t == 0.0f || c.t == 1.0f));
      }
}

TEST_CASE("cube faces: direction -> face -> direction round-trips", "[geometry]") {
  std::mt19937 rng(7);
  std::normal_distribution<float> g;
  for (int k = 0; k < 20000; ++k) {
    const glm::vec3 d = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
    const cube_coord c = cube_face_from_direction(d);
    REQUIRE((c.s >= 0 && c.s <= 1 && c.t >= 0 && c.t <= 1));
    const glm::vec3 back = glm::normalize(cube_direction_from_face(c.face, c.s, c.t));
    REQUIRE(glm::length(back - d) < 1e-6f);
    // and face -> direction -> face on the same face
    const cube_coord again = cube_face_from_direction(back);
    REQUIRE(again.face == c.face);
  }
}

TEST_CASE("cube faces: zero and non-finite directions give a defined answer", "[geometry]") {
  for (glm::vec3 d : {glm::vec3(0.0f), glm::vec3(NAN, 0, 0), glm::vec3(INFINITY, 1, 0)}) {
    const cube_coord c = cube_face_from_direction(d);
    CHECK(c.face == cube_face::pos_x);
    CHECK(c.s == 0.5f);
    CHECK(c.t == 0.5f);
  }
}

TEST_CASE("frames: orthonormal and right-handed on a dense set of normals, poles included", "[geometry]") {
  std::vector<glm::vec3> normals = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
  for (float e : {1e-3f, 1e-5f, 1e-7f, 1e-9f, 1e-20f, 1e-38f})
    for (float sz : {-1.f, 1.f}) {
      normals.push_back(glm::normalize(glm::vec3(e, 0, sz)));
      normals.push_back(glm::normalize(glm::vec3(0, -e, sz)));
      normals.push_back(glm::normalize(glm::vec3(e, e, sz)));
      normals.push_back(glm::normalize(glm::vec3(1, 0, sz * e)));  // near the equator
      normals.push_back(glm::vec3(0, 0, sz) + glm::vec3(-0.0f));
    }
  normals.push_back({0, 0, -0.0f + 1.0f});
  normals.push_back({-0.0f, -0.0f, -1.0f});
  // 200 x 400 latitude-longitude grid
  for (int i = 0; i <= 200; ++i)
    for (int j = 0; j < 400; ++j) {
      const double th = pi * i / 200, ph = 2 * pi * j / 400;
      normals.push_back(glm::vec3(float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)), float(std::cos(th))));
    }
  for (const glm::vec3& n0 : normals) {
    const glm::vec3 n = n0 / glm::length(n0);
    const frame f = make_frame(n);
    INFO("n = " << n.x << " " << n.y << " " << n.z);
    REQUIRE(std::isfinite(f.t.x + f.t.y + f.t.z + f.b.x + f.b.y + f.b.z));
    REQUIRE(std::fabs(glm::length(f.t) - 1) < 1e-6f);
    REQUIRE(std::fabs(glm::length(f.b) - 1) < 1e-6f);
    REQUIRE(std::fabs(glm::dot(f.t, f.b)) < 1e-6f);
    REQUIRE(std::fabs(glm::dot(f.t, n)) < 1e-6f);
    REQUIRE(std::fabs(glm::dot(f.b, n)) < 1e-6f);
    REQUIRE(glm::length(glm::cross(f.t, f.b) - n) < 1e-6f);
    const glm::vec3 v(0.3f, -0.2f, 0.9f);
    REQUIRE(glm::length(f.to_local(f.to_world(v)) - v) < 1e-6f);
  }
}

TEST_CASE("frames: continuous inside each hemisphere", "[geometry]") {
  // Documented: continuous except across n.z = 0. A small step in n inside a hemisphere moves
  // t and b by a comparable amount (Lipschitz bound 4 is generous; a jump would be ~1).
  std::mt19937 rng(3);
  std::normal_distribution<float> g;
  for (int k = 0; k < 5000; ++k) {
    glm::vec3 n = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
    if (std::fabs(n.z) < 0.05f) continue;
    const glm::vec3 m = glm::normalize(n + 1e-3f * glm::vec3(g(rng), g(rng), g(rng)));
    if (m.z * n.z <= 0) continue;
    const frame a = make_frame(n), b = make_frame(m);
    const float dn = glm::length(n - m);
    REQUIRE(glm::length(a.t - b.t) <= 4 * dn / std::fabs(n.z) + 1e-5f);
  }
}
