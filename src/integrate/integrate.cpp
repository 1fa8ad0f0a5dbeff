// Hemicube integration: exact per-texel weights, per-wall gradient coefficients, and the two
// passes (texels, walls) that reduce a hemicube buffer. See integrate.hpp and docs/integration.md.
#include "hemilight/integrate.hpp"

#include "hemilight/parallel.hpp"

#include "../core/table_cache.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define HEMILIGHT_INTEGRATE_AVX2 1
#define HEMILIGHT_TARGET_AVX2_FMA __attribute__((target("avx2,fma")))
#else
#define HEMILIGHT_INTEGRATE_AVX2 0
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

namespace hemilight {

namespace {

using dvec3 = glm::dvec3;

// Vector solid angle of a spherical polygon, integral of w dw: 1/2 sum beta_k gamma_k (Lambert).
// With hemicube corner order (c x r = a) it points out of the cube through the texel.
dvec3 vector_solid_angle(const std::array<dvec3, 4>& c) {
  dvec3 sum(0.0);
  for (std::size_t k = 0; k < 4; ++k) {
    const dvec3 x = glm::cross(c[k], c[(k + 1) % 4]);
    const double len = glm::length(x);
    if (len > 0.0) sum += std::atan2(len, glm::dot(c[k], c[(k + 1) % 4])) * x / len;
  }
  return 0.5 * sum;
}

dvec3 texel_centre(int n, std::size_t i) { return dvec3(hemicube_texel_direction(n, i)); }

struct wall_coefficients {
  glm::dvec2 great_arc{0.0};
  glm::dvec2 classified{0.0};
};

// Coefficients of the wall with unit end directions d0, d1 between texels with centres ca, cb.
wall_coefficients wall_between(const dvec3& d0, const dvec3& d1, const dvec3& ca, const dvec3& cb) {
  wall_coefficients out;
  const dvec3 x = glm::cross(d0, d1);
  const double sin_beta = glm::length(x);
  if (sin_beta == 0.0) return out;
  dvec3 m = x / sin_beta;
  if (glm::dot(m, cb - ca) < 0.0) m = -m;  // m points from texel a into texel b
  const double beta = std::atan2(sin_beta, glm::dot(d0, d1));  // arc length
  // Integral of cos(theta) = w.z along the great arc d(s) = d0 cos s + w sin s, s in [0, beta].
  const dvec3 w = glm::normalize(d1 - glm::dot(d0, d1) * d0);
  const double cos_integral = d0.z * std::sin(beta) + w.z * (1.0 - std::cos(beta));
  out.great_arc = glm::dvec2(m.x, m.y) * cos_integral;

  // Classified walls (Ward & Heckbert adapted): rate from the wall's latitude/longitude class
  // at its midpoint, direction normalize(m_t).
  const double mt = std::hypot(m.x, m.y);
  if (mt == 0.0) return out;
  const dvec3 mid = glm::normalize(d0 + d1);
  const double sin_theta = std::hypot(mid.x, mid.y);
  const double cos_theta = mid.z;
  bool longitude = false;  // the wall runs along a meridian (constant longitude)
  if (sin_theta > 1e-12) {
    const double cphi = mid.x / sin_theta, sphi = mid.y / sin_theta;
    const dvec3 theta_hat(cos_theta * cphi, cos_theta * sphi, -sin_theta);
    const dvec3 phi_hat(-sphi, cphi, 0.0);
    const dvec3 along = glm::normalize(d1 - d0);
    longitude = std::fabs(glm::dot(along, theta_hat)) > std::fabs(glm::dot(along, phi_hat));
  }
  const double rate = longitude ? 1.0 / sin_theta : cos_theta;
  out.classified = glm::dvec2(m.x, m.y) / mt * cos_integral * rate;
  return out;
}

constexpr double hl2_basis[3][3] = {
    {-0.40824829046386301637, 0.70710678118654752440, 0.57735026918962576451},
    {-0.40824829046386301637, -0.70710678118654752440, 0.57735026918962576451},
    {0.81649658092772603273, 0.0, 0.57735026918962576451},
};

constexpr float sh_y00 = 0.282094791773878143f;  // 1 / (2 sqrt(pi))
constexpr float sh_y1 = 0.488602511902919921f;   // sqrt(3) / (2 sqrt(pi))

}  // namespace

integration_table::integration_table(int n) : n_(n) {
  check_hemicube_resolution(n, "integration_table");
  const std::size_t count = hemicube_texel_count(n);
  const std::size_t un = static_cast<std::size_t>(n);
  for (std::vector<float>* v : {&vx, &vy, &vz, &simple_x, &simple_y, &hl2[0], &hl2[1], &hl2[2], &solid_angle,
                                &right_great_arc_x, &right_great_arc_y, &up_great_arc_x, &up_great_arc_y,
                                &right_classified_x, &right_classified_y, &up_classified_x, &up_classified_y})
    v->assign(count, 0.0f);
  extrapolation_neighbours.assign(count, 0);

  const double s = 2.0 / n;
  // Each texel's entries depend on that texel alone: split over all cores for large tables (about
  // 1 us per texel: N = 4096 took 50 s on one core), on the calling thread below 64k texels.
  const int threads = count < (std::size_t(1) << 16) ? 1 : 0;
  parallel_for(count, threads, 4096, [&](int, std::size_t first, std::size_t last) {
    for (std::size_t i = first; i < last; ++i) {
      const std::array<dvec3, 4> corners = hemicube_texel_corners(n, i);
      const dvec3 v = vector_solid_angle(corners);
      vx[i] = static_cast<float>(v.x);
      vy[i] = static_cast<float>(v.y);
      vz[i] = static_cast<float>(v.z);
      const dvec3 c = texel_centre(n, i);
      simple_x[i] = static_cast<float>(3.0 * v.z * c.x);
      simple_y[i] = static_cast<float>(3.0 * v.z * c.y);
      for (int k = 0; k < 3; ++k) {
        const dvec3 b(hl2_basis[k][0], hl2_basis[k][1], hl2_basis[k][2]);
        hl2[k][i] = static_cast<float>(std::max(0.0, glm::dot(v, b)));
      }
      solid_angle[i] = static_cast<float>(hemicube_texel_solid_angle(n, i));

      // Walls inside the face: to the right (x + 1) and up (y + 1) neighbours.
      const hemicube_texel t = hemicube_texel_from_index(n, i);
      const int height = hemicube_face_height(n, t.face);
      extrapolation_neighbours[i] = static_cast<std::uint8_t>((t.x > 0 ? 1 : 0) | (t.x + 2 < n ? 2 : 0) |
                                                              (t.y > 0 ? 4 : 0) | (t.y + 2 < height ? 8 : 0));
      const glm::dvec2 lo = hemicube_texel_min_corner(n, t);
      auto point = [&](double u, double w) { return glm::normalize(hemicube_face_point(t.face, u, w)); };
      if (t.x + 1 < n) {
        const wall_coefficients w = wall_between(point(lo.x + s, lo.y), point(lo.x + s, lo.y + s), c, texel_centre(n, i + 1));
        right_great_arc_x[i] = static_cast<float>(w.great_arc.x);
        right_great_arc_y[i] = static_cast<float>(w.great_arc.y);
        right_classified_x[i] = static_cast<float>(w.classified.x);
        right_classified_y[i] = static_cast<float>(w.classified.y);
      }
      if (t.y + 1 < hemicube_face_height(n, t.face)) {
        const wall_coefficients w = wall_between(point(lo.x, lo.y + s), point(lo.x + s, lo.y + s), c, texel_centre(n, i + un));
        up_great_arc_x[i] = static_cast<float>(w.great_arc.x);
        up_great_arc_y[i] = static_cast<float>(w.great_arc.y);
        up_classified_x[i] = static_cast<float>(w.classified.x);
        up_classified_y[i] = static_cast<float>(w.classified.y);
      }
    }
  });

  // Walls across face borders. (1) Each side face's top row meets the top face along z = 1.
  border_walls.reserve(6 * un);
  auto add_border = [&](std::size_t a, std::size_t b, const dvec3& p0, const dvec3& p1) {
    const wall_coefficients w = wall_between(glm::normalize(p0), glm::normalize(p1), texel_centre(n, a), texel_centre(n, b));
    border_walls.push_back({static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
                            {static_cast<float>(w.great_arc.x), static_cast<float>(w.great_arc.y)},
                            {static_cast<float>(w.classified.x), static_cast<float>(w.classified.y)}});
  };
  auto top_index = [&](double x, double y) {  // top-face texel containing (x, y, 1); edges clamp inward
    auto cell = [&](double c) { return std::clamp(static_cast<int>(std::floor((c + 1.0) / s)), 0, n - 1); };
    return hemicube_texel_index(n, {hemicube_face::top, cell(x), cell(y)});
  };
  const hemicube_face sides[4] = {hemicube_face::pos_x, hemicube_face::pos_y, hemicube_face::neg_x, hemicube_face::neg_y};
  for (hemicube_face f : sides) {
    for (int x = 0; x < n; ++x) {
      const double u0 = -1.0 + s * x, u1 = u0 + s;
      const dvec3 p0 = hemicube_face_point(f, u0, 1.0), p1 = hemicube_face_point(f, u1, 1.0);
      const dvec3 mid = 0.5 * (p0 + p1);
      add_border(hemicube_texel_index(n, {f, x, n / 2 - 1}), top_index(mid.x, mid.y), p0, p1);
    }
  }
  // (2) Neighbouring side faces (in the rotation order pos_x -> pos_y -> neg_x -> neg_y) meet
  // along a vertical cube edge: column N-1 of one face and column 0 of the next.
  for (int k = 0; k < 4; ++k) {
    const hemicube_face f = sides[k], g = sides[(k + 1) % 4];
    for (int y = 0; y < n / 2; ++y) {
      const double v0 = s * y, v1 = v0 + s;
      add_border(hemicube_texel_index(n, {f, n - 1, y}), hemicube_texel_index(n, {g, 0, y}), hemicube_face_point(f, 1.0, v0),
                 hemicube_face_point(f, 1.0, v1));
    }
  }
}

std::shared_ptr<const integration_table> integration_table::get(int n) {
  if (!is_valid_hemicube_resolution(n)) return std::make_shared<const integration_table>(n);  // throws
  // Kept in the process's table cache (table_cache.hpp: LRU within the budget of memory.hpp).
  return detail::cached_table<integration_table>(
      detail::table_kind::integration, n, [n] { return std::make_shared<const integration_table>(n); },
      [](const integration_table& t) {
        std::size_t bytes = detail::vector_bytes(t.border_walls) + detail::vector_bytes(t.extrapolation_neighbours);
        for (const std::vector<float>* v :
             {&t.vx, &t.vy, &t.vz, &t.simple_x, &t.simple_y, &t.hl2[0], &t.hl2[1], &t.hl2[2], &t.solid_angle,
              &t.right_great_arc_x, &t.right_great_arc_y, &t.up_great_arc_x, &t.up_great_arc_y, &t.right_classified_x,
              &t.right_classified_y, &t.up_classified_x, &t.up_classified_y})
          bytes += detail::vector_bytes(*v);
        return bytes;
      });
}

void validate_integrate_options(const integrate_options& options, const std::string& who) {
  if (!(options.min_wall_distance >= 0.0f) || !std::isfinite(options.min_wall_distance))
    throw_invalid_argument(who + ": min_wall_distance is " + std::to_string(options.min_wall_distance) +
                           "; it must be finite and >= 0 (0 = automatic)");
}

hemicube_integrator::hemicube_integrator(int resolution, const integrate_options& options)
    : n_(resolution), options_(options) {
  validate_integrate_options(options, "hemicube_integrator");
  table_ = integration_table::get(resolution);  // validates the resolution
  const std::size_t count = hemicube_texel_count(resolution);
  // Padded by zeros, a row before and a row and a group after: the extrapolating wall pass reads
  // the neighbours of every texel of a group (those outside the face are masked out).
  inv_r_.resize(count + 2 * static_cast<std::size_t>(resolution) + 8);
  if (options.extrapolate_wall_depth) wall_inv_.resize(2 * count);
  lit_.resize(count / 8 + 2);
}

namespace {

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

// wall_inv[i] for the walls between texel i and i + step, i < count - step (nb: the table's
// extrapolation_neighbours; bits `before_bit` and `after_bit` for this direction). inv is padded
// (see the integrator's constructor), so i - step and i + 2 step can be read for every i; where
// they lie outside the face their bit is clear and they are not used.
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

// The float kernel is compiled twice where the compiler can dispatch at load time (GCC/Clang on
// x86-64 Linux: an AVX2 clone and the portable SSE2 default, picked by the CPU); the two give the
// same sums up to the order of float additions inside a block.
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
// Hand-written AVX2 + FMA kernels for the float path on CPUs that have both (picked at run time):
// the same sums as texel_sums_impl + vector_sums_impl and wall_sums_impl, in one pass each, with
// every accumulator kept in a register (the compiler's "omp simd" versions spill or cannot
// fuse). Eight texels per step, blocks of `block` texels summed into double like the others; a
// scalar tail. Results equal the portable path up to float rounding order (tested through the
// float-against-double checks).

HEMILIGHT_TARGET_AVX2_FMA inline double hsum(__m256 v) noexcept {
  alignas(32) float lane[8];
  _mm256_store_ps(lane, v);
  double s = 0.0;
  for (float x : lane) s += double(x);
  return s;
}

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
                                              const std::uint8_t* nb = nullptr) noexcept {
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

// Picked once: both kernels need AVX2 and FMA.
bool cpu_has_avx2_fma() noexcept {
  static const bool yes = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return yes;
}
#endif

// ---- the stages of hemicube_integrator::run ----------------------------------------------------
// Each stage reads the buffer's planes (texel_planes) and the table, and writes only what its
// parameters say. With Inner = double (integrate_options::double_precision) the portable sums run
// in double; the AVX2 kernels serve the float path only.

// The buffer's planes as the passes read them (count = 3 N^2 texels, row = N).
struct texel_planes {
  const float *r, *g, *b;        // radiance per channel
  const float* dist;             // distance per texel
  const std::uint8_t* flags;     // texel_flags per texel
  std::size_t count, row;
};

// What pass 1 sums: s1 = E per channel, total projected solid angle, harmonic sum, back faces;
// phi = the vector irradiance's local (x, y) per channel (filled by the AVX2 texel pass, else by
// vector_pass); the smallest distance; the black groups of 8 texels the AVX2 pass mapped.
struct texel_sums {
  double s1[6] = {};
  double phi[6] = {};
  bool have_phi = false;
  float min_distance = 0.0f;
  std::size_t black_groups = 0;
};

// Pass 1: writes inv[i] = 1 / distance for every texel (inv: the integrator's padded scratch)
// and, with the AVX2 kernels and map_black, lit[group] (any radiance in a group of 8 texels).
template <class Inner>
texel_sums texel_pass(const texel_planes& p, const integration_table& t, bool avx2, bool map_black, float* inv,
                      std::uint8_t* lit) {
  texel_sums s;
  if (avx2) {
#if HEMILIGHT_INTEGRATE_AVX2
    if (map_black)
      s.min_distance = texel_pass_avx2<true>(p.r, p.g, p.b, p.dist, p.flags, t.vx.data(), t.vy.data(), t.vz.data(), inv, lit,
                                             &s.black_groups, p.count, s.s1, s.phi);
    else
      s.min_distance = texel_pass_avx2<false>(p.r, p.g, p.b, p.dist, p.flags, t.vx.data(), t.vy.data(), t.vz.data(), inv,
                                              nullptr, nullptr, p.count, s.s1, s.phi);
    s.have_phi = true;
#endif
  } else if constexpr (std::is_same<Inner, float>::value) {
    s.min_distance = texel_sums_float(p.r, p.g, p.b, p.dist, p.flags, t.vz.data(), inv, p.count, s.s1);
  } else {
    s.min_distance = texel_sums_impl<Inner>(p.r, p.g, p.b, p.dist, p.flags, t.vz.data(), inv, p.count, s.s1);
  }
  assert(s.min_distance > 0.0f);
  return s;
}

// E, the harmonic mean and smallest distances and the back-face fraction from pass 1's sums.
irradiance_sample scalar_outputs(const texel_sums& s) {
  irradiance_sample out;
  out.irradiance = glm::vec3(float(s.s1[0]), float(s.s1[1]), float(s.s1[2]));
  const double total = s.s1[3], harmonic = s.s1[4];
  out.harmonic_mean_distance = harmonic > 0 ? float(total / harmonic) : std::numeric_limits<float>::infinity();
  out.min_distance = s.min_distance;
  out.backface_fraction = float(s.s1[5] / total);
  return out;
}

// The vector irradiance's (x, y) per channel into s.phi, where pass 1 did not sum them.
template <class Inner>
void vector_pass(const texel_planes& p, const integration_table& t, texel_sums& s) {
  if constexpr (std::is_same<Inner, float>::value)
    vector_sums_float(p.r, p.g, p.b, t.vx.data(), t.vy.data(), p.count, s.phi);
  else
    vector_sums_impl<Inner>(p.r, p.g, p.b, t.vx.data(), t.vy.data(), p.count, s.phi);
}

// g_r = n x Phi per channel; in the local frame z x (x, y, z) = (-y, x, 0).
std::array<glm::vec3, 3> rotation_gradient_of(const double (&phi)[6], const frame& f) {
  std::array<glm::vec3, 3> g;
  for (std::size_t c = 0; c < 3; ++c) g[c] = f.to_world(glm::vec3(-float(phi[2 * c + 1]), float(phi[2 * c]), 0.0f));
  return g;
}

// A translation gradient from its local (x, y) sums per channel, acc[2 c], acc[2 c + 1].
std::array<glm::vec3, 3> local_gradient_to_world(const double (&acc)[6], const frame& f) {
  std::array<glm::vec3, 3> g;
  for (std::size_t c = 0; c < 3; ++c) g[c] = f.to_world(glm::vec3(float(acc[2 * c]), float(acc[2 * c + 1]), 0.0f));
  return g;
}

// The simple estimator: per-texel weights 3 P_i w_t,i / r_i (inv: 1 / distance), then the same
// weighted sums as the vector irradiance. (A comparison estimator: the scratch allocation per call
// does not matter.)
template <class Inner>
std::array<glm::vec3, 3> simple_translation_gradient(const texel_planes& p, const integration_table& t, const float* inv,
                                                     const frame& f) {
  const float* sx = t.simple_x.data();
  const float* sy = t.simple_y.data();
  std::vector<float> wx(p.count), wy(p.count);
  for (std::size_t i = 0; i < p.count; ++i) {
    wx[i] = sx[i] * inv[i];
    wy[i] = sy[i] * inv[i];
  }
  double acc[6] = {};
  vector_sums_impl<Inner>(p.r, p.g, p.b, wx.data(), wy.data(), p.count, acc);
  return local_gradient_to_world(acc, f);
}

// The largest inverse distance a wall moves with: 1 / min_wall_distance, or automatically
// 10 / the harmonic mean distance (0 when nothing was hit: sky-sky walls only).
float wall_inverse_distance_cap(const integrate_options& o, const texel_sums& s) {
  if (o.min_wall_distance > 0.0f) return 1.0f / o.min_wall_distance;
  const double total = s.s1[3], harmonic = s.s1[4];
  return harmonic > 0 ? float(10.0 * harmonic / total) : 0.0f;
}

// One estimator's coefficients of the walls inside faces: right walls (rx, ry) and upper walls
// (ux, uy) of each texel, local x and y.
struct face_wall_weights {
  const float *rx, *ry, *ux, *uy;
};

face_wall_weights face_walls_of(const integration_table& t, bool arc) {
  return {arc ? t.right_great_arc_x.data() : t.right_classified_x.data(),
          arc ? t.right_great_arc_y.data() : t.right_classified_y.data(),
          arc ? t.up_great_arc_x.data() : t.up_classified_x.data(), arc ? t.up_great_arc_y.data() : t.up_classified_y.data()};
}

// The walls inside faces, with each wall's inverse distance extrapolated (extrapolate_wall_depth):
// AVX2: inside the wall pass; portable: per-wall inverse distances first into wall_inv (right
// walls, then upper walls; 2 count floats), then the sums. Adds into acc[6].
template <class Inner>
void extrapolated_face_wall_sums(const texel_planes& p, const integration_table& t, const face_wall_weights& w,
                                 const float* inv, float cap, bool avx2, std::size_t black_groups, const std::uint8_t* lit,
                                 float* wall_inv, double (&acc)[6]) {
  const std::uint8_t* nb = t.extrapolation_neighbours.data();
#if HEMILIGHT_INTEGRATE_AVX2
  if (avx2) {  // computed in the wall pass itself, only for the groups it does not skip
    if (black_groups > 0)
      wall_pass_avx2<true, true>(p.r, p.g, p.b, inv, lit, w.rx, w.ry, w.ux, w.uy, p.row, p.count, cap, acc, nb);
    else
      wall_pass_avx2<false, true>(p.r, p.g, p.b, inv, lit, w.rx, w.ry, w.ux, w.uy, p.row, p.count, cap, acc, nb);
    return;
  }
#else
  (void)avx2, (void)black_groups, (void)lit;
#endif
  float* wr = wall_inv;
  float* wu = wr + p.count;
  extrapolated_walls(inv, nb, 1, 1u, 2u, p.count, wr);
  extrapolated_walls(inv, nb, p.row, 4u, 8u, p.count, wu);
  if constexpr (std::is_same<Inner, float>::value) {
    wall_sums_given_float(p.r, p.g, p.b, wr, w.rx, w.ry, 1, p.count - 1, cap, acc);
    wall_sums_given_float(p.r, p.g, p.b, wu, w.ux, w.uy, p.row, p.count - p.row, cap, acc);
  } else {
    wall_sums_impl<Inner, true>(p.r, p.g, p.b, wr, w.rx, w.ry, 1, p.count - 1, cap, acc);
    wall_sums_impl<Inner, true>(p.r, p.g, p.b, wu, w.ux, w.uy, p.row, p.count - p.row, cap, acc);
  }
}

// The walls inside faces, each moving with its nearer texel (the larger of the two inverse
// distances, capped). Texel i with i + step (step 1: right neighbour, step N: the row above); the
// tables hold zero coefficients where i + step is not a neighbour (row and face ends), so both
// directions run over one contiguous range. Adds into acc[6].
template <class Inner>
void face_wall_sums(const texel_planes& p, const face_wall_weights& w, const float* inv, float cap, bool avx2,
                    std::size_t black_groups, const std::uint8_t* lit, double (&acc)[6]) {
  if (avx2) {
#if HEMILIGHT_INTEGRATE_AVX2
    if (black_groups > 0)
      wall_pass_avx2<true>(p.r, p.g, p.b, inv, lit, w.rx, w.ry, w.ux, w.uy, p.row, p.count, cap, acc);
    else
      wall_pass_avx2<false>(p.r, p.g, p.b, inv, lit, w.rx, w.ry, w.ux, w.uy, p.row, p.count, cap, acc);
#else
    (void)black_groups, (void)lit;
#endif
    return;
  }
  const auto walls = [&](std::size_t step, const float* cx, const float* cy) {
    if constexpr (std::is_same<Inner, float>::value)
      wall_sums_float(p.r, p.g, p.b, inv, cx, cy, step, p.count - step, cap, acc);
    else
      wall_sums_impl<Inner>(p.r, p.g, p.b, inv, cx, cy, step, p.count - step, cap, acc);
  };
  walls(1, w.rx, w.ry);
  walls(p.row, w.ux, w.uy);
}

// The 6 N walls across face borders. Equal radiance on both sides adds exactly zero (most walls
// of an emission-only hemicube, which has black groups; a lit one would only pay for the test).
// Adds into acc[6].
void border_wall_sums(const texel_planes& p, const integration_table& t, bool arc, const float* inv, float cap,
                      std::size_t black_groups, double (&acc)[6]) {
  const float *r = p.r, *g = p.g, *b = p.b;
  for (const integration_table::wall& w : t.border_walls) {
    if (black_groups > 0 && r[w.a] == r[w.b] && g[w.a] == g[w.b] && b[w.a] == b[w.b]) continue;
    const double iw = std::min(std::max(inv[w.a], inv[w.b]), cap);
    const float* c = arc ? w.great_arc : w.classified;
    const double wx = c[0] * iw, wy = c[1] * iw;
    acc[0] += (double(r[w.b]) - r[w.a]) * wx;
    acc[1] += (double(r[w.b]) - r[w.a]) * wy;
    acc[2] += (double(g[w.b]) - g[w.a]) * wx;
    acc[3] += (double(g[w.b]) - g[w.a]) * wy;
    acc[4] += (double(b[w.b]) - b[w.a]) * wx;
    acc[5] += (double(b[w.b]) - b[w.a]) * wy;
  }
}

// SH band 1 is the vector irradiance: its local (x, y) are phi and z is E. The other 12 sums
// (per channel: solid angle, three HL2 weights) here; writes out.sh_l1 and out.hl2.
template <class Inner>
void directional_outputs(const texel_planes& p, const integration_table& t, const texel_sums& s, const frame& f,
                         irradiance_sample& out) {
  double d[12] = {};
  if constexpr (std::is_same<Inner, float>::value)
    directional_sums_float(p.r, p.g, p.b, t.solid_angle.data(), t.hl2[0].data(), t.hl2[1].data(), t.hl2[2].data(), p.count, d);
  else
    directional_sums_impl<Inner>(p.r, p.g, p.b, t.solid_angle.data(), t.hl2[0].data(), t.hl2[1].data(), t.hl2[2].data(),
                                 p.count, d);
  for (std::size_t c = 0; c < 3; ++c) {
    const glm::vec3 w = f.to_world(glm::vec3(float(s.phi[2 * c]), float(s.phi[2 * c + 1]), float(s.s1[c])));
    out.sh_l1[0][int(c)] = sh_y00 * float(d[4 * c]);
    out.sh_l1[1][int(c)] = sh_y1 * w.y;
    out.sh_l1[2][int(c)] = sh_y1 * w.z;
    out.sh_l1[3][int(c)] = sh_y1 * w.x;
    for (std::size_t k = 0; k < 3; ++k) out.hl2[k][int(c)] = float(d[4 * c + 1 + k]);
  }
}

}  // namespace

// The chain: pass 1 over the texels (E, distances, back faces; the vector irradiance with the
// AVX2 kernels), the scalar outputs, the vector irradiance where still needed, g_r, g_t (the
// simple estimator's texel sums, or the walls inside faces and across their borders), the
// directional outputs. Acc: the precision of the portable sums inside a block (float, or double
// when asked for).
template <class Acc>
irradiance_sample hemicube_integrator::run(const hemicube_buffer& buffer) {
  using Inner = Acc;
  const integration_table& t = *table_;
  const texel_planes p{buffer.channel(0), buffer.channel(1),   buffer.channel(2),
                       buffer.distance.data(), buffer.flags.data(), hemicube_texel_count(n_), static_cast<std::size_t>(n_)};
  float* inv = inv_r_.data() + p.row;  // see the padding in the constructor
  const frame& f = buffer.basis;
#if HEMILIGHT_INTEGRATE_AVX2
  const bool avx2 = std::is_same<Inner, float>::value && options_.simd_kernels && cpu_has_avx2_fma();
#else
  const bool avx2 = false;
#endif
  // When the wall pass (classified or great-arc g_t) follows, pass 1 maps the black groups for
  // it: if the last mapped hemicube had at least 1/8 of its groups black (emission-only
  // hemicubes), and every 16th hemicube anyway. Skipping black groups never changes a result, so
  // this history only changes the speed: lit hemicubes (bounce passes) skip the mapping's cost.
  const bool wall_pass = options_.translation == translation_estimator::classified ||
                         options_.translation == translation_estimator::great_arc;
  const bool map_black = wall_pass && (map_black_ || ++unmapped_ >= 16);

  // Stage 1: pass 1 over the texels, and the outputs it gives.
  texel_sums s = texel_pass<Inner>(p, t, avx2, map_black, inv, lit_.data());
  if (avx2 && map_black) {
    map_black_ = s.black_groups * 8 >= p.count / 8;
    unmapped_ = 0;
  }
  irradiance_sample out = scalar_outputs(s);
  // Stage 2: the rotation gradient (and the vector irradiance the directional outputs share).
  if ((options_.rotation_gradient || options_.directional) && !s.have_phi) vector_pass<Inner>(p, t, s);
  if (options_.rotation_gradient) out.rotation_gradient = rotation_gradient_of(s.phi, f);
  // Stage 3: the translation gradient.
  if (options_.translation == translation_estimator::simple) {
    out.translation_gradient = simple_translation_gradient<Inner>(p, t, inv, f);
  } else if (options_.translation != translation_estimator::none) {
    const float cap = wall_inverse_distance_cap(options_, s);
    const bool arc = options_.translation == translation_estimator::great_arc;
    const face_wall_weights w = face_walls_of(t, arc);
    double acc[6] = {};
    if (options_.extrapolate_wall_depth)
      extrapolated_face_wall_sums<Inner>(p, t, w, inv, cap, avx2, s.black_groups, lit_.data(), wall_inv_.data(), acc);
    else
      face_wall_sums<Inner>(p, w, inv, cap, avx2, s.black_groups, lit_.data(), acc);
    border_wall_sums(p, t, arc, inv, cap, s.black_groups, acc);
    out.translation_gradient = local_gradient_to_world(acc, f);
  }
  // Stage 4: the directional outputs.
  if (options_.directional) directional_outputs<Inner>(p, t, s, f, out);
  return out;
}

irradiance_sample hemicube_integrator::integrate(const hemicube_buffer& buffer) {
  const std::size_t count = hemicube_texel_count(n_);
  if (buffer.resolution != n_ || buffer.distance.size() != count || buffer.flags.size() != count ||
      buffer.radiance.size() != 3 * count)
    throw_invalid_argument("hemicube_integrator::integrate: buffer has resolution " + std::to_string(buffer.resolution) +
                           " and " + std::to_string(buffer.distance.size()) + " texels; the integrator expects " +
                           std::to_string(n_) + " and " + std::to_string(count));
  return options_.double_precision ? run<double>(buffer) : run<float>(buffer);
}

irradiance_sample integrate(const hemicube_buffer& buffer, const integrate_options& options) {
  hemicube_integrator integrator(buffer.resolution, options);
  return integrator.integrate(buffer);
}

}  // namespace hemilight
