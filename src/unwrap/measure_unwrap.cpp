// Step 7 of the unwrapper (unwrap_internal.hpp): measure_unwrap, the stretch (Sander et al. 2001),
// seams and UV area of a result.
#include "unwrap_internal.hpp"

#include <algorithm>
#include <cmath>

namespace hemilight::unwrap_detail {

namespace {

// Sander et al.'s stretch of the map from parameter q (scene units) to surface p over one
// triangle: the squared L2 term (G^2 + g^2) / 2 and G, its larger singular value. False for a
// parameter triangle without positive area.
bool triangle_stretch(const glm::dvec2 (&q)[3], const glm::dvec3 (&p)[3], double& l2_squared, double& largest) {
  const double a2 = (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[2].x - q[0].x) * (q[1].y - q[0].y);  // twice the area
  if (!(a2 > 0.0)) return false;
  const glm::dvec3 ss = (p[0] * (q[1].y - q[2].y) + p[1] * (q[2].y - q[0].y) + p[2] * (q[0].y - q[1].y)) / a2;
  const glm::dvec3 st = (p[0] * (q[2].x - q[1].x) + p[1] * (q[0].x - q[2].x) + p[2] * (q[1].x - q[0].x)) / a2;
  const double a = glm::dot(ss, ss), b = glm::dot(ss, st), c = glm::dot(st, st);
  l2_squared = 0.5 * (a + c);
  largest = std::sqrt(0.5 * ((a + c) + std::sqrt((a - c) * (a - c) + 4.0 * b * b)));
  return true;
}

}  // namespace

void measure_unwrap(const mesh_view& m, const welded_mesh& w, const placement& p, int page_size, unwrap_result& out) {
  unwrap_stats& s = out.stats;
  const double texels_per_uv = double(page_size);
  double uv_area = 0.0, area3 = 0.0, area_param = 0.0, l2_sum = 0.0, linf = 0.0, seams = 0.0;
  for (std::size_t t = 0; t < m.triangle_count; ++t) {
    if (w.degenerate[t]) continue;
    glm::dvec2 q[3];
    glm::dvec3 pos[3];
    for (int k = 0; k < 3; ++k) {
      q[k] = glm::dvec2(out.uvs[out.indices[3 * t + std::size_t(k)]]) * texels_per_uv;
      pos[k] = m.corner(t, k);
    }
    const double a_texels = 0.5 * std::fabs((q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[2].x - q[0].x) * (q[1].y - q[0].y));
    uv_area += a_texels;
    double l2 = 0.0, g = 0.0;
    const glm::dvec2 qs[3] = {q[0] / p.density, q[1] / p.density, q[2] / p.density};
    if (p.density > 0.0 && triangle_stretch(qs, pos, l2, g)) {
      l2_sum += l2 * w.area[t];
      area3 += w.area[t];
      area_param += a_texels / (p.density * p.density);
      linf = std::max(linf, g);
    }
    // Seams: this edge's UV length where a triangle at the same welded edge lies in another chart.
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t self = std::uint32_t(3 * t + std::size_t(e));
      bool seam = false;
      for (std::uint32_t o = w.same_edge[self]; o != self && !seam; o = w.same_edge[o])
        seam = out.triangle_chart[o / 3] != out.triangle_chart[t];
      if (seam) seams += glm::length(q[(e + 1) % 3] - q[e]);
    }
  }
  s.uv_area_fraction = uv_area / (double(s.pages) * texels_per_uv * texels_per_uv);
  const double normalise = area3 > 0.0 ? std::sqrt(area_param / area3) : 1.0;
  s.stretch_l2 = area3 > 0.0 ? std::sqrt(l2_sum / area3) * normalise : 1.0;
  s.stretch_linf = area3 > 0.0 ? linf * normalise : 1.0;
  s.seam_texels = seams;
}

}  // namespace hemilight::unwrap_detail
