// Internal to the rasterizer (not installed; included by rasterizer.cpp only): the AVX2 kernel
// set, eight texels (or eight triangles) per step: the depth test, the span and small-triangle
// kernels, the resolve, and the broadcast frame of the eight-lane set-up (leaf_avx.inl). Compiled
// with target attributes (isa.hpp) and called only when the CPU has AVX2 (rasterizer_impl::avx2_).
#pragma once

#include "isa.hpp"
#include "kernel_common.hpp"
#include "../scene/scene_access.hpp"

#include <cfloat>
#include <cstddef>
#include <cstdint>
#include <cstring>

#if HEMILIGHT_RASTER_AVX2

namespace hemilight {

using namespace raster_detail;

namespace {

// Largest triangle extent (in 1/256 texel) for the AVX2 small-triangle kernel, which also takes the big triangles of small hemicubes: with both
// extents <= E = 120 texels (30,720 in fixed point), every edge value it forms (texel centres in
// the triangle's box, or up to 8 texels past it in x), dx (Py - Ay) - dy (Px - Ax) + bias, is at
// most E^2 + E (E + 2^11) + 1 = 1,950,351,361 < 2^31 - 1: exact in 32-bit lanes, and so are the
// two products and the signed area of the set-up. 120 rather than 64: three in five of the
// room's triangles over 64 texels across are under 120, and the box scan of their part on the
// face is cheaper than the exact span walk.
constexpr std::int64_t avx2_extent = 120 * sub_one;

// The AVX2 kernels compute exactly what the scalar reference does (the same float operations in
// the same order; target("avx2") does not enable FMA contraction), so buffers stay bit-identical.
// They may read and write back up to 7 texels past the last one they own (the rows are contiguous
// and the visibility buffers are padded by 8): masked lanes store the values they loaded.

// Depth test of the eight texels at depth / ids: where `mask` is set and z is nearer (a larger
// 1/w), z and `id` win. Returns the lanes where z equals the depth already there (a tie, which
// the drawing order decides: occlusion culling's front-to-back pass must know). The common tail
// of the AVX2 kernels.
HEMILIGHT_TARGET_AVX2 inline __m256 depth_test8(float* depth, std::uint32_t* ids, __m256 z, __m256 mask,
                                                __m256 id) noexcept {
  const __m256 old = _mm256_loadu_ps(depth);
  const __m256 closer = _mm256_and_ps(_mm256_cmp_ps(z, old, _CMP_GT_OQ), mask);
  _mm256_storeu_ps(depth, _mm256_blendv_ps(old, z, closer));
  float* ip = reinterpret_cast<float*>(ids);
  _mm256_storeu_ps(ip, _mm256_blendv_ps(_mm256_loadu_ps(ip), id, closer));
  return _mm256_and_ps(_mm256_cmp_ps(z, old, _CMP_EQ_OQ), mask);
}

// Depth test of texels [lo, hi] of one row (drow, irow: the row's depth and ids).
// The depth test of span_avx2 with its constants given (zr: the row's depth, dz: its step per
// texel, zmin = FLT_MIN, id: the record in every lane), shared with the span walk's functor.
// Logs the tie lanes `tie` of the eight texels at depth (depths z), if any.
HEMILIGHT_TARGET_AVX2 inline void log_ties8(tie_log* ties, const float* depth, __m256 z, __m256 tie, __m256 id) {
  if (const int bits = _mm256_movemask_ps(tie)) {
    alignas(32) float zl[8];
    _mm256_store_ps(zl, z);
    ties->add(depth, zl, static_cast<std::uint32_t>(_mm256_cvtsi256_si32(_mm256_castps_si256(id))), static_cast<unsigned>(bits));
  }
}

// Ties go to `ties` (tie_log) when `log` (else `ties` is not read).
template <bool log>
HEMILIGHT_TARGET_AVX2 inline __attribute__((always_inline)) void span_body_avx2(float* drow, std::uint32_t* irow,
                                                                               int lo, int hi, __m256 zr, __m256 dz,
                                                                               __m256 zmin, __m256 id,
                                                                               tie_log* ties) noexcept {
  const __m256i end = _mm256_set1_epi32(hi + 1), eight = _mm256_set1_epi32(8);
  __m256i xi = _mm256_add_epi32(_mm256_set1_epi32(lo), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
  for (int x = lo; x <= hi; x += 8, xi = _mm256_add_epi32(xi, eight)) {
    const __m256 z = _mm256_max_ps(_mm256_add_ps(zr, _mm256_mul_ps(dz, _mm256_cvtepi32_ps(xi))), zmin);
    const __m256 tie = depth_test8(drow + x, irow + x, z, _mm256_castsi256_ps(_mm256_cmpgt_epi32(end, xi)), id);
    if (log) log_ties8(ties, drow + x, z, tie, id);
  }
}

HEMILIGHT_TARGET_AVX2 void span_avx2(float* drow, std::uint32_t* irow, int lo, int hi, float zrow, float dzdx,
                                     std::uint32_t draw, tie_log* ties) noexcept {
  const __m256 id = _mm256_castsi256_ps(_mm256_set1_epi32(static_cast<int>(draw)));
  if (ties)
    span_body_avx2<true>(drow, irow, lo, hi, _mm256_set1_ps(zrow), _mm256_set1_ps(dzdx), _mm256_set1_ps(FLT_MIN), id, ties);
  else
    span_body_avx2<false>(drow, irow, lo, hi, _mm256_set1_ps(zrow), _mm256_set1_ps(dzdx), _mm256_set1_ps(FLT_MIN), id, ties);
}

// The exact span walk's rows in depth mode (draw_fixed): walk_rows with span_avx2's depth test
// inlined and its constants set up once per triangle instead of once per row. The same float
// operations on the same values as span_avx2 and the scalar span, so the same bits.
template <bool log>
struct depth_spans_avx2 {
  float* depth;
  std::uint32_t* ids;
  std::size_t n;
  double z00, dzdy;
  __m256 dz, zmin, id;
  std::size_t spans = 0, fragments = 0;
  tie_log* ties = nullptr;

  HEMILIGHT_TARGET_AVX2 depth_spans_avx2(float* depth_, std::uint32_t* ids_, int n_, double z00_, double dzdy_,
                                         float dzdx, std::uint32_t draw) noexcept
      : depth(depth_), ids(ids_), n(static_cast<std::size_t>(n_)), z00(z00_), dzdy(dzdy_),
        dz(_mm256_set1_ps(dzdx)), zmin(_mm256_set1_ps(FLT_MIN)),
        id(_mm256_castsi256_ps(_mm256_set1_epi32(static_cast<int>(draw)))) {}

  HEMILIGHT_TARGET_AVX2 void operator()(int y, int lo, int hi) noexcept {
    ++spans;
    fragments += static_cast<std::size_t>(hi - lo + 1);
    const std::size_t row = static_cast<std::size_t>(y) * n;
    span_body_avx2<log>(depth + row, ids + row, lo, hi, _mm256_set1_ps(static_cast<float>(z00 + dzdy * y)), dz, zmin, id,
                        ties);
  }
};

// The span walk of draw_fixed (see there), depth mode, AVX2. flatten: walk_rows and the span
// functor are inlined here (an always_inline functor could not be: walk_rows is not AVX2 code).
HEMILIGHT_TARGET_AVX2 __attribute__((flatten)) void walk_depth_avx2(
    int nl, int nr, const edge_walk* left, const edge_walk* right, std::int64_t y0, std::int64_t y1,
    std::int64_t x_begin, std::int64_t x_end, float* depth, std::uint32_t* ids, int n, double z00, double dzdy,
    float dzdx, std::uint32_t draw, raster_statistics& stats, tie_log* ties) noexcept {
  const auto walk = [&](auto& span) HEMILIGHT_TARGET_AVX2 {
    span.ties = ties;
    walk_rows_of(nl, nr, left, right, y0, y1, x_begin, x_end, span);
    stats.spans += span.spans;
    stats.fragments += span.fragments;
  };
  if (ties) {
    depth_spans_avx2<true> span(depth, ids, n, z00, dzdy, dzdx, draw);
    walk(span);
  } else {
    depth_spans_avx2<false> span(depth, ids, n, z00, dzdy, dzdx, draw);
    walk(span);
  }
}

// The small-triangle path of small_triangle_sse2_impl, eight texels per step.
// base, sx, sy: the 32-bit edge values at the box's first texel (x_begin, y_begin) and their
// steps per texel in x and y (the caller checks they fit, see avx2_extent).
template <bool count_mode, bool log>
HEMILIGHT_TARGET_AVX2 inline __attribute__((always_inline)) void small_triangle_avx2_body(
    const std::int32_t* base, const std::int32_t* sx, const std::int32_t* sy, std::size_t stride, std::int64_t x_begin,
    std::int64_t x_end, std::int64_t y_begin, std::int64_t y_end, int n, float* depth, std::uint32_t* ids,
    std::uint32_t* counts, double z00, double dzdy, float dzdx, std::uint32_t draw, tie_log* ties) noexcept {
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  __m256i step[3], row[3], dy[3];
  for (std::size_t k = 0; k < 3; ++k) {
    // Values at (x_begin + lane, y_begin); edge k's values are at [k * stride].
    const std::int32_t b = base[k * stride], ex = sx[k * stride];
    row[k] = _mm256_add_epi32(_mm256_set1_epi32(b), _mm256_mullo_epi32(_mm256_set1_epi32(ex), lane));
    step[k] = _mm256_set1_epi32(8 * ex);
    dy[k] = _mm256_set1_epi32(sy[k * stride]);
  }
  const __m256 dz = _mm256_set1_ps(dzdx), zmin = _mm256_set1_ps(FLT_MIN);
  const __m256 id = _mm256_castsi256_ps(_mm256_set1_epi32(static_cast<int>(draw)));
  const int xb = static_cast<int>(x_begin), xe = static_cast<int>(x_end);
  const __m256i end = _mm256_set1_epi32(xe + 1);
  if (!count_mode && xe - xb < 8) {
    // One group per row (most triangles of big scenes): the lanes' x, their depth step and the
    // box mask are the same on every row. The same operations as below, so the same bits.
    const __m256i xi = _mm256_add_epi32(_mm256_set1_epi32(xb), lane);
    const __m256i box = _mm256_cmpgt_epi32(end, xi);
    const __m256 zx = _mm256_mul_ps(dz, _mm256_cvtepi32_ps(xi));
    __m256i a = row[0], b = row[1], c = row[2];
    for (std::int64_t y = y_begin; y <= y_end; ++y) {
      const __m256i in = _mm256_andnot_si256(_mm256_or_si256(_mm256_or_si256(a, b), c), box);
      a = _mm256_add_epi32(a, dy[0]);
      b = _mm256_add_epi32(b, dy[1]);
      c = _mm256_add_epi32(c, dy[2]);
      // No test for an empty row: the depth test then stores back what it loaded, and a branch
      // here mispredicted often enough (slivers, box corners) to cost more than the stores: without
      // it and the one below, the room renders ~13% faster (interleaved timings; more instructions).
      const __m256 mask = _mm256_castsi256_ps(_mm256_srai_epi32(in, 31));
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(n) + static_cast<std::size_t>(xb);
      const __m256 zr = _mm256_set1_ps(static_cast<float>(z00 + dzdy * static_cast<double>(y)));
      const __m256 z = _mm256_max_ps(_mm256_add_ps(zr, zx), zmin);
      const __m256 tie = depth_test8(depth + i, ids + i, z, mask, id);
      if (log) log_ties8(ties, depth + i, z, tie, id);
    }
    return;
  }
  for (std::int64_t y = y_begin; y <= y_end; ++y) {
    const std::size_t r = static_cast<std::size_t>(y) * static_cast<std::size_t>(n);
    const __m256 zr = _mm256_set1_ps(static_cast<float>(z00 + dzdy * static_cast<double>(y)));
    __m256i a = row[0], b = row[1], c = row[2];
    for (int x = xb; x <= xe; x += 8) {
      const __m256i xi = _mm256_add_epi32(_mm256_set1_epi32(x), lane);
      // Covered lanes (the OR of the three edge values has a clear sign bit) inside the box.
      const __m256i in = _mm256_andnot_si256(_mm256_or_si256(_mm256_or_si256(a, b), c), _mm256_cmpgt_epi32(end, xi));
      a = _mm256_add_epi32(a, step[0]);
      b = _mm256_add_epi32(b, step[1]);
      c = _mm256_add_epi32(c, step[2]);
      // No test for an empty group either (see the one-group loop above).
      const __m256 mask = _mm256_castsi256_ps(_mm256_srai_epi32(in, 31));
      const std::size_t i = r + static_cast<std::size_t>(x);
      if (count_mode) {
        __m256i* cp = reinterpret_cast<__m256i*>(counts + i);
        _mm256_storeu_si256(cp, _mm256_sub_epi32(_mm256_loadu_si256(cp), _mm256_castps_si256(mask)));
        continue;
      }
      const __m256 z = _mm256_max_ps(_mm256_add_ps(zr, _mm256_mul_ps(dz, _mm256_cvtepi32_ps(xi))), zmin);
      const __m256 tie = depth_test8(depth + i, ids + i, z, mask, id);
      if (log) log_ties8(ties, depth + i, z, tie, id);
    }
    row[0] = _mm256_add_epi32(row[0], dy[0]);
    row[1] = _mm256_add_epi32(row[1], dy[1]);
    row[2] = _mm256_add_epi32(row[2], dy[2]);
  }
}

// small_triangle_avx2_body as a function (for draw_fixed, outside the AVX2 set-up).
template <bool count_mode>
HEMILIGHT_TARGET_AVX2 void small_triangle_avx2_impl(const std::int32_t* base, const std::int32_t* sx,
                                                    const std::int32_t* sy, std::int64_t x_begin, std::int64_t x_end,
                                                    std::int64_t y_begin, std::int64_t y_end, int n, float* depth,
                                                    std::uint32_t* ids, std::uint32_t* counts, double z00, double dzdy,
                                                    float dzdx, std::uint32_t draw, tie_log* ties) noexcept {
  if (ties)
    small_triangle_avx2_body<count_mode, true>(base, sx, sy, 1, x_begin, x_end, y_begin, y_end, n, depth, ids, counts, z00,
                                               dzdy, dzdx, draw, ties);
  else
    small_triangle_avx2_body<count_mode, false>(base, sx, sy, 1, x_begin, x_end, y_begin, y_end, n, depth, ids, counts, z00,
                                                dzdy, dzdx, draw, ties);
}

// The resolve of resolve_texels (below), eight texels per step; the last count % 8 (0 or 4)
// texels are left to the caller. Runs are found by shade key (the draw's entry in shades), so the
// two triangles of a quad, or all black surfaces, make one run. packed: the key is the id's low
// `bits` bits (no lookup); otherwise keys[id].
template <bool packed>
HEMILIGHT_TARGET_AVX2 void resolve_texels_avx2(std::size_t count, float* __restrict depth,
                                               const float* __restrict lengths, std::uint32_t* __restrict ids,
                                               const shade* __restrict shades,
                                               const std::uint32_t* __restrict keys, std::uint32_t bits,
                                               float* __restrict distance,
                                               float* __restrict red, float* __restrict green,
                                               float* __restrict blue, std::uint8_t* __restrict flags) noexcept {
  const __m256 zero = _mm256_setzero_ps();
  // The current run: its shade key, and its record when all its texels so far had one record
  // (a cheap first test); -1 = none (record numbers are < 2^31).
  __m256i run_id = _mm256_set1_epi32(-1), run_key = _mm256_set1_epi32(-1);
  const __m256i key_mask = _mm256_set1_epi32(static_cast<int>((1u << bits) - 1u));
  __m256 run_r = zero, run_g = zero, run_b = zero;
  std::uint64_t run_flags = 0;
  for (std::size_t i = 0; i + 8 <= count; i += 8) {
    const __m256 d = _mm256_loadu_ps(depth + i);
    _mm256_storeu_ps(depth + i, zero);  // cleared for the next render
    _mm256_storeu_ps(distance + i, _mm256_div_ps(_mm256_loadu_ps(lengths + i), d));  // +inf for 1/w = 0
    const __m256i id = _mm256_and_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids + i)),
                                        _mm256_castps_si256(_mm256_cmp_ps(d, zero, _CMP_GT_OQ)));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(ids + i), id);
    __m256i key, this_run = run_id;
    bool same_run;
    if (packed) {
      key = _mm256_and_si256(id, key_mask);
      same_run = _mm256_movemask_epi8(_mm256_cmpeq_epi32(key, run_key)) == -1;
    } else if (_mm256_movemask_epi8(_mm256_cmpeq_epi32(id, run_id)) == -1) {
      same_run = true;
    } else {
      // Eight texels of one record (most groups: big triangles, black walls) look up its key
      // with one load; only groups of several records gather (slow on some CPUs). Either way the
      // run remembers the record, so the next group of the same record skips the lookup.
      const __m256i id0 = _mm256_broadcastd_epi32(_mm256_castsi256_si128(id));
      const bool one_record = _mm256_movemask_epi8(_mm256_cmpeq_epi32(id, id0)) == -1;
      key = one_record ? _mm256_set1_epi32(static_cast<int>(keys[static_cast<std::uint32_t>(_mm256_cvtsi256_si32(id))]))
                       : _mm256_i32gather_epi32(reinterpret_cast<const int*>(keys), id, 4);
      this_run = one_record ? id0 : _mm256_set1_epi32(-1);
      same_run = _mm256_movemask_epi8(_mm256_cmpeq_epi32(key, run_key)) == -1;
      run_id = this_run;  // same shade (maybe other records): the run goes on
    }
    if (!same_run) {
      const __m256i first = _mm256_broadcastd_epi32(_mm256_castsi256_si128(key));
      const __m256i is_first = _mm256_cmpeq_epi32(key, first);
      if (_mm256_movemask_epi8(is_first) != -1) {  // (never for a group of one record)
        run_id = run_key = _mm256_set1_epi32(-1);
        // Two shades (a group across the boundary of two regions, the usual mixed group): the
        // first lane's and the last lane's, blended.
        const __m256i last = _mm256_permutevar8x32_epi32(key, _mm256_set1_epi32(7));
        if (_mm256_movemask_epi8(_mm256_or_si256(is_first, _mm256_cmpeq_epi32(key, last))) == -1) {
          const shade& s0 = shades[static_cast<std::uint32_t>(_mm256_cvtsi256_si32(key))];
          const shade& s1 = shades[static_cast<std::uint32_t>(_mm256_extract_epi32(key, 7))];
          const __m256 m = _mm256_castsi256_ps(is_first);
          _mm256_storeu_ps(red + i, _mm256_blendv_ps(_mm256_set1_ps(s1.r), _mm256_set1_ps(s0.r), m));
          _mm256_storeu_ps(green + i, _mm256_blendv_ps(_mm256_set1_ps(s1.g), _mm256_set1_ps(s0.g), m));
          _mm256_storeu_ps(blue + i, _mm256_blendv_ps(_mm256_set1_ps(s1.b), _mm256_set1_ps(s0.b), m));
          // Byte k of `pick` is 0xff where lane k has the first shade: byte 0 of each lane's mask.
          const __m256i bytes = _mm256_shuffle_epi8(
              is_first, _mm256_setr_epi8(0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 0, 4, 8, 12, -1,
                                         -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1));
          const std::uint64_t pick =
              static_cast<std::uint32_t>(_mm_cvtsi128_si32(_mm256_castsi256_si128(bytes))) |
              static_cast<std::uint64_t>(static_cast<std::uint32_t>(_mm_cvtsi128_si32(_mm256_extracti128_si256(bytes, 1))))
                  << 32;
          const std::uint64_t f0 = (s0.flags & 0xffu) * 0x0101010101010101ull, f1 = (s1.flags & 0xffu) * 0x0101010101010101ull;
          const std::uint64_t f = (f0 & pick) | (f1 & ~pick);
          std::memcpy(flags + i, &f, 8);
          continue;
        }
        // More shades: texel by texel.
        alignas(32) std::uint32_t lane[8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(lane), key);
        copy_shades(lane, 8, shades, red + i, green + i, blue + i, flags + i);
        continue;
      }
      // A new run of shade key `first`.
      run_key = first;
      run_id = this_run;
      const shade& sh = shades[static_cast<std::uint32_t>(_mm256_cvtsi256_si32(key))];
      run_r = _mm256_set1_ps(sh.r);
      run_g = _mm256_set1_ps(sh.g);
      run_b = _mm256_set1_ps(sh.b);
      run_flags = (sh.flags & 0xffu) * 0x0101010101010101ull;
    }
    _mm256_storeu_ps(red + i, run_r);
    _mm256_storeu_ps(green + i, run_g);
    _mm256_storeu_ps(blue + i, run_b);
    std::memcpy(flags + i, &run_flags, 8);
  }
}

}  // namespace

