// Cube-map filtering: the fast cosine-power / irradiance filter, its brute-force reference, the
// gloss mapping and mip chains, and 9-coefficient SH irradiance.
#include "hemilight/cubemap.hpp"
#include "hemilight/parallel.hpp"

#include "cubemap_internal.hpp"
#include "../core/table_cache.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#include <xmmintrin.h>
#endif
// The AVX2 + FMA stencil kernel (run-time dispatch); define HEMILIGHT_CUBEMAP_AVX2=0 to build
// only the portable one (how the SSE2 path is tested on AVX2 machines).
#if !defined(HEMILIGHT_CUBEMAP_AVX2)
#if defined(__x86_64__) && defined(__linux__) && (defined(__GNUC__) || defined(__clang__))
#define HEMILIGHT_CUBEMAP_AVX2 1
#else
#define HEMILIGHT_CUBEMAP_AVX2 0
#endif
#endif
#if HEMILIGHT_CUBEMAP_AVX2
#include <immintrin.h>
#endif

namespace hemilight {

namespace cubemap_detail {

face_table::face_table(int size) : n(size), texels(std::size_t(size) * std::size_t(size)) {
  const std::size_t m = std::size_t(size) + 1;
  const double s = 2.0 / size;
  // A(u, v) at the texel corners once; a texel's solid angle is a 2 x 2 difference of them.
  std::vector<double> a(m * m);
  for (std::size_t j = 0; j < m; ++j)
    for (std::size_t i = 0; i < m; ++i) {
      const double u = -1.0 + s * static_cast<double>(i), v = -1.0 + s * static_cast<double>(j);
      a[j * m + i] = std::atan2(u * v, std::sqrt(u * u + v * v + 1.0));
    }
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const std::size_t i = std::size_t(x), j = std::size_t(y);
      const double omega = a[(j + 1) * m + i + 1] - a[j * m + i + 1] - a[(j + 1) * m + i] + a[j * m + i];
      const double u = cubemap_texel_coordinate(size, x, edge_fixup::none);
      const double v = cubemap_texel_coordinate(size, y, edge_fixup::none);
      const double len = std::sqrt(u * u + v * v + 1.0);
      texels[j * std::size_t(size) + i] =
          glm::vec4(static_cast<float>(u / len), static_cast<float>(v / len), static_cast<float>(1.0 / len),
                    static_cast<float>(omega));
    }
}

std::shared_ptr<const face_table> face_table::get(int size) {
  // Kept in the process's table cache (table_cache.hpp: LRU within the budget of memory.hpp).
  return detail::cached_table<face_table>(
      detail::table_kind::cube_face, size, [size] { return std::make_shared<const face_table>(size); },
      [](const face_table& t) { return detail::vector_bytes(t.texels); });
}

}  // namespace cubemap_detail

using namespace cubemap_detail;

namespace {

constexpr double pi = 3.14159265358979323846;

void check_power(const char* fn, float power) {
  if (!std::isfinite(power) || !(power > 0.0f))
    throw_invalid_argument(std::string(fn) + ": specular power " + std::to_string(power) +
                           " is invalid; it must be finite and > 0");
}

void check_output_size(const char* fn, int size) {
  if (size < 1 || size > cubemap_max_size)
    throw_invalid_argument(std::string(fn) + ": output size " + std::to_string(size) + " is outside [1, " +
                           std::to_string(cubemap_max_size) + "]");
}

void check_options(const char* fn, const filter_options& o) {
  const int f = static_cast<int>(o.fixup);
  if (f < 0 || f > 2) throw_invalid_argument(std::string(fn) + ": fixup " + std::to_string(f) + " is not 0, 1 or 2");
  if (!std::isfinite(o.cutoff) || !(o.cutoff > 0.0f) || !(o.cutoff < 1.0f))
    throw_invalid_argument(std::string(fn) + ": cutoff " + std::to_string(o.cutoff) + " is outside (0, 1)");
  if (!std::isfinite(o.texels_per_sigma) || !(o.texels_per_sigma > 0.0f))
    throw_invalid_argument(std::string(fn) + ": texels_per_sigma " + std::to_string(o.texels_per_sigma) +
                           " must be finite and > 0");
  if (o.min_input_size < 1)
    throw_invalid_argument(std::string(fn) + ": min_input_size " + std::to_string(o.min_input_size) + " must be >= 1");
  if (o.irradiance_input_size < 1)
    throw_invalid_argument(std::string(fn) + ": irradiance_input_size " + std::to_string(o.irradiance_input_size) +
                           " must be >= 1");
}

// Level 0 of the input and coarser levels below it (as long as the size stays even), each
// texel with its face-local centre direction and exact solid angle (the shared face table). A
// coarser texel holds the solid-angle-weighted mean of its four children (downsample_cube).
// (Tried and dropped: evaluating coarse texels at their energy centroid; it cut the error at
// texels_per_sigma = 1.5 by a third but cost 1.6x the time, worse than raising texels_per_sigma.)
struct chain_level {
  const cube_image* image = nullptr;
  std::shared_ptr<const face_table> centres;
  // The stencil path's two four-float copies of the image (four_float_copies), built on first
  // use and kept for the next level of a chain that reads the same input level. An input_chain
  // is used by one thread at a time (each call makes its own).
  mutable std::vector<float> four_float;
};

struct input_chain {
  std::vector<cube_image> owned;  // levels 1..
  std::vector<chain_level> levels;
  explicit input_chain(const cube_image& top) {
    owned.reserve(16);
    levels.push_back({&top, face_table::get(top.size), {}});
    while (levels.back().image->size > 1 && levels.back().image->size % 2 == 0) {
      owned.push_back(downsample_cube(*levels.back().image));
      levels.push_back({&owned.back(), face_table::get(owned.back().size), {}});
    }
  }
};

// The weight max(0, d.w)^p as a function of x = 1 - d.w over [0, 1 - cos(theta_max)]: a table
// with linear interpolation for p >= 8 (the relative interpolation error is below 1e-5: the log
// of the weight changes by ln(1/cutoff)/1024 per step), std::pow below (wide lobes, coarse
// levels: few evaluations, and the table would be inaccurate near dot = 0 for p < 1). Past the
// cutoff the table falls linearly to 0 over one step and stays 0, so the tabulated weight needs
// no branch (everything outside the lobe, including dot <= 0, reads 0).
struct lobe {
  static constexpr int steps = 1024;
  float power = 1;
  float cos_max = 0;
  bool cosine = false;  // p == 1: the weight is the dot itself
  bool tabulated = false;
  float inv_step = 0;
  std::vector<float> table;

  lobe(float p, float cutoff) : power(p) {
    cos_max = static_cast<float>(std::pow(static_cast<double>(cutoff), 1.0 / p));
    cosine = p == 1.0f;
    if (p >= 8.0f) {
      tabulated = true;
      const double range = 1.0 - cos_max;
      table.assign(steps + 3, 0.0f);
      for (int i = 0; i <= steps; ++i)
        table[std::size_t(i)] = static_cast<float>(std::pow(1.0 - range * i / steps, static_cast<double>(p)));
      inv_step = static_cast<float>(steps / range);
    }
  }
  float weight(float dot) const noexcept {
    if (cosine) return dot;
    if (!tabulated) return std::pow(dot, power);
    return tabulated_weight(dot);
  }
  float tabulated_weight(float dot) const noexcept {
    const float f = std::min(std::max(0.0f, 1.0f - dot) * inv_step, static_cast<float>(steps + 1));
    const int i = static_cast<int>(f);
    const float t = f - static_cast<float>(i);
    const float* e = table.data() + i;
    return e[0] + t * (e[1] - e[0]);
  }
};

// floor() without a libm call (SSE2 has no rounding instruction). |v| < 2^31.
inline int fast_floor(double v) noexcept {
  const int i = static_cast<int>(v);
  return i - (v < static_cast<double>(i) ? 1 : 0);
}

// The row v of a face crossed by a cap whose boundary is an ellipse (the `ellipse` case of
// cap_range): A u^2 + B u + C >= 0 from (dl.(u, v, 1))^2 >= k (1 + u^2 + v^2), A = qa < 0, between
// the roots (-B -+ sqrt(disc)) / (2 qa), the first the smaller; inv_2qa = 0.5 / qa. The roots are
// clamped to [-2, 2] (near the ellipse's limit qa -> 0 they blow up). False if the row misses it.
inline bool cap_row(double dlx, double dly, double dlz, double k, double qa, double inv_2qa, double v, double& lo,
                    double& hi) noexcept {
  const double e = dlz + v * dly;
  const double qb = 2.0 * dlx * e, qc = e * e - k * (1.0 + v * v);
  const double disc = qb * qb - 4.0 * qa * qc;
  if (disc < 0.0) return false;
  const double root = std::sqrt(disc);
  lo = std::clamp((-qb + root) * inv_2qa, -2.0, 2.0);
  hi = std::clamp((-qb - root) * inv_2qa, -2.0, 2.0);
  return true;
}

// Range of face coordinate (along `c`) covered by the cap {w : d.w >= cos(theta)} on the face with
// local direction components (dc, dr, da) of d. Returns false if the cap misses the face.
bool cap_range(double dc, double da, double s2, double rho, double& lo, double& hi) {
  if (da > 0.0 && da * da > s2) {
    // The cap's boundary is an ellipse on the face plane; its tangent lines u = u0 solve
    // (da^2 - s2) u0^2 - 2 dc da u0 + (dc^2 - s2) = 0 (the dual conic of n n^T - s2 I).
    const double q = da * da - s2;
    const double disc = std::sqrt(std::max(0.0, s2 * (da * da + dc * dc - s2)));
    lo = (dc * da - disc) / q;
    hi = (dc * da + disc) / q;
  } else {
    // The cap reaches the face plane's horizon: bound it by the ball |w - d| <= rho instead.
    // On a face the major component is >= 1/sqrt(3).
    const double a_lo = std::max(da - rho, 0.5773502691896258), a_hi = std::min(da + rho, 1.0);
    if (a_hi < a_lo) return false;
    const double c_lo = std::max(dc - rho, -1.0), c_hi = std::min(dc + rho, 1.0);
    lo = std::min(c_lo / a_lo, c_lo / a_hi);
    hi = std::max(c_hi / a_lo, c_hi / a_hi);
  }
  // Near the ellipse's limit q -> 0 the bounds blow up; keep them where int conversion is safe.
  lo = std::clamp(lo, -2.0, 2.0);
  hi = std::clamp(hi, -2.0, 2.0);
  return hi >= -1.0 && lo <= 1.0;
}

// Running sums of w L per channel and of w for one output texel, w = solid angle * tabulated
// lobe weight: SSE2 vectors (four texels per step) that live across all rows and faces of the
// output texel and are reduced once at the end, plus scalar sums for what is not a multiple of
// four texels. The order of the sums depends only on the output direction, never on threads:
// results are deterministic.
struct row_sums {
#if defined(__SSE2__)
  __m128 a = _mm_setzero_ps(), b = _mm_setzero_ps(), c = _mm_setzero_ps(), w = _mm_setzero_ps();
#endif
  float s[5] = {0, 0, 0, 0, 0};  // R, G, B, A, weight

