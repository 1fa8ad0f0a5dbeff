// Step 3 of the unwrapper (unwrap_internal.hpp): parameterize_charts, as the chain
// chart_vertices -> project_chart (planar) | solve_lscm (curved) -> split_flipped_charts.
#include "unwrap_internal.hpp"

#include "hemilight/parallel.hpp"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>

namespace hemilight::unwrap_detail {

namespace {

// One chart's vertices (welded, increasing) and UVs, as a worker makes them.
struct chart_map {
  std::vector<std::uint32_t> vertex;
  std::vector<glm::dvec2> uv;
  bool flipped = false;  // the conformal map turned a triangle over: the chart is split
};

// An orthonormal basis (t, b) of the plane of unit normal n, (t, b, n) right-handed, in double.
void plane_basis(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
  const glm::dvec3 axis = std::fabs(n.x) < 0.6 ? glm::dvec3(1, 0, 0) : (std::fabs(n.y) < 0.6 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1));
  t = glm::normalize(glm::cross(axis, n));
  b = glm::cross(n, t);
}

// The chart's welded vertices, increasing, and each corner's index among them (3 per triangle).
void chart_vertices(const mesh_view& m, const welded_mesh& w, const std::uint32_t* tris, std::size_t count,
                    std::vector<std::uint32_t>& vertex, std::vector<std::uint32_t>& corner) {
  vertex.clear();
  for (std::size_t i = 0; i < count; ++i)
    for (int k = 0; k < 3; ++k) vertex.push_back(w.welded(m, tris[i], k));
  std::sort(vertex.begin(), vertex.end());
  vertex.erase(std::unique(vertex.begin(), vertex.end()), vertex.end());
  corner.resize(3 * count);
  for (std::size_t i = 0; i < count; ++i)
    for (int k = 0; k < 3; ++k)
      corner[3 * i + std::size_t(k)] =
          std::uint32_t(std::lower_bound(vertex.begin(), vertex.end(), w.welded(m, tris[i], k)) - vertex.begin());
}

// The position of each chart vertex (any input vertex welded to it: they are bit-identical).
std::vector<glm::dvec3> vertex_positions(const mesh_view& m, const welded_mesh& w, const std::uint32_t* tris, std::size_t count,
                                         const std::vector<std::uint32_t>& corner, std::size_t n) {
  std::vector<glm::dvec3> p(n);
  for (std::size_t i = 0; i < count; ++i)
    for (int k = 0; k < 3; ++k) p[corner[3 * i + std::size_t(k)]] = m.corner(tris[i], k);
  (void)w;
  return p;
}

// Orthographic projection onto the plane of normal n, relative to the first vertex: an isometry
// of a planar chart.
void project_chart(const std::vector<glm::dvec3>& p, const glm::dvec3& n, std::vector<glm::dvec2>& uv) {
  glm::dvec3 t, b;
  plane_basis(n, t, b);
  uv.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) uv[i] = glm::dvec2(glm::dot(p[i] - p[0], t), glm::dot(p[i] - p[0], b));
}

double signed_area(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  return 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
}

