// The level-of-detail proxies of a scene's BVH nodes (lod.hpp), built bottom-up with
// meshoptimizer's simplifier.
#include "lod.hpp"

#include "../scene/scene_access.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <memory>
#include <mutex>
#include <unordered_map>

namespace hemilight::raster_detail {

namespace {

// A proxy input triangle: its scene vertices and its material's stand-in (a scene triangle).
struct proxy_triangle {
  std::array<std::uint32_t, 3> v;
  std::uint32_t material;
};

// meshoptimizer's error bound, relative to the simplified group's extent: loose on purpose, so
// that the simplifier reaches about half the triangles (a proxy is only drawn where its node spans
// under a texel or so; docs/raster.md measures what it changes).
constexpr float simplify_error = 0.02f;

// The triangles of one shade simplified to about half (kept as they are when there are only a
// few, or when the simplifier cannot remove any).
void simplify_group(const std::vector<proxy_triangle>& in, const std::vector<glm::vec3>& positions,
                    std::vector<proxy_triangle>& out) {
  if (in.size() <= 2) {
    out.insert(out.end(), in.begin(), in.end());
    return;
  }
  // Local vertices (the simplifier works on a compact vertex array), in order of first use.
  std::unordered_map<std::uint32_t, std::uint32_t> local;
  std::vector<float> xyz;
  std::vector<std::uint32_t> global, indices;
  indices.reserve(3 * in.size());
  for (const proxy_triangle& t : in)
    for (std::uint32_t g : t.v) {
      const auto [it, added] = local.emplace(g, static_cast<std::uint32_t>(global.size()));
      if (added) {
        global.push_back(g);
        xyz.insert(xyz.end(), {positions[g].x, positions[g].y, positions[g].z});
      }
      indices.push_back(it->second);
    }
  const std::size_t target = std::max<std::size_t>(3, (indices.size() / 6) * 3);
  std::vector<std::uint32_t> kept(indices.size());
  float error = 0.0f;
  const std::size_t n = meshopt_simplify(kept.data(), indices.data(), indices.size(), xyz.data(), global.size(),
                                         3 * sizeof(float), target, simplify_error, 0, &error);
  const std::uint32_t material = in.front().material;
  for (std::size_t i = 0; i + 2 < n; i += 3)
    out.push_back({{global[kept[i]], global[kept[i + 1]], global[kept[i + 2]]}, material});
}

// Node i's proxy from its input (the node's triangles or its children's proxies), shade by shade.
void make_proxy(const scene& s, std::vector<proxy_triangle> input, std::vector<proxy_triangle>& proxy) {
  const auto shade = [&](const proxy_triangle& t) {
    return std::uint64_t(s.emission_index(t.material)) << 1 | (s.triangle_material(t.material).two_sided ? 1u : 0u);
  };
  std::stable_sort(input.begin(), input.end(), [&](const proxy_triangle& a, const proxy_triangle& b) { return shade(a) < shade(b); });
  std::vector<proxy_triangle> group;
  for (std::size_t i = 0; i < input.size();) {
    std::size_t j = i;
    while (j < input.size() && shade(input[j]) == shade(input[i])) ++j;
    group.assign(input.begin() + static_cast<std::ptrdiff_t>(i), input.begin() + static_cast<std::ptrdiff_t>(j));
    simplify_group(group, s.positions(), proxy);
    i = j;
  }
}

std::shared_ptr<lod_proxies> build(const scene& s) {
  auto out = std::make_shared<lod_proxies>();
  const std::vector<bvh_node>& nodes = s.bvh();
  const std::vector<std::uint32_t>& indices = s.indices();
  const std::vector<glm::vec3>& positions = s.positions();
  out->first.assign(nodes.size(), 0u);
  out->count.assign(nodes.size(), 0u);
  // Bottom-up (children follow their parent in the array); a child's proxy input is dropped once
  // its parent has used it, and every proxy is stored as it is made.
  std::vector<std::vector<proxy_triangle>> proxies(nodes.size());
  std::vector<proxy_triangle> input;
  for (std::size_t i = nodes.size(); i-- > 0;) {
    input.clear();
    if (nodes[i].count) {
      for (std::uint32_t k = 0; k < nodes[i].count; ++k) {
        const std::uint32_t t = s.triangles()[nodes[i].first + k].index;
        input.push_back({{indices[3 * std::size_t(t)], indices[3 * std::size_t(t) + 1], indices[3 * std::size_t(t) + 2]}, t});
      }
    } else {
      for (std::uint32_t c : {nodes[i].first, nodes[i].first + 1}) {
        input.insert(input.end(), proxies[c].begin(), proxies[c].end());
        std::vector<proxy_triangle>().swap(proxies[c]);
      }
    }
    make_proxy(s, input, proxies[i]);
    out->first[i] = static_cast<std::uint32_t>(out->triangles.size());
    out->count[i] = static_cast<std::uint32_t>(proxies[i].size());
    for (const proxy_triangle& t : proxies[i]) {
      out->triangles.push_back({positions[t.v[0]], positions[t.v[1]], positions[t.v[2]], t.material});
      out->vertices.push_back(t.v);
    }
  }
  return out;
}

}  // namespace

const lod_proxies& lod_proxies_of(const scene& s) {
  detail::lazy_slot* slot = detail::derived_access::of(s, detail::derived_kind::raster_lod);
  if (!slot->done.load(std::memory_order_acquire))
    std::call_once(slot->once, [&] {
      slot->value = build(s);
      slot->done.store(true, std::memory_order_release);
    });
  return *static_cast<const lod_proxies*>(slot->value.get());
}

}  // namespace hemilight::raster_detail