  // Adds texels xa..xb of one row (`row`: face-local directions and solid angles, `px`: pixels).
  void add(const lobe& lb, const glm::vec3& dl, const glm::vec4* row, const float* px, std::size_t ch, int xa,
           int xb) noexcept {
    int x = xa;
#if defined(__SSE2__)
    const __m128 dx = _mm_set1_ps(dl.x), dy = _mm_set1_ps(dl.y), dz = _mm_set1_ps(dl.z);
    const __m128 one = _mm_set1_ps(1.0f), zero = _mm_setzero_ps(), inv = _mm_set1_ps(lb.inv_step);
    const __m128 top = _mm_set1_ps(static_cast<float>(lobe::steps + 1));
    const float* tab = lb.table.data();
    alignas(16) int idx[4];
    for (; x + 3 <= xb; x += 4) {
      __m128 tx = _mm_loadu_ps(&row[x].x), ty = _mm_loadu_ps(&row[x + 1].x);
      __m128 tz = _mm_loadu_ps(&row[x + 2].x), tw = _mm_loadu_ps(&row[x + 3].x);
      _MM_TRANSPOSE4_PS(tx, ty, tz, tw);  // now x, y, z, solid angle of the four texels
      const __m128 dot = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, tx), _mm_mul_ps(dy, ty)), _mm_mul_ps(dz, tz));
      const __m128 f = _mm_min_ps(_mm_mul_ps(_mm_max_ps(zero, _mm_sub_ps(one, dot)), inv), top);
      const __m128i fi = _mm_cvttps_epi32(f);
      const __m128 t = _mm_sub_ps(f, _mm_cvtepi32_ps(fi));
      _mm_store_si128(reinterpret_cast<__m128i*>(idx), fi);
      const __m128 e0 = _mm_setr_ps(tab[idx[0]], tab[idx[1]], tab[idx[2]], tab[idx[3]]);
      const __m128 e1 = _mm_setr_ps(tab[idx[0] + 1], tab[idx[1] + 1], tab[idx[2] + 1], tab[idx[3] + 1]);
      const __m128 wt = _mm_mul_ps(tw, _mm_add_ps(e0, _mm_mul_ps(t, _mm_sub_ps(e1, e0))));
      w = _mm_add_ps(w, wt);
      const float* p = px + std::size_t(x) * ch;
      if (ch == 3) {
        // 12 floats r0 g0 b0 r1 | g1 b1 r2 g2 | b2 r3 g3 b3 times w0 w0 w0 w1 | w1 w1 w2 w2 | w2 w3 w3 w3
        a = _mm_add_ps(a, _mm_mul_ps(_mm_loadu_ps(p), _mm_shuffle_ps(wt, wt, _MM_SHUFFLE(1, 0, 0, 0))));
        b = _mm_add_ps(b, _mm_mul_ps(_mm_loadu_ps(p + 4), _mm_shuffle_ps(wt, wt, _MM_SHUFFLE(2, 2, 1, 1))));
        c = _mm_add_ps(c, _mm_mul_ps(_mm_loadu_ps(p + 8), _mm_shuffle_ps(wt, wt, _MM_SHUFFLE(3, 3, 3, 2))));
      } else {
        a = _mm_add_ps(a, _mm_mul_ps(_mm_loadu_ps(p), _mm_shuffle_ps(wt, wt, _MM_SHUFFLE(0, 0, 0, 0))));
        b = _mm_add_ps(b, _mm_mul_ps(_mm_loadu_ps(p + 4), _mm_shuffle_ps(wt, wt, _MM_SHUFFLE(1, 1, 1, 1))));
        c = _mm_add_ps(c, _mm_mul_ps(_mm_loadu_ps(p + 8), _mm_shuffle_ps(wt, wt, _MM_SHUFFLE(2, 2, 2, 2))));
        a = _mm_add_ps(a, _mm_mul_ps(_mm_loadu_ps(p + 12), _mm_shuffle_ps(wt, wt, _MM_SHUFFLE(3, 3, 3, 3))));
      }
    }
#endif
    for (; x <= xb; ++x) {
      const glm::vec4& t = row[x];
      const float wt = t.w * lb.tabulated_weight(dl.x * t.x + dl.y * t.y + dl.z * t.z);
      const float* p = px + std::size_t(x) * ch;
      for (std::size_t k = 0; k < ch; ++k) s[k] += wt * p[k];
      s[4] += wt;
    }
  }

  // Channel sums (R, G, B, A) and the weight sum.
  void total(std::size_t ch, double out[5]) const noexcept {
    for (int k = 0; k < 5; ++k) out[k] = s[k];
#if defined(__SSE2__)
    alignas(16) float va[4], vb[4], vc[4], vw[4];
    _mm_store_ps(va, a);
    _mm_store_ps(vb, b);
    _mm_store_ps(vc, c);
    _mm_store_ps(vw, w);
    if (ch == 3) {
      out[0] += double(va[0]) + va[3] + vb[2] + vc[1];
      out[1] += double(va[1]) + vb[0] + vb[3] + vc[2];
      out[2] += double(va[2]) + vb[1] + vc[0] + vc[3];
    } else {
      for (int k = 0; k < 4; ++k) out[k] += double(va[k]) + vb[k] + vc[k];
    }
    out[4] += (double(vw[0]) + vw[1]) + (double(vw[2]) + vw[3]);
#else
    (void)ch;
#endif
  }
};

