// hemilight/raster.hpp — the software hemicube rasterizer: what a surface point sees.
//
// hemicube_rasterizer::render() draws the five faces of the hemicube of geometry.hpp at a point
// with a frame into a hemicube_buffer (hemicube.hpp): per texel the outgoing radiance seen through
// the texel centre, the Euclidean distance to it along the centre's direction, and flags.
//
// Contract (docs/raster.md, "How a render works", has the pipeline and the precision argument):
//   - Point sampling at texel centres, watertight: inside a closed mesh further than the near
//     distance from the point, every texel centre is covered exactly once, for every N up to
//     hemicube_max_resolution and every finite geometry. Equal depths keep the triangle the
//     reference order (the scene's BVH, depth first) draws first.
//   - Depth is 1/w of the triangle's plane at the texel centre; the distance is the ray-plane
//     intersection along the centre's direction (~1e-6 relative; at grazing incidence |cos| <
//     1e-3 it degrades like 1e-7 / |cos| and may be huge but finite).
//   - Front faces (and two-sided triangles) give their emission or the radiance texture at the
//     perspective-correct lightmap UV (texel_hit_front); one-sided triangles seen from behind
//     occlude with radiance 0 (texel_back_face); texels that see nothing give the sky (+inf,
//     texel_miss). Only the z >= 0 half of the side faces is drawn.
//   - See-through triangles (scene::see_through_triangles(); docs/materials.md) are drawn after
//     the opaque ones by a per-texel ray test (watertight: a texel centre on an edge two of them
//     share belongs to one): an alpha-tested one covers a texel where it is nearer and present at
//     the centre (scene::alpha_present; also with edge_coverage, no partial coverage), and loses a
//     depth tie to an opaque one; seen from behind, a one-sided one is black without
//     texel_back_face (cards are no closed surfaces: they do not make a texel look inside geometry); translucent ones never set depth, distance or flags: per texel
//     the layers in front of what it sees are composited far to near, L = transmittance L + the
//     layer's own radiance (emission, or the texture at its lightmap UV; 0 seen from behind a
//     one-sided one). They occlude nothing in the occlusion culling (they are tested against it),
//     have no level of detail, and render_coverage does not count them.
//   - Near plane: everything within `near` of the point along a face's axis is invisible (default
//     1e-4 of the scene's diagonal). A point on a surface does not see that surface.
//   - Deterministic: every buffer is bitwise the same on every code path (scalar, SSE2, AVX2,
//     AVX-512) and with or without occlusion culling, whatever the order of renders.
//   - Threads: the scene is shared and immutable; a rasterizer is used by one thread at a time.
#pragma once

#include "hemilight/geometry.hpp"
#include "hemilight/hemicube.hpp"
#include "hemilight/image_io.hpp"
#include "hemilight/scene.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace hemilight {

// The environment sky of raster_options (hemilight/cubemap.hpp: include it to build or sample
// one). Only declared here: the rasterizer's callers need not compile the cube-map module.
struct cubemap;

/// A read-only view of an RGB(A) float radiance texture over the scene's lightmap UVs. Sampled
/// bilinearly with clamp-to-edge; texel (x, y) (x = column, y = row of `pixels`) has its centre at
/// uv = ((x + 0.5) / width, (y + 0.5) / height), so u grows with the column and v with the row.
/// The bounce pass writes emission + albedo E / pi into it. The memory is the caller's and must
/// outlive the render calls that use it.
struct radiance_texture {
  const float* pixels = nullptr;  ///< width * height * channels floats, row-major, channels interleaved
  int width = 0;
  int height = 0;
  int channels = 3;  ///< 3 (RGB) or 4 (RGBA, alpha ignored)

  radiance_texture() = default;
  radiance_texture(const float* pixels_, int width_, int height_, int channels_ = 3) noexcept
      : pixels(pixels_), width(width_), height(height_), channels(channels_) {}
  /// A view of an image (image_io.hpp); the image must outlive the view.
  explicit radiance_texture(const image& img) noexcept
      : pixels(img.pixels.data()), width(img.width), height(img.height), channels(img.channels) {}

