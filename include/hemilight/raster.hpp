// hemilight/raster.hpp — the software hemicube rasterizer: what a surface point sees.
//
// hemicube_rasterizer::render() draws the five faces of the hemicube of geometry.hpp at a point
// with a frame into a hemicube_buffer (hemicube.hpp): per texel the outgoing radiance seen through
// the texel centre, the Euclidean distance to it along the texel's centre direction, and flags.
//
// Pipeline (per hemicube, all in the point's local frame, normal = +z):
//   1. Culling: the scene's BVH is traversed once; a node is dropped when it lies entirely below
//      the tangent plane (z <= 0), outside all five face frusta, or (small, far nodes) between
//      the texel centres of every face it touches; each surviving node keeps the mask of faces
//      it can touch. Each triangle is moved to the local frame once. The culling is
//      conservative: it never changes a rendered texel. There is no occlusion culling: the cost
//      follows the triangles above the tangent plane that are not too small to matter at N.
//   2. Visibility, per face: homogeneous clipping against the near plane w >= near (w is the
//      distance along the face's forward axis) and a guard band |u|, |v| <= 1000 w; projection;
//      snapping to fixed point with 8 sub-texel bits; 64-bit integer edge functions with a
//      tie-breaking rule (an edge owns the texel centres exactly on it iff it runs upwards, or
//      horizontally towards -x): triangles sharing an edge leave no gap and cover no texel twice.
//      Depth is 1/w, exact for the triangle's 3D plane (not interpolated from clipped vertices),
//      resolved per texel (nearest wins; equal depths keep the first triangle drawn).
//      Side faces only rasterize their rows (the z >= 0 half).
//   3. Resolve, per texel: the texel-centre ray is intersected with the plane of the triangle
//      that won, giving the Euclidean distance (not the projected depth) and, for a radiance
//      texture, perspective-correct UVs. Front faces (and two-sided triangles from either side)
//      give the texture's bilinear value at that UV, or the triangle's emission, and flag
//      texel_hit_front (0); one-sided triangles seen from behind occlude but give radiance 0 and
//      texel_back_face; texels that see nothing give the sky's radiance, +inf and texel_miss.
//      The distance is |D| / (1/w) with D = a + u c + v r the texel centre's direction on the
//      face and 1/w the triangle's plane evaluated there: the ray-plane intersection, accurate
//      to ~1e-6 relative except at grazing incidence (|cos| < 1e-3), where it degrades like
//      1e-7 / |cos|. A texel covered by a triangle seen almost exactly edge-on can get a huge
//      (up to ~1e38) but finite distance; it is still flagged as a hit.
//
// Precision. Clip-space vertices are finite floats; after guard-band clipping every projected
// coordinate is within 1001 N/2 texels of the face, i.e. |X| < 1001 * 2048 * 256 < 2^29 in
// fixed point (computed in double, so still 1/256 texel) for every valid N, so edge-function
// terms stay below 2^60 and are exact in 64-bit integers. Watertightness (every texel centre inside a closed mesh around the point
// is covered exactly once) therefore holds for every N <= 4096 and every finite geometry, as long
// as the geometry is further than the near distance from the point along each face's axis.
// Clipped vertices on a shared edge are computed from the edge's endpoints in a canonical order,
// so two triangles sharing an edge clip it to bit-identical points. Texel centres closer than
// 1/512 texel to an edge are decided by the snapped (not the exact) edge.
//
// Near plane: geometry with w < near on a face is clipped away, i.e. everything inside the cube
// of half-size `near` around the point is invisible. Default: 1e-4 times the scene's bounding-box
// diagonal (1e-4 scene units for an empty or single-point scene): far below any geometric detail,
// far above float noise of the local coordinates for scenes not more than ~100 sizes from the
// origin. A point lying on a surface does not see that surface (it is at z = 0, no texel centre
// is there).
//
// Threads: the scene is shared and immutable; a hemicube_rasterizer owns its scratch memory and is
// used by one thread at a time. N threads = N rasterizers, no locks.
//
// SIMD. Two kernel sets, both bit-identical to the scalar reference path (tested):
//   - AVX2 (picked at run time where the CPU has it; GCC/Clang on x86-64): each triangle is set
//     up in vector registers (its three vertices and its normal moved to the local frame in one
//     register per axis, the face tests, clip codes and the double-precision projection of the
//     three vertices at once, the edge functions of small triangles in 32-bit lanes) with the
//     same float and integer operations as the scalar path; triangles up to 120
//     texels across are scanned over their box eight texels at a time with 32-bit edge values,
//     the coverage mask going straight into the depth test; longer spans are depth-tested eight
//     texels at a time; the resolve writes runs of texels that see the same shade (found through
//     a per-render shade key, so the two triangles of a quad make one run) as broadcast stores.
//     Where the CPU has AVX-512 (F, VL, BW, DQ) the set-up runs as an AVX-512 build of the same
//     code (32 registers; raster_options::diagnostics.avx512).
//   - SSE2 (every x86-64): the same for triangles up to 32 texels across, four texels at a time.
// raster_options::diagnostics.simd = false selects the scalar reference path;
// raster_options::diagnostics.avx2 = false keeps the SSE2 kernels on an AVX2 machine. (The culling outcodes use SSE2 unconditionally: the
// same exact float comparisons, four per instruction.) Other targets use the scalar path.
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
  /// mesh boundary, a change of material, a silhouette) may cross gets, from each triangle that
  /// covers it in part, the exact area of the (projected, clipped) triangle within the texel as a
  /// fraction of the texel, not the all-or-nothing sample at its centre; the triangles sharing a
  /// texel are resolved front to back (each takes the smaller of its coverage and what is left;
  /// the sky, or the triangle that covers the whole texel behind them, the rest), and the
  /// texel's radiance is the blend. Every other texel (inside a triangle, or crossed only by
  /// edges between triangles of one material facing the same way) is as without it. flags and
  /// seen_triangle() keep their meaning (what the texel centre sees: bit-identical to a render
  /// without the option); a blended texel's distance is to the plane of the nearest triangle
  /// with a share of it (along the centre's direction), which is the centre's distance unless a
  /// nearer triangle covers part of the texel. Deterministic bit for bit, the same on every SIMD
  /// path. Cost at N = 64 (render + integration): 1.7x on tessellated rooms, 6x on the Cornell
  /// box (material changes all around), 28x on a terrain seen from its own surface
  /// (docs/raster.md); bind() sorts the scene's edges (O(E log E)). Off by default.
  bool edge_coverage = false;

  /// Diagnostic switches, for comparisons and tests only (not for tuning): every setting gives
  /// bit-identical buffers (tested), only the speed differs. The defaults pick the fastest kernels
  /// the CPU has; an engine leaves them alone.
  struct diagnostic_switches {
    /// Use the SIMD kernels (SSE2 on every x86-64, AVX2 where the CPU has it; see the top of
    /// this header). false selects the scalar reference path.
    bool simd = true;
    /// With simd: use the AVX2 kernels (eight texels per step) where the CPU has AVX2 (checked
    /// at run time); false keeps the SSE2 ones, e.g. to test them on an AVX2 machine.
    bool avx2 = true;
    /// With avx2: run the eight-lane set-up (the bulk of a render) as its AVX-512 build where the
    /// CPU has AVX-512 F, VL, BW and DQ (checked at run time): the same 256-bit code with 32
    /// registers, 5-10% faster on AMD Zen 5. false keeps the AVX2 build.
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
  std::size_t occlusion_redraws = 0;   ///< renders drawn again in the reference order (a depth tie; 0 or 1)
};

