// The irradiance cache: record weights, a bounding-volume hierarchy over records, deterministic
// round-based placement, radius limits, interpolation. See cache.hpp.
#include "hemilight/cache.hpp"

#include "hemilight/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <memory>
#include <mutex>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <unordered_map>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hemilight {

namespace {

constexpr float max_weight = 1e12f;  // caps Ward's 1/0 at a record's own position and normal
constexpr float behind_epsilon = 1e-6f;

float luminance(const glm::vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

std::string vec_str(const glm::vec3& v) {
  return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

// The largest distance at which a record can have a positive weight: a R for both weightings.
float coverage_radius(const cache_record& r, const cache_options& o) { return o.error_threshold * r.radius; }

// The weight the coverage tests use: Ward's w where it passes 1/a (for both Ward weightings, so
// ward_continuous places the same records as ward), the Tabellion-Lamorlette w where positive;
// else 0. record_weight (the interpolation's weight) is this, less 1/a for ward_continuous.
// R is a cache_record or a record_bvh::key (anything with position, normal and radius).
template <class R>
inline float coverage_weight(const R& r, const glm::vec3& x, const glm::vec3& n, const cache_options& o) {
  const float d = glm::length(x - r.position);
  const float ndot = std::sqrt(std::max(0.0f, 1.0f - glm::dot(n, r.normal)));
  if (o.weight != cache_weight::tabellion_lamorlette) {
    const float denom = d / r.radius + ndot;
    const float w = denom > 1.0f / max_weight ? 1.0f / denom : max_weight;
    return w > 1.0f / o.error_threshold ? w : 0.0f;
  }
  const float k = 1.0f / (2.0f * o.error_threshold);
  const float w = 1.0f - k * std::max(d / (0.5f * r.radius), ndot / 0.12326f);
  return w > 0.0f ? w : 0.0f;
}

// record_weight and record_is_behind (cache.hpp), inline for the placement's hot loops.
template <class R>
inline float weight_of(const R& r, const glm::vec3& x, const glm::vec3& n, const cache_options& o) {
  const float w = coverage_weight(r, x, n, o);
  // w > 1/a here, so w - 1/a > 0 (IEEE subtraction of two different floats is never 0).
  return o.weight == cache_weight::ward_continuous && w > 0.0f ? w - 1.0f / o.error_threshold : w;
}
template <class R>
inline bool is_behind(const R& r, const glm::vec3& x, const glm::vec3& n) {
  return 0.5f * glm::dot(x - r.position, r.normal + n) < -behind_epsilon;
}

// A record's prediction at (x, n): order 0 = E_i, 1 = with the gradient terms, 2 = also with the
// second-order term 1/2 dx^T H dx, clamped per channel to +-a E_i (the error a allows: a record
// whose irradiance is 0, in an umbra, stays 0 instead of bending towards its lit neighbours).
glm::vec3 extrapolate(const cache_record& r, const glm::vec3& x, const glm::vec3& n, int order, float a = 1.0f) {
  glm::vec3 e = r.irradiance;
  if (order >= 1) {
    const glm::vec3 rot = glm::cross(r.normal, n);
    const glm::vec3 dx = x - r.position;
    for (int c = 0; c < 3; ++c)
      e[c] += glm::dot(rot, r.rotation_gradient[std::size_t(c)]) + glm::dot(dx, r.translation_gradient[std::size_t(c)]);
    if (order >= 2)
      for (int c = 0; c < 3; ++c) {
        const float limit = a * r.irradiance[c];
        e[c] += std::clamp(0.5f * glm::dot(dx, r.hessian[std::size_t(c)] * dx), -limit, limit);
      }
  }
  return e;
}

// The order of the predictions that options ask for.
int prediction_order(const cache_options& o) { return !o.use_gradients ? 0 : (o.second_order ? 2 : 1); }

// A bounding-volume hierarchy over the records' coverage spheres, rebuilt after every round
// (records are only added between rounds, so queries never race with insertion). Query cost
// O(log n + k) for k records whose box holds the point.
class record_bvh {
 public:
  // What a query needs of a record to weigh it, in leaf order (32 bytes; the records themselves
  // are ten times larger): the weights and is_behind read only these, bit for bit the record's.
  struct key {
    glm::vec3 position;
    float radius;
    glm::vec3 normal;
    std::uint32_t index;  // the record's index
  };

  // threads: how many cores the build may use (the two halves below the root are built in
  // parallel; the tree is the same for any count).
  void build(const std::vector<cache_record>& records, const cache_options& o, int threads = 1) {
    records_ = &records;
    nodes_.clear();
    index_.resize(records.size());
    std::iota(index_.begin(), index_.end(), 0u);
    lo_.resize(records.size());
    hi_.resize(records.size());
    for (std::size_t i = 0; i < records.size(); ++i) {
      const float r = coverage_radius(records[i], o);
      lo_[i] = records[i].position - glm::vec3(r);
      hi_[i] = records[i].position + glm::vec3(r);
    }
    if (records.empty()) {
      keys_.clear();
      return;
    }
    const auto count = static_cast<std::uint32_t>(records.size());
    nodes_.push_back({});
    const std::uint32_t mid = split(nodes_[0], 0, count);
    if (mid == 0) {  // the root is a leaf
      fill_keys(records);
      return;
    }
    // Left and right subtrees into their own arrays (in parallel), then spliced: root, left root,
    // right root, the rest of the left, the rest of the right.
    std::vector<node> half[2];
    parallel_for(2, threads, 1, [&](int, std::size_t b, std::size_t e) {
      for (std::size_t h = b; h < e; ++h) {
        half[h].push_back({});
        build_into(half[h], 0, h ? mid : 0, h ? count : mid);
      }
    });
    const auto left_size = static_cast<std::uint32_t>(half[0].size());
    const auto remap = [&](std::uint32_t h, std::uint32_t k) -> std::uint32_t {
      if (k == 0) return 1 + h;
      return h == 0 ? 3 + (k - 1) : 3 + (left_size - 1) + (k - 1);
    };
    nodes_.resize(1 + half[0].size() + half[1].size());
    nodes_[0].first = 1;
    nodes_[0].count = 0;
    for (std::uint32_t h = 0; h < 2; ++h)
      for (std::uint32_t k = 0; k < half[h].size(); ++k) {
        node nd = half[h][k];
        if (nd.count == 0) nd.first = remap(h, nd.first);
        nodes_[remap(h, k)] = nd;
      }
    fill_keys(records);
  }

  // After radii changed but no record was added or moved: the same tree with new boxes. The
  // tree's shape depends only on the positions (split() orders centres), so this gives exactly
  // what build() would, in O(n) instead of O(n log n). Parents precede their children in nodes_,
  // so one backward pass sees every child before its parent.
  void refit(const std::vector<cache_record>& records, const cache_options& o) {
    for (std::size_t i = 0; i < records.size(); ++i) {
      const float r = coverage_radius(records[i], o);
      lo_[i] = records[i].position - glm::vec3(r);
      hi_[i] = records[i].position + glm::vec3(r);
    }
    for (std::size_t k = nodes_.size(); k-- > 0;) {
      node& nd = nodes_[k];
      glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
      if (nd.count > 0) {
        for (std::uint32_t j = nd.first; j < nd.first + nd.count; ++j) {
          lo = glm::min(lo, lo_[index_[j]]);
          hi = glm::max(hi, hi_[index_[j]]);
        }
      } else {
        lo = glm::min(nodes_[nd.first].lo, nodes_[nd.first + 1].lo);
        hi = glm::max(nodes_[nd.first].hi, nodes_[nd.first + 1].hi);
      }
      nd.lo = lo;
      nd.hi = hi;
    }
    fill_keys(records);
  }

  // Calls f(key) for every record whose coverage box holds x.
  template <class F>
  void query(const glm::vec3& x, F&& f) const {
    if (nodes_.empty()) return;
    std::uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const node& nd = nodes_[stack[--top]];
      if (x.x < nd.lo.x || x.y < nd.lo.y || x.z < nd.lo.z || x.x > nd.hi.x || x.y > nd.hi.y || x.z > nd.hi.z) continue;
      if (nd.count > 0) {
        for (std::uint32_t k = nd.first; k < nd.first + nd.count; ++k) f(keys_[k]);
      } else {
        stack[top++] = nd.first;
        stack[top++] = nd.first + 1;
      }
    }
  }

 private:
  struct node {
    glm::vec3 lo, hi;
    std::uint32_t first, count;  // leaf: records [first, first + count); inner: children first, first + 1
  };

  // Sets nd's box over index_[begin, end); returns 0 if it stays a leaf (<= 4 records), else
  // the split point after a median split on the longest axis of the centres (index_ reordered).
  std::uint32_t split(node& nd, std::uint32_t begin, std::uint32_t end) {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    glm::vec3 clo = lo, chi = hi;
    for (std::uint32_t k = begin; k < end; ++k) {
      const std::uint32_t i = index_[k];
      lo = glm::min(lo, lo_[i]);
      hi = glm::max(hi, hi_[i]);
      clo = glm::min(clo, (*records_)[i].position);
      chi = glm::max(chi, (*records_)[i].position);
    }
    nd.lo = lo;
    nd.hi = hi;
    if (end - begin <= 4) {
      nd.first = begin;
      nd.count = end - begin;
      return 0;
    }
    const glm::vec3 ext = chi - clo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(index_.begin() + begin, index_.begin() + mid, index_.begin() + end,
                     [&](std::uint32_t a, std::uint32_t b) {
                       const float pa = (*records_)[a].position[axis], pb = (*records_)[b].position[axis];
                       return pa < pb || (pa == pb && a < b);  // total order: deterministic
                     });
    nd.count = 0;
    return mid;
  }
  // Builds the subtree of index_[begin, end) with its root at out[slot]; children are allocated
  // in pairs (left, right = left + 1). Depth stays below 64 because every split halves the range.
  void build_into(std::vector<node>& out, std::uint32_t slot, std::uint32_t begin, std::uint32_t end) {
    node nd{};
    const std::uint32_t mid = split(nd, begin, end);
    if (mid != 0) {
      nd.first = static_cast<std::uint32_t>(out.size());
      out.push_back({});
      out.push_back({});
      build_into(out, nd.first, begin, mid);
      build_into(out, nd.first + 1, mid, end);
    }
    out[slot] = nd;
  }

  void fill_keys(const std::vector<cache_record>& records) {
    keys_.resize(records.size());
    for (std::size_t k = 0; k < records.size(); ++k) {
      const cache_record& r = records[index_[k]];
      keys_[k] = {r.position, r.radius, r.normal, index_[k]};
    }
  }

  const std::vector<cache_record>* records_ = nullptr;
  std::vector<key> keys_;  // in index_ order
  std::vector<node> nodes_;
  std::vector<std::uint32_t> index_;
  std::vector<glm::vec3> lo_, hi_;
};

// The cells of a uniform grid over a box: cubes of side >= `cell`, grown by 1.25x until there are
// at most 4 count + 64 of them (at most 1024 per axis). point_grid and seed_grid share them.
struct grid_cells {
  glm::vec3 lo{0.0f};
  float inv_cell = 1.0f;
  glm::ivec3 dims{1};

  void fit(const glm::vec3& box_lo, const glm::vec3& ext, float cell, std::size_t count) {
    lo = box_lo;
    for (;;) {
      dims = glm::ivec3(glm::min(glm::floor(ext / cell), glm::vec3(1023.0f))) + 1;
      if (double(dims.x) * dims.y * dims.z <= 4.0 * double(count) + 64.0) break;
      cell *= 1.25f;
    }
    inv_cell = 1.0f / cell;
  }
  std::size_t size() const { return std::size_t(dims.x) * std::size_t(dims.y) * std::size_t(dims.z); }
  glm::ivec3 cell_of(const glm::vec3& q) const {
    return glm::ivec3(glm::clamp((q - lo) * inv_cell, glm::vec3(0.0f), glm::vec3(dims - 1)));  // NaN-free for finite q
  }
  std::size_t index(const glm::ivec3& q) const {
    return (std::size_t(q.z) * std::size_t(dims.y) + std::size_t(q.y)) * std::size_t(dims.x) + std::size_t(q.x);
  }
};

// A uniform grid over the points (cells in CSR order), built once: which points lie in a
// sphere. Placement uses it to find the points whose coverage a new or shrunk record can change.
class point_grid {
 public:
  void build(const glm::vec3* p, std::size_t count) {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (std::size_t i = 0; i < count; ++i) {
      lo = glm::min(lo, p[i]);
      hi = glm::max(hi, p[i]);
    }
    p_ = p;
    const glm::vec3 ext = count ? glm::max(hi - lo, glm::vec3(0.0f)) : glm::vec3(0.0f);
    // About one cell per point over the box (points on surfaces fill few cells).
    float cell = std::cbrt(std::max(ext.x * ext.y * ext.z, 0.0f) / float(std::max<std::size_t>(count, 1)));
    cell = std::max({cell, 1e-3f * std::max({ext.x, ext.y, ext.z}), 1e-30f});
    cells_.fit(lo, ext, cell, count);
    const std::size_t cells = cells_.size();
    start_.assign(cells + 1, 0u);
    for (std::size_t i = 0; i < count; ++i) ++start_[cells_.index(cells_.cell_of(p[i])) + 1];
    for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
    points_.resize(count);
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < count; ++i) points_[fill[cells_.index(cells_.cell_of(p[i]))]++] = static_cast<std::uint32_t>(i);
  }

  // Calls f(i) for every point i with |p_i - c| <= r.
  template <class F>
  void for_each_in_sphere(const glm::vec3& c, float r, F&& f) const {
    if (points_.empty()) return;
    const glm::ivec3 a = cells_.cell_of(c - glm::vec3(r)), b = cells_.cell_of(c + glm::vec3(r));
    const float r2 = r * r;
    for (int z = a.z; z <= b.z; ++z)
      for (int y = a.y; y <= b.y; ++y)
        for (int x = a.x; x <= b.x; ++x) {
          const std::size_t cell = cells_.index({x, y, z});
          for (std::uint32_t k = start_[cell]; k < start_[cell + 1]; ++k) {
            const glm::vec3 d = p_[points_[k]] - c;
            if (glm::dot(d, d) <= r2) f(points_[k]);
          }
        }
  }

 private:
  const glm::vec3* p_ = nullptr;
  grid_cells cells_;
  std::vector<std::uint32_t> start_, points_;
};

// Second-order terms (fit_record_hessians in cache.hpp). For record i, in its tangent frame
// (t, b): the symmetric H2 = [[h11, h12], [h12, h22]] that best maps the neighbours' offsets
// (dt, db) to their gradient differences (per channel), two equations per neighbour:
//     h11 dt + h12 db = dg.t,   h12 dt + h22 db = dg.b.
// The normal matrix depends only on the offsets, so the three channels share it.
// Points with normals added one at a time into a uniform grid of cells at least `cell` wide
// over a box (a linked list per cell; positions and normals stored in insertion order): is there
// one near a point? At most about 4 count + 64 cells.
class seed_grid {
 public:
  void reset(const glm::vec3& lo, const glm::vec3& hi, float cell, std::size_t count) {
    const glm::vec3 ext = glm::max(hi - lo, glm::vec3(0.0f));
    cells_.fit(lo, ext, std::max({cell, 1e-6f * std::max({ext.x, ext.y, ext.z}), 1e-30f}), count);
    head_.assign(cells_.size(), none);
    next_.clear();
    position_.clear();
    normal_.clear();
  }
  void insert(const glm::vec3& x, const glm::vec3& n) {
    const std::size_t c = cells_.index(cells_.cell_of(x));
    next_.push_back(head_[c]);
    position_.push_back(x);
    normal_.push_back(n);
    head_[c] = static_cast<std::uint32_t>(next_.size() - 1);
  }
  // Whether pred(position, normal) holds for an item in the cells that the box x +- r touches
  // (a superset of the items within r of x); stops at the first that does.
  template <class F>
  bool any_near(const glm::vec3& x, float r, F&& pred) const {
    const glm::ivec3 a = cells_.cell_of(x - glm::vec3(r)), b = cells_.cell_of(x + glm::vec3(r));
    for (int z = a.z; z <= b.z; ++z)
      for (int y = a.y; y <= b.y; ++y)
        for (int xx = a.x; xx <= b.x; ++xx)
          for (std::uint32_t k = head_[cells_.index({xx, y, z})]; k != none; k = next_[k])
            if (pred(position_[k], normal_[k])) return true;
    return false;
  }