  /// Throws error(invalid_argument) naming the problem unless pixels is non-null, the sizes are
  /// positive and channels is 3 or 4. `who` prefixes the message.
  void validate(const char* who) const;

  /// Bilinear, clamp-to-edge value at uv. Non-finite uv clamps to an edge (never reads outside).
  /// Precondition: validate() passed. Cost: 4 texel reads.
  glm::vec3 sample(const glm::vec2& uv) const noexcept;
};

/// Options of a hemicube_rasterizer.
struct raster_options {
  /// Near-plane distance along each face's forward axis (scene units). 0 = the default,
  /// default_near_distance(scene). Must be finite and >= 0.
  float near_distance = 0.0f;
  /// Optional environment sky: texels that hit nothing get sky->sample(world direction of the
  /// texel centre) (seamless bilinear, top level; cubemap.hpp) instead of the scene's constant
  /// sky radiance. The cube map's directions are the scene's world axes (OpenGL face table).
  /// Shared and immutable; build it with cubemap::from_image (which checks every value); the
  /// constructor throws error(invalid_argument) for an empty or inconsistent map.
  std::shared_ptr<const cubemap> sky = nullptr;
  /// Exact edge coverage (docs/raster.md, "Exact edge coverage"): a texel that a hard edge (a
  /// mesh boundary, a change of material, a silhouette) may cross gets the blend of the exact
  /// covered fractions of the triangles in it, resolved front to back (the rest: the sky, or the
  /// triangle behind them that covers it whole); every other texel is as without it. flags and
  /// seen_triangle() keep their meaning (what the texel centre sees); a blended texel's distance
  /// is to the plane of the nearest triangle with a share of it. Deterministic bit for bit on
  /// every path. Cost: several times a render (docs/raster.md); bind() sorts the scene's edges
  /// (O(E log E)). Off by default.
  bool edge_coverage = false;
  /// Level of detail: a BVH node whose box spans under lod_texels hemicube texels (seen from
  /// more than twice its half diagonal) is drawn from a simplified proxy of its triangles
  /// (meshoptimizer, built once per scene on the first bind that asks for it) instead of its
  /// triangles: far clusters cost a few triangles. It changes the buffers (docs/raster.md, "Level
  /// of detail", measures the error against N and the threshold); 0 = exact, the default. Range
  /// [0, 16]; ignored with edge_coverage.
  float lod_texels = 0.0f;

  /// Diagnostic switches, for comparisons and tests only (not for tuning): every setting gives
  /// bit-identical buffers (tested), only the speed differs. The defaults pick the fastest kernels
  /// the CPU has; an engine leaves them alone.
  struct diagnostic_switches {
    /// Use the SIMD kernels (SSE2 on every x86-64, AVX2 where the CPU has it). false selects the
    /// scalar reference path.
    bool simd = true;
    /// With simd: use the AVX2 kernels (eight texels per step) where the CPU has AVX2 (checked
    /// at run time); false keeps the SSE2 ones, e.g. to test them on an AVX2 machine.
    bool avx2 = true;
    /// With avx2: run the eight-lane set-up as its AVX-512 build where the CPU has AVX-512 F, VL,
    /// BW and DQ (checked at run time). false keeps the AVX2 build.
    bool avx512 = true;
    /// Occlusion culling: BVH nodes wholly behind what is already drawn are skipped (without edge
    /// coverage). false draws everything in view, the reference the culling is tested against.
    bool occlusion_culling = true;
    /// Scenes with fewer drawable triangles are drawn without occlusion culling: there its tests
    /// cost more than they save (docs/raster.md, "Occlusion culling").
    std::size_t occlusion_min_triangles = 8192;
  };
  /// Diagnostic switches (see diagnostic_switches): for comparisons only.
  diagnostic_switches diagnostics = {};
};

/// Throws error(invalid_argument) naming the field, the message starting with `who`: a negative
/// or non-finite near_distance, an empty or inconsistent sky cube map. Cost: O(1).
void validate_raster_options(const raster_options& options, const std::string& who);

