// Steps 2-6 of the baker (internal, not installed): the per-sample state of a bake and its
// stages (bake.hpp, "pipeline"), shared by bake_lightmap, bake_scene and the sharded bake:
//   place_samples -> [lights_at_samples] -> { pass_radiance_texture -> hemicube_pass (the cache or
//   a hemicube per sample) -> merge_pass (add_direct, fill_invalid_samples) }* -> finish_samples
//   (fill_invalid_ao, fill_direct_outputs, write_outputs)
// bake_samples runs the chain in one process (bake_lightmap.cpp); shards.cpp runs hemicube_pass
// per shard and the rest in its merges; direct.cpp holds the lights' stages, outputs.cpp the
// images, bake_scene.cpp the scene set-up (make_scene_setup) and pages (scene_pages).
#pragma once

#include "coverage.hpp"
#include "seam_search.hpp"

#include "hemilight/bake.hpp"
#include "hemilight/lights.hpp"

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace hemilight::bake_detail {

// The per-sample state of a bake (bake_lightmap's stages below), for sampled texels only.
struct sample_points {
  std::vector<std::size_t> texel_of;     // texel index of each sample
  std::vector<glm::vec3> positions, normals;
  std::vector<std::uint32_t> owner;      // the texel's owner triangle (its material)
  std::vector<glm::vec3> tangents, bitangents;  // the texel's lightmap tangent frame (with normals)
  std::vector<float> spacing;            // the texel's world size (the cache's cache_run::point_spacing)
};

// A 2 x 2 block of texels of a scene bake's atlas that holds the radiance of the occluder-only
// triangles of one material (their UVs all point at the block's centre, where bilinear lookups
// read only the block).
struct occluder_block {
  std::array<std::size_t, 4> texels{};
  glm::vec3 emission{0.0f}, albedo{0.0f};
};

// Where the samples' values go: the texel grid of the bake (one lightmap, or the atlas of a scene
// bake's pages) and what its radiance textures hold besides the sampled texels. A plain
// bake_lightmap uses the grid alone (everything else empty: today's bake, bit for bit).
struct bake_layout {
  int width = 0, height = 0;
  std::vector<std::uint8_t> blocked;  // per texel, 1: never filled by dilation (outside every page); empty: none
  // (destination, source) texel pairs copied after dilation into radiance textures: the guard
  // rows and columns around each page repeat its edge, so that bilinear lookups near a page's
  // border read what clamp-to-edge would in a texture of its own.
  std::vector<std::pair<std::size_t, std::size_t>> guards;
  std::vector<glm::vec3> albedo, emission;  // per texel, or empty: the owner triangle's material
  std::vector<occluder_block> occluders;
  bool occluders_reflect = false;  // occluders add albedo x the mean irradiance / pi to their emission
  bool textured_first_pass = false;  // pass 1 sees the emission through a texture (emission images)
  // The seams the outputs are stitched along (bake_options::stitch_seams; empty: none) and the
  // pages' rectangles in the grid their sides refer to.
  std::vector<seam_piece> seams;
  std::vector<page_rect> seam_pages;
  const char* who = "bake_lightmap";

  const std::uint8_t* blocked_mask() const { return blocked.empty() ? nullptr : blocked.data(); }
};

// L1 SH per sample, coefficient-major (sh[k][i]).
using sh_planes = std::array<std::vector<glm::vec3>, 4>;

// What one pass gives per sample.
struct pass_values {
  std::vector<glm::vec3> e;
  sh_planes sh;                 // with directional outputs in this pass
  std::vector<hl2_cone> cone;   // with output_hl2 in this pass (reference make_frame(normal).t)
  std::vector<float> ao;        // with ao_distance, in the first pass only
  std::vector<std::uint8_t> invalid;  // 1: the sample is inside geometry (filled, not computed)
};

// What the lights give per sample (step 3b), computed once: e and sh are added to every pass
// before its invalid samples are filled; hl2 (in the texel's lightmap frame) and the shadow mask
// are filled once after the passes and written with the outputs.
struct direct_values {
  std::vector<glm::vec3> e;
  sh_planes sh;                                // with output_sh_l1
  std::array<std::vector<glm::vec3>, 3> hl2;   // with output_hl2
  std::array<std::vector<glm::vec3>, 2> mask;  // with a shadow mask: channels (0, 1, 2) and (3, -, -)
};

// Per-sample values at samples inside geometry (invalid[i] = 1) replaced by those of the valid
// texels around them in the lightmap: texel dilation that grows through sampled texels only, so it
// stays in the texel's own chart (charts apart in the atlas are not 8-connected through sampled
// texels), the same side of the same surface, never a chart across a wall nor a record. An invalid
// texel whose chart has no valid texel gets 0, not the light of whatever chart lies next to it in
// the atlas (docs/bake.md, "Leaks").
class invalid_filler {
 public:
  invalid_filler(const sample_points& pts, const std::vector<std::uint8_t>& invalid, const bake_layout& layout);
  bool needed() const { return any_; }
  void operator()(std::vector<glm::vec3>& values) const;

 private:
  const sample_points& pts_;
  const std::vector<std::uint8_t>& invalid_;
  const bake_layout& layout_;
  std::vector<std::uint8_t> filled_;
  std::vector<std::uint8_t> blocked_;  // 1: not sampled (padding, other pages' guards): never filled nor crossed
  bool any_ = false;
};

// The atlas of a scene bake: pages stacked vertically in one texel grid, each with guard rows
// and columns between it and the rest (copies of its edge in radiance textures, never filled by
// dilation), then the occluders' 2 x 2 blocks.
struct scene_atlas {
  bake_layout layout;
  std::vector<int> page_y;  // first row of each page
};

// The combined geometry of a scene bake: the input's triangles with lightmap UVs in the atlas
// (vertices shared by meshes duplicated, occluders' corners pointing at their material's block)
// and, per vertex, its page UV (for the per-page samples).
struct scene_geometry {
  std::size_t clamped_uvs = 0;  // page UVs up to lightmap_uv_tolerance outside [0, 1], clamped
  std::string clamped_warning;  // naming the first of them
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> page_uvs;
  std::vector<glm::vec2> texcoords;  // the alpha textures' coordinates, per vertex (when the input has them)
  std::vector<std::uint32_t> indices;
  std::vector<int> triangle_page;  // per triangle: page, or -1 (occluder)
  std::vector<material> occluder_materials;
  std::vector<std::size_t> triangle_block;  // per triangle: its occluder block (occluders only)
};

// A scene bake's set-up (bake_scene.cpp: check_scene_input -> make_scene_geometry ->
// make_scene_atlas -> combined_scene -> atlas_samples -> page_materials): everything before the
// passes, the same bits for every job of a sharded bake. Throws as bake_scene does.
struct scene_setup {
  scene_geometry geometry;
  scene_atlas atlas;
  std::shared_ptr<const scene> sc;
  sparse_samples samples;
  std::vector<std::size_t> page_overlapping;  // per page
};
scene_setup make_scene_setup(const char* who, const scene_bake_input& input, const bake_options& o);

// The seams of a scene bake (within meshes, between meshes and pages) into the atlas's layout;
// returns the time it took.
double scene_seams(const scene_bake_input& input, const scene_geometry& g, const scene& walls, scene_atlas& atlas);

// The pages of a scene bake cut from the atlas's result `all` (filled: its texels written or
// dilated), with the whole bake's statistics and warnings.
scene_bake_result scene_pages(const char* who, const scene_bake_input& input, const scene_setup& su, bake_result&& all,
                              const std::vector<std::uint8_t>& filled);

// Wall time since t0, in seconds.
double seconds_since(std::chrono::steady_clock::time_point t0);

// Step 2: the sampled texels (coverage >= min_coverage), offset along their normals by
// max(2 x the scene's near distance, offset_texels x texel size); fills r's coverage, sampled and
// their statistics. Throws error(invalid_argument) when no texel is sampled.
sample_points place_samples(const sparse_samples& s, const scene& sc, const bake_options& o, const bake_layout& layout,
                            bake_result& r);

// Step 3b with its timing (stats.direct_seconds): the lights' values at every sample, or nothing
// without lights.
direct_values lights_at_samples(const sample_points& pts, const scene& sc, const light_set& lights, const bake_options& o,
                                bake_stats& stats);

// Step 3b: the lights' direct irradiance (and SH, HL2, shadow-mask visibility as the options ask)
// at every sample; keep_going (may be empty) is polled between blocks (false: error(cancelled)).
direct_values direct_pass(const sample_points& pts, const scene& sc, const light_set& lights, const bake_options& o,
                          const std::function<bool()>& keep_going);

// A pass's irradiance (and SH, where the pass computed it) plus the lights'.
void add_direct(const direct_values& d, pass_values& v);

// The lights' HL2 values and shadow mask at samples inside geometry (valid = 0 after all passes)
// from the valid texels around them, as the passes' values are.
void fill_direct_outputs(const sample_points& pts, const std::vector<std::uint8_t>& valid, const bake_layout& layout,
                         direct_values& d);

// Steps 5 and 6: the lightmap images from the last pass (less `first` with indirect_only), with
// the lights' HL2 and shadow mask and the first pass's ambient occlusion `ao` (per sample, filled
// at samples inside geometry; empty: none), dilated around every chart. `filled` receives the
// texels written or dilated.
void write_outputs(const sample_points& pts, const pass_values& last, const pass_values* first, const direct_values* direct,
                   const std::vector<float>& ao, const std::vector<std::uint8_t>& valid, const bake_options& o,
                   const bake_layout& layout, bake_result& r, std::vector<std::uint8_t>& filled);

// Step 4's radiance texture for pass `e` != null: emission + albedo e / pi per sample, dilated,
// with the occluder blocks and the guards; e = null: the emission alone (pass 1 with emission
// images).
image pass_radiance_texture(const scene& sc, const sample_points& pts, const std::vector<glm::vec3>* e, const bake_options& o,
                            const bake_layout& layout);

// Step 4, the hemicubes of pass `pass` (0-based) at the samples pts: through the cache or a
// hemicube per sample, seeing `texture` (null: the scene's emission); known_inside (null, or
// per sample 1: found inside geometry by an earlier pass) skips hemicubes. The values as the
// sampler gives them: no lights, invalid samples not filled. Appends the pass's cache_stats.
pass_values hemicube_pass(const sample_points& pts, const std::shared_ptr<const scene>& sc, const bake_options& o, int pass,
                          const radiance_texture* texture, const std::uint8_t* known_inside,
                          const std::function<bool(float)>& progress, bake_stats& stats);

// A pass's values finished over all samples: the lights added (direct may be null), samples
// inside geometry filled from their chart, valid[i] cleared where the pass found sample i inside.
void merge_pass(const sample_points& pts, const direct_values* direct, const bake_layout& layout, pass_values& v,
                std::vector<std::uint8_t>& valid);

// The ambient occlusion at samples inside geometry (valid = 0 after all passes) from the valid
// texels around them in their own chart.
void fill_invalid_ao(const sample_points& pts, const std::vector<std::uint8_t>& valid, const bake_layout& layout,
                     std::vector<float>& ao);

// Steps 5 and 6 after the passes: AO and the lights' outputs filled at samples inside geometry,
// then write_outputs.
void finish_samples(const sample_points& pts, const pass_values& last, const pass_values* first, direct_values* direct,
                    std::vector<float>& ao, const std::vector<std::uint8_t>& valid, const bake_options& o,
                    const bake_layout& layout, bake_result& r, std::vector<std::uint8_t>& filled);

// Steps 2-6 of bake.hpp on the samples of a layout (one lightmap, or a scene bake's atlas):
// the passes, the lights, the outputs. `filled` receives the texels written or dilated; t0 is
// the start of the bake (its statistics' times). Cost: the passes' hemicubes dominate.
bake_result bake_samples(sparse_samples s, const std::shared_ptr<const scene>& sc, const bake_options& o,
                         const bake_layout& layout, std::chrono::steady_clock::time_point t0, std::vector<std::uint8_t>& filled);

}  // namespace hemilight::bake_detail
