// measure_seams (seams.hpp): the step of a baked lightmap along its seams, as an engine shows it,
// as the chain check_seam_options -> (seam_mesh of the input) -> find_seams -> sample_pieces ->
// summarise.
#include "checks.hpp"
#include "seam_search.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace hemilight {

namespace bake_detail {

namespace {

void check_seam_options(const seam_options& o) {
  if (!(o.coplanar_degrees > 0.0f && o.coplanar_degrees <= 90.0f))
    throw_invalid_argument("measure_seams: coplanar_degrees " + num(o.coplanar_degrees) + " is not in (0, 90]");
  if (!(o.samples_per_texel >= 0.25f && o.samples_per_texel <= 64.0f))
    throw_invalid_argument("measure_seams: samples_per_texel " + num(o.samples_per_texel) + " is not in [0.25, 64]");
  if (!(o.step_threshold >= 0.0f) || !std::isfinite(o.step_threshold))
    throw_invalid_argument("measure_seams: step_threshold " + num(o.step_threshold) + " must be finite and >= 0");
}

// Checks one page's result: an RGB image and a sampled array of its size.
void check_result_page(const bake_result& r, const std::string& name) {
  const image& e = r.irradiance;
  if (e.channels != 3 || e.width < 1 || e.height < 1 || e.pixels.size() != std::size_t(e.width) * std::size_t(e.height) * 3)
    throw_invalid_argument("measure_seams: " + name + ".irradiance is not an RGB image (" + std::to_string(e.width) + " x " +
                           std::to_string(e.height) + ", " + std::to_string(e.channels) + " channels)");
  if (r.sampled.size() != std::size_t(e.width) * std::size_t(e.height))
    throw_invalid_argument("measure_seams: " + name + ".sampled has " + std::to_string(r.sampled.size()) +
                           " entries, the irradiance " + std::to_string(std::size_t(e.width) * std::size_t(e.height)) + " texels");
  if (!r.valid.empty() && r.valid.size() != r.sampled.size())
    throw_invalid_argument("measure_seams: " + name + ".valid has " + std::to_string(r.valid.size()) + " entries, the irradiance " +
                           std::to_string(r.sampled.size()) + " texels");
}


// A page as the metric reads it: its irradiance and which texels hold a valid sample.
struct page_view {
  const image* irradiance = nullptr;
  const std::vector<std::uint8_t>* valid = nullptr;  // bake_result::valid, or sampled where valid is empty
};

// Luminance of a bilinear lookup at texel coordinates t of a page; false when no texel of its
// footprint (with a nonzero weight) is valid: the side is hidden there (inside geometry).
bool lookup(const page_view& page, const glm::vec2& t, double& y) {
  const image& img = *page.irradiance;
  const page_rect r{0, 0, img.width, img.height};
  const footprint f = bilinear_footprint(r, std::size_t(img.width), t);
  y = bilinear_luminance(f, [&](std::size_t k) { return img.pixels.data() + 3 * k; });
  bool seen = false;
  for (std::size_t k = 0; k < 4; ++k) seen = seen || (f.weight[k] > 0.0f && (*page.valid)[f.texel[k]]);
  return seen;
}

// One class's steps: (relative step, length it stands for) per sample point.
using steps = std::vector<std::pair<double, double>>;

seam_figures summarise(steps s, std::size_t pieces, double length, double threshold) {
  seam_figures f;
  f.pieces = pieces;
  f.samples = s.size();
  f.length_texels = length;
  if (s.empty()) return f;
  std::sort(s.begin(), s.end());
  double w = 0.0, sum2 = 0.0, over = 0.0;
  for (const auto& [d, l] : s) {
    w += l;
    sum2 += l * d * d;
    if (d > double(threshold)) over += l;
  }
  f.rms = w > 0.0 ? std::sqrt(sum2 / w) : 0.0;
  f.max = s.back().first;
  f.step_fraction = w > 0.0 ? over / w : 0.0;
  double run = 0.0;
  f.p95 = s.back().first;
  for (const auto& [d, l] : s) {
    run += l;
    if (run >= 0.95 * w) {
      f.p95 = d;
      break;
    }
  }
  return f;
}

// The relative steps at the sample points of every piece (seams.hpp), summarised per class.
seam_report sample_pieces(const std::vector<seam_piece>& pieces, const std::vector<page_view>& pages, double floor,
                          const seam_options& o) {
  double hidden = 0.0;
  // Per class (coplanar, crease, walled): the steps, the pieces, the length.
  steps s[3];
  std::size_t count[3] = {0, 0, 0};
  double length[3] = {0.0, 0.0, 0.0};
  for (const seam_piece& p : pieces) {
    const auto n = std::size_t(std::max(1.0, std::ceil(double(o.samples_per_texel) * double(p.length_texels))));
    const int c = p.walled ? 2 : p.coplanar ? 0 : 1;
    steps& out = s[c];
    count[c] += 1;
    length[c] += double(p.length_texels);
    for (std::size_t j = 0; j < n; ++j) {
      const float t = (float(j) + 0.5f) / float(n);
      double ya = 0.0, yb = 0.0;
      const bool seen_a = lookup(pages[std::size_t(p.a.page)], p.a.t0 + t * (p.a.t1 - p.a.t0), ya);
      const bool seen_b = lookup(pages[std::size_t(p.b.page)], p.b.t0 + t * (p.b.t1 - p.b.t0), yb);
      if (!seen_a || !seen_b) {
        hidden += double(p.length_texels) / double(n);
        continue;
      }
      const double scale = std::max(0.5 * (ya + yb), floor);
      const double d = scale > 0.0 ? std::fabs(ya - yb) / scale : 0.0;
      out.emplace_back(d, double(p.length_texels) / double(n));
    }
  }
  seam_report r;
  r.floor = floor;
  r.hidden_length_texels = hidden;
  r.coplanar = summarise(std::move(s[0]), count[0], length[0], o.step_threshold);
  r.crease = summarise(std::move(s[1]), count[1], length[1], o.step_threshold);
  r.walled = summarise(std::move(s[2]), count[2], length[2], o.step_threshold);
  return r;
}

// 5% of the mean luminance of the sampled texels of all pages.
double step_floor(const std::vector<const bake_result*>& pages) {
  double sum = 0.0;
  std::size_t n = 0;
  for (const bake_result* r : pages)
    for (std::size_t k = 0; k < r->sampled.size(); ++k)
      if (r->sampled[k]) {
        sum += rgb_luminance(r->irradiance.pixels.data() + 3 * k);
        ++n;
      }
  return n > 0 ? 0.05 * sum / double(n) : 0.0;
}

// A (page) UV within lightmap_uv_tolerance of [0, 1], as the baker takes them: the seams' lengths
// in texels, and so the sample counts, stay bounded by the page.
void check_uv_range(const glm::vec2& uv, const std::string& name) {
  for (int c = 0; c < 2; ++c)
    if (!(uv[c] >= -lightmap_uv_tolerance && uv[c] <= 1.0f + lightmap_uv_tolerance))
      throw_invalid_argument("measure_seams: " + name + (c == 0 ? ".u = " : ".v = ") + num(uv[c]) + " is outside [0, 1]");
}

// What the seam search reads: indices in range, positions, UVs and normals finite.
void check_geometry(const scene_desc& d, const glm::vec3* normals) {
  if (!d.lightmap_uvs) throw_invalid_argument("measure_seams: the scene has no lightmap UVs (scene_desc::lightmap_uvs is null)");
  if (d.triangle_count > 0 && (!d.indices || !d.positions)) throw_invalid_argument("measure_seams: indices or positions is null");
  for (std::size_t i = 0; i < 3 * d.triangle_count; ++i)
    if (d.indices[i] >= d.vertex_count)
      throw_invalid_argument("measure_seams: indices[" + std::to_string(i) + "] = " + std::to_string(d.indices[i]) +
                             " is out of range: " + std::to_string(d.vertex_count) + " vertices");
  const auto finite = [](const auto& v, int n) {
    for (int c = 0; c < n; ++c)
      if (!std::isfinite(v[c])) return false;
    return true;
  };
  for (std::size_t i = 0; i < d.vertex_count; ++i) {
    if (!finite(d.positions[i], 3)) throw_invalid_argument("measure_seams: positions[" + std::to_string(i) + "] is not finite");
    if (!finite(d.lightmap_uvs[i], 2)) throw_invalid_argument("measure_seams: lightmap_uvs[" + std::to_string(i) + "] is not finite");
    check_uv_range(d.lightmap_uvs[i], "lightmap_uvs[" + std::to_string(i) + "]");
    if (normals && !finite(normals[i], 3)) throw_invalid_argument("measure_seams: normals[" + std::to_string(i) + "] is not finite");
  }
}

}  // namespace

}  // namespace bake_detail

