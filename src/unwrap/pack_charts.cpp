// Steps 4 and 6 of the unwrapper (unwrap_internal.hpp): orient_charts (smallest bounding
// rectangles), pack_charts (a skyline packer per page, quarter turns allowed; for a target size,
// a bisection on the density) and page_uv.
#include "unwrap_internal.hpp"

#include "hemilight/error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace hemilight::unwrap_detail {

namespace {

double cross(const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// Convex hull, counter-clockwise, without collinear points (Andrew's monotone chain).
std::vector<glm::dvec2> convex_hull(std::vector<glm::dvec2> p) {
  std::sort(p.begin(), p.end(), [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return p;
  std::vector<glm::dvec2> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0.0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(h[k - 2], h[k - 1], p[i]) <= 0.0) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  return h;
}

// The direction (unit) of the smallest-area rectangle around a counter-clockwise hull: one of its
// sides lies along a hull edge (Freeman and Shapira). Rotating calipers: for each edge, the
// farthest point along the edge, against it and away from it advance monotonically. O(h).
glm::dvec2 smallest_rectangle_direction(const std::vector<glm::dvec2>& h) {
  const std::size_t n = h.size();
  if (n < 3) return n == 2 && h[1] != h[0] ? glm::normalize(h[1] - h[0]) : glm::dvec2(1.0, 0.0);
  std::size_t far = 0, right = 0, left = 0;
  double best = std::numeric_limits<double>::infinity();
  glm::dvec2 best_d(1.0, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec2 d = glm::normalize(h[(i + 1) % n] - h[i]), nrm(-d.y, d.x);  // nrm points inside
    const auto along = [&](std::size_t j) { return glm::dot(h[j % n], d); };
    const auto across = [&](std::size_t j) { return glm::dot(h[j % n], nrm); };
    if (i == 0)  // the first edge's extremes by a full scan; later ones advance from there
      for (std::size_t j = 1; j < n; ++j) {
        if (across(j) > across(far)) far = j;
        if (along(j) > along(right)) right = j;
        if (along(j) < along(left)) left = j;
      }
    for (std::size_t s = 0; s < n && across(far + 1) >= across(far); ++s) far = (far + 1) % n;
    for (std::size_t s = 0; s < n && along(right + 1) >= along(right); ++s) right = (right + 1) % n;
    for (std::size_t s = 0; s < n && along(left + 1) <= along(left); ++s) left = (left + 1) % n;
    const double area = (along(right) - along(left)) * (across(far) - across(i));
    if (area < best) {
      best = area;
      best_d = d;
    }
  }
  return best_d;
}

}  // namespace

glm::dvec2 orient_chart(glm::dvec2* uv, std::size_t count) {
  const glm::dvec2 d = smallest_rectangle_direction(convex_hull(std::vector<glm::dvec2>(uv, uv + count)));
  glm::dvec2 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < count; ++i) {
    uv[i] = glm::dvec2(glm::dot(uv[i], d), glm::dot(uv[i], glm::dvec2(-d.y, d.x)));  // a rotation
    lo = glm::min(lo, uv[i]);
    hi = glm::max(hi, uv[i]);
  }
  const glm::dvec2 extent = hi - lo;
  const bool turn = extent.y > extent.x;
  for (std::size_t i = 0; i < count; ++i) {
    const glm::dvec2 q = uv[i] - lo;
    uv[i] = turn ? glm::dvec2(extent.y - q.y, q.x) : q;
  }
  return turn ? glm::dvec2(extent.y, extent.x) : extent;
}

namespace {

// A skyline of one page's bin: segments (x, top y, width) left to right.
class skyline {
 public:
  explicit skyline(int size) : size_(size), nodes_{{0, 0, size}} {}

