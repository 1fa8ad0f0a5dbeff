// hemilight/memory.hpp — what the library keeps between calls, and how to bound and free it.
//
// Tables that depend only on a resolution (the hemicube's texel weights, the integrator's
// weights, the probes' SH9 texel weights, the HL2 cone weights of the irradiance cache, the
// cube-map face tables) are built on first use and shared by every caller. They are kept in one
// process-wide least-recently-used cache with a byte budget: the tables it retains never exceed
// the budget; a table in use (held by a rasterizer, integrator, cache or filter call) is never
// freed under its holder, and is shared rather than rebuilt while held. A table the cache let go
// of is rebuilt on the next use, bitwise the same.
//
// Per-resolution sizes (T = 3 N^2, the texels of a hemicube of resolution N; S = a cube face's
// size): hemicube_table 8 T bytes; integration_table 69 T + 144 N bytes; SH9 texel weights 36 T;
// HL2 cone weights 28 T; cube-map face table 16 S^2. N = 256: 1.5 + 13 + 6.8 + 5.3 MiB;
// N = 512: 6 + 52 + 27 + 21 MiB. docs/reliability.md ("Memory") has every entry's peak.
//
// The C ABI's equivalents: hemilight_set_table_budget, hemilight_release_tables (which also free
// the per-thread context of hemilight_sample_irradiance).
#pragma once

#include <cstddef>

namespace hemilight {

/// The default budget of the table cache: 256 MiB. It retains every table of two resolutions up
/// to N = 512 at once (about 106 MiB per resolution), so common use never rebuilds a table, while
/// a process that used many resolutions keeps at most this much.
inline constexpr std::size_t default_table_budget = std::size_t(256) << 20;

/// Sets the table cache's byte budget (0: retain nothing; tables then live only while held) and
/// drops least-recently-used tables until the retained ones fit. Tables in use stay alive with
/// their holders. Thread-safe; cost: O(tables retained).
void set_table_budget(std::size_t bytes) noexcept;

/// The table cache's byte budget (default_table_budget unless set_table_budget changed it).
std::size_t table_budget() noexcept;

/// Drops every table the cache retains (the budget is unchanged); a table still held elsewhere
/// is freed when its last holder lets go. Returns the bytes the cache retained before the call.
/// Thread-safe; cost: O(tables retained).
std::size_t release_tables() noexcept;

/// The table cache's state, for tests and monitoring.
struct table_cache_statistics {
  std::size_t retained_bytes = 0;   ///< bytes of the tables the cache retains (<= the budget)
  std::size_t retained_tables = 0;  ///< how many tables it retains
  std::size_t builds = 0;           ///< tables built since the process started
  std::size_t evictions = 0;        ///< tables dropped to fit the budget (not by release_tables)
};

/// A snapshot of the table cache's state. Thread-safe.
table_cache_statistics table_cache_stats() noexcept;

}  // namespace hemilight