/// The near distance used when raster_options::near_distance is 0: 1e-4 times the scene's
/// bounding-box diagonal, or 1e-4 if that is 0 (empty or single-point scene).
float default_near_distance(const scene& s) noexcept;

/// Counters of the last render (for tuning and tests of the culling; reset by every render).
struct raster_statistics {
  std::size_t nodes_visited = 0;       ///< BVH nodes tested
  std::size_t triangles_tested = 0;    ///< triangles moved to the local frame and tested per face
  std::size_t face_triangles = 0;      ///< (triangle, face) pairs sent to clipping and rasterization
  std::size_t clipped = 0;             ///< of those, how many needed clipping
  std::size_t spans = 0;               ///< row spans written by the span paths (not by the SIMD
                                       ///< small-triangle paths, which have no spans)
  std::size_t fragments = 0;           ///< texels depth-tested (or counted) by the span paths
  std::size_t edge_texels_tested = 0;  ///< edge coverage: texels classified by the partial-texel pass
  std::size_t edge_fragments = 0;      ///< edge coverage: partial (triangle, texel) fragments kept
  std::size_t edge_hard_edges = 0;     ///< edge coverage: edges needing exact coverage in this view
  std::size_t edge_hard_texels = 0;    ///< edge coverage: texels such an edge may cross (exact there)
  std::size_t nodes_occluded = 0;      ///< occlusion culling: nodes skipped as hidden on every face they touch
  std::size_t triangles_occluded = 0;  ///< occlusion culling: the triangles below those nodes
  std::size_t face_triangles_occluded = 0;  ///< occlusion culling: big (triangle, face) pairs found hidden before their spans
  std::size_t occlusion_redraws = 0;   ///< renders drawn again in the reference order (a depth tie with level of detail, or too many ties; 0 or 1)
  std::size_t occlusion_ties_settled = 0;  ///< occlusion culling: depth ties at a texel's final depth, given the reference order's winner in place
  std::size_t lod_nodes = 0;           ///< level of detail: nodes drawn from their proxies
  std::size_t see_through_tested = 0;     ///< see-through (alpha-tested, translucent) triangles tested
  std::size_t see_through_fragments = 0;  ///< texels tested for them (their rows' spans on each face)
  std::size_t see_through_occluded = 0;   ///< occlusion culling: (see-through triangle, face) pairs found hidden
  std::size_t translucent_fragments = 0;  ///< translucent layers composited over the texels
};

namespace raster_detail {
class rasterizer_impl;  // src/raster/internal.hpp
}  // namespace raster_detail

/// A per-thread hemicube renderer over a shared scene (see the top of this header).
///
/// Memory: about 8 bytes per texel of scratch (visibility buffers) plus 16 bytes per texel of
/// direction tables, plus 8 bytes per triangle drawn (~70 with a texture), 16 bytes per distinct
/// emission of the scene and 4 per BVH node; kept between renders and grown on demand. With
/// occlusion culling, 4 more bytes per texel and 5 per tile of 8 x 8 texels. With edge coverage,
/// 16 bytes per scene edge that may be hard and per crease triangle, 12 more bytes per texel and
/// 32 per partial (triangle, texel) fragment.
/// The state lives in a cache-line aligned block of its own (rasterizers of different threads
/// kept side by side, e.g. a std::vector of them, share no line of it).
class hemicube_rasterizer {
 public:
  /// Value of seen_triangle() for a texel that sees nothing.
  static constexpr std::uint32_t no_triangle = 0xffffffffu;

  /// Throws error(invalid_argument) for a null scene or a negative or non-finite near distance.
  explicit hemicube_rasterizer(std::shared_ptr<const scene> s, raster_options options = {});

  /// Renders another scene (or the same with other options) from now on, keeping the direction
  /// tables and scratch memory: what constructing a new rasterizer would give, without paying
  /// for the tables again (they cost about as much as a few renders at N = 64). Renders are
  /// bitwise those of a new rasterizer. Errors as the constructor; on error nothing changes.
  /// Cost: O(distinct emissions of the scene).
  void bind(std::shared_ptr<const scene> s, const raster_options& options = {});