 private:
  static constexpr std::uint32_t none = 0xffffffffu;
  grid_cells cells_;
  std::vector<std::uint32_t> head_, next_;
  std::vector<glm::vec3> position_, normal_;
};

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

// What the placement's coverage test needs beyond the value: how many records cover the point and
// the largest first-order term |lum(prediction) - lum(E_i)| of a covering record relative to
// max(lum(E_i), floor) (floor given in).
struct coverage_detail {
  float floor = 0.0f;
  int records = 0;
  float first_order = 0.0f;
  float max_weight = 0.0f;       // largest weight of a covering record
  std::uint32_t last = 0;        // index of the last covering record (the only one when records == 1)
  float last_prediction = 0.0f;  // its luminance prediction at the point
  float max_backface = 0.0f;     // largest backface_fraction of a covering record
  std::size_t visited = 0;       // records whose box the query visited (covering or not)
};

// Interpolation at one point through the BVH; returns the weight sum (0: not covered).
// `spread` (optional) receives the range (max - min) of the luminance the covering records
// predict for the point, and `own` whether one of them sits at the point itself.
// `sh` (optional) receives the same weighted average of the records' L1 SH (zero if uncovered),
// `cone` the same of the HL2 cones, `detail` (optional) what coverage_detail describes.
float interpolate(const std::vector<cache_record>& records, const record_bvh& bvh, const glm::vec3& x,
                  const glm::vec3& n, const cache_options& o, glm::vec3& out, float* spread = nullptr,
                  bool* own = nullptr, std::array<glm::vec3, 4>* sh = nullptr, hl2_cone* cone = nullptr,
                  coverage_detail* detail = nullptr) {
  glm::vec3 sum(0.0f);
  std::array<glm::vec3, 4> sh_sum{};
  hl2_cone cone_sum;
  if (cone) cone_sum.reference = make_frame(n).t;
  float wsum = 0.0f, lo = std::numeric_limits<float>::infinity(), hi = -lo;
  bool at_record = false;
  const int order = prediction_order(o);
  std::size_t visited = 0;
  bvh.query(x, [&](const record_bvh::key& key) {
    ++visited;
    const float w = weight_of(key, x, n, o);
    if (w <= 0.0f || is_behind(key, x, n)) return;
    const std::uint32_t i = key.index;
    const cache_record& r = records[i];
    const glm::vec3 e = extrapolate(r, x, n, order, o.error_threshold);
    sum += w * e;
    wsum += w;
    if (sh)
      for (std::size_t k = 0; k < 4; ++k) sh_sum[k] += w * r.sh_l1[k];
    if (cone) {
      const hl2_cone c = rotate_hl2_cone(r.cone, r.normal, cone_sum.reference);
      for (std::size_t k = 0; k < std::size_t(hl2_cone_terms); ++k) cone_sum.coefficients[k] += w * c.coefficients[k];
    }
    const float l = luminance(e);
    lo = std::min(lo, l);
    hi = std::max(hi, l);
    if (detail) {
      const float li = luminance(r.irradiance);
      ++detail->records;
      detail->last = i;
      detail->max_weight = std::max(detail->max_weight, w);
      detail->last_prediction = l;
      detail->max_backface = std::max(detail->max_backface, r.backface_fraction);
      detail->first_order = std::max(detail->first_order, std::fabs(l - li) / std::max({li, detail->floor, 1e-30f}));
    }
    at_record = at_record || r.position == x;
  });
  out = wsum > 0.0f ? glm::max(sum / wsum, glm::vec3(0.0f)) : glm::vec3(0.0f);
  if (sh)
    for (std::size_t k = 0; k < 4; ++k) (*sh)[k] = wsum > 0.0f ? sh_sum[k] / wsum : glm::vec3(0.0f);
  if (cone) {
    if (wsum > 0.0f)
      for (glm::vec3& c : cone_sum.coefficients) c /= wsum;
    *cone = cone_sum;
  }
  if (detail) detail->visited = visited;
  if (spread) *spread = wsum > 0.0f ? hi - lo : 0.0f;
  if (own) *own = at_record;
  return wsum;
}

// Median distance from a point to its nearest neighbour, over up to 1024 evenly strided points,
// found with a hash grid (cell = bounding-box diagonal / sqrt(count): points on surfaces).
float median_spacing(const glm::vec3* p, std::size_t count, float diagonal) {
  if (count < 2 || !(diagonal > 0.0f)) return 0.0f;
  const float cell = diagonal / std::sqrt(float(count));
  auto key = [&](const glm::vec3& v) {
    const auto q = glm::ivec3(glm::floor(v / cell));
    return (std::uint64_t(std::uint32_t(q.x)) * 73856093u) ^ (std::uint64_t(std::uint32_t(q.y)) * 19349663u) ^
           (std::uint64_t(std::uint32_t(q.z)) * 83492791u);
  };
  // The hash grid as (key, point) pairs sorted by key: a cell's points are one equal range.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> grid(count);
  for (std::size_t i = 0; i < count; ++i) grid[i] = {key(p[i]), static_cast<std::uint32_t>(i)};
  std::sort(grid.begin(), grid.end());
  std::vector<float> nn;
  const std::size_t stride = std::max<std::size_t>(1, count / 1024);
  for (std::size_t i = 0; i < count; i += stride) {
    float best = std::numeric_limits<float>::infinity();
    for (int ring = 1; ring <= 4 && !std::isfinite(best); ring *= 2) {
      const glm::ivec3 q = glm::ivec3(glm::floor(p[i] / cell));
      for (int dz = -ring; dz <= ring; ++dz)
        for (int dy = -ring; dy <= ring; ++dy)
          for (int dx = -ring; dx <= ring; ++dx) {
            const glm::vec3 c = (glm::vec3(q + glm::ivec3(dx, dy, dz)) + 0.5f) * cell;
            const std::uint64_t k = key(c);
            auto it = std::lower_bound(grid.begin(), grid.end(), std::make_pair(k, std::uint32_t(0)));
            for (; it != grid.end() && it->first == k; ++it) {
              if (it->second == i) continue;
              const float d = glm::length(p[it->second] - p[i]);
              if (d > 0.0f) best = std::min(best, d);
            }
          }
    }
    if (std::isfinite(best)) nn.push_back(best);
  }
  if (nn.empty()) return 0.0f;
  std::nth_element(nn.begin(), nn.begin() + std::ptrdiff_t(nn.size() / 2), nn.end());
  return nn[nn.size() / 2];
}

void validate(const glm::vec3* positions, const glm::vec3* normals, std::size_t count, const cache_options& o) {
  const std::string fn = "cache_irradiance: ";
  if (count == 0) throw_invalid_argument(fn + "count is 0: there are no points");
  if (!positions) throw_invalid_argument(fn + "positions is NULL");
  if (!normals) throw_invalid_argument(fn + "normals is NULL");
  for (std::size_t i = 0; i < count; ++i) {
    const glm::vec3 &p = positions[i], &n = normals[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw_invalid_argument(fn + "positions[" + std::to_string(i) + "] = " + vec_str(p) + " is not finite");
    const float len = glm::length(n);
    if (!(std::fabs(len - 1.0f) <= 1e-3f))
      throw_invalid_argument(fn + "normals[" + std::to_string(i) + "] = " + vec_str(n) + " has length " +
                             std::to_string(len) + "; it must be a unit vector");
  }
  if (!(o.error_threshold > 0.0f && o.error_threshold <= 1.0f))
    throw_invalid_argument(fn + "error_threshold is " + std::to_string(o.error_threshold) + "; it must be in (0, 1]");
  if (!(o.min_radius >= 0.0f) || !std::isfinite(o.min_radius))
    throw_invalid_argument(fn + "min_radius is " + std::to_string(o.min_radius) + "; it must be finite and >= 0 (0 = automatic)");
  if (!(o.max_radius >= 0.0f) || !std::isfinite(o.max_radius))
    throw_invalid_argument(fn + "max_radius is " + std::to_string(o.max_radius) + "; it must be finite and >= 0 (0 = automatic)");
  if (o.min_radius > 0.0f && o.max_radius > 0.0f && o.min_radius > o.max_radius)
    throw_invalid_argument(fn + "min_radius " + std::to_string(o.min_radius) + " is larger than max_radius " +
                           std::to_string(o.max_radius));
  if (!(o.second_opinion >= 0.0f) || !std::isfinite(o.second_opinion))
    throw_invalid_argument(fn + "second_opinion is " + std::to_string(o.second_opinion) + "; it must be finite and >= 0 (0 = off)");
  if (!(o.sole_record_reach > 0.0f && o.sole_record_reach <= 1.0f))
    throw_invalid_argument(fn + "sole_record_reach is " + std::to_string(o.sole_record_reach) + "; it must be in (0, 1] (1 = off)");
  if (!(o.nearby_opinion >= 0.0f && o.nearby_opinion <= 16.0f))
    throw_invalid_argument(fn + "nearby_opinion is " + std::to_string(o.nearby_opinion) + "; it must be in [0, 16] (0 = off)");
  if (!(o.invalid_backface_fraction >= 0.0f && o.invalid_backface_fraction <= 1.0f))
    throw_invalid_argument(fn + "invalid_backface_fraction is " + std::to_string(o.invalid_backface_fraction) +
                           "; it must be in [0, 1]");
}

// 64-bit mix (splitmix64 finaliser): a fixed pseudo-random order of the points.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Per-texel weights of the HL2 cone series (cache.hpp, hl2_cone): w[term][texel] such that
// coefficient term = sum_i L_i w[term][i], in the hemicube's local frame (reference = +x).
struct cone_weights {
  std::array<std::vector<float>, hl2_cone_terms> w;
};

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

// The table of resolution n, built once per process for n <= 512 (like integration_table::get).
std::shared_ptr<const cone_weights> make_cone_weights(int n) {
  static std::mutex mutex;
  static std::unordered_map<int, std::shared_ptr<const cone_weights>> cache;
  if (n > 512) return build_cone_weights(n);
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[n];
  if (!slot) slot = build_cone_weights(n);
  return slot;
}

// out[c] += sum_i plane_c[i] w[i] for the three planes r, g, b of `count` texels (a multiple of
// 4): four lanes of float partial sums per block of 1024 texels, each block's lanes summed in a
// fixed order into double. SSE2 where available; the scalar path does the same operations in the
// same order.
void weighted_sums(const float* r, const float* g, const float* b, const float* w, std::size_t count, double (&out)[3]) {
  for (std::size_t b0 = 0; b0 < count; b0 += 1024) {
    const std::size_t b1 = std::min(count, b0 + 1024);
    float lanes[3][4];
#if defined(__SSE2__)
    __m128 ar = _mm_setzero_ps(), ag = _mm_setzero_ps(), ab = _mm_setzero_ps();
    for (std::size_t i = b0; i < b1; i += 4) {
      const __m128 wv = _mm_loadu_ps(w + i);
      ar = _mm_add_ps(ar, _mm_mul_ps(_mm_loadu_ps(r + i), wv));
      ag = _mm_add_ps(ag, _mm_mul_ps(_mm_loadu_ps(g + i), wv));
      ab = _mm_add_ps(ab, _mm_mul_ps(_mm_loadu_ps(b + i), wv));
    }
    _mm_storeu_ps(lanes[0], ar);
    _mm_storeu_ps(lanes[1], ag);
    _mm_storeu_ps(lanes[2], ab);
#else
    for (auto& lane : lanes)
      for (float& v : lane) v = 0.0f;
    for (std::size_t i = b0; i < b1; i += 4)
      for (std::size_t j = 0; j < 4; ++j) {
        lanes[0][j] += r[i + j] * w[i + j];
        lanes[1][j] += g[i + j] * w[i + j];
        lanes[2][j] += b[i + j] * w[i + j];
      }
#endif
    for (int c = 0; c < 3; ++c) out[c] += double((lanes[c][0] + lanes[c][1]) + (lanes[c][2] + lanes[c][3]));
  }
}

}  // namespace

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

float record_weight(const cache_record& r, const glm::vec3& x, const glm::vec3& n, const cache_options& o) {
  return weight_of(r, x, n, o);
}

bool record_is_behind(const cache_record& r, const glm::vec3& x, const glm::vec3& n) { return is_behind(r, x, n); }

glm::vec3 interpolate_records(const std::vector<cache_record>& records, const glm::vec3& x, const glm::vec3& n,
                              const cache_options& o, float* weight_sum) {
  glm::vec3 sum(0.0f);
  float wsum = 0.0f;
  for (const cache_record& r : records) {
    const float w = record_weight(r, x, n, o);
    if (w <= 0.0f || record_is_behind(r, x, n)) continue;
    sum += w * extrapolate(r, x, n, prediction_order(o), o.error_threshold);
    wsum += w;
  }
  if (weight_sum) *weight_sum = wsum;
  return wsum > 0.0f ? glm::max(sum / wsum, glm::vec3(0.0f)) : glm::vec3(0.0f);
}

void fit_record_hessians(std::vector<cache_record>& records, const cache_options& o) {
  if (!(o.error_threshold > 0.0f && o.error_threshold <= 1.0f))
    throw_invalid_argument("fit_record_hessians: options.error_threshold is " + std::to_string(o.error_threshold) +
                           "; it must be in (0, 1]");
  for (std::size_t i = 0; i < records.size(); ++i) {
    const cache_record& r = records[i];
    const std::string which = "fit_record_hessians: record " + std::to_string(i);
    if (!(r.radius >= 0.0f) || !std::isfinite(r.radius))
      throw_invalid_argument(which + " has radius " + std::to_string(r.radius) + "; it must be finite and >= 0");
    if (!std::isfinite(r.position.x) || !std::isfinite(r.position.y) || !std::isfinite(r.position.z))
      throw_invalid_argument(which + " has position " + vec_str(r.position) + "; it must be finite");
    if (!(std::fabs(glm::length(r.normal) - 1.0f) <= 1e-3f))
      throw_invalid_argument(which + " has normal " + vec_str(r.normal) + "; it must have length 1 (within 1e-3)");
  }
  fit_hessians(records, o, resolve_thread_count(o.thread_count));
}

std::array<glm::vec3, 4> interpolate_records_sh_l1(const std::vector<cache_record>& records, const glm::vec3& x,
                                                   const glm::vec3& n, const cache_options& o) {
  std::array<glm::vec3, 4> sum{};
  float wsum = 0.0f;
  for (const cache_record& r : records) {
    const float w = record_weight(r, x, n, o);
    if (w <= 0.0f || record_is_behind(r, x, n)) continue;
    for (std::size_t k = 0; k < 4; ++k) sum[k] += w * r.sh_l1[k];
    wsum += w;
  }
  if (wsum > 0.0f)
    for (glm::vec3& c : sum) c /= wsum;
  return sum;
}

namespace {

// One run of cache_irradiance (cache.hpp), as a chain of named stages over shared state:
//   derive_radii -> [ coverage_pass -> pick_seeds -> render_seeds -> append_records
//                     -> limit_radii -> mark_dirty ]* -> fit_hessians -> interpolate_all
//                     -> fill_invalid
// Per point the state is: covered (a record's weight passes 1/a and the opinions agree), own
// invalid sample (inside geometry: its own hemicube saw back faces), presumed inside (within the
// exclusion ball of an invalid sample on the same side of the same surface), contested (presumed
// inside, but a valid record covers it too: the point may be on either side of a contact, so it
// gets its own hemicube). A point is open (a seed candidate) when it is none of covered, own
// invalid or presumed-but-uncontested.
class placement {
 public:
  placement(const glm::vec3* positions, const glm::vec3* normals, std::size_t count, const irradiance_sampler& sampler,
            const cache_options& options)
      : p_(positions), n_(normals), count_(count), sampler_(sampler), o_(options) {}

