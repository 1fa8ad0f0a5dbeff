// The process-wide cache of per-resolution tables (internal, not installed): one LRU keyed by
// (kind, N) with a byte budget, shared by every module that keeps tables between calls
// (hemicube_table, integration_table, the probes' SH9 texel weights, the cube-map face tables,
// the cache's HL2 cone weights). The public controls are in hemilight/memory.hpp.
//
// Rules:
// - Tables are handed out as shared_ptr: a table in use is never freed under its holder. The
//   cache keeps a strong reference to the tables it retains and a weak one to every table it
//   built, so a table still held by a caller is found and shared (never built twice) even after
//   the cache let go of it.
// - The retained tables' bytes never exceed the budget: after each insertion the least recently
//   used tables are dropped (the newest last; a table larger than the whole budget is handed out
//   but not retained).
// - Tables of one key are built once: concurrent callers of the same key wait for the first
//   builder (tables of other keys are built in parallel).
#pragma once

#include <cstddef>
#include <functional>
#include <memory>

namespace hemilight::detail {

/// What a cached table is (one LRU over all kinds).
enum class table_kind : int {
  hemicube_weights = 0,  ///< hemicube_table (geometry.hpp)
  integration = 1,       ///< integration_table (integrate.hpp)
  sh9_texel = 2,         ///< the probes' SH9 texel weights (probes.cpp)
  cube_face = 3,         ///< cube-map face table (cubemap_internal.hpp)
  cone_weights = 4,      ///< the cache's HL2 cone weights (src/directional/hl2_cone.cpp)
};

/// Untyped core of cached_table: the shared table of (kind, n), built by `build` if no live one
/// exists. `build` returns the table and its heap bytes. Exceptions from `build` propagate
/// (nothing is cached then). Thread-safe.
std::shared_ptr<const void> cached_table_untyped(
    table_kind kind, int n, const std::function<std::shared_ptr<const void>(std::size_t& bytes)>& build);

/// The shared table of (kind, n): `build()` returns std::shared_ptr<const T> (or <T>), `bytes(t)`
/// its memory in bytes (used for the budget). See the rules above.
template <class T, class Build, class Bytes>
std::shared_ptr<const T> cached_table(table_kind kind, int n, Build build, Bytes bytes) {
  std::shared_ptr<const void> p = cached_table_untyped(kind, n, [&](std::size_t& size) -> std::shared_ptr<const void> {
    std::shared_ptr<const T> t = build();
    size = bytes(*t);
    return t;
  });
  return std::static_pointer_cast<const T>(p);
}

/// Bytes of a vector's storage (capacity), for the `bytes` callbacks.
template <class V>
std::size_t vector_bytes(const V& v) noexcept {
  return v.capacity() * sizeof(typename V::value_type);
}

}  // namespace hemilight::detail
