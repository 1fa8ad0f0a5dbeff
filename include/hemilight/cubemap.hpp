// hemilight/cubemap.hpp — environment cube maps: texel <-> direction mappings (texel centres,
// NVTT's stretch and warp), GPU-like CPU sampling, the runtime lookup fixup, cosine-power and
// irradiance filtering with exact texel solid angles, 9-coefficient SH irradiance, mip chains.
//
// Conventions (geometry.hpp, image_io.hpp, docs/cubemap.md):
//   - Faces in OpenGL order +X, -X, +Y, -Y, +Z, -Z. A face is the plane "major axis = 1" with
//     face coordinates (u, v) = (sc / |ma|, tc / |ma|) in [-1, 1] from the GL table; u grows with
//     the texel column x (GL s), v with the row y (GL t). Direction of (u, v) on face f:
//     axis(f) + u * column(f) + v * row(f) (cube_face_point).
//   - Memory: cube_image (image_io.hpp), face-major, rows, columns, channels interleaved.
//   - Texel weights are exact solid angles of the texel's square on its face (area-element
//     formula), whatever mapping assigned its direction.
//
// Mappings (texel index x of a face of n texels -> face coordinate u):
//   centre   u = (x + 0.5) * 2/n - 1                  what GPUs sample
//   stretch  u = 2x / (n - 1) - 1                     edge texels of adjacent faces coincide
//   warp     u = c + a c^3, c = the centre u, a = n^2 / (n - 1)^3   edge texels coincide too
// Size 1: every mapping gives u = 0 (the face centre). Under stretch and warp the edge texels
// (x = 0 and x = n - 1) get exactly -1 and +1 and u(n-1-x) = -u(x) exactly, so adjacent faces'
// edge texels have bitwise identical directions.
//
// Thread safety: everything here is a pure function or reads immutable objects; cubemap::sample
// may be called from any number of threads at once.
#pragma once

#include "hemilight/error.hpp"
#include "hemilight/geometry.hpp"
#include "hemilight/image_io.hpp"

#include <glm/glm.hpp>

#include <array>
#include <cstddef>
#include <vector>

