// model_import.hpp — models for the command-line baker (hemilight_bake): glTF 2.0, FBX, OBJ and
// whatever else assimp reads, as the meshes, materials, textures and lights of a scene bake
// (bake.hpp, bake_scene). Part of the examples, not of the library.
//
// What is read:
//   - Every mesh of every node, with the node's world transform (instances included: a mesh that
//     several nodes use is one `mesh` per node). Normals by the inverse transpose; a mirroring
//     transform (negative determinant) flips the triangles' winding so that front faces stay front.
//   - Lightmap UVs from UV channel `lightmap_channel` (1 by default: glTF's TEXCOORD_1). Every mesh
//     without that channel is named in one error, or (import_options::allow_missing_lightmap_uvs)
//     imported without lightmap UVs for the caller to generate (unwrap.hpp). UVs up to
//     lightmap_uv_tolerance outside [0, 1] are accepted (the baker clamps them); degenerate
//     triangles are kept (the baker skips them); a triangle with 3D area but no lightmap UV area is
//     an error only with import_options::strict (else the baker counts it).
//   - Materials: base colour (glTF baseColorFactor, else the diffuse colour Kd) times its texture
//     (glTF baseColorTexture, else the diffuse texture map_Kd), emissive colour (emissiveFactor /
//     Ke) times its texture, two-sided. Textures are decoded by stb_image (Debian's libstb-dev):
//     files next to the model or embedded (glb, data URIs); 8-bit values are sRGB and converted to
//     linear, the alpha channel is kept as it is (glTF: linear). A texture that cannot be read is
//     an error naming the material and the file (not a warning: a bake with a wrong albedo, or
//     with leaves that should be cut out baked solid, is worse than none).
//   - Opacity (glTF only; scene.hpp, surface_opacity): alphaMode MASK is alpha-tested with
//     alpha = baseColorFactor's alpha, alphaCutoff (default 0.5) and, when the base colour texture
//     has an alpha channel that is not everywhere 255, that channel as its alpha texture (read at
//     the texture's own UV set, TEXCOORD_0 normally; one alpha texture per image, shared by the
//     materials using it); a MASK material that is present everywhere (alpha >= cutoff, no alpha
//     texture) is opaque. BLEND is translucent with transmittance 1 - a (grey), a = the factor's
//     alpha x the texture's mean alpha. KHR_materials_transmission (assimp 5.2's
//     AI_MATKEY_TRANSMISSION_FACTOR) is translucent with transmittance = factor x base colour
//     (factor x texture mean), clamped to [0, 1], whatever the alpha mode (with BLEND:
//     (1 - a) + a x that; a MASK cut-out is then not applied); the transmission texture is not
//     read. OPAQUE, and every other format (OBJ's dissolve, FBX's opacity), is opaque.
//     import_options::ignore_opacity makes everything opaque.
//   - Lights (aiLight), transformed by the node of the same name (assimp's convention).
// Every error is one line naming the file and the mesh, material or texture (std::runtime_error).
#pragma once

#include "hemilight/bake.hpp"
#include "hemilight/lights.hpp"
#include "hemilight/unwrap.hpp"

#include <string>
#include <vector>

namespace hemilight::model_import {

/// A decoded texture: linear RGB, row 0 = the first row of the file (the top of the picture).
struct texture {
  int width = 0, height = 0;
  std::vector<glm::vec3> texels;
  /// The alpha channel (width x height, 0..255 as stored, rows as texels), or empty when the image
  /// has none or it is 255 everywhere.
  std::vector<std::uint8_t> alpha;
  std::string source;  ///< file path or "embedded texture N"

  /// The texel under uv (assimp's convention: v grows upwards, so row = (1 - v) height), with
  /// repeat wrapping (glTF's default). Nearest: averaging over a footprint is done by the caller.
  glm::vec3 lookup(glm::vec2 uv) const noexcept;
  /// The mean of all texels.
  glm::vec3 mean() const noexcept;
  /// The mean alpha, in [0, 1] (1 without an alpha channel).
  float mean_alpha() const noexcept;
};

/// A material as the baker uses it.
struct material {
  std::string name;
  glm::vec3 base_color{0.8f};  ///< factor (linear), multiplied by the texture where there is one
  glm::vec3 emissive{0.0f};    ///< factor (linear radiance), multiplied by the texture where there is one
  bool two_sided = false;
  int base_color_texture = -1, emissive_texture = -1;  ///< index into model::textures, or -1
  unsigned base_color_uv = 0, emissive_uv = 0;         ///< UV channel of each texture

  /// How it lets light through (the rules at the top), as the scene takes it: opacity,
  /// alpha (the factor), alpha_cutoff, alpha_texture (index into model::alpha_textures, read at
  /// UV channel base_color_uv: mesh_texcoords) and transmittance.
  surface_opacity opacity = surface_opacity::opaque;
  float alpha = 1.0f, alpha_cutoff = 0.5f;
  int alpha_texture = -1;
  glm::vec3 transmittance{0.0f};
  /// What the file says (for the import's summary and model_export's writer): glTF's alphaMode
  /// ("" for other formats), the base colour factor's alpha, alphaCutoff and the
  /// KHR_materials_transmission factor (0 without), also with import_options::ignore_opacity.
  std::string alpha_mode;
  float base_alpha = 1.0f, gltf_alpha_cutoff = 0.5f, transmission = 0.0f;

