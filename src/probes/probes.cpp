// Light probes (probes.hpp): two world-aligned hemicubes per point, projected on SH9 with
// per-texel integrals of the basis, plus the lights' direct part.
#include "hemilight/probes.hpp"

#include "hemilight/error.hpp"
#include "hemilight/geometry.hpp"
#include "hemilight/hemicube.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/raster.hpp"

#include "../core/table_cache.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace hemilight {

namespace {

constexpr double sh_c0 = 0.282094791773878, sh_c1 = 0.488602511902920, sh_c2 = 1.092548430592079,
                 sh_c3 = 0.315391565252520, sh_c4 = 0.546274215296040;

template <class V, class T>
void basis_of(const V& w, T (&y)[9]) {
  const T x = T(w.x), yy = T(w.y), z = T(w.z);
  y[0] = T(sh_c0);
  y[1] = T(sh_c1) * yy;
  y[2] = T(sh_c1) * z;
  y[3] = T(sh_c1) * x;
  y[4] = T(sh_c2) * x * yy;
  y[5] = T(sh_c2) * yy * z;
  y[6] = T(sh_c3) * (T(3) * z * z - T(1));
  y[7] = T(sh_c2) * x * z;
  y[8] = T(sh_c4) * (x * x - yy * yy);
}

// Per texel of the up hemicube (world = local), the integral of each basis function over the
// texel: weights[k * texels + t]. The down hemicube's frame (t = +x, b = -y, n = -z) maps local
// (x, y, z) to world (x, -y, -z), so its weights are these times down_sign[k].
class sh9_texel_table {
 public:
  explicit sh9_texel_table(int n) : n_(n), texels_(hemicube_texel_count(n)), weights_(9 * texels_) {
    // 4-point Gauss-Legendre on [-1, 1].
    static const double gx[4] = {-0.861136311594053, -0.339981043584856, 0.339981043584856, 0.861136311594053};
    static const double gw[4] = {0.347854845137454, 0.652145154862546, 0.652145154862546, 0.347854845137454};
    // Texels wider than 1/8 of a face are split into sub x sub squares first (N < 16), so the
    // rule always spans at most 1/8 of a face: relative error below 1e-9 everywhere.
    const int sub = std::max(1, 16 / n);
    const double h = 1.0 / (n * sub);  // half the side of a square of the rule (texels span 2 / N)
    parallel_for(texels_, 0, 1024, [&](int, std::size_t b, std::size_t e) {
      for (std::size_t t = b; t < e; ++t) {
        const hemicube_texel tx = hemicube_texel_from_index(n_, t);
        const glm::dvec2 corner = hemicube_texel_min_corner(n_, tx);
        double sum[9] = {};
        for (int si = 0; si < sub; ++si)
          for (int sj = 0; sj < sub; ++sj) {
            const glm::dvec2 c = corner + glm::dvec2((2 * si + 1) * h, (2 * sj + 1) * h);
            for (int i = 0; i < 4; ++i)
              for (int j = 0; j < 4; ++j) {
                const glm::dvec3 p = hemicube_face_point(tx.face, c.x + h * gx[i], c.y + h * gx[j]);
                const double len2 = glm::dot(p, p), len = std::sqrt(len2);
                const double jac = gw[i] * gw[j] * h * h / (len2 * len);  // d omega = du dv / |p|^3
                double y[9];
                basis_of(p / len, y);
                for (int k = 0; k < 9; ++k) sum[k] += jac * y[k];
              }
          }
        for (int k = 0; k < 9; ++k) weights_[std::size_t(k) * texels_ + t] = float(sum[k]);
      }
    });
  }
  int resolution() const noexcept { return n_; }
  std::size_t texels() const noexcept { return texels_; }
  const float* weights(int k) const noexcept { return weights_.data() + std::size_t(k) * texels_; }

  // The shared table of resolution N, in the process's table cache (table_cache.hpp).
  static std::shared_ptr<const sh9_texel_table> get(int n) {
    return detail::cached_table<sh9_texel_table>(
        detail::table_kind::sh9_texel, n, [n] { return std::make_shared<const sh9_texel_table>(n); },
        [](const sh9_texel_table& t) { return detail::vector_bytes(t.weights_); });
  }

 private:
  int n_;
  std::size_t texels_;
  std::vector<float> weights_;
};

constexpr float down_sign[9] = {1, -1, -1, 1, -1, 1, 1, -1, 1};

// Adds a hemicube's projection (sign per coefficient) to c, and its back-face solid angle to back.
void project(const hemicube_buffer& buf, const sh9_texel_table& table, const float (&sign)[9], const float* solid_angle,
             double (&c)[9][3], double& back) {
  // Sums of L w per (channel, coefficient): float over blocks of 1024 texels, vectorised (omp simd;
  // a block's rounding error is ~1e-6 of its sum), the blocks in double, in a fixed order: bitwise
  // the same on every thread.
  const std::size_t texels = table.texels(), block = 1024;
  for (int ch = 0; ch < 3; ++ch) {
    const float* L = buf.channel(ch);
    for (int k = 0; k < 9; ++k) {
      const float* w = table.weights(k);
      double s = 0.0;
      for (std::size_t b = 0; b < texels; b += block) {
        const std::size_t e = std::min(texels, b + block);
        float bs = 0.0f;
#pragma omp simd reduction(+ : bs)
        for (std::size_t t = b; t < e; ++t) bs += L[t] * w[t];
        s += double(bs);
      }
      c[k][ch] += double(sign[k]) * s;
    }
  }
  for (std::size_t t = 0; t < texels; ++t)
    if (buf.flags[t] & texel_back_face) back += double(solid_angle[t]);
}

// The lights' direct part at p: each light as a point source from the direction of its visible
// vector irradiance, with the irradiance a surface facing the light gets.
void add_lights(const scene& s, const light_set& lights, const direct_options& o, const glm::vec3& p, double (&c)[9][3]) {
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const light& l = lights[i];
    glm::vec3 toward;
    if (l.type == light_type::directional) {
      toward = -l.direction;
    } else {
      toward = l.position - p;
      const float d = glm::length(toward);
      if (!(d > 0.0f)) continue;  // at the light's centre: no direction
      toward /= d;
    }
    const light_sample ls = direct_light(s, lights, i, p, toward, o);
    if (ls.irradiance == glm::vec3(0.0f)) continue;
    const glm::vec3 w = glm::length(ls.direction) > 0.0f ? ls.direction : toward;
    double y[9];
    basis_of(glm::dvec3(w), y);
    for (int k = 0; k < 9; ++k)
      for (int ch = 0; ch < 3; ++ch) c[k][ch] += y[k] * double(ls.irradiance[ch]);
  }
}

}  // namespace

