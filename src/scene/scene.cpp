#include "hemilight/scene.hpp"
#include "scene_access.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <unordered_map>

namespace hemilight {

namespace {

const char* const axis_name[3] = {"x", "y", "z"};

void check_non_negative(const std::string& name, const glm::vec3& v) {
  for (int c = 0; c < 3; ++c)
    if (!(v[c] >= 0.0f && v[c] <= max_radiance))
      throw_invalid_argument("scene::create: " + name + "." + "rgb"[c] + " is " + std::to_string(v[c]) +
                             "; it must be finite, >= 0 and at most 1e30 (max_radiance)");
}

}  // namespace

bool is_degenerate_triangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) noexcept {
  const glm::dvec3 pa(a), pb(b), pc(c);
  const glm::dvec3 ab = pb - pa, bc = pc - pb, ca = pa - pc;
  const double longest = std::sqrt(std::max({glm::dot(ab, ab), glm::dot(bc, bc), glm::dot(ca, ca)}));
  const glm::dvec3 m3 = glm::max(glm::abs(pa), glm::max(glm::abs(pb), glm::abs(pc)));
  const double m = std::max({m3.x, m3.y, m3.z});
  const double twice_area = glm::length(glm::cross(ab, pc - pa));
  // Written so that NaN (and L = 0: coincident vertices) gives true.
  return !(twice_area > degenerate_height_tolerance * longest * m) || !std::isfinite(twice_area + m);
}

scene_desc scene_mesh::desc() const {
  scene_desc d;
  d.positions = positions.data();
  d.vertex_count = positions.size();
  d.indices = indices.data();
  d.triangle_count = indices.size() / 3;
  d.materials = materials.data();
  d.lightmap_uvs = lightmap_uvs.empty() ? nullptr : lightmap_uvs.data();
  d.sky_radiance = sky_radiance;
  d.texcoords = texcoords.empty() ? nullptr : texcoords.data();
  alpha_views.clear();
  for (const alpha_image& a : alpha_textures) alpha_views.push_back({a.values.data(), a.width, a.height});
  d.alpha_textures = alpha_views.empty() ? nullptr : alpha_views.data();
  d.alpha_texture_count = alpha_views.size();
  return d;
}

void scene_mesh::add_triangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const material& m) {
  const auto base = static_cast<std::uint32_t>(positions.size());
  positions.insert(positions.end(), {a, b, c});
  indices.insert(indices.end(), {base, base + 1, base + 2});
  materials.push_back(m);
}

void scene_mesh::add_quad(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d,
                          const material& m) {
  add_grid(a, b, c, d, 1, 1, m);
}

void scene_mesh::add_grid(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d, int nu,
                          int nv, const material& m, bool flip) {
  const auto base = static_cast<std::uint32_t>(positions.size());
  const auto lerp = [](const glm::vec3& p, const glm::vec3& q, float s) { return (1.0f - s) * p + s * q; };
  for (int j = 0; j <= nv; ++j) {
    const float t = static_cast<float>(j) / static_cast<float>(nv);
    // Edge points first (a-d and b-c), then across: grids sharing an edge agree bit for bit.
    const glm::vec3 left = lerp(a, d, t), right = lerp(b, c, t);
    for (int i = 0; i <= nu; ++i) positions.push_back(lerp(left, right, static_cast<float>(i) / static_cast<float>(nu)));
  }
  const auto row = static_cast<std::uint32_t>(nu + 1);
  for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(nv); ++j)
    for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(nu); ++i) {
      const std::uint32_t p00 = base + j * row + i, p10 = p00 + 1, p01 = p00 + row, p11 = p01 + 1;
      if (flip)
        indices.insert(indices.end(), {p00, p11, p10, p00, p01, p11});
      else
        indices.insert(indices.end(), {p00, p10, p11, p00, p11, p01});
      materials.push_back(m);
      materials.push_back(m);
    }
}