  // The lowest-top position of a w x h rectangle (ties: leftmost); false if none fits.
  bool find(int w, int h, std::size_t& node, int& x, int& y) const {
    long best_top = -1;
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      const int nx = nodes_[i].x;
      if (nx + w > size_) break;
      int top = 0;
      for (std::size_t j = i; j < nodes_.size() && nodes_[j].x < nx + w; ++j) top = std::max(top, nodes_[j].y);
      if (top + h > size_) continue;
      if (best_top < 0 || top + h < best_top) {
        best_top = top + h;
        node = i;
        x = nx;
        y = top;
      }
    }
    return best_top >= 0;
  }

  // Places a w x h rectangle at (x, y) as found at `node`.
  void place(std::size_t node, int x, int y, int w, int h) {
    nodes_.insert(nodes_.begin() + std::ptrdiff_t(node), segment{x, y + h, w});
    const int end = x + w;
    std::size_t i = node + 1;
    while (i < nodes_.size() && nodes_[i].x < end) {
      const int seg_end = nodes_[i].x + nodes_[i].w;
      if (seg_end <= end) {
        nodes_.erase(nodes_.begin() + std::ptrdiff_t(i));
      } else {
        nodes_[i].w = seg_end - end;
        nodes_[i].x = end;
        break;
      }
    }
    for (std::size_t k = 0; k + 1 < nodes_.size();) {  // merge equal neighbours
      if (nodes_[k].y == nodes_[k + 1].y) {
        nodes_[k].w += nodes_[k + 1].w;
        nodes_.erase(nodes_.begin() + std::ptrdiff_t(k + 1));
      } else {
        ++k;
      }
    }
  }

 private:
  struct segment {
    int x, y, w;
  };
  int size_;
  std::vector<segment> nodes_;
};

// A chart's rectangle in texels at `density`: at least 1 x 1 (and at most 2^30, far past any page).
int texels(double extent, double density) { return std::max(1, int(std::min(std::ceil(extent * density - 1e-9), 1073741824.0))); }

// Packs the charts in `order` at `density` into pages of one bin each (bin: page_size - padding,
// rectangles grown by padding). With max_pages 1, returns false when one does not fit.
bool pack_at(const chart_uvs& uvs, const std::vector<std::uint32_t>& order, double density, const unwrap_options& o,
             int max_pages, placement& p) {
  const int bin = o.page_size - o.padding;
  std::vector<skyline> pages;
  p.page.assign(uvs.extent.size(), 0);
  p.origin.assign(uvs.extent.size(), glm::dvec2(0.0));
  p.turned.assign(uvs.extent.size(), 0);
  for (std::uint32_t c : order) {
    const int w = texels(uvs.extent[c].x, density), h = texels(uvs.extent[c].y, density);
    bool placed = false;
    for (std::size_t page = 0; !placed; ++page) {
      if (page == pages.size()) {
        if (int(pages.size()) == max_pages) return false;
        pages.emplace_back(bin);
      }
      std::size_t node_a = 0, node_b = 0;
      int xa = 0, ya = 0, xb = 0, yb = 0;
      const bool fit_a = pages[page].find(w + o.padding, h + o.padding, node_a, xa, ya);
      const bool fit_b = w != h && pages[page].find(h + o.padding, w + o.padding, node_b, xb, yb);
      if (!fit_a && !fit_b) continue;
      const bool turn = fit_b && (!fit_a || yb + w < ya + h || (yb + w == ya + h && xb < xa));
      const int pw = turn ? h : w, ph = turn ? w : h;
      pages[page].place(turn ? node_b : node_a, turn ? xb : xa, turn ? yb : ya, pw + o.padding, ph + o.padding);
      const double ew = (turn ? uvs.extent[c].y : uvs.extent[c].x) * density, eh = (turn ? uvs.extent[c].x : uvs.extent[c].y) * density;
      p.page[c] = std::uint32_t(page);
      p.turned[c] = turn ? 1 : 0;
      // Centred in its rectangle (the rectangle rounds the chart up to whole texels).
      p.origin[c] = glm::dvec2(o.padding + (turn ? xb : xa) + 0.5 * (pw - ew), o.padding + (turn ? yb : ya) + 0.5 * (ph - eh));
      placed = true;
    }
  }
  p.pages = int(pages.size());
  p.density = density;
  return true;
}

// Charts tallest first (in scene units, then widest, then lower index): the skyline's order.
std::vector<std::uint32_t> packing_order(const chart_uvs& uvs) {
  std::vector<std::uint32_t> order(uvs.extent.size());
  for (std::size_t c = 0; c < order.size(); ++c) order[c] = std::uint32_t(c);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const glm::dvec2 ea = uvs.extent[a], eb = uvs.extent[b];
    return ea.y > eb.y || (ea.y == eb.y && (ea.x > eb.x || (ea.x == eb.x && a < b)));
  });
  return order;
}

