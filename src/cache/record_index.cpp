// The builds of the cache's search structures (record_index.hpp).
#include "record_index.hpp"

#include "weights.hpp"

#include "hemilight/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hemilight::cache_detail {

void record_bvh::build(const std::vector<cache_record>& records, const cache_options& o, int threads,
                       const std::vector<std::uint32_t>* subset) {
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

std::uint32_t record_bvh::split(node& nd, std::uint32_t begin, std::uint32_t end) {
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

void record_bvh::build_into(std::vector<node>& out, std::uint32_t slot, std::uint32_t begin, std::uint32_t end) {
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

void record_bvh::fill_keys(const std::vector<cache_record>& records) {
  keys_.resize(items_.size());
  for (std::size_t k = 0; k < items_.size(); ++k) {
    const cache_record& r = records[items_[k].index];
    keys_[k] = {r.position, r.radius, r.normal, items_[k].index};
  }
}

void record_lists::reset(std::size_t points, int owners) {
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

void record_lists::lay_out(std::size_t w) {
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

void grid_cells::fit(const glm::vec3& box_lo, const glm::vec3& ext, float cell, std::size_t count) {
  lo = box_lo;
  for (;;) {
    dims = glm::ivec3(glm::min(glm::floor(ext / cell), glm::vec3(1023.0f))) + 1;
    if (double(dims.x) * dims.y * dims.z <= 4.0 * double(count) + 64.0) break;
    cell *= 1.25f;
  }
  inv_cell = 1.0f / cell;
}

void point_grid::build(const glm::vec3* p, std::size_t count) {
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

}  // namespace hemilight::cache_detail
