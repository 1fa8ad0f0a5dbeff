// Step 5 of the unwrapper (unwrap_internal.hpp): charts cut into pieces that keep their UVs,
// split_sparse_charts (charts that fill little of their rectangle) and split_large_charts (charts
// longer than a page).
#include "unwrap_internal.hpp"

#include "hemilight/error.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <utility>

namespace hemilight::unwrap_detail {

namespace {

// A chart that fills less than this of its smallest bounding rectangle is a candidate for cuts:
// the packer places rectangles, and the empty part of a chart's rectangle is lost. Of the
// partitions by repeated halving (at most sparse_cut_depth deep) the one whose pieces' rectangles,
// each grown by the padding, take the least room is kept, if that is less than sparse_cut_gain of
// the whole's (a cut adds a seam and padding around both pieces). Measured on terrains and levels
// (docs/unwrap.md, "Design notes").
constexpr double sparse_chart_fill = 0.8;
constexpr double sparse_cut_gain = 0.9;
constexpr int sparse_cut_depth = 4;  // up to 16 pieces per chart

// A chart being split: its triangles, vertices (welded, increasing) and oriented UVs.
struct piece {
  std::vector<std::uint32_t> tris, vertex;
  std::vector<glm::dvec2> uv;
  glm::dvec2 extent{0.0};