void scene_mesh::add_box(const glm::vec3& lo, const glm::vec3& hi, const material& m, bool inward) {
  const glm::vec3 p[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                          {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  // Counter-clockwise seen from outside.
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 4, 7, 3}, {1, 2, 6, 5}};
  for (const auto& f : faces) {
    if (inward)
      add_quad(p[f[3]], p[f[2]], p[f[1]], p[f[0]], m);
    else
      add_quad(p[f[0]], p[f[1]], p[f[2]], p[f[3]], m);
  }
}

std::shared_ptr<const scene> scene::create(const scene_desc& desc) {
  if (desc.vertex_count > max_scene_elements)
    throw error(status::out_of_memory, "scene::create: vertex_count " + std::to_string(desc.vertex_count) +
                                           " is over the limit of " + std::to_string(max_scene_elements));
  if (desc.triangle_count > max_scene_elements)
    throw error(status::out_of_memory, "scene::create: triangle_count " + std::to_string(desc.triangle_count) +
                                           " is over the limit of " + std::to_string(max_scene_elements));
  if (desc.vertex_count > 0 && !desc.positions)
    throw_invalid_argument("scene::create: positions is null but vertex_count is " + std::to_string(desc.vertex_count));
  if (desc.triangle_count > 0 && !desc.indices)
    throw_invalid_argument("scene::create: indices is null but triangle_count is " +
                           std::to_string(desc.triangle_count));
  check_non_negative("sky_radiance", desc.sky_radiance);

  std::shared_ptr<scene> s(new scene());
  s->sky_ = desc.sky_radiance;
  s->positions_.assign(desc.positions, desc.positions + desc.vertex_count);
  s->lo_ = glm::vec3(std::numeric_limits<float>::infinity());
  s->hi_ = -s->lo_;
  for (std::size_t i = 0; i < desc.vertex_count; ++i) {
    const glm::vec3& p = s->positions_[i];
    for (int c = 0; c < 3; ++c)
      if (!(std::fabs(p[c]) <= max_coordinate))
        throw_invalid_argument("scene::create: positions[" + std::to_string(i) + "]." + axis_name[c] + " is " +
                               std::to_string(p[c]) + "; positions must be finite and at most 1e18 in magnitude");
    s->lo_ = glm::min(s->lo_, p);
    s->hi_ = glm::max(s->hi_, p);
  }
  // Diagonal in double: a float could overflow for coordinates near FLT_MAX.
  if (desc.vertex_count > 0) {
    const glm::dvec3 diag = glm::dvec3(s->hi_) - glm::dvec3(s->lo_);
    s->size_ = static_cast<float>(std::min(glm::length(diag), double(std::numeric_limits<float>::max())));
  }
  if (desc.lightmap_uvs) {
    s->uvs_.assign(desc.lightmap_uvs, desc.lightmap_uvs + desc.vertex_count);
    for (std::size_t i = 0; i < s->uvs_.size(); ++i)
      for (int c = 0; c < 2; ++c)
        if (!std::isfinite(s->uvs_[i][c]))
          throw_invalid_argument("scene::create: lightmap_uvs[" + std::to_string(i) + "]." + "uv"[c] + " is " +
                                 std::to_string(s->uvs_[i][c]) + "; UVs must be finite");
  }
  s->indices_.assign(desc.indices, desc.indices + 3 * desc.triangle_count);
  for (std::size_t i = 0; i < s->indices_.size(); ++i)
    if (s->indices_[i] >= desc.vertex_count)
      throw_invalid_argument("scene::create: indices[" + std::to_string(i) + "] = " + std::to_string(s->indices_[i]) +
                             " is out of range: " + std::to_string(desc.vertex_count) + " vertices");
  if (desc.materials) {
    s->materials_.assign(desc.materials, desc.materials + desc.triangle_count);
    for (std::size_t i = 0; i < s->materials_.size(); ++i) {
      check_non_negative("materials[" + std::to_string(i) + "].emission", s->materials_[i].emission);
      check_non_negative("materials[" + std::to_string(i) + "].albedo", s->materials_[i].albedo);
    }
  } else {
    s->materials_.assign(desc.triangle_count, material{});
  }
  s->index_emissions();
  s->copy_opacity(desc);

  s->triangles_.reserve(desc.triangle_count);
  for (std::size_t i = 0; i < desc.triangle_count; ++i) {
    const glm::vec3& a = s->positions_[s->indices_[3 * i]];
    const glm::vec3& b = s->positions_[s->indices_[3 * i + 1]];
    const glm::vec3& c = s->positions_[s->indices_[3 * i + 2]];
    if (is_degenerate_triangle(a, b, c)) continue;  // no area at float precision: never drawn
    const material& m = s->materials_[i];
    if (m.opacity == surface_opacity::opaque)
      s->triangles_.push_back({a, b, c, static_cast<std::uint32_t>(i)});
    else if (m.opacity == surface_opacity::translucent || m.alpha_texture >= 0 || m.alpha >= m.alpha_cutoff)
      s->see_through_.push_back({a, b, c, static_cast<std::uint32_t>(i)});
  }
  s->build_bvh();
  for (auto& slot : s->derived_) slot = std::make_shared<detail::lazy_slot>();  // filled on first use (scene_access.hpp)
  return s;
}