seam_report measure_seams(const bake_input& input, const bake_result& result, const seam_options& o) {
  using namespace bake_detail;
  check_seam_options(o);
  check_result_page(result, "result");
  check_geometry(input.scene, input.normals);
  const std::shared_ptr<const scene> walls = scene::create(input.scene);
  const std::vector<seam_piece> pieces =
      lightmap_seams(input, result.irradiance.width, result.irradiance.height, o.coplanar_degrees, *walls);
  return sample_pieces(pieces, {page_view{&result.irradiance, result.valid.empty() ? &result.sampled : &result.valid}},
                       step_floor({&result}), o);
}

seam_report measure_seams(const scene_bake_input& input, const scene_bake_result& result, const seam_options& o) {
  using namespace bake_detail;
  check_seam_options(o);
  if (result.pages.size() != input.pages.size())
    throw_invalid_argument("measure_seams: the result has " + std::to_string(result.pages.size()) + " pages, the input " +
                           std::to_string(input.pages.size()));
  std::vector<page_view> images;
  std::vector<const bake_result*> pages;
  seam_mesh m;
  for (std::size_t p = 0; p < input.pages.size(); ++p) {
    const bake_result& r = result.pages[p];
    check_result_page(r, "result.pages[" + std::to_string(p) + "]");
    if (r.irradiance.width != input.pages[p].width || r.irradiance.height != input.pages[p].height)
      throw_invalid_argument("measure_seams: result.pages[" + std::to_string(p) + "] is " + std::to_string(r.irradiance.width) + " x " +
                             std::to_string(r.irradiance.height) + ", the input's page " + std::to_string(input.pages[p].width) +
                             " x " + std::to_string(input.pages[p].height));
    images.push_back(page_view{&r.irradiance, r.valid.empty() ? &r.sampled : &r.valid});
    pages.push_back(&r);
    m.pages.push_back(page_rect{0, 0, r.irradiance.width, r.irradiance.height});
  }
  const scene_desc& d = input.geometry.scene;
  check_geometry(d, input.geometry.normals);
  std::vector<glm::vec2> uvs(3 * d.triangle_count);
  std::vector<int> page_of(d.triangle_count, -1);
  std::size_t next = 0;
  for (std::size_t k = 0; k < input.meshes.size(); ++k) {
    const bake_mesh& mesh = input.meshes[k];
    if (mesh.first_triangle != next || mesh.triangle_count > d.triangle_count - next)
      throw_invalid_argument("measure_seams: meshes[" + std::to_string(k) + "] does not start where the previous mesh ends or runs "
                             "past the scene's triangles");
    if (mesh.page < -1 || (mesh.page >= 0 && std::size_t(mesh.page) >= input.pages.size()))
      throw_invalid_argument("measure_seams: meshes[" + std::to_string(k) + "].page = " + std::to_string(mesh.page) +
                             " is not -1 or a page index");
    for (int c = 0; c < 2; ++c)
      if (!std::isfinite(mesh.uv_scale[c]) || !std::isfinite(mesh.uv_offset[c]))
        throw_invalid_argument("measure_seams: meshes[" + std::to_string(k) + "]: uv_scale or uv_offset is not finite");
    for (std::size_t t = next; t < next + mesh.triangle_count; ++t) {
      page_of[t] = mesh.page;
      for (std::size_t c = 0; c < 3; ++c) {
        uvs[3 * t + c] = d.lightmap_uvs[d.indices[3 * t + c]] * mesh.uv_scale + mesh.uv_offset;
        if (mesh.page >= 0)
          check_uv_range(uvs[3 * t + c], "meshes[" + std::to_string(k) + "]: the page UV of vertex " + std::to_string(d.indices[3 * t + c]));
      }
    }
    next += mesh.triangle_count;
  }
  if (next != d.triangle_count)
    throw_invalid_argument("measure_seams: the meshes cover " + std::to_string(next) + " of the scene's " +
                           std::to_string(d.triangle_count) + " triangles");
  m.positions = d.positions;
  m.vertex_count = d.vertex_count;
  m.indices = d.indices;
  m.triangle_count = d.triangle_count;
  m.normals = input.geometry.normals;
  m.corner_uvs = uvs.data();
  m.triangle_page = page_of.data();
  const std::shared_ptr<const scene> walls = scene::create(d);
  const std::vector<seam_piece> pieces = find_seams(m, o.coplanar_degrees, *walls);
  return sample_pieces(pieces, images, step_floor(pages), o);
}

}  // namespace hemilight
