// bake_scene (bake.hpp): several lightmap pages baked as one atlas (pages stacked with guard
// rows, occluder-only meshes as 2 x 2 blocks of their material), as a chain of named stages:
//   check_scene_input -> make_scene_geometry -> make_scene_atlas -> combined_scene (atlas_uvs)
//   -> atlas_samples (per page: page_triangles, compute_sparse_samples, append_page_samples)
//   -> page_materials -> bake_samples -> crop_page per page
#include "checks.hpp"
#include "coverage.hpp"
#include "pipeline.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <type_traits>

namespace hemilight {

namespace bake_detail {

namespace {

// Checks a page's optional material image: its size, channels and every value.
void check_page_image(const char* who, std::size_t p, const char* name, const image& img, const lightmap_page& page, float hi) {
  if (img.width == 0 && img.height == 0 && img.pixels.empty()) return;
  const std::string what = std::string(who) + ": pages[" + std::to_string(p) + "]." + name;
  if (img.width != page.width || img.height != page.height || img.channels != 3 ||
      img.pixels.size() != std::size_t(img.width) * std::size_t(img.height) * 3)
    throw_invalid_argument(what + " is " + std::to_string(img.width) + " x " + std::to_string(img.height) + " with " +
                           std::to_string(img.channels) + " channels: it must be " + std::to_string(page.width) + " x " +
                           std::to_string(page.height) + " RGB (3 channels), the page's size");
  for (std::size_t k = 0; k < img.pixels.size(); ++k)
    if (!(img.pixels[k] >= 0.0f && img.pixels[k] <= hi)) {
      const std::size_t t = k / 3;
      throw_invalid_argument(what + " (" + std::to_string(t % std::size_t(img.width)) + ", " + std::to_string(t / std::size_t(img.width)) +
                             ") = " + num(img.pixels[k]) + " is outside [0, " + num(hi) + "]");
    }
}

scene_atlas make_atlas(const std::vector<lightmap_page>& pages, std::size_t occluder_materials) {
  scene_atlas a;
  int width = 0;
  for (const lightmap_page& p : pages) width = std::max(width, p.width);
  if (occluder_materials > 0) width = std::max(width, 2);
  const std::size_t blocks_per_strip = std::size_t(width / 2);
  const std::size_t strips = occluder_materials == 0 ? 0 : (occluder_materials + blocks_per_strip - 1) / blocks_per_strip;
  std::size_t rows = 0;
  for (std::size_t p = 0; p < pages.size(); ++p) {
    if (p > 0) ++rows;  // guard above
    a.page_y.push_back(int(rows));
    rows += std::size_t(pages[p].height);
    if (p + 1 < pages.size() || strips > 0) ++rows;  // guard below
  }
  const std::size_t occluder_y = rows;
  rows += 2 * strips;
  // Every image of the bake has the atlas's size (at most max_image_pixels, as image::make says):
  // refused here, before the atlas's masks, coverage and textures are allocated.
  if (rows > max_image_pixels / std::size_t(width))
    throw error(status::out_of_memory, "bake_scene: the pages' atlas would be " + std::to_string(width) + " x " +
                                           std::to_string(rows) +
                                           " texels (the widest page x the sum of the heights and two guard rows between "
                                           "pages), over the limit of 2^28");
  if (rows > std::size_t(std::numeric_limits<int>::max() / 2))
    throw_invalid_argument("bake_scene: the pages' atlas would have " + std::to_string(rows) + " rows: too many");
  bake_layout& l = a.layout;
  l.width = width;
  l.height = int(rows);
  const std::size_t w = std::size_t(width);
  l.blocked.assign(w * rows, 1);
  for (std::size_t p = 0; p < pages.size(); ++p) {
    const std::size_t y0 = std::size_t(a.page_y[p]), pw = std::size_t(pages[p].width), ph = std::size_t(pages[p].height);
    for (std::size_t y = y0; y < y0 + ph; ++y)
      std::fill(l.blocked.begin() + std::ptrdiff_t(y * w), l.blocked.begin() + std::ptrdiff_t(y * w + pw), std::uint8_t(0));
    // Guards: the row above and below (where present) and the column right of the page (where
    // the atlas is wider), corners included, each a copy of the nearest texel of the page.
    const std::size_t gy0 = p > 0 ? y0 - 1 : y0;
    const std::size_t gy1 = (p + 1 < pages.size() || strips > 0) ? y0 + ph : y0 + ph - 1;  // inclusive
    const std::size_t gx1 = pw < w ? pw : pw - 1;                                            // inclusive
    for (std::size_t y = gy0; y <= gy1; ++y)
      for (std::size_t x = 0; x <= gx1; ++x) {
        const std::size_t sx = std::min(x, pw - 1), sy = std::clamp(y, y0, y0 + ph - 1);
        if (sx != x || sy != y) l.guards.emplace_back(y * w + x, sy * w + sx);
      }
  }
  for (std::size_t m = 0; m < occluder_materials; ++m) {
    const std::size_t x = 2 * (m % blocks_per_strip), y = occluder_y + 2 * (m / blocks_per_strip);
    occluder_block b;
    b.texels = {y * w + x, y * w + x + 1, (y + 1) * w + x, (y + 1) * w + x + 1};
    l.occluders.push_back(b);
  }
  return a;
}

std::string uv_text(const glm::vec2& v) { return "(" + num(v.x) + ", " + num(v.y) + ")"; }

// Checks the meshes: each starts where the previous one ends, the meshes cover the scene's
// triangles, pages are -1 or a page index, scale and offset are finite (naming the mesh).
void check_meshes(const char* who, const scene_bake_input& in) {
  const std::size_t T = in.geometry.scene.triangle_count;
  std::size_t next = 0;
  for (std::size_t m = 0; m < in.meshes.size(); ++m) {
    const bake_mesh& mesh = in.meshes[m];
    const std::string name = std::string(who) + ": meshes[" + std::to_string(m) + "]";
    if (mesh.first_triangle != next)
      throw_invalid_argument(name + ".first_triangle = " + std::to_string(mesh.first_triangle) + " must be " + std::to_string(next) +
                             " (meshes cover the triangles in order, each starting where the previous one ends)");
    if (mesh.triangle_count > T - next)
      throw_invalid_argument(name + ": triangles [" + std::to_string(mesh.first_triangle) + ", " +
                             std::to_string(mesh.first_triangle + mesh.triangle_count) + ") run past the scene's " +
                             std::to_string(T) + " triangles");
    next += mesh.triangle_count;
    if (mesh.page < -1 || (mesh.page >= 0 && std::size_t(mesh.page) >= in.pages.size()))
      throw_invalid_argument(name + ".page = " + std::to_string(mesh.page) + " is not -1 (occluder only) or a page index (" +
                             std::to_string(in.pages.size()) + " pages)");
    for (int c = 0; c < 2; ++c)
      if (!std::isfinite(mesh.uv_scale[c]) || !std::isfinite(mesh.uv_offset[c]))
        throw_invalid_argument(name + ": uv_scale " + uv_text(mesh.uv_scale) + " or uv_offset " + uv_text(mesh.uv_offset) +
                               " is not finite");
  }
  if (next != T)
    throw_invalid_argument(std::string(who) + ": the meshes cover " + std::to_string(next) + " of the scene's " + std::to_string(T) +
                           " triangles: every triangle must belong to a mesh");
}

// Checks the meshes (check_meshes) and maps every vertex of every mesh to its page (uv_scale,
// uv_offset; the result in [0, 1]), naming the mesh in every error.
scene_geometry make_scene_geometry(const char* who, const scene_bake_input& in) {
  check_meshes(who, in);
  const scene_desc& d = in.geometry.scene;
  const std::size_t T = d.triangle_count;
  scene_geometry g;
  constexpr std::uint32_t none = 0xffffffffu;
  // Meshes come in triangle order, so a vertex's copy for its latest user is all that is needed.
  std::vector<std::uint32_t> last_user(d.vertex_count, none), last_copy(d.vertex_count, none);
  const auto add_vertex = [&](std::uint32_t v, const glm::vec2& page_uv) {
    g.positions.push_back(d.positions[v]);
    if (in.geometry.normals) g.normals.push_back(in.geometry.normals[v]);
    if (d.texcoords) g.texcoords.push_back(d.texcoords[v]);
    g.page_uvs.push_back(page_uv);
    return std::uint32_t(g.positions.size() - 1);
  };
  std::map<std::array<float, 6>, std::size_t> blocks;  // occluder material -> block
  g.indices.reserve(3 * T);
  g.triangle_page.reserve(T);
  g.triangle_block.assign(T, 0);
  for (std::size_t m = 0; m < in.meshes.size(); ++m) {
    const bake_mesh& mesh = in.meshes[m];
    const auto mu = std::uint32_t(m);
    for (std::size_t t = mesh.first_triangle; t < mesh.first_triangle + mesh.triangle_count; ++t) {
      g.triangle_page.push_back(mesh.page);
      if (mesh.page < 0) {
        // Occluder: its own three corners (their UVs point at its material's block, set below).
        const material mat = d.materials ? d.materials[t] : material{};
        const std::array<float, 6> key{{mat.emission.x, mat.emission.y, mat.emission.z, mat.albedo.x, mat.albedo.y, mat.albedo.z}};
        const auto it = blocks.emplace(key, g.occluder_materials.size()).first;
        if (it->second == g.occluder_materials.size()) g.occluder_materials.push_back(mat);
        g.triangle_block[t] = it->second;
        for (int c = 0; c < 3; ++c) g.indices.push_back(add_vertex(d.indices[3 * t + std::size_t(c)], glm::vec2(0.0f)));
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t v = d.indices[3 * t + std::size_t(c)];
        std::uint32_t out;
        if (last_user[v] == mu) {
          out = last_copy[v];
        } else {
          // uv' = uv * scale + offset, in float (the engine's arithmetic).
          const glm::vec2 q = d.lightmap_uvs[v] * mesh.uv_scale + mesh.uv_offset;
          constexpr float lo = -lightmap_uv_tolerance, hi = 1.0f + lightmap_uv_tolerance;
          if (!(q.x >= lo && q.x <= hi && q.y >= lo && q.y <= hi))
            throw_invalid_argument(std::string(who) + ": meshes[" + std::to_string(m) + "] (page " + std::to_string(mesh.page) +
                                   "): lightmap_uvs[" + std::to_string(v) + "] * uv_scale + uv_offset = " + uv_text(q) +
                                   " is outside [0, 1] by more than lightmap_uv_tolerance (0.001)");
          const glm::vec2 clamped = glm::clamp(q, 0.0f, 1.0f);
          if (clamped != q && g.clamped_uvs++ == 0)
            g.clamped_warning = "meshes[" + std::to_string(m) + "] (page " + std::to_string(mesh.page) + "): lightmap_uvs[" +
                                std::to_string(v) + "] * uv_scale + uv_offset = " + uv_text(q);
          out = add_vertex(v, clamped);
          last_user[v] = mu;
          last_copy[v] = out;
        }
        g.indices.push_back(out);
      }
    }
  }
  if (g.clamped_uvs > 0)
    g.clamped_warning = std::string(who) + ": " + std::to_string(g.clamped_uvs) + " page UV" + (g.clamped_uvs > 1 ? "s lie" : " lies") +
                        " outside [0, 1] by at most lightmap_uv_tolerance (0.001) (the first: " + g.clamped_warning +
                        "): clamped onto [0, 1]";
  return g;
}

// A scene bake's input: the options (their size aside), each page's size and images, the
// geometry (UVs finite only: the meshes' scale and offset map them into pages) and the sky.
void check_scene_input(const char* who, const scene_bake_input& input, const bake_options& o) {
  check_options(o, who, false);
  if (input.pages.empty()) throw_invalid_argument(std::string(who) + ": there are no pages (scene_bake_input::pages is empty)");
  for (std::size_t p = 0; p < input.pages.size(); ++p) {
    const lightmap_page& page = input.pages[p];
    check_size((std::string(who) + ": pages[" + std::to_string(p) + "]").c_str(), page.width, page.height);
    check_page_image(who, p, "albedo", page.albedo, page, 1.0f);
    check_page_image(who, p, "emission", page.emission, page, max_radiance);
  }
  check_input(who, input.geometry, false);
  check_environment(who, o);
}

// The atlas of the pages, its occluder blocks holding their materials.
scene_atlas make_scene_atlas(const char* who, const scene_bake_input& input, const scene_geometry& g) {
  scene_atlas atlas = make_atlas(input.pages, g.occluder_materials.size());
  bake_layout& layout = atlas.layout;
  layout.who = who;
  layout.occluders_reflect = input.occluders == occluder_radiance::emission_plus_mean_bounce;
  for (std::size_t b = 0; b < g.occluder_materials.size(); ++b) {
    layout.occluders[b].emission = g.occluder_materials[b].emission;
    layout.occluders[b].albedo = g.occluder_materials[b].albedo;
  }
  return atlas;
}

// Every vertex's lightmap UV in the atlas: its page UV in the page's rows, or, for occluders,
// the centre of their material's block.
std::vector<glm::vec2> atlas_uvs(const scene_bake_input& input, const scene_geometry& g, const scene_atlas& atlas) {
  const bake_layout& layout = atlas.layout;
  const std::size_t W = std::size_t(layout.width);
  std::vector<glm::vec2> uvs(g.positions.size());
  for (std::size_t t = 0; t < g.triangle_page.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t v = g.indices[3 * t + std::size_t(c)];
      const int p = g.triangle_page[t];
      if (p < 0) {
        const std::size_t k = layout.occluders[g.triangle_block[t]].texels[0];
        uvs[v] = glm::vec2(float(double(k % W + 1) / double(W)), float(double(k / W + 1) / double(layout.height)));
      } else {
        const lightmap_page& page = input.pages[std::size_t(p)];
        const glm::vec2 q = g.page_uvs[v];
        uvs[v] = glm::vec2(float(double(q.x) * page.width / double(W)),
                           float((double(q.y) * page.height + atlas.page_y[std::size_t(p)]) / double(layout.height)));
      }
    }
  return uvs;
}

// The scene the hemicubes see: the input's triangles and materials over the combined vertices,
// with their atlas UVs.
std::shared_ptr<const scene> combined_scene(const scene_desc& d, const scene_geometry& g, const std::vector<glm::vec2>& uvs) {
  scene_desc combined = d;
  combined.positions = g.positions.data();
  combined.vertex_count = g.positions.size();
  combined.indices = g.indices.data();
  combined.lightmap_uvs = uvs.data();
  combined.texcoords = d.texcoords ? g.texcoords.data() : nullptr;
  return scene::create(combined);
}

// One page's triangles as a mesh of their own (compact vertex arrays, page UVs), with the scene
// triangle of each.
struct page_mesh {
  std::vector<std::uint32_t> tris, idx;  // scene triangle of each; indices into the arrays below
  std::vector<glm::vec3> pos, nrm;
  std::vector<glm::vec2> uvs;
  std::vector<material> mats;

