// The compiled sums of kernels.hpp: the float builds of the portable loops (cloned for AVX2 where
// the compiler dispatches at load time) and the hand-written AVX2 + FMA kernels.
#include "kernels.hpp"

#include <cstring>

#if HEMILIGHT_INTEGRATE_AVX2
#include <immintrin.h>
#endif

// AVX2 and default clones of the hot sums, picked at load time (an ifunc). Not under
// ThreadSanitizer: the instrumented resolver would run before the sanitizer's runtime is set up
// and crash the loader (the TSan build then runs the default clone).
#if defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define HEMILIGHT_TSAN_BUILD 1
#endif
#endif
#if defined(__SANITIZE_THREAD__)
#define HEMILIGHT_TSAN_BUILD 1
#endif
#if defined(__x86_64__) && defined(__linux__) && (defined(__GNUC__) || defined(__clang__)) && !defined(HEMILIGHT_TSAN_BUILD)
#define HEMILIGHT_TARGET_CLONES_AVX2 __attribute__((target_clones("avx2", "default")))
#else
#define HEMILIGHT_TARGET_CLONES_AVX2
#endif

namespace hemilight::integrate_detail {

void extrapolated_walls(const float* inv, const std::uint8_t* nb, std::size_t step, unsigned before_bit, unsigned after_bit,
                        std::size_t count, float* wall_inv) {
#pragma omp simd
  for (std::size_t i = 0; i < count - step; ++i)
    wall_inv[i] = extrapolated_wall_inv(inv[i], inv[i + step], inv[i - step], inv[i + 2 * step], (nb[i] & before_bit) != 0,
                                        (nb[i] & after_bit) != 0);
}

HEMILIGHT_TARGET_CLONES_AVX2
void wall_sums_given_float(const float* r, const float* g, const float* b, const float* wall_inv, const float* cx,
                           const float* cy, std::size_t step, std::size_t end, float cap, double* acc) {
  wall_sums_impl<float, true>(r, g, b, wall_inv, cx, cy, step, end, cap, acc);
}

HEMILIGHT_TARGET_CLONES_AVX2
void directional_sums_float(const float* r, const float* g, const float* b, const float* omega, const float* h0,
                            const float* h1, const float* h2, std::size_t count, double* d) {
  directional_sums_impl<float>(r, g, b, omega, h0, h1, h2, count, d);
}

HEMILIGHT_TARGET_CLONES_AVX2
void wall_sums_float(const float* r, const float* g, const float* b, const float* inv, const float* cx, const float* cy,
                     std::size_t step, std::size_t end, float cap, double* acc) {
  wall_sums_impl<float>(r, g, b, inv, cx, cy, step, end, cap, acc);
}

HEMILIGHT_TARGET_CLONES_AVX2
void vector_sums_float(const float* r, const float* g, const float* b, const float* vx, const float* vy, std::size_t count,
                       double* phi) {
  vector_sums_impl<float>(r, g, b, vx, vy, count, phi);
}

HEMILIGHT_TARGET_CLONES_AVX2
float texel_sums_float(const float* r, const float* g, const float* b, const float* dist, const std::uint8_t* flags,
                       const float* vz, float* inv, std::size_t count, double* s1) {
  return texel_sums_impl<float>(r, g, b, dist, flags, vz, inv, count, s1);
}

#if HEMILIGHT_INTEGRATE_AVX2
// The AVX2 + FMA kernels (kernels.hpp says what each sums).
namespace {

HEMILIGHT_TARGET_AVX2_FMA inline double hsum(__m256 v) noexcept {
  alignas(32) float lane[8];
  _mm256_store_ps(lane, v);
  double s = 0.0;
  for (float x : lane) s += double(x);
  return s;
}

// extrapolated_wall_inv for eight walls (texels i.. against i + step..; hb, ha: lane masks of
// the neighbours' presence). The same operations (the compiler may fuse a multiply-add here and
// not in the portable path, so the last bit can differ).
HEMILIGHT_TARGET_AVX2_FMA inline __attribute__((always_inline)) __m256 extrapolated8(__m256 ia, __m256 ib, __m256 before,
                                                                                   __m256 after, __m256 hb, __m256 ha) noexcept {
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff)), half = _mm256_set1_ps(0.5f),
               two = _mm256_set1_ps(2.0f);
  const __m256 a_nearer = _mm256_cmp_ps(ia, ib, _CMP_GE_OQ);
  const __m256 near = _mm256_blendv_ps(ib, ia, a_nearer), far = _mm256_blendv_ps(ia, ib, a_nearer);
  const __m256 beside = _mm256_blendv_ps(after, before, a_nearer);
  const __m256 usable = _mm256_and_ps(_mm256_blendv_ps(ha, hb, a_nearer),
                                      _mm256_cmp_ps(_mm256_and_ps(_mm256_sub_ps(near, beside), abs_mask),
                                                    _mm256_and_ps(_mm256_sub_ps(near, far), abs_mask), _CMP_LE_OQ));
  const __m256 e = _mm256_add_ps(near, _mm256_mul_ps(half, _mm256_sub_ps(near, beside)));
  const __m256 lo = _mm256_mul_ps(half, near), hi = _mm256_mul_ps(two, near);
  const __m256 clamped = _mm256_blendv_ps(_mm256_blendv_ps(e, hi, _mm256_cmp_ps(e, hi, _CMP_GT_OQ)), lo,
                                          _mm256_cmp_ps(e, lo, _CMP_LT_OQ));
  return _mm256_blendv_ps(near, clamped, usable);
}