namespace hemilight {

// ---------------------------------------------------------------------------------------------
// Mappings
// ---------------------------------------------------------------------------------------------

/// How output texels get their directions (the values match hemilight_edge_fixup of the C ABI).
enum class edge_fixup : int {
  none = 0,     ///< texel centres: the GPU's own mapping
  stretch = 1,  ///< NVTT stretch: u = 2x/(n-1) - 1; exactly undone by fixup_lookup
  warp = 2,     ///< NVTT warp: u = c + a c^3 on the centre c, a = n^2/(n-1)^3
};

/// Largest cube-map face size hemilight's cube-map functions accept: the largest whose six faces
/// fit in max_image_pixels (image_io.hpp: 2^28 pixels), so every size in [1, 6688] can be
/// allocated, filtered and written (6 x 6688^2 RGB floats is 3 GiB).
inline constexpr int cubemap_max_size = 6688;

/// Face coordinate u in [-1, 1] of texel index x (0..n-1) of an n-texel face edge under a
/// mapping (table above). n = 1 gives 0. Computed in double; symmetric (u(n-1-x) = -u(x)) and
/// exactly +-1 at the edge texels for stretch and warp. Precondition: 1 <= n, 0 <= x < n
/// (asserted). Cost: a few flops.
double cubemap_texel_coordinate(int n, int x, edge_fixup mapping) noexcept;

/// The unnormalised direction axis + u column + v row of face coordinates (u, v) on a face (see
/// the top of this header; the same as geometry.hpp's cube_direction_from_face with
/// u = 2s - 1, v = 2t - 1, but without the rounding of going through s, t). Exact.
glm::vec3 cube_face_point(cube_face face, float u, float v) noexcept;

/// Unit direction of texel (x, y) of `face` of a size-n cube map under a mapping.
/// Precondition: 1 <= n <= cubemap_max_size, face in [0, 6), x, y in [0, n) (asserted; the
/// C ABI validates). Cost: a few flops and a square root.
glm::vec3 cubemap_texel_direction(int n, int face, int x, int y, edge_fixup mapping) noexcept;

/// Exact solid angle (sr) of texel (x, y) of a size-n face: the square
/// [x, x+1] x [y, y+1] * 2/n - 1 on the face plane, by the area-element formula. The 6 n^2
/// texels sum to 4 pi. Precondition as cubemap_texel_direction. Cost: 4 atan2 (double).
double cubemap_texel_solid_angle(int n, int x, int y) noexcept;

// ---------------------------------------------------------------------------------------------
// Runtime lookup fixup
// ---------------------------------------------------------------------------------------------

/// The lookup transform that makes a stretch-filtered cube map seamless when sampled per face
/// (clamp-to-edge bilinear, no seamless filtering): the two components other than the major
/// one are multiplied by
///   scale = (size - 1) / size            when lod < 0 (a known, fixed size), or
///   scale = max(0, 1 - 2^lod / size)     when lod >= 0 (explicit LOD, size = top-level size).
/// Sampling the result at texel-centre coordinates then lands exactly where the stretch mapping
/// put the texel's direction (exact, linear); for warp it is exact only at face centres and
/// edges (see docs/cubemap.md for how far off it is in between).
///
/// Behaviour, identical in the GLSL and HLSL snippets (include/hemilight/shaders/):
///   - major axis: the first of x, y, z whose |component| is >= the other two (the same tie rule
///     as cube_face_from_direction), so on an edge or corner tie the other components shrink and
///     the result lies strictly inside that face: the face choice no longer depends on how the
///     hardware breaks ties (stretch edge texels coincide, so either face gives the same value);
///   - the zero vector is returned unchanged (zero); a NaN component fails every comparison it
///     is in, so the major axis is chosen among the others (z if all fail) and the NaN
///     propagates into the result (the C ABI rejects NaN and Inf instead);
///   - lod at or past the last mip (2^lod >= size) gives scale 0: every lookup goes to the face
///     centre, which is where a 1 x 1 face's single texel is (the stretch mapping at size 1);
///   - the length of the vector changes; cube lookups do not care, normalise if you do.
/// Precondition: size >= 1 (asserted). Cost: a few flops and one exp2.
glm::vec3 fixup_lookup(const glm::vec3& direction, int size, float lod) noexcept;

// ---------------------------------------------------------------------------------------------
// Cube maps with mips, and GPU-like sampling
// ---------------------------------------------------------------------------------------------

/// A cube map with an optional mip chain: levels[0] is the top level (size n), levels[i] has
/// size max(1, n >> i), all with the same channel count (3 or 4). Immutable once built when
/// shared between threads.
struct cubemap {
  std::vector<cube_image> levels;

  int size() const noexcept { return levels.empty() ? 0 : levels[0].size; }
  int channels() const noexcept { return levels.empty() ? 0 : levels[0].channels; }
  int level_count() const noexcept { return static_cast<int>(levels.size()); }

  /// A cube map of one level (takes ownership). With build_mips, the full chain down to 1 x 1
  /// is added by solid-angle-weighted 2 x 2 averaging (downsample_cube). Throws
  /// error(invalid_argument) for an inconsistent image (size < 1 or > cubemap_max_size, channels
  /// not 3 or 4, pixel count wrong) or non-finite pixels. Cost: O(6 n^2).
  static cubemap from_image(cube_image top, bool build_mips);

  /// Throws error(invalid_argument) naming the problem if levels are empty, inconsistent (sizes,
  /// channels, pixel counts) or hold non-finite values. Cost: O(pixels).
  void validate() const;

