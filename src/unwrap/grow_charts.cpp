// Step 2 of the unwrapper (unwrap_internal.hpp): grow_charts, as the chain planar_regions,
// region_graph, grow_from_seeds, collect_charts.
#include "unwrap_internal.hpp"

#include <algorithm>
#include <cmath>
#include <queue>
#include <tuple>

namespace hemilight::unwrap_detail {

namespace {

// Largest angle (radians) between a triangle's normal and its planar region's seed normal: 1e-3.
// Normals of coplanar float triangles differ by their vertices' rounding, about 6e-8 x (coordinate
// magnitude / edge length): up to 6e-4 for 1 cm triangles 100 units from the origin. Projecting a
// region this flat onto one plane stretches it by at most 1 / cos(2e-3) - 1 = 2e-6.
constexpr double planar_region_angle = 1e-3;

// Most triangles a chart grown from several regions takes: each curved chart is one sparse
// solve, and a solve's cost grows faster than its size; 16384 keeps each within a few tens of
// milliseconds (docs/unwrap.md) while terrains still come in few charts. A single planar region
// may be larger (it is projected, not solved).
constexpr std::size_t max_curved_chart_triangles = 16384;

// Deviations 1 - cos(angle) within one step of this count as equal, so that among nearly equal
// normals the chart grows nearest first (round charts pack better): 0.002 is 3.6 degrees at 0.
constexpr double deviation_step = 0.002;

struct regions {
  std::vector<std::uint32_t> of_triangle;  // per triangle, or none
  std::vector<std::vector<std::uint32_t>> triangles;
  std::vector<glm::dvec3> normal, centroid;  // area-weighted
  std::vector<double> area;
  std::vector<std::uint32_t> adjacency_first, adjacency;  // CSR: the regions each borders
};

// Triangles flood-filled across linked edges while their normals stay within
// planar_region_angle of the seed's; seeds in triangle order.
void planar_regions(const mesh_view& m, const welded_mesh& w, regions& r) {
  const double cos_planar = std::cos(planar_region_angle);
  r.of_triangle.assign(m.triangle_count, none);
  std::vector<std::uint32_t> stack;
  for (std::size_t seed = 0; seed < m.triangle_count; ++seed) {
    if (w.degenerate[seed] || r.of_triangle[seed] != none) continue;
    const auto id = std::uint32_t(r.triangles.size());
    r.triangles.emplace_back();
    glm::dvec3 n_sum(0.0), c_sum(0.0);
    double a_sum = 0.0;
    r.of_triangle[seed] = id;
    stack.assign(1, std::uint32_t(seed));
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      r.triangles[id].push_back(t);
      n_sum += w.normal[t] * w.area[t];
      c_sum += (m.corner(t, 0) + m.corner(t, 1) + m.corner(t, 2)) * (w.area[t] / 3.0);
      a_sum += w.area[t];
      for (int e = 0; e < 3; ++e) {
        const std::uint32_t nb = w.neighbour[3 * std::size_t(t) + std::size_t(e)];
        if (nb == none) continue;
        const std::uint32_t u = nb / 3;
        if (r.of_triangle[u] == none && glm::dot(w.normal[u], w.normal[seed]) >= cos_planar) {
          r.of_triangle[u] = id;
          stack.push_back(u);
        }
      }
    }
    std::sort(r.triangles[id].begin(), r.triangles[id].end());
    r.normal.push_back(glm::normalize(n_sum));
    r.centroid.push_back(c_sum / a_sum);
    r.area.push_back(a_sum);
  }
}

// The regions each region borders across linked edges (CSR, increasing).
void region_graph(const mesh_view& m, const welded_mesh& w, regions& r) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::size_t t = 0; t < m.triangle_count; ++t)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t nb = w.neighbour[3 * t + std::size_t(e)];
      if (nb == none) continue;
      const std::uint32_t a = r.of_triangle[t], b = r.of_triangle[nb / 3];
      if (a != b) pairs.emplace_back(a, b);
    }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  r.adjacency_first.assign(r.triangles.size() + 1, 0);
  for (const auto& p : pairs) ++r.adjacency_first[p.first + 1];
  for (std::size_t i = 1; i < r.adjacency_first.size(); ++i) r.adjacency_first[i] += r.adjacency_first[i - 1];
  r.adjacency.resize(pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) r.adjacency[i] = pairs[i].second;
}

