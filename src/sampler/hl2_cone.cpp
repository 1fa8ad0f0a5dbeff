// The HL2 cone: its per-texel quadrature weights, the projection of a hemicube onto them
// (hl2_cone.hpp), and the public rotate / evaluate / hl2_from_cone (sampler.hpp).
#include "hl2_cone.hpp"

#include "weighted_sums.hpp"

#include "../core/table_cache.hpp"

#include "hemilight/geometry.hpp"
#include "hemilight/integrate.hpp"

#include <algorithm>
#include <cmath>

namespace hemilight {

namespace sampler_detail {

namespace {

// Fourier cosine coefficients c_0..c_M of g(theta) = max(0, A + B cos theta), B >= 0, A >= 0.
void clamped_cosine_series(double a, double b, double (&c)[hl2_cone_order + 1]) {
  constexpr double pi = 3.14159265358979323846;
  for (double& v : c) v = 0.0;
  if (b <= a) {  // never clamped: the series is A + B cos theta
    c[0] = a;
    c[1] = b;
    return;
  }
  const double t0 = std::acos(-a / b);  // g > 0 for |theta| < t0
  c[0] = (a * t0 + b * std::sin(t0)) / pi;
  c[1] = 2.0 / pi * (a * std::sin(t0) + 0.5 * b * (t0 + 0.5 * std::sin(2.0 * t0)));
  for (int m = 2; m <= hl2_cone_order; ++m)
    c[m] = 2.0 / pi *
           (a * std::sin(m * t0) / m + 0.5 * b * (std::sin((m - 1) * t0) / (m - 1) + std::sin((m + 1) * t0) / (m + 1)));
}

// The weights of resolution n: exact (the texel's vector solid angle) where the whole texel is
// within 35.26 degrees of the normal, else the closed-form series of the clamped cosine
// integrated over 8 x 8 sub-rectangles with exact solid angles.
std::shared_ptr<const cone_weights> build_cone_weights(int n) {
  const double cos_a = 1.0 / std::sqrt(3.0), sin_a = std::sqrt(2.0 / 3.0);
  auto out = std::make_shared<cone_weights>();
  const std::size_t count = hemicube_texel_count(n);
  for (auto& v : out->w) v.assign(count, 0.0f);
  const auto table = integration_table::get(n);
  constexpr int sub = 8;
  const double step = 2.0 / n / sub;
  for (std::size_t i = 0; i < count; ++i) {
    double acc[hl2_cone_terms] = {};
    // Within 35.26 degrees of the normal (z >= sqrt2 |xy|) every b(phi) sees the whole texel:
    // integral of w . b(phi) over the texel = V . b(phi) exactly (V = vector solid angle).
    bool linear = true;
    for (const glm::dvec3& c : hemicube_texel_corners(n, i)) {
      const glm::dvec3 d = glm::normalize(c);
      linear = linear && d.z >= std::sqrt(2.0) * std::hypot(d.x, d.y);
    }
    if (linear) {
      acc[0] = cos_a * table->vz[i];
      acc[1] = sin_a * table->vx[i];
      acc[2] = sin_a * table->vy[i];
    } else {
      const hemicube_texel t = hemicube_texel_from_index(n, i);
      const glm::dvec2 lo = hemicube_texel_min_corner(n, t);
      for (int sy = 0; sy < sub; ++sy)
        for (int sx = 0; sx < sub; ++sx) {
          const double u0 = lo.x + sx * step, v0 = lo.y + sy * step;
          const double omega = std::fabs(rectangle_solid_angle(u0, v0, u0 + step, v0 + step));
          const glm::dvec3 d = glm::normalize(hemicube_face_point(t.face, u0 + 0.5 * step, v0 + 0.5 * step));
          double c[hl2_cone_order + 1];
          clamped_cosine_series(cos_a * std::max(d.z, 0.0), sin_a * std::hypot(d.x, d.y), c);
          const double psi = std::atan2(d.y, d.x);
          acc[0] += omega * c[0];
          for (int m = 1; m <= hl2_cone_order; ++m) {
            acc[2 * m - 1] += omega * c[m] * std::cos(m * psi);
            acc[2 * m] += omega * c[m] * std::sin(m * psi);
          }
        }
    }
    for (int k = 0; k < hl2_cone_terms; ++k) out->w[std::size_t(k)][i] = float(acc[k]);
  }
  return out;
}

}  // namespace

// The table of resolution n, in the process's table cache (table_cache.hpp, like
// integration_table::get).
std::shared_ptr<const cone_weights> make_cone_weights(int n) {
  return detail::cached_table<cone_weights>(detail::table_kind::cone_weights, n, [n] { return build_cone_weights(n); },
                                            [](const cone_weights& t) {
                                              std::size_t bytes = 0;
                                              for (const std::vector<float>& v : t.w) bytes += detail::vector_bytes(v);
                                              return bytes;
                                            });
}

hl2_cone project_hl2_cone(const hemicube_buffer& buffer, const cone_weights& weights, const glm::vec3& reference) {
  const std::size_t count = buffer.texel_count();
  const float* pr = buffer.channel(0);  // the buffer's radiance is planar (hemicube.hpp)
  const float* pg = buffer.channel(1);
  const float* pb = buffer.channel(2);
  double total[hl2_cone_terms][3] = {};
  for (std::size_t k = 0; k < std::size_t(hl2_cone_terms); ++k) weighted_sums(pr, pg, pb, weights.w[k].data(), count, total[k]);
  hl2_cone out;
  out.reference = reference;
  for (std::size_t k = 0; k < std::size_t(hl2_cone_terms); ++k)
    out.coefficients[k] = glm::vec3(float(total[k][0]), float(total[k][1]), float(total[k][2]));
  return out;
}

}  // namespace sampler_detail

hl2_cone rotate_hl2_cone(const hl2_cone& c, const glm::vec3& normal, const glm::vec3& reference) noexcept {
  const glm::vec3 r = reference - normal * glm::dot(normal, reference);
  const float delta = std::atan2(glm::dot(r, glm::cross(normal, c.reference)), glm::dot(r, c.reference));
  hl2_cone out;
  out.reference = reference;
  out.coefficients[0] = c.coefficients[0];
  for (int m = 1; m <= hl2_cone_order; ++m) {
    const float cm = std::cos(float(m) * delta), sm = std::sin(float(m) * delta);
    const glm::vec3 a = c.coefficients[std::size_t(2 * m - 1)], b = c.coefficients[std::size_t(2 * m)];
    out.coefficients[std::size_t(2 * m - 1)] = a * cm + b * sm;
    out.coefficients[std::size_t(2 * m)] = b * cm - a * sm;
  }
  return out;
}

glm::vec3 evaluate_hl2_cone(const hl2_cone& c, float phi) noexcept {
  glm::vec3 e = c.coefficients[0];
  for (int m = 1; m <= hl2_cone_order; ++m)
    e += c.coefficients[std::size_t(2 * m - 1)] * std::cos(float(m) * phi) + c.coefficients[std::size_t(2 * m)] * std::sin(float(m) * phi);
  return e;
}

std::array<glm::vec3, 3> hl2_from_cone(const hl2_cone& c, const frame& f) noexcept {
  const float two_thirds_pi = 2.09439510f;
  const float phi_t = std::atan2(glm::dot(f.t, glm::cross(f.n, c.reference)), glm::dot(f.t, c.reference));
  const float s = glm::dot(glm::cross(f.t, f.b), f.n) >= 0.0f ? 1.0f : -1.0f;
  const float beta[3] = {two_thirds_pi, -two_thirds_pi, 0.0f};  // azimuths of hl2 basis 0, 1, 2 in (t, b)
  std::array<glm::vec3, 3> out;
  for (std::size_t k = 0; k < 3; ++k) out[k] = glm::max(evaluate_hl2_cone(c, phi_t + s * beta[k]), glm::vec3(0.0f));
  return out;
}

}  // namespace hemilight
