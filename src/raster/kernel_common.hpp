// Internal to the rasterizer (not installed; included by rasterizer.cpp only): what the scalar,
// SSE2 and AVX2 paths share. The fixed-point grid's integer helpers, the exact span walk (its
// rows are written by a functor per path), and the resolve's shade lookup and copy.
#pragma once

#include "internal.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace hemilight {

using namespace raster_detail;

namespace {

// floor(a / m) for m > 0 and |a|, m < 2^52: a double estimate (off by at most one, both are
// exact doubles) made exact with integer checks; cheaper than a 64-bit division.
inline std::int64_t floor_div(std::int64_t a, std::int64_t m) noexcept {
  auto q = static_cast<std::int64_t>(static_cast<double>(a) / static_cast<double>(m));
  while (q * m > a) --q;
  while ((q + 1) * m <= a) ++q;
  return q;
}

// Nearest integer, halves away from zero (deterministic, no libm call). |x| < 2^30 here.
inline std::int64_t round_to_int(double x) noexcept {
  return static_cast<std::int64_t>(x >= 0.0 ? x + 0.5 : x - 0.5);
}

// One edge of the exact span walk: the bound on x (left: x >= bound, right: x <= bound) of the
// current row as quotient and remainder, and their steps per row (see draw_fixed).
struct edge_walk {
  std::int64_t bound, rem, m, q_step, r_step;
};

// Rows y0..y1 of the exact span walk with NL left and NR right edges; span(y, lo, hi) writes a
// row. The carries are branch-free (sign masks): they are taken in a data-dependent pattern.
template <std::size_t NL, std::size_t NR, class Span>
inline void walk_rows(const edge_walk* left_in, const edge_walk* right_in, std::int64_t y0, std::int64_t y1,
                      std::int64_t x_begin, std::int64_t x_end, Span& span) {
  edge_walk left[NL], right[NR];
  std::copy(left_in, left_in + NL, left);
  std::copy(right_in, right_in + NR, right);
  for (std::int64_t y = y0; y <= y1; ++y) {
    std::int64_t lo = x_begin, hi = x_end;
    for (std::size_t i = 0; i < NL; ++i) {
      edge_walk& e = left[i];
      lo = std::max(lo, e.bound);
      e.rem -= e.r_step;
      const std::int64_t carry = e.rem >> 63;  // -1 if rem < 0, else 0
      e.bound += e.q_step - carry;
      e.rem += carry & e.m;
    }
    for (std::size_t i = 0; i < NR; ++i) {
      edge_walk& e = right[i];
      hi = std::min(hi, e.bound);
      e.rem += e.r_step - e.m;
      const std::int64_t keep = e.rem >> 63;  // -1 if the old rem + r_step < m (no carry)
      e.bound += e.q_step + 1 + keep;
      e.rem += keep & e.m;
    }
    if (lo <= hi) span(static_cast<int>(y), static_cast<int>(lo), static_cast<int>(hi));
  }
}

// walk_rows for the edge counts a triangle with area has: one left and one right bound (with a
// horizontal edge), or one and two, or two and one. Fixed counts keep the walk in registers.
template <class Span>
inline void walk_rows_of(int nl, int nr, const edge_walk* left, const edge_walk* right, std::int64_t y0, std::int64_t y1,
                         std::int64_t x_begin, std::int64_t x_end, Span& span) {
  if (nl == 1 && nr == 1)
    walk_rows<1, 1>(left, right, y0, y1, x_begin, x_end, span);
  else if (nl == 1 && nr == 2)
    walk_rows<1, 2>(left, right, y0, y1, x_begin, x_end, span);
  else if (nl == 2 && nr == 1)
    walk_rows<2, 1>(left, right, y0, y1, x_begin, x_end, span);
  else
    assert(false && "a triangle with area has a left and a right edge");
}

// A texel's id -> its entry in shades: the low `bits` bits of the id when the rasterizer packs
// the key there (rasterizer_impl::key_bits_), else keys[id] (keys: per draw).
struct key_map {
  const std::uint32_t* keys;
  std::uint32_t bits;
  std::uint32_t operator()(std::uint32_t id) const noexcept { return bits ? id & ((1u << bits) - 1u) : keys[id]; }
};

// The resolves' per-texel copy (groups of texels with different shades, and the scalar path):
// the shade (keys[k] indexes shades) copied to the radiance planes and flags.
inline void copy_shades(const std::uint32_t* keys, std::size_t count, const shade* shades,
                        float* red, float* green, float* blue, std::uint8_t* flags) noexcept {
  for (std::size_t k = 0; k < count; ++k) {
    const shade& sh = shades[keys[k]];
    red[k] = sh.r;
    green[k] = sh.g;
    blue[k] = sh.b;
    flags[k] = static_cast<std::uint8_t>(sh.flags);
  }
}

}  // namespace

}  // namespace hemilight