// The filtered value along unit direction d over one input level.
glm::dvec4 filter_direction(const chain_level& level, const lobe& lb, const glm::vec3& d) {
  const cube_image& in = *level.image;
  const int n = in.size;
  const std::size_t ch = std::size_t(in.channels);
  const double cos_max = lb.cos_max;
  const double s2 = std::max(0.0, 1.0 - cos_max * cos_max);
  const double rho = std::sqrt(std::max(0.0, 2.0 - 2.0 * cos_max));  // chord = 2 sin(theta / 2)
  double acc[4] = {0, 0, 0, 0}, wsum = 0;
  row_sums sums;  // the tabulated lobes' running sums
  for (int f = 0; f < 6; ++f) {
    const face_frame& fr = frame_of(f);
    const glm::vec3 dl(glm::dot(d, fr.column), glm::dot(d, fr.row), glm::dot(d, fr.axis));
    double u0, u1, v0, v1;
    if (!cap_range(dl.x, dl.z, s2, rho, u0, u1) || !cap_range(dl.y, dl.z, s2, rho, v0, v1)) continue;
    const double h = 0.5 * n;
    // One texel of margin against rounding.
    const int x0 = std::clamp(static_cast<int>(std::floor((u0 + 1.0) * h)) - 1, 0, n - 1);
    const int x1 = std::clamp(static_cast<int>(std::floor((u1 + 1.0) * h)) + 1, 0, n - 1);
    const int y0 = std::clamp(static_cast<int>(std::floor((v0 + 1.0) * h)) - 1, 0, n - 1);
    const int y1 = std::clamp(static_cast<int>(std::floor((v1 + 1.0) * h)) + 1, 0, n - 1);
    const glm::vec4* face_texels = level.centres->texels.data();
    const bool ellipse = dl.z > 0.0f && static_cast<double>(dl.z) * dl.z > s2;
    const double k = cos_max * cos_max;
    const double qa = static_cast<double>(dl.x) * dl.x - k;  // < 0 when `ellipse`
    const double inv_2qa = ellipse ? 0.5 / qa : 0.0;
    for (int y = y0; y <= y1; ++y) {
      int xa = x0, xb = x1;
      if (ellipse) {
        // This row's span of the cap: A u^2 + B u + C >= 0 from (d.(u, v, 1))^2 >= k (1 + u^2 + v^2),
        // A < 0 in the ellipse case. Texel centres u = (2x + 1)/n - 1 between the roots; no margin
        // is needed: a centre that rounding puts on the wrong side has a weight of ~cutoff.
        const double v = (2.0 * y + 1.0) / n - 1.0;
        double r_lo, r_hi;
        if (!cap_row(dl.x, dl.y, dl.z, k, qa, inv_2qa, v, r_lo, r_hi)) continue;
        xa = std::max(x0, fast_floor((r_lo + 1.0) * h - 0.5) + 1);
        xb = std::min(x1, fast_floor((r_hi + 1.0) * h - 0.5));
        if (xb < xa) continue;
      }
      const glm::vec4* row = face_texels + std::size_t(y) * std::size_t(n);
      const float* px = in.at(f, 0, y);
      if (lb.tabulated) {
        // Pad the span to a multiple of four texels (inside the face) so the SIMD loop has no
        // scalar tail: texels outside the cap read weight 0 from the table, so this only costs.
        const int padded = (xb - xa + 4) / 4 * 4;
        if (padded <= n) {
          xb = std::min(n - 1, xa + padded - 1);
          xa = xb - padded + 1;
        }
        sums.add(lb, dl, row, px, ch, xa, xb);
        continue;
      }
      const float cmax = lb.cos_max;
      for (int x = xa; x <= xb; ++x) {
        const glm::vec4& t = row[x];
        const float dot = dl.x * t.x + dl.y * t.y + dl.z * t.z;
        if (!(dot > cmax) || !(dot > 0.0f)) continue;
        const double w = static_cast<double>(t.w * lb.weight(dot));
        const float* p = px + std::size_t(x) * ch;
        for (std::size_t c = 0; c < ch; ++c) acc[c] += w * static_cast<double>(p[c]);
        wsum += w;
      }
    }
  }
  if (lb.tabulated) {
    double t[5];
    sums.total(ch, t);
    for (std::size_t c = 0; c < 4; ++c) acc[c] += t[c];
    wsum += t[4];
  }
  if (!(wsum > 0.0)) {
    // The lobe is narrower than the input's texels and no texel centre falls inside it: the
    // integral of the piecewise-constant input against it is the texel that contains d.
    const cube_coord cc = cube_face_from_direction(d);
    const int x = std::clamp(static_cast<int>(cc.s * static_cast<float>(n)), 0, n - 1);
    const int y = std::clamp(static_cast<int>(cc.t * static_cast<float>(n)), 0, n - 1);
    const float* p = in.at(static_cast<int>(cc.face), x, y);
    return glm::dvec4(p[0], p[1], p[2], ch == 4 ? p[3] : 1.0f);
  }
  return glm::dvec4(acc[0], acc[1], acc[2], ch == 4 ? acc[3] : wsum) / wsum;  // RGB alpha: 1
}

// Picks the input level for a lobe of power p.
const chain_level& pick_level(const input_chain& chain, float power, bool irradiance, const filter_options& o) {
  const double need =
      irradiance ? static_cast<double>(o.irradiance_input_size)
                 : std::max(2.0 * static_cast<double>(o.texels_per_sigma) * std::sqrt(static_cast<double>(power)),
                            static_cast<double>(o.min_input_size));
  const chain_level* best = &chain.levels[0];
  for (const chain_level& l : chain.levels)
    if (static_cast<double>(l.image->size) >= need) best = &l;
  return *best;
}

// ---------------------------------------------------------------------------------------------
// Precomputed weight stencils (the default path of filter_chain).
//
// The weight of input texel w for output texel d, solid_angle(w) max(0, d.w)^p, depends only on
// the two texels' places on their grids. The cube has 48 symmetries (signed permutations of the
// axes: 6 faces x 8 in-face symmetries) that map the input grid onto itself and, for every
// mapping (texel centres, stretch, warp: all mirror-symmetric and the same along u and v), the
// output grid onto itself. So the weights are computed once, in double with std::pow, for the
// output texels of one eighth of one face (the fundamental domain) and applied to all 48 images
// of it: out(M d) = sum_w W(d, w) L(M w). What is left per tap is a load and a multiply-add.

// (M w)_i = sign_i w_perm(i): one of the 48 symmetries of the cube.
struct axis_symmetry {
  int perm[3];
  float sign[3];
  glm::vec3 apply(const glm::vec3& w) const noexcept {
    return {sign[0] * w[perm[0]], sign[1] * w[perm[1]], sign[2] * w[perm[2]]};
  }
};

const std::array<axis_symmetry, 48>& cube_symmetries() {
  static const std::array<axis_symmetry, 48> all = [] {
    std::array<axis_symmetry, 48> s{};
    static constexpr int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int k = 0;
    for (const auto& p : perms)
      for (int signs = 0; signs < 8; ++signs) {
        axis_symmetry& m = s[std::size_t(k++)];
        for (int i = 0; i < 3; ++i) {
          m.perm[i] = p[i];
          m.sign[i] = (signs >> i) & 1 ? -1.0f : 1.0f;
        }
      }
    return s;
  }();
  return all;
}

// Where texel (x, y) of face f of an n x n cube grid goes under a symmetry: texel index (face-major,
// rows, columns) origin + x dx + y dy, in copy `copy` of the grid (0: as stored, 1: each face
// transposed; map_face picks the copy in which x moves along a row when contiguous_runs is set).
struct face_map {
  std::ptrdiff_t origin = 0, dx = 0, dy = 0;
  int copy = 0;
};

face_map map_face(const axis_symmetry& m, int f, int n, bool contiguous_runs = false) {
  const face_frame& fr = frame_of(f);
  const glm::vec3 a = m.apply(fr.axis), c = m.apply(fr.column), r = m.apply(fr.row);
  int f2 = 0;
  while (f2 < 5 && frame_of(f2).axis != a) ++f2;  // exact: the frames' components are 0 and +-1
  const face_frame& g = frame_of(f2);
  // u' = cu u + ru v, v' = cv u + rv v; each coefficient is 0 or +-1, and u -> -u is x -> n - 1 - x
  // for every mapping (cubemap_texel_coordinate mirrors the upper half).
  const int cu = static_cast<int>(glm::dot(c, g.column)), ru = static_cast<int>(glm::dot(r, g.column));
  const int cv = static_cast<int>(glm::dot(c, g.row)), rv = static_cast<int>(glm::dot(r, g.row));
  const std::ptrdiff_t nn = n, ox = (cu < 0 || ru < 0) ? nn - 1 : 0, oy = (cv < 0 || rv < 0) ? nn - 1 : 0;
  face_map fm;
  if (contiguous_runs && cu == 0 && n > 1) {
    // x (the canonical run direction) moves along a column: read the transposed copy, where
    // texel (X, Y) of a face is at index X n + Y, so that the run is consecutive in memory.
    fm.origin = std::ptrdiff_t(f2) * nn * nn + ox * nn + oy;
    fm.dx = cv;
    fm.dy = ru * nn;
    fm.copy = 1;
    return fm;
  }
  fm.origin = std::ptrdiff_t(f2) * nn * nn + oy * nn + ox;
  fm.dx = cv * nn + cu;
  fm.dy = rv * nn + ru;
  return fm;
}

// One run of consecutive texels along a row of a canonical input face, and its weights.
struct stencil_run {
  std::int32_t face, y, x0, count;
};

// The runs of one canonical face: runs[begin, end).
struct stencil_face {
  std::int32_t face, begin, end;
};

// The normalised weights of one output texel of the fundamental domain.
struct stencil {
  std::vector<stencil_run> runs;
  std::vector<stencil_face> faces;
  std::vector<float> weights;  // run after run
  double norm = 1;             // 1 / (sum of the float weights): constant input stays constant
};

// Input texel directions (face-local) and exact solid angles in double, per size: texel (x, y)
// points along (coord[x], coord[y], 1) inv_len[y n + x].
struct double_table {
  std::vector<double> coord, inv_len, omega;
  explicit double_table(const face_table& t)
      : coord(std::size_t(t.n)), inv_len(t.texels.size()), omega(t.texels.size()) {
    const int n = t.n;
    for (int x = 0; x < n; ++x) coord[std::size_t(x)] = cubemap_texel_coordinate(n, x, edge_fixup::none);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const std::size_t i = std::size_t(y) * std::size_t(n) + std::size_t(x);
        const double u = coord[std::size_t(x)], v = coord[std::size_t(y)];
        inv_len[i] = 1.0 / std::sqrt(u * u + v * v + 1.0);
        omega[i] = static_cast<double>(t.texels[i].w);
      }
  }
};

// Builds the stencil of unit direction d (face-local frames of the canonical faces) over `level`.
// dot^p for dot in (cos_max, 1]: std::pow for p < 8, else a table of (1 - x)^p over
// x = 1 - dot in [0, 1 - cos_max] with linear interpolation in double. The log of the weight
// changes by ln(1/cutoff)/steps per step, so the relative interpolation error is below
// (ln(1/cutoff)/steps)^2/8: 2e-7 for the cutoff 1e-4 (3e-7 for 1e-5), far below float rounding
// of the sums that use it, and 1/20 of the cost of std::pow.
struct lobe_power {
  static constexpr int steps = 8192;
  double power, inv_step = 0;
  bool cosine, tabulated;
  std::vector<double> table;
  lobe_power(double p, double cos_max) : power(p), cosine(p == 1.0), tabulated(p >= 8.0) {
    if (!tabulated) return;
    const double range = 1.0 - cos_max;
    table.resize(steps + 2);
    for (int i = 0; i <= steps + 1; ++i) table[std::size_t(i)] = std::pow(std::max(0.0, 1.0 - range * i / steps), p);
    inv_step = steps / range;
  }
  double operator()(double dot) const noexcept {
    if (cosine) return dot;
    if (!tabulated) return std::pow(dot, power);
    const double f = std::min((1.0 - dot) * inv_step, static_cast<double>(steps));
    const int i = static_cast<int>(f);
    const double t = f - i;
    return table[std::size_t(i)] + t * (table[std::size_t(i) + 1] - table[std::size_t(i)]);
  }
};

