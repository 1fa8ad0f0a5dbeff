// Second-order terms of the cache: the Hessian fit (hessian.hpp, fit_record_hessians in cache.hpp).
#include "fit_record_hessians.hpp"

#include "record_index.hpp"
#include "weights.hpp"

#include "hemilight/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace hemilight {

namespace cache_detail {

namespace {

// The least-squares system of one record's tangent-plane Hessian: the normal matrix (the three
// channels share it: it depends only on the offsets) with its ridge, and the right-hand side per
// channel.
struct hessian_system {
  double m[3][3] = {};
  double rhs[3][3] = {};
};

// For record ri, in its tangent frame f = (t, b): the symmetric H2 = [[h11, h12], [h12, h22]]
// that best maps the neighbours' offsets (dt, db) to their gradient differences (per channel),
// two equations per neighbour:
//     h11 dt + h12 db = dg.t,   h12 dt + h22 db = dg.b.
// Summed over `near` in its order; then a ridge of 1e-6 of the trace.
hessian_system normal_equations(const std::vector<cache_record>& records, const cache_record& ri, const frame& f,
                                const std::vector<std::uint32_t>& near) {
  hessian_system sys;
  double (&m)[3][3] = sys.m;
  for (std::uint32_t j : near) {
    const glm::vec3 d = records[j].position - ri.position;
    const double dt = glm::dot(d, f.t), db = glm::dot(d, f.b);
    m[0][0] += dt * dt;
    m[0][1] += dt * db;
    m[1][1] += dt * dt + db * db;
    m[1][2] += dt * db;
    m[2][2] += db * db;
    for (std::size_t c = 0; c < 3; ++c) {
      const glm::vec3 dg = records[j].translation_gradient[c] - ri.translation_gradient[c];
      const double gt = glm::dot(dg, f.t), gb = glm::dot(dg, f.b);
      sys.rhs[c][0] += dt * gt;
      sys.rhs[c][1] += db * gt + dt * gb;
      sys.rhs[c][2] += db * gb;
    }
  }
  m[1][0] = m[0][1];
  m[2][1] = m[1][2];
  const double ridge = 1e-6 * (m[0][0] + m[1][1] + m[2][2]);
  for (int k = 0; k < 3; ++k) m[k][k] += ridge;
  return sys;
}

// inv = m^-1 by the adjugate (m is symmetric positive definite with the ridge); false when the
// determinant is not positive (inv is then not written).
bool invert(const double (&m)[3][3], double (&inv)[3][3]) {
  const double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1], c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2],
               c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
  const double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
  if (!(det > 0.0)) return false;
  const double out[3][3] = {{c00 / det, (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det, (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det},
                            {c01 / det, (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det, (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det},
                            {c02 / det, (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det, (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det}};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) inv[r][c] = out[r][c];
  return true;
}

// Scale s in [0, 1] of channel c's tangent Hessian h: the least-squares factor of the quadratic
// term in the neighbours' irradiance beyond the first-order prediction (`miss`, per neighbour:
// data the fit did not use); 0 when the quadratic term is 0 everywhere.
double second_order_scale(const std::vector<cache_record>& records, const cache_record& ri, const frame& f,
                          const std::vector<std::uint32_t>& near, const std::vector<glm::vec3>& miss, glm::length_t c,
                          const double (&h)[3]) {
  double rq = 0.0, qq = 0.0;
  for (std::size_t k = 0; k < near.size(); ++k) {
    const glm::vec3 d = records[near[k]].position - ri.position;
    const double dt = glm::dot(d, f.t), db = glm::dot(d, f.b);
    const double q = 0.5 * (h[0] * dt * dt + 2.0 * h[1] * dt * db + h[2] * db * db);
    const double r = miss[k][c];
    rq += r * q;
    qq += q * q;
  }
  return qq > 0.0 ? std::clamp(rq / qq, 0.0, 1.0) : 0.0;
}

// World space: H = s T H2 T^T with T = [t b] (glm is column-major: hm[col][row]).
glm::mat3 world_hessian(const frame& f, double s, const double (&h)[3]) {
  glm::mat3 hm(0.0f);
  for (int p = 0; p < 3; ++p)
    for (int q = 0; q < 3; ++q)
      hm[q][p] = float(s * (h[0] * f.t[p] * f.t[q] + h[1] * (f.t[p] * f.b[q] + f.b[p] * f.t[q]) + h[2] * f.b[p] * f.b[q]));
  return hm;
}

// Record i's Hessians into `fitted` (channels left as they are where no fit holds): its
// neighbours within 2 a R_i with n_i . n_j > 0.95, in index order (a fixed summation order,
// whatever the grid's); at least 2 of them. `near` and `miss` are scratch.
void fit_record(const std::vector<cache_record>& records, const point_grid& grid, std::size_t i, const cache_options& o,
                std::vector<std::uint32_t>& near, std::vector<glm::vec3>& miss, std::array<glm::mat3, 3>& fitted) {
  const cache_record& ri = records[i];
  const frame f = make_frame(ri.normal);
  near.clear();
  grid.for_each_in_sphere(ri.position, 2.0f * o.error_threshold * ri.radius, [&](std::uint32_t j) {
    if (j != i && glm::dot(ri.normal, records[j].normal) > 0.95f) near.push_back(j);
  });
  if (near.size() < 2) return;
  std::sort(near.begin(), near.end());
  const hessian_system sys = normal_equations(records, ri, f, near);
  double inv[3][3];
  if (!invert(sys.m, inv)) return;
  // What the first-order prediction misses at each neighbour (the scale's data).
  miss.clear();
  for (std::uint32_t j : near) miss.push_back(records[j].irradiance - extrapolate(ri, records[j].position, records[j].normal, 1));
  for (glm::length_t c = 0; c < 3; ++c) {
    double h[3];
    for (int k = 0; k < 3; ++k) h[k] = inv[k][0] * sys.rhs[c][0] + inv[k][1] * sys.rhs[c][1] + inv[k][2] * sys.rhs[c][2];
    const double s = second_order_scale(records, ri, f, near, miss, c, h);
    if (!(s > 0.0) || !std::isfinite(s * (std::fabs(h[0]) + std::fabs(h[1]) + std::fabs(h[2])))) continue;
    fitted[std::size_t(c)] = world_hessian(f, s, h);
  }
}

}  // namespace

// Second-order terms (fit_record_hessians in cache.hpp): every record's fit (fit_record) in
// parallel, from the records as they were, then written back.
void fit_hessians(std::vector<cache_record>& records, const cache_options& o, int threads) {
  const std::size_t count = records.size();
  std::vector<glm::vec3> where(count);
  for (std::size_t i = 0; i < count; ++i) where[i] = records[i].position;
  point_grid grid;
  grid.build(where.data(), count);
  std::vector<std::array<glm::mat3, 3>> fitted(count);
  parallel_for(count, threads, 64, [&](int, std::size_t b, std::size_t e) {
    std::vector<std::uint32_t> near;
    std::vector<glm::vec3> miss;
    for (std::size_t i = b; i < e; ++i) fit_record(records, grid, i, o, near, miss, fitted[i]);
  });
  for (std::size_t i = 0; i < count; ++i) records[i].hessian = fitted[i];
}

}  // namespace cache_detail

void fit_record_hessians(std::vector<cache_record>& records, const cache_options& o, int thread_count) {
  if (!(o.error_threshold >= min_error_threshold && o.error_threshold <= 1.0f))
    throw_invalid_argument("fit_record_hessians: options.error_threshold is " + std::to_string(o.error_threshold) +
                           "; it must be in [0.001, 1]");
  if (thread_count < 0)
    throw_invalid_argument("fit_record_hessians: thread_count is " + std::to_string(thread_count) + "; it must be >= 0");
  for (std::size_t i = 0; i < records.size(); ++i) {
    const cache_record& r = records[i];
    const std::string which = "fit_record_hessians: record " + std::to_string(i);
    if (!(r.radius >= 0.0f) || !std::isfinite(r.radius))
      throw_invalid_argument(which + " has radius " + std::to_string(r.radius) + "; it must be finite and >= 0");
    if (!std::isfinite(r.position.x) || !std::isfinite(r.position.y) || !std::isfinite(r.position.z))
      throw_invalid_argument(which + " has position " + cache_detail::vec_str(r.position) + "; it must be finite");
    if (!(std::fabs(glm::length(r.normal) - 1.0f) <= 1e-3f))
      throw_invalid_argument(which + " has normal " + cache_detail::vec_str(r.normal) + "; it must have length 1 (within 1e-3)");
  }
  cache_detail::fit_hessians(records, o, resolve_thread_count(thread_count));
}

}  // namespace hemilight
