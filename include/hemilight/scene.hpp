// hemilight/scene.hpp — the triangles a hemicube sees, with no more than the lighting needs.
//
// A scene is built once by scene::create() from a scene_desc (pointers + counts the caller owns;
// everything is copied) and is immutable afterwards: share it between threads through
// std::shared_ptr<const scene>, no locks needed. Everything per hemicube lives in a
// hemicube_rasterizer (raster.hpp), one per thread.
//
// Triangles: positions (vec3, scene units) and uint32 indices, three per triangle. The front face
// winds counter-clockwise: its normal is (v1 - v0) x (v2 - v0). Per triangle a material: emitted
// radiance (RGB, >= 0), albedo (RGB, kept for the bounce passes; the rasterizer does not use it)
// whether it is two-sided, and how it lets light through (opaque, alpha-tested with an optional
// 8-bit alpha texture, or translucent with an RGB transmittance). A one-sided triangle seen from behind still occludes, but the
// hemicube texel gets radiance 0 and the texel_back_face flag (hemicube.hpp).
// Optionally per-vertex lightmap UVs: then a radiance texture passed to the render call
// (raster.hpp) replaces the triangles' emission (it holds emission + albedo E / pi of a bounce).
// Sky: a constant radiance seen where nothing is hit.
//
// Degenerate triangles (no area at the precision of their float coordinates:
// is_degenerate_triangle) are accepted and never drawn: they never occlude (they keep their
// index). An empty scene is valid: every texel sees the sky.
#pragma once

#include "hemilight/error.hpp"

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace hemilight {

namespace detail {
struct lazy_slot;   // data derived from the scene on first use by the modules above it (src/scene/scene_access.hpp)
struct derived_access;
struct scene_access;  // the SIMD vertex arrays of the rasterizer and the ray fallback (src/scene/scene_access.hpp)
}  // namespace detail

/// How a triangle lets light through (material::opacity). docs/materials.md states the rules and
/// measures their error and cost.
enum class surface_opacity : std::uint8_t {
  /// Blocks all light: the hemicubes see it, shadow rays stop at it (the default).
  opaque = 0,
  /// Alpha-tested (glTF alphaMode MASK): present where its alpha (material::alpha times the alpha
  /// texture at the point, if it has one) is >= material::alpha_cutoff, absent elsewhere. Decided
  /// per hemicube texel at the texel centre and per shadow ray at its hit point.
  alpha_tested = 1,
  /// Translucent (glTF BLEND, KHR_materials_transmission): lets material::transmittance of the light
  /// behind it through (per channel) and adds what it sends itself (emission, or the bounce's
  /// radiance texture, attenuated by the translucent layers in front of it). Never hides what is
  /// behind it from a hemicube texel's depth, distance or flags; shadow rays multiply their
  /// transmittances.
  translucent = 2,
};

/// Per-triangle material: what the hemicube sees of a triangle and what a bounce needs.
struct material {
  glm::vec3 emission{0.0f};  ///< emitted radiance (W m^-2 sr^-1 or any unit), each channel >= 0
  glm::vec3 albedo{0.0f};    ///< diffuse reflectance, each channel in [0, 1] (not used to render)
  bool two_sided = false;    ///< seen from behind, a two-sided triangle looks like its front
  surface_opacity opacity = surface_opacity::opaque;  ///< opaque, alpha_tested or translucent
  /// alpha_tested: the alpha factor in [0, 1], multiplied with the alpha texture's value (glTF
  /// baseColorFactor's alpha). Ignored otherwise.
  float alpha = 1.0f;
  /// alpha_tested: present where alpha >= alpha_cutoff; in [0, 1] (glTF alphaCutoff, default 0.5).
  float alpha_cutoff = 0.5f;
  /// alpha_tested: index into scene_desc::alpha_textures, or -1: the alpha factor alone (the whole
  /// triangle present or absent). With a texture the scene needs scene_desc::texcoords.
  int alpha_texture = -1;
  /// translucent: the fraction of the light passing through, per channel in [0, 1] (glTF: the
  /// transmission factor times the base colour, or 1 - alpha for BLEND without it). Ignored
  /// otherwise.
  glm::vec3 transmittance{0.0f};
};

/// A single-channel 8-bit alpha texture (value / 255) for alpha-tested materials, sampled
/// bilinearly at the triangle's texcoords with repeat wrapping (glTF's default sampler): texel
/// (x, y) (x = column, y = row of `values`) has its centre at ((x + 0.5) / width,
/// (y + 0.5) / height). The memory is the caller's; scene::create copies it.
struct alpha_texture {
  const std::uint8_t* values = nullptr;  ///< width * height values, row-major
  int width = 0;                         ///< texels, in [1, 16384]
  int height = 0;                        ///< texels, in [1, 16384]
};

/// Largest radiance (any channel, W m^-2 sr^-1) a scene, sky, environment map or light colour may
/// hold: sums of it over hemicubes, bounces and lights stay finite in float. Larger finite values
/// are rejected with error(invalid_argument) where they are given.
inline constexpr float max_radiance = 1e30f;

/// Largest coordinate magnitude (scene units) of vertices, lights and query points: products of
/// coordinates (edge functions, squared distances) must stay finite in float, and Embree's rays
/// take components up to 1.8e18. Larger finite values are rejected where they are given.
inline constexpr float max_coordinate = 1e18f;

/// Largest vertex and triangle counts scene::create accepts (2^31 - 1): indices are uint32 and
/// the rasterizer keeps triangle numbers in 32 bits. Larger counts get error(out_of_memory).
inline constexpr std::size_t max_scene_elements = (std::size_t(1) << 31) - 1;

/// Tolerance of is_degenerate_triangle: the height of a triangle over its longest edge, as a
/// fraction of the largest magnitude m of its vertices' coordinates, at or below which it has no
/// area. Why 2^-22 (4 float ulps of m): rounding each coordinate of exactly collinear points to
/// float (an export, a node transform applied in float) moves each vertex by up to
/// sqrt(3) 2^-24 m, which leaves the rounded triangle a height of up to 2 sqrt(3) 2^-24 m, about
/// 3.5 x 2^-24 m; 4 covers it with a margin. A test on the area alone (area < 1e-10 x the longest
/// edge squared) misses such triangles: their area reaches 1e-7 x L x m, and m >= L / (2 sqrt 3).
/// Every triangle with area <= 1e-10 L^2 is degenerate here too, for the same reason.
inline constexpr double degenerate_height_tolerance = 0x1p-22;

/// True when the triangle (a, b, c) has no area at the precision of its coordinates: twice its
/// area |(b - a) x (c - a)| (in double) is at most degenerate_height_tolerance x L x m, L its
/// longest edge and m the largest coordinate magnitude of its vertices (so also when L = 0:
/// coincident vertices). Non-finite input gives true. The one rule of the scene (never drawn),
/// the baker (no texels; bake_stats::degenerate_triangles) and the unwrapper (unwrap.hpp).
/// Cost: O(1).
bool is_degenerate_triangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) noexcept;

