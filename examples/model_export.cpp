// A scene_mesh as glTF binary through assimp's exporter (model_export.hpp).
#include "model_export.hpp"

#include <assimp/GltfMaterial.h>
#include <assimp/material.h>
#include <assimp/scene.h>
#include <assimp/Exporter.hpp>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>
#include <tuple>
#include <vector>

namespace hemilight::model_export {

namespace {

// A material's bits, for finding the distinct ones.
using material_key = std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t, bool>;
material_key key_of(const material& m) {
  std::uint32_t b[6];
  std::memcpy(b, &m.albedo, 12);
  std::memcpy(b + 3, &m.emission, 12);
  return {b[0], b[1], b[2], b[3], b[4], b[5], m.two_sided};
}

aiMaterial* make_material(const material& m, unsigned index) {
  auto* am = new aiMaterial();
  const aiString name("material " + std::to_string(index));
  am->AddProperty(&name, AI_MATKEY_NAME);
  const aiColor4D base(m.albedo.x, m.albedo.y, m.albedo.z, 1.0f);
  am->AddProperty(&base, 1, AI_MATKEY_BASE_COLOR);
  const aiColor3D diffuse(m.albedo.x, m.albedo.y, m.albedo.z), emissive(m.emission.x, m.emission.y, m.emission.z);
  am->AddProperty(&diffuse, 1, AI_MATKEY_COLOR_DIFFUSE);
  am->AddProperty(&emissive, 1, AI_MATKEY_COLOR_EMISSIVE);
  const float metallic = 0.0f, roughness = 1.0f;
  am->AddProperty(&metallic, 1, AI_MATKEY_METALLIC_FACTOR);
  am->AddProperty(&roughness, 1, AI_MATKEY_ROUGHNESS_FACTOR);
  const int two_sided = m.two_sided ? 1 : 0;
  am->AddProperty(&two_sided, 1, AI_MATKEY_TWOSIDED);
  return am;
}

}  // namespace

void write_glb(const scene_mesh& mesh, const std::string& path) {
  const std::size_t V = mesh.positions.size(), T = mesh.triangle_count();
  if (mesh.lightmap_uvs.size() != V)
    throw std::runtime_error("cannot write '" + path + "': the mesh has " + std::to_string(mesh.lightmap_uvs.size()) +
                             " lightmap UVs for " + std::to_string(V) + " vertices");
  // Per vertex: the area-weighted mean of its triangles' normals.
  std::vector<glm::dvec3> normal_sum(V, glm::dvec3(0.0));
  for (std::size_t t = 0; t < T; ++t) {
    const std::uint32_t* v = &mesh.indices[3 * t];
    const glm::dvec3 a(mesh.positions[v[0]]),
        n = glm::cross(glm::dvec3(mesh.positions[v[1]]) - a, glm::dvec3(mesh.positions[v[2]]) - a);
    for (int k = 0; k < 3; ++k) normal_sum[v[k]] += n;
  }
  // The distinct materials in order of first use, and each triangle's.
  std::map<material_key, unsigned> index_of;
  std::vector<material> materials;
  std::vector<unsigned> triangle_material(T);
  for (std::size_t t = 0; t < T; ++t) {
    const auto [it, added] = index_of.emplace(key_of(mesh.materials[t]), static_cast<unsigned>(materials.size()));
    if (added) materials.push_back(mesh.materials[t]);
    triangle_material[t] = it->second;
  }
  const auto n = static_cast<unsigned>(materials.size());
  auto scene = std::make_unique<aiScene>();
  scene->mRootNode = new aiNode("level");
  scene->mRootNode->mNumMeshes = n;
  scene->mRootNode->mMeshes = new unsigned[n];
  scene->mNumMaterials = n;
  scene->mMaterials = new aiMaterial*[n];
  scene->mNumMeshes = n;
  scene->mMeshes = new aiMesh*[n];
  for (unsigned k = 0; k < n; ++k) {
    scene->mRootNode->mMeshes[k] = k;
    scene->mMaterials[k] = make_material(materials[k], k);
    scene->mMeshes[k] = nullptr;
  }
  std::vector<std::uint32_t> local(V, UINT32_MAX);
  std::vector<std::uint32_t> used;
  for (unsigned k = 0; k < n; ++k) {
    used.clear();
    std::size_t faces = 0;
    for (std::size_t t = 0; t < T; ++t) {
      if (triangle_material[t] != k) continue;
      ++faces;
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t v = mesh.indices[3 * t + static_cast<std::size_t>(c)];
        if (local[v] == UINT32_MAX) {
          local[v] = static_cast<std::uint32_t>(used.size());
          used.push_back(v);
        }
      }
    }
    auto* am = new aiMesh();
    scene->mMeshes[k] = am;
    am->mName = aiString("mesh " + std::to_string(k));
    am->mMaterialIndex = k;
    am->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    am->mNumVertices = static_cast<unsigned>(used.size());
    am->mVertices = new aiVector3D[used.size()];
    am->mNormals = new aiVector3D[used.size()];
    for (unsigned c = 0; c < 2; ++c) {
      am->mTextureCoords[c] = new aiVector3D[used.size()];
      am->mNumUVComponents[c] = 2;
    }
    for (std::size_t i = 0; i < used.size(); ++i) {
      const glm::vec3 p = mesh.positions[used[i]];
      const glm::dvec3 s = normal_sum[used[i]];
      const glm::vec3 nn = glm::dot(s, s) > 0.0 ? glm::vec3(glm::normalize(s)) : glm::vec3(0.0f, 1.0f, 0.0f);
      am->mVertices[i] = aiVector3D(p.x, p.y, p.z);
      am->mNormals[i] = aiVector3D(nn.x, nn.y, nn.z);
      // assimp's glTF exporter writes 1 - v (its v grows upwards, glTF's downwards): give it 1 - v.
      const glm::vec2 uv = mesh.lightmap_uvs[used[i]];
      for (unsigned c = 0; c < 2; ++c) am->mTextureCoords[c][i] = aiVector3D(uv.x, 1.0f - uv.y, 0.0f);
    }
    am->mNumFaces = static_cast<unsigned>(faces);
    am->mFaces = new aiFace[faces];
    std::size_t f = 0;
    for (std::size_t t = 0; t < T; ++t) {
      if (triangle_material[t] != k) continue;
      aiFace& face = am->mFaces[f++];
      face.mNumIndices = 3;
      face.mIndices = new unsigned[3];
      for (int c = 0; c < 3; ++c) face.mIndices[c] = local[mesh.indices[3 * t + static_cast<std::size_t>(c)]];
    }
    for (std::uint32_t v : used) local[v] = UINT32_MAX;
  }
  Assimp::Exporter exporter;
  if (exporter.Export(scene.get(), "glb2", path) != AI_SUCCESS)
    throw std::runtime_error("cannot write '" + path + "': " + exporter.GetErrorString());
}