// Charts as lists of regions: seeds by decreasing area (ties: lower index); a chart takes a
// bordering region when its normal lies within the chart angle of both the seed's and the chart's
// current mean normal, smallest deviation first (ties: nearest the seed, then lower index).
std::vector<std::vector<std::uint32_t>> grow_from_seeds(const regions& r, double cos_max) {
  const std::size_t R = r.triangles.size();
  std::vector<std::uint32_t> order(R);
  for (std::size_t i = 0; i < R; ++i) order[i] = std::uint32_t(i);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return r.area[a] > r.area[b] || (r.area[a] == r.area[b] && a < b); });
  std::vector<std::uint32_t> chart_of(R, none);
  std::vector<std::vector<std::uint32_t>> charts;
  using candidate = std::tuple<double, double, std::uint32_t>;  // (deviation step, squared distance, region)
  for (std::uint32_t seed : order) {
    if (chart_of[seed] != none) continue;
    const auto c = std::uint32_t(charts.size());
    charts.emplace_back(1, seed);
    chart_of[seed] = c;
    glm::dvec3 sum = r.normal[seed] * r.area[seed];
    std::size_t tris = r.triangles[seed].size();
    std::priority_queue<candidate, std::vector<candidate>, std::greater<candidate>> heap;
    const auto push_neighbours = [&](std::uint32_t region) {
      const glm::dvec3 mean = glm::normalize(sum);
      for (std::uint32_t k = r.adjacency_first[region]; k < r.adjacency_first[region + 1]; ++k) {
        const std::uint32_t nb = r.adjacency[k];
        if (chart_of[nb] != none) continue;
        const glm::dvec3 d = r.centroid[nb] - r.centroid[seed];
        heap.emplace(std::floor((1.0 - glm::dot(r.normal[nb], mean)) / deviation_step), glm::dot(d, d), nb);
      }
    };
    push_neighbours(seed);
    while (!heap.empty()) {
      const std::uint32_t nb = std::get<2>(heap.top());
      heap.pop();
      if (chart_of[nb] != none || tris + r.triangles[nb].size() > max_curved_chart_triangles) continue;
      if (glm::dot(r.normal[nb], glm::normalize(sum)) < cos_max || glm::dot(r.normal[nb], r.normal[seed]) < cos_max) continue;
      chart_of[nb] = c;
      charts[c].push_back(nb);
      sum += r.normal[nb] * r.area[nb];
      tris += r.triangles[nb].size();
      push_neighbours(nb);
    }
  }
  return charts;
}

// The charts' triangles (increasing), planar flags and mean normals.
void collect_charts(const regions& r, const std::vector<std::vector<std::uint32_t>>& region_charts, std::size_t triangle_count,
                    chart_set& out) {
  out.triangle_chart.assign(triangle_count, none);
  out.first.assign(1, 0);
  std::vector<std::uint32_t> tris;
  for (const std::vector<std::uint32_t>& rc : region_charts) {
    tris.clear();
    glm::dvec3 sum(0.0);
    for (std::uint32_t region : rc) {
      tris.insert(tris.end(), r.triangles[region].begin(), r.triangles[region].end());
      sum += r.normal[region] * r.area[region];
    }
    std::sort(tris.begin(), tris.end());
    out.add(tris, rc.size() == 1, glm::normalize(sum));
  }
}

}  // namespace

void chart_set::add(const std::vector<std::uint32_t>& tris, bool is_planar, const glm::dvec3& n) {
  if (first.empty()) first.push_back(0);
  const auto c = std::uint32_t(first.size() - 1);
  for (std::uint32_t t : tris) triangle_chart[t] = c;
  triangles.insert(triangles.end(), tris.begin(), tris.end());
  first.push_back(std::uint32_t(triangles.size()));
  planar.push_back(is_planar ? 1 : 0);
  normal.push_back(n);
}

chart_set grow_charts(const mesh_view& m, const welded_mesh& w, double max_chart_angle_degrees) {
  regions r;
  planar_regions(m, w, r);
  region_graph(m, w, r);
  const double cos_max = std::cos(max_chart_angle_degrees * 3.14159265358979323846 / 180.0);
  chart_set out;
  collect_charts(r, grow_from_seeds(r, cos_max), m.triangle_count, out);
  out.triangle_region = std::move(r.of_triangle);
  return out;
}

}  // namespace hemilight::unwrap_detail