/// What scene::create reads (nothing is kept: the scene copies what it needs).
struct scene_desc {
  const glm::vec3* positions = nullptr;    ///< vertex_count positions (finite)
  std::size_t vertex_count = 0;
  const std::uint32_t* indices = nullptr;  ///< 3 * triangle_count vertex indices (< vertex_count)
  std::size_t triangle_count = 0;
  const material* materials = nullptr;     ///< triangle_count materials, or null: all black, one-sided
  const glm::vec2* lightmap_uvs = nullptr; ///< vertex_count lightmap UVs (finite), or null: none
  glm::vec3 sky_radiance{0.0f};            ///< radiance seen where nothing is hit, each channel >= 0
  /// vertex_count material texture coordinates (finite; glTF TEXCOORD_0), where the alpha textures
  /// are read; or null. Required when a material has an alpha_texture.
  const glm::vec2* texcoords = nullptr;
  const alpha_texture* alpha_textures = nullptr;  ///< alpha_texture_count textures, or null
  std::size_t alpha_texture_count = 0;
};

/// An alpha texture that owns its values (scene_mesh::alpha_textures).
struct alpha_image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> values;  ///< width * height, row-major
};

/// A mesh that owns its arrays, with helpers to build one; desc() views it as a scene_desc.
/// The reference scenes (reference_scenes.hpp) and the tests build their geometry with it.
struct scene_mesh {
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
  std::vector<material> materials;       ///< one per triangle
  std::vector<glm::vec2> lightmap_uvs;   ///< empty, or one per vertex
  glm::vec3 sky_radiance{0.0f};
  std::vector<glm::vec2> texcoords;      ///< empty, or one per vertex (alpha textures' coordinates)
  std::vector<alpha_image> alpha_textures;
  mutable std::vector<alpha_texture> alpha_views;  ///< desc()'s views of alpha_textures (set by desc())