  glm::dvec2 uv_of(std::uint32_t welded) const {
    return uv[std::size_t(std::lower_bound(vertex.begin(), vertex.end(), welded) - vertex.begin())];
  }
};

// The part of `from` made of `tris`: its vertices and their UVs, re-oriented.
piece sub_piece(const mesh_view& m, const welded_mesh& w, const piece& from, std::vector<std::uint32_t> tris) {
  piece out;
  out.tris = std::move(tris);
  for (std::uint32_t t : out.tris)
    for (int k = 0; k < 3; ++k) out.vertex.push_back(w.welded(m, t, k));
  std::sort(out.vertex.begin(), out.vertex.end());
  out.vertex.erase(std::unique(out.vertex.begin(), out.vertex.end()), out.vertex.end());
  for (std::uint32_t v : out.vertex) out.uv.push_back(from.uv_of(v));
  out.extent = orient_chart(out.uv.data(), out.uv.size());
  return out;
}

// `p` cut across its longer side (u: oriented charts are wider than tall) at the middle, or at the
// median triangle when the middle leaves one side empty. Precondition: at least 2 triangles.
std::pair<piece, piece> halves(const mesh_view& m, const welded_mesh& w, const piece& p) {
  std::vector<std::pair<double, std::uint32_t>> by_u;
  for (std::uint32_t t : p.tris) {
    double u = 0.0;
    for (int k = 0; k < 3; ++k) u += p.uv_of(w.welded(m, t, k)).x;
    by_u.emplace_back(u / 3.0, t);
  }
  std::sort(by_u.begin(), by_u.end());
  std::size_t cut = std::size_t(std::lower_bound(by_u.begin(), by_u.end(), std::make_pair(0.5 * p.extent.x, std::uint32_t(0))) - by_u.begin());
  if (cut == 0 || cut == by_u.size()) cut = by_u.size() / 2;
  std::vector<std::uint32_t> a, b;
  for (std::size_t i = 0; i < by_u.size(); ++i) (i < cut ? a : b).push_back(by_u[i].second);
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  return {sub_piece(m, w, p, std::move(a)), sub_piece(m, w, p, std::move(b))};
}

// How a chart is cut: whether to look at a piece at all, and what a piece costs kept whole.
struct split_rule {
  std::function<bool(const piece&)> consider;
  std::function<double(const piece&)> cost;  // of the piece kept whole; cuts are kept where they lower the total
  double gain = 1.0;                          // a cut is kept when its pieces cost less than gain x the whole
  int depth = 64;                             // most cuts in a row
};

// The cheapest partition of `p` by repeated halves (at most rule.depth deep): the pieces, appended
// to `out`; returns their cost.
double split_piece(const mesh_view& m, const welded_mesh& w, piece p, const split_rule& rule, int depth, std::vector<piece>& out) {
  const double whole = rule.cost(p);
  if (depth == 0 || !rule.consider(p) || p.tris.size() < 2) {
    out.push_back(std::move(p));
    return whole;
  }
  auto [a, b] = halves(m, w, p);
  std::vector<piece> parts;
  const double cut = split_piece(m, w, std::move(a), rule, depth - 1, parts) + split_piece(m, w, std::move(b), rule, depth - 1, parts);
  if (!(cut < rule.gain * whole)) {
    out.push_back(std::move(p));
    return whole;
  }
  for (piece& pc : parts) out.push_back(std::move(pc));
  return cut;
}

// Every chart through split_piece with `rule`; the charts are renumbered only when one is cut.
void split_charts(const mesh_view& m, const welded_mesh& w, chart_set& charts, chart_uvs& uvs, const split_rule& rule) {
  const std::size_t C = charts.size();
  std::vector<std::vector<piece>> pieces(C);
  bool any = false;
  for (std::size_t c = 0; c < C; ++c) {
    piece whole;
    whole.tris.assign(charts.triangles.begin() + std::ptrdiff_t(charts.first[c]), charts.triangles.begin() + std::ptrdiff_t(charts.first[c + 1]));
    whole.vertex.assign(uvs.vertex.begin() + std::ptrdiff_t(uvs.first[c]), uvs.vertex.begin() + std::ptrdiff_t(uvs.first[c + 1]));
    whole.uv.assign(uvs.uv.begin() + std::ptrdiff_t(uvs.first[c]), uvs.uv.begin() + std::ptrdiff_t(uvs.first[c + 1]));
    whole.extent = uvs.extent[c];
    split_piece(m, w, std::move(whole), rule, rule.depth, pieces[c]);
    any = any || pieces[c].size() > 1;
  }
  if (!any) return;
  chart_set out_charts;
  out_charts.triangle_chart.assign(m.triangle_count, none);
  out_charts.triangle_region = charts.triangle_region;
  chart_uvs out_uvs;
  out_uvs.first.assign(1, 0);
  for (std::size_t c = 0; c < C; ++c)
    for (const piece& pc : pieces[c]) {
      out_charts.add(pc.tris, charts.planar[c] != 0, charts.normal[c]);
      out_uvs.vertex.insert(out_uvs.vertex.end(), pc.vertex.begin(), pc.vertex.end());
      out_uvs.uv.insert(out_uvs.uv.end(), pc.uv.begin(), pc.uv.end());
      out_uvs.first.push_back(std::uint32_t(out_uvs.vertex.size()));
      out_uvs.extent.push_back(pc.extent);
    }
  charts = std::move(out_charts);
  uvs = std::move(out_uvs);
}

// The UV area of a piece's triangles over its rectangle's.
double rectangle_fill(const mesh_view& m, const welded_mesh& w, const piece& p) {
  double area = 0.0;
  for (std::uint32_t t : p.tris) {
    const glm::dvec2 a = p.uv_of(w.welded(m, t, 0)), b = p.uv_of(w.welded(m, t, 1)), c = p.uv_of(w.welded(m, t, 2));
    area += 0.5 * std::fabs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
  }
  return area / std::max(p.extent.x * p.extent.y, 1e-300);
}

}  // namespace

void split_sparse_charts(const mesh_view& m, const welded_mesh& w, chart_set& charts, chart_uvs& uvs, double density, int padding) {
  split_rule rule;
  rule.consider = [&](const piece& p) { return rectangle_fill(m, w, p) < sparse_chart_fill; };
  rule.cost = [&](const piece& p) { return (std::ceil(p.extent.x * density) + padding) * (std::ceil(p.extent.y * density) + padding); };
  rule.gain = sparse_cut_gain;
  rule.depth = sparse_cut_depth;
  split_charts(m, w, charts, uvs, rule);
}

void split_large_charts(const mesh_view& m, const welded_mesh& w, chart_set& charts, chart_uvs& uvs, double limit, double density) {
  // Cost: 1 for a piece that fits, more than two halves can cost for one that does not.
  split_rule rule;
  rule.consider = [&](const piece& p) {
    if (std::max(p.extent.x, p.extent.y) <= limit) return false;
    if (p.tris.size() == 1)
      throw_invalid_argument("unwrap_lightmap: triangle " + std::to_string(p.tris[0]) + " is " + std::to_string(p.extent.x * density) +
                             " texels across at texels_per_unit " + std::to_string(density) +
                             ", more than a page holds: lower texels_per_unit or raise page_size");
    return true;
  };
  rule.cost = [&](const piece& p) { return std::max(p.extent.x, p.extent.y) <= limit ? 1.0 : 1e300; };
  split_charts(m, w, charts, uvs, rule);
}

}  // namespace hemilight::unwrap_detail
