// Cube-map mappings, the runtime lookup fixup, mip building and GPU-like sampling.
#include "hemilight/cubemap.hpp"

#include "cubemap_internal.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

namespace hemilight {

namespace cubemap_detail {

const face_frame& frame_of(int face) noexcept {
  // axis + u column + v row, from the GL table (geometry.hpp, cube_direction_from_face).
  static const face_frame frames[6] = {
      {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}},   // +X: sc = -rz, tc = -ry
      {{-1, 0, 0}, {0, 0, 1}, {0, -1, 0}},   // -X: sc = +rz, tc = -ry
      {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}},     // +Y: sc = +rx, tc = +rz
      {{0, -1, 0}, {1, 0, 0}, {0, 0, -1}},   // -Y: sc = +rx, tc = -rz
      {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}},    // +Z: sc = +rx, tc = -ry
      {{0, 0, -1}, {-1, 0, 0}, {0, -1, 0}},  // -Z: sc = -rx, tc = -ry
  };
  return frames[face];
}

void validate_level(const char* what, const cube_image& c) {
  if (c.size < 1 || c.size > cubemap_max_size)
    throw_invalid_argument(std::string(what) + ": size " + std::to_string(c.size) + " is outside [1, " +
                           std::to_string(cubemap_max_size) + "]");
  if (c.channels != 3 && c.channels != 4)
    throw_invalid_argument(std::string(what) + ": channels is " + std::to_string(c.channels) + "; it must be 3 or 4");
  const std::size_t expected = 6u * std::size_t(c.size) * std::size_t(c.size) * std::size_t(c.channels);
  if (c.pixels.size() != expected)
    throw_invalid_argument(std::string(what) + ": holds " + std::to_string(c.pixels.size()) + " floats, expected " +
                           std::to_string(expected));
  for (std::size_t i = 0; i < c.pixels.size(); ++i)
    if (!std::isfinite(c.pixels[i]))
      throw_invalid_argument(std::string(what) + ": value " + std::to_string(i) + " is not finite");
}

}  // namespace cubemap_detail

using namespace cubemap_detail;

double cubemap_texel_coordinate(int n, int x, edge_fixup mapping) noexcept {
  assert(n >= 1 && x >= 0 && x < n);
  if (n == 1) return 0.0;  // every mapping: the face centre (no division by n - 1 = 0)
  // Mirror the upper half so that u(n-1-x) = -u(x) holds bitwise.
  if (2 * x > n - 1) return -cubemap_texel_coordinate(n, n - 1 - x, mapping);
  const double dn = n;
  switch (mapping) {
    case edge_fixup::none: return (2.0 * x + 1.0) / dn - 1.0;
    case edge_fixup::stretch: return x == 0 ? -1.0 : 2.0 * x / (dn - 1.0) - 1.0;
    case edge_fixup::warp: {
      if (x == 0) return -1.0;  // c + a c^3 = -1 exactly in real arithmetic; make it so in floats
      const double c = (2.0 * x + 1.0) / dn - 1.0;
      const double a = dn * dn / ((dn - 1.0) * (dn - 1.0) * (dn - 1.0));
      return c + a * c * c * c;
    }
  }
  return 0.0;
}

glm::vec3 cube_face_point(cube_face face, float u, float v) noexcept {
  const face_frame& f = frame_of(static_cast<int>(face));
  return f.axis + u * f.column + v * f.row;  // components are 0, +-1: exact
}

glm::vec3 cubemap_texel_direction(int n, int face, int x, int y, edge_fixup mapping) noexcept {
  assert(face >= 0 && face < 6 && y >= 0 && y < n);
  const glm::dvec3 p = face_point_d(face, cubemap_texel_coordinate(n, x, mapping), cubemap_texel_coordinate(n, y, mapping));
  return glm::vec3(p / std::sqrt(glm::dot(p, p)));
}

double cubemap_texel_solid_angle(int n, int x, int y) noexcept {
  assert(n >= 1 && x >= 0 && x < n && y >= 0 && y < n);
  const double s = 2.0 / n;
  return rectangle_solid_angle(-1.0 + s * x, -1.0 + s * y, -1.0 + s * (x + 1), -1.0 + s * (y + 1));
}

glm::vec3 fixup_lookup(const glm::vec3& d, int size, float lod) noexcept {
  assert(size >= 1);
  const float n = static_cast<float>(size);
  // The same expression, in the same order, as the GLSL and HLSL snippets.
  const float scale = lod < 0.0f ? (n - 1.0f) / n : std::max(0.0f, 1.0f - std::exp2(lod) / n);
  const glm::vec3 a = glm::abs(d);
  if (a.x >= a.y && a.x >= a.z) return {d.x, d.y * scale, d.z * scale};
  if (a.y >= a.z) return {d.x * scale, d.y, d.z * scale};
  return {d.x * scale, d.y * scale, d.z};
}