// The position and the frame's axes, broadcast once per render for draw_leaf_avx2, and the
// scene's per-coordinate vertex arrays.
struct raster_detail::simd_frame {
  __m256 p[3];              // each component of the position in all eight lanes
  __m256 t[3], b[3], n[3];  // each component of t, b, n in all eight lanes
  const float* coordinates[3][3];  // detail::scene_access::vertex_coordinates(s, vertex, axis)

  HEMILIGHT_TARGET_AVX2 void set(const glm::vec3& position, const frame& basis, const scene& s) noexcept {
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) coordinates[i][k] = detail::scene_access::vertex_coordinates(s, i, k);
    for (int k = 0; k < 3; ++k) {
      p[k] = _mm256_set1_ps(position[k]);
      t[k] = _mm256_set1_ps(basis.t[k]);
      b[k] = _mm256_set1_ps(basis.b[k]);
      n[k] = _mm256_set1_ps(basis.n[k]);
    }
  }
};

namespace {
// frame::to_local's dot(w, axis) = (w.x axis.x + w.y axis.y) + w.z axis.z, eight lanes.
HEMILIGHT_TARGET_AVX2 inline __m256 dot8(const __m256 (&w)[3], const __m256 (&axis)[3]) noexcept {
  return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(w[0], axis[0]), _mm256_mul_ps(w[1], axis[1])),
                       _mm256_mul_ps(w[2], axis[2]));
}
HEMILIGHT_TARGET_AVX2 inline __m256 negative8(__m256 m) noexcept {
  return _mm256_cmp_ps(m, _mm256_setzero_ps(), _CMP_LT_OQ);
}
HEMILIGHT_TARGET_AVX2 inline __m256 positive8(__m256 m) noexcept {
  return _mm256_cmp_ps(m, _mm256_setzero_ps(), _CMP_GT_OQ);
}
}  // namespace

}  // namespace hemilight

#else
namespace hemilight {
// Without the AVX2 kernels the set-up's broadcast frame is never used: an empty stand-in.
struct raster_detail::simd_frame {};
}  // namespace hemilight
#endif  // HEMILIGHT_RASTER_AVX2