  cache_result run() {
    const auto start = std::chrono::steady_clock::now();
    threads_ = resolve_thread_count(o_.thread_count);
    derive_radii();
    set_up();
    for (;;) {
      cache_round_stats round;
      round.spacing = spacing_;
      timed(round.coverage_seconds, [&] { coverage_pass(round); });
      const std::size_t open = count_open();
      round.open_points = open;
      report(1.0f - float(open) / float(count_));
      if (open == 0) {
        stats_.round_details.push_back(round);
        break;
      }
      std::vector<std::size_t> seeds;
      timed(round.seed_seconds, [&] { seeds = pick_seeds(); });
      std::vector<cache_sample> samples;
      timed(round.render_seconds, [&] { samples = render_seeds(seeds, open); });
      round.seeds = seeds.size();
      timed(round.update_seconds, [&] {
        const std::size_t first_new = append_records(seeds, samples, round);
        const bool limited = limit_radii(first_new);
        mark_dirty(first_new);
        // Only radii changed since limit_radii built the tree (if it did): refit its boxes.
        if (limited)
          bvh_.refit(records_, o_);
        else
          bvh_.build(records_, o_, threads_);
      });
      stats_.round_details.push_back(round);
      ++stats_.rounds;
      if (spacing_ > finest_)
        spacing_ = std::max(finest_, 0.5f * spacing_);
      else if (seeds.empty())
        break;  // defensive: nothing could be placed
    }
    if (o_.second_order && o_.use_gradients) fit_hessians(records_, o_, threads_);
    cache_result result;
    const auto t_final = std::chrono::steady_clock::now();
    interpolate_all(result);
    stats_.invalid_points = count_invalid(result);
    if (o_.fill_invalid) fill_invalid(result);
    stats_.interpolation_seconds = seconds_since(t_final);
    for (const cache_round_stats& r : stats_.round_details) stats_.render_seconds += r.render_seconds;
    stats_.records = records_.size();
    stats_.min_radius = o_.min_radius;
    stats_.max_radius = o_.max_radius;
    stats_.seconds = seconds_since(start);
    stats_.placement_seconds = std::max(0.0, stats_.seconds - stats_.render_seconds - stats_.interpolation_seconds);
    report(1.0f);
    result.records = std::move(records_);
    result.stats = stats_;
    return result;
  }

