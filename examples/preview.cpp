// Rendered previews of baked scenes (preview.hpp): the pages' radiance in an atlas with guard
// texels, the scene with atlas UVs, and the top face of a hemicube at the eye.
#include "preview.hpp"

#include "hemilight/raster.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace hemilight::preview {

namespace {

constexpr float pi_f = 3.14159265358979323846f;

// The scene as the preview renders it: per-corner vertices with UVs in an atlas of the pages
// (stacked vertically, one guard row above and below each page and a guard column right of
// narrower ones, copies of the page's edge: clamp-to-edge per page), plus a 2 x 2 black block
// for occluders.
struct preview_scene {
  std::shared_ptr<const scene> sc;
  image atlas;
};

preview_scene make_preview_scene(const scene_bake_input& in, const std::vector<image>& radiance) {
  const scene_desc& d = in.geometry.scene;
  int width = 2;
  for (const lightmap_page& p : in.pages) width = std::max(width, p.width + 1);
  std::vector<int> page_y;
  int rows = 0;
  for (const lightmap_page& p : in.pages) {
    page_y.push_back(rows + 1);
    rows += p.height + 2;
  }
  const int black_y = rows;
  rows += 2;
  preview_scene ps;
  ps.atlas = image::make(width, rows, 3);
  for (std::size_t p = 0; p < in.pages.size(); ++p) {
    const lightmap_page& page = in.pages[p];
    for (int y = -1; y <= page.height; ++y)
      for (int x = 0; x <= page.width; ++x) {
        const int sx = std::min(x, page.width - 1), sy = std::clamp(y, 0, page.height - 1);
        std::memcpy(ps.atlas.at(x, page_y[p] + y), radiance[p].at(sx, sy), 3 * sizeof(float));
      }
  }
  std::vector<glm::vec3> positions;
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> indices;
  positions.reserve(3 * d.triangle_count);
  uvs.reserve(3 * d.triangle_count);
  for (const bake_mesh& m : in.meshes)
    for (std::size_t t = m.first_triangle; t < m.first_triangle + m.triangle_count; ++t)
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t v = d.indices[3 * t + std::size_t(c)];
        glm::vec2 uv(1.0f / float(width), float(black_y + 1) / float(rows));  // the black block's centre
        if (m.page >= 0) {
          const lightmap_page& page = in.pages[std::size_t(m.page)];
          const glm::vec2 q = d.lightmap_uvs[v] * m.uv_scale + m.uv_offset;
          uv = glm::vec2(q.x * float(page.width) / float(width), (q.y * float(page.height) + float(page_y[std::size_t(m.page)])) / float(rows));
        }
        indices.push_back(std::uint32_t(positions.size()));
        positions.push_back(d.positions[v]);
        uvs.push_back(uv);
      }
  scene_desc desc;
  desc.positions = positions.data();
  desc.vertex_count = positions.size();
  desc.indices = indices.data();
  desc.triangle_count = d.triangle_count;
  desc.materials = d.materials;
  desc.lightmap_uvs = uvs.data();
  desc.sky_radiance = d.sky_radiance;
  ps.sc = scene::create(desc);
  return ps;
}

// The hemicube frame of a camera: n towards the target, t to the right, b downwards (so the top
// face's rows run from the top of the picture down), right-handed.
frame camera_frame(const camera& cam) {
  const glm::vec3 n = glm::normalize(cam.target - cam.eye);
  const glm::vec3 up = std::fabs(n.y) > 0.999f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  const glm::vec3 t = glm::normalize(glm::cross(n, up));
  return frame{t, glm::cross(n, t), n};
}

void check_camera(const camera& cam) {
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(cam.eye[c]) || !std::isfinite(cam.target[c])) throw_invalid_argument("preview: the camera is not finite");
  if (!(glm::length(cam.target - cam.eye) > 0.0f)) throw_invalid_argument("preview: the camera's eye and target coincide");
  if (!(cam.fov_degrees > 0.0f && cam.fov_degrees <= 90.0f))
    throw_invalid_argument("preview: field of view " + std::to_string(cam.fov_degrees) + " is not in (0, 90] degrees");
}

// The hemicube resolution whose top face, cropped to `size` texels, spans the camera's field of
// view, and the first column/row of that crop.
void crop_of(const camera& cam, int size, int& n, int& first) {
  const double f = std::tan(double(cam.fov_degrees) * 3.14159265358979323846 / 360.0);
  n = 2 * int(std::ceil(double(size) / (2.0 * f)));
  n = std::max(n, size + (size % 2));
  if (n > 4096)
    throw_invalid_argument("preview: a " + std::to_string(size) + "-pixel picture at " + std::to_string(cam.fov_degrees) +
                           " degrees needs a hemicube of " + std::to_string(n) + " > 4096 texels: widen the field of view");
  first = (n - size) / 2;
}

}  // namespace