// Least-squares conformal map (Levy et al. 2002): per triangle, in its own plane, the
// Cauchy-Riemann residuals of (u, v), weighted by sqrt(area); two vertices pinned at their
// projections onto the chart's mean plane (the extremes along its wider axis). Solved on the
// normal equations by Eigen's SimplicialLDLT. Returns false if the solve fails.
bool solve_lscm(const std::vector<glm::dvec3>& p, const std::vector<std::uint32_t>& corner, const glm::dvec3& n,
                std::vector<glm::dvec2>& uv) {
  const std::size_t V = p.size(), T = corner.size() / 3;
  std::vector<glm::dvec2> proj;
  project_chart(p, n, proj);
  glm::dvec2 lo = proj[0], hi = proj[0];
  for (const glm::dvec2& q : proj) lo = glm::min(lo, q), hi = glm::max(hi, q);
  const int axis = hi.x - lo.x >= hi.y - lo.y ? 0 : 1;
  std::size_t pin[2] = {0, 0};
  for (std::size_t i = 0; i < V; ++i) {
    if (proj[i][axis] < proj[pin[0]][axis]) pin[0] = i;
    if (proj[i][axis] > proj[pin[1]][axis]) pin[1] = i;
  }
  if (pin[0] == pin[1]) return false;
  std::vector<std::ptrdiff_t> column(V, -1);  // the unknown u of vertex i is column 2 c, v is 2 c + 1
  std::ptrdiff_t free_count = 0;
  for (std::size_t i = 0; i < V; ++i)
    if (i != pin[0] && i != pin[1]) column[i] = free_count++;
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(12 * T);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(Eigen::Index(2 * T));
  for (std::size_t t = 0; t < T; ++t) {
    const std::uint32_t* c = &corner[3 * t];
    // The triangle in its own plane: corner 0 at the origin, corner 1 on +x, counter-clockwise.
    const glm::dvec3 e1 = p[c[1]] - p[c[0]], e2 = p[c[2]] - p[c[0]];
    const glm::dvec3 x = glm::normalize(e1), y = glm::normalize(glm::cross(glm::cross(e1, e2), e1));
    const glm::dvec2 q[3] = {{0.0, 0.0}, {glm::length(e1), 0.0}, {glm::dot(e2, x), glm::dot(e2, y)}};
    const double area = signed_area(q[0], q[1], q[2]);
    if (!(area > 0.0)) continue;  // below double precision: no constraint
    const double scale = 1.0 / (2.0 * std::sqrt(area));
    const auto row = Eigen::Index(2 * t);
    for (int k = 0; k < 3; ++k) {
      const glm::dvec2 e = q[(k + 2) % 3] - q[(k + 1) % 3];  // the edge opposite corner k
      // u_x - v_y = sum(-e.y u_k - e.x v_k), u_y + v_x = sum(e.x u_k - e.y v_k), over 2 area.
      const double cu[2] = {-e.y * scale, e.x * scale}, cv[2] = {-e.x * scale, -e.y * scale};
      const std::size_t i = c[k];
      for (int r = 0; r < 2; ++r) {
        if (column[i] >= 0) {
          entries.emplace_back(row + r, Eigen::Index(2 * column[i]), cu[r]);
          entries.emplace_back(row + r, Eigen::Index(2 * column[i] + 1), cv[r]);
        } else {
          rhs[row + r] -= cu[r] * proj[i].x + cv[r] * proj[i].y;
        }
      }
    }
  }
  Eigen::SparseMatrix<double> a(Eigen::Index(2 * T), Eigen::Index(2 * free_count));
  a.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SparseMatrix<double> at = a.transpose();
  const Eigen::SparseMatrix<double> ata = at * a;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(ata);
  if (solver.info() != Eigen::Success) return false;
  const Eigen::VectorXd x = solver.solve(at * rhs);
  if (solver.info() != Eigen::Success) return false;
  uv.resize(V);
  for (std::size_t i = 0; i < V; ++i)
    uv[i] = column[i] < 0 ? proj[i] : glm::dvec2(x[Eigen::Index(2 * column[i])], x[Eigen::Index(2 * column[i] + 1)]);
  return true;
}

// A curved chart's map scaled so that its UV area equals its 3D area; false if a triangle is
// turned over or lost its area, or a value is not finite.
bool check_and_scale(const std::vector<glm::dvec3>& p, const std::vector<std::uint32_t>& corner, std::vector<glm::dvec2>& uv) {
  double area3 = 0.0, area2 = 0.0;
  for (std::size_t t = 0; t < corner.size() / 3; ++t) {
    const std::uint32_t* c = &corner[3 * t];
    const double a = signed_area(uv[c[0]], uv[c[1]], uv[c[2]]);
    if (!(a > 0.0)) return false;
    area2 += a;
    area3 += 0.5 * glm::length(glm::cross(p[c[1]] - p[c[0]], p[c[2]] - p[c[0]]));
  }
  const double s = std::sqrt(area3 / area2);
  if (!std::isfinite(s)) return false;
  const glm::dvec2 origin = uv[0];
  for (glm::dvec2& q : uv) q = (q - origin) * s;
  return true;
}