 private:
  static double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  }
  template <class F>
  static void timed(double& seconds, F&& f) {
    const auto t = std::chrono::steady_clock::now();
    f();
    seconds += seconds_since(t);
  }

  // Coverage can drop between rounds (radii shrink), so the reported fraction is the running
  // maximum: progress never goes backwards.
  void report(float fraction) {
    reported_ = std::max(reported_, fraction);
    if (o_.progress && !o_.progress(reported_)) throw error(status::cancelled, "cache_irradiance: cancelled by the progress callback");
  }

  // Automatic radii from the points' extent and spacing (cache_options::min_radius, max_radius).
  void derive_radii() {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (std::size_t i = 0; i < count_; ++i) {
      lo = glm::min(lo, p_[i]);
      hi = glm::max(hi, p_[i]);
    }
    lo_ = lo;
    hi_ = hi;
    diagonal_ = glm::length(hi - lo);
    const float a = o_.error_threshold;
    if (o_.min_radius == 0.0f) {
      const float spacing = median_spacing(p_, count_, diagonal_);
      o_.min_radius = spacing > 0.0f ? spacing / a : std::max(diagonal_, 1e-3f) * 1e-3f;
    }
    if (o_.max_radius == 0.0f) o_.max_radius = 0.2f * diagonal_;
    o_.max_radius = std::max(o_.max_radius, o_.min_radius);
    spacing_ = a * o_.max_radius;
    finest_ = a * o_.min_radius;
    nearby_reach_ = o_.nearby_opinion * finest_;
    contact_backface_ = 0.1f * o_.invalid_backface_fraction;
  }