// The weights of `count` consecutive texels of one input row (texel i: face coordinate
// coord[i], 1/|(u, v, 1)| inv_len[i], solid angle omega[i]) for the face-local lobe direction with
// components (dlx, cy = dly v + dlz): omega lobe(dot) where dot > cos_max, else 0. Returns their sum.
double row_weights(const lobe_power& lobe, double cos_max, double dlx, double cy, const double* coord,
                   const double* inv_len, const double* omega, int count, double* out) noexcept {
  double total = 0;
  for (int i = 0; i < count; ++i) {
    const double dot = (dlx * coord[i] + cy) * inv_len[i];
    out[i] = dot > cos_max && dot > 0.0 ? omega[i] * lobe(dot) : 0.0;
    total += out[i];
  }
  return total;
}

#if HEMILIGHT_CUBEMAP_AVX2
// The same for a tabulated lobe, four texels at a time (AVX2 + FMA, the table read by gathers):
// equal to the portable one to double rounding. cos_max >= 0, so dot > cos_max implies dot > 0.
__attribute__((target("avx2,fma"))) double row_weights_avx2(const lobe_power& lobe, double cos_max, double dlx,
                                                             double cy, const double* coord, const double* inv_len,
                                                             const double* omega, int count, double* out) noexcept {
  const __m256d vdlx = _mm256_set1_pd(dlx), vcy = _mm256_set1_pd(cy), one = _mm256_set1_pd(1.0);
  const __m256d inv = _mm256_set1_pd(lobe.inv_step), top = _mm256_set1_pd(static_cast<double>(lobe_power::steps));
  const __m256d cmax = _mm256_set1_pd(cos_max), zero = _mm256_setzero_pd();
  const __m256d all = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  const double* table = lobe.table.data();
  __m256d sum = _mm256_setzero_pd();
  int i = 0;
  for (; i + 3 < count; i += 4) {
    const __m256d dot =
        _mm256_mul_pd(_mm256_fmadd_pd(vdlx, _mm256_loadu_pd(coord + i), vcy), _mm256_loadu_pd(inv_len + i));
    const __m256d f = _mm256_min_pd(_mm256_mul_pd(_mm256_sub_pd(one, dot), inv), top);
    const __m128i k = _mm256_cvttpd_epi32(f);
    const __m256d t = _mm256_sub_pd(f, _mm256_cvtepi32_pd(k));
    // (the masked form: GCC 12 warns about the unmasked one's undefined source operand)
    const __m256d e0 = _mm256_mask_i32gather_pd(zero, table, k, all, 8);
    const __m256d e1 = _mm256_mask_i32gather_pd(zero, table + 1, k, all, 8);
    const __m256d lobe_w = _mm256_fmadd_pd(t, _mm256_sub_pd(e1, e0), e0);
    const __m256d w = _mm256_and_pd(_mm256_mul_pd(_mm256_loadu_pd(omega + i), lobe_w),
                                    _mm256_cmp_pd(dot, cmax, _CMP_GT_OQ));
    _mm256_storeu_pd(out + i, w);
    sum = _mm256_add_pd(sum, w);
  }
  alignas(32) double lanes[4];
  _mm256_store_pd(lanes, sum);
  return (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) +
         row_weights(lobe, cos_max, dlx, cy, coord + i, inv_len + i, omega + i, count - i, out + i);
}
#endif

void build_stencil(const double_table& tab, int n, const lobe_power& lobe, double cos_max, const glm::dvec3& d,
                   stencil& s) {
  s.runs.clear();
  s.faces.clear();
  s.weights.clear();
  const double s2 = std::max(0.0, 1.0 - cos_max * cos_max);
  const double rho = std::sqrt(std::max(0.0, 2.0 - 2.0 * cos_max));
  const double k = cos_max * cos_max;
  const double h = 0.5 * n;
  double total = 0;
  static thread_local std::vector<double> row_w;  // one row's weights
#if HEMILIGHT_CUBEMAP_AVX2
  static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
  constexpr bool avx2 = false;
  constexpr auto row_weights_avx2 = row_weights;
#endif
  for (int f = 0; f < 6; ++f) {
    const face_frame& fr = frame_of(f);
    const glm::dvec3 dl(glm::dot(d, glm::dvec3(fr.column)), glm::dot(d, glm::dvec3(fr.row)),
                        glm::dot(d, glm::dvec3(fr.axis)));
    double u0, u1, v0, v1;
    if (!cap_range(dl.x, dl.z, s2, rho, u0, u1) || !cap_range(dl.y, dl.z, s2, rho, v0, v1)) continue;
    const int x0 = std::clamp(static_cast<int>(std::floor((u0 + 1.0) * h)) - 1, 0, n - 1);
    const int x1 = std::clamp(static_cast<int>(std::floor((u1 + 1.0) * h)) + 1, 0, n - 1);
    const int y0 = std::clamp(static_cast<int>(std::floor((v0 + 1.0) * h)) - 1, 0, n - 1);
    const int y1 = std::clamp(static_cast<int>(std::floor((v1 + 1.0) * h)) + 1, 0, n - 1);
    const bool ellipse = dl.z > 0.0 && dl.z * dl.z > s2;
    const double qa = dl.x * dl.x - k;
    for (int y = y0; y <= y1; ++y) {
      int xa = x0, xb = x1;
      if (ellipse && qa < 0.0) {
        // the row's span of the cap (as filter_direction), widened by one texel each side: the
        // weights below decide exactly which texels count
        const double v = (2.0 * y + 1.0) / n - 1.0;
        double r_lo, r_hi;
        if (!cap_row(dl.x, dl.y, dl.z, k, qa, 0.5 / qa, v, r_lo, r_hi)) continue;
        xa = std::max(x0, fast_floor((r_lo + 1.0) * h - 0.5));
        xb = std::min(x1, fast_floor((r_hi + 1.0) * h - 0.5) + 1);
        if (xb < xa) continue;
      }
      // The weights of the span, then the run from the first to the last nonzero one.
      row_w.resize(std::size_t(xb - xa + 1));
      const std::size_t row = std::size_t(y) * std::size_t(n) + std::size_t(xa);
      const double cy = dl.y * tab.coord[std::size_t(y)] + dl.z;
      const double row_total =
          (avx2 && lobe.tabulated ? row_weights_avx2 : row_weights)(lobe, cos_max, dl.x, cy, tab.coord.data() + xa,
                                                                     tab.inv_len.data() + row, tab.omega.data() + row,
                                                                     xb - xa + 1, row_w.data());
      if (!(row_total > 0.0)) continue;
      total += row_total;  // the weights outside [first, last] are 0
      int first = xa, last = xb;
      while (!(row_w[std::size_t(first - xa)] > 0.0)) ++first;
      while (!(row_w[std::size_t(last - xa)] > 0.0)) --last;
      // Pad the run with zero weights to a multiple of four texels, inside the face's row, so the
      // SIMD loop has no tail (a zero weight times a finite texel adds nothing).
      int lo = first, hi = last;
      const int padded = (last - first + 4) / 4 * 4;
      if (padded <= n) {
        hi = std::min(n - 1, first + padded - 1);
        lo = hi - padded + 1;
      }
      s.runs.push_back({f, y, lo, hi - lo + 1});
      const std::size_t at = s.weights.size();
      s.weights.resize(at + std::size_t(hi - lo + 1));
      float* out = s.weights.data() + at;
      std::fill(out, out + (first - lo), 0.0f);
      const double* src = row_w.data() + (first - xa);
      for (int i = 0; i <= last - first; ++i) out[first - lo + i] = static_cast<float>(src[i]);
      std::fill(out + (last - lo + 1), out + (hi - lo + 1), 0.0f);
    }
  }
  if (!(total > 0.0)) {
    // The lobe is narrower than the input's texels and no texel centre falls inside it: the
    // texel that contains d (as filter_direction).
    s.runs.clear();
    s.weights.clear();
    const glm::vec3 df(d);
    const cube_coord cc = cube_face_from_direction(df);
    const int x = std::clamp(static_cast<int>(cc.s * static_cast<float>(n)), 0, n - 1);
    const int y = std::clamp(static_cast<int>(cc.t * static_cast<float>(n)), 0, n - 1);
    s.runs.push_back({static_cast<std::int32_t>(cc.face), y, x, 1});
    s.faces.push_back({static_cast<std::int32_t>(cc.face), 0, 1});
    s.weights.push_back(1.0f);
    s.norm = 1.0;
    return;
  }
  for (std::size_t i = 0; i < s.runs.size(); ++i) {
    if (s.faces.empty() || s.faces.back().face != s.runs[i].face)
      s.faces.push_back({s.runs[i].face, static_cast<std::int32_t>(i), static_cast<std::int32_t>(i)});
    s.faces.back().end = static_cast<std::int32_t>(i + 1);
  }
  // Normalise in double, then make the float weights' own sum exactly what the output divides by.
  // (four partial sums: one chain of dependent additions per tap was a tenth of the build time)
  double fsum[4] = {0, 0, 0, 0};
  const double inv_total = 1.0 / total;
  const std::size_t count = s.weights.size();
  float* w = s.weights.data();
  std::size_t i = 0;
  for (; i + 3 < count; i += 4)
    for (std::size_t j = 0; j < 4; ++j) {
      w[i + j] = static_cast<float>(static_cast<double>(w[i + j]) * inv_total);
      fsum[j] += static_cast<double>(w[i + j]);
    }
  for (; i < count; ++i) {
    w[i] = static_cast<float>(static_cast<double>(w[i]) * inv_total);
    fsum[0] += static_cast<double>(w[i]);
  }
  s.norm = 1.0 / ((fsum[0] + fsum[1]) + (fsum[2] + fsum[3]));
}