  /// Drops the references to the scene and the sky (a cached rasterizer then keeps no released
  /// scene alive), keeping the tables and scratch memory. render() and render_coverage() throw
  /// error(invalid_argument) until bind() is called.
  void unbind() noexcept;

  /// Renders the hemicube at `position` (world) with frame `basis` (world; basis.n is the normal,
  /// local +z) at resolution N into `out` (resized to N; position and basis are stored in it).
  /// `texture` (optional): the radiance texture sampled at the perspective-correct lightmap UV of
  /// triangles when the scene has lightmap UVs; otherwise (or when null) texels get the
  /// triangles' emission.
  ///
  /// Errors (error(invalid_argument), `out` untouched): a non-finite position; a basis that is not
  /// orthonormal and right-handed to within 1e-3 (each length within 1e-3 of 1, pairwise dots
  /// below 1e-3, (t x b) . n > 0); N odd or outside [2, 4096]; an invalid texture.
  /// Cost: O(BVH nodes visited + triangles drawn + covered texels + 3 N^2): the triangles drawn
  /// are those above the tangent plane, not too small to matter at N, and (with occlusion
  /// culling) not hidden behind nearer ones; docs/raster.md has the measured figures. With
  /// raster_options::edge_coverage add O(hard edges + the hard texels of the triangles touching
  /// them).
  void render(const glm::vec3& position, const frame& basis, int resolution, hemicube_buffer& out,
              const radiance_texture* texture = nullptr);

  /// Debug and test aid: rasterizes like render() but without depth test and counts, per texel
  /// (hemicube texel order, 3 N^2 entries), the triangle fragments that cover its centre.
  /// Inside a closed mesh (further than the near distance) every count is exactly 1.
  /// Errors as render().
  void render_coverage(const glm::vec3& position, const frame& basis, int resolution,
                       std::vector<std::uint32_t>& counts);

  /// After render(): the scene triangle (scene_desc numbering) seen through a texel, or
  /// no_triangle for a miss (after render_coverage(): no_triangle everywhere). Where triangles of
  /// one shade meet at exactly the same depth (coplanar overlaps) and occlusion culling drew the
  /// render, it may name another of them than the reference order's first (the buffer is the same
  /// either way). A debugging and testing aid; the buffer itself does not carry triangle numbers.
  /// Precondition: texel < 3 N^2 of the last render, and not moved from since (asserted).
  std::uint32_t seen_triangle(std::size_t texel) const noexcept;

  /// The near distance in use (the option, or the scene's default). Cost: O(1).
  float near_distance() const noexcept;
  /// Counters of the last render (raster_statistics). Cost: O(1).
  const raster_statistics& statistics() const noexcept;
  /// The scene bound (null after unbind() or a move). Cost: O(1).
  const std::shared_ptr<const scene>& scene_ptr() const noexcept;

  /// Copies and moves: a copy renders bitwise as the original; it allocates and copies the
  /// tables and scratch memory (see Memory above; std::bad_alloc if that fails), so copy a
  /// rasterizer once per thread, not per render. A move is O(1). A moved-from rasterizer holds
  /// nothing: render() and render_coverage() throw error(invalid_argument) until bind() gives it
  /// a scene again; near_distance() is 0, statistics() all zero, scene_ptr() null.
  hemicube_rasterizer(const hemicube_rasterizer& other);
  hemicube_rasterizer(hemicube_rasterizer&& other) noexcept;
  hemicube_rasterizer& operator=(const hemicube_rasterizer& other);
  hemicube_rasterizer& operator=(hemicube_rasterizer&& other) noexcept;
  ~hemicube_rasterizer();

 private:
  // The state and the drawing code (src/raster/internal.hpp, not installed). Allocated
  // cache-line aligned: rasterizers of different threads never share a line of it.
  std::unique_ptr<raster_detail::rasterizer_impl> impl_;
};

}  // namespace hemilight