  bake_input input() const {
    bake_input sub;
    sub.scene.positions = pos.data();
    sub.scene.vertex_count = pos.size();
    sub.scene.indices = idx.data();
    sub.scene.triangle_count = tris.size();
    sub.scene.materials = mats.data();
    sub.scene.lightmap_uvs = uvs.data();
    sub.normals = nrm.empty() ? nullptr : nrm.data();
    return sub;
  }
};

// The name of scene triangle t in the caller's terms: "meshes[2] triangle 4 (scene triangle 40)".
std::string mesh_triangle_name(const scene_bake_input& input, std::size_t t) {
  std::size_t mesh = 0;
  while (t >= input.meshes[mesh].first_triangle + input.meshes[mesh].triangle_count) ++mesh;
  return "meshes[" + std::to_string(mesh) + "] triangle " + std::to_string(t - input.meshes[mesh].first_triangle) +
         " (scene triangle " + std::to_string(t) + ")";
}

// Page p's triangles; with strict, a triangle with 3D area but none in the page (the test
// compute_sparse_samples makes) is refused, named by its mesh (without strict,
// compute_sparse_samples counts it).
page_mesh page_triangles(const char* who, const scene_bake_input& input, const scene_geometry& g, std::size_t p, bool strict) {
  constexpr std::uint32_t none = lightmap_samples::no_triangle;
  const lightmap_page& page = input.pages[p];
  const scene_desc& d = input.geometry.scene;
  page_mesh m;
  std::vector<std::uint32_t> remap(g.positions.size(), none);
  for (std::size_t t = 0; t < d.triangle_count; ++t) {
    if (g.triangle_page[t] != int(p)) continue;
    const std::uint32_t* ti = g.indices.data() + 3 * t;
    const glm::dvec2 a = glm::dvec2(g.page_uvs[ti[0]]) * glm::dvec2(page.width, page.height);
    const glm::dvec2 b = glm::dvec2(g.page_uvs[ti[1]]) * glm::dvec2(page.width, page.height);
    const glm::dvec2 c = glm::dvec2(g.page_uvs[ti[2]]) * glm::dvec2(page.width, page.height);
    if (strict && !is_degenerate_triangle(g.positions[ti[0]], g.positions[ti[1]], g.positions[ti[2]]) &&
        !(0.5 * std::fabs(cross2(a, b, c)) > 1e-12 * double(page.width) * double(page.height)))
      throw_invalid_argument(std::string(who) + ": " + mesh_triangle_name(input, t) +
                             " has zero area in its page's UV space (but not in 3D): it would get no texels");
    m.tris.push_back(std::uint32_t(t));
    m.mats.push_back(d.materials ? d.materials[t] : material{});
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = ti[k];
      if (remap[v] == none) {
        remap[v] = std::uint32_t(m.pos.size());
        m.pos.push_back(g.positions[v]);
        m.uvs.push_back(g.page_uvs[v]);
        if (!g.normals.empty()) m.nrm.push_back(g.normals[v]);
      }
      m.idx.push_back(remap[v]);
    }
  }
  return m;
}

// Appends a page's samples `ps` (its own texel grid and triangle numbers) to the atlas's `s`:
// texels, centroids and triangles mapped into the atlas (the page's first row: y0).
void append_page_samples(sparse_samples& s, sparse_samples&& ps, const std::vector<std::uint32_t>& tris,
                         const lightmap_page& page, std::size_t y0, const bake_layout& layout) {
  constexpr std::uint32_t none = lightmap_samples::no_triangle;
  const std::size_t W = std::size_t(layout.width);
  if (s.size() == 0 && y0 == 0 && std::size_t(page.width) == W) {
    // The first page at the atlas's origin with its width: its texel indices are the atlas's;
    // taken over in place (no second copy of the samples at the peak).
    const std::size_t overlapping = s.overlapping_texels;
    sparse_samples moved = std::move(ps);
    for (std::size_t n = 0; n < moved.size(); ++n) {
      moved.owner[n] = tris[moved.owner[n]];
      moved.sample_triangle[n] = moved.sample_triangle[n] == none ? none : tris[moved.sample_triangle[n]];
      moved.centroid[n] = glm::vec2(float(double(moved.centroid[n].x) * page.width / double(W)),
                                    float((double(moved.centroid[n].y) * page.height) / double(layout.height)));
    }
    moved.width = layout.width;
    moved.height = layout.height;
    moved.overlapping_texels = overlapping;
    s = std::move(moved);
    return;
  }
  for (std::size_t n = 0; n < ps.size(); ++n) {
    const std::size_t j = ps.texel[n], x = j % std::size_t(page.width), y = j / std::size_t(page.width);
    s.texel.push_back((y0 + y) * W + x);
    s.coverage.push_back(ps.coverage[n]);
    s.owner.push_back(tris[ps.owner[n]]);
    s.sample_triangle.push_back(ps.sample_triangle[n] == none ? none : tris[ps.sample_triangle[n]]);
    s.centroid.emplace_back(float(double(ps.centroid[n].x) * page.width / double(W)),
                            float((double(ps.centroid[n].y) * page.height + double(y0)) / double(layout.height)));
    s.position.push_back(ps.position[n]);
    s.normal.push_back(ps.normal[n]);
    s.texel_world_size.push_back(ps.texel_world_size[n]);
    s.tangent.push_back(ps.tangent[n]);
    s.bitangent.push_back(ps.bitangent[n]);
  }
}

// Step 1 per page, in the page's own texel grid (its UVs), merged into the atlas (pages in
// order: the atlas texel indices stay increasing). page_overlapping receives each page's
// overlapping texels.
// The triangles that cover nothing are counted over the pages (the first named in scene_desc
// numbering); occluder-only meshes' triangles are not counted.
sparse_samples atlas_samples(const char* who, const scene_bake_input& input, const scene_geometry& g, const scene_atlas& atlas,
                             bool strict, std::vector<std::size_t>& page_overlapping) {
  sparse_samples s;
  s.width = atlas.layout.width;
  s.height = atlas.layout.height;
  page_overlapping.assign(input.pages.size(), 0);
  std::size_t degenerate = 0, no_uv_area = 0, first_no_uv_area = bake_stats::no_index;
  for (std::size_t p = 0; p < input.pages.size(); ++p) {
    const page_mesh m = page_triangles(who, input, g, p, strict);
    if (m.tris.empty()) continue;  // an empty page: all dilation (nothing to fill from)
    sparse_samples ps = compute_sparse_samples(m.input(), input.pages[p].width, input.pages[p].height, strict, who);
    page_overlapping[p] = ps.overlapping_texels;
    s.overlapping_texels += ps.overlapping_texels;
    degenerate += ps.degenerate_triangles;
    no_uv_area += ps.no_uv_area_triangles;
    if (ps.no_uv_area_triangles > 0) first_no_uv_area = std::min<std::size_t>(first_no_uv_area, m.tris[ps.first_no_uv_area_triangle]);
    append_page_samples(s, std::move(ps), m.tris, input.pages[p], std::size_t(atlas.page_y[p]), atlas.layout);
  }
  s.degenerate_triangles = degenerate;
  s.no_uv_area_triangles = no_uv_area;
  s.first_no_uv_area_triangle = first_no_uv_area;
  return s;
}

// Per-texel materials where a page has images (the other pages: their owners' materials).
void page_materials(const scene_bake_input& input, const scene_atlas& atlas, const sparse_samples& s, bake_layout& layout) {
  const scene_desc& d = input.geometry.scene;
  const std::size_t W = std::size_t(layout.width), texels = W * std::size_t(layout.height);
  const bool any_albedo = std::any_of(input.pages.begin(), input.pages.end(), [](const lightmap_page& p) { return p.albedo.width > 0; });
  const bool any_emission = std::any_of(input.pages.begin(), input.pages.end(), [](const lightmap_page& p) { return p.emission.width > 0; });
  if (any_albedo) layout.albedo.assign(texels, glm::vec3(0.0f));
  if (any_emission) layout.emission.assign(texels, glm::vec3(0.0f));
  layout.textured_first_pass = any_emission;
  if (!any_albedo && !any_emission) return;
  // The page of every atlas row (-1: a guard or the occluders' blocks).
  std::vector<int> row_page(std::size_t(layout.height), -1);
  for (std::size_t p = 0; p < input.pages.size(); ++p)
    for (int y = 0; y < input.pages[p].height; ++y) row_page[std::size_t(atlas.page_y[p] + y)] = int(p);
  for (std::size_t n = 0; n < s.size(); ++n) {
    const std::size_t k = s.texel[n];
    const int p = row_page[k / W];
    const lightmap_page& page = input.pages[std::size_t(p)];
    const int x = int(k % W), y = int(k / W) - atlas.page_y[std::size_t(p)];
    const material m = d.materials ? d.materials[s.owner[n]] : material{};
    if (any_albedo)
      layout.albedo[k] = page.albedo.width > 0 ? glm::vec3(page.albedo.at(x, y)[0], page.albedo.at(x, y)[1], page.albedo.at(x, y)[2])
                                               : m.albedo;
    if (any_emission)
      layout.emission[k] = page.emission.width > 0
                               ? glm::vec3(page.emission.at(x, y)[0], page.emission.at(x, y)[1], page.emission.at(x, y)[2])
                               : m.emission;
  }
}

}  // namespace

// The seams of a scene bake (within meshes, between meshes and pages) into the atlas's layout, each
// side in its page's rows; returns the time it took.
double scene_seams(const scene_bake_input& input, const scene_geometry& g, const scene& walls, scene_atlas& atlas) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<glm::vec2> uvs(g.indices.size());
  for (std::size_t i = 0; i < uvs.size(); ++i) uvs[i] = g.page_uvs[g.indices[i]];
  seam_mesh m;
  m.positions = g.positions.data();
  m.vertex_count = g.positions.size();
  m.indices = g.indices.data();
  m.triangle_count = g.triangle_page.size();
  m.normals = g.normals.empty() ? nullptr : g.normals.data();
  m.corner_uvs = uvs.data();
  m.triangle_page = g.triangle_page.data();
  for (std::size_t p = 0; p < input.pages.size(); ++p)
    m.pages.push_back(page_rect{0, atlas.page_y[p], input.pages[p].width, input.pages[p].height});
  atlas.layout.seams = find_seams(m, seam_stitch_degrees, walls);
  atlas.layout.seam_pages = m.pages;
  return seconds_since(t0);
}