// Applies a stencil to the image of its output texel under one symmetry (`maps`: the symmetry's
// map of each canonical input face) on four-float texels (`px4`: the two copies of
// four_float_copies, RGBA or RGB and a zero). Float sums within a face, double across faces. A
// run's texels are consecutive in memory, forwards or backwards (faces of one texel aside);
// runs are padded to multiples of four texels where the face is wide enough.
void apply_stencil_portable(const stencil& s, const face_map* maps, const float* const* px4, double out[4]) noexcept {
  const float* w = s.weights.data();
  for (int c = 0; c < 4; ++c) out[c] = 0.0;
  for (const stencil_face& sf : s.faces) {
    const face_map& m = maps[sf.face];
    const float* base = px4[m.copy] + m.origin * 4;
    const std::ptrdiff_t step = m.dx * 4, row = m.dy * 4;
#if defined(__SSE2__)
    __m128 a0 = _mm_setzero_ps(), a1 = _mm_setzero_ps();
    for (std::int32_t i = sf.begin; i < sf.end; ++i) {
      const stencil_run& r = s.runs[std::size_t(i)];
      const float* p = base + std::ptrdiff_t(r.x0) * step + std::ptrdiff_t(r.y) * row;
      int k = 0;
      for (; k + 1 < r.count; k += 2, p += 2 * step) {
        a0 = _mm_add_ps(a0, _mm_mul_ps(_mm_set1_ps(w[k]), _mm_loadu_ps(p)));
        a1 = _mm_add_ps(a1, _mm_mul_ps(_mm_set1_ps(w[k + 1]), _mm_loadu_ps(p + step)));
      }
      if (k < r.count) a0 = _mm_add_ps(a0, _mm_mul_ps(_mm_set1_ps(w[k]), _mm_loadu_ps(p)));
      w += r.count;
    }
    alignas(16) float a[4];
    _mm_store_ps(a, _mm_add_ps(a0, a1));
#else
    float a[4] = {0, 0, 0, 0};
    for (std::int32_t i = sf.begin; i < sf.end; ++i) {
      const stencil_run& r = s.runs[std::size_t(i)];
      const float* p = base + std::ptrdiff_t(r.x0) * step + std::ptrdiff_t(r.y) * row;
      for (int k = 0; k < r.count; ++k, p += step)
        for (int c = 0; c < 4; ++c) a[c] += w[k] * p[c];
      w += r.count;
    }
#endif
    for (int c = 0; c < 4; ++c) out[c] += static_cast<double>(a[c]);
  }
}

#if HEMILIGHT_CUBEMAP_AVX2
// The same with AVX2 + FMA (picked at run time when the CPU has them). A run is consecutive
// texels, forwards or backwards (map_face with contiguous runs): one 256-bit load reads two
// texels, and the weight vector (w_k x 4 | w_k+1 x 4) comes from one 128-bit broadcast of four
// weights and an in-lane permute; four 256-bit partial sums. Sums differ from the portable path
// only in float rounding (fused multiply-adds, another order of the additions).
__attribute__((target("avx2,fma"))) void apply_stencil_avx2(const stencil& s, const face_map* maps,
                                                             const float* const* px4, double out[4]) noexcept {
  const float* w = s.weights.data();
  __m256d acc = _mm256_setzero_pd();
  for (const stencil_face& sf : s.faces) {
    const face_map& m = maps[sf.face];
    const float* base = px4[m.copy] + m.origin * 4;
    const std::ptrdiff_t step = m.dx * 4, row = m.dy * 4;
    __m256 a0 = _mm256_setzero_ps(), a1 = _mm256_setzero_ps(), a2 = _mm256_setzero_ps(), a3 = _mm256_setzero_ps();
    __m128 t = _mm_setzero_ps();
    if (m.dx == 1 || m.dx == -1) {
      // Forwards, a 256-bit load at tap k's texel holds taps (k | k + 1); backwards, the load one
      // texel lower holds (k + 1 | k): pick the weights to match.
      const bool back = m.dx < 0;
      const __m256i lo = back ? _mm256_setr_epi32(1, 1, 1, 1, 0, 0, 0, 0) : _mm256_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1);
      const __m256i hi = back ? _mm256_setr_epi32(3, 3, 3, 3, 2, 2, 2, 2) : _mm256_setr_epi32(2, 2, 2, 2, 3, 3, 3, 3);
      const std::ptrdiff_t pair = back ? -4 : 0;
      for (std::int32_t i = sf.begin; i < sf.end; ++i) {
        const stencil_run& r = s.runs[std::size_t(i)];
        const float* p = base + std::ptrdiff_t(r.x0) * step + std::ptrdiff_t(r.y) * row;
        int k = 0;
        for (; k + 7 < r.count; k += 8, p += 8 * step) {
          const __m256 w0 = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(w + k));
          const __m256 w1 = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(w + k + 4));
          a0 = _mm256_fmadd_ps(_mm256_permutevar_ps(w0, lo), _mm256_loadu_ps(p + pair), a0);
          a1 = _mm256_fmadd_ps(_mm256_permutevar_ps(w0, hi), _mm256_loadu_ps(p + pair + 2 * step), a1);
          a2 = _mm256_fmadd_ps(_mm256_permutevar_ps(w1, lo), _mm256_loadu_ps(p + pair + 4 * step), a2);
          a3 = _mm256_fmadd_ps(_mm256_permutevar_ps(w1, hi), _mm256_loadu_ps(p + pair + 6 * step), a3);
        }
        if (k + 3 < r.count) {
          const __m256 w0 = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(w + k));
          a0 = _mm256_fmadd_ps(_mm256_permutevar_ps(w0, lo), _mm256_loadu_ps(p + pair), a0);
          a1 = _mm256_fmadd_ps(_mm256_permutevar_ps(w0, hi), _mm256_loadu_ps(p + pair + 2 * step), a1);
          k += 4;
          p += 4 * step;
        }
        for (; k < r.count; ++k, p += step) t = _mm_fmadd_ps(_mm_broadcast_ss(w + k), _mm_loadu_ps(p), t);
        w += r.count;
      }
    } else {
      // a face of one texel (n = 1): no run has more than one texel
      for (std::int32_t i = sf.begin; i < sf.end; ++i) {
        const stencil_run& r = s.runs[std::size_t(i)];
        const float* p = base + std::ptrdiff_t(r.x0) * step + std::ptrdiff_t(r.y) * row;
        for (int k = 0; k < r.count; ++k, p += step) t = _mm_fmadd_ps(_mm_broadcast_ss(w + k), _mm_loadu_ps(p), t);
        w += r.count;
      }
    }
    const __m256 a = _mm256_add_ps(_mm256_add_ps(a0, a1), _mm256_add_ps(a2, a3));
    const __m128 sum = _mm_add_ps(_mm_add_ps(_mm256_castps256_ps128(a), _mm256_extractf128_ps(a, 1)), t);
    acc = _mm256_add_pd(acc, _mm256_cvtps_pd(sum));
  }
  _mm256_storeu_pd(out, acc);
}
#endif

void apply_stencil(const stencil& s, const face_map* maps, const float* const* px4, double out[4]) noexcept {
#if HEMILIGHT_CUBEMAP_AVX2
  static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (avx2) return apply_stencil_avx2(s, maps, px4, out);
#endif
  apply_stencil_portable(s, maps, px4, out);
}

// Stretch and warp put the edge texels of adjacent faces on the same direction. The filter
// computes each from its own (symmetry, stencil) pair, so the float sums can differ in the last
// bits; copy the first one (face-major order) to the others so that they are bitwise identical,
// as a per-direction filter makes them.
void share_edge_texels(cube_image& out, edge_fixup fixup) {
  const int n = out.size;
  struct entry {
    glm::vec3 d;
    std::size_t texel;
  };
  std::vector<entry> edge;
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        if (x == 0 || y == 0 || x == n - 1 || y == n - 1)
          edge.push_back({cubemap_texel_direction(n, f, x, y, fixup),
                          (std::size_t(f) * std::size_t(n) + std::size_t(y)) * std::size_t(n) + std::size_t(x)});
  const auto less = [](const entry& a, const entry& b) {
    if (a.d.x != b.d.x) return a.d.x < b.d.x;
    if (a.d.y != b.d.y) return a.d.y < b.d.y;
    if (a.d.z != b.d.z) return a.d.z < b.d.z;
    return a.texel < b.texel;
  };
  std::sort(edge.begin(), edge.end(), less);
  const std::size_t ch = std::size_t(out.channels);
  for (std::size_t i = 0, j; i < edge.size(); i = j) {
    for (j = i + 1; j < edge.size() && edge[j].d == edge[i].d; ++j)
      std::copy_n(out.pixels.data() + edge[i].texel * ch, ch, out.pixels.data() + edge[j].texel * ch);
  }
}