  void set_up() {
    bvh_.build(records_, o_);
    for (auto* v : {&covered_, &own_invalid_, &presumed_, &contested_}) v->assign(count_, 0);
    dirty_.assign(count_, 1);  // the first coverage pass tests every point
    record_at_point_.assign(count_, -1);
    grid_of_points_.build(p_, count_);
    std::vector<std::uint64_t> key(count_);
    for (std::size_t i = 0; i < count_; ++i) key[i] = mix(i);
    order_.resize(count_);
    std::iota(order_.begin(), order_.end(), std::size_t(0));
    std::sort(order_.begin(), order_.end(), [&](std::size_t x, std::size_t y) { return key[x] < key[y]; });
    // The coverage tests weigh records with Ward's own weight under ward_continuous too, so that
    // both place the same records (only the final interpolation differs; cache.hpp).
    coverage_options_ = o_;
    if (coverage_options_.weight == cache_weight::ward_continuous) coverage_options_.weight = cache_weight::ward;
    coverage_options_.progress = nullptr;
    coverage_options_.second_order = false;  // the Hessians are fitted after placement
  }

  bool inside(std::size_t i) const { return own_invalid_[i] || (presumed_[i] && !contested_[i]); }
  bool open(std::size_t i) const { return !covered_[i] && !inside(i); }
  std::size_t count_open() const {
    std::size_t open_points = 0;
    for (std::size_t i = 0; i < count_; ++i) open_points += open(i) ? 1u : 0u;
    return open_points;
  }

  // 1. Coverage of every point whose answer can have changed (parallel, read-only on the
  // records): the dirty points (all of them in the first pass; then those in the reach of a
  // record added or shrunk in the last round, within nearby_opinion's reach of a new record, or
  // newly presumed inside). Every other point, open or covered, sees the same records with the
  // same radii as when it was last checked, and its opinions come from the same records, so its
  // answer stands. The dark floor of the tests
  // (floor_e_: 5% of the mean irradiance of the first round's records, a uniform sample of the
  // points) is fixed once set, so no answer depends on records far away.
  void coverage_pass(cache_round_stats& round) {
    if (!floor_set_ && !records_.empty()) {
      double mean = 0.0;
      for (const cache_record& r : records_) mean += luminance(r.irradiance);
      floor_e_ = 0.05f * float(mean / double(records_.size()));
      floor_set_ = true;
    }
    struct tally {
      std::size_t checked = 0, visited = 0, max_visited = 0;
      std::array<std::size_t, cache_stats::histogram_buckets> histogram{};
    };
    std::vector<tally> tallies(static_cast<std::size_t>(threads_));
    parallel_for(count_, threads_, 4096, [&](int worker, std::size_t b, std::size_t e) {
      tally& t = tallies[std::size_t(worker)];
      for (std::size_t i = b; i < e; ++i) {
        if (own_invalid_[i] || !dirty_[i]) continue;
        std::size_t visited = 0;
        check_point(i, visited);
        ++t.checked;
        t.visited += visited;
        t.max_visited = std::max(t.max_visited, visited);
        ++t.histogram[cache_stats::histogram_bucket(visited)];
      }
    });
    for (const tally& t : tallies) {
      round.points_checked += t.checked;
      round.records_visited += t.visited;
      round.max_records_visited = std::max(round.max_records_visited, t.max_visited);
      for (std::size_t k = 0; k < t.histogram.size(); ++k) stats_.records_visited_histogram[k] += t.histogram[k];
    }
    std::fill(dirty_.begin(), dirty_.end(), std::uint8_t(0));
  }