bool parse_numbers(const std::string& text, std::vector<float>& out) {
  out.clear();
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t comma = text.find(',', at);
    const std::string item = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    char* end = nullptr;
    const float x = std::strtof(item.c_str(), &end);
    if (item.empty() || *end || !std::isfinite(x)) return false;
    out.push_back(x);
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  return true;
}

bool parse_camera(const std::string& text, camera& out) {
  std::vector<float> v;
  if (!parse_numbers(text, v) || (v.size() != 6 && v.size() != 7)) return false;
  camera c;
  c.eye = {v[0], v[1], v[2]};
  c.target = {v[3], v[4], v[5]};
  if (v.size() == 7) c.fov_degrees = v[6];
  if (!(c.fov_degrees > 0.0f && c.fov_degrees <= 90.0f) || !(glm::length(c.target - c.eye) > 0.0f)) return false;
  out = c;
  return true;
}

std::vector<image> page_radiance(const scene_bake_input& in, const scene_bake_result& result) {
  const scene_desc& d = in.geometry.scene;
  std::vector<image> out;
  for (std::size_t p = 0; p < in.pages.size(); ++p) {
    const lightmap_page& page = in.pages[p];
    const std::size_t texels = std::size_t(page.width) * std::size_t(page.height);
    // Area-weighted materials of the page's triangles per texel (exact clipped areas).
    std::vector<glm::dvec3> albedo(texels, glm::dvec3(0.0)), emission(texels, glm::dvec3(0.0));
    std::vector<double> weight(texels, 0.0);
    for (const bake_mesh& m : in.meshes) {
      if (m.page != int(p)) continue;
      for (std::size_t t = m.first_triangle; t < m.first_triangle + m.triangle_count; ++t) {
        glm::vec2 q[3];
        for (int c = 0; c < 3; ++c)
          q[c] = (d.lightmap_uvs[d.indices[3 * t + std::size_t(c)]] * m.uv_scale + m.uv_offset) * glm::vec2(page.width, page.height);
        const material mat = d.materials ? d.materials[t] : material{};
        const int x0 = std::clamp(int(std::floor(std::min({q[0].x, q[1].x, q[2].x}))), 0, page.width - 1);
        const int x1 = std::clamp(int(std::ceil(std::max({q[0].x, q[1].x, q[2].x}))) - 1, 0, page.width - 1);
        const int y0 = std::clamp(int(std::floor(std::min({q[0].y, q[1].y, q[2].y}))), 0, page.height - 1);
        const int y1 = std::clamp(int(std::ceil(std::max({q[0].y, q[1].y, q[2].y}))) - 1, 0, page.height - 1);
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x) {
            const float a = clip_triangle_to_texel(q[0], q[1], q[2], x, y).area;
            if (!(a > 0.0f)) continue;
            const std::size_t k = std::size_t(y) * std::size_t(page.width) + std::size_t(x);
            albedo[k] += double(a) * glm::dvec3(mat.albedo);
            emission[k] += double(a) * glm::dvec3(mat.emission);
            weight[k] += double(a);
          }
      }
    }
    image r = image::make(page.width, page.height, 3);
    std::vector<std::uint8_t> filled(texels, 0);
    const image& e = result.pages[p].irradiance;
    for (std::size_t k = 0; k < texels; ++k) {
      if (!(weight[k] > 0.0)) continue;
      const glm::vec3 a = page.albedo.width > 0 ? glm::vec3(page.albedo.pixels[3 * k], page.albedo.pixels[3 * k + 1], page.albedo.pixels[3 * k + 2])
                                                : glm::vec3(albedo[k] / weight[k]);
      const glm::vec3 em = page.emission.width > 0
                               ? glm::vec3(page.emission.pixels[3 * k], page.emission.pixels[3 * k + 1], page.emission.pixels[3 * k + 2])
                               : glm::vec3(emission[k] / weight[k]);
      const glm::vec3 l = em + a * glm::vec3(e.pixels[3 * k], e.pixels[3 * k + 1], e.pixels[3 * k + 2]) / pi_f;
      std::memcpy(r.pixels.data() + 3 * k, &l, sizeof l);
      filled[k] = 1;
    }
    dilate(r, filled, 2);
    out.push_back(std::move(r));
  }
  return out;
}