namespace {

// Page p's result: the atlas rows of the page (images, per-texel arrays) and its statistics.
bake_result crop_page(const bake_result& all, const std::vector<std::uint8_t>& filled, const scene_atlas& atlas,
                      const lightmap_page& page, std::size_t p, std::size_t overlapping) {
  bake_result r;
  const std::size_t W = std::size_t(atlas.layout.width);
  const std::size_t y0 = std::size_t(atlas.page_y[p]), pw = std::size_t(page.width), ph = std::size_t(page.height);
  const auto crop = [&](const image& img) {
    if (img.width == 0) return image{};
    image c = image::make(page.width, page.height, img.channels);
    const std::size_t ch = std::size_t(img.channels);
    for (std::size_t y = 0; y < ph; ++y)
      std::memcpy(c.pixels.data() + y * pw * ch, img.pixels.data() + ((y0 + y) * W) * ch, pw * ch * sizeof(float));
    return c;
  };
  const auto crop_bytes = [&](const auto& v) {
    std::remove_cv_t<std::remove_reference_t<decltype(v)>> c(pw * ph);
    for (std::size_t y = 0; y < ph; ++y)
      std::copy_n(v.begin() + std::ptrdiff_t((y0 + y) * W), pw, c.begin() + std::ptrdiff_t(y * pw));
    return c;
  };
  r.irradiance = crop(all.irradiance);
  r.coverage = crop_bytes(all.coverage);
  r.valid = crop_bytes(all.valid);
  r.sampled = crop_bytes(all.sampled);
  for (std::size_t j = 0; j < 4; ++j) r.sh_l1[j] = crop(all.sh_l1[j]);
  for (std::size_t j = 0; j < 3; ++j) r.hl2[j] = crop(all.hl2[j]);
  r.shadow_mask = crop(all.shadow_mask);
  r.ao = crop(all.ao);
  const std::vector<std::uint8_t> page_filled = crop_bytes(filled);
  r.stats.texels = pw * ph;
  r.stats.overlapping_texels = overlapping;
  for (std::size_t k = 0; k < pw * ph; ++k) {
    if (r.coverage[k] > 0.0f) ++r.stats.covered_texels;
    if (r.sampled[k]) ++r.stats.sampled_texels;
    if (r.sampled[k] && !r.valid[k]) ++r.stats.invalid_texels;
    if (!r.sampled[k] && page_filled[k]) ++r.stats.dilated_texels;
  }
  return r;
}

}  // namespace