// The largest density (16 bisection steps between the density at which every chart is one texel
// and the area bound) at which the charts fit one page.
placement pack_to_size(const chart_uvs& uvs, const std::vector<std::uint32_t>& order, const unwrap_options& o) {
  double longest = 0.0;
  for (const glm::dvec2& e : uvs.extent) longest = std::max({longest, e.x, e.y});
  const double one_texel = 1.0 / std::max(longest, 1e-300);  // every chart within 1 x 1 texels, with its area
  placement best;
  if (!pack_at(uvs, order, one_texel, o, 1, best))
    throw_invalid_argument("unwrap_lightmap: the " + std::to_string(uvs.extent.size()) + " charts do not fit one page of " +
                           std::to_string(o.page_size) + " x " + std::to_string(o.page_size) + " texels even at one texel each (padding " +
                           std::to_string(o.padding) + "): use a larger page_size, or texels_per_unit > 0 to spill into several pages");
  double area = 0.0;
  for (const glm::dvec2& e : uvs.extent) area += e.x * e.y;
  double lo = one_texel, hi = std::max(one_texel, double(o.page_size - o.padding) / std::sqrt(std::max(area, 1e-300)));
  placement trial;
  if (pack_at(uvs, order, hi, o, 1, trial)) return trial;
  for (int step = 0; step < 16; ++step) {
    const double mid = 0.5 * (lo + hi);
    if (pack_at(uvs, order, mid, o, 1, trial)) {
      lo = mid;
      best = trial;
    } else {
      hi = mid;
    }
  }
  return best;
}

}  // namespace

double estimate_density(const chart_uvs& uvs, const unwrap_options& o, double fill) {
  double area = 0.0;
  for (const glm::dvec2& e : uvs.extent) area += e.x * e.y;
  return double(o.page_size - o.padding) * std::sqrt(fill / std::max(area, 1e-300));
}

void orient_charts(chart_uvs& uvs) {
  const std::size_t C = uvs.first.size() - 1;
  uvs.extent.resize(C);
  for (std::size_t c = 0; c < C; ++c) uvs.extent[c] = orient_chart(uvs.uv.data() + uvs.first[c], uvs.first[c + 1] - uvs.first[c]);
}

placement pack_charts(const chart_uvs& uvs, const unwrap_options& o) {
  const std::vector<std::uint32_t> order = packing_order(uvs);
  if (o.texels_per_unit == 0.0f) return pack_to_size(uvs, order, o);
  placement p;
  if (!pack_at(uvs, order, double(o.texels_per_unit), o, o.max_pages, p))
    throw_invalid_argument("unwrap_lightmap: the charts need more than max_pages = " + std::to_string(o.max_pages) + " pages of " +
                           std::to_string(o.page_size) + " x " + std::to_string(o.page_size) + " texels at texels_per_unit " +
                           std::to_string(o.texels_per_unit) + ": lower texels_per_unit or raise page_size or max_pages");
  return p;
}

glm::vec2 page_uv(const chart_uvs& uvs, const placement& p, std::size_t c, std::size_t i, int page_size) {
  const glm::dvec2 q = uvs.uv[i];
  const glm::dvec2 local = p.turned[c] ? glm::dvec2(uvs.extent[c].y - q.y, q.x) : q;
  const glm::dvec2 t = (p.origin[c] + local * p.density) / double(page_size);
  return glm::clamp(glm::vec2(t), 0.0f, 1.0f);
}

}  // namespace hemilight::unwrap_detail
