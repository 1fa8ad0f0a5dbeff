// hemilight/bake.hpp — the lightmap baker: from triangles with lightmap UVs to an irradiance
// lightmap, through the irradiance cache, with bounces.
//
// Pipeline (docs/bake.md):
//   1. Samples. Every triangle is rasterized in UV space over the W x H texel grid with exact
//      coverage: the triangle (in texel units) is clipped against each texel square
//      (Sutherland-Hodgman), giving the covered area and its centroid. Per texel:
//        - coverage = the summed covered fraction of all triangles, clamped to 1;
//        - owner = the triangle with the largest covered area (ties: lower triangle index)
//          — the overlap rule: where triangles overlap in UV space the owner's material is the
//          texel's material and the owner is preferred for the sample;
//        - sample point = the area-weighted centroid of all covered parts; it is mapped to 3D
//          through the owner if it lies inside the owner's UV triangle, else through another
//          covering triangle that contains it (largest area first), else the owner's own centroid
//          is used. (So a texel on the diagonal of a quad gets its centre, a texel on a chart
//          border the centroid of the covered part: never a point outside the surface.)
//        - normal = the triangle's interpolated vertex normal there (normalised), or its face
//          normal when no vertex normals are given (or they interpolate to ~0).
//      Texels with coverage < min_coverage get no sample.
//   2. Offset. Each sample moves along its normal by
//          max(2 x default_near_distance(scene), offset_texels x texel world size),
//      texel world size = sqrt(3D area / UV area in texels) of the sample's triangle: the point
//      leaves its own surface by a fraction of a texel, and always by more than the near plane.
//   3. Irradiance. cache_irradiance() with make_hemicube_sampler() (cache.hpp), each hemicube
//      rolled about its normal by an angle hashed from the sample position (deterministic per
//      texel): hemicube aliasing shows as fine noise, not bands. Samples inside geometry (their own
//      hemicube sees back faces, or the cache presumes them inside from an invalid sample on the
//      same side of the same surface: cache.hpp) are filled by dilating the valid texels around
//      them in the lightmap (the same chart: never light from across a wall), in both modes.
//   3b. Lights (bake_options::lights, lights.hpp). Their direct irradiance E_L is computed at
//      every sample once, with shadow rays (never interpolated: the cache sees only what the
//      hemicubes gather), and every pass's irradiance is E_hemicube + E_L. So pass 1's radiance
//      texture holds emission + albedo (E_hemicube + E_L) / pi and the bounces carry the lights'
//      light; indirect_only (E_bounces - E_1) drops E_L with the emitters' first bounce. The SH
//      and HL2 maps get each light's part along its direction (below), and an optional shadow
//      mask holds the visibility of up to four lights per texel.
//   4. Bounces. Pass 1 sees emission and sky. Pass k > 1 renders with a radiance texture (same
//      size as the lightmap) holding, per texel, emission + albedo E_{k-1} / pi of the texel's
//      owner, dilated like the lightmap. The result of pass `bounces` is the lightmap; with
//      indirect_only it is E_bounces - E_1, clamped at 0 (everything but the first bounce).
//   5. Dilation. Every chart grows into the empty texels around it, one ring per step (each
//      empty texel with a filled 8-neighbour gets the mean of its filled 8-neighbours), so
//      bilinear lookups at chart borders do not pull in black.
//
//   6. Directional lightmaps (optional, bake_options::output_sh_l1 / output_hl2). In the last pass
//      (and, with indirect_only, the first) the hemicube sampler also computes the world-space L1
//      SH of the incoming radiance and/or the irradiance on the cone of HL2 directions (54.74
//      degrees from the normal) as a Fourier series in azimuth (cache.hpp, hl2_cone); cache
//      records carry both and each texel gets their Ward-weighted average (cones rotated to a
//      common reference tangent first). SH maps are those coefficients. HL2 maps are the cone
//      series read at the azimuths of the three basis vectors of the texel's lightmap tangent
//      frame (lightmap_tangent_frame, hl2_from_cone): frame-correct for any tangent, exact for
//      light within 35.26 degrees of the normal, otherwise cut at azimuthal order 3 (measured 1.7%
//      RMS for a grazing side light, where going through L1 SH would give 25%; docs/bake.md).
//      All of them are dilated like the irradiance. A light adds to them what radiance from one
//      direction w (light_sample::direction) would: with F = E_L / (n . w), SH coefficient
//      F Y(w) and HL2 value F max(0, b_k . w). Exact for hard lights; for soft ones w is the
//      direction of the visible part's vector irradiance (the spread of a small disc or sphere
//      is lost: L1 and the clamped cosine change by O(a^2) for a light of angular radius a).
//
// UV <-> texel convention (the same as radiance_texture::sample, raster.hpp): texel (x, y) has
// its centre at uv = ((x + 0.5) / W, (y + 0.5) / H); u grows with the column x, v with the row y.
// Row 0 (v near 0) is the first row in memory and the first (top) scanline of the EXR files.
// Upload the rows in memory order and sample with the same uv in Direct3D or OpenGL.
//
// Determinism: the same input gives bitwise the same lightmap for any thread count.
#pragma once