scene_setup make_scene_setup(const char* who, const scene_bake_input& input, const bake_options& o) {
  check_scene_input(who, input, o);
  scene_setup su;
  su.geometry = make_scene_geometry(who, input);
  su.atlas = make_scene_atlas(who, input, su.geometry);
  su.sc = combined_scene(input.geometry.scene, su.geometry, atlas_uvs(input, su.geometry, su.atlas));
  su.samples = atlas_samples(who, input, su.geometry, su.atlas, o.strict, su.page_overlapping);
  page_materials(input, su.atlas, su.samples, su.atlas.layout);
  return su;
}

scene_bake_result scene_pages(const char* who, const scene_bake_input& input, const scene_setup& su, bake_result&& all,
                              const std::vector<std::uint8_t>& filled) {
  const scene_geometry& g = su.geometry;
  all.stats.clamped_uvs = g.clamped_uvs;
  if (g.clamped_uvs > 0) all.stats.warnings.push_back(g.clamped_warning);
  if (all.stats.no_uv_area_triangles > 0)
    all.stats.warnings.push_back(
        no_uv_area_warning(who, all.stats.no_uv_area_triangles, mesh_triangle_name(input, all.stats.first_no_uv_area_triangle)));
  scene_bake_result out;
  out.pages.resize(input.pages.size());
  for (std::size_t p = 0; p < input.pages.size(); ++p)
    out.pages[p] = crop_page(all, filled, su.atlas, input.pages[p], p, su.page_overlapping[p]);
  out.stats = std::move(all.stats);
  out.stats.texels = 0;
  for (const bake_result& r : out.pages) out.stats.texels += r.stats.texels;
  return out;
}

}  // namespace bake_detail

scene_bake_result bake_scene(const scene_bake_input& input, const bake_options& o) {
  using namespace bake_detail;
  const char* who = "bake_scene";
  const auto t0 = std::chrono::steady_clock::now();
  scene_setup su = make_scene_setup(who, input, o);
  const double seam_seconds = o.stitch_seams ? scene_seams(input, su.geometry, *su.sc, su.atlas) : 0.0;
  std::vector<std::uint8_t> filled;
  bake_result all = bake_samples(std::move(su.samples), su.sc, o, su.atlas.layout, t0, filled);
  all.stats.stitch_seconds += seam_seconds;
  return scene_pages(who, input, su, std::move(all), filled);
}

}  // namespace hemilight
