// The integrator's sums over a hemicube's texels and walls (internal, not installed): the portable
// loops the compiler vectorises (templates over the accumulator type, float or double), their
// float builds cloned for AVX2 (kernels.cpp), and the hand-written AVX2 + FMA kernels.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define HEMILIGHT_INTEGRATE_AVX2 1
#define HEMILIGHT_TARGET_AVX2_FMA __attribute__((target("avx2,fma")))
#else
#define HEMILIGHT_INTEGRATE_AVX2 0
#endif

namespace hemilight::integrate_detail {

// Every sum below runs over blocks of at most `block` texels; inside a block it is one SIMD
// reduction in Inner ("#pragma omp simd reduction" lets the compiler split it into vector lanes;
// built with -fopenmp-simd, no OpenMP runtime), and block totals are added in double. With
// Inner = float each result is accurate to about the float rounding of one block, whatever N.
constexpr std::size_t block = 1024;

// Sum over the walls between texel i and i + step of (L_b - L_a) * coefficient * 1 / r_wall, per
// channel and coefficient component, into acc[6]. Hot loop of the integrator. 1 / r_wall is the
// larger of inv[i], inv[i + step], or with Given, inv[i] itself (the walls' own inverse
// distances: extrapolate_wall_depth).
template <class Inner, bool Given = false>
inline __attribute__((always_inline)) void wall_sums_impl(const float* r, const float* g, const float* b, const float* inv,
                                                          const float* cx, const float* cy, std::size_t step,
                                                          std::size_t end, float cap, double* acc) {
  for (std::size_t b0 = 0; b0 < end; b0 += block) {
    const std::size_t b1 = std::min(end, b0 + block);
    Inner a0 = 0, a1 = 0, a2 = 0, a3 = 0, a4 = 0, a5 = 0;
#pragma omp simd reduction(+ : a0, a1, a2, a3, a4, a5)
    for (std::size_t i = b0; i < b1; ++i) {
      const float near_inv = Given ? inv[i] : inv[i] > inv[i + step] ? inv[i] : inv[i + step];
      const Inner w = Inner(near_inv < cap ? near_inv : cap);
      const Inner wx = Inner(cx[i]) * w, wy = Inner(cy[i]) * w;
      const Inner dr = Inner(r[i + step]) - Inner(r[i]), dg = Inner(g[i + step]) - Inner(g[i]),
                  db = Inner(b[i + step]) - Inner(b[i]);
      a0 += dr * wx;
      a1 += dr * wy;
      a2 += dg * wx;
      a3 += dg * wy;
      a4 += db * wx;
      a5 += db * wy;
    }
    const Inner sums[6] = {a0, a1, a2, a3, a4, a5};
    for (int k = 0; k < 6; ++k) acc[k] += double(sums[k]);
  }
}

// The inverse distance of the wall between texels a and b (inv: 1/distance per texel): the
// nearer texel's, extrapolated half a texel towards the wall from its neighbour on the far side
// (`before` of a, `after` of b; has_before / has_after: 1 when it lies in the same face, else 0)
// when that neighbour's depth is closer to it than the other texel's (the wall is the
// discontinuity, not the neighbour), clamped to [1/2, 2] x the centre's. Branch-free, so that
// the loops below vectorise.
inline float extrapolated_wall_inv(float ia, float ib, float before, float after, bool has_before,
                                   bool has_after) noexcept {
  const bool a_nearer = ia >= ib;
  const float near = a_nearer ? ia : ib, far = a_nearer ? ib : ia;
  const float beside = a_nearer ? before : after;
  const bool usable = (a_nearer ? has_before : has_after) && std::fabs(near - beside) <= std::fabs(near - far);
  const float e = near + 0.5f * (near - beside);
  const float clamped = e < 0.5f * near ? 0.5f * near : (e > 2.0f * near ? 2.0f * near : e);
  return usable ? clamped : near;
}

// Inverts the distances and sums pass 1 (E per channel, total projected solid angle, harmonic
// sum, back faces) into s1[6]; returns the min distance. r, g, b: the buffer's radiance planes.
template <class Inner>
inline __attribute__((always_inline)) float texel_sums_impl(const float* r, const float* g, const float* b,
                                                            const float* dist, const std::uint8_t* flags,
                                                            const float* vz, float* inv, std::size_t count, double* s1) {
  float min_d = std::numeric_limits<float>::infinity();
#pragma omp simd reduction(min : min_d)
  for (std::size_t i = 0; i < count; ++i) {
    inv[i] = 1.0f / dist[i];
    min_d = dist[i] < min_d ? dist[i] : min_d;
  }
  for (std::size_t b0 = 0; b0 < count; b0 += block) {
    const std::size_t b1 = std::min(count, b0 + block);
    Inner e0 = 0, e1 = 0, e2 = 0, pt = 0, hs = 0, bk = 0;
#pragma omp simd reduction(+ : e0, e1, e2, pt, hs, bk)
    for (std::size_t i = b0; i < b1; ++i) {
      const Inner p = Inner(vz[i]);
      e0 += Inner(r[i]) * p;
      e1 += Inner(g[i]) * p;
      e2 += Inner(b[i]) * p;
      pt += p;
      hs += p * Inner(inv[i]);
      bk += p * Inner((flags[i] >> 1) & 1u);  // texel_back_face is bit 1
    }
    const Inner sums[6] = {e0, e1, e2, pt, hs, bk};
    for (int k = 0; k < 6; ++k) s1[k] += double(sums[k]);
  }
  // OpenMP starts each lane of a min reduction at the largest float (Clang does; GCC uses +inf),
  // so a hemicube of misses only (all +inf) gives FLT_MAX there. No hit is that far (coordinates
  // are at most 1e18): FLT_MAX means nothing was hit.
  return min_d >= std::numeric_limits<float>::max() ? std::numeric_limits<float>::infinity() : min_d;
}

// The sums of the directional outputs not shared with E and g_r: per channel, L_i times the
// texel's solid angle and its three HL2 weights, into d[12] (channel-major: R Omega, R h0, R h1,
// R h2, G ...).
template <class Inner>
inline __attribute__((always_inline)) void directional_sums_impl(const float* r, const float* g, const float* b,
                                                                 const float* omega, const float* h0, const float* h1,
                                                                 const float* h2, std::size_t count, double* d) {
  for (std::size_t b0 = 0; b0 < count; b0 += block) {
    const std::size_t b1 = std::min(count, b0 + block);
    Inner r0 = 0, r1 = 0, r2 = 0, r3 = 0, g0 = 0, g1 = 0, g2 = 0, g3 = 0, c0 = 0, c1 = 0, c2 = 0, c3 = 0;
#pragma omp simd reduction(+ : r0, r1, r2, r3, g0, g1, g2, g3, c0, c1, c2, c3)
    for (std::size_t i = b0; i < b1; ++i) {
      const Inner w = Inner(omega[i]), k0 = Inner(h0[i]), k1 = Inner(h1[i]), k2 = Inner(h2[i]);
      const Inner lr = Inner(r[i]), lg = Inner(g[i]), lb = Inner(b[i]);
      r0 += lr * w;
      r1 += lr * k0;
      r2 += lr * k1;
      r3 += lr * k2;
      g0 += lg * w;
      g1 += lg * k0;
      g2 += lg * k1;
      g3 += lg * k2;
      c0 += lb * w;
      c1 += lb * k0;
      c2 += lb * k1;
      c3 += lb * k2;
    }
    const Inner sums[12] = {r0, r1, r2, r3, g0, g1, g2, g3, c0, c1, c2, c3};
    for (int k = 0; k < 12; ++k) d[k] += double(sums[k]);
  }
}

// Sums L_i (x, y) of the texels' vector solid angles per channel into phi[6] (for g_r).
template <class Inner>
inline __attribute__((always_inline)) void vector_sums_impl(const float* r, const float* g, const float* b, const float* vx,
                                                            const float* vy, std::size_t count, double* phi) {
  for (std::size_t b0 = 0; b0 < count; b0 += block) {
    const std::size_t b1 = std::min(count, b0 + block);
    Inner a0 = 0, a1 = 0, a2 = 0, a3 = 0, a4 = 0, a5 = 0;
#pragma omp simd reduction(+ : a0, a1, a2, a3, a4, a5)
    for (std::size_t i = b0; i < b1; ++i) {
      const Inner x = Inner(vx[i]), y = Inner(vy[i]);
      a0 += Inner(r[i]) * x;
      a1 += Inner(r[i]) * y;
      a2 += Inner(g[i]) * x;
      a3 += Inner(g[i]) * y;
      a4 += Inner(b[i]) * x;
      a5 += Inner(b[i]) * y;
    }
    const Inner sums[6] = {a0, a1, a2, a3, a4, a5};
    for (int k = 0; k < 6; ++k) phi[k] += double(sums[k]);
  }
}

// wall_inv[i] for the walls between texel i and i + step, i < count - step (nb: the table's
// extrapolation_neighbours; bits `before_bit` and `after_bit` for this direction). inv is padded
// (see the integrator's constructor), so i - step and i + 2 step can be read for every i; where
// they lie outside the face their bit is clear and they are not used.
void extrapolated_walls(const float* inv, const std::uint8_t* nb, std::size_t step, unsigned before_bit, unsigned after_bit,
                        std::size_t count, float* wall_inv);

// The float builds of the sums above. Where the compiler can dispatch at load time (GCC/Clang on
// x86-64 Linux, not under ThreadSanitizer) each is compiled twice, an AVX2 clone and the portable
// SSE2 default, picked by the CPU (the definitions in kernels.cpp carry the attribute); the two
// give the same sums up to the order of float additions inside a block.
float texel_sums_float(const float* r, const float* g, const float* b, const float* dist, const std::uint8_t* flags,
                       const float* vz, float* inv, std::size_t count, double* s1);
void vector_sums_float(const float* r, const float* g, const float* b, const float* vx, const float* vy, std::size_t count,
                       double* phi);
void directional_sums_float(const float* r, const float* g, const float* b, const float* omega, const float* h0,
                            const float* h1, const float* h2, std::size_t count, double* d);
void wall_sums_float(const float* r, const float* g, const float* b, const float* inv, const float* cx, const float* cy,
                     std::size_t step, std::size_t end, float cap, double* acc);
void wall_sums_given_float(const float* r, const float* g, const float* b, const float* wall_inv, const float* cx,
                           const float* cy, std::size_t step, std::size_t end, float cap, double* acc);

#if HEMILIGHT_INTEGRATE_AVX2
// Hand-written AVX2 + FMA kernels for the float path on CPUs that have both (cpu_has_avx2_fma):
// the same sums as texel_sums_impl + vector_sums_impl and wall_sums_impl, in one pass each, with
// every accumulator kept in a register (the compiler's "omp simd" versions spill or cannot
// fuse). Eight texels per step, blocks of `block` texels summed into double like the others; a
// scalar tail. Results equal the portable path up to float rounding order (tested through the
// float-against-double checks). Built for LitMap, CheckLit and Extrapolate true and false.

// Pass 1 with the vector sums: inv[i] = 1 / dist[i]; s1 = (E_r, E_g, E_b, sum P, sum P / r,
// sum P back); phi = per channel (sum L x, sum L y), always (six FMAs per step; the caller
// ignores them without g_r or directional outputs); returns min dist. With LitMap (for the wall
// pass): lit[k] = whether any radiance of texels 8k..8k+7 is non-zero (bitwise; count / 8
// rounded up entries), and black groups (all zero) skip the sums, which they would not change;
// *black = how many groups are black. Without it (no wall pass follows), neither costs anything.
template <bool LitMap>
HEMILIGHT_TARGET_AVX2_FMA float texel_pass_avx2(const float* r, const float* g, const float* b, const float* dist,
                                                const std::uint8_t* flags, const float* vx, const float* vy,
                                                const float* vz, float* inv, std::uint8_t* lit, std::size_t* black,
                                                std::size_t count, double* s1, double* phi) noexcept;

// Both wall passes inside faces (right neighbour i + 1, coefficients rx, ry, over i < count - 1;
// the texel above i + row, coefficients ux, uy, over i < count - row) into acc[6], as
// wall_sums_impl does for each. With CheckLit, lit: texel_pass_avx2's black-group map; a group
// whose texels and right and upper neighbours are all black has zero radiance differences and
// is skipped (it would add exactly +-0 to every sum: the result is the same bits). Without it
// (no black group: a lit hemicube) the test would only cost.
// With Extrapolate, each wall's inverse distance is extrapolated_wall_inv's (nb: the table's
// extrapolation_neighbours; inv must be readable from -row to count + row + 8: the integrator
// pads it with zeros) instead of the larger of the two texels'.
template <bool CheckLit, bool Extrapolate = false>
HEMILIGHT_TARGET_AVX2_FMA void wall_pass_avx2(const float* r, const float* g, const float* b, const float* inv,
                                              const std::uint8_t* lit, const float* rx, const float* ry,
                                              const float* ux, const float* uy, std::size_t row,
                                              std::size_t count, float cap, double* acc,
                                              const std::uint8_t* nb = nullptr) noexcept;

// Whether the CPU has both AVX2 and FMA (asked once).
bool cpu_has_avx2_fma() noexcept;
#endif

}  // namespace hemilight::integrate_detail