#include "hemilight/cache.hpp"
#include "hemilight/cubemap.hpp"
#include "hemilight/image_io.hpp"
#include "hemilight/lights.hpp"
#include "hemilight/scene.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace hemilight {

/// Largest lightmap width or height bake_lightmap accepts. The per-sample state is kept for
/// covered texels only: peak memory is about 32 bytes per texel (the result's images and masks)
/// plus, per sampled texel, about 124 bytes on a flat quad at N = 8 and up to about 210 bytes on
/// a heightfield at N = 64 with more cache records (docs/bake.md, "Scaling" and "Memory"), so a
/// fully sampled 8192^2 needs up to about 14 GiB; larger maps are refused with
/// error(invalid_argument).
inline constexpr int max_lightmap_size = 8192;

/// Options of bake_lightmap.
struct bake_options {
  int width = 256, height = 256;  ///< lightmap size in texels, each in [1, max_lightmap_size]
  int resolution = 64;            ///< hemicube N (even, 2..4096)
  /// Number of light bounces, >= 1: 1 = direct light only (emission and sky); each more bounce
  /// is one more pass of the whole cache. At most 64.
  int bounces = 1;
  /// Store only the indirect part: E_bounces - E_1 (clamped at 0), for engines that add direct
  /// light at run time. Needs bounces >= 2 to be nonzero.
  bool indirect_only = false;
  /// Texels whose covered fraction is below this get no sample (they are filled by dilation).
  /// Range [0, 1]; 0 samples every texel touched by a triangle.
  float min_coverage = 0.01f;
  /// Sample offset along the normal in texel world sizes (see the top of this header), >= 0.
  float offset_texels = 0.05f;
  /// Rings of dilation around every chart, >= 0; -1 fills every empty texel of the lightmap.
  int dilation = 16;
  /// Cache settings (error_threshold, radii, weights, ...). Its thread_count and progress are
  /// ignored: the fields below are used instead.
  cache_options cache;
  /// false: a hemicube at every sampled texel (no interpolation); the reference the cache's
  /// error is measured against. (cache.fill_invalid is ignored: the baker fills invalid texels
  /// by dilation.)
  bool use_cache = true;
  int thread_count = 0;  ///< 0 = all cores
  /// Output the L1 SH lightmaps (bake_result::sh_l1): world-space coefficients of the incoming
  /// radiance. Costs 3 multiply-adds per hemicube texel in the last pass (and the first with
  /// indirect_only): a few percent of the bake; off by default.
  bool output_sh_l1 = false;
  /// Output the Half-Life 2 basis lightmaps (bake_result::hl2), in each texel's lightmap tangent
  /// frame, from the interpolated HL2 cone series (top of this header). Costs 21 multiply-adds per
  /// hemicube texel in the directional passes, 96 bytes per record, and once per process a weight
  /// table (~0.25 s at N = 64); off by default.
  bool output_hl2 = false;
  /// Optional environment sky: hemicube texels that hit nothing see this cube map's radiance along
  /// their world direction (raster_options::sky; seamless bilinear, directions = the scene's world
  /// axes, OpenGL face table) instead of scene_desc::sky_radiance. Build it with
  /// cubemap::from_image (which checks every value). null: the constant sky.
  std::shared_ptr<const cubemap> environment;
  bool edge_coverage = false;  ///< hemicubes with exact edge coverage (raster_options::edge_coverage; docs/raster.md)
  /// Analytic lights (lights.hpp): direct light at every sample, added to every pass (step 3b at
  /// the top of this header). Checked as validate_lights does ("bake_lightmap: lights[2].radius
  /// = -1 is negative"). Cost: per sample and light one shadow ray (hard) or 12 (soft), 264 in a
  /// penumbra (direct_options). Empty: no lights.
  std::vector<light> lights;
  /// Shadow rays of the lights: sample counts and ray offset (lights.hpp). Checked as
  /// validate_direct_options does.
  direct_options direct;
  /// Shadow mask (bake_result::shadow_mask): channel c holds, per texel, the visibility in [0, 1]
  /// of light shadow_mask_lights[c] (an index into lights), the mask that engines with real-time
  /// direct light multiply it by; -1 leaves the channel 0. All -1 (the default): no mask. An
  /// index past the lights is an error.
  std::array<int, 4> shadow_mask_lights{{-1, -1, -1, -1}};
  /// Called from the calling thread with the fraction of the whole bake done, in [0, 1] and never
  /// decreasing; return
  /// false to cancel (error(status::cancelled) is thrown, nothing is returned). May be empty.
  std::function<bool(float fraction)> progress;
};