// Lanes of the eight bytes `bits` that have bit `bit` set, as a float mask.
HEMILIGHT_TARGET_AVX2_FMA inline __attribute__((always_inline)) __m256 bit_mask8(__m128i bits, int bit) noexcept {
  const __m128i m = _mm_set1_epi8(static_cast<char>(bit));
  return _mm256_castsi256_ps(_mm256_cvtepi8_epi32(_mm_cmpeq_epi8(_mm_and_si128(bits, m), m)));
}

}  // namespace

template <bool LitMap>
HEMILIGHT_TARGET_AVX2_FMA float texel_pass_avx2(const float* r, const float* g, const float* b, const float* dist,
                                                const std::uint8_t* flags, const float* vx, const float* vy,
                                                const float* vz, float* inv, std::uint8_t* lit, std::size_t* black,
                                                std::size_t count, double* s1, double* phi) noexcept {
  std::size_t black_groups = 0;
  const __m256 one = _mm256_set1_ps(1.0f);
  const __m128i back_bit = _mm_set1_epi8(2);  // texel_back_face
  __m256 min_d = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  std::size_t i = 0;
  for (std::size_t b0 = 0; b0 + 8 <= count; b0 += block) {
    const std::size_t b1 = std::min(count, b0 + block) & ~std::size_t(7);
    __m256 e0 = _mm256_setzero_ps(), e1 = e0, e2 = e0, pt = e0, hs = e0, bk = e0;
    __m256 a0 = e0, a1 = e0, a2 = e0, a3 = e0, a4 = e0, a5 = e0;
    for (i = b0; i < b1; i += 8) {
      const __m256 d = _mm256_loadu_ps(dist + i);
      min_d = _mm256_min_ps(min_d, d);
      const __m256 iv = _mm256_div_ps(one, d);  // 0 for +inf
      _mm256_storeu_ps(inv + i, iv);
      const __m256 p = _mm256_loadu_ps(vz + i), x = _mm256_loadu_ps(vx + i), y = _mm256_loadu_ps(vy + i);
      pt = _mm256_add_ps(pt, p);
      hs = _mm256_fmadd_ps(p, iv, hs);
      // Back-face texels: bytes with bit 1 set, widened to lane masks (most groups have none).
      std::uint64_t eight_flags;
      std::memcpy(&eight_flags, flags + i, 8);
      if (eight_flags & 0x0202020202020202ull) {
        __m128i fl = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(flags + i));
        fl = _mm_cmpeq_epi8(_mm_and_si128(fl, back_bit), back_bit);
        const __m256 is_back = _mm256_castsi256_ps(_mm256_cvtepi8_epi32(fl));
        bk = _mm256_add_ps(bk, _mm256_and_ps(is_back, p));
      }
      const __m256 lr = _mm256_loadu_ps(r + i), lg = _mm256_loadu_ps(g + i), lb = _mm256_loadu_ps(b + i);
      if constexpr (LitMap) {
        // Black groups (every bit of the three channels zero) add exactly nothing below; most of
        // an emission-only hemicube is black, so they skip the sums and tell the wall pass.
        const __m256i any = _mm256_castps_si256(_mm256_or_ps(_mm256_or_ps(lr, lg), lb));
        const bool is_lit = !_mm256_testz_si256(any, any);
        lit[i >> 3] = is_lit;
        if (!is_lit) {
          ++black_groups;
          continue;
        }
      }
      e0 = _mm256_fmadd_ps(lr, p, e0);
      a0 = _mm256_fmadd_ps(lr, x, a0);
      a1 = _mm256_fmadd_ps(lr, y, a1);
      e1 = _mm256_fmadd_ps(lg, p, e1);
      a2 = _mm256_fmadd_ps(lg, x, a2);
      a3 = _mm256_fmadd_ps(lg, y, a3);
      e2 = _mm256_fmadd_ps(lb, p, e2);
      a4 = _mm256_fmadd_ps(lb, x, a4);
      a5 = _mm256_fmadd_ps(lb, y, a5);
    }
    const __m256 sums[12] = {e0, e1, e2, pt, hs, bk, a0, a1, a2, a3, a4, a5};
    for (int k = 0; k < 6; ++k) s1[k] += hsum(sums[k]);
    for (int k = 0; k < 6; ++k) phi[k] += hsum(sums[6 + k]);
  }
  alignas(32) float m[8];
  _mm256_store_ps(m, min_d);
  float md = m[0];
  for (float v : m) md = v < md ? v : md;
  if (LitMap && i < count) lit[i >> 3] = 0;
  for (; i < count; ++i) {  // tail (count is a multiple of 4, not always of 8)
    if (LitMap) lit[i >> 3] |= r[i] != 0.0f || g[i] != 0.0f || b[i] != 0.0f;
    inv[i] = 1.0f / dist[i];
    md = dist[i] < md ? dist[i] : md;
    const double p = vz[i];
    s1[0] += double(r[i]) * p;
    s1[1] += double(g[i]) * p;
    s1[2] += double(b[i]) * p;
    s1[3] += p;
    s1[4] += p * double(inv[i]);
    s1[5] += (flags[i] & 2u) ? p : 0.0;
    phi[0] += double(r[i]) * vx[i];
    phi[1] += double(r[i]) * vy[i];
    phi[2] += double(g[i]) * vx[i];
    phi[3] += double(g[i]) * vy[i];
    phi[4] += double(b[i]) * vx[i];
    phi[5] += double(b[i]) * vy[i];
  }
  if (LitMap) *black = black_groups;
  return md;
}