  /// The per-triangle material: albedo = base colour x texture mean (clamped to [0, 1]),
  /// emission = emissive x texture mean, two-sided, and the opacity fields above. What hemicubes
  /// see where no per-texel image is used.
  hemilight::material flat(const std::vector<texture>& textures) const;
};

/// One instance of one of the file's meshes, in world space.
struct mesh {
  std::string name;           ///< "mesh 2 ('Chair') at node 'Chair.001'"
  unsigned source_mesh = 0;   ///< index of the file's mesh
  unsigned instance = 0;      ///< 0 for the first node that uses the mesh, 1 for the second, ...
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> lightmap_uvs;
  std::vector<std::vector<glm::vec2>> uv_channels;  ///< every UV channel the mesh has (for textures)
  std::vector<std::uint32_t> indices;
  unsigned material = 0;      ///< index into model::materials
  int page = 0;               ///< the lightmap page of its UVs: its instance, or the page generated UVs put it on
};

struct model {
  std::vector<mesh> meshes;
  std::vector<material> materials;
  std::vector<texture> textures;
  /// The alpha textures of alpha-tested materials (material::alpha_texture), one per image: the
  /// alpha channel of textures[alpha_sources[k]] (scene.hpp's alpha texture: row 0 = v = 0).
  std::vector<alpha_image> alpha_textures;
  std::vector<int> alpha_sources;
  /// With import_options::ignore_opacity: how many materials were made opaque though the file
  /// makes them see-through.
  std::size_t ignored_see_through = 0;
  std::vector<light> lights;
  /// Lightmap pages: 1 + the largest mesh::page (instance k of every mesh goes to page k, so that
  /// instances, which share their lightmap UVs, never share texels).
  int pages = 1;
  /// The meshes imported without lightmap UVs (import_options::allow_missing_lightmap_uvs), by name.
  std::vector<std::string> without_lightmap_uvs;
};

/// How import_model reads a file.
struct import_options {
  unsigned lightmap_channel = 1;            ///< the UV channel of the lightmap UVs, < AI_MAX_NUMBER_OF_TEXTURECOORDS
  bool allow_missing_lightmap_uvs = false;  ///< meshes without the channel: imported without lightmap UVs, not an error
  bool strict = false;                      ///< a triangle with 3D area but no lightmap UV area is an error
  bool ignore_opacity = false;              ///< every material opaque (alpha modes and transmission not applied)
};

/// Reads a model file. Throws std::runtime_error with one line naming the file and what is wrong:
/// no such file, assimp's error, no meshes with triangles, meshes without UV channel
/// lightmap_channel (all of them named; unless allowed), a lightmap UV more than
/// lightmap_uv_tolerance outside [0, 1], with strict a triangle with 3D area but no UV area (named
/// by its mesh and index), a texture that cannot be read (naming the material and the file), a
/// mesh without the UV channel its material's alpha texture is read at (naming both). Cost:
/// assimp's import plus one pass over the vertices and the textures' texels.
model import_model(const std::string& path, const import_options& options);
model import_model(const std::string& path, unsigned lightmap_channel = 1);

/// One line on the model's see-through materials ("2 of 5 materials let light through: 'Leaves'
/// alpha-tested (MASK, cutoff 0.5, alpha texture 'leaves.png' 64 x 64), 'Glass' translucent
/// (transmission 0.9: transmittance 0.81, 0.9, 0.9)"), or "" when there is none (and no
/// ignored_see_through).
std::string opacity_summary(const model& m);

/// The texcoords at which the alpha texture of mesh `me`'s material is read, per vertex, in the
/// scene's convention (scene.hpp, alpha_texture: (u, 1 - v) of assimp's v-up UVs, glTF's own
/// values), or empty when its material reads no alpha texture.
std::vector<glm::vec2> mesh_texcoords(const model& m, const mesh& me);

/// Gives the model the lightmap UVs of `r`, the unwrap (unwrap_lightmap) of its meshes' world
/// positions concatenated in order (mesh k's vertices after those of meshes 0..k-1): each mesh's
/// vertices become the result's (attributes copied from their sources), a mesh whose triangles lie
/// on several pages is split into one mesh per page (named "... (page P)"), and mesh::page and
/// model::pages follow the pages. Cost: O(V + T).
void apply_lightmap_uvs(model& m, const unwrap_result& r);

/// The per-texel albedo and emission of one lightmap page (width x height, the page's texel
/// convention: bake.hpp), each texel the area-weighted mean, over the parts of the page's
/// triangles inside it, of base colour x texture (emissive x texture): the texture is averaged
/// over the texel's footprint by supersampling it (2..16 points per axis, more where a lightmap
/// texel covers more texture texels). Albedo clamped to [0, 1]. Texels no triangle covers are 0.
/// Both images are empty when no material of the page's meshes has a texture (the triangles'
/// flat values are then exact). Cost: O(covered texels x supersamples).
struct page_images {
  image albedo, emission;
};
page_images bake_page_materials(const model& m, int page, int width, int height);

}  // namespace hemilight::model_import
