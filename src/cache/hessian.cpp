// Second-order terms of the cache: the Hessian fit (hessian.hpp, fit_record_hessians in cache.hpp).
#include "hessian.hpp"

#include "record_index.hpp"
#include "weights.hpp"

#include "hemilight/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace hemilight {

namespace cache_detail {

// Second-order terms (fit_record_hessians in cache.hpp). For record i, in its tangent frame
// (t, b): the symmetric H2 = [[h11, h12], [h12, h22]] that best maps the neighbours' offsets
// (dt, db) to their gradient differences (per channel), two equations per neighbour:
//     h11 dt + h12 db = dg.t,   h12 dt + h22 db = dg.b.
// The normal matrix depends only on the offsets, so the three channels share it.
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
    for (std::size_t i = b; i < e; ++i) {
      const cache_record& ri = records[i];
      const frame f = make_frame(ri.normal);
      near.clear();
      grid.for_each_in_sphere(ri.position, 2.0f * o.error_threshold * ri.radius, [&](std::uint32_t j) {
        if (j != i && glm::dot(ri.normal, records[j].normal) > 0.95f) near.push_back(j);
      });
      if (near.size() < 2) continue;
      std::sort(near.begin(), near.end());  // a fixed summation order, whatever the grid's
      double m[3][3] = {}, rhs[3][3] = {};  // normal matrix; right-hand side per channel
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
          rhs[c][0] += dt * gt;
          rhs[c][1] += db * gt + dt * gb;
          rhs[c][2] += db * gb;
        }
      }
      m[1][0] = m[0][1];
      m[2][1] = m[1][2];
      const double ridge = 1e-6 * (m[0][0] + m[1][1] + m[2][2]);
      for (int k = 0; k < 3; ++k) m[k][k] += ridge;
      // Solve by the adjugate (m is symmetric positive definite with the ridge).
      const double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1], c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2],
                   c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
      const double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
      if (!(det > 0.0)) continue;
      const double inv[3][3] = {{c00 / det, (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det, (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det},
                                {c01 / det, (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det, (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det},
                                {c02 / det, (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det, (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det}};
      // What the first-order prediction misses at each neighbour (the scale's data, below).
      miss.clear();
      for (std::uint32_t j : near) miss.push_back(records[j].irradiance - extrapolate(ri, records[j].position, records[j].normal, 1));
      for (glm::length_t c = 0; c < 3; ++c) {
        double h[3];
        for (int k = 0; k < 3; ++k) h[k] = inv[k][0] * rhs[c][0] + inv[k][1] * rhs[c][1] + inv[k][2] * rhs[c][2];
        // Scale s in [0, 1]: the least-squares factor of the quadratic term in the neighbours'
        // irradiance beyond the first-order prediction (data the fit above did not use).
        double rq = 0.0, qq = 0.0;
        for (std::size_t k = 0; k < near.size(); ++k) {
          const glm::vec3 d = records[near[k]].position - ri.position;
          const double dt = glm::dot(d, f.t), db = glm::dot(d, f.b);
          const double q = 0.5 * (h[0] * dt * dt + 2.0 * h[1] * dt * db + h[2] * db * db);
          const double r = miss[k][c];
          rq += r * q;
          qq += q * q;
        }
        const double s = qq > 0.0 ? std::clamp(rq / qq, 0.0, 1.0) : 0.0;
        if (!(s > 0.0) || !std::isfinite(s * (std::fabs(h[0]) + std::fabs(h[1]) + std::fabs(h[2])))) continue;
        // World space: H = s T H2 T^T with T = [t b] (glm is column-major: hm[col][row]).
        glm::mat3 hm(0.0f);
        for (int p = 0; p < 3; ++p)
          for (int q = 0; q < 3; ++q)
            hm[q][p] = float(s * (h[0] * f.t[p] * f.t[q] + h[1] * (f.t[p] * f.b[q] + f.b[p] * f.t[q]) + h[2] * f.b[p] * f.b[q]));
        fitted[i][std::size_t(c)] = hm;
      }
    }
  });
  for (std::size_t i = 0; i < count; ++i) records[i].hessian = fitted[i];
}

}  // namespace cache_detail

void fit_record_hessians(std::vector<cache_record>& records, const cache_options& o) {
  if (!(o.error_threshold >= min_error_threshold && o.error_threshold <= 1.0f))
    throw_invalid_argument("fit_record_hessians: options.error_threshold is " + std::to_string(o.error_threshold) +
                           "; it must be in [0.001, 1]");
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
  cache_detail::fit_hessians(records, o, resolve_thread_count(o.thread_count));
}

}  // namespace hemilight