  // The coverage test of one point (coverage_pass); `visited` counts the records the query saw.
  void check_point(std::size_t i, std::size_t& visited) {
    const float a = o_.error_threshold;
    glm::vec3 value;
    float spread = 0.0f;
    bool own = false;
    coverage_detail detail;
    detail.floor = floor_e_;
    const float w = interpolate(records_, bvh_, p_[i], n_[i], coverage_options_, value, &spread, &own, nullptr, nullptr, &detail);
    visited = detail.visited;
    bool ok = w > 0.0f;
    // Presumed inside: a valid record that covers the point contests the presumption (the point
    // may lie across a contact from the invalid sample); from then on it needs its own hemicube.
    if (presumed_[i] && !contested_[i]) {
      if (!ok) {
        covered_[i] = 0;
        return;
      }
      contested_[i] = 1;
    }
    if (contested_[i]) ok = ok && own;
    // A covering record that saw back faces stands at a contact or an intersection: its
    // neighbours get their own hemicubes rather than its extrapolation.
    if (ok && !own && detail.max_backface > contact_backface_) ok = false;
    if (ok && o_.refine_disagreement && !own) ok = spread <= a * std::max(luminance(value), floor_e_);
    // Second opinion: a point that only one record covers is not covered while that record's
    // first-order term there exceeds second_opinion x a x max(E_i, floor): no other record can
    // disagree with an extrapolation that may be wrong (an edge between two rows of points, a
    // second derivative the gradient does not see).
    if (ok && o_.second_opinion > 0.0f && !own && detail.records == 1) ok = detail.first_order <= o_.second_opinion * a;
    // Sole record reach: a point that one record covers must lie inside sole_record_reach of
    // that record's reach (Ward: weight >= 1 / (sole_record_reach x a)), not on its rim.
    if (ok && o_.sole_record_reach < 1.0f && !own && detail.records == 1 && coverage_options_.weight == cache_weight::ward)
      ok = detail.max_weight >= 1.0f / (o_.sole_record_reach * a);
    // Nearby opinion: records near a point that one record covers, which do not cover it
    // themselves, must predict the same there within a (a hard shadow edge between two rows of
    // points is invisible to the covering record's gradient, not to a record beyond it).
    if (ok && o_.nearby_opinion > 0.0f && !own && detail.records == 1) ok = nearby_records_agree(i, detail);
    covered_[i] = ok ? 1 : 0;
  }

  bool nearby_records_agree(std::size_t i, const coverage_detail& detail) const {
    const glm::vec3 x = p_[i], nx = n_[i];
    const float la = std::max(detail.last_prediction, 0.0f);
    const float tolerance = o_.error_threshold * std::max(la, floor_e_);
    bool ok = true;
    grid_of_points_.for_each_in_sphere(x, nearby_reach_, [&](std::uint32_t j) {
      const std::int32_t k = record_at_point_[j];
      if (!ok || k < 0 || std::uint32_t(k) == detail.last) return;
      const cache_record& rb = records_[std::size_t(k)];
      if (glm::dot(rb.normal, nx) <= 0.9f || record_is_behind(rb, x, nx)) return;
      const float lb = luminance(glm::max(extrapolate(rb, x, nx, o_.use_gradients ? 1 : 0), glm::vec3(0.0f)));
      if (std::fabs(lb - la) > tolerance) ok = false;
    });
    return ok;
  }

  // 2. Seeds: open points in the fixed order, at least `spacing` from this round's earlier seeds
  // of a similar normal; at the finest spacing every open point is a seed. The round's seeds go
  // into a uniform grid of cells at least `spacing` wide, so a candidate looks at the seeds of
  // the cells around it only (cost O(open points), whatever the spacing).
  std::vector<std::size_t> pick_seeds() {
    std::vector<std::size_t> seeds;
    const bool finest = !(spacing_ > finest_);
    if (finest) {
      for (std::size_t i : order_)
        if (open(i)) seeds.push_back(i);
      return seeds;
    }
    seed_cells_.reset(lo_, hi_, spacing_, count_);
    const float r2 = spacing_ * spacing_;
    // The points are visited in a pseudo-random order: their open flags go into one small array
    // first, and the positions and normals a few steps ahead are prefetched.
    is_open_.resize(count_);
    for (std::size_t i = 0; i < count_; ++i) is_open_[i] = open(i) ? 1 : 0;
    constexpr std::size_t ahead = 16;
    for (std::size_t k = 0; k < count_; ++k) {
      if (k + ahead < count_) {
        const std::size_t q = order_[k + ahead];
        __builtin_prefetch(&p_[q]);
        __builtin_prefetch(&n_[q]);
      }
      const std::size_t i = order_[k];
      if (!is_open_[i]) continue;
      const glm::vec3 x = p_[i], nx = n_[i];
      const bool blocked = seed_cells_.any_near(x, spacing_, [&](const glm::vec3& c, const glm::vec3& nc) {
        const glm::vec3 d = x - c;
        return glm::dot(d, d) <= r2 && glm::length(x - c) < spacing_ && glm::dot(nx, nc) > 0.9f;
      });
      if (blocked) continue;
      seed_cells_.insert(x, nx);
      seeds.push_back(i);
    }
    return seeds;
  }

  // 3. The seeds' hemicubes in parallel; results land in per-seed slots (deterministic).
  std::vector<cache_sample> render_seeds(const std::vector<std::size_t>& seeds, std::size_t open_points) {
    std::vector<cache_sample> samples(seeds.size());
    std::atomic<bool> cancel{false};
    std::atomic<std::size_t> done{0};
    const float covered_fraction = 1.0f - float(open_points) / float(count_);
    parallel_for(seeds.size(), threads_, 1, [&](int worker, std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e && !cancel; ++k) {
        samples[k] = sampler_(worker, p_[seeds[k]], n_[seeds[k]]);
        const std::size_t finished = ++done;
        // Worker 0 is the calling thread: the only one that calls progress.
        if (worker == 0 && o_.progress) {
          reported_ = std::max(reported_, covered_fraction + (1.0f - covered_fraction) * float(finished) / float(seeds.size()) * 0.99f);
          if (!o_.progress(reported_)) cancel = true;
        }
      }
    });
    if (cancel) throw error(status::cancelled, "cache_irradiance: cancelled by the progress callback");
    stats_.hemicubes += seeds.size();
    return samples;
  }

  // 4. New records in seed order with their own radius limits (split sphere, gradient limit,
  // clamp to [min_radius, max_radius]); invalid samples mark their point and, within their
  // exclusion ball, the points on the same side of the same surface (presume_inside). Returns
  // the index of the first new record.
  std::size_t append_records(const std::vector<std::size_t>& seeds, const std::vector<cache_sample>& samples,
                             cache_round_stats& round) {
    const std::size_t first_new = records_.size();
    old_radius_.resize(first_new);
    for (std::size_t j = 0; j < first_new; ++j) old_radius_[j] = records_[j].radius;
    for (std::size_t k = 0; k < seeds.size(); ++k) {
      const std::size_t i = seeds[k];
      const cache_sample& s = samples[k];
      if (s.backface_fraction > o_.invalid_backface_fraction) {
        ++stats_.invalid_samples;
        ++round.invalid_samples;
        own_invalid_[i] = 1;
        presume_inside(i, s.min_distance);
        continue;
      }
      records_.push_back(make_record(i, s));
      record_at_point_[i] = static_cast<std::int32_t>(records_.size() - 1);
    }
    round.records_added = records_.size() - first_new;
    return first_new;
  }

  cache_record make_record(std::size_t i, const cache_sample& s) const {
    cache_record r;
    r.position = p_[i];
    r.normal = n_[i];
    r.irradiance = s.irradiance;
    r.rotation_gradient = s.rotation_gradient;
    r.translation_gradient = s.translation_gradient;
    r.harmonic_distance = s.harmonic_mean_distance;
    r.backface_fraction = s.backface_fraction;
    if (o_.directional) {
      r.sh_l1 = s.sh_l1;
      r.cone = s.cone;
    }
    float radius = std::isfinite(s.harmonic_mean_distance) ? s.harmonic_mean_distance : o_.max_radius;
    if (o_.gradient_radius_limit) {
      const float gt = glm::length(0.2126f * s.translation_gradient[0] + 0.7152f * s.translation_gradient[1] +
                                   0.0722f * s.translation_gradient[2]);
      const float e = luminance(s.irradiance);
      if (gt > 0.0f && e > 0.0f) radius = std::min(radius, e / gt);
    }
    r.radius = std::clamp(radius, o_.min_radius, o_.max_radius);
    return r;
  }

  // An invalid sample at point i saw nothing nearer than min_distance in its visible half-space:
  // points within 0.9 of that distance, on the visible side of its tangent plane (not below it by
  // more than 1% of the ball) and with a similar normal (n . n_i > 0.9), lie in the same closed
  // region, so they are presumed inside without a hemicube of their own. Points on other surfaces
  // (a wall meeting the floor, a slab's underside inside another slab) are never presumed: the
  // ball says nothing behind the sample. A valid record covering a presumed point contests it
  // (check_point).
  void presume_inside(std::size_t i, float min_distance) {
    if (!std::isfinite(min_distance) || !(min_distance > 0.0f)) return;
    const float ball = 0.9f * min_distance;
    const glm::vec3 c = p_[i], nc = n_[i];
    grid_of_points_.for_each_in_sphere(c, ball, [&](std::uint32_t j) {
      if (presumed_[j] || glm::dot(n_[j], nc) <= 0.9f || glm::dot(p_[j] - c, nc) < -0.01f * ball) return;
      presumed_[j] = 1;
      dirty_[j] = 1;
    });
  }

