// Internal to hemilight (not installed): the scene's per-coordinate vertex arrays, which only the
// SIMD paths read (the rasterizer's eight-lane set-up, the ray queries' fallback traversal), and
// the slot that the modules above the scene fill with what they derive from it on first use. The
// tests include this header to check the arrays against scene::triangles().
#pragma once

#include "hemilight/scene.hpp"

#include <atomic>
#include <cstddef>
#include <memory>
#include <mutex>

namespace hemilight {
namespace detail {

/// Data derived from an immutable scene on first use by a module above it (the ray queries' Embree
/// scene): scene::create makes an empty slot, the module fills `value` once under `once` and
/// publishes it with `done` (release), so later readers take the fast path (acquire). The scene
/// knows nothing of what the slot holds.
struct lazy_slot {
  std::once_flag once;
  std::atomic<bool> done{false};
  std::shared_ptr<void> value;
};

/// The scene's lazy slots, one per kind of data a module derives from it: the ray queries' Embree
/// scene (rays.cpp), the rasterizer's level-of-detail proxies (src/raster/lod.cpp), the edges
/// exact edge coverage may find hard (src/raster/edge_coverage.cpp) and the rasterizer's
/// per-triangle keys and draw order (src/raster/rasterizer.cpp). Null only for a scene not made
/// by scene::create.
enum class derived_kind : int { rays = 0, raster_lod = 1, raster_edges = 2, raster_keys = 3 };
struct derived_access {
  static lazy_slot* of(const scene& s, derived_kind kind) noexcept { return s.derived_[static_cast<int>(kind)].get(); }
};

struct scene_access {
  /// The vertex coordinates of s.triangles() again, one array per coordinate:
  /// vertex_coordinates(s, v, a)[t] is coordinate a (0 = x, 1 = y, 2 = z) of vertex v (0, 1, 2) of
  /// s.triangles()[t], bit for bit. Each array has 8 entries of zero padding after the last
  /// triangle, so SIMD code loads eight consecutive triangles without gathers.
  /// Precondition: v, a in [0, 2]. Cost: O(1).
  static const float* vertex_coordinates(const scene& s, int v, int a) noexcept {
    return s.coordinates_.data() + static_cast<std::size_t>(3 * v + a) * (s.triangles_.size() + 8);
  }
};

}  // namespace detail
}  // namespace hemilight