  std::size_t triangle_count() const noexcept { return indices.size() / 3; }

  /// A view of the arrays (valid while the mesh lives and is not modified, and until the next
  /// desc() call: the alpha textures' views are kept in the mesh).
  scene_desc desc() const;

  /// Appends the triangle (a, b, c) with its own three vertices; front face counter-clockwise.
  void add_triangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const material& m);

  /// Appends the planar quad a, b, c, d (counter-clockwise seen from its front) as the two
  /// triangles (a, b, c) and (a, c, d), sharing vertices a and c.
  void add_quad(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d, const material& m);

  /// Appends the quad a, b, c, d split into an nu x nv grid of quads (2 nu nv triangles, shared
  /// vertices, front face as add_quad). Grid points are bilinear in the corners and computed as
  /// (1 - s) p + s q, so the corners and edge points are bit-identical to what another grid
  /// with the same corners and edge divisions computes: meshes built from such grids are closed.
  /// `flip` reverses the winding (front face on the other side) without changing any vertex.
  /// Precondition: nu, nv >= 1.
  void add_grid(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d, int nu, int nv,
                const material& m, bool flip = false);

  /// Appends a box (12 triangles) with corners lo and hi, faces pointing outwards (inwards when
  /// `inward` is set: a closed room).
  void add_box(const glm::vec3& lo, const glm::vec3& hi, const material& m, bool inward = false);
};

/// A node of the scene's bounding-volume hierarchy (binary, over triangle bounding boxes).
struct bvh_node {
  glm::vec3 lo, hi;     ///< bounding box of everything below
  std::uint32_t first;  ///< leaf: first triangle (in scene::triangles() order); inner: left child (right = first + 1)
  std::uint32_t count;  ///< leaf: number of triangles (> 0); inner: 0
};

/// An immutable, validated set of triangles with materials, an optional lightmap UV set, a sky
/// radiance and a bounding-volume hierarchy, shared by every thread that renders hemicubes.
class scene {
 public:
  /// A drawable (non-degenerate) triangle as the rasterizer reads it, in BVH order (opaque ones;
  /// see_through_triangles(): the others, in scene_desc order).
  struct triangle {
    glm::vec3 v0, v1, v2;  ///< world positions, front face counter-clockwise
    std::uint32_t index;   ///< the triangle's number in the scene_desc
  };

  /// Validates `desc`, copies what lighting needs and builds the BVH.
  ///
  /// Errors (hemilight::error, the message names the argument and the index):
  ///   invalid_argument: a null array with a nonzero count; a NaN/Inf position or UV
  ///     ("positions[4].y is nan"); an index >= vertex_count ("indices[17] = 900 is out of range:
  ///     12 vertices"); a negative or non-finite emission, albedo or sky radiance; an unknown
  ///     opacity, an alpha, alpha_cutoff or transmittance outside [0, 1], an alpha_texture that is
  ///     not -1 or an index into alpha_textures ("materials[3].alpha_texture = 2: 1 alpha
  ///     texture"), a texture size outside [1, 16384] or null values, a texture used without
  ///     texcoords, a NaN/Inf texcoord.
  ///   out_of_memory: more than max_scene_elements vertices or triangles, or an allocation failure.
  /// Degenerate triangles (is_degenerate_triangle: repeated indices, collinear or coincident
  /// positions, up to float rounding) are accepted and never drawn. Cost: O(T log^2 T) for T triangles; memory about 140 bytes per triangle. The
  /// ray queries' Embree scene (rays.hpp) is not built here but on the first ray query or
  /// prepare_rays() call.
  static std::shared_ptr<const scene> create(const scene_desc& desc);

  std::size_t vertex_count() const noexcept { return positions_.size(); }
  /// Number of triangles in the scene_desc (drawable or not).
  std::size_t triangle_count() const noexcept { return materials_.size(); }
  /// Number of non-degenerate triangles (is_degenerate_triangle: the ones the rasterizer draws and
  /// rays hit), opaque or not.
  std::size_t drawable_triangle_count() const noexcept { return triangles_.size() + see_through_.size(); }