template <bool CheckLit, bool Extrapolate>
HEMILIGHT_TARGET_AVX2_FMA void wall_pass_avx2(const float* r, const float* g, const float* b, const float* inv,
                                              const std::uint8_t* lit, const float* rx, const float* ry,
                                              const float* ux, const float* uy, std::size_t row,
                                              std::size_t count, float cap, double* acc,
                                              const std::uint8_t* nb) noexcept {
  const std::size_t both = count - row;  // texels with both walls
  const __m256 cp = _mm256_set1_ps(cap);
  std::size_t i = 0;
  for (std::size_t b0 = 0; b0 + 8 <= both; b0 += block) {
    const std::size_t b1 = std::min(both, b0 + block) & ~std::size_t(7);
    __m256 a0 = _mm256_setzero_ps(), a1 = a0, a2 = a0, a3 = a0, a4 = a0, a5 = a0;
    for (i = b0; i < b1; i += 8) {
      // Texels i..i+8 (right walls) and i+row..i+row+7 (upper walls) all black: nothing to add.
      if (CheckLit && !(lit[i >> 3] | lit[(i >> 3) + 1] | lit[(i + row) >> 3] | lit[(i + row + 7) >> 3])) continue;
      const __m256 iv = _mm256_loadu_ps(inv + i);
      __m256 wr, wu;
      if (Extrapolate) {
        const __m128i bits = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(nb + i));
        wr = _mm256_min_ps(extrapolated8(iv, _mm256_loadu_ps(inv + i + 1), _mm256_loadu_ps(inv + i - 1),
                                         _mm256_loadu_ps(inv + i + 2), bit_mask8(bits, 1), bit_mask8(bits, 2)), cp);
        wu = _mm256_min_ps(extrapolated8(iv, _mm256_loadu_ps(inv + i + row), _mm256_loadu_ps(inv + i - row),
                                         _mm256_loadu_ps(inv + i + 2 * row), bit_mask8(bits, 4), bit_mask8(bits, 8)), cp);
      } else {
        wr = _mm256_min_ps(_mm256_max_ps(iv, _mm256_loadu_ps(inv + i + 1)), cp);
        wu = _mm256_min_ps(_mm256_max_ps(iv, _mm256_loadu_ps(inv + i + row)), cp);
      }
      const __m256 wrx = _mm256_mul_ps(_mm256_loadu_ps(rx + i), wr), wry = _mm256_mul_ps(_mm256_loadu_ps(ry + i), wr);
      const __m256 wux = _mm256_mul_ps(_mm256_loadu_ps(ux + i), wu), wuy = _mm256_mul_ps(_mm256_loadu_ps(uy + i), wu);
      __m256 l = _mm256_loadu_ps(r + i);
      __m256 dr = _mm256_sub_ps(_mm256_loadu_ps(r + i + 1), l), du = _mm256_sub_ps(_mm256_loadu_ps(r + i + row), l);
      a0 = _mm256_fmadd_ps(du, wux, _mm256_fmadd_ps(dr, wrx, a0));
      a1 = _mm256_fmadd_ps(du, wuy, _mm256_fmadd_ps(dr, wry, a1));
      l = _mm256_loadu_ps(g + i);
      dr = _mm256_sub_ps(_mm256_loadu_ps(g + i + 1), l);
      du = _mm256_sub_ps(_mm256_loadu_ps(g + i + row), l);
      a2 = _mm256_fmadd_ps(du, wux, _mm256_fmadd_ps(dr, wrx, a2));
      a3 = _mm256_fmadd_ps(du, wuy, _mm256_fmadd_ps(dr, wry, a3));
      l = _mm256_loadu_ps(b + i);
      dr = _mm256_sub_ps(_mm256_loadu_ps(b + i + 1), l);
      du = _mm256_sub_ps(_mm256_loadu_ps(b + i + row), l);
      a4 = _mm256_fmadd_ps(du, wux, _mm256_fmadd_ps(dr, wrx, a4));
      a5 = _mm256_fmadd_ps(du, wuy, _mm256_fmadd_ps(dr, wry, a5));
    }
    const __m256 sums[6] = {a0, a1, a2, a3, a4, a5};
    for (int k = 0; k < 6; ++k) acc[k] += hsum(sums[k]);
  }
  // Tails: the rest of the texels with both walls, then the right walls of the last row.
  const auto wall = [&](std::size_t k, std::size_t step, float cx, float cy) {
    float near_inv = inv[k] > inv[k + step] ? inv[k] : inv[k + step];
    if (Extrapolate) {
      const unsigned before_bit = step == 1 ? 1u : 4u, after_bit = step == 1 ? 2u : 8u;
      near_inv = extrapolated_wall_inv(inv[k], inv[k + step], inv[k - step], inv[k + 2 * step], (nb[k] & before_bit) != 0,
                                       (nb[k] & after_bit) != 0);
    }
    const double w = near_inv < cap ? near_inv : cap;
    const double wx = cx * w, wy = cy * w;
    acc[0] += (double(r[k + step]) - r[k]) * wx;
    acc[1] += (double(r[k + step]) - r[k]) * wy;
    acc[2] += (double(g[k + step]) - g[k]) * wx;
    acc[3] += (double(g[k + step]) - g[k]) * wy;
    acc[4] += (double(b[k + step]) - b[k]) * wx;
    acc[5] += (double(b[k + step]) - b[k]) * wy;
  };
  for (; i < both; ++i) {
    wall(i, 1, rx[i], ry[i]);
    wall(i, row, ux[i], uy[i]);
  }
  for (; i + 1 < count; ++i) wall(i, 1, rx[i], ry[i]);
}