std::array<float, 9> sh9_basis(const glm::vec3& w) noexcept {
  float y[9];
  basis_of(w, y);
  std::array<float, 9> out;
  for (int k = 0; k < 9; ++k) out[std::size_t(k)] = y[k];
  return out;
}

glm::vec3 sh9_irradiance(const sh9_rgb& c, const glm::vec3& normal) noexcept {
  const float len = glm::length(normal);
  if (!(len > 0.0f) || !std::isfinite(len)) return glm::vec3(0.0f);
  float y[9];
  basis_of(normal / len, y);
  constexpr float pi = 3.14159265358979f;
  const float a[9] = {pi, 2 * pi / 3, 2 * pi / 3, 2 * pi / 3, pi / 4, pi / 4, pi / 4, pi / 4, pi / 4};
  glm::vec3 e(0.0f);
  for (int k = 0; k < 9; ++k) e += a[k] * y[k] * c[std::size_t(k)];
  return e;
}

probe_result sample_probes(std::shared_ptr<const scene> s, const glm::vec3* positions, std::size_t count,
                           const probe_options& o) {
  // Step 1: checks, before any work.
  if (!s) throw_invalid_argument("sample_probes: scene is null");
  if (count > 0 && !positions) throw_invalid_argument("sample_probes: positions is null but count is " + std::to_string(count));
  check_hemicube_resolution(o.resolution, "sample_probes");
  validate_raster_options(o.raster, "sample_probes: raster");
  if (o.thread_count < 0)
    throw_invalid_argument("sample_probes: thread_count is " + std::to_string(o.thread_count) + "; it must be >= 0 (0 = all cores)");
  if (o.lights) validate_direct_options(o.direct);
  if (o.texture) {
    o.texture->validate("sample_probes: texture");
    if (!s->has_lightmap_uvs()) throw_invalid_argument("sample_probes: a texture was given but the scene has no lightmap UVs");
  }
  for (std::size_t i = 0; i < count; ++i)
    for (int c = 0; c < 3; ++c)
      if (!(std::fabs(positions[i][c]) <= max_coordinate))
        throw_invalid_argument("sample_probes: positions[" + std::to_string(i) + "]." + "xyz"[c] + " is " +
                               std::to_string(positions[i][c]) + "; it must be finite and at most 1e18 in magnitude");
  // Step 2: the tables, one context per worker.
  probe_result out;
  out.probes.resize(count);
  out.backface_fraction.resize(count);
  if (count == 0) return out;
  const int n = o.resolution;
  const std::shared_ptr<const sh9_texel_table> table = sh9_texel_table::get(n);
  const std::shared_ptr<const hemicube_table> solid = hemicube_table::get(n);
  // One context per worker that runs (at most min(thread_count, chunks of 8 points)), made by the
  // worker on its first chunk.
  constexpr std::size_t grain = 8;
  const int workers = static_cast<int>(
      std::min(static_cast<std::size_t>(resolve_thread_count(o.thread_count)), (count + grain - 1) / grain));
  const raster_options& ro = o.raster;
  struct context {
    std::unique_ptr<hemicube_rasterizer> raster;
    hemicube_buffer buffer;
  };
  std::vector<context> contexts(static_cast<std::size_t>(workers));
  const frame up{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, down{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
  static constexpr float up_sign[9] = {1, 1, 1, 1, 1, 1, 1, 1, 1};
  // Step 3: per point, the two hemicubes, their projections, the lights.
  parallel_for(count, workers, grain, [&](int worker, std::size_t b, std::size_t e) {
    context& cx = contexts[std::size_t(worker)];
    if (!cx.raster) cx.raster = std::make_unique<hemicube_rasterizer>(s, ro);
    for (std::size_t i = b; i < e; ++i) {
      double c[9][3] = {}, back = 0.0;
      cx.raster->render(positions[i], up, n, cx.buffer, o.texture);
      project(cx.buffer, *table, up_sign, solid->solid_angle(), c, back);
      cx.raster->render(positions[i], down, n, cx.buffer, o.texture);
      project(cx.buffer, *table, down_sign, solid->solid_angle(), c, back);
      if (o.lights) add_lights(*s, *o.lights, o.direct, positions[i], c);
      for (int k = 0; k < 9; ++k) out.probes[i][std::size_t(k)] = glm::vec3(float(c[k][0]), float(c[k][1]), float(c[k][2]));
      out.backface_fraction[i] = float(std::min(1.0, back / (4.0 * 3.14159265358979323846)));
    }
  });
  return out;
}

}  // namespace hemilight