  /// The drawable triangles whose material is alpha_tested or translucent, in scene_desc order:
  /// they are not in triangles() nor in the BVH. The rasterizer draws them after the opaque ones;
  /// the ray queries test them apart (rays.hpp). An alpha-tested triangle whose alpha factor is
  /// below its cutoff and that has no texture is left out (it is never present).
  const std::vector<triangle>& see_through_triangles() const noexcept { return see_through_; }
  /// True when alpha-tested triangle i (scene_desc numbering) is present at the point with
  /// barycentric coordinates (b1, b2) (the point is v0 + b1 (v1 - v0) + b2 (v2 - v0)): its alpha
  /// factor times its texture's bilinear value at the interpolated texcoord is >= its cutoff.
  /// True for triangles that are not alpha-tested. Precondition: i < triangle_count(). Cost: O(1),
  /// four texel reads.
  bool alpha_present(std::size_t i, float b1, float b2) const noexcept;
  /// The material texture coordinates (empty if the scene has none, or no material reads them).
  const std::vector<glm::vec2>& texcoords() const noexcept { return texcoords_; }

  const std::vector<glm::vec3>& positions() const noexcept { return positions_; }
  const std::vector<std::uint32_t>& indices() const noexcept { return indices_; }
  /// Material of triangle i (scene_desc numbering). Precondition: i < triangle_count().
  const material& triangle_material(std::size_t i) const noexcept { return materials_[i]; }
  /// The distinct emissions of the scene's materials (compared bit for bit), in order of first
  /// appearance; emission_index(i) is triangle i's entry (scene_desc numbering; precondition:
  /// i < triangle_count()). The rasterizer labels what each texel sees with this number.
  const std::vector<glm::vec3>& emissions() const noexcept { return emissions_; }
  std::uint32_t emission_index(std::size_t i) const noexcept { return emission_index_[i]; }
  bool has_lightmap_uvs() const noexcept { return !uvs_.empty(); }
  /// Per-vertex lightmap UVs (empty if the scene has none).
  const std::vector<glm::vec2>& lightmap_uvs() const noexcept { return uvs_; }
  const glm::vec3& sky_radiance() const noexcept { return sky_; }

  /// Bounding box of all vertices (lo > hi, i.e. (+inf, -inf), for a scene without vertices).
  const glm::vec3& bounds_lo() const noexcept { return lo_; }
  const glm::vec3& bounds_hi() const noexcept { return hi_; }
  /// Length of the bounding box diagonal (scene units); 0 for an empty or single-point scene.
  /// The near-plane default of the rasterizer and the cache's radius defaults derive from it.
  float size() const noexcept { return size_; }

  /// Drawable triangles in BVH order, and the BVH (node 0 is the root; empty if no triangle).
  const std::vector<triangle>& triangles() const noexcept { return triangles_; }
  const std::vector<bvh_node>& bvh() const noexcept { return nodes_; }

  /// Largest number of triangles in a BVH leaf. Coarse on purpose: the rasterizer's AVX2 set-up
  /// tests eight triangles of a leaf for less than a node visit costs (docs/raster.md). The BVH
  /// splits at multiples of it, so all leaves but one per subtree split are full.
  static constexpr std::uint32_t max_leaf_triangles = 32;

 private:
  scene() = default;
  void index_emissions();
  void copy_opacity(const scene_desc& desc);
  void build_bvh();

  std::vector<glm::vec3> positions_;
  std::vector<std::uint32_t> indices_;
  std::vector<material> materials_;
  std::vector<glm::vec3> emissions_;            // distinct emissions (bitwise)
  std::vector<std::uint32_t> emission_index_;   // per triangle: its entry in emissions_
  std::vector<glm::vec2> uvs_;
  std::vector<glm::vec2> texcoords_;
  std::vector<alpha_image> alpha_textures_;
  std::vector<triangle> see_through_;
  glm::vec3 sky_{0.0f};
  glm::vec3 lo_{0.0f}, hi_{0.0f};
  float size_ = 0.0f;
  std::vector<triangle> triangles_;
  std::vector<float> coordinates_;  // detail::scene_access::vertex_coordinates: 9 arrays of triangles_.size() + 8
  friend struct detail::scene_access;
  std::vector<bvh_node> nodes_;
  // The ray queries' acceleration structure (rays.hpp): empty until the first query builds it.
  friend struct detail::derived_access;
  std::shared_ptr<detail::lazy_slot> derived_[4];
};

}  // namespace hemilight