/// Statistics of one bake.
struct bake_stats {
  std::size_t texels = 0;             ///< W x H
  std::size_t covered_texels = 0;     ///< texels with coverage > 0
  std::size_t sampled_texels = 0;     ///< texels with coverage >= min_coverage (one sample each)
  std::size_t invalid_texels = 0;     ///< sampled texels filled by the cache (inside geometry), any pass
  std::size_t overlapping_texels = 0; ///< texels whose covering triangles sum to more than 1.001 texel (UV overlap)
  std::size_t dilated_texels = 0;     ///< empty texels filled by dilation
  std::size_t hemicubes = 0;          ///< hemicubes rendered, all passes
  std::size_t records = 0;            ///< cache records, all passes
  std::vector<cache_stats> passes;    ///< the cache's statistics per pass
  double coverage_seconds = 0.0;      ///< step 1
  double direct_seconds = 0.0;        ///< step 3b: the lights' direct irradiance (0 without lights)
  double seconds = 0.0;               ///< the whole bake (wall time)
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
  /// interpolated HL2 cone series (top of this header). A uniform sky L gives pi L (1 + 1/sqrt 3) / 2
  /// in all three. With indirect_only: last pass minus first pass. Dilated.
  std::array<image, 3> hl2;
  /// With shadow_mask_lights (else empty): W x H RGBA, channel c = the visibility of light
  /// shadow_mask_lights[c] (lights.hpp's light_sample::visibility: 1 for a light that casts no
  /// shadow, 0 where it is below the horizon or behind a rect), 0 for unused channels. Dilated.
  image shadow_mask;
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
///   invalid_argument: options out of range (size 0 or > max_lightmap_size, bounces < 1 or > 64,
///     bad resolution, min_coverage not in [0, 1], offset_texels < 0 or NaN, dilation < -1, cache
///     options out of range); no lightmap UVs; a UV outside [0, 1] ("lightmap_uvs[7].u = 1.2 is
///     outside [0, 1]"); a triangle with nonzero 3D area but zero UV area; a non-finite normal; an
///     albedo outside [0, 1];
///     everything scene::create rejects; no texel sampled (nothing to bake);
///   cancelled: the progress callback returned false.
/// Cost: O(UV-covered texels) for the samples, then per pass one cache run (cache.hpp): about
/// hemicubes x (20-100 us at N = 64) / threads.
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
/// directional maps and shadow mask at the page's size; its stats hold the page's texel counts:
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
/// lightmap_uvs[17] * uv_scale + uv_offset = (1.25, 0.5) is outside [0, 1]"); a triangle with
/// 3D area but no area in its page ("meshes[2] triangle 4 (scene triangle 40) ..."); bad
/// geometry as bake_lightmap reports it (except that raw UVs may lie outside [0, 1]); no texel
/// sampled in any page; bad options as bake_lightmap. cancelled: the progress callback.
/// out_of_memory: the pages' atlas (the widest page x the sum of the heights and two guard rows
/// between pages) over max_image_pixels (2^28 texels), refused before it is allocated.
/// Cost: as bake_lightmap over the sum of the pages' texels, plus copies of the vertices.
scene_bake_result bake_scene(const scene_bake_input& input, const bake_options& options);

/// The samples of a lightmap (step 1 of the pipeline, before the offset), per texel, row-major.
struct lightmap_samples {
  int width = 0, height = 0;
  std::vector<float> coverage;              ///< covered fraction, clamped to [0, 1]
  /// Owner triangle (scene_desc numbering) by the overlap rule, or no_triangle if nothing covers the texel.
  std::vector<std::uint32_t> owner;
  /// Triangle the sample lies on (the owner or another covering triangle), or no_triangle.
  std::vector<std::uint32_t> sample_triangle;
  std::vector<glm::vec2> centroid;          ///< sample point in UV (not texel) units
  std::vector<glm::vec3> position;          ///< sample point in 3D, on sample_triangle
  std::vector<glm::vec3> normal;            ///< unit normal at the sample
  std::vector<float> texel_world_size;      ///< sqrt(3D area / UV area in texels) of sample_triangle
  /// Lightmap tangent frame at the sample (lightmap_tangent_frame of sample_triangle with the
  /// sample's normal): unit tangent along +u and bitangent along +v, both orthogonal to `normal`.
  /// (tangent, bitangent, normal) is left-handed on mirrored charts.
  std::vector<glm::vec3> tangent, bitangent;
  std::size_t overlapping_texels = 0;       ///< texels whose covered areas sum to more than 1.001

