// The irradiance cache: record weights, a bounding-volume hierarchy over records, deterministic
// round-based placement, radius limits, interpolation. See cache.hpp.
#include "hemilight/cache.hpp"

#include "hemilight/parallel.hpp"

#include "table_cache.hpp"

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
// placement::candidate_count: seed candidates per seed spacing along a surface (so about 9 per
// spacing x spacing square); 3 keeps the seeds' spacing as with every point a candidate (the
// records, hemicube counts and errors: docs/cache.md) while checking a third fewer points.
constexpr double candidates_per_spacing = 3.0;
// placement: a record whose coverage sphere holds at most max_listed_points points is listed at
// them (record_lists) while the lists hold fewer than list_entries_per_point entries per point in
// all; the others go into a tree of their own. Lists make a coverage test cheap; the budget bounds
// their memory (docs/cache.md: the time and memory of both).
constexpr std::size_t max_listed_points = 1024;
constexpr std::size_t list_entries_per_point = 8;
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
// R is a cache_record or a record_lists::key (anything with position, normal and radius).
template <class R>
inline float coverage_weight(const R& r, const glm::vec3& x, const glm::vec3& n, const cache_options& o) {
  // Both weights are 0 beyond d = a R (Ward: d / R >= a makes w <= 1/a; T-L: d / (R/2) >= 2a makes
  // w <= 0). Points beyond it by more than float rounding (1e-4 relative: the arithmetic below
  // rounds by ~1e-7) are rejected without the square roots and the division: the same result.
  const glm::vec3 dx = x - r.position;
  const float reach = o.error_threshold * r.radius;
  if (glm::dot(dx, dx) > 1.0002f * reach * reach) return 0.0f;
  const float d = glm::length(dx);
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

// What a record's first-order prediction needs, compact (a third of a cache_record): predict()
// gives bit for bit extrapolate(record, x, n, 1).
struct linear_model {
  glm::vec3 position, normal, irradiance;
  std::array<glm::vec3, 3> rotation_gradient, translation_gradient;
  explicit linear_model(const cache_record& r)
      : position(r.position), normal(r.normal), irradiance(r.irradiance), rotation_gradient(r.rotation_gradient),
        translation_gradient(r.translation_gradient) {}
  glm::vec3 predict(const glm::vec3& x, const glm::vec3& n) const {
    glm::vec3 e = irradiance;
    const glm::vec3 rot = glm::cross(normal, n);
    const glm::vec3 dx = x - position;
    for (int c = 0; c < 3; ++c)
      e[c] += glm::dot(rot, rotation_gradient[std::size_t(c)]) + glm::dot(dx, translation_gradient[std::size_t(c)]);
    return e;
  }
};

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

// What a query needs of a record to weigh it (32 bytes; the records themselves are ten times
// larger): the weights and is_behind read only these, bit for bit the record's.
struct record_key {
  glm::vec3 position;
  float radius;
  glm::vec3 normal;
  std::uint32_t index;  // the record's index
};

// A bounding-volume hierarchy over the records' coverage boxes (centre +- a R), rebuilt after
// every round's new records are appended (limit_radii finds each new record's neighbours with it:
// the records of every leaf whose box holds the new record's position). Median splits on the
// longest axis of the centres, leaves of at most 4 records: the tree, and so the neighbours, depend
// only on the positions and radii, not on the thread count.
class record_bvh {
 public:
  // What a query reports of a record (32 bytes; the records themselves are ten times larger).
  using key = record_key;

  // threads: how many cores the build may use (the two halves below the root are built in
  // parallel; the tree is the same for any count).
  // `subset`: the indices of the records to hold, ascending, or nullptr for all of them.
  void build(const std::vector<cache_record>& records, const cache_options& o, int threads = 1,
             const std::vector<std::uint32_t>* subset = nullptr) {
    nodes_.clear();
    const std::size_t n = subset ? subset->size() : records.size();
    items_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const std::uint32_t i = subset ? (*subset)[k] : static_cast<std::uint32_t>(k);
      const float r = coverage_radius(records[i], o);
      items_[k] = {records[i].position, records[i].position - glm::vec3(r), records[i].position + glm::vec3(r), i};
    }
    if (n == 0) {
      keys_.clear();
      return;
    }
    const auto count = static_cast<std::uint32_t>(n);
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

  // Calls f(key) for every record of every leaf whose box holds x.
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
  // A record while the tree is built: its centre, its box, its index (items_ is reordered).
  struct item {
    glm::vec3 centre, lo, hi;
    std::uint32_t index;
  };

  // Sets nd's box over items_[begin, end); returns 0 if it stays a leaf (<= 4 records), else
  // the split point after a median split on the longest axis of the centres (items_ reordered:
  // which records fall on either side is fixed by a total order, their order within a side is not
  // and does not matter).
  std::uint32_t split(node& nd, std::uint32_t begin, std::uint32_t end) {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    glm::vec3 clo = lo, chi = hi;
    for (std::uint32_t k = begin; k < end; ++k) {
      const item& it = items_[k];
      lo = glm::min(lo, it.lo);
      hi = glm::max(hi, it.hi);
      clo = glm::min(clo, it.centre);
      chi = glm::max(chi, it.centre);
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
    std::nth_element(items_.begin() + begin, items_.begin() + mid, items_.begin() + end, [axis](const item& a, const item& b) {
      const float pa = a.centre[axis], pb = b.centre[axis];
      return pa < pb || (pa == pb && a.index < b.index);  // total order: deterministic
    });
    nd.count = 0;
    return mid;
  }
  // Builds the subtree of items_[begin, end) with its root at out[slot]; children are allocated
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
    keys_.resize(items_.size());
    for (std::size_t k = 0; k < items_.size(); ++k) {
      const cache_record& r = records[items_[k].index];
      keys_[k] = {r.position, r.radius, r.normal, items_[k].index};
    }
  }

  std::vector<item> items_;
  std::vector<key> keys_;  // in items_ order
  std::vector<node> nodes_;
};

// Which records can cover each point: per point, the records whose coverage sphere (radius a R)
// held it when they were added. Radii only shrink after a record is added (cache.hpp: limits),
// so the records that cover a point now are among them, and a query at a point reads one short
// list instead of searching a structure. A record whose sphere shrank past the point stays in the
// list until compact() drops it; the weight test ignores it meanwhile. Every query in placement
// and in the final interpolation is at one of the points. A list's first inline_room entries are
// kept inline; the rest lie in the pool of the point's owner, and a full one moves to the end of
// that pool with twice the room. Also holds every record's key (with its current radius).
// Queries are read-only and may run in parallel; add, append and set_radius may not run during
// them, appends to points of different owners may.
class record_lists {
 public:
  using key = record_key;

  // owners: how many workers may append at once (each to the points it owns, owner()).
  void reset(std::size_t points, int owners) {
    keys_.clear();
    std::size_t pools = 1;  // a power of two: owner() is a mask
    while (pools < std::size_t(std::max(owners, 1))) pools *= 2;
    pools_.assign(pools, {});
    compacted_size_.assign(pools, 0);
    inline_.assign(points * inline_room, 0);
    begin_.assign(points, 0);
    size_.assign(points, 0);
    room_.assign(points, 0);
  }

  std::size_t size() const { return keys_.size(); }
  const key& operator[](std::size_t i) const { return keys_[i]; }
  void add(const cache_record& r) { keys_.push_back({r.position, r.radius, r.normal, static_cast<std::uint32_t>(keys_.size())}); }
  // A record's radius after it shrank.
  void set_radius(std::size_t index, float radius) { keys_[index].radius = radius; }

  std::size_t owners() const { return pools_.size(); }

  // Which owner's pool holds the overflow of `point`'s list: appends to points of different
  // owners may run in parallel. Blocks of 64 points, so that owners do not share cache lines.
  std::size_t owner(std::size_t point) const { return (point >> 6) & (pools_.size() - 1); }

  // Lays the overflow lists of owner w's points out again in point order, each with room for its
  // records only, when its pool has grown to more than twice its size at the last layout (lists
  // move to the end of the pool as they grow, and leave their old room behind).
  void lay_out(std::size_t w) {
    std::vector<std::uint32_t>& pool = pools_[w];
    if (pool.size() <= 2 * compacted_size_[w] + 1024) return;
    std::vector<std::uint32_t> fresh;
    fresh.reserve(pool.size() / 2);
    for (std::uint32_t point = 0; point < size_.size(); ++point) {
      if (owner(point) != w) continue;
      if (size_[point] <= inline_room) {  // no overflow: no room kept in the new pool either
        begin_[point] = room_[point] = 0;
        continue;
      }
      const auto at = static_cast<std::uint32_t>(fresh.size());
      const std::uint32_t over = size_[point] - inline_room;
      fresh.insert(fresh.end(), pool.begin() + begin_[point], pool.begin() + begin_[point] + over);
      begin_[point] = at;
      room_[point] = over;
    }
    pool.swap(fresh);
    compacted_size_[w] = pool.size();
  }

  // Lists `record` at `point`.
  void append(std::uint32_t point, std::uint32_t record) {
    const std::uint32_t k = size_[point]++;
    if (k < inline_room) {
      inline_[std::size_t(point) * inline_room + k] = record;
      return;
    }
    const std::uint32_t over = k - inline_room;
    std::vector<std::uint32_t>& pool = pools_[owner(point)];
    if (over == room_[point]) {
      const std::uint32_t room = room_[point] ? 2 * room_[point] : 4;
      const auto at = static_cast<std::uint32_t>(pool.size());
      pool.resize(pool.size() + room);
      std::copy_n(pool.begin() + begin_[point], over, pool.begin() + at);
      begin_[point] = at;
      room_[point] = room;
    }
    pool[begin_[point] + over] = record;
  }

  // Drops from the list at `point` the records for which keep(key) is false (point's list only:
  // lists of different points may be compacted in parallel).
  template <class F>
  void compact(std::size_t point, F&& keep) {
    std::uint32_t* in = inline_.data() + point * inline_room;
    std::uint32_t* over = size_[point] > inline_room ? pools_[owner(point)].data() + begin_[point] : nullptr;
    const auto at = [&](std::uint32_t k) -> std::uint32_t& { return k < inline_room ? in[k] : over[k - inline_room]; };
    std::uint32_t kept = 0;
    for (std::uint32_t k = 0; k < size_[point]; ++k)
      if (keep(keys_[at(k)])) {
        const std::uint32_t v = at(k);
        at(kept++) = v;
      }
    size_[point] = kept;
  }

  // Calls f(key) for every record listed at `point`: a superset of the records whose coverage
  // sphere holds it, in no particular order.
  template <class F>
  void query(std::size_t point, F&& f) const {
    const std::uint32_t n = size_[point];
    const std::uint32_t* in = inline_.data() + point * inline_room;
    for (std::uint32_t k = 0; k < std::min(n, inline_room); ++k) f(keys_[in[k]]);
    if (n > inline_room) {
      const std::uint32_t* over = pools_[owner(point)].data() + begin_[point];
      for (std::uint32_t k = 0; k < n - inline_room; ++k) f(keys_[over[k]]);
    }
  }

 private:
  static constexpr std::uint32_t inline_room = 4;  // entries per point kept inline (most lists are short)
  std::vector<key> keys_;
  std::vector<std::uint32_t> inline_;  // per point, its first inline_room entries
  std::vector<std::vector<std::uint32_t>> pools_;
  std::vector<std::size_t> compacted_size_;  // per pool: its size after the last lay_out
  // Per point: its list's length, and where the entries beyond inline_room lie in pools_[owner(point)].
  std::vector<std::uint32_t> begin_, size_, room_;
};

// The cells of a uniform grid over a box: cubes of side >= `cell`, grown by 1.25x until there are
// at most 4 count + 64 of them (at most 1024 per axis). point_grid and incremental_grid share them.
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
    const glm::vec3 ext = count ? glm::max(hi - lo, glm::vec3(0.0f)) : glm::vec3(0.0f);
    // About one cell per point over the box (points on surfaces fill few cells).
    float cell = std::cbrt(std::max(ext.x * ext.y * ext.z, 0.0f) / float(std::max<std::size_t>(count, 1)));
    cell = std::max({cell, 1e-3f * std::max({ext.x, ext.y, ext.z}), 1e-30f});
    cells_.fit(lo, ext, cell, count);
    const std::size_t cells = cells_.size();
    std::vector<std::uint32_t> cell_of(count);
    start_.assign(cells + 1, 0u);
    for (std::size_t i = 0; i < count; ++i) {
      cell_of[i] = static_cast<std::uint32_t>(cells_.index(cells_.cell_of(p[i])));
      ++start_[cell_of[i] + 1];
    }
    for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
    points_.resize(count);
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < count; ++i) points_[fill[cell_of[i]]++] = static_cast<std::uint32_t>(i);
    p_ = p;
  }

  // Calls f(i) for every point i with |p_i - c| <= r.
  template <class F>
  void for_each_in_sphere(const glm::vec3& c, float r, F&& f) const {
    if (points_.empty()) return;
    const glm::ivec3 a = cells_.cell_of(c - glm::vec3(r)), b = cells_.cell_of(c + glm::vec3(r));
    const float r2 = r * r;
    for (int z = a.z; z <= b.z; ++z)
      for (int y = a.y; y <= b.y; ++y) {
        // The cells a.x..b.x of a row are consecutive in CSR order: one run of points.
        const std::size_t row = cells_.index({a.x, y, z});
        const std::uint32_t end = start_[row + std::size_t(b.x - a.x) + 1];
        for (std::uint32_t k = start_[row]; k < end; ++k) {
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

// Items at positions, added one at a time into a uniform grid of cells at least `cell` wide over
// a box (a linked list per cell, items stored in insertion order): is there one near a point? At
// most about 4 count + 64 cells. pick_seeds keeps the round's seeds in one (item: position and
// normal), nearby_records_agree the records (item: the record's index).
template <class Item>
class incremental_grid {
 public:
  void reset(const glm::vec3& lo, const glm::vec3& hi, float cell, std::size_t count) {
    const glm::vec3 ext = glm::max(hi - lo, glm::vec3(0.0f));
    cells_.fit(lo, ext, std::max({cell, 1e-6f * std::max({ext.x, ext.y, ext.z}), 1e-30f}), count);
    head_.assign(cells_.size(), none);
    next_.clear();
    item_.clear();
  }
  void insert(const glm::vec3& x, const Item& item) {
    const std::size_t c = cells_.index(cells_.cell_of(x));
    next_.push_back(head_[c]);
    item_.push_back(item);
    head_[c] = static_cast<std::uint32_t>(next_.size() - 1);
  }
  // Whether pred(item) holds for an item in the cells that the box x +- r touches (a superset of
  // the items within r of x); stops at the first that does. x's own cell first: the item that
  // answers is most often there.
  template <class F>
  bool any_near(const glm::vec3& x, float r, F&& pred) const {
    const std::size_t own = cells_.index(cells_.cell_of(x));
    for (std::uint32_t k = head_[own]; k != none; k = next_[k])
      if (pred(item_[k])) return true;
    const glm::ivec3 a = cells_.cell_of(x - glm::vec3(r)), b = cells_.cell_of(x + glm::vec3(r));
    for (int z = a.z; z <= b.z; ++z)
      for (int y = a.y; y <= b.y; ++y)
        for (int xx = a.x; xx <= b.x; ++xx) {
          const std::size_t c = cells_.index({xx, y, z});
          if (c == own) continue;
          for (std::uint32_t k = head_[c]; k != none; k = next_[k])
            if (pred(item_[k])) return true;
        }
    return false;
  }

 private:
  static constexpr std::uint32_t none = 0xffffffffu;
  grid_cells cells_;
  std::vector<std::uint32_t> head_, next_;
  std::vector<Item> item_;
};

// A seed of pick_seeds: where it is and its normal.
struct seed {
  glm::vec3 position, normal;
};

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
  std::size_t visited = 0;       // records whose box the query visited (covering or not)
};

// Interpolation at one point through the BVH; returns the weight sum (0: not covered).
// `spread` (optional) receives the range (max - min) of the luminance the covering records
// predict for the point, and `own` whether one of them sits at the point itself.
// `sh` (optional) receives the same weighted average of the records' L1 SH (zero if uncovered),
// `cone` the same of the HL2 cones, `detail` (optional) what coverage_detail describes.
float interpolate(const std::vector<cache_record>& records, const record_lists& lists, const record_bvh& large, std::size_t point, const glm::vec3& x,
                  const glm::vec3& n, const cache_options& o, glm::vec3& out, float* spread = nullptr,
                  bool* own = nullptr, std::array<glm::vec3, 4>* sh = nullptr, hl2_cone* cone = nullptr,
                  coverage_detail* detail = nullptr) {
  // 1. The covering records and their weights, then in record order: the sums below do not
  // depend on how the lists and the tree report records (the same order as interpolate_records).
  struct covering {
    std::uint32_t index;
    float w;
  };
  thread_local std::vector<covering> cover;
  cover.clear();
  std::size_t visited = 0;
  const auto consider = [&](const record_key& key) {
    ++visited;
    const float w = weight_of(key, x, n, o);
    if (w > 0.0f && !is_behind(key, x, n)) cover.push_back({key.index, w});
  };
  lists.query(point, consider);  // the records of few points, listed at the point
  large.query(x, consider);      // the others (each record is in one of the two)
  std::sort(cover.begin(), cover.end(), [](const covering& p, const covering& q) { return p.index < q.index; });
  // 2. The weighted sums.
  glm::vec3 sum(0.0f);
  std::array<glm::vec3, 4> sh_sum{};
  hl2_cone cone_sum;
  if (cone) cone_sum.reference = make_frame(n).t;
  float wsum = 0.0f, lo = std::numeric_limits<float>::infinity(), hi = -lo;
  bool at_record = false;
  const int order = prediction_order(o);
  for (const covering& c : cover) {
    const std::uint32_t i = c.index;
    const float w = c.w;
    const cache_record& r = records[i];
    const glm::vec3 e = extrapolate(r, x, n, order, o.error_threshold);
    sum += w * e;
    wsum += w;
    if (sh)
      for (std::size_t k = 0; k < 4; ++k) sh_sum[k] += w * r.sh_l1[k];
    if (cone) {
      const hl2_cone rc = rotate_hl2_cone(r.cone, r.normal, cone_sum.reference);
      for (std::size_t k = 0; k < std::size_t(hl2_cone_terms); ++k) cone_sum.coefficients[k] += w * rc.coefficients[k];
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
      detail->first_order = std::max(detail->first_order, std::fabs(l - li) / std::max({li, detail->floor, 1e-30f}));
    }
    at_record = at_record || r.position == x;
  }
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

// Median distance from a point to its nearest other point (at a distance > 0), over up to 1024
// evenly strided points, found in the point grid within spheres of radius diagonal / sqrt(count)
// (about the spacing of points on surfaces), doubled up to four times that; a point with no
// neighbour that near is left out.
float median_spacing(const glm::vec3* p, std::size_t count, float diagonal, const point_grid& grid) {
  if (count < 2 || !(diagonal > 0.0f)) return 0.0f;
  const float reach = diagonal / std::sqrt(float(count));
  std::vector<float> nn;
  const std::size_t stride = std::max<std::size_t>(1, count / 1024);
  for (std::size_t i = 0; i < count; i += stride) {
    float best = std::numeric_limits<float>::infinity();
    for (float r = reach; r <= 4.0f * reach && !(best <= r); r *= 2.0f)
      grid.for_each_in_sphere(p[i], r, [&](std::uint32_t j) {
        const float d = glm::length(p[j] - p[i]);
        if (d > 0.0f) best = std::min(best, d);
      });
    if (best <= 4.0f * reach) nn.push_back(best);
  }
  if (nn.empty()) return 0.0f;
  std::nth_element(nn.begin(), nn.begin() + std::ptrdiff_t(nn.size() / 2), nn.end());
  return nn[nn.size() / 2];
}

}  // namespace

void validate_cache_options(const cache_options& o, const std::string& who) {
  const std::string fn = who + ": ";
  if (!(o.error_threshold >= min_error_threshold && o.error_threshold <= 1.0f))
    throw_invalid_argument(fn + "error_threshold is " + std::to_string(o.error_threshold) +
                           "; it must be in [0.001, 1] (below 0.001 every point would be a record: use a hemicube per point)");
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

namespace {

void validate(const glm::vec3* positions, const glm::vec3* normals, std::size_t count, const cache_options& o) {
  const std::string fn = "cache_irradiance: ";
  if (count == 0) throw_invalid_argument(fn + "count is 0: there are no points");
  if (!positions) throw_invalid_argument(fn + "positions is NULL");
  if (!normals) throw_invalid_argument(fn + "normals is NULL");
  glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (std::size_t i = 0; i < count; ++i) {
    const glm::vec3 &p = positions[i], &n = normals[i];
    if (!(std::fabs(p.x) <= max_coordinate && std::fabs(p.y) <= max_coordinate && std::fabs(p.z) <= max_coordinate))
      throw_invalid_argument(fn + "positions[" + std::to_string(i) + "] = " + vec_str(p) + " is not finite or beyond 1e18");
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
    const float len = glm::length(n);
    if (!(std::fabs(len - 1.0f) <= 1e-3f))
      throw_invalid_argument(fn + "normals[" + std::to_string(i) + "] = " + vec_str(n) + " has length " +
                             std::to_string(len) + "; it must be a unit vector");
  }
  // Distances between points are squared in float (weights, grids): the extent must keep them finite.
  const double diagonal = glm::length(hi - lo);
  if (diagonal > max_point_extent)
    throw_invalid_argument(fn + "the points span " + std::to_string(diagonal) + " units (bounding-box diagonal); at most " +
                           std::to_string(max_point_extent) + " is supported (squared distances must fit in float)");
  validate_cache_options(o, "cache_irradiance");
}

// 64-bit mix (splitmix64 finaliser): a fixed pseudo-random order of the points.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// The points 0..count-1 sorted by mix(i) (a bijection, so no two keys are equal): the fixed
// pseudo-random order of placement. A least-significant-digit radix sort, four passes of 16 bits.
std::vector<std::uint32_t> pseudo_random_order(std::size_t count) {
  std::vector<std::uint64_t> key(count), key_tmp(count);
  std::vector<std::uint32_t> idx(count), idx_tmp(count);
  for (std::size_t i = 0; i < count; ++i) {
    key[i] = mix(i);
    idx[i] = static_cast<std::uint32_t>(i);
  }
  std::vector<std::uint32_t> start(1u << 16);
  for (int shift = 0; shift < 64; shift += 16) {
    std::fill(start.begin(), start.end(), 0u);
    for (std::uint64_t k : key) ++start[(k >> shift) & 0xffffu];
    std::uint32_t sum = 0;
    for (std::uint32_t& c : start) {
      const std::uint32_t n = c;
      c = sum;
      sum += n;
    }
    for (std::size_t i = 0; i < count; ++i) {
      const std::uint32_t at = start[(key[i] >> shift) & 0xffffu]++;
      key_tmp[at] = key[i];
      idx_tmp[at] = idx[i];
    }
    key.swap(key_tmp);
    idx.swap(idx_tmp);
  }
  return idx;
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
  if (!(o.error_threshold >= min_error_threshold && o.error_threshold <= 1.0f))
    throw_invalid_argument("fit_record_hessians: options.error_threshold is " + std::to_string(o.error_threshold) +
                           "; it must be in [0.001, 1]");
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
//   derive_radii -> set_up -> [ coverage_pass -> pick_seeds -> render_seeds -> append_records
//                     -> limit_radii -> mark_dirty ]* -> fit_hessians -> interpolate_all
//                     -> fill_invalid
// Per point the state is: covered (a record's weight passes 1/a and the opinions agree), own
// invalid sample (inside geometry: its own hemicube saw back faces), presumed inside (within the
// exclusion ball of an invalid sample on the same side of the same surface; final, as own invalid
// is). A point is open when it is none of covered, own invalid or presumed; an open point is a
// seed candidate when its rank in the fixed pseudo-random order is below the round's
// candidate_count.
// Where the time goes and why each structure is there: docs/cache.md, "Placement".
// The structures, each kept up to date as records are added:
//   lists_      per point, the records of few points whose sphere held it, and
//   large_tree_ the other records in a tree (both: coverage and final interpolation)
//   bvh_        the records' boxes, rebuilt each round (limit_radii's neighbours)
//   record_cells_  the records' positions (nearby_records_agree)
//   models_     per record, its first-order model, compact (limit_radii, nearby_records_agree)
class placement {
 public:
  placement(const glm::vec3* positions, const glm::vec3* normals, std::size_t count, const irradiance_sampler& sampler,
            const cache_options& options)
      : p_(positions), n_(normals), count_(count), sampler_(sampler), o_(options) {}

  cache_result run() {
    const auto start = std::chrono::steady_clock::now();
    threads_ = resolve_thread_count(o_.thread_count);
    grid_of_points_.build(p_, count_);
    derive_radii();
    set_up();
    for (;;) {
      cache_round_stats round;
      round.spacing = spacing_;
      candidates_ = candidate_count();
      timed(round.coverage_seconds, [&] { coverage_pass(round); });
      const std::size_t open = open_candidates();
      round.open_points = open;
      report(1.0f - float(open_list_.size()) / float(count_));
      if (open == 0) {
        stats_.round_details.push_back(round);
        if (candidates_ == count_) break;
        spacing_ = std::max(finest_, 0.5f * spacing_);  // nothing to place among this round's candidates
        continue;
      }
      std::vector<std::size_t> seeds;
      timed(round.seed_seconds, [&] { seeds = pick_seeds(); });
      std::vector<cache_sample> samples;
      timed(round.render_seconds, [&] { samples = render_seeds(seeds, open); });
      round.seeds = seeds.size();
      timed(round.update_seconds, [&] {
        const std::size_t first_new = append_records(seeds, samples, round);
        limit_radii(first_new);
        mark_dirty(first_new);
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
      const float spacing = median_spacing(p_, count_, diagonal_, grid_of_points_);
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
    lists_.reset(count_, threads_);
    large_records_.clear();
    listed_points_.clear();
    listed_entries_ = 0;
    list_budget_ = list_entries_per_point * count_;
    large_tree_.build(records_, o_, 1, &large_records_);
    record_cells_.reset(lo_, hi_, std::max(nearby_reach_, finest_), count_);
    for (auto* v : {&covered_, &own_invalid_, &presumed_}) v->assign(count_, 0);
    // Points the caller knows to be inside geometry (cache_options::known_inside) are invalid
    // from the start, as if their own sample had been: no hemicube, no coverage test.
    if (o_.known_inside)
      for (std::size_t i = 0; i < count_; ++i) own_invalid_[i] = o_.known_inside[i] ? 1 : 0;
    dirty_.assign(count_, 1);  // the first coverage pass tests every point
    dirty_list_.resize(count_);
    std::iota(dirty_list_.begin(), dirty_list_.end(), std::uint32_t(0));
    in_open_list_.assign(count_, 0);
    open_list_.clear();
    order_ = pseudo_random_order(count_);
    rank_.resize(count_);
    for (std::size_t k = 0; k < count_; ++k) rank_[order_[k]] = static_cast<std::uint32_t>(k);
    // The coverage tests weigh records with Ward's own weight under ward_continuous too, so that
    // both place the same records (only the final interpolation differs; cache.hpp).
    coverage_options_ = o_;
    if (coverage_options_.weight == cache_weight::ward_continuous) coverage_options_.weight = cache_weight::ward;
    coverage_options_.progress = nullptr;
    coverage_options_.second_order = false;  // the Hessians are fitted after placement
  }

  bool inside(std::size_t i) const { return own_invalid_[i] || presumed_[i]; }
  bool open(std::size_t i) const { return !covered_[i] && !inside(i); }
  float radius_of(std::size_t j) const { return lists_[j].radius; }  // compact: the record's radius

  // The seed candidates of the round: the points of rank below this count. At spacing s only
  // about candidates_per_spacing^2 points per s x s area of surface take part (the first ones in
  // the fixed pseudo-random order: a uniform sample); the coverage of the others is checked when a
  // finer spacing makes them candidates, so a point is not checked again and again while records
  // are coarse. At the finest spacing, and from spacing candidates_per_spacing x finest on, every
  // point.
  std::size_t candidate_count() const {
    if (!(spacing_ > finest_)) return count_;
    const double share = double(candidates_per_spacing) * double(finest_) / double(spacing_);
    return share >= 1.0 ? count_ : std::max<std::size_t>(1, std::size_t(double(count_) * share * share));
  }
  // How many open points are candidates (open_list_ is in rank order: a prefix).
  std::size_t open_candidates() const {
    return std::size_t(std::lower_bound(open_list_.begin(), open_list_.end(), candidates_,
                                        [&](std::uint32_t i, std::size_t k) { return rank_[i] < k; }) - open_list_.begin());
  }

  // 1. Coverage of every candidate point whose answer can have changed (parallel, read-only on
  // the records): the dirty points (all of them at first; then those in the reach of a record
  // added or shrunk since they were last checked, within nearby_opinion's reach of a new record,
  // or newly presumed inside). Every other point, open or covered, sees the same records with the
  // same radii as when it was last checked, and its opinions come from the same records, so its
  // answer stands. Dirty points that are not yet candidates stay dirty until they are (at the
  // finest spacing every point is). The dark floor of the tests
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
    in_index_order(dirty_list_, dirty_);  // neighbouring points (lightmap order) one after another
    parallel_for(dirty_list_.size(), threads_, 1024, [&](int worker, std::size_t b, std::size_t e) {
      tally& t = tallies[std::size_t(worker)];
      for (std::size_t k = b; k < e; ++k) {
        const std::size_t i = dirty_list_[k];
        if (inside(i) || rank_[i] >= candidates_) continue;
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
    update_open_list();
  }

  // The open points in the fixed order (open_list_): a point's answer changes only in a coverage
  // pass that checks it, or when it becomes inside (then it is dropped here), so the checked
  // points that are open join the list and the list drops what is no longer open.
  void update_open_list() {
    std::size_t deferred = 0;
    for (std::uint32_t i : dirty_list_) {
      if (rank_[i] >= candidates_) {  // not checked: stays dirty
        dirty_list_[deferred++] = i;
        continue;
      }
      dirty_[i] = 0;
      if (open(i) && !in_open_list_[i]) {
        in_open_list_[i] = 1;
        open_list_.push_back(i);
      }
    }
    dirty_list_.resize(deferred);
    std::size_t kept = 0;
    for (std::uint32_t i : open_list_) {
      if (open(i))
        open_list_[kept++] = i;
      else
        in_open_list_[i] = 0;
    }
    open_list_.resize(kept);
    if (open_list_.size() > count_ / 16) {  // a long list: the order itself, filtered
      open_list_.clear();
      for (std::uint32_t i : order_)
        if (in_open_list_[i]) open_list_.push_back(i);
    } else {  // a short one: sorted by rank
      for (std::uint32_t& i : open_list_) i = rank_[i];
      std::sort(open_list_.begin(), open_list_.end());
      for (std::uint32_t& k : open_list_) k = order_[k];
    }
  }

  // Sorts `list`, the indices of the points whose flag is set, ascending: a long list by a scan of
  // the flags, a short one by sorting.
  void in_index_order(std::vector<std::uint32_t>& list, const std::vector<std::uint8_t>& flag) const {
    if (list.size() > count_ / 16) {
      list.clear();
      for (std::size_t i = 0; i < count_; ++i)
        if (flag[i]) list.push_back(static_cast<std::uint32_t>(i));
    } else {
      std::sort(list.begin(), list.end());
    }
  }

  // The coverage test of one point (coverage_pass); `visited` counts the records the query saw.
  void check_point(std::size_t i, std::size_t& visited) {
    const float a = o_.error_threshold;
    glm::vec3 value;
    float spread = 0.0f;
    bool own = false;
    coverage_detail detail;
    detail.floor = floor_e_;
    // Records whose sphere shrank past the point never cover it again (radii only shrink): out
    // of its list (the margin is coverage_weight's).
    lists_.compact(i, [&](const record_lists::key& key) {
      const glm::vec3 dx = p_[i] - key.position;
      const float reach = o_.error_threshold * key.radius;
      return glm::dot(dx, dx) <= 1.0002f * reach * reach;
    });
    const float w = interpolate(records_, lists_, large_tree_, i, p_[i], n_[i], coverage_options_, value, &spread, &own, nullptr, nullptr, &detail);
    visited = detail.visited;
    bool ok = w > 0.0f;
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
    const float r2 = nearby_reach_ * nearby_reach_;
    return !record_cells_.any_near(x, nearby_reach_, [&](std::uint32_t k) {
      const linear_model& rb = models_[k];
      const glm::vec3 d = rb.position - x;
      if (k == detail.last || glm::dot(d, d) > r2) return false;
      if (glm::dot(rb.normal, nx) <= 0.9f || is_behind(rb, x, nx)) return false;
      const float lb = luminance(glm::max(o_.use_gradients ? rb.predict(x, nx) : rb.irradiance, glm::vec3(0.0f)));
      return std::fabs(lb - la) > tolerance;
    });
  }

  // 2. Seeds: open points in the fixed order, at least `spacing` from this round's earlier seeds
  // of a similar normal; at the finest spacing every open point is a seed. The round's seeds go
  // into a uniform grid of cells at least `spacing` wide, so a candidate looks at the seeds of
  // the cells around it only (cost O(open points), whatever the spacing).
  std::vector<std::size_t> pick_seeds() {
    std::vector<std::size_t> seeds;
    const bool finest = !(spacing_ > finest_);
    if (finest) {
      seeds.assign(open_list_.begin(), open_list_.begin() + std::ptrdiff_t(open_candidates()));
      return seeds;
    }
    seed_cells_.reset(lo_, hi_, spacing_, open_list_.size());
    const float r2 = spacing_ * spacing_;
    // The points are visited in a pseudo-random order: the positions and normals a few steps
    // ahead are prefetched.
    constexpr std::size_t ahead = 16;
    const std::size_t open_count = open_candidates();
    for (std::size_t k = 0; k < open_count; ++k) {
      if (k + ahead < open_count) {
        const std::size_t q = open_list_[k + ahead];
        __builtin_prefetch(&p_[q]);
        __builtin_prefetch(&n_[q]);
      }
      const std::size_t i = open_list_[k];
      const glm::vec3 x = p_[i], nx = n_[i];
      const bool blocked = seed_cells_.any_near(x, spacing_, [&](const seed& c) {
        const glm::vec3 d = x - c.position;
        return glm::dot(d, d) <= r2 && glm::length(d) < spacing_ && glm::dot(nx, c.normal) > 0.9f;
      });
      if (blocked) continue;
      seed_cells_.insert(x, {x, nx});
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
  // exclusion ball, the points on the same side of the same surface (presumed_by). Returns
  // the index of the first new record.
  std::size_t append_records(const std::vector<std::size_t>& seeds, const std::vector<cache_sample>& samples,
                             cache_round_stats& round) {
    const std::size_t first_new = records_.size();
    old_radius_.resize(first_new);
    for (std::size_t j = 0; j < first_new; ++j) old_radius_[j] = radius_of(j);
    // The records, and the points each invalid sample presumes inside, in parallel; then
    // appended in seed order.
    std::vector<cache_record> made(seeds.size());
    std::vector<std::vector<std::uint32_t>> presumed(seeds.size());
    parallel_for(seeds.size(), threads_, 64, [&](int, std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k)
        if (samples[k].backface_fraction > o_.invalid_backface_fraction)
          presumed[k] = presumed_by(seeds[k], samples[k].min_distance);
        else
          made[k] = make_record(seeds[k], samples[k]);
    });
    for (std::size_t k = 0; k < seeds.size(); ++k) {
      const std::size_t i = seeds[k];
      const cache_sample& s = samples[k];
      if (s.backface_fraction > o_.invalid_backface_fraction) {
        ++stats_.invalid_samples;
        ++round.invalid_samples;
        own_invalid_[i] = 1;
        for (std::uint32_t j : presumed[k]) presumed_[j] = 1;  // final: never tested or seeded again
        continue;
      }
      records_.push_back(made[k]);
      models_.push_back(linear_model(records_.back()));
      record_cells_.insert(records_.back().position, static_cast<std::uint32_t>(records_.size() - 1));
      lists_.add(records_.back());
      record_point_.push_back(static_cast<std::uint32_t>(i));
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
    // A record that saw back faces stands at a contact (where parts meet or intersect): its
    // reach stops short of the nearest geometry its hemicube saw, so it never covers points
    // across the contact (the ball of radius min_distance around it holds no geometry).
    if (s.backface_fraction > contact_backface_ && std::isfinite(s.min_distance) && s.min_distance > 0.0f)
      radius = std::min(radius, s.min_distance);
    r.radius = std::clamp(radius, o_.min_radius, o_.max_radius);
    return r;
  }

  // An invalid sample at point i saw nothing nearer than min_distance in its visible half-space:
  // points within 0.9 of that distance, on the visible side of its tangent plane (not below it by
  // more than 1% of the ball) and with a similar normal (n . n_i > 0.9), lie in the same closed
  // region, so they are presumed inside without a hemicube of their own, for good: a surface
  // separating such a point from the sample would cross the ball, where the hemicube saw nothing.
  // Points on other surfaces (a wall meeting the floor, a slab's underside inside another slab)
  // are never presumed: the ball says nothing behind the sample.
  std::vector<std::uint32_t> presumed_by(std::size_t i, float min_distance) const {
    std::vector<std::uint32_t> out;
    if (!std::isfinite(min_distance) || !(min_distance > 0.0f)) return out;
    const float ball = 0.9f * min_distance;
    const glm::vec3 c = p_[i], nc = n_[i];
    grid_of_points_.for_each_in_sphere(c, ball, [&](std::uint32_t j) {
      if (presumed_[j] || glm::dot(n_[j], nc) <= 0.9f || glm::dot(p_[j] - c, nc) < -0.01f * ball) return;
      out.push_back(j);
    });
    return out;
  }

  // 5. Neighbour clamping and shrinking of disagreeing neighbours, sequential in record order
  // over pairs (new record, neighbour) (deterministic); then the records and the lists' keys take
  // the new radii.
  void limit_radii(std::size_t first_new) {
    if (!(records_.size() > first_new && (o_.neighbour_clamp || o_.shrink_disagreeing))) return;
    const float a = o_.error_threshold;
    // The pairs of each new record i: the records j of every leaf of bvh_ (built over all records
    // with the radii before this stage) whose box holds x_i, in record order, with their distance
    // and whether their first-order predictions of each other disagree by more than a (neither
    // depends on the radii, so both are found first, in parallel).
    struct pair {
      std::uint32_t j;
      bool disagree;
      float d;
    };
    const bool shrink = o_.shrink_disagreeing;
    bvh_.build(records_, o_, threads_);
    std::vector<std::vector<pair>> candidates(records_.size() - first_new);
    parallel_for(candidates.size(), threads_, 64, [&](int, std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        const std::size_t i = first_new + k;
        const linear_model& mi = models_[i];
        const float ri = radius_of(i);
        // The neighbours from the tree's keys (sorted after: a record lies in one leaf, so no
        // index twice), with their distance and whether a disagreement could change anything:
        // with neighbour clamping not while R_i + d stays within the gap radius 0.4 d / a (then
        // the clamp R_j <= R_i + d is the stronger limit on R_j, and R_i is already inside the
        // gap); R_i only shrinks in the pass below, so that holds there too (1% margin for float
        // rounding). Only those pairs read the two records' models.
        std::vector<pair>& near = candidates[k];
        bvh_.query(mi.position, [&](const record_bvh::key& key) {
          if (std::size_t(key.index) == i) return;
          const float d = glm::length(mi.position - key.position);
          const bool moot = o_.neighbour_clamp && ri + d <= 0.99f * (0.4f * d / a);
          near.push_back({key.index, shrink && !moot && d > 0.0f && glm::dot(mi.normal, key.normal) > 0.9f, d});
        });
        std::sort(near.begin(), near.end(), [](const pair& x, const pair& y) { return x.j < y.j; });
        for (pair& q : near) {
          if (!q.disagree) continue;  // (holds "to be tested" until here)
          const linear_model& mj = models_[q.j];
          // Each record's first-order prediction of the other's irradiance (luminance).
          const float ei = luminance(mi.irradiance), ej = luminance(mj.irradiance);
          const float pij = luminance(mi.predict(mj.position, mj.normal));
          const float pji = luminance(mj.predict(mi.position, mi.normal));
          const float err = std::max(std::fabs(pij - ej) / std::max(ej, 1e-20f), std::fabs(pji - ei) / std::max(ei, 1e-20f));
          q.disagree = err > a;
        }
      }
    });
    // The sequential pass works on a compact copy of the radii (the lists' keys hold them).
    radius_.resize(records_.size());
    for (std::size_t j = 0; j < records_.size(); ++j) radius_[j] = radius_of(j);
    // At the finest spacing, neighbour clamping does not shrink older records (only the new ones,
    // by each other and by the older ones): the points those cover stay covered, instead of
    // opening again round after round. A disagreement still shrinks both.
    const bool clamp_older = spacing_ > finest_;
    for (std::size_t i = first_new; i < records_.size(); ++i) {
      float& ri = radius_[i];
      for (const pair& q : candidates[i - first_new]) {
        float& rj = radius_[q.j];
        const float d = q.d;
        if (o_.neighbour_clamp) {
          ri = std::max(o_.min_radius, std::min(ri, rj + d));
          if (clamp_older || q.j >= first_new) rj = std::max(o_.min_radius, std::min(rj, ri + d));
        }
        if (q.disagree) {
          // Shrink so that their coverage (a R each) leaves a gap between them: 0.4 d each.
          const float r_gap = std::max(o_.min_radius, 0.4f * d / a);
          ri = std::min(ri, r_gap);
          rj = std::min(rj, r_gap);
        }
      }
    }
    for (std::size_t j = 0; j < records_.size(); ++j)
      if (radius_[j] != radius_of(j)) {
        records_[j].radius = radius_[j];
        lists_.set_radius(j, radius_[j]);
      }
  }

  // 6. Points whose coverage this round's records can have changed (in a new record's sphere, or
  // in the old sphere of a shrunk one, which holds its new one, or within nearby_opinion's reach
  // of a new record) are re-checked in the next coverage pass; the new records join the lists of
  // the points their spheres hold (after the limits: their final radii).
  void mark_dirty(std::size_t first_new) {
    const float a = o_.error_threshold;
    // (1e-4 wider: the weights measure distance with glm::length, the grid with a squared one.)
    const auto reach_of = [&](std::size_t j) { return a * radius_of(j) * 1.0001f; };
    // a. Each worker marks its own flags and lists what it marked (merged into dirty_list_ after:
    // which points are dirty does not depend on which worker marked what), and counts each new
    // record's points.
    marks_.resize(std::size_t(threads_));
    for (worker_marks& m : marks_) m.flag.resize(count_, 0);
    listed_points_.resize(records_.size(), 0);
    parallel_for(records_.size(), threads_, 256, [&](int worker, std::size_t b, std::size_t e) {
      worker_marks& m = marks_[std::size_t(worker)];
      const auto mark = [&](std::uint32_t i) {
        if (!m.flag[i]) {
          m.flag[i] = 1;
          m.list.push_back(i);
        }
      };
      for (std::size_t j = b; j < e; ++j) {
        const glm::vec3 x = lists_[j].position;
        const float reach = reach_of(j), reach2 = reach * reach;
        if (j >= first_new) {
          const float marked = o_.nearby_opinion > 0.0f ? std::max(reach, nearby_reach_ * 1.0001f) : reach;
          std::uint32_t points = 0;
          grid_of_points_.for_each_in_sphere(x, marked, [&](std::uint32_t i) {
            mark(i);
            const glm::vec3 d = p_[i] - x;
            points += glm::dot(d, d) <= reach2 ? 1u : 0u;
          });
          listed_points_[j] = points;
        } else if (radius_of(j) != old_radius_[j]) {
          grid_of_points_.for_each_in_sphere(x, a * old_radius_[j] * 1.0001f, mark);  // the old sphere holds the new one
        }
      }
    });
    for (worker_marks& m : marks_) {
      for (std::uint32_t i : m.list) {
        m.flag[i] = 0;
        if (!dirty_[i]) {
          dirty_[i] = 1;
          dirty_list_.push_back(i);
        }
      }
      m.list.clear();
    }
    // b. Which new records are listed, in record order (deterministic): those of at most
    // max_listed_points points while the lists' entries stay within the budget; the others are
    // large and kept in a tree of their own (with the radii as they are now).
    std::vector<std::uint32_t> listed;
    for (std::size_t j = first_new; j < records_.size(); ++j) {
      const bool is_listed = listed_points_[j] <= max_listed_points && listed_entries_ + listed_points_[j] <= list_budget_;
      if (is_listed) {
        listed_entries_ += listed_points_[j];
        listed.push_back(static_cast<std::uint32_t>(j));
      } else {
        large_records_.push_back(static_cast<std::uint32_t>(j));
      }
    }
    large_tree_.build(records_, o_, threads_, &large_records_);
    // c. The listed records join the lists of their points: their (record, point) pairs found in
    // parallel, then appended by the owner of each point (owners in parallel); in batches of at
    // most about one pair per point, so the pairs in flight take no more memory than that.
    for (std::size_t first = 0; first < listed.size();) {
      std::size_t last = first, pairs = 0;
      while (last < listed.size() && (last == first || pairs + listed_points_[listed[last]] <= count_)) pairs += listed_points_[listed[last++]];
      parallel_for(last - first, threads_, 64, [&](int worker, std::size_t b, std::size_t e) {
        worker_marks& m = marks_[std::size_t(worker)];
        for (std::size_t k = first + b; k < first + e; ++k) {
          const std::uint32_t j = listed[k];
          grid_of_points_.for_each_in_sphere(lists_[j].position, reach_of(j), [&](std::uint32_t i) { m.found.push_back({j, i}); });
        }
      });
      parallel_for(lists_.owners(), threads_, 1, [&](int, std::size_t b, std::size_t e) {
        for (std::size_t owner = b; owner < e; ++owner)
          for (const worker_marks& m : marks_)
            for (const auto& jp : m.found)
              if (lists_.owner(jp.second) == owner) lists_.append(jp.second, jp.first);
      });
      for (worker_marks& m : marks_) m.found.clear();
      first = last;
    }
    parallel_for(lists_.owners(), threads_, 1, [&](int, std::size_t b, std::size_t e) {
      for (std::size_t owner = b; owner < e; ++owner) lists_.lay_out(owner);
    });
    for (worker_marks& m : marks_) m.found.shrink_to_fit();  // (emptied by the last batch)
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
        if (!inside(i) && interpolate(records_, lists_, large_tree_, i, p_[i], n_[i], o_, v, nullptr, nullptr, o_.directional ? &sh : nullptr,
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
  float contact_backface_ = 0.0f;  // records seeing more back faces than this stand at a contact (make_record)
  float floor_e_ = 0.0f;   // the tests' dark floor (coverage_pass), fixed once set
  bool floor_set_ = false;
  std::vector<cache_record> records_;
  record_lists lists_;     // the records of up to max_listed_points points, per point
  record_bvh large_tree_;  // the others (large_records_), rebuilt each round
  std::vector<std::uint32_t> large_records_;
  std::vector<std::uint32_t> listed_points_;  // per new record: the points in its sphere (mark_dirty)
  std::size_t listed_entries_ = 0, list_budget_ = 0;  // list entries written so far, and the most allowed
  record_bvh bvh_;  // limit_radii: the records' boxes
  std::vector<float> radius_;  // limit_radii: the radii during its sequential pass
  std::vector<linear_model> models_;  // per record: its first-order model, compact (limit_radii, nearby_records_agree)
  incremental_grid<std::uint32_t> record_cells_;  // the records' positions (nearby_records_agree)
  std::vector<std::uint32_t> record_point_;  // per record: the point it was placed at
  point_grid grid_of_points_;
  std::vector<std::uint8_t> covered_, dirty_, own_invalid_, presumed_;
  incremental_grid<seed> seed_cells_;  // pick_seeds: the round's seeds so far
  glm::vec3 lo_{0.0f}, hi_{0.0f};  // the points' bounding box
  std::size_t candidates_ = 0;                 // the round's candidates: points of rank below it
  std::vector<std::uint32_t> rank_;            // per point: its place in the fixed pseudo-random order
  std::vector<std::uint32_t> order_;           // the points in that order (order_[rank_[i]] = i)
  std::vector<std::uint32_t> dirty_list_;      // the points with dirty_ set: the next coverage pass's
  std::vector<std::uint32_t> open_list_;       // the open points, by rank_ (update_open_list)
  std::vector<std::uint8_t> in_open_list_;
  std::vector<float> old_radius_;
  struct worker_marks {
    std::vector<std::uint8_t> flag;
    std::vector<std::uint32_t> list;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> found;  // (new record, point in its sphere)
  };
  std::vector<worker_marks> marks_;  // mark_dirty: each worker's marks
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
  // One context per worker, made by the worker on its first call: a worker that never runs (a
  // cache of a few points on many threads) costs nothing. The options are checked now, once.
  { hemicube_rasterizer check(s, o.raster); }
  if (!is_valid_hemicube_resolution(o.resolution))
    throw_invalid_argument("make_hemicube_sampler: resolution " + std::to_string(o.resolution) +
                           " is invalid: it must be even and in [2, 4096]");
  if (!(o.integrate.min_wall_distance >= 0.0f) || !std::isfinite(o.integrate.min_wall_distance))  // as hemicube_integrator
    throw_invalid_argument("make_hemicube_sampler: integrate.min_wall_distance is " + std::to_string(o.integrate.min_wall_distance) +
                           "; it must be finite and >= 0 (0 = automatic)");
  auto contexts = std::make_shared<std::vector<std::unique_ptr<context>>>(static_cast<std::size_t>(workers));
  return [contexts, s, o, table, cone_table](int worker, const glm::vec3& x, const glm::vec3& n) -> cache_sample {
    if (worker < 0 || std::size_t(worker) >= contexts->size())
      throw_invalid_argument("hemicube sampler: worker " + std::to_string(worker) + " is out of range");
    std::unique_ptr<context>& slot = (*contexts)[std::size_t(worker)];
    if (!slot)
      slot = std::make_unique<context>(context{hemicube_rasterizer(s, o.raster), hemicube_integrator(o.resolution, o.integrate), {}});
    context& c = *slot;
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
