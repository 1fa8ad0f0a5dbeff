// hemilight/bake.hpp — the lightmap baker: from triangles with lightmap UVs to an irradiance
// lightmap (optionally directional maps, a shadow mask and ambient occlusion), through the
// irradiance cache, with bounces and analytic lights. The pipeline, its steps and its figures: docs/bake.md.
//
// UV <-> texel convention (the same as radiance_texture::sample, raster.hpp): texel (x, y) has
// its centre at uv = ((x + 0.5) / W, (y + 0.5) / H); u grows with the column x, v with the row y.
// Row 0 (v near 0) is the first row in memory and the first (top) scanline of the EXR files.
// Upload the rows in memory order and sample with the same uv in Direct3D or OpenGL.
//
// Determinism: the same input gives bitwise the same lightmap for any thread count.
#pragma once

#include "hemilight/cache.hpp"
#include "hemilight/image_io.hpp"
#include "hemilight/lights.hpp"
#include "hemilight/scene.hpp"
#include "hemilight/unwrap.hpp"  // generate_lightmap_uvs: lightmap UVs for what the baker bakes

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace hemilight {

/// Largest lightmap width or height bake_lightmap accepts: peak memory is O(texels) plus
/// O(sampled texels) (docs/bake.md, "Memory per texel"), up to about 14 GiB for a fully sampled
/// 8192^2. Larger maps are refused with error(invalid_argument).
inline constexpr int max_lightmap_size = 8192;

/// Largest number of light bounces a bake takes (bake_options::bounces).
inline constexpr int max_bounces = 64;

/// How far outside [0, 1] a lightmap UV component may lie and still be baked, clamped onto
/// [0, 1] (bake_lightmap's UVs; bake_scene's page UVs after scale and offset). Why 1e-3: UV sets
/// made elsewhere leave UVs a hair outside the square (float rounding: 6e-8 near 1; a packer's
/// margin computed in its own texel grid: up to half a texel, 4.9e-4 for 1024^2, as -0.00048 in a
/// real export). 1e-3 takes both for maps from 512^2 up, while a UV meant for another tile or
/// page (1.2, -0.5) is still refused. Clamping moves a vertex by at most 1e-3 of the map: one
/// texel at 1024, 8 at max_lightmap_size, at the map's border, where charts have their padding.
inline constexpr float lightmap_uv_tolerance = 1e-3f;

/// Options of bake_lightmap.
struct bake_options {
  int width = 256, height = 256;  ///< lightmap size in texels, each in [1, max_lightmap_size]
  /// How each hemicube is rendered and integrated: resolution N, raster (near plane, environment
  /// sky `raster.sky`, exact edge coverage), integrate. The baker rolls hemicubes unless
  /// sampler.roll is false.
  sampler_options sampler;
  /// The irradiance cache's settings (used when use_cache is on; always validated).
  cache_options cache;
  /// false: a hemicube at every sampled texel (no interpolation); the reference the cache's error
  /// is measured against.
  bool use_cache = true;
  /// Light bounces, in [1, max_bounces]: 1 = direct light only (emission and sky); each more
  /// bounce is one more pass of the whole cache.
  int bounces = 1;
  /// Store only the indirect part: E_bounces - E_1 (clamped at 0), for engines that add direct
  /// light at run time. Needs bounces >= 2 to be nonzero.
  bool indirect_only = false;
  /// Texels whose covered fraction is below this get no sample (they are filled by dilation).
  /// In [0, 1]; 0 samples every texel touched by a triangle.
  float min_coverage = 0.01f;
  /// Sample offset along the normal in texel world sizes (docs/bake.md, step 2), finite, >= 0.
  float offset_texels = 0.05f;
  /// Rings of dilation around every chart, >= 0; -1 fills every empty texel of the lightmap.
  int dilation = 16;
  /// Stitch the seams (seams.hpp): after the passes, the texels that bilinear lookups along
  /// seams between faces whose shading normals agree within seam_stitch_degrees (1) read (both
  /// sides, padding included) are set by least squares so that
  /// both sides agree along the seam while staying close to their baked values; dilation follows.
  /// Seams with a wall standing on them and points where the irradiance jumps across the seam
  /// (more than the two sides' gradients explain: a hard shadow along it) are left as baked.
  /// Within a mesh, between meshes and between pages; every output (irradiance, SH, HL2, shadow
  /// mask). Cost: O(T log T) to find the seams, then about linear in the seams' texels
  /// (docs/bake.md, "Seams").
  bool stitch_seams = true;
  /// Output the L1 SH lightmaps (bake_result::sh_l1). Cost: 3 multiply-adds per hemicube texel in
  /// the directional passes.
  bool output_sh_l1 = false;
  /// Output the Half-Life 2 basis lightmaps (bake_result::hl2). Cost: 21 multiply-adds per
  /// hemicube texel in the directional passes, 96 bytes per record, a table per resolution.
  bool output_hl2 = false;
  /// Analytic lights (lights.hpp): direct light at every sample, added to every pass; checked as
  /// validate_lights does. Cost per sample and light: one shadow ray (hard) to 264 (penumbra).
  std::vector<light> lights;
  direct_options direct;  ///< the lights' shadow rays, checked as validate_direct_options does
  /// A triangle with 3D area but no lightmap UV area (at most 1e-12 of the UV square: a broken
  /// unwrap): false, it still occludes, gets no texels and is counted and named
  /// (bake_stats::no_uv_area_triangles, warnings); true, the bake fails with error(invalid_argument)
  /// naming it. Degenerate triangles (is_degenerate_triangle, scene.hpp) are skipped either way.
  bool strict = false;
  /// Shadow mask (bake_result::shadow_mask): channel c holds the visibility of light
  /// shadow_mask_lights[c] (an index into lights), -1 leaves it 0. All -1: no mask.
  std::array<int, 4> shadow_mask_lights{{-1, -1, -1, -1}};
  /// Ambient occlusion (bake_result::ao) within this distance, in scene units: per texel the
  /// cosine-weighted fraction of the hemisphere that sees no geometry (front or back faces) within
  /// it (docs/bake.md, "Ambient occlusion"). Finite and >= 0, else error(invalid_argument) naming
  /// "ao_distance"; 0 = no AO (the default: the bake is then bitwise what it was without AO). Taken
  /// from the first pass's hemicubes (no pass of its own) and, with use_cache, interpolated by the
  /// cache with the irradiance's record weights (no gradients); the cache's AO rule
  /// (cache.expert.refine_where_ao_disagrees, on) adds first-pass records where AO varies faster
  /// than E, which changes the irradiance's bits too (it lowers its error); without the rule or
  /// without the cache the irradiance is bitwise that of the bake without AO. Cost: one compare
  /// and add per hemicube texel in the first pass, the added records' hemicubes (+14% to +145% of
  /// the first pass's on the reference scenes, docs/bake.md), 4 bytes per record and sample, the
  /// image (12 bytes per texel) and its stitching and dilation.
  float ao_distance = 0.0f;
  int thread_count = 0;  ///< >= 0; 0 = all cores. Results do not depend on it.
  /// Called from the calling thread with the fraction of the bake done, in [0, 1], never
  /// decreasing; return false to cancel (error(status::cancelled), nothing returned). May be empty.
  std::function<bool(float fraction)> progress;
};

/// Statistics of one bake.
struct bake_stats {
  std::size_t texels = 0;             ///< W x H
  std::size_t covered_texels = 0;     ///< texels with coverage > 0
  std::size_t sampled_texels = 0;     ///< texels with coverage >= min_coverage (one sample each)
  std::size_t invalid_texels = 0;     ///< sampled texels inside geometry in any pass (filled by dilation)
  std::size_t overlapping_texels = 0; ///< texels whose covering triangles sum to more than 1.001 texel (UV overlap)
  std::size_t dilated_texels = 0;     ///< empty texels filled by dilation
  std::size_t hemicubes = 0;          ///< hemicubes rendered, all passes
  std::size_t records = 0;            ///< cache records, all passes
  std::vector<cache_stats> passes;    ///< the cache's statistics per pass
  /// Input the bake went past (bake_options::strict). Triangles without 3D area
  /// (is_degenerate_triangle): skipped, no texels, never occlude.
  std::size_t degenerate_triangles = 0;
  /// Triangles with 3D area but no lightmap UV area: they occlude but get no texels.
  std::size_t no_uv_area_triangles = 0;
  /// The lowest-numbered of them (scene_desc numbering), or no_index.
  std::size_t first_no_uv_area_triangle = no_index;
  /// Lightmap UVs (vertices; bake_scene: page UVs of a mesh's vertices) up to
  /// lightmap_uv_tolerance outside [0, 1], clamped onto it.
  std::size_t clamped_uvs = 0;
  /// One line per kind of input problem above but degenerate triangles, naming the first case
  /// ("bake_lightmap: 2 triangles have 3D area but no lightmap UV area (the first: triangle 34):
  /// they occlude but get no texels"). Empty for clean input.
  std::vector<std::string> warnings;
  double coverage_seconds = 0.0;      ///< exact UV coverage and samples (compute_lightmap_samples)
  double direct_seconds = 0.0;        ///< the lights' direct irradiance (0 without lights)
  std::size_t seam_texels = 0;        ///< texels set by seam stitching (0 without stitch_seams)
  double stitch_seconds = 0.0;        ///< finding and stitching the seams, every output
  double seconds = 0.0;               ///< the whole bake (wall time)

  static constexpr std::size_t no_index = ~std::size_t(0);
};

/// What bake_lightmap returns.
struct bake_result {
  image irradiance;                  ///< W x H RGB irradiance E (integral of L cos theta d omega), dilated
  std::vector<float> coverage;       ///< per texel (row-major), covered fraction in [0, 1]
  /// Per texel: 1 if it was sampled (coverage >= min_coverage) and its sample was valid in every
  /// pass (not inside geometry), else 0. Dilated texels are 0.
  std::vector<std::uint8_t> valid;
  std::vector<std::uint8_t> sampled;  ///< per texel: 1 if a sample was placed (coverage >= min_coverage)
  /// With output_sh_l1 (else four empty images): the L1 SH of the incoming radiance per texel,
  /// one W x H RGB image per coefficient, world space, in integrate.hpp's order and
  /// normalisation: sh_l1[0] = Y00 (0.282095), sh_l1[1] = Y1-1 (0.488603 y), sh_l1[2] = Y10
  /// (0.488603 z), sh_l1[3] = Y11 (0.488603 x); coefficient = integral over the texel's upper
  /// hemisphere of L Y d omega. A uniform sky L over a plane of normal n gives (sqrt(pi) L,
  /// (sqrt(3 pi)/2) L (n_y, n_z, n_x)). With indirect_only: last pass minus first pass. Dilated.
  std::array<image, 4> sh_l1;
  /// With output_hl2 (else three empty images): irradiance through the Half-Life 2 basis vectors
  /// hl2_basis[k] of each texel's lightmap tangent frame (lightmap_tangent_frame), >= 0, from the
  /// interpolated HL2 cone series (docs/bake.md, "Directional lightmaps"). A uniform sky L gives
  /// pi L (1 + 1/sqrt 3) / 2 in all three. With indirect_only: last pass minus first pass. Dilated.
  std::array<image, 3> hl2;
  /// With shadow_mask_lights (else empty): W x H RGBA, channel c = the visibility of light
  /// shadow_mask_lights[c] (lights.hpp's light_sample::visibility: 1 for a light that casts no
  /// shadow, 0 where it is below the horizon or behind a rect), 0 for unused channels. Dilated.
  image shadow_mask;
  /// With ao_distance > 0 (else empty): W x H RGB, the ambient occlusion in all three channels
  /// (image_io writes 3 or 4 channels), in [0, 1]: 1 = open, 0 = fully occluded within
  /// ao_distance. From the first pass (also with indirect_only or several bounces); texels inside
  /// geometry are filled from their own chart, seams stitched and the map dilated like the
  /// irradiance.
  image ao;
  bake_stats stats;
};

/// What the baker needs besides a scene_desc: optional per-vertex normals (vertex_count unit
/// or non-unit vectors; null: face normals).
struct bake_input {
  scene_desc scene;                       ///< geometry, materials, sky; lightmap_uvs required
  const glm::vec3* normals = nullptr;     ///< per-vertex shading normals, or null
};

/// Bakes the irradiance lightmap of a scene (all meshes share one lightmap UV space).
///
/// Errors (hemilight::error naming the problem; nothing returned):
///   invalid_argument: options out of range (size 0 or > max_lightmap_size, bounces not in
///     [1, max_bounces], bad resolution, min_coverage not in [0, 1], offset_texels < 0 or NaN,
///     dilation < -1, ao_distance < 0 or not finite, cache options out of range); no lightmap UVs; a UV more than
///     lightmap_uv_tolerance outside [0, 1] ("lightmap_uvs[7].u = 1.2 is outside [0, 1]"); with
///     strict, a triangle with 3D area but no UV area; a non-finite normal; an albedo outside
///     [0, 1]; everything scene::create rejects; no texel sampled (nothing to bake);
/// Degenerate triangles are skipped and counted, UVs within the tolerance clamped and counted,
/// triangles with 3D area but no UV area (without strict) counted and named (bake_stats).
///   cancelled: the progress callback returned false.
/// Cost: O(UV-covered texels) for the samples, then per pass one cache run (cache.hpp): one
/// render and integration per hemicube, spread over the threads, plus O(sampled texels).
bake_result bake_lightmap(const bake_input& input, const bake_options& options);

// ---- scenes: many meshes, several lightmap pages ---------------------------------------------

/// One lightmap page of a scene bake (bake_scene): its size and optional per-texel materials.
struct lightmap_page {
  int width = 256, height = 256;  ///< texels, each in [1, max_lightmap_size]
  /// Optional per-texel albedo: width x height, 3 channels, each value in
  /// [0, 1], indexed like the page's texels. Used for the bounces instead of the owner triangle's
  /// albedo. Empty (width 0): the triangles' albedo.
  image albedo;
  /// Optional per-texel emitted radiance: width x height, 3 channels, each value in
  /// [0, max_radiance]. Used instead of the owner triangle's emission, from the first pass on
  /// (which then renders through a radiance texture, bilinear like the bounces: sharp emission
  /// edges inside a texel are blurred over one texel). Empty: the triangles' emission.
  image emission;
};

/// One mesh of a scene bake: a range of the scene's triangles and where its lightmap UVs go.
///
/// UV convention (Unity's lightmapScaleOffset): the mesh's lightmap UV (scene_desc::lightmap_uvs)
/// maps to page UV  uv' = uv * uv_scale + uv_offset  (componentwise, in float), and uv' is read
/// with bake.hpp's texel convention in the page: texel (x, y) of a W x H page has its centre at
/// ((x + 0.5) / W, (y + 0.5) / H). Every uv' must lie in [0, 1]. Unity's lightmapScaleOffset
/// (x, y, z, w) is uv_scale = (x, y), uv_offset = (z, w); upload the page's rows in memory order
/// (row 0 first, as for bake_lightmap) and the engine's uv' addresses the texel baked for it.
struct bake_mesh {
  std::size_t first_triangle = 0;  ///< its triangles: [first_triangle, first_triangle + triangle_count)
  std::size_t triangle_count = 0;
  /// Index of its page in scene_bake_input::pages, or -1: an occluder only. An occluder blocks
  /// hemicubes and shadow rays and gets no texels; hemicubes see it with the radiance given by
  /// scene_bake_input::occluders.
  int page = -1;
  glm::vec2 uv_scale{1.0f};   ///< finite
  glm::vec2 uv_offset{0.0f};  ///< finite
};

/// What occluder-only meshes send to the hemicubes.
enum class occluder_radiance {
  /// Their emission alone: they reflect nothing (black to the bounces). The default: it never
  /// adds light that is not there; an occluder near baked surfaces darkens them by what it would
  /// have reflected (docs/bake.md, "Pages and occluders", measures it).
  emission,
  /// Their emission plus albedo x the previous pass's mean irradiance over all sampled texels
  /// / pi: a coarse estimate of what they reflect (one value per material for the whole scene).
  emission_plus_mean_bounce,
};

/// A scene for bake_scene: the geometry (all meshes' triangles in one scene_desc, with per-vertex
/// lightmap UVs that may lie outside [0, 1] before the meshes' scale and offset), its pages and
/// its meshes.
struct scene_bake_input {
  bake_input geometry;              ///< positions, indices, materials, lightmap UVs, sky, normals
  std::vector<lightmap_page> pages; ///< at least one
  /// Meshes in triangle order: meshes[0] starts at triangle 0, each starts where the previous one
  /// ends, the last ends at the scene's triangle count. A vertex used by several meshes is
  /// duplicated internally (each mesh maps it with its own scale and offset).
  std::vector<bake_mesh> meshes;
  occluder_radiance occluders = occluder_radiance::emission;
};

/// What bake_scene returns: one bake_result per page (its irradiance, coverage, valid, sampled,
/// directional maps, shadow mask and ambient occlusion at the page's size; its stats hold the page's texel counts:
/// texels, covered, sampled, invalid, overlapping, dilated; the rest 0) and the whole bake's
/// statistics.
struct scene_bake_result {
  std::vector<bake_result> pages;
  bake_stats stats;
};

/// Bakes every page of a scene in one bake: all pages' samples go through the same passes, so
/// light bounces between meshes of different pages (each pass's radiance texture holds all
/// pages), and occluder-only meshes shadow them. Per page the result is what bake_lightmap would
/// give for the page's meshes with the other pages' meshes present (to within float rounding of
/// the radiance lookups and the near plane, which scales with the scene's size): the samples of
/// a page are computed in its own texel grid, dilation (options.dilation, invalid samples) stays
/// inside each page, and charts of different pages never bleed into each other, neither in the
/// outputs nor in the radiance textures (each page's border behaves as clamp-to-edge).
/// options.width and height are ignored (the pages give the sizes); everything else as
/// bake_lightmap.
///
/// Errors (hemilight::error(invalid_argument) naming the problem in the caller's terms; nothing
/// returned): no pages; a page size out of range ("bake_scene: pages[1]: size 0 x 64 ...");
/// an albedo or emission image of the wrong size or channel count, or a value out of range
/// ("pages[0].albedo (3, 7) = 1.5 is outside [0, 1]"); meshes not covering the triangles in order;
/// a page index out of range ("meshes[2].page = 5 is not -1 or a page index (3 pages)"); a
/// non-finite scale or offset; a UV mapped outside the page ("meshes[2] (page 1):
/// lightmap_uvs[17] * uv_scale + uv_offset = (1.25, 0.5) is outside [0, 1]", beyond
/// lightmap_uv_tolerance); with strict, a triangle with 3D area but no area in its page
/// ("meshes[2] triangle 4 (scene triangle 40) ..."; without strict it is counted and named in the
/// whole bake's stats, bake_lightmap's rules for degenerate triangles and clamped UVs apply); bad
/// geometry as bake_lightmap reports it (except that raw UVs may lie outside [0, 1]); no texel
/// sampled in any page; bad options as bake_lightmap. cancelled: the progress callback.
/// out_of_memory: the pages' atlas (the widest page x the sum of the heights and two guard rows
/// between pages) over max_image_pixels (2^28 texels), refused before it is allocated.
/// Cost: as bake_lightmap over the sum of the pages' texels, plus copies of the vertices.
scene_bake_result bake_scene(const scene_bake_input& input, const bake_options& options);

/// The samples of a lightmap (before the offset: docs/bake.md, step 1), per texel, row-major.
struct lightmap_samples {
  int width = 0, height = 0;
  std::vector<float> coverage;              ///< summed covered fraction, clamped to [0, 1]
  /// Owner triangle (scene_desc numbering): the largest covered area (ties: the lower index); its
  /// material is the texel's. no_triangle if nothing covers the texel.
  std::vector<std::uint32_t> owner;
  /// Triangle the sample lies on: the owner if it contains the combined centroid, else the
  /// covering triangle of largest area that does, else the owner; or no_triangle.
  std::vector<std::uint32_t> sample_triangle;
  /// Sample point in UV (not texel) units: the area-weighted centroid of all covered parts, or
  /// the owner's own covered part's centroid where that lies on no covering triangle.
  std::vector<glm::vec2> centroid;
  std::vector<glm::vec3> position;          ///< sample point in 3D, on sample_triangle
  std::vector<glm::vec3> normal;            ///< unit interpolated vertex normal, or the face normal
  std::vector<float> texel_world_size;      ///< sqrt(3D area / UV area in texels) of sample_triangle
  /// Lightmap tangent frame at the sample (lightmap_tangent_frame of sample_triangle with the
  /// sample's normal): unit tangent along +u and bitangent along +v, both orthogonal to `normal`.
  /// (tangent, bitangent, normal) is left-handed on mirrored charts.
  std::vector<glm::vec3> tangent, bitangent;
  std::size_t overlapping_texels = 0;       ///< texels whose covered areas sum to more than 1.001
  /// Triangles that cover no texel: degenerate (is_degenerate_triangle), and with 3D area but no
  /// UV area (as bake_stats counts them).
  std::size_t degenerate_triangles = 0, no_uv_area_triangles = 0;

  static constexpr std::uint32_t no_triangle = 0xffffffffu;
};

/// Exact coverage and sample points of every texel. Validates like bake_lightmap (size, UVs,
/// normals) with its rules for degenerate input (bake_options::strict false: UVs within
/// lightmap_uv_tolerance clamped, degenerate triangles and triangles without UV area cover
/// nothing); positions and indices must be valid (as scene::create checks). Cost: O(sum over
/// triangles of the texels in their UV bounding box).
lightmap_samples compute_lightmap_samples(const bake_input& input, int width, int height);

/// Area (in texel units, [0, 1]) and centroid (texel units) of the part of the triangle a, b, c
/// (texel units, any winding) inside the texel square [x, x+1] x [y, y+1]. Area 0 (centroid =
/// the texel centre) if they do not overlap. Cost: clipping against 4 half-planes.
struct texel_clip {
  float area = 0.0f;
  glm::vec2 centroid{0.0f};
};
texel_clip clip_triangle_to_texel(const glm::vec2& a, const glm::vec2& b, const glm::vec2& c, int x, int y) noexcept;

/// What the baked surfaces send out, as a radiance texture over the lightmap (W x H RGB): per
/// sampled texel emission + albedo E / pi of the material of the triangle that owns it, E the
/// result's irradiance; dilated as bounce passes dilate theirs (at least 2 rings). What light
/// probes (probes.hpp: probe_options::texture) or later hemicubes should see of a baked scene.
/// `input` and `options` must be those of the bake (its size and materials). Meaningless for an
/// indirect_only bake (its E lacks the first bounce): throws error(invalid_argument) then, and
/// when the result's size does not match options. Cost: compute_lightmap_samples plus O(texels).
image bake_radiance_texture(const bake_input& input, const bake_options& options, const bake_result& result);

/// Grows the filled texels of `img` into the empty ones, `rings` times (-1: until every texel
/// is filled or nothing changes): an empty texel with at least one filled 8-neighbour gets the
/// mean of them and becomes filled. `filled` (width x height, 0/1) is updated. Returns the number
/// of texels filled. Throws error(invalid_argument) if filled's size is not width x height or
/// rings < -1. Cost: O(texels x rings).
std::size_t dilate(image& img, std::vector<std::uint8_t>& filled, int rings);

// ---- directional lightmaps ------------------------------------------------------------------

/// The lightmap tangent frame of a triangle (positions p, lightmap UVs uv) at a point of unit
/// shading normal n: t = dP/du projected onto the tangent plane and normalised (Gram-Schmidt);
/// b = +-(n x t), the sign that makes b . dP/dv >= 0 (so (t, b, n) is left-handed on mirrored
/// charts, as in tangent-space normal mapping); f.n = n. Engines that shade with the HL2 maps must
/// build the same frame from the lightmap UVs. Degenerate cases: when dP/du is (nearly) along n
/// or the UV triangle has no area, t comes from dP/dv (t = b x n) or, failing that,
/// make_frame(n). Never NaN for a unit n and finite input. Cost: O(1).
frame lightmap_tangent_frame(const glm::vec3 (&p)[3], const glm::vec2 (&uv)[3], const glm::vec3& n) noexcept;

/// Writes the bake's EXR files (write_exr, image_io.hpp) with names prefix + suffix:
/// "_irradiance.exr", "_mask.exr" (bake_mask_image), and when present "_sh_l1_0.exr" ..
/// "_sh_l1_3.exr" (coefficients Y00, Y1-1, Y10, Y11), "_hl2_0.exr" .. "_hl2_2.exr",
/// "_shadow_mask.exr" (RGBA) and "_ao.exr" (the AO in R, G and B). Returns
/// the paths written, in that order. Errors: as write_exr (error(io) naming the file; files
/// written before the failure stay).
std::vector<std::string> write_bake_exrs(const bake_result& result, const std::string& prefix,
                                         exr_pixel_type type = exr_pixel_type::float32);

/// Mask image of a bake: R = coverage, G = valid, B = 1 where a sample was placed (covered
/// >= min_coverage), for writing with write_exr.
image bake_mask_image(const bake_result& result);

}  // namespace hemilight
