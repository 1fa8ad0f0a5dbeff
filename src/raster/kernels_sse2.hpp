// Internal to the rasterizer (not installed; included by rasterizer.cpp only): the SSE2 kernel
// set, four texels (or four clip planes) per step. SSE2 is part of the x86-64 baseline, so these
// are inlined into the generic code that calls them. Each gives the scalar path's bits (tested).
#pragma once

#include "isa.hpp"
#include "kernel_common.hpp"

#include <cfloat>
#include <cstddef>
#include <cstdint>
#include <cstring>

#if HEMILIGHT_RASTER_SSE2

namespace hemilight {

using namespace raster_detail;

namespace {

// Logs the tie lanes `tie` of the four texels at depth (depths z), if any.
inline void log_ties4(tie_log* ties, const float* depth, __m128 z, __m128 tie, std::uint32_t id) {
  if (const int bits = _mm_movemask_ps(tie)) {
    alignas(16) float zl[4];
    _mm_store_ps(zl, z);
    ties->add(depth, zl, id, static_cast<unsigned>(bits));
  }
}

// Largest triangle extent (in 1/256 texel) for the 32-bit SSE2 small-triangle path.
constexpr std::int64_t simd_extent = 32 * sub_one;

// Small triangles (draw_fixed, step 4b): the box scanned four texels per step with 32-bit edge
// values, the coverage mask going straight into the depth test (or the counts). ex, ey, e0: the int64 edge functions (tie bias included) at texel (x, y):
// E = ex x + ey y + e0; covered iff all three are >= 0.
template <bool count_mode, bool log>
void small_triangle_sse2_body(const std::int64_t (&ex)[3], const std::int64_t (&ey)[3], const std::int64_t (&e0)[3],
                              std::int64_t x_begin, std::int64_t x_end, std::int64_t y_begin, std::int64_t y_end, int n,
                              float* depth, std::uint32_t* ids, std::uint32_t* counts, double z00, double dzdy,
                              float dzdx, std::uint32_t draw, tie_log* ties) noexcept {
  const __m128i lane = _mm_setr_epi32(0, 1, 2, 3);
  __m128i step[3], row[3];
  for (int k = 0; k < 3; ++k) {
    // Values at (x_begin + lane, y_begin): exact in int64, small enough for int32 here.
    const std::int64_t base = ex[k] * x_begin + ey[k] * y_begin + e0[k];
    row[k] = _mm_setr_epi32(static_cast<std::int32_t>(base), static_cast<std::int32_t>(base + ex[k]),
                            static_cast<std::int32_t>(base + 2 * ex[k]), static_cast<std::int32_t>(base + 3 * ex[k]));
    step[k] = _mm_set1_epi32(static_cast<std::int32_t>(4 * ex[k]));
  }
  const __m128i dy0 = _mm_set1_epi32(static_cast<std::int32_t>(ey[0])), dy1 = _mm_set1_epi32(static_cast<std::int32_t>(ey[1])),
                dy2 = _mm_set1_epi32(static_cast<std::int32_t>(ey[2]));
  const __m128 dz = _mm_set1_ps(dzdx), zmin = _mm_set1_ps(FLT_MIN);
  const __m128i id = _mm_set1_epi32(static_cast<std::int32_t>(draw));
  const int xb = static_cast<int>(x_begin), xe = static_cast<int>(x_end);
  for (std::int64_t y = y_begin; y <= y_end; ++y) {
    const std::size_t r = static_cast<std::size_t>(y) * static_cast<std::size_t>(n);
    const __m128 zr = _mm_set1_ps(static_cast<float>(z00 + dzdy * static_cast<double>(y)));
    __m128i a = row[0], b = row[1], c = row[2];
    for (int x = xb; x <= xe; x += 4) {
      // Covered lanes: the OR of the three values has a clear sign bit.
      const __m128i in = _mm_cmpgt_epi32(_mm_or_si128(_mm_or_si128(a, b), c), _mm_set1_epi32(-1));
      a = _mm_add_epi32(a, step[0]);
      b = _mm_add_epi32(b, step[1]);
      c = _mm_add_epi32(c, step[2]);
      if (_mm_movemask_epi8(in) == 0) continue;
      if (x + 3 >= n) {
        // Last group of the row would pass the row's end: scalar, lane by lane.
        alignas(16) std::int32_t m[4];
        _mm_store_si128(reinterpret_cast<__m128i*>(m), in);
        for (int k = 0; k < 4 && x + k < n; ++k) {
          if (!m[k]) continue;
          const std::size_t i = r + static_cast<std::size_t>(x + k);
          if (count_mode) {
            ++counts[i];
            continue;
          }
          float z = _mm_cvtss_f32(zr) + dzdx * static_cast<float>(x + k);
          z = z > FLT_MIN ? z : FLT_MIN;
          if (log && z == depth[i]) ties->add(depth + i, &z, draw, 1u);
          if (z > depth[i]) {
            depth[i] = z;
            ids[i] = draw;
          }
        }
        continue;
      }
      const std::size_t i = r + static_cast<std::size_t>(x);
      if (count_mode) {
        __m128i* cp = reinterpret_cast<__m128i*>(counts + i);
        _mm_storeu_si128(cp, _mm_sub_epi32(_mm_loadu_si128(cp), in));  // in = -1 where covered
        continue;
      }
      const __m128 xf = _mm_cvtepi32_ps(_mm_add_epi32(_mm_set1_epi32(x), lane));
      const __m128 z = _mm_max_ps(_mm_add_ps(zr, _mm_mul_ps(dz, xf)), zmin);
      const __m128 old = _mm_loadu_ps(depth + i);
      const __m128 closer = _mm_and_ps(_mm_cmpgt_ps(z, old), _mm_castsi128_ps(in));
      if (log) log_ties4(ties, depth + i, z, _mm_and_ps(_mm_cmpeq_ps(z, old), _mm_castsi128_ps(in)), draw);
      _mm_storeu_ps(depth + i, _mm_or_ps(_mm_and_ps(closer, z), _mm_andnot_ps(closer, old)));
      __m128i* ip = reinterpret_cast<__m128i*>(ids + i);
      const __m128i mask = _mm_castps_si128(closer);
      _mm_storeu_si128(ip, _mm_or_si128(_mm_and_si128(mask, id), _mm_andnot_si128(mask, _mm_loadu_si128(ip))));
    }
    row[0] = _mm_add_epi32(row[0], dy0);
    row[1] = _mm_add_epi32(row[1], dy1);
    row[2] = _mm_add_epi32(row[2], dy2);
  }
}

// small_triangle_sse2_body, logging ties when `ties` is not null.
template <bool count_mode>
void small_triangle_sse2_impl(const std::int64_t (&ex)[3], const std::int64_t (&ey)[3], const std::int64_t (&e0)[3],
                              std::int64_t x_begin, std::int64_t x_end, std::int64_t y_begin, std::int64_t y_end, int n,
                              float* depth, std::uint32_t* ids, std::uint32_t* counts, double z00, double dzdy,
                              float dzdx, std::uint32_t draw, tie_log* ties) noexcept {
  if (ties)
    small_triangle_sse2_body<count_mode, true>(ex, ey, e0, x_begin, x_end, y_begin, y_end, n, depth, ids, counts, z00, dzdy,
                                               dzdx, draw, ties);
  else
    small_triangle_sse2_body<count_mode, false>(ex, ey, e0, x_begin, x_end, y_begin, y_end, n, depth, ids, counts, z00, dzdy,
                                                dzdx, draw, ties);
}

// outcode() (rasterizer.cpp) of a local-frame point: the same twelve differences, four per
// register (x + (-y) is x - y exactly; the sign of a zero cannot change a "< 0" test), so both
// versions give the same bits.
inline unsigned outcode_sse2(const glm::vec3& p) noexcept {
  const __m128 zero = _mm_setzero_ps();
  const __m128 a = _mm_add_ps(_mm_setr_ps(p.x, p.x, -p.x, -p.x), _mm_setr_ps(-p.y, p.y, -p.y, p.y));
  const __m128 b = _mm_sub_ps(_mm_setr_ps(p.x, -p.x, p.y, -p.y), _mm_set1_ps(p.z));
  const __m128 c = _mm_add_ps(_mm_set1_ps(p.z), _mm_setr_ps(-p.x, p.x, -p.y, p.y));
  return static_cast<unsigned>(p.z < 0) | static_cast<unsigned>(_mm_movemask_ps(_mm_cmplt_ps(a, zero))) << 1 |
         static_cast<unsigned>(_mm_movemask_ps(_mm_cmplt_ps(b, zero))) << 5 |
         static_cast<unsigned>(_mm_movemask_ps(_mm_cmplt_ps(c, zero))) << 9;
}

// raster_face's clip codes of a vertex c (bit 0: w < near; bits 1-4: outside the guard band's
// four planes, gw = guard_band w): gw + (-u) is gw - u exactly, the same bits as the scalar
// expressions.
inline unsigned clip_codes_sse2(const clip_vertex& c, float gw, float near) noexcept {
  const __m128 d = _mm_add_ps(_mm_set1_ps(gw), _mm_setr_ps(-c.u, c.u, -c.v, c.v));
  return static_cast<unsigned>(c.w - near < 0.0f) |
         static_cast<unsigned>(_mm_movemask_ps(_mm_cmplt_ps(d, _mm_setzero_ps()))) << 1;
}

// The span paths' depth test of texels [x, hi] of one row (drow, irow: the row's depth and ids)
// four at a time: the same operations in the same order as the scalar loop (span_writer), so the
// results are bit-identical (tested). max(z, FLT_MIN) returns FLT_MIN for NaN, like the scalar
// select. Returns the first texel not done (fewer than four are left from it to hi).
template <bool log>
inline int span_sse2_body(float* drow, std::uint32_t* irow, int x, int hi, float zrow, float dzdx,
                          std::uint32_t draw, tie_log* ties) noexcept {
  const __m128 zr = _mm_set1_ps(zrow), dz = _mm_set1_ps(dzdx), zmin = _mm_set1_ps(FLT_MIN);
  const __m128i id = _mm_set1_epi32(static_cast<int>(draw)), lane = _mm_setr_epi32(0, 1, 2, 3);
  for (; x + 3 <= hi; x += 4) {
    const __m128 xf = _mm_cvtepi32_ps(_mm_add_epi32(_mm_set1_epi32(x), lane));
    const __m128 z = _mm_max_ps(_mm_add_ps(zr, _mm_mul_ps(dz, xf)), zmin);
    const __m128 old = _mm_loadu_ps(drow + x);
    const __m128 closer = _mm_cmpgt_ps(z, old);
    if (log) log_ties4(ties, drow + x, z, _mm_cmpeq_ps(z, old), draw);
    _mm_storeu_ps(drow + x, _mm_or_ps(_mm_and_ps(closer, z), _mm_andnot_ps(closer, old)));
    __m128i* ip = reinterpret_cast<__m128i*>(irow + x);
    const __m128i mask = _mm_castps_si128(closer);
    _mm_storeu_si128(ip, _mm_or_si128(_mm_and_si128(mask, id), _mm_andnot_si128(mask, _mm_loadu_si128(ip))));
  }
  return x;
}

inline int span_sse2(float* drow, std::uint32_t* irow, int x, int hi, float zrow, float dzdx, std::uint32_t draw,
                     tie_log* ties) noexcept {
  return ties ? span_sse2_body<true>(drow, irow, x, hi, zrow, dzdx, draw, ties)
              : span_sse2_body<false>(drow, irow, x, hi, zrow, dzdx, draw, ties);
}

// resolve_texels (rasterizer.cpp) four texels at a time, from texel 0 while four are left: the
// same values as its scalar loop. Returns the first texel not done.
inline std::size_t resolve_texels_sse2(std::size_t count, float* __restrict depth, const float* __restrict lengths,
                                       std::uint32_t* __restrict ids, const shade* __restrict shades, key_map key_of,
                                       float* __restrict distance, float* __restrict red, float* __restrict green,
                                       float* __restrict blue, std::uint8_t* __restrict flags) noexcept {
  std::size_t i = 0;
  // Four texels at a time: distance, id of unwritten texels -> 0, radiance, flags. Texels come
  // in runs that see the same record (a triangle, or the sky): when four neighbours share one,
  // its channels go out as three broadcast stores, kept while the record does not change, and
  // its flags as one word; mixed groups are written texel by texel.
  const __m128 zero = _mm_setzero_ps();
  __m128i run_id = _mm_set1_epi32(-1);  // no record yet (record numbers are < 2^31)
  __m128 run_r = zero, run_g = zero, run_b = zero;
  std::uint32_t run_flags = 0;
  for (; i + 4 <= count; i += 4) {
    const __m128 d = _mm_loadu_ps(depth + i);
    _mm_storeu_ps(depth + i, zero);  // cleared for the next render
    _mm_storeu_ps(distance + i, _mm_div_ps(_mm_loadu_ps(lengths + i), d));  // +inf for 1/w = 0
    const __m128i id = _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(ids + i)),
                                     _mm_castps_si128(_mm_cmpgt_ps(d, zero)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(ids + i), id);
    bool uniform = true;
    if (_mm_movemask_epi8(_mm_cmpeq_epi32(id, run_id)) != 0xffff) {
      const __m128i first = _mm_shuffle_epi32(id, 0);
      if (_mm_movemask_epi8(_mm_cmpeq_epi32(id, first)) == 0xffff) {
        run_id = first;
        const shade& sh = shades[key_of(static_cast<std::uint32_t>(_mm_cvtsi128_si32(id)))];
        run_r = _mm_set1_ps(sh.r);
        run_g = _mm_set1_ps(sh.g);
        run_b = _mm_set1_ps(sh.b);
        run_flags = (sh.flags & 0xffu) * 0x01010101u;
      } else {
        run_id = _mm_set1_epi32(-1);
        uniform = false;
      }
    }
    if (uniform) {
      _mm_storeu_ps(red + i, run_r);
      _mm_storeu_ps(green + i, run_g);
      _mm_storeu_ps(blue + i, run_b);
      std::memcpy(flags + i, &run_flags, 4);
      continue;
    }
    std::uint32_t lane[4];
    _mm_storeu_si128(reinterpret_cast<__m128i*>(lane), id);
    for (std::uint32_t& k : lane) k = key_of(k);
    copy_shades(lane, 4, shades, red + i, green + i, blue + i, flags + i);
  }
  return i;
}
}  // namespace

}  // namespace hemilight

#endif  // HEMILIGHT_RASTER_SSE2