void scene::copy_opacity(const scene_desc& desc) {
  // Checks first: the textures, then each material's opacity fields.
  if (desc.alpha_texture_count > 0 && !desc.alpha_textures)
    throw_invalid_argument("scene::create: alpha_textures is null but alpha_texture_count is " +
                           std::to_string(desc.alpha_texture_count));
  for (std::size_t t = 0; t < desc.alpha_texture_count; ++t) {
    const alpha_texture& a = desc.alpha_textures[t];
    const std::string name = "scene::create: alpha_textures[" + std::to_string(t) + "]";
    if (a.width < 1 || a.height < 1 || a.width > 16384 || a.height > 16384)
      throw_invalid_argument(name + " size " + std::to_string(a.width) + " x " + std::to_string(a.height) +
                             " is invalid; each side must be in [1, 16384]");
    if (!a.values) throw_invalid_argument(name + ".values is null");
  }
  bool reads_texcoords = false;
  for (std::size_t i = 0; i < materials_.size(); ++i) {
    const material& m = materials_[i];
    const std::string name = "scene::create: materials[" + std::to_string(i) + "]";
    const auto unit = [&](const char* field, float v) {
      if (!(v >= 0.0f && v <= 1.0f))
        throw_invalid_argument(name + "." + field + " is " + std::to_string(v) + "; it must be in [0, 1]");
    };
    switch (m.opacity) {
      case surface_opacity::opaque: break;
      case surface_opacity::alpha_tested:
        unit("alpha", m.alpha);
        unit("alpha_cutoff", m.alpha_cutoff);
        if (m.alpha_texture < -1 || (m.alpha_texture >= 0 && std::size_t(m.alpha_texture) >= desc.alpha_texture_count))
          throw_invalid_argument(name + ".alpha_texture = " + std::to_string(m.alpha_texture) +
                                 " is not -1 or an index into alpha_textures (" +
                                 std::to_string(desc.alpha_texture_count) + " alpha textures)");
        if (m.alpha_texture >= 0) reads_texcoords = true;
        break;
      case surface_opacity::translucent:
        unit("transmittance.r", m.transmittance.x);
        unit("transmittance.g", m.transmittance.y);
        unit("transmittance.b", m.transmittance.z);
        break;
      default:
        throw_invalid_argument(name + ".opacity is " + std::to_string(static_cast<int>(m.opacity)) +
                               "; it must be opaque (0), alpha_tested (1) or translucent (2)");
    }
  }
  if (!reads_texcoords) return;
  if (!desc.texcoords)
    throw_invalid_argument("scene::create: texcoords is null but a material reads an alpha texture");
  texcoords_.assign(desc.texcoords, desc.texcoords + desc.vertex_count);
  for (std::size_t i = 0; i < texcoords_.size(); ++i)
    for (int c = 0; c < 2; ++c)
      if (!std::isfinite(texcoords_[i][c]))
        throw_invalid_argument("scene::create: texcoords[" + std::to_string(i) + "]." + "uv"[c] + " is " +
                               std::to_string(texcoords_[i][c]) + "; texcoords must be finite");
  alpha_textures_.resize(desc.alpha_texture_count);
  for (std::size_t t = 0; t < desc.alpha_texture_count; ++t) {
    const alpha_texture& a = desc.alpha_textures[t];
    alpha_textures_[t].width = a.width;
    alpha_textures_[t].height = a.height;
    alpha_textures_[t].values.assign(a.values, a.values + std::size_t(a.width) * std::size_t(a.height));
  }
}

