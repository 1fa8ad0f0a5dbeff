// Step 6 of the unwrapper (unwrap_internal.hpp): emit_vertices, the output vertices (one per chart
// and input vertex) with their page UVs, and where degenerate triangles go.
#include "unwrap_internal.hpp"

namespace hemilight::unwrap_detail {

namespace {

// The output vertices made so far, found by (chart, input vertex): a short list per input vertex.
class vertex_table {
 public:
  vertex_table(std::size_t vertex_count, unwrap_result& out) : head_(vertex_count, none), out_(out) {}

  // The output vertex of input vertex v in chart c, made with `uv` on first use.
  std::uint32_t get(std::uint32_t c, std::uint32_t v, const glm::vec2& uv) {
    for (std::uint32_t e = head_[v]; e != none; e = entries_[e].next)
      if (entries_[e].chart == c) return entries_[e].out;
    const auto index = std::uint32_t(out_.vertex_source.size());
    out_.vertex_source.push_back(v);
    out_.uvs.push_back(uv);
    entries_.push_back({c, index, head_[v]});
    head_[v] = std::uint32_t(entries_.size() - 1);
    return index;
  }

 private:
  struct entry {
    std::uint32_t chart, out, next;
  };
  std::vector<std::uint32_t> head_;
  std::vector<entry> entries_;
  unwrap_result& out_;
};

// Per welded vertex: the lowest chart that has it, or none.
std::vector<std::uint32_t> first_chart_of_vertices(const welded_mesh& w, const chart_uvs& uvs) {
  std::vector<std::uint32_t> first(w.welded_count, none);
  for (std::size_t c = uvs.first.size() - 1; c-- > 0;)
    for (std::uint32_t i = uvs.first[c]; i < uvs.first[c + 1]; ++i) first[uvs.vertex[i]] = std::uint32_t(c);
  return first;
}

}  // namespace

void emit_vertices(const mesh_view& m, const welded_mesh& w, const chart_set& charts, const chart_uvs& uvs, const placement& p,
                   int page_size, unwrap_result& out) {
  const std::size_t T = m.triangle_count;
  out.indices.resize(3 * T);
  out.triangle_page.assign(T, 0);
  out.triangle_chart.assign(T, unwrap_result::no_chart);
  vertex_table table(m.vertex_count, out);
  const std::vector<std::uint32_t> chart_of_vertex = first_chart_of_vertices(w, uvs);
  for (std::size_t t = 0; t < T; ++t) {
    std::uint32_t c = charts.triangle_chart[t];
    int anchor = 0;  // a corner of a degenerate triangle that lies in chart c
    if (c == none)   // degenerate: the chart of the first corner that has one
      for (int k = 2; k >= 0; --k)
        if (chart_of_vertex[w.welded(m, t, k)] != none) {
          c = chart_of_vertex[w.welded(m, t, k)];
          anchor = k;
        }
    if (c == none) {  // touching no chart: all at (0, 0) of page 0
      for (int k = 0; k < 3; ++k) out.indices[3 * t + std::size_t(k)] = table.get(none, m.indices[3 * t + std::size_t(k)], glm::vec2(0.0f));
      continue;
    }
    const glm::vec2 anchor_uv = page_uv(uvs, p, c, uvs.find(c, w.welded(m, t, anchor)), page_size);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = uvs.find(c, w.welded(m, t, k));
      const glm::vec2 uv = i == none ? anchor_uv : page_uv(uvs, p, c, i, page_size);
      out.indices[3 * t + std::size_t(k)] = table.get(c, m.indices[3 * t + std::size_t(k)], uv);
    }
    out.triangle_page[t] = p.page[c];
    out.triangle_chart[t] = c;
  }
}

}  // namespace hemilight::unwrap_detail
