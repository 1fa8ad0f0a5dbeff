// integration_table: the integrator's per-resolution weights, exact per texel (vector solid angle,
// projected solid angle, HL2 and SH weights) and per wall (gradient coefficients), computed in
// double and stored as float. See integrate.hpp and docs/integration.md.
#include "hemilight/integrate.hpp"

#include "hemilight/parallel.hpp"

#include "../core/table_cache.hpp"

#include <algorithm>
#include <cmath>

namespace hemilight {

namespace {

using dvec3 = glm::dvec3;

// Vector solid angle of a spherical polygon, integral of w dw: 1/2 sum beta_k gamma_k (Lambert).
// With hemicube corner order (c x r = a) it points out of the cube through the texel.
dvec3 vector_solid_angle(const std::array<dvec3, 4>& c) {
  dvec3 sum(0.0);
  for (std::size_t k = 0; k < 4; ++k) {
    const dvec3 x = glm::cross(c[k], c[(k + 1) % 4]);
    const double len = glm::length(x);
    if (len > 0.0) sum += std::atan2(len, glm::dot(c[k], c[(k + 1) % 4])) * x / len;
  }
  return 0.5 * sum;
}

dvec3 texel_centre(int n, std::size_t i) { return dvec3(hemicube_texel_direction(n, i)); }

struct wall_coefficients {
  glm::dvec2 great_arc{0.0};
  glm::dvec2 classified{0.0};
};

// Coefficients of the wall with unit end directions d0, d1 between texels with centres ca, cb.
wall_coefficients wall_between(const dvec3& d0, const dvec3& d1, const dvec3& ca, const dvec3& cb) {
  wall_coefficients out;
  const dvec3 x = glm::cross(d0, d1);
  const double sin_beta = glm::length(x);
  if (sin_beta == 0.0) return out;
  dvec3 m = x / sin_beta;
  if (glm::dot(m, cb - ca) < 0.0) m = -m;  // m points from texel a into texel b
  const double beta = std::atan2(sin_beta, glm::dot(d0, d1));  // arc length
  // Integral of cos(theta) = w.z along the great arc d(s) = d0 cos s + w sin s, s in [0, beta].
  const dvec3 w = glm::normalize(d1 - glm::dot(d0, d1) * d0);
  const double cos_integral = d0.z * std::sin(beta) + w.z * (1.0 - std::cos(beta));
  out.great_arc = glm::dvec2(m.x, m.y) * cos_integral;

  // Classified walls (Ward & Heckbert adapted): rate from the wall's latitude/longitude class
  // at its midpoint, direction normalize(m_t).
  const double mt = std::hypot(m.x, m.y);
  if (mt == 0.0) return out;
  const dvec3 mid = glm::normalize(d0 + d1);
  const double sin_theta = std::hypot(mid.x, mid.y);
  const double cos_theta = mid.z;
  bool longitude = false;  // the wall runs along a meridian (constant longitude)
  if (sin_theta > 1e-12) {
    const double cphi = mid.x / sin_theta, sphi = mid.y / sin_theta;
    const dvec3 theta_hat(cos_theta * cphi, cos_theta * sphi, -sin_theta);
    const dvec3 phi_hat(-sphi, cphi, 0.0);
    const dvec3 along = glm::normalize(d1 - d0);
    longitude = std::fabs(glm::dot(along, theta_hat)) > std::fabs(glm::dot(along, phi_hat));
  }
  const double rate = longitude ? 1.0 / sin_theta : cos_theta;
  out.classified = glm::dvec2(m.x, m.y) / mt * cos_integral * rate;
  return out;
}

constexpr double hl2_basis[3][3] = {
    {-0.40824829046386301637, 0.70710678118654752440, 0.57735026918962576451},
    {-0.40824829046386301637, -0.70710678118654752440, 0.57735026918962576451},
    {0.81649658092772603273, 0.0, 0.57735026918962576451},
};

// Sizes every per-texel entry for `count` texels, all zero.
void size_entries(integration_table& t, std::size_t count) {
  for (std::vector<float>* v : {&t.vx, &t.vy, &t.vz, &t.simple_x, &t.simple_y, &t.hl2[0], &t.hl2[1], &t.hl2[2],
                                &t.solid_angle, &t.right_great_arc_x, &t.right_great_arc_y, &t.up_great_arc_x,
                                &t.up_great_arc_y, &t.right_classified_x, &t.right_classified_y, &t.up_classified_x,
                                &t.up_classified_y})
    v->assign(count, 0.0f);
  t.extrapolation_neighbours.assign(count, 0);
}

// The entries of texel i: its weights, which neighbours the wall-depth extrapolation may use,
// and its walls inside the face, to the right (x + 1) and up (y + 1) neighbours.
void fill_texel(integration_table& t, int n, std::size_t i) {
  const double s = 2.0 / n;
  const std::size_t un = static_cast<std::size_t>(n);
  const std::array<dvec3, 4> corners = hemicube_texel_corners(n, i);
  const dvec3 v = vector_solid_angle(corners);
  t.vx[i] = static_cast<float>(v.x);
  t.vy[i] = static_cast<float>(v.y);
  t.vz[i] = static_cast<float>(v.z);
  const dvec3 c = texel_centre(n, i);
  t.simple_x[i] = static_cast<float>(3.0 * v.z * c.x);
  t.simple_y[i] = static_cast<float>(3.0 * v.z * c.y);
  for (int k = 0; k < 3; ++k) {
    const dvec3 b(hl2_basis[k][0], hl2_basis[k][1], hl2_basis[k][2]);
    t.hl2[k][i] = static_cast<float>(std::max(0.0, glm::dot(v, b)));
  }
  t.solid_angle[i] = static_cast<float>(hemicube_texel_solid_angle(n, i));

  const hemicube_texel tx = hemicube_texel_from_index(n, i);
  const int height = hemicube_face_height(n, tx.face);
  t.extrapolation_neighbours[i] = static_cast<std::uint8_t>((tx.x > 0 ? 1 : 0) | (tx.x + 2 < n ? 2 : 0) |
                                                            (tx.y > 0 ? 4 : 0) | (tx.y + 2 < height ? 8 : 0));
  const glm::dvec2 lo = hemicube_texel_min_corner(n, tx);
  auto point = [&](double u, double w) { return glm::normalize(hemicube_face_point(tx.face, u, w)); };
  if (tx.x + 1 < n) {
    const wall_coefficients w = wall_between(point(lo.x + s, lo.y), point(lo.x + s, lo.y + s), c, texel_centre(n, i + 1));
    t.right_great_arc_x[i] = static_cast<float>(w.great_arc.x);
    t.right_great_arc_y[i] = static_cast<float>(w.great_arc.y);
    t.right_classified_x[i] = static_cast<float>(w.classified.x);
    t.right_classified_y[i] = static_cast<float>(w.classified.y);
  }
  if (tx.y + 1 < hemicube_face_height(n, tx.face)) {
    const wall_coefficients w = wall_between(point(lo.x, lo.y + s), point(lo.x + s, lo.y + s), c, texel_centre(n, i + un));
    t.up_great_arc_x[i] = static_cast<float>(w.great_arc.x);
    t.up_great_arc_y[i] = static_cast<float>(w.great_arc.y);
    t.up_classified_x[i] = static_cast<float>(w.classified.x);
    t.up_classified_y[i] = static_cast<float>(w.classified.y);
  }
}

// Every texel's entries. Each depends on that texel alone: split over all cores for large tables
// (about 1 us per texel: N = 4096 took 50 s on one core), on the calling thread below 64k texels.
void fill_texels(integration_table& t, int n) {
  const std::size_t count = hemicube_texel_count(n);
  const int threads = count < (std::size_t(1) << 16) ? 1 : 0;
  parallel_for(count, threads, 4096, [&](int, std::size_t first, std::size_t last) {
    for (std::size_t i = first; i < last; ++i) fill_texel(t, n, i);
  });
}

// The 6 N walls across face borders, into t.border_walls: (1) each side face's top row meets the
// top face along z = 1; (2) neighbouring side faces (in the rotation order pos_x -> pos_y ->
// neg_x -> neg_y) meet along a vertical cube edge: column N-1 of one face and column 0 of the next.
void add_border_walls(integration_table& t, int n) {
  const double s = 2.0 / n;
  t.border_walls.reserve(6 * static_cast<std::size_t>(n));
  auto add_border = [&](std::size_t a, std::size_t b, const dvec3& p0, const dvec3& p1) {
    const wall_coefficients w = wall_between(glm::normalize(p0), glm::normalize(p1), texel_centre(n, a), texel_centre(n, b));
    t.border_walls.push_back({static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
                              {static_cast<float>(w.great_arc.x), static_cast<float>(w.great_arc.y)},
                              {static_cast<float>(w.classified.x), static_cast<float>(w.classified.y)}});
  };
  auto top_index = [&](double x, double y) {  // top-face texel containing (x, y, 1); edges clamp inward
    auto cell = [&](double c) { return std::clamp(static_cast<int>(std::floor((c + 1.0) / s)), 0, n - 1); };
    return hemicube_texel_index(n, {hemicube_face::top, cell(x), cell(y)});
  };
  const hemicube_face sides[4] = {hemicube_face::pos_x, hemicube_face::pos_y, hemicube_face::neg_x, hemicube_face::neg_y};
  for (hemicube_face f : sides) {  // (1)
    for (int x = 0; x < n; ++x) {
      const double u0 = -1.0 + s * x, u1 = u0 + s;
      const dvec3 p0 = hemicube_face_point(f, u0, 1.0), p1 = hemicube_face_point(f, u1, 1.0);
      const dvec3 mid = 0.5 * (p0 + p1);
      add_border(hemicube_texel_index(n, {f, x, n / 2 - 1}), top_index(mid.x, mid.y), p0, p1);
    }
  }
  for (int k = 0; k < 4; ++k) {  // (2)
    const hemicube_face f = sides[k], g = sides[(k + 1) % 4];
    for (int y = 0; y < n / 2; ++y) {
      const double v0 = s * y, v1 = v0 + s;
      add_border(hemicube_texel_index(n, {f, n - 1, y}), hemicube_texel_index(n, {g, 0, y}), hemicube_face_point(f, 1.0, v0),
                 hemicube_face_point(f, 1.0, v1));
    }
  }
}

}  // namespace

integration_table::integration_table(int n) : n_(n) {
  check_hemicube_resolution(n, "integration_table");
  size_entries(*this, hemicube_texel_count(n));
  fill_texels(*this, n);
  add_border_walls(*this, n);
}

std::shared_ptr<const integration_table> integration_table::get(int n) {
  if (!is_valid_hemicube_resolution(n)) return std::make_shared<const integration_table>(n);  // throws
  // Kept in the process's table cache (table_cache.hpp: LRU within the budget of memory.hpp).
  return detail::cached_table<integration_table>(
      detail::table_kind::integration, n, [n] { return std::make_shared<const integration_table>(n); },
      [](const integration_table& t) {
        std::size_t bytes = detail::vector_bytes(t.border_walls) + detail::vector_bytes(t.extrapolation_neighbours);
        for (const std::vector<float>* v :
             {&t.vx, &t.vy, &t.vz, &t.simple_x, &t.simple_y, &t.hl2[0], &t.hl2[1], &t.hl2[2], &t.solid_angle,
              &t.right_great_arc_x, &t.right_great_arc_y, &t.up_great_arc_x, &t.up_great_arc_y, &t.right_classified_x,
              &t.right_classified_y, &t.up_classified_x, &t.up_classified_y})
          bytes += detail::vector_bytes(*v);
        return bytes;
      });
}

}  // namespace hemilight