namespace {

// The material of an imported one: factors, two-sided, a base colour texture read from a file, and
// what the file said of its opacity (glTF alphaMode, alphaCutoff, the base colour's alpha,
// KHR_materials_transmission's factor).
aiMaterial* make_material(const model_import::material& mat, const std::vector<model_import::texture>& textures,
                          const std::string& out_dir) {
  auto* am = new aiMaterial();
  const aiString name(mat.name);
  am->AddProperty(&name, AI_MATKEY_NAME);
  const aiColor4D base(mat.base_color.x, mat.base_color.y, mat.base_color.z, mat.base_alpha);
  if (!mat.alpha_mode.empty()) {
    const aiString mode(mat.alpha_mode);
    am->AddProperty(&mode, AI_MATKEY_GLTF_ALPHAMODE);
    am->AddProperty(&mat.gltf_alpha_cutoff, 1, AI_MATKEY_GLTF_ALPHACUTOFF);
  }
  if (mat.transmission > 0.0f) am->AddProperty(&mat.transmission, 1, AI_MATKEY_TRANSMISSION_FACTOR);
  am->AddProperty(&base, 1, AI_MATKEY_BASE_COLOR);
  const aiColor3D diffuse(mat.base_color.x, mat.base_color.y, mat.base_color.z), emissive(mat.emissive.x, mat.emissive.y, mat.emissive.z);
  am->AddProperty(&diffuse, 1, AI_MATKEY_COLOR_DIFFUSE);
  am->AddProperty(&emissive, 1, AI_MATKEY_COLOR_EMISSIVE);
  const int two_sided = mat.two_sided ? 1 : 0;
  am->AddProperty(&two_sided, 1, AI_MATKEY_TWOSIDED);
  std::error_code ec;
  if (mat.base_color_texture >= 0) {
    const std::string& source = textures[std::size_t(mat.base_color_texture)].source;
    if (std::filesystem::is_regular_file(source, ec)) {
      const aiString file(std::filesystem::relative(source, out_dir, ec).generic_string());
      am->AddProperty(&file, AI_MATKEY_TEXTURE(aiTextureType_DIFFUSE, 0));
      const int channel = int(mat.base_color_uv);
      am->AddProperty(&channel, 1, AI_MATKEY_UVWSRC(aiTextureType_DIFFUSE, 0));
    }
  }
  return am;
}

}  // namespace