  // 5. Neighbour clamping and shrinking of disagreeing neighbours, sequential in record order
  // over pairs (new record, any record) within reach (deterministic). Returns whether it built
  // the record tree (then only radii changed since, and a refit suffices).
  bool limit_radii(std::size_t first_new) {
    if (!(records_.size() > first_new && (o_.neighbour_clamp || o_.shrink_disagreeing))) return false;
    const float a = o_.error_threshold;
    bvh_.build(records_, o_, threads_);
    // The pairs of each new record i: records j whose coverage box holds x_i, with their distance
    // and whether their first-order predictions of each other disagree by more than a (neither
    // depends on the radii, so both are found first, in parallel; the tree is not rebuilt during
    // the sequential pass below).
    struct pair {
      std::uint32_t j;
      bool disagree;
      float d;
    };
    const bool shrink = o_.shrink_disagreeing;
    std::vector<std::vector<pair>> candidates(records_.size() - first_new);
    parallel_for(candidates.size(), threads_, 64, [&](int, std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        std::vector<pair>& near = candidates[k];
        const std::size_t i = first_new + k;
        const cache_record& ri = records_[i];
        bvh_.query(ri.position, [&](const record_bvh::key& key) {
          if (std::size_t(key.index) != i)
            near.push_back({key.index, shrink && glm::dot(ri.normal, key.normal) > 0.9f, glm::length(ri.position - key.position)});
        });
        std::sort(near.begin(), near.end(), [](const pair& x, const pair& y) { return x.j < y.j; });
        for (pair& q : near) {
          // (disagree holds "similar normals" until here.)
          if (q.disagree && q.d > 0.0f) {
            const cache_record& rj = records_[q.j];
            // Each record's first-order prediction of the other's irradiance (luminance).
            const float ei = luminance(ri.irradiance), ej = luminance(rj.irradiance);
            const float pij = luminance(extrapolate(ri, rj.position, rj.normal, 1));
            const float pji = luminance(extrapolate(rj, ri.position, ri.normal, 1));
            const float err = std::max(std::fabs(pij - ej) / std::max(ej, 1e-20f), std::fabs(pji - ei) / std::max(ei, 1e-20f));
            q.disagree = err > a;
          } else {
            q.disagree = false;
          }
        }
      }
    });
    for (std::size_t i = first_new; i < records_.size(); ++i) {
      for (const pair& q : candidates[i - first_new]) {
        cache_record& ri = records_[i];
        cache_record& rj = records_[q.j];
        const float d = q.d;
        if (o_.neighbour_clamp) {
          ri.radius = std::max(o_.min_radius, std::min(ri.radius, rj.radius + d));
          rj.radius = std::max(o_.min_radius, std::min(rj.radius, ri.radius + d));
        }
        if (q.disagree) {
          // Shrink so that their coverage (a R each) leaves a gap between them: 0.4 d each.
          const float r_gap = std::max(o_.min_radius, 0.4f * d / a);
          ri.radius = std::min(ri.radius, r_gap);
          rj.radius = std::min(rj.radius, r_gap);
        }
      }
    }
    return true;
  }

  // 6. Points whose coverage this round's records can have changed (a shrunk record's old
  // sphere holds its new one) are re-checked in the next coverage pass.
  void mark_dirty(std::size_t first_new) {
    const float a = o_.error_threshold;
    // Worker 0 marks dirty_ itself, the others their own arrays, OR-ed in after (only ones are
    // written, so the result does not depend on which worker marked what).
    dirty_extra_.resize(std::size_t(std::max(threads_ - 1, 0)));
    for (std::vector<std::uint8_t>& v : dirty_extra_) v.assign(count_, 0);
    parallel_for(records_.size(), threads_, 256, [&](int worker, std::size_t b, std::size_t e) {
      std::uint8_t* dirty = worker == 0 ? dirty_.data() : dirty_extra_[std::size_t(worker - 1)].data();
      for (std::size_t j = b; j < e; ++j) {
        const bool added = j >= first_new;
        if (!added && records_[j].radius == old_radius_[j]) continue;
        const float r = coverage_radius(records_[j], o_);
        const float reach = added ? r : std::max(r, a * old_radius_[j]);
        // (1e-4 wider: the weights measure distance with glm::length, the grid with a squared one.)
        grid_of_points_.for_each_in_sphere(records_[j].position, reach * 1.0001f, [&](std::uint32_t i) { dirty[i] = 1; });
        // nearby_opinion consults the records placed within nearby_reach of a point.
        if (added && o_.nearby_opinion > 0.0f)
          grid_of_points_.for_each_in_sphere(records_[j].position, nearby_reach_ * 1.0001f, [&](std::uint32_t i) { dirty[i] = 1; });
      }
    });
    for (const std::vector<std::uint8_t>& v : dirty_extra_)
      for (std::size_t i = 0; i < count_; ++i) dirty_[i] |= v[i];
  }

  // 7. Final interpolation (parallel) of every point that is not inside geometry.
  void interpolate_all(cache_result& result) const {
    result.irradiance.assign(count_, glm::vec3(0.0f));
    result.valid.assign(count_, 0);
    if (o_.directional) {
      result.sh_l1.assign(count_, std::array<glm::vec3, 4>{});
      result.cone.assign(count_, hl2_cone{});
    }
    parallel_for(count_, threads_, 4096, [&](int, std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        glm::vec3 v;
        std::array<glm::vec3, 4> sh{};
        hl2_cone cone;
        if (!inside(i) && interpolate(records_, bvh_, p_[i], n_[i], o_, v, nullptr, nullptr, o_.directional ? &sh : nullptr,
                                      o_.directional ? &cone : nullptr) > 0.0f) {
          result.irradiance[i] = v;
          result.valid[i] = 1;
          if (o_.directional) {
            result.sh_l1[i] = sh;
            result.cone[i] = cone;
          }
        }
      }
    });
  }

  // 8. Points inside geometry (or, defensively, left uncovered) get the relaxed-weight average
  // (1 / (d / R + sqrt(1 - n.n_i)), no threshold) of the 8 best records on the same side of
  // their surface (n . n_i > 0.5, not behind), searched in spheres that double from 4 x the finest
  // seed spacing; from the third doubling on, of any records in the sphere.
  std::size_t count_invalid(const cache_result& result) const {
    std::size_t invalid = 0;
    for (std::uint8_t v : result.valid) invalid += v ? 0u : 1u;
    return invalid;
  }

  void fill_invalid(cache_result& result) const {
    if (records_.empty() || stats_.invalid_points == 0) return;
    std::vector<std::size_t> fill;
    for (std::size_t i = 0; i < count_; ++i)
      if (!result.valid[i]) fill.push_back(i);
    std::vector<glm::vec3> where(records_.size());
    for (std::size_t j = 0; j < records_.size(); ++j) where[j] = records_[j].position;
    point_grid grid;
    grid.build(where.data(), where.size());
    parallel_for(fill.size(), threads_, 256, [&](int, std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) fill_point(fill[k], grid, result);
    });
  }

  void fill_point(std::size_t i, const point_grid& grid, cache_result& result) const {
    std::array<std::pair<float, std::uint32_t>, 8> best;
    best.fill({0.0f, 0u});
    const auto consider = [&](std::uint32_t j, bool same_side) {
      const cache_record& r = records_[j];
      if (same_side && (glm::dot(n_[i], r.normal) <= 0.5f || record_is_behind(r, p_[i], n_[i]))) return;
      const float denom = glm::length(p_[i] - r.position) / r.radius + std::sqrt(std::max(0.0f, 1.0f - glm::dot(n_[i], r.normal)));
      const float w = 1.0f / std::max(denom, 1e-12f);
      if (w > best.back().first || (w == best.back().first && j < best.back().second && w > 0.0f)) {
        best.back() = {w, j};
        // Weight, then index: a fixed order whatever order the grid visits records in.
        std::sort(best.begin(), best.end(), [](const auto& x, const auto& y) {
          return x.first > y.first || (x.first == y.first && x.second < y.second);
        });
      }
    };
    // Doubling spheres: records on the point's side first; from 4 x the first radius on, any
    // record in the sphere (a point deep inside a solid may have no record on its side nearby).
    const float first = 4.0f * std::max(finest_, 1e-30f);
    for (float radius = first; best.front().first == 0.0f; radius *= 2.0f) {
      grid.for_each_in_sphere(p_[i], radius, [&](std::uint32_t j) { consider(j, true); });
      if (best.front().first == 0.0f && radius >= 4.0f * first)
        grid.for_each_in_sphere(p_[i], radius, [&](std::uint32_t j) { consider(j, false); });
      if (radius > 2.0f * diagonal_ + o_.max_radius) break;
    }
    if (best.front().first == 0.0f)  // defensive: the spheres above end beyond every record
      for (std::uint32_t j = 0; j < records_.size(); ++j) consider(j, false);
    glm::vec3 sum(0.0f);
    std::array<glm::vec3, 4> sh{};
    hl2_cone cone;
    cone.reference = make_frame(n_[i]).t;
    float wsum = 0.0f;
    for (const auto& bw : best)
      if (bw.first > 0.0f) {
        const cache_record& rec = records_[bw.second];
        sum += bw.first * rec.irradiance;
        if (o_.directional) {
          for (std::size_t c = 0; c < 4; ++c) sh[c] += bw.first * rec.sh_l1[c];
          const hl2_cone rc = rotate_hl2_cone(rec.cone, rec.normal, cone.reference);
          for (std::size_t c = 0; c < std::size_t(hl2_cone_terms); ++c) cone.coefficients[c] += bw.first * rc.coefficients[c];
        }
        wsum += bw.first;
      }
    result.irradiance[i] = wsum > 0.0f ? sum / wsum : glm::vec3(0.0f);
    if (o_.directional && wsum > 0.0f) {
      for (std::size_t c = 0; c < 4; ++c) result.sh_l1[i][c] = sh[c] / wsum;
      for (glm::vec3& c : cone.coefficients) c /= wsum;
      result.cone[i] = cone;
    }
  }

  const glm::vec3* p_;
  const glm::vec3* n_;
  std::size_t count_;
  const irradiance_sampler& sampler_;
  cache_options o_;
  cache_options coverage_options_;
  int threads_ = 1;
  float diagonal_ = 0.0f, spacing_ = 0.0f, finest_ = 0.0f, nearby_reach_ = 0.0f, reported_ = 0.0f;
  float contact_backface_ = 0.0f;
  float floor_e_ = 0.0f;   // the tests' dark floor (coverage_pass), fixed once set
  bool floor_set_ = false;  // records seeing more back faces than this stand at a contact (check_point)
  std::vector<cache_record> records_;
  record_bvh bvh_;
  point_grid grid_of_points_;
  std::vector<std::uint8_t> covered_, dirty_, own_invalid_, presumed_, contested_;
  seed_grid seed_cells_;  // pick_seeds: the round's seeds so far
  std::vector<std::uint8_t> is_open_;  // pick_seeds: open(i) of every point
  glm::vec3 lo_{0.0f}, hi_{0.0f};  // the points' bounding box
  std::vector<std::int32_t> record_at_point_;  // per point: the record placed there, or -1
  std::vector<std::size_t> order_;             // the fixed pseudo-random order of the points
  std::vector<float> old_radius_;
  std::vector<std::vector<std::uint8_t>> dirty_extra_;  // mark_dirty: workers 1, 2, ...' marks
  cache_stats stats_;
};

}  // namespace