// ---------------------------------------------------------------------------------------------

cubemap cubemap::from_image(cube_image top, bool build_mips) {
  validate_level("cubemap::from_image", top);
  cubemap m;
  m.levels.push_back(std::move(top));
  if (build_mips) {
    if ((m.size() & (m.size() - 1)) != 0)
      throw_invalid_argument("cubemap::from_image: size " + std::to_string(m.size()) +
                             " is not a power of two; a full mip chain needs one");
    while (m.levels.back().size > 1) m.levels.push_back(downsample_cube(m.levels.back()));
  }
  return m;
}

void cubemap::validate() const {
  if (levels.empty()) throw_invalid_argument("cubemap: no levels");
  for (std::size_t i = 0; i < levels.size(); ++i) {
    const std::string what = "cubemap level " + std::to_string(i);
    validate_level(what.c_str(), levels[i]);
    const int expected = std::max(1, levels[0].size >> i);
    if (levels[i].size != expected)
      throw_invalid_argument(what + ": size " + std::to_string(levels[i].size) + ", expected " + std::to_string(expected));
    if (levels[i].channels != levels[0].channels) throw_invalid_argument(what + ": channel count differs from level 0");
  }
}

cube_image downsample_cube(const cube_image& level) {
  const int n = level.size;
  if (n > 1 && n % 2 != 0)
    throw_invalid_argument("downsample_cube: size " + std::to_string(n) + " is odd; it must be 1 or even");
  if (n == 1) return level;
  const int m = n / 2;
  const std::size_t ch = std::size_t(level.channels);
  cube_image out = cube_image::make(m, level.channels);
  const std::shared_ptr<const face_table> table = face_table::get(n);
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < m; ++y)
      for (int x = 0; x < m; ++x) {
        double acc[4] = {0, 0, 0, 0}, wsum = 0;
        for (int j = 0; j < 2; ++j)
          for (int i = 0; i < 2; ++i) {
            const int cx = 2 * x + i, cy = 2 * y + j;
            const double w = table->texels[std::size_t(cy) * std::size_t(n) + std::size_t(cx)].w;
            const float* p = level.at(f, cx, cy);
            for (std::size_t c = 0; c < ch; ++c) acc[c] += w * p[c];
            wsum += w;
          }
        float* o = out.at(f, x, y);
        for (std::size_t c = 0; c < ch; ++c) o[c] = static_cast<float>(acc[c] / wsum);
      }
  return out;
}

cube_image procedural_environment(int size, int channels) {
  cube_image c = cube_image::make(size, channels);
  const glm::dvec3 sun = glm::normalize(glm::dvec3(0.4, 0.6, -0.7));
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const glm::dvec3 w = glm::dvec3(cubemap_texel_direction(size, f, x, y, edge_fixup::none));
        glm::dvec3 l;
        if (w.y >= 0.0) {
          const double bands = 0.5 + 0.5 * std::sin(6.0 * std::atan2(w.z, w.x) + 4.0 * w.y);
          l = glm::mix(glm::dvec3(1.2, 1.0, 0.8), glm::dvec3(0.3, 0.5, 1.0), w.y) + 0.4 * bands * glm::dvec3(0.2, 0.6, 0.3);
        } else {
          l = glm::dvec3(0.25, 0.2, 0.15) * (1.0 + 0.5 * w.y);
        }
        const double c_sun = glm::dot(w, sun), c_edge = std::cos(0.05);
        if (c_sun > c_edge - 0.002) l += glm::dvec3(200.0, 180.0, 150.0) * std::min(1.0, (c_sun - c_edge + 0.002) / 0.004);
        float* p = c.at(f, x, y);
        for (int k = 0; k < 3; ++k) p[k] = static_cast<float>(l[k]);
        if (channels == 4) p[3] = 1.0f;
      }
  return c;
}

// ---------------------------------------------------------------------------------------------
// Sampling