void write_glb(const model_import::model& m, const std::string& path) {
  const auto n = static_cast<unsigned>(m.meshes.size());
  auto scene = std::make_unique<aiScene>();
  scene->mRootNode = new aiNode("model");
  scene->mRootNode->mNumChildren = n;
  scene->mRootNode->mChildren = new aiNode*[n];
  scene->mNumMeshes = n;
  scene->mMeshes = new aiMesh*[n];
  for (unsigned k = 0; k < n; ++k) scene->mMeshes[k] = nullptr;
  const std::string out_dir = std::filesystem::absolute(path).parent_path().string();
  const auto materials = static_cast<unsigned>(std::max<std::size_t>(m.materials.size(), 1));
  scene->mNumMaterials = materials;
  scene->mMaterials = new aiMaterial*[materials];
  for (unsigned k = 0; k < materials; ++k)
    scene->mMaterials[k] = make_material(k < m.materials.size() ? m.materials[k] : model_import::material{}, m.textures, out_dir);
  for (unsigned k = 0; k < n; ++k) {
    const model_import::mesh& me = m.meshes[k];
    const std::size_t V = me.positions.size(), T = me.indices.size() / 3;
    if (me.lightmap_uvs.size() != V) throw std::runtime_error("cannot write '" + path + "': " + me.name + " has no lightmap UVs");
    auto* node = new aiNode(me.name);
    node->mParent = scene->mRootNode;
    node->mNumMeshes = 1;
    node->mMeshes = new unsigned[1]{k};
    scene->mRootNode->mChildren[k] = node;
    auto* am = new aiMesh();
    scene->mMeshes[k] = am;
    am->mName = aiString(me.name);
    am->mMaterialIndex = me.material < materials ? me.material : 0;
    am->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    am->mNumVertices = static_cast<unsigned>(V);
    am->mVertices = new aiVector3D[V];
    am->mNormals = new aiVector3D[V];
    // UV channel 0 as imported (else a copy of the lightmap UVs: glTF's TEXCOORD_1 needs a TEXCOORD_0),
    // channel 1 the lightmap UVs; assimp's glTF exporter writes 1 - v (its v grows upwards).
    const bool own0 = !me.uv_channels.empty() && me.uv_channels[0].size() == V;
    for (unsigned c = 0; c < 2; ++c) {
      am->mTextureCoords[c] = new aiVector3D[V];
      am->mNumUVComponents[c] = 2;
    }
    for (std::size_t i = 0; i < V; ++i) {
      const glm::vec3 p = me.positions[i], nn = me.normals[i];
      am->mVertices[i] = aiVector3D(p.x, p.y, p.z);
      am->mNormals[i] = aiVector3D(nn.x, nn.y, nn.z);
      const glm::vec2 uv = me.lightmap_uvs[i];
      am->mTextureCoords[1][i] = aiVector3D(uv.x, 1.0f - uv.y, 0.0f);
      am->mTextureCoords[0][i] = own0 ? aiVector3D(me.uv_channels[0][i].x, me.uv_channels[0][i].y, 0.0f) : am->mTextureCoords[1][i];
    }
    am->mNumFaces = static_cast<unsigned>(T);
    am->mFaces = new aiFace[T];
    for (std::size_t t = 0; t < T; ++t) {
      aiFace& face = am->mFaces[t];
      face.mNumIndices = 3;
      face.mIndices = new unsigned[3];
      for (int c = 0; c < 3; ++c) face.mIndices[c] = me.indices[3 * t + static_cast<std::size_t>(c)];
    }
  }
  Assimp::Exporter exporter;
  if (exporter.Export(scene.get(), "glb2", path) != AI_SUCCESS)
    throw std::runtime_error("cannot write '" + path + "': " + exporter.GetErrorString());
}

}  // namespace hemilight::model_export