// Four floats per texel, so that one SIMD load reads a texel (RGB inputs get a zero fourth), as
// stored and then with each face transposed (texel (x, y) of face f at f n^2 + x n + y): under a
// symmetry that turns the canonical rows into columns, a stencil run reads consecutive texels of
// the transposed copy instead of texels one row (n texels, a cache line and often a page) apart.
const std::vector<float>& four_float_copies(const chain_level& level, int thread_count) {
  if (!level.four_float.empty()) return level.four_float;
  const cube_image& in = *level.image;
  const std::size_t n = std::size_t(in.size), ch = std::size_t(in.channels), nn = n * n, count = 6 * nn;
  std::vector<float>& out = level.four_float;
  out.resize(count * 8);
  float* transposed = out.data() + count * 4;
  parallel_for(6 * n, thread_count, 16, [&](int, std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {  // row y of face f: a row of one copy, a column of the other
      const std::size_t f = r / n, y = r % n;
      for (std::size_t x = 0; x < n; ++x) {
        const float* src = in.pixels.data() + (f * nn + y * n + x) * ch;
        float* a = out.data() + (f * nn + y * n + x) * 4;
        float* b = transposed + (f * nn + x * n + y) * 4;
        for (std::size_t c = 0; c < 4; ++c) a[c] = b[c] = c < ch ? src[c] : 0.0f;
      }
    }
  });
  return out;
}

cube_image filter_chain_stencils(const chain_level& level, float power, bool irradiance, int out_size,
                                 const filter_options& o) {
  const cube_image& in = *level.image;
  const int n = in.size, ch = in.channels;
  const double cutoff = irradiance ? 1e-30 : static_cast<double>(o.cutoff);
  // the same extent as the direct path's lobe (float cos_max), so both cut the same texels
  const double cos_max = static_cast<double>(static_cast<float>(std::pow(cutoff, 1.0 / static_cast<double>(power))));
  const lobe_power lobe(static_cast<double>(power), cos_max);
  const double_table tab(*level.centres);
  cube_image out = cube_image::make(out_size, ch);
  const std::vector<float>& rgba = four_float_copies(level, o.thread_count);
  const float* const px4[2] = {rgba.data(), rgba.data() + rgba.size() / 2};
  const auto& sym = cube_symmetries();
  // Maps of the canonical faces under each symmetry, for the input and for the output grid.
  std::vector<face_map> in_maps(48 * 6), out_maps(48);
  for (std::size_t g = 0; g < 48; ++g) {
    for (int f = 0; f < 6; ++f) in_maps[g * 6 + std::size_t(f)] = map_face(sym[g], f, n, true);
    out_maps[g] = map_face(sym[g], 4, out_size);  // the fundamental domain lies on +Z (face 4)
  }
  // The fundamental domain: texels (x, y) of face +Z with x <= y <= (n - 1) / 2. Every output
  // texel is the image of one of them; it is computed once, for the first (symmetry, texel) pair
  // (in this fixed order) that reaches it.
  std::vector<std::pair<int, int>> domain;
  for (int y = 0; 2 * y <= out_size - 1; ++y)
    for (int x = 0; x <= y; ++x) domain.emplace_back(x, y);
  const std::size_t out_count = 6u * std::size_t(out_size) * std::size_t(out_size);
  std::vector<std::int32_t> owner(out_count, -1);  // g * domain size + domain index
  for (std::size_t g = 0; g < 48; ++g)
    for (std::size_t i = 0; i < domain.size(); ++i) {
      const face_map& m = out_maps[g];
      const std::size_t t = std::size_t(m.origin + domain[i].first * m.dx + domain[i].second * m.dy);
      assert(t < out_count);
      if (owner[t] < 0) owner[t] = static_cast<std::int32_t>(g * domain.size() + i);
    }
  // Work items: blocks of neighbouring stencils of the domain (~128 KB of weights, so that they
  // stay in the worker's cache). A worker builds a block's stencils, then applies them in the
  // order symmetry, stencil: each weight is read up to 48 times from cache, and within one
  // symmetry neighbouring output texels read neighbouring input texels. Blocks are independent
  // (no barrier inside a level, which matters when another process shares the cores), and
  // there are at least ~4 per worker so that small levels still use every core. Each output
  // texel comes from the same stencil and the same order of sums whichever worker computes it.
  const double cap = 2.0 * pi * (1.0 - std::max(cos_max, 0.0));
  const double taps = std::min(6.0 * n * n, 1.5 * cap / (4.0 * pi / (6.0 * n * n)) + 8.0);
  const std::size_t workers = static_cast<std::size_t>(resolve_thread_count(o.thread_count));
  const std::size_t block = std::clamp<std::size_t>(static_cast<std::size_t>(32768.0 / taps), 1,
                                                    std::max<std::size_t>(1, domain.size() / (4 * workers)));
  const std::size_t blocks = (domain.size() + block - 1) / block;
  const double scale = irradiance ? pi : 1.0;
  std::vector<std::vector<stencil>> scratch(workers);  // one block of stencils per worker
  parallel_for(blocks, o.thread_count, 1, [&](int worker, std::size_t begin, std::size_t end) {
    std::vector<stencil>& stencils = scratch[std::size_t(worker)];
    stencils.resize(block);
    for (std::size_t bi = begin; bi < end; ++bi) {
      const std::size_t b0 = bi * block, b1 = std::min(domain.size(), b0 + block);
      for (std::size_t i = b0; i < b1; ++i) {
        const auto [x, y] = domain[i];
        const glm::dvec3 d = glm::normalize(face_point_d(4, cubemap_texel_coordinate(out_size, x, o.fixup),
                                                         cubemap_texel_coordinate(out_size, y, o.fixup)));
        build_stencil(tab, n, lobe, cos_max, d, stencils[i - b0]);
      }
      for (std::size_t g = 0; g < 48; ++g) {
        const face_map& m = out_maps[g];
        const face_map* maps = in_maps.data() + g * 6;
        for (std::size_t i = b0; i < b1; ++i) {
          const std::size_t t = std::size_t(m.origin + domain[i].first * m.dx + domain[i].second * m.dy);
          if (owner[t] != static_cast<std::int32_t>(g * domain.size() + i)) continue;
          const stencil& st = stencils[i - b0];
          float* dst = out.pixels.data() + t * std::size_t(ch);
          double v[4];
          apply_stencil(st, maps, px4, v);
          for (int c = 0; c < ch; ++c)  // alpha: the mean, not scaled
            dst[c] = static_cast<float>(v[c] * st.norm * (c < 3 ? scale : 1.0));
        }
      }
    }
  });
  if (o.fixup != edge_fixup::none) share_edge_texels(out, o.fixup);
  return out;
}

cube_image filter_chain(const input_chain& chain, float power, bool irradiance, int out_size, const filter_options& o) {
  const chain_level& level = pick_level(chain, power, irradiance, o);
  if (o.precomputed_weights) return filter_chain_stencils(level, power, irradiance, out_size, o);
  const cube_image& in = *level.image;
  const lobe lb(power, irradiance ? 1e-30f : o.cutoff);  // the cosine lobe: the whole hemisphere
  cube_image out = cube_image::make(out_size, in.channels);
  const std::size_t ch = std::size_t(in.channels);
  const double scale = irradiance ? pi : 1.0;
  const std::size_t rows = 6u * std::size_t(out_size);
  parallel_for(rows, o.thread_count, 1, [&](int, std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      const int f = static_cast<int>(r / std::size_t(out_size)), y = static_cast<int>(r % std::size_t(out_size));
      for (int x = 0; x < out_size; ++x) {
        const glm::vec3 d = cubemap_texel_direction(out_size, f, x, y, o.fixup);
        const glm::dvec4 v = filter_direction(level, lb, d) * scale;
        float* p = out.at(f, x, y);
        for (std::size_t c = 0; c < ch; ++c) p[c] = static_cast<float>(v[static_cast<glm::length_t>(c)]);
        if (irradiance && ch == 4) p[3] = static_cast<float>(v[3] / scale);  // alpha: the mean, not scaled
      }
    }
  });
  return out;
}

}  // namespace

cube_image filter_cosine_power(const cubemap& input, float power, int output_size, const filter_options& options) {
  const char* fn = "filter_cosine_power";
  if (input.levels.empty()) throw_invalid_argument(std::string(fn) + ": the input cube map has no levels");
  validate_level(fn, input.levels[0]);
  check_power(fn, power);
  check_output_size(fn, output_size);
  check_options(fn, options);
  const input_chain chain(input.levels[0]);
  return filter_chain(chain, power, false, output_size, options);
}

cube_image filter_irradiance(const cubemap& input, int output_size, const filter_options& options) {
  const char* fn = "filter_irradiance";
  if (input.levels.empty()) throw_invalid_argument(std::string(fn) + ": the input cube map has no levels");
  validate_level(fn, input.levels[0]);
  check_output_size(fn, output_size);
  check_options(fn, options);
  const input_chain chain(input.levels[0]);
  return filter_chain(chain, 1.0f, true, output_size, options);
}

