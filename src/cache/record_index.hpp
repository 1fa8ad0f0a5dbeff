// The cache's search structures over records and points (internal, not installed): which
// records can cover a point (record_lists, record_bvh), which points lie in a sphere
// (point_grid), is there an item near a point (incremental_grid). Queries are inline (the
// placement's hot loops); the builds are in record_index.cpp.
#pragma once

#include "hemilight/cache.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace hemilight::cache_detail {

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
             const std::vector<std::uint32_t>* subset = nullptr);

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
  std::uint32_t split(node& nd, std::uint32_t begin, std::uint32_t end);
  // Builds the subtree of items_[begin, end) with its root at out[slot]; children are allocated
  // in pairs (left, right = left + 1). Depth stays below 64 because every split halves the range.
  void build_into(std::vector<node>& out, std::uint32_t slot, std::uint32_t begin, std::uint32_t end);

  void fill_keys(const std::vector<cache_record>& records);

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
  void reset(std::size_t points, int owners);

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
  void lay_out(std::size_t w);

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

  void fit(const glm::vec3& box_lo, const glm::vec3& ext, float cell, std::size_t count);
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
  void build(const glm::vec3* p, std::size_t count);

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

}  // namespace hemilight::cache_detail