namespace {

glm::vec4 texel(const raw_cube& c, int face, int x, int y) noexcept {
  const float* p = c.pixels + ((std::size_t(face) * std::size_t(c.size) + std::size_t(y)) * std::size_t(c.size) +
                               std::size_t(x)) * std::size_t(c.channels);
  return {p[0], p[1], p[2], c.channels == 4 ? p[3] : 1.0f};
}

// The texel that texel (x, y) of `face`, one step outside the face along one axis, is on the
// neighbouring face: the extended texel centre's direction, looked up with the GL table.
glm::vec4 texel_beyond_edge(const raw_cube& c, int face, int x, int y) noexcept {
  const int n = c.size;
  const float u = (2.0f * static_cast<float>(x) + 1.0f) / static_cast<float>(n) - 1.0f;
  const float v = (2.0f * static_cast<float>(y) + 1.0f) / static_cast<float>(n) - 1.0f;
  const cube_coord cc = cube_face_from_direction(cube_face_point(static_cast<cube_face>(face), u, v));
  const int tx = std::clamp(static_cast<int>(std::floor(cc.s * static_cast<float>(n))), 0, n - 1);
  const int ty = std::clamp(static_cast<int>(std::floor(cc.t * static_cast<float>(n))), 0, n - 1);
  return texel(c, static_cast<int>(cc.face), tx, ty);
}

glm::vec4 fetch_seamless(const raw_cube& c, int face, int x, int y) noexcept {
  const int n = c.size;
  const bool out_x = x < 0 || x >= n, out_y = y < 0 || y >= n;
  if (!out_x && !out_y) return texel(c, face, x, y);
  if (out_x != out_y) return texel_beyond_edge(c, face, x, y);
  // Beyond a corner: the mean of the three texels that meet there (what D3D specifies).
  const int cx = std::clamp(x, 0, n - 1), cy = std::clamp(y, 0, n - 1);
  return (texel(c, face, cx, cy) + texel_beyond_edge(c, face, x, cy) + texel_beyond_edge(c, face, cx, y)) / 3.0f;
}

}  // namespace

namespace cubemap_detail {

glm::vec4 sample_bilinear_raw(const raw_cube& c, const glm::vec3& d, cube_sampling mode) noexcept {
  const cube_coord cc = cube_face_from_direction(d);
  const int n = c.size, face = static_cast<int>(cc.face);
  const float fx = cc.s * static_cast<float>(n) - 0.5f, fy = cc.t * static_cast<float>(n) - 0.5f;
  const float flx = std::floor(fx), fly = std::floor(fy);
  const float ax = fx - flx, ay = fy - fly;
  const int x0 = static_cast<int>(flx), y0 = static_cast<int>(fly);
  glm::vec4 t00, t10, t01, t11;
  if (mode == cube_sampling::clamp_per_face || (x0 >= 0 && y0 >= 0 && x0 + 1 < n && y0 + 1 < n)) {
    const int xa = std::clamp(x0, 0, n - 1), xb = std::clamp(x0 + 1, 0, n - 1);
    const int ya = std::clamp(y0, 0, n - 1), yb = std::clamp(y0 + 1, 0, n - 1);
    t00 = texel(c, face, xa, ya);
    t10 = texel(c, face, xb, ya);
    t01 = texel(c, face, xa, yb);
    t11 = texel(c, face, xb, yb);
  } else {
    t00 = fetch_seamless(c, face, x0, y0);
    t10 = fetch_seamless(c, face, x0 + 1, y0);
    t01 = fetch_seamless(c, face, x0, y0 + 1);
    t11 = fetch_seamless(c, face, x0 + 1, y0 + 1);
  }
  return (t00 * (1.0f - ax) + t10 * ax) * (1.0f - ay) + (t01 * (1.0f - ax) + t11 * ax) * ay;
}

glm::vec4 sample_lod_raw(const raw_cube* levels, int level_count, const glm::vec3& d, float lod,
                         cube_sampling mode) noexcept {
  const int last = level_count - 1;
  if (!(lod > 0.0f)) return sample_bilinear_raw(levels[0], d, mode);  // also NaN
  if (lod >= static_cast<float>(last)) return sample_bilinear_raw(levels[last], d, mode);
  const int l0 = static_cast<int>(std::floor(lod));
  const float t = lod - static_cast<float>(l0);
  const glm::vec4 a = sample_bilinear_raw(levels[l0], d, mode);
  if (t == 0.0f) return a;
  return a * (1.0f - t) + sample_bilinear_raw(levels[l0 + 1], d, mode) * t;
}

}  // namespace cubemap_detail

glm::vec4 sample_bilinear(const cube_image& c, const glm::vec3& d, cube_sampling mode) noexcept {
  return sample_bilinear_raw({c.pixels.data(), c.size, c.channels}, d, mode);
}

glm::vec4 sample_lod(const cubemap& map, const glm::vec3& d, float lod, cube_sampling mode) noexcept {
  raw_cube levels[32];
  const int count = std::min(map.level_count(), 32);
  for (int l = 0; l < count; ++l) {
    const cube_image& c = map.levels[std::size_t(l)];
    levels[l] = {c.pixels.data(), c.size, c.channels};
  }
  return sample_lod_raw(levels, count, d, lod, mode);
}

glm::vec4 sample_lod(const cube_level_view* levels, int level_count, const glm::vec3& d, float lod, cube_sampling mode) noexcept {
  return cubemap_detail::sample_lod_raw(levels, level_count, d, lod, mode);
}

glm::vec4 cubemap::sample(const glm::vec3& direction) const noexcept {
  assert(!levels.empty());
  return sample_bilinear(levels[0], direction, cube_sampling::seamless);
}

}  // namespace hemilight