  static constexpr std::uint32_t no_triangle = 0xffffffffu;
};

/// Exact coverage and sample points of every texel (step 1). Validates like bake_lightmap
/// (size, UVs, normals, zero-area UV triangles); positions and indices must be valid (as
/// scene::create checks). Cost: O(sum over triangles of the texels in their UV bounding box).
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

/// Gives `mesh` lightmap UVs for the baker: planar groups of edge-connected triangles (same
/// plane, shared edge by position) become charts, each projected onto its plane at one common
/// texel density and packed in shelves into a size x size lightmap with `padding` empty texels
/// between charts (and at the border). Vertices shared by several charts are duplicated, so the
/// mesh's vertex count may grow; triangles keep their order and materials. Meant for the
/// built-in scenes (boxes, rooms), not as a general unwrapper. Throws error(invalid_argument)
/// for size < 8, padding < 0 or 4 padding >= size. Cost: O(T log T) plus a few packings.
void generate_lightmap_uvs(scene_mesh& mesh, int size, int padding = 2);

// ---- directional lightmaps ------------------------------------------------------------------

/// The Half-Life 2 basis in a tangent frame (t, b, n): local coordinates of its three unit
/// vectors, the same as integrate.hpp's irradiance_sample::hl2: (-1/sqrt6, 1/sqrt2, 1/sqrt3),
/// (-1/sqrt6, -1/sqrt2, 1/sqrt3), (sqrt(2/3), 0, 1/sqrt3). They are mutually orthogonal and each
/// is 54.7 degrees from n.
inline constexpr float hl2_basis[3][3] = {
    {-0.408248290f, 0.707106781f, 0.577350269f},
    {-0.408248290f, -0.707106781f, 0.577350269f},
    {0.816496581f, 0.0f, 0.577350269f},
};

/// Irradiance of a plane of unit normal d from L1 SH coefficients of incoming radiance
/// (integrate.hpp's order and normalisation, world space): the clamped-cosine convolution of the
/// L1 radiance, (sqrt(pi)/2) c_00 + sqrt(pi/3) (c_11 d.x + c_1-1 d.y + c_10 d.z), per channel,
/// clamped at 0. Exact for radiance fields in SH bands 0 and 1 and for a uniform sky over any
/// hemisphere; otherwise the band-2 part of the true irradiance is missing. Cost: O(1).
glm::vec3 sh_l1_irradiance(const std::array<glm::vec3, 4>& sh, const glm::vec3& d) noexcept;

/// The three Half-Life 2 values of a texel from L1 SH alone: sh_l1_irradiance along the world
/// directions of hl2_basis in frame f (f.t, f.b, f.n unit and orthogonal; left-handed frames are
/// fine: the basis follows the frame). For engines that keep only the SH maps. L1 loses the
/// band >= 2 part of the clamped cosine: 13% RMS for a small overhead lamp, 25% for a grazing side
/// light (docs/bake.md); the baker's own HL2 maps use the cone series instead. Cost: O(1).
std::array<glm::vec3, 3> hl2_from_sh_l1(const std::array<glm::vec3, 4>& sh, const frame& f) noexcept;

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
/// "_sh_l1_3.exr" (coefficients Y00, Y1-1, Y10, Y11), "_hl2_0.exr" .. "_hl2_2.exr" and
/// "_shadow_mask.exr" (RGBA). Returns
/// the paths written, in that order. Errors: as write_exr (error(io) naming the file; files
/// written before the failure stay).
std::vector<std::string> write_bake_exrs(const bake_result& result, const std::string& prefix,
                                         exr_pixel_type type = exr_pixel_type::float32);

/// Mask image of a bake: R = coverage, G = valid, B = 1 where a sample was placed (covered
/// >= min_coverage), for writing with write_exr.
image bake_mask_image(const bake_result& result);

}  // namespace hemilight
