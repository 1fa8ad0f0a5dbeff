// model_export.hpp — a scene_mesh written as a glTF 2.0 binary (.glb) through assimp's exporter, the
// counterpart of model_import.hpp, for hemilight_make_level. Part of the examples, not of the
// library.
#pragma once

#include "hemilight/scene.hpp"

#include "model_import.hpp"

#include <string>

namespace hemilight::model_export {

/// Writes `mesh` to `path` as glTF binary (assimp's "glb2" exporter) in one node at the origin:
/// one mesh per distinct material (bit for bit, in order of first use), holding that material's
/// triangles in their order, with positions, normals (per vertex the area-weighted mean of its
/// triangles' normals; (0, 1, 0) where those have no area), the lightmap UVs as TEXCOORD_1 and a
/// copy as TEXCOORD_0, and a material with baseColorFactor = albedo, emissiveFactor = emission,
/// doubleSided = two_sided, metallic 0, roughness 1. UVs are stored as the baker reads them
/// (model_import.hpp: glTF's v, row 0 at v = 0), so import_model gives back the same values
/// (to float rounding of 1 - v, at most 6e-8). assimp may merge vertices that are equal in every
/// attribute. Throws std::runtime_error naming the file when the mesh has no lightmap UVs or the
/// export fails. Cost: O(V + T) plus assimp's export (about 1 s per million triangles).
void write_glb(const scene_mesh& mesh, const std::string& path);

/// Writes an imported model with its lightmap UVs (such as apply_lightmap_uvs gave it) to `path` as
/// glTF binary, so that an engine renders with the layout that was baked: one node per mesh at the
/// origin (world-space positions, as imported), its normals, its UV channels (TEXCOORD_0 ...) with
/// the lightmap UVs as TEXCOORD_1 (channel 0 a copy of them when the mesh had none), and per
/// material the base colour (with its alpha) and emissive factors, two-sided, glTF's alphaMode,
/// alphaCutoff and KHR_materials_transmission factor as the file had them, and a base colour
/// texture read from a file (referenced by its path relative to `path`'s folder; embedded textures,
/// and so their alpha, and lights are not written). The lightmap UVs are stored as the baker reads them (import_model gives them back to
/// float rounding of 1 - v). Throws std::runtime_error naming the file when a mesh has no lightmap
/// UVs or the export fails. Cost: O(V + T) plus assimp's export.
void write_glb(const model_import::model& m, const std::string& path);

}  // namespace hemilight::model_export