bool scene::alpha_present(std::size_t i, float b1, float b2) const noexcept {
  const material& m = materials_[i];
  if (m.opacity != surface_opacity::alpha_tested) return true;
  if (m.alpha_texture < 0) return m.alpha >= m.alpha_cutoff;
  const std::uint32_t* v = indices_.data() + 3 * i;
  const glm::vec2& t0 = texcoords_[v[0]];
  const glm::vec2 uv = t0 + b1 * (texcoords_[v[1]] - t0) + b2 * (texcoords_[v[2]] - t0);
  const alpha_image& a = alpha_textures_[static_cast<std::size_t>(m.alpha_texture)];
  // Repeat wrap: continuous texel coordinates (centres at integers) reduced into [0, size).
  const auto wrap = [](float x, int size) {
    const double s = static_cast<double>(size), c = static_cast<double>(x) * s - 0.5;
    double r = c - s * std::floor(c / s);
    if (!(r >= 0.0 && r < s)) r = 0.0;  // rounding at the top end, or NaN
    return r;
  };
  const double px = wrap(uv.x, a.width), py = wrap(uv.y, a.height);
  const int x0 = static_cast<int>(px), y0 = static_cast<int>(py);
  const int x1 = x0 + 1 == a.width ? 0 : x0 + 1, y1 = y0 + 1 == a.height ? 0 : y0 + 1;
  const double fx = px - x0, fy = py - y0;
  const auto at = [&](int x, int y) {
    return static_cast<double>(a.values[static_cast<std::size_t>(y) * static_cast<std::size_t>(a.width) + static_cast<std::size_t>(x)]);
  };
  const double top = (1.0 - fx) * at(x0, y0) + fx * at(x1, y0);
  const double bottom = (1.0 - fx) * at(x0, y1) + fx * at(x1, y1);
  const double value = ((1.0 - fy) * top + fy * bottom) / 255.0;
  return static_cast<double>(m.alpha) * value >= static_cast<double>(m.alpha_cutoff);
}

void scene::index_emissions() {
  // Keyed by the bits: -0 and +0 (both valid emissions) stay apart, so every texel gets exactly
  // its material's value. Neighbouring triangles mostly share a material: checked first.
  struct bits_hash {
    std::size_t operator()(const std::array<std::uint32_t, 3>& k) const noexcept {
      return (k[0] * 0x9e3779b1u) ^ (k[1] * 0x85ebca77u) ^ (k[2] * 0xc2b2ae3du);
    }
  };
  std::unordered_map<std::array<std::uint32_t, 3>, std::uint32_t, bits_hash> index;
  emissions_.clear();
  emission_index_.resize(materials_.size());
  std::array<std::uint32_t, 3> last{};
  std::uint32_t last_index = 0;
  for (std::size_t i = 0; i < materials_.size(); ++i) {
    std::array<std::uint32_t, 3> key;
    std::memcpy(key.data(), &materials_[i].emission, sizeof key);
    if (i == 0 || key != last) {
      const auto found = index.emplace(key, static_cast<std::uint32_t>(emissions_.size()));
      if (found.second) emissions_.push_back(materials_[i].emission);
      last = key;
      last_index = found.first->second;
    }
    emission_index_[i] = last_index;
  }
}