namespace raster_detail {
class rasterizer_impl;  // src/raster/internal.hpp
}  // namespace raster_detail

/// A per-thread hemicube renderer over a shared scene (see the top of this header).
///
/// Memory: about 8 bytes per texel of scratch (visibility buffers) plus 16 bytes per texel of
/// direction tables, plus 8 bytes per triangle drawn (~70 with a texture) and 16 bytes per distinct
/// emission of the scene; kept between renders and grown on demand. With edge coverage, 16 bytes
/// per scene edge that may be hard and per crease triangle, 12 more bytes per texel and 32 per
/// partial (triangle, texel) fragment (~1,000 per hemicube of the Cornell box at N = 64, under
/// 100 in tessellated rooms).
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
  /// Cost: O(visible BVH nodes + triangles above the tangent plane + covered texels + 3 N^2);
  /// Cornell box at N = 64: about 25 us on one core of a 2020s server (AVX2); a closed room of
  /// 1,000 small triangles, all in view: about 65 us (the cost is per triangle). With
  /// raster_options::edge_coverage add O(hard edges + the hard texels of the triangles touching
  /// them): 1.5-15x in all at N = 64 (see the option).
  void render(const glm::vec3& position, const frame& basis, int resolution, hemicube_buffer& out,
              const radiance_texture* texture = nullptr);

  /// Debug and test aid: rasterizes like render() but without depth test and counts, per texel
  /// (hemicube texel order, 3 N^2 entries), the triangle fragments that cover its centre.
  /// Inside a closed mesh (further than the near distance) every count is exactly 1.
  /// Errors as render().
  void render_coverage(const glm::vec3& position, const frame& basis, int resolution,
                       std::vector<std::uint32_t>& counts);

  /// After render(): the scene triangle (scene_desc numbering) seen through a texel, or
  /// no_triangle for a miss (after render_coverage(): no_triangle everywhere). A debugging and
  /// testing aid; the buffer itself does not carry triangle numbers.
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