// The builds the integrator calls.
template float texel_pass_avx2<false>(const float*, const float*, const float*, const float*, const std::uint8_t*,
                                      const float*, const float*, const float*, float*, std::uint8_t*, std::size_t*,
                                      std::size_t, double*, double*) noexcept;
template float texel_pass_avx2<true>(const float*, const float*, const float*, const float*, const std::uint8_t*,
                                     const float*, const float*, const float*, float*, std::uint8_t*, std::size_t*,
                                     std::size_t, double*, double*) noexcept;
template void wall_pass_avx2<false, false>(const float*, const float*, const float*, const float*, const std::uint8_t*,
                                           const float*, const float*, const float*, const float*, std::size_t, std::size_t,
                                           float, double*, const std::uint8_t*) noexcept;
template void wall_pass_avx2<false, true>(const float*, const float*, const float*, const float*, const std::uint8_t*,
                                          const float*, const float*, const float*, const float*, std::size_t, std::size_t,
                                          float, double*, const std::uint8_t*) noexcept;
template void wall_pass_avx2<true, false>(const float*, const float*, const float*, const float*, const std::uint8_t*,
                                          const float*, const float*, const float*, const float*, std::size_t, std::size_t,
                                          float, double*, const std::uint8_t*) noexcept;
template void wall_pass_avx2<true, true>(const float*, const float*, const float*, const float*, const std::uint8_t*,
                                         const float*, const float*, const float*, const float*, std::size_t, std::size_t,
                                         float, double*, const std::uint8_t*) noexcept;

// Picked once: both kernels need AVX2 and FMA.
bool cpu_has_avx2_fma() noexcept {
  static const bool yes = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return yes;
}
#endif

}  // namespace hemilight::integrate_detail