std::vector<float> filter_reference(const cube_image& input, float power, int output_size, edge_fixup fixup,
                                    const std::vector<std::size_t>& texels, int thread_count) {
  const char* fn = "filter_reference";
  validate_level(fn, input);
  if (!std::isfinite(power)) check_power(fn, power);
  check_output_size(fn, output_size);
  const bool irradiance = !(power > 0.0f);
  const std::size_t on = std::size_t(output_size), count_all = 6u * on * on;
  for (std::size_t t : texels)
    if (t >= count_all) throw_invalid_argument(std::string(fn) + ": texel " + std::to_string(t) + " is out of range");
  // Every input texel's direction and exact solid angle, in double.
  const int n = input.size;
  const std::size_t nn = std::size_t(n) * std::size_t(n);
  std::vector<glm::dvec4> in(6 * nn);
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const glm::dvec3 p = glm::normalize(face_point_d(f, cubemap_texel_coordinate(n, x, edge_fixup::none),
                                                         cubemap_texel_coordinate(n, y, edge_fixup::none)));
        in[std::size_t(f) * nn + std::size_t(y) * std::size_t(n) + std::size_t(x)] =
            glm::dvec4(p, cubemap_texel_solid_angle(n, x, y));
      }
  const std::size_t count = texels.empty() ? count_all : texels.size();
  const std::size_t ch = std::size_t(input.channels);
  std::vector<float> out(count * ch);
  parallel_for(count, thread_count, 1, [&](int, std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t t = texels.empty() ? k : texels[k];
      const int f = static_cast<int>(t / (on * on));
      const int y = static_cast<int>((t % (on * on)) / on), x = static_cast<int>(t % on);
      const glm::dvec3 d = face_point_d(f, cubemap_texel_coordinate(output_size, x, fixup),
                                        cubemap_texel_coordinate(output_size, y, fixup));
      const glm::dvec3 dn = glm::normalize(d);
      double acc[4] = {0, 0, 0, 0}, wsum = 0;
      for (std::size_t i = 0; i < in.size(); ++i) {
        const double dot = glm::dot(dn, glm::dvec3(in[i]));
        if (dot <= 0.0) continue;
        const double w = in[i].w * (irradiance ? dot : std::pow(dot, static_cast<double>(power)));
        const float* p = input.pixels.data() + i * ch;
        for (std::size_t c = 0; c < ch; ++c) acc[c] += w * p[c];
        wsum += w;
      }
      for (std::size_t c = 0; c < ch; ++c) {
        const double scale = irradiance && c < 3 ? pi : 1.0;
        out[k * ch + c] = static_cast<float>(scale * acc[c] / wsum);
      }
    }
  });
  return out;
}

float gloss_power(int top_size, int level, float texels) noexcept {
  assert(top_size >= 1 && level >= 0 && texels > 0.0f);
  const int size = level >= 31 ? 1 : std::max(1, top_size >> level);
  const float half = static_cast<float>(size) / (2.0f * texels);
  return half * half;
}

namespace {

// The levels of a chain, one power each; with options.cascade (texel-centre outputs only) a
// level whose lobe is wider than the previous one's is filtered from that previous output level
// with the differential lobe 1/q = 1/p_k - 1/p_(k-1) (cos^p composes like a Gaussian for large p).
// Only where the previous level resolves the differential lobe (its size >= 2 texels_per_sigma
// sqrt(q), the rule of the input mip choice) and p_k >= 256: below, cos^p is too far from a
// Gaussian (measured on the 256^2 sky, cmft's lobes: p = 64 from 152 adds 1.2%, p = 2 from 4.8
// 45%).
constexpr float cascade_min_power = 256.0f;
cubemap chain_levels(const cube_image& top, int output_size, const std::vector<float>& powers, const filter_options& o) {
  const input_chain chain(top);
  cubemap out;
  for (std::size_t l = 0; l < powers.size(); ++l) {
    const int size = std::max(1, output_size >> l);
    const double q = l > 0 && powers[l] < powers[l - 1]
                         ? 1.0 / (1.0 / static_cast<double>(powers[l]) - 1.0 / static_cast<double>(powers[l - 1]))
                         : 0.0;
    // the previous level must resolve the differential lobe as finely as texels_per_sigma asks
    const bool resolved =
        q > 0.0 && out.levels[l - 1].size >= 2.0 * static_cast<double>(o.texels_per_sigma) * std::sqrt(q);
    if (o.cascade && o.fixup == edge_fixup::none && resolved && powers[l] >= cascade_min_power) {
      const input_chain previous(out.levels[l - 1]);
      out.levels.push_back(filter_chain(previous, static_cast<float>(q), false, size, o));
    } else {
      out.levels.push_back(filter_chain(chain, powers[l], false, size, o));
    }
  }
  return out;
}

}  // namespace

cubemap filter_mip_chain(const cubemap& input, int output_size, const filter_options& options, float lobe_texels,
                         int levels) {
  const char* fn = "filter_mip_chain";
  if (input.levels.empty()) throw_invalid_argument(std::string(fn) + ": the input cube map has no levels");
  validate_level(fn, input.levels[0]);
  check_output_size(fn, output_size);
  check_options(fn, options);
  if (!std::isfinite(lobe_texels) || !(lobe_texels > 0.0f))
    throw_invalid_argument(std::string(fn) + ": lobe_texels must be finite and > 0");
  if (levels < 0) throw_invalid_argument(std::string(fn) + ": levels " + std::to_string(levels) + " is negative");
  int full = 1;
  while ((output_size >> full) >= 1 && full < 31) ++full;
  const int count = levels == 0 ? full : std::min(levels, full);
  std::vector<float> powers;
  for (int l = 0; l < count; ++l) powers.push_back(gloss_power(output_size, l, lobe_texels));
  return chain_levels(input.levels[0], output_size, powers, options);
}

cubemap filter_mip_chain_powers(const cubemap& input, int output_size, const std::vector<float>& powers,
                                const filter_options& options) {
  const char* fn = "filter_mip_chain_powers";
  if (input.levels.empty()) throw_invalid_argument(std::string(fn) + ": the input cube map has no levels");
  validate_level(fn, input.levels[0]);
  check_output_size(fn, output_size);
  check_options(fn, options);
  int full = 1;
  while ((output_size >> full) >= 1 && full < 31) ++full;
  if (powers.empty() || powers.size() > std::size_t(full))
    throw_invalid_argument(std::string(fn) + ": " + std::to_string(powers.size()) + " powers for a chain of " +
                           std::to_string(full) + " levels; give 1 to " + std::to_string(full));
  for (float p : powers) check_power(fn, p);
  return chain_levels(input.levels[0], output_size, powers, options);
}

// ---------------------------------------------------------------------------------------------
// SH

std::array<double, 9> sh9_basis(const glm::dvec3& w) noexcept {
  const double x = w.x, y = w.y, z = w.z;
  return {0.28209479177387814,
          0.4886025119029199 * y,
          0.4886025119029199 * z,
          0.4886025119029199 * x,
          1.0925484305920792 * x * y,
          1.0925484305920792 * y * z,
          0.31539156525252005 * (3.0 * z * z - 1.0),
          1.0925484305920792 * x * z,
          0.5462742152960396 * (x * x - y * y)};
}

namespace {

// The projection of project_sh9 and project_sh25: per row of texels a float sum of
// L(w) Y_k(w) d omega (basis(w, b) writes Y_0..Y_{K-1} at w into b), the rows added in double in
// row order, so the result is the same for any thread count. `who` names the caller in errors.
template <std::size_t K, class Basis>
std::array<glm::dvec4, K> project_sh(const char* who, const cube_image& level, int thread_count, Basis basis) {
  validate_level(who, level);
  const int n = level.size;
  const std::shared_ptr<const face_table> table = face_table::get(n);
  const std::size_t rows = 6u * std::size_t(n), ch = std::size_t(level.channels);
  std::vector<std::array<glm::dvec4, K>> partial(rows);  // one partial sum per row
  parallel_for(rows, thread_count, 8, [&](int, std::size_t begin, std::size_t end) {
    float b[K];
    for (std::size_t r = begin; r < end; ++r) {
      const int f = static_cast<int>(r / std::size_t(n)), y = static_cast<int>(r % std::size_t(n));
      const face_frame& fr = frame_of(f);
      // Float sums within the row (at most 6688 terms of similar size), double across rows.
      std::array<glm::vec4, K> acc{};
      for (int x = 0; x < n; ++x) {
        const glm::vec4& t = table->texels[std::size_t(y) * std::size_t(n) + std::size_t(x)];
        const glm::vec3 w = fr.column * t.x + fr.row * t.y + fr.axis * t.z;
        const float* p = level.at(f, x, y);
        const glm::vec4 lw = glm::vec4(p[0], p[1], p[2], ch == 4 ? p[3] : 1.0f) * t.w;
        basis(w, b);
        for (std::size_t k = 0; k < K; ++k) acc[k] += lw * b[k];
      }
      for (std::size_t k = 0; k < K; ++k) partial[r][k] = glm::dvec4(acc[k]);
    }
  });
  std::array<glm::dvec4, K> total{};
  for (const auto& row : partial)
    for (std::size_t k = 0; k < K; ++k) total[k] += row[k];
  return total;
}

// The output of irradiance_from_sh9 and irradiance_from_sh25: checks size, channels and mapping,
// then each texel gets E = irradiance(n) at its unit direction n under `mapping` (RGB; alpha, if
// any, is E.w / pi: the cosine-weighted mean, not scaled).
template <class Irradiance>
cube_image irradiance_map(const char* who, int size, edge_fixup mapping, int channels, int thread_count, Irradiance irradiance) {
  check_output_size(who, size);
  if (channels != 3 && channels != 4)
    throw_invalid_argument(std::string(who) + ": channels is " + std::to_string(channels) + "; it must be 3 or 4");
  const int m = static_cast<int>(mapping);
  if (m < 0 || m > 2) throw_invalid_argument(std::string(who) + ": mapping " + std::to_string(m) + " is not 0, 1 or 2");
  cube_image out = cube_image::make(size, channels);
  const std::size_t rows = 6u * std::size_t(size), ch = std::size_t(channels);
  std::vector<float> coord(static_cast<std::size_t>(size));  // the mapping's face coordinate of each index
  for (int i = 0; i < size; ++i) coord[std::size_t(i)] = static_cast<float>(cubemap_texel_coordinate(size, i, mapping));
  parallel_for(rows, thread_count, 16, [&](int, std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      const int f = static_cast<int>(r / std::size_t(size)), y = static_cast<int>(r % std::size_t(size));
      const face_frame& fr = frame_of(f);
      const glm::vec3 row_point = fr.axis + coord[std::size_t(y)] * fr.row;
      for (int x = 0; x < size; ++x) {
        const glm::vec3 p3 = row_point + coord[std::size_t(x)] * fr.column;
        const glm::vec4 e = irradiance(p3 / std::sqrt(glm::dot(p3, p3)));
        float* p = out.at(f, x, y);
        p[0] = e.x;
        p[1] = e.y;
        p[2] = e.z;
        if (ch == 4) p[3] = static_cast<float>(static_cast<double>(e.w) / pi);
      }
    }
  });
  return out;
}

}  // namespace