void scene::build_bvh() {
  nodes_.clear();
  coordinates_.assign(9 * 8, 0.0f);  // scene_access::vertex_coordinates of an empty scene: the padding only
  if (triangles_.empty()) return;
  const std::size_t count = triangles_.size();
  std::vector<glm::vec3> centroid(count), tlo(count), thi(count);
  std::vector<std::uint32_t> order(count);
  for (std::size_t i = 0; i < count; ++i) {
    const triangle& t = triangles_[i];
    tlo[i] = glm::min(t.v0, glm::min(t.v1, t.v2));
    thi[i] = glm::max(t.v0, glm::max(t.v1, t.v2));
    centroid[i] = 0.5f * tlo[i] + 0.5f * thi[i];
    order[i] = static_cast<std::uint32_t>(i);
  }
  nodes_.reserve(2 * (count / max_leaf_triangles + 1));
  // Split near the median on the longest axis of the centroids' box. Explicit stack of (node, begin, end).
  struct task {
    std::size_t node, begin, end;
  };
  std::vector<task> stack;
  nodes_.push_back({});
  stack.push_back({0, 0, count});
  while (!stack.empty()) {
    const task tk = stack.back();
    stack.pop_back();
    glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
    glm::vec3 clo = lo, chi = hi;
    for (std::size_t i = tk.begin; i < tk.end; ++i) {
      lo = glm::min(lo, tlo[order[i]]);
      hi = glm::max(hi, thi[order[i]]);
      clo = glm::min(clo, centroid[order[i]]);
      chi = glm::max(chi, centroid[order[i]]);
    }
    nodes_[tk.node].lo = lo;
    nodes_[tk.node].hi = hi;
    const std::size_t n = tk.end - tk.begin;
    if (n <= max_leaf_triangles) {
      nodes_[tk.node].first = static_cast<std::uint32_t>(tk.begin);
      nodes_[tk.node].count = static_cast<std::uint32_t>(n);
      continue;
    }
    const glm::vec3 ext = chi - clo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    // Split at a multiple of the leaf size near the median: leaves then hold a full
    // max_leaf_triangles (four full groups of eight for the AVX2 set-up) except one per
    // subtree, where a plain median split leaves ~17 (two full groups and a nearly empty one).
    const std::size_t leaves = (n + max_leaf_triangles - 1) / max_leaf_triangles;
    const std::size_t mid = tk.begin + leaves / 2 * max_leaf_triangles;
    const auto first = order.begin() + static_cast<std::ptrdiff_t>(tk.begin);
    std::nth_element(first, order.begin() + static_cast<std::ptrdiff_t>(mid),
                     order.begin() + static_cast<std::ptrdiff_t>(tk.end),
                     [&](std::uint32_t x, std::uint32_t y) {
                       const float cx = centroid[x][axis], cy = centroid[y][axis];
                       return cx < cy || (cx == cy && x < y);  // deterministic order for ties
                     });
    // Children are allocated as a pair: left, then right = left + 1.
    const std::size_t left = nodes_.size();
    nodes_.push_back({});
    const std::size_t right = nodes_.size();
    nodes_.push_back({});
    nodes_[tk.node].count = 0;
    nodes_[tk.node].first = static_cast<std::uint32_t>(left);
    stack.push_back({right, mid, tk.end});
    stack.push_back({left, tk.begin, mid});
  }
  std::vector<triangle> sorted(count);
  for (std::size_t i = 0; i < count; ++i) sorted[i] = triangles_[order[i]];
  triangles_.swap(sorted);
  // The same coordinates, one array each (detail::scene_access::vertex_coordinates), zero-padded by 8.
  const std::size_t stride = count + 8;
  coordinates_.assign(9 * stride, 0.0f);
  for (std::size_t i = 0; i < count; ++i) {
    const glm::vec3* v[3] = {&triangles_[i].v0, &triangles_[i].v1, &triangles_[i].v2};
    for (int k = 0; k < 9; ++k) coordinates_[static_cast<std::size_t>(k) * stride + i] = (*v[k / 3])[k % 3];
  }
}

}  // namespace hemilight