// One chart's map: projection for a planar chart, else LSCM (flipped when it fails).
chart_map map_chart(const mesh_view& m, const welded_mesh& w, const chart_set& charts, std::size_t c) {
  chart_map out;
  const std::uint32_t* tris = charts.triangles.data() + charts.first[c];
  const std::size_t count = charts.first[c + 1] - charts.first[c];
  std::vector<std::uint32_t> corner;
  chart_vertices(m, w, tris, count, out.vertex, corner);
  const std::vector<glm::dvec3> p = vertex_positions(m, w, tris, count, corner, out.vertex.size());
  if (charts.planar[c]) {
    project_chart(p, charts.normal[c], out.uv);
    return out;
  }
  out.flipped = !solve_lscm(p, corner, charts.normal[c], out.uv) || !check_and_scale(p, corner, out.uv);
  return out;
}

// The charts with every flipped one replaced by its planar regions (in region order), each of
// which is projected; the others keep their maps.
void split_flipped_charts(const mesh_view& m, const welded_mesh& w, chart_set& charts, std::vector<chart_map>& maps) {
  if (std::none_of(maps.begin(), maps.end(), [](const chart_map& cm) { return cm.flipped; })) return;
  chart_set out;
  out.triangle_chart.assign(m.triangle_count, none);
  out.triangle_region = charts.triangle_region;
  std::vector<chart_map> out_maps;
  std::vector<std::uint32_t> tris;
  for (std::size_t c = 0; c < charts.size(); ++c) {
    const auto begin = charts.triangles.begin() + std::ptrdiff_t(charts.first[c]);
    const auto end = charts.triangles.begin() + std::ptrdiff_t(charts.first[c + 1]);
    if (!maps[c].flipped) {
      out.add(std::vector<std::uint32_t>(begin, end), charts.planar[c] != 0, charts.normal[c]);
      out_maps.push_back(std::move(maps[c]));
      continue;
    }
    std::vector<std::uint32_t> by_region(begin, end);
    std::stable_sort(by_region.begin(), by_region.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return charts.triangle_region[a] < charts.triangle_region[b]; });
    for (std::size_t i = 0; i < by_region.size();) {
      std::size_t j = i;
      glm::dvec3 sum(0.0);
      tris.clear();
      for (; j < by_region.size() && charts.triangle_region[by_region[j]] == charts.triangle_region[by_region[i]]; ++j) {
        tris.push_back(by_region[j]);
        sum += w.normal[by_region[j]] * w.area[by_region[j]];
      }
      out.add(tris, true, glm::normalize(sum));
      out_maps.push_back(map_chart(m, w, out, out.size() - 1));
      i = j;
    }
  }
  charts = std::move(out);
  maps = std::move(out_maps);
}

}  // namespace

chart_uvs parameterize_charts(const mesh_view& m, const welded_mesh& w, chart_set& charts, int thread_count) {
  std::vector<chart_map> maps(charts.size());
  parallel_for(charts.size(), thread_count, 16, [&](int, std::size_t begin, std::size_t end) {
    for (std::size_t c = begin; c < end; ++c) maps[c] = map_chart(m, w, charts, c);
  });
  split_flipped_charts(m, w, charts, maps);
  chart_uvs out;
  out.first.assign(1, 0);
  for (chart_map& cm : maps) {
    out.vertex.insert(out.vertex.end(), cm.vertex.begin(), cm.vertex.end());
    out.uv.insert(out.uv.end(), cm.uv.begin(), cm.uv.end());
    out.first.push_back(std::uint32_t(out.vertex.size()));
  }
  return out;
}

std::uint32_t chart_uvs::find(std::size_t c, std::uint32_t v) const {
  const auto begin = vertex.begin() + std::ptrdiff_t(first[c]), end = vertex.begin() + std::ptrdiff_t(first[c + 1]);
  const auto it = std::lower_bound(begin, end, v);
  return it != end && *it == v ? std::uint32_t(it - vertex.begin()) : none;
}

}  // namespace hemilight::unwrap_detail