sh9 project_sh9(const cube_image& level, int thread_count) {
  sh9 out;
  out.coefficients = project_sh<9>("project_sh9", level, thread_count, [](const glm::vec3& w, float* b) {
    b[0] = 0.28209479177387814f;
    b[1] = 0.4886025119029199f * w.y;
    b[2] = 0.4886025119029199f * w.z;
    b[3] = 0.4886025119029199f * w.x;
    b[4] = 1.0925484305920792f * w.x * w.y;
    b[5] = 1.0925484305920792f * w.y * w.z;
    b[6] = 0.31539156525252005f * (3.0f * w.z * w.z - 1.0f);
    b[7] = 1.0925484305920792f * w.x * w.z;
    b[8] = 0.5462742152960396f * (w.x * w.x - w.y * w.y);
  });
  return out;
}

glm::dvec4 sh9_irradiance(const sh9& radiance, const glm::dvec3& n) noexcept {
  static constexpr double band[9] = {pi,           2.0 * pi / 3, 2.0 * pi / 3, 2.0 * pi / 3, pi / 4,
                                     pi / 4,       pi / 4,       pi / 4,       pi / 4};
  const std::array<double, 9> b = sh9_basis(n);
  glm::dvec4 e(0.0);
  for (std::size_t k = 0; k < 9; ++k) e += radiance.coefficients[k] * (band[k] * b[k]);
  return e;
}

cube_image irradiance_from_sh9(const sh9& radiance, int size, edge_fixup mapping, int channels, int thread_count) {
  // E(n) is a quadratic polynomial in n: fold the band factors and basis constants into one
  // coefficient per monomial (1, y, z, x, xy, yz, 3z^2 - 1, xz, x^2 - y^2) and channel.
  static constexpr double band[9] = {pi, 2.0 * pi / 3, 2.0 * pi / 3, 2.0 * pi / 3, pi / 4, pi / 4, pi / 4, pi / 4, pi / 4};
  static constexpr double basis_constant[9] = {0.28209479177387814, 0.4886025119029199, 0.4886025119029199,
                                               0.4886025119029199,  1.0925484305920792, 1.0925484305920792,
                                               0.31539156525252005, 1.0925484305920792, 0.5462742152960396};
  std::array<glm::vec4, 9> k;
  for (std::size_t j = 0; j < 9; ++j) k[j] = glm::vec4(radiance.coefficients[j] * (band[j] * basis_constant[j]));
  return irradiance_map("irradiance_from_sh9", size, mapping, channels, thread_count, [&](const glm::vec3& n) {
    return k[0] + k[1] * n.y + k[2] * n.z + k[3] * n.x + k[4] * (n.x * n.y) + k[5] * (n.y * n.z) +
           k[6] * (3.0f * n.z * n.z - 1.0f) + k[7] * (n.x * n.z) + k[8] * (n.x * n.x - n.y * n.y);
  });
}

// ---------------------------------------------------------------------------------------------
// SH, bands 0-4

namespace {

// The 25 real SH basis functions at unit (x, y, z), in T (float for the projection's inner loop,
// double for sh25_basis). Constants: sqrt((2l + 1)/(4 pi) (l - |m|)!/(l + |m|)!) times the
// associated Legendre polynomial's factors, as in the usual tables (band 3 and 4 written out).
template <class T>
void sh25_basis_t(T x, T y, T z, T* b) noexcept {
  const T x2 = x * x, y2 = y * y, z2 = z * z;
  b[0] = T(0.28209479177387814);
  b[1] = T(0.4886025119029199) * y;
  b[2] = T(0.4886025119029199) * z;
  b[3] = T(0.4886025119029199) * x;
  b[4] = T(1.0925484305920792) * x * y;
  b[5] = T(1.0925484305920792) * y * z;
  b[6] = T(0.31539156525252005) * (T(3) * z2 - T(1));
  b[7] = T(1.0925484305920792) * x * z;
  b[8] = T(0.5462742152960396) * (x2 - y2);
  b[9] = T(0.5900435899266435) * y * (T(3) * x2 - y2);
  b[10] = T(2.890611442640554) * x * y * z;
  b[11] = T(0.4570457994644658) * y * (T(5) * z2 - T(1));
  b[12] = T(0.3731763325901154) * z * (T(5) * z2 - T(3));
  b[13] = T(0.4570457994644658) * x * (T(5) * z2 - T(1));
  b[14] = T(1.445305721320277) * z * (x2 - y2);
  b[15] = T(0.5900435899266435) * x * (x2 - T(3) * y2);
  b[16] = T(2.5033429417967046) * x * y * (x2 - y2);
  b[17] = T(1.7701307697799304) * y * z * (T(3) * x2 - y2);
  b[18] = T(0.9461746957575601) * x * y * (T(7) * z2 - T(1));
  b[19] = T(0.6690465435572892) * y * z * (T(7) * z2 - T(3));
  b[20] = T(0.10578554691520431) * (T(35) * z2 * z2 - T(30) * z2 + T(3));
  b[21] = T(0.6690465435572892) * x * z * (T(7) * z2 - T(3));
  b[22] = T(0.47308734787878004) * (x2 - y2) * (T(7) * z2 - T(1));
  b[23] = T(1.7701307697799304) * x * z * (x2 - T(3) * y2);
  b[24] = T(0.6258357354491761) * (x2 * (x2 - T(3) * y2) - y2 * (T(3) * x2 - y2));
}

// The clamped cosine's band factors A_l for bands 0-4, per coefficient.
constexpr double sh25_band_factor(std::size_t k) noexcept {
  return k < 1 ? pi : k < 4 ? 2.0 * pi / 3.0 : k < 9 ? pi / 4.0 : k < 16 ? 0.0 : -pi / 24.0;
}

}  // namespace

std::array<double, 25> sh25_basis(const glm::dvec3& w) noexcept {
  std::array<double, 25> b;
  sh25_basis_t(w.x, w.y, w.z, b.data());
  return b;
}

sh25 project_sh25(const cube_image& level, int thread_count) {
  sh25 out;
  out.coefficients = project_sh<25>("project_sh25", level, thread_count,
                                    [](const glm::vec3& w, float* b) { sh25_basis_t(w.x, w.y, w.z, b); });
  return out;
}

glm::dvec4 sh25_irradiance(const sh25& radiance, const glm::dvec3& n) noexcept {
  double b[25];
  sh25_basis_t(n.x, n.y, n.z, b);
  glm::dvec4 e(0.0);
  for (std::size_t k = 0; k < 25; ++k) e += radiance.coefficients[k] * (sh25_band_factor(k) * b[k]);
  return e;
}

cube_image irradiance_from_sh25(const sh25& radiance, int size, edge_fixup mapping, int channels, int thread_count) {
  // Band factors folded into the coefficients; band 3 (A_3 = 0) is skipped.
  std::array<glm::vec4, 25> k;
  for (std::size_t j = 0; j < 25; ++j) k[j] = glm::vec4(radiance.coefficients[j] * sh25_band_factor(j));
  return irradiance_map("irradiance_from_sh25", size, mapping, channels, thread_count, [&](const glm::vec3& n) {
    float b[25];
    sh25_basis_t(n.x, n.y, n.z, b);
    glm::vec4 e(0.0f);
    for (std::size_t j = 0; j < 9; ++j) e += k[j] * b[j];
    for (std::size_t j = 16; j < 25; ++j) e += k[j] * b[j];
    return e;
  });
}

}  // namespace hemilight
