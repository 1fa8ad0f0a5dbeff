// hemicube_integrator and integrate: the reduction of a hemicube buffer, as the chain of
// hemicube_integrator::run's stages over the sums of kernels.hpp. See integrate.hpp and
// docs/integration.md.
#include "hemilight/integrate.hpp"

#include "kernels.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

namespace hemilight {

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

using namespace integrate_detail;

constexpr float sh_y00 = 0.282094791773878143f;  // 1 / (2 sqrt(pi))
constexpr float sh_y1 = 0.488602511902919921f;   // sqrt(3) / (2 sqrt(pi))

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

// g_t of the classified or great-arc estimator (o.translation): the walls inside faces (their
// inverse distances extrapolated with o.extrapolate_wall_depth; wall_inv: its scratch), then the
// walls across face borders, with pass 1's sums s, its inverse distances inv and black-group map
// lit.
template <class Inner>
std::array<glm::vec3, 3> wall_translation_gradient(const texel_planes& p, const integration_table& t,
                                                   const integrate_options& o, const texel_sums& s, const float* inv,
                                                   bool avx2, const std::uint8_t* lit, float* wall_inv, const frame& f) {
  const float cap = wall_inverse_distance_cap(o, s);
  const bool arc = o.translation == translation_estimator::great_arc;
  const face_wall_weights w = face_walls_of(t, arc);
  double acc[6] = {};
  if (o.extrapolate_wall_depth)
    extrapolated_face_wall_sums<Inner>(p, t, w, inv, cap, avx2, s.black_groups, lit, wall_inv, acc);
  else
    face_wall_sums<Inner>(p, w, inv, cap, avx2, s.black_groups, lit, acc);
  border_wall_sums(p, t, arc, inv, cap, s.black_groups, acc);
  return local_gradient_to_world(acc, f);
}

// Whether the float path runs the hand-written AVX2 kernels: asked for (o.simd_kernels), and the
// CPU has AVX2 and FMA.
template <class Inner>
bool use_avx2_kernels(const integrate_options& o) {
#if HEMILIGHT_INTEGRATE_AVX2
  return std::is_same<Inner, float>::value && o.simd_kernels && cpu_has_avx2_fma();
#else
  (void)o;
  return false;
#endif
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
  const bool avx2 = use_avx2_kernels<Inner>(options_);
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
  if (options_.translation == translation_estimator::simple)
    out.translation_gradient = simple_translation_gradient<Inner>(p, t, inv, f);
  else if (options_.translation != translation_estimator::none)
    out.translation_gradient =
        wall_translation_gradient<Inner>(p, t, options_, s, inv, avx2, lit_.data(), wall_inv_.data(), f);
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