image render(const scene_bake_input& in, const std::vector<image>& radiance, const camera& cam, int size) {
  if (size < 16 || size > 4096) throw_invalid_argument("preview: size " + std::to_string(size) + " is not in [16, 4096]");
  check_camera(cam);
  int n = 0, first = 0;
  crop_of(cam, size, n, first);
  const preview_scene ps = make_preview_scene(in, radiance);
  hemicube_rasterizer rasterizer(ps.sc);
  hemicube_buffer buf;
  const radiance_texture texture(ps.atlas);
  rasterizer.render(cam.eye, camera_frame(cam), n, buf, &texture);
  image picture = image::make(size, size, 3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const glm::vec3 l = buf.radiance_at(std::size_t(first + y) * std::size_t(n) + std::size_t(first + x));  // top face
      std::memcpy(picture.at(x, y), &l, sizeof l);
    }
  return picture;
}

camera default_camera(const scene_bake_input& in, const std::vector<image>& radiance) {
  const preview_scene ps = make_preview_scene(in, radiance);
  const glm::vec3 lo = ps.sc->bounds_lo(), hi = ps.sc->bounds_hi(), c = 0.5f * (lo + hi), ext = hi - lo;
  const float radius = std::max(0.5f * glm::length(ext), 1e-6f);
  std::vector<camera> candidates;
  for (const glm::vec3 dir : {glm::vec3(1, 0.6f, 1), glm::vec3(-1, 0.6f, 1), glm::vec3(1, 0.6f, -1), glm::vec3(-1, 0.6f, -1)}) {
    camera cam;
    cam.target = c;
    cam.eye = c + glm::normalize(dir) * (1.05f * radius / 0.5f);  // the bounding sphere fits 60 degrees
    cam.fov_degrees = 60.0f;
    candidates.push_back(cam);
  }
  for (const glm::vec3 axis : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::vec3(-1, 0, 0)}) {
    camera cam;
    const glm::vec3 half = 0.42f * ext * glm::abs(axis);
    cam.eye = c + half * axis + glm::vec3(0.0f, 0.1f * ext.y, 0.0f);
    cam.target = c - half * axis;
    cam.fov_degrees = 75.0f;
    if (glm::length(cam.target - cam.eye) > 0.0f) candidates.push_back(cam);
  }
  hemicube_rasterizer rasterizer(ps.sc);
  hemicube_buffer buf;
  camera best = candidates.front();
  double best_score = -1.0;
  for (const camera& cam : candidates) {
    const int n = 64;
    const float f = std::tan(cam.fov_degrees * pi_f / 360.0f);
    const int m = std::max(2, int(std::lround(f * n))), first = (n - m) / 2;
    rasterizer.render(cam.eye, camera_frame(cam), n, buf);
    std::size_t front = 0;
    for (int y = first; y < first + m; ++y)
      for (int x = first; x < first + m; ++x) front += buf.flags[std::size_t(y) * std::size_t(n) + std::size_t(x)] == texel_hit_front ? 1u : 0u;
    const double score = double(front) / double(m * m);
    if (score > best_score) {
      best_score = score;
      best = cam;
    }
  }
  return best;
}

void write_png(const std::string& path, const image& picture) {
  double sum = 0.0;
  const std::size_t pixels = picture.pixels.size() / 3;
  for (std::size_t k = 0; k < pixels; ++k)
    sum += 0.2126 * picture.pixels[3 * k] + 0.7152 * picture.pixels[3 * k + 1] + 0.0722 * picture.pixels[3 * k + 2];
  write_png(path, picture, pixels ? sum / double(pixels) : 0.0);
}

void write_png(const std::string& path, const image& picture, double mean) {
  const double k = mean > 0.0 ? 0.5 / mean : 1.0;
  std::vector<unsigned char> rgb(picture.pixels.size());
  for (std::size_t i = 0; i < picture.pixels.size(); ++i) {
    const double x = std::max(0.0, double(picture.pixels[i])) * k;
    const double t = x / (1.0 + x);
    const double s = t <= 0.0031308 ? 12.92 * t : 1.055 * std::pow(t, 1.0 / 2.4) - 0.055;
    rgb[i] = static_cast<unsigned char>(std::lround(std::clamp(s, 0.0, 1.0) * 255.0));
  }
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  img.width = png_uint_32(picture.width);
  img.height = png_uint_32(picture.height);
  img.format = PNG_FORMAT_RGB;
  if (!png_image_write_to_file(&img, path.c_str(), 0, rgb.data(), 0, nullptr))
    throw std::runtime_error("cannot write '" + path + "': " + img.message);
}

}  // namespace hemilight::preview