cache_result cache_irradiance(const glm::vec3* positions, const glm::vec3* normals, std::size_t count,
                              const irradiance_sampler& sampler, const cache_options& options) {
  validate(positions, normals, count, options);
  if (!sampler) throw_invalid_argument("cache_irradiance: sampler is empty");
  return placement(positions, normals, count, sampler, options).run();
}


irradiance_sampler make_hemicube_sampler(std::shared_ptr<const scene> s, const hemicube_sampler_options& o, int workers) {
  if (!s) throw_invalid_argument("make_hemicube_sampler: scene is null");
  if (workers < 1) throw_invalid_argument("make_hemicube_sampler: workers is " + std::to_string(workers) + "; it must be >= 1");
  if (o.sh_l1 && !o.integrate.rotation_gradient)
    throw_invalid_argument("make_hemicube_sampler: sh_l1 needs integrate.rotation_gradient (band 1 comes from it)");
  std::shared_ptr<const hemicube_table> table = o.sh_l1 ? hemicube_table::get(o.resolution) : nullptr;
  std::shared_ptr<const cone_weights> cone_table = o.hl2_cone ? make_cone_weights(o.resolution) : nullptr;
  struct context {
    hemicube_rasterizer raster;
    hemicube_integrator integrator;
    hemicube_buffer buffer;
  };
  auto contexts = std::make_shared<std::vector<std::unique_ptr<context>>>();
  for (int w = 0; w < workers; ++w)
    contexts->push_back(std::make_unique<context>(context{hemicube_rasterizer(s, o.raster),
                                                          hemicube_integrator(o.resolution, o.integrate), {}}));
  return [contexts, o, table, cone_table](int worker, const glm::vec3& x, const glm::vec3& n) -> cache_sample {
    if (worker < 0 || std::size_t(worker) >= contexts->size())
      throw_invalid_argument("hemicube sampler: worker " + std::to_string(worker) + " is out of range");
    context& c = *(*contexts)[std::size_t(worker)];
    frame f = make_frame(n);
    if (o.roll) {
      std::uint32_t bits[3];
      std::memcpy(bits, &x, sizeof bits);
      const std::uint64_t h = mix((std::uint64_t(bits[0]) << 32 | bits[1]) ^ mix(bits[2]));
      const float angle = float(h >> 40) * (6.2831853f / float(1u << 24));
      const glm::vec3 t = std::cos(angle) * f.t + std::sin(angle) * f.b;
      f.b = glm::cross(f.n, t);
      f.t = t;
    }
    c.raster.render(x, f, o.resolution, c.buffer, o.texture);
    cache_sample out = c.integrator.integrate(c.buffer);
    const std::size_t count = c.buffer.texel_count();
    const hemicube_buffer& cb = c.buffer;
    const float* pr = cb.channel(0);  // the buffer's radiance is planar (hemicube.hpp)
    const float* pg = cb.channel(1);
    const float* pb = cb.channel(2);
    if (cone_table) {
      // 7 terms x 3 channels over the planes (weighted_sums: deterministic order).
      double total[hl2_cone_terms][3] = {};
      for (std::size_t k = 0; k < std::size_t(hl2_cone_terms); ++k) weighted_sums(pr, pg, pb, cone_table->w[k].data(), count, total[k]);
      out.cone.reference = f.t;
      for (std::size_t k = 0; k < std::size_t(hl2_cone_terms); ++k)
        out.cone.coefficients[k] = glm::vec3(float(total[k][0]), float(total[k][1]), float(total[k][2]));
    }
    if (o.sh_l1) {
      // Band 0: solid-angle-weighted radiance; band 1: Y1 times Phi = E n + g_r x n (per channel).
      constexpr double y00 = 0.282094791773878143, y1 = 0.488602511902919921;
      double s0[3] = {0.0, 0.0, 0.0};
      weighted_sums(pr, pg, pb, table->solid_angle(), count, s0);
      for (int ch = 0; ch < 3; ++ch) {
        const glm::dvec3 phi = double(out.irradiance[ch]) * glm::dvec3(f.n) +
                               glm::cross(glm::dvec3(out.rotation_gradient[std::size_t(ch)]), glm::dvec3(f.n));
        out.sh_l1[0][ch] = float(y00 * s0[ch]);
        out.sh_l1[1][ch] = float(y1 * phi.y);
        out.sh_l1[2][ch] = float(y1 * phi.z);
        out.sh_l1[3][ch] = float(y1 * phi.x);
      }
    }
    return out;
  };
}

}  // namespace hemilight