  /// The sky lookup for the rasterizer: radiance seen along `direction` (need not be unit),
  /// seamless bilinear at the top level; RGB in .xyz, alpha (1 for RGB maps) in .w. A zero or
  /// non-finite direction gives the +X face centre's value (never NaN). Thread-safe on an
  /// immutable cubemap. Precondition: level_count() >= 1. Cost: O(1), one bilinear lookup.
  glm::vec4 sample(const glm::vec3& direction) const noexcept;
};

/// One 2 x 2-smaller level: each texel is the solid-angle-weighted mean of its four children,
/// so the integral over any texel is kept (a size-1 input gives a copy; odd sizes > 1 are
/// refused). Throws error(invalid_argument) for odd sizes > 1. Cost: O(6 n^2).
cube_image downsample_cube(const cube_image& level);

/// How a CPU lookup filters, like GPUs do.
enum class cube_sampling {
  clamp_per_face,  ///< bilinear inside the chosen face, clamp-to-edge (no seamless filtering)
  seamless,        ///< bilinear across faces (GL_TEXTURE_CUBE_MAP_SEAMLESS / D3D10+): a texel
                   ///< beyond an edge is taken from the neighbouring face; beyond a corner, the
                   ///< missing texel is the mean of the three that meet there
};

/// Bilinear lookup of one level along `direction` (need not be unit): face by
/// cube_face_from_direction, texel-centre coordinates. Output: channels in .xyzw (w = 1 for RGB).
/// A zero or non-finite direction reads the +X face centre. Precondition: a consistent level.
glm::vec4 sample_bilinear(const cube_image& level, const glm::vec3& direction, cube_sampling mode) noexcept;

/// Explicit-LOD lookup: lod clamped to [0, level_count - 1] (NaN reads level 0), trilinear
/// between floor(lod) and the next level. Precondition: map.level_count() >= 1.
glm::vec4 sample_lod(const cubemap& map, const glm::vec3& direction, float lod, cube_sampling mode) noexcept;

/// One cube-map level in memory the caller owns: six faces of size x size texels of `channels`
/// (3 or 4) floats, laid out as cube_image::pixels.
struct cube_level_view {
  const float* pixels = nullptr;
  int size = 0;
  int channels = 3;
};

/// sample_lod over a mip chain of views (levels[l] of size max(1, levels[0].size >> l)), read in
/// place: what an engine's mapped texture memory gives without a copy. Precondition:
/// level_count >= 1 and every view consistent. Cost: at most two bilinear lookups.
glm::vec4 sample_lod(const cube_level_view* levels, int level_count, const glm::vec3& direction, float lod,
                     cube_sampling mode) noexcept;

/// A procedural test environment (linear radiance, strictly positive): a sky brighter towards
/// +y, a darker ground below the horizon, a few coloured bands across the sky and a sun of
/// radiance ~200 and angular radius ~2.9 degrees with a smooth rim. Texel values are the
/// function at texel centres. Used by the tests, examples and benchmarks. Throws as
/// cube_image::make for bad sizes or channels. Cost: O(6 size^2).
cube_image procedural_environment(int size, int channels = 3);

// ---------------------------------------------------------------------------------------------
// Filtering
// ---------------------------------------------------------------------------------------------

/// Options of the fast filters.
struct filter_options {
  edge_fixup fixup = edge_fixup::none;  ///< mapping of the output texel directions
  int thread_count = 0;                 ///< 0: all cores (parallel.hpp)
  /// Lobe cutoff, in (0, 1): input texels whose weight dot^p is below this are skipped; the lobe's
  /// angular extent is acos(cutoff^(1/p)) (docs/cubemap.md compares cutoffs).
  float cutoff = 1e-4f;
  /// Accuracy/speed knob: the filter reads the coarsest input mip whose texels (2/size rad at a
  /// face centre) are at most sigma / texels_per_sigma, sigma = 1/sqrt(p) the lobe's width.
  /// Larger is slower and closer to brute force (docs/cubemap.md, "Speed against accuracy").
  float texels_per_sigma = 2.5f;
  /// Smallest input mip size the cosine-power filter reads: a bright compact source such as a sun
  /// needs several texels per lobe width (docs/cubemap.md, "Filtering").
  int min_input_size = 64;
  /// Input mip size the irradiance (cosine-lobe) filter reads (clamped to the input's size); the
  /// error falls as O(size^-2) (docs/cubemap.md, "Irradiance methods against brute force").
  int irradiance_input_size = 16;
  /// true (default): the lobe weights are computed once per call, in double, for the output
  /// texels of one eighth of one face, and applied to all 48 symmetric images of them, so each tap
  /// is a multiply-add. false: the lobe is evaluated per tap (a 1024-step table for p >= 8), kept
  /// for comparison. Both read the same input mip and cut the lobe at the same extent.
  bool precomputed_weights = true;
  /// Mip chains only (filter_mip_chain, filter_mip_chain_powers), texel-centre outputs only
  /// (fixup none; ignored otherwise): a level whose lobe is wider than the previous level's is
  /// filtered from that previous output level with the differential lobe 1/q = 1/p_k - 1/p_(k-1),
  /// so it reads a narrower lobe; only for levels with p >= 256 whose previous level has at least
  /// 2 texels_per_sigma sqrt(q) texels. Off by default (docs/cubemap.md, "Cascade").
  bool cascade = false;
};

/// Filters `input` with the normalised cosine-power lobe: each output texel with direction d
/// (from options.fixup's mapping) is sum L(w) W(w) / sum W(w), W = solid_angle(w) max(0, d.w)^p,
/// over the input texels w within the lobe's extent, read from the input mip chosen by the
/// options (only level 0 of `input` is read; coarser mips are built from it). Constant input gives exactly that
/// constant (to float rounding). power: p > 0 (p = 1 is the cosine lobe, normalised).
/// Deterministic: bitwise identical for any thread count. A lobe narrower than the input's
/// texels (sigma below ~1 input texel) is undersampled; where no input texel centre lies inside
/// it, the output is the input texel that contains d (the limit of a very narrow lobe).
/// Throws error(invalid_argument) for an invalid input (cubemap::validate), p not finite and
/// > 0, output_size outside [1, cubemap_max_size], or bad options. Cost: about
/// 6 out^2 * 6 (4.3 r)^2 taps for narrow lobes, r the lobe's width in texels of the input mip
/// read (texels_per_sigma to twice that, or less when the input's top level is coarser), the
/// whole input mip for wide lobes; with precomputed_weights a tap is a multiply-add and 1/48 of
/// them also cost a weight evaluation. Extra memory with precomputed weights: the weights and
/// runs of at most ~2M taps at a time (~16 MB), 4 bytes per output texel, and for RGB input a
/// four-float copy of the input mip read (16 bytes per texel).
cube_image filter_cosine_power(const cubemap& input, float power, int output_size, const filter_options& options = {});

/// Irradiance E(n) = integral of L(w) max(0, n.w) dw (W/m^2 for L in W/m^2/sr; a uniform sky L
/// gives pi L), per output texel direction n, by the same fast filter with the cosine lobe over
/// the whole hemisphere, reading the input mip of size options.irradiance_input_size; the
/// quadrature is normalised so that a constant map gives exactly pi L. Errors as
/// filter_cosine_power. Cost: 6 out^2 * (texels of the input mip on a hemisphere).
cube_image filter_irradiance(const cubemap& input, int output_size, const filter_options& options = {});

/// The brute-force reference of filter_cosine_power for the output texels listed in `texels`
/// (indices into the output's 6 out^2 texels, face-major) or all of them when `texels` is empty:
/// every texel of input level 0, exact solid angles, std::pow in double, no cutoff. power <= 0
/// means the irradiance filter (cosine lobe, times pi / sum of weights as filter_irradiance).
/// Returns channels() values per listed texel (or a full cube image's pixels). Errors as
/// filter_cosine_power. Cost: 6 n_in^2 per output texel — slow on purpose.
std::vector<float> filter_reference(const cube_image& input, float power, int output_size, edge_fixup fixup,
                                    const std::vector<std::size_t>& texels, int thread_count = 0);

/// Specular power of mip level `level` of a chain whose top level has size `top_size` (the gloss
/// mapping): the lobe's width sigma = 1/sqrt(p) equals `texels` texels of that level at a face
/// centre (2/size rad each), p = (size / (2 texels))^2, size = max(1, top_size >> level).
/// texels = 1 by default: top level of 256 gets p = 16384, the 1 x 1 level p = 0.25.
/// Precondition: top_size >= 1, level >= 0, texels > 0.
float gloss_power(int top_size, int level, float texels = 1.0f) noexcept;

/// A radiance mip chain: level i (size max(1, output_size >> i)) is filter_cosine_power of
/// `input` with gloss_power(output_size, i, lobe_texels), all levels down to 1 x 1 (use
/// `levels` > 0 to stop earlier). Errors as filter_cosine_power.
cubemap filter_mip_chain(const cubemap& input, int output_size, const filter_options& options = {},
                         float lobe_texels = 1.0f, int levels = 0);

/// A radiance mip chain with a specular power per level: level i (size max(1, output_size >> i))
/// is filter_cosine_power of `input` with powers[i], for every entry of `powers` (at most the
/// number of levels down to 1 x 1). The same as calling filter_cosine_power per level, but the
/// input's mips are built once. Use it for another gloss mapping, e.g. cmft's
/// p_i = 2^(10 (1 - i / 8) + 1). Errors as filter_cosine_power; an empty `powers`, too many
/// entries or an invalid power throws error(invalid_argument).
cubemap filter_mip_chain_powers(const cubemap& input, int output_size, const std::vector<float>& powers,
                                const filter_options& options = {});

// ---------------------------------------------------------------------------------------------
// Spherical harmonics (bands 0-2)
// ---------------------------------------------------------------------------------------------

/// Nine SH coefficients per channel (real SH, the usual order: (0,0), (1,-1), (1,0), (1,1),
/// (2,-2), (2,-1), (2,0), (2,1), (2,2); Y_1,-1 ~ y, Y_1,0 ~ z, Y_1,1 ~ x). Channels in .xyzw.
struct sh9 {
  std::array<glm::dvec4, 9> coefficients{};
};

/// The nine real SH basis functions at a unit direction.
std::array<double, 9> sh9_basis(const glm::dvec3& w) noexcept;

/// Projects a cube-map level on SH bands 0-2 with exact texel solid angles (directions at
/// texel centres). Deterministic for any thread count. Errors: error(invalid_argument) for an
/// inconsistent or non-finite image. Cost: 6 n^2 * ~30 flops.
sh9 project_sh9(const cube_image& level, int thread_count = 0);

/// Irradiance at unit normal n from SH radiance: sum A_l L_lm Y_lm(n) with the clamped-cosine
/// band factors A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4 (Ramamoorthi and Hanrahan 2001).
/// Exact for radiance in bands 0-2; otherwise the SH truncation error, large for a small bright
/// sun (docs/cubemap.md). Cost: ~40 flops.
glm::dvec4 sh9_irradiance(const sh9& radiance, const glm::dvec3& n) noexcept;

/// A cube map of size `size` whose texels (directions from `mapping`) hold sh9_irradiance.
/// channels: 3 or 4. Throws error(invalid_argument) for a bad size or channel count.
cube_image irradiance_from_sh9(const sh9& radiance, int size, edge_fixup mapping, int channels = 3,
                               int thread_count = 0);

// ---------------------------------------------------------------------------------------------
// Spherical harmonics (bands 0-4)
// ---------------------------------------------------------------------------------------------

/// Twenty-five SH coefficients per channel (real SH, bands 0-4, band after band, m = -l..l within
/// a band; the first nine are sh9's). Channels in .xyzw.
struct sh25 {
  std::array<glm::dvec4, 25> coefficients{};
};

/// The 25 real SH basis functions of bands 0-4 at a unit direction (the first nine as
/// sh9_basis; band 3 and 4 in the usual Cartesian forms, e.g. Y_4,0 = 3/(16 sqrt(pi))
/// (35 z^4 - 30 z^2 + 3)). Cost: ~60 flops.
std::array<double, 25> sh25_basis(const glm::dvec3& w) noexcept;

/// Projects a cube-map level on SH bands 0-4 with exact texel solid angles (directions at texel
/// centres). Deterministic for any thread count. Errors: error(invalid_argument) for an
/// inconsistent or non-finite image. Cost: 6 n^2 * ~100 flops.
sh25 project_sh25(const cube_image& level, int thread_count = 0);

/// Irradiance at unit normal n from SH radiance of bands 0-4: sum A_l L_lm Y_lm(n), A_0 = pi,
/// A_1 = 2 pi / 3, A_2 = pi / 4, A_3 = 0, A_4 = -pi / 24 (the clamped cosine's band factors;
/// Ramamoorthi and Hanrahan 2001), as cmft's "bands 0-4" irradiance. The truncation error is
/// smaller than sh9's but still large for a small bright source, which rings near the terminator
/// (docs/cubemap.md).
/// Cost: ~100 flops.
glm::dvec4 sh25_irradiance(const sh25& radiance, const glm::dvec3& n) noexcept;

/// A cube map of size `size` whose texels (directions from `mapping`) hold sh25_irradiance
/// (alpha, with 4 channels: the cosine-weighted mean, not scaled by pi). channels: 3 or 4.
/// Throws error(invalid_argument) for a bad size, channel count or mapping. Cost: ~100 flops per
/// texel.
cube_image irradiance_from_sh25(const sh25& radiance, int size, edge_fixup mapping, int channels = 3,
                                int thread_count = 0);

}  // namespace hemilight
