// Models for the command-line baker (model_import.hpp): assimp's scene walked node by node,
// textures decoded by stb_image, per-texel materials averaged over lightmap texel footprints.
#include "model_import.hpp"

#include <assimp/GltfMaterial.h>
#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <stb_image.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>

namespace hemilight::model_import {

namespace {

[[noreturn]] void fail(const std::string& message) { throw std::runtime_error(message); }

float srgb_to_linear(float s) { return s <= 0.04045f ? s / 12.92f : std::pow((s + 0.055f) / 1.055f, 2.4f); }

// 8-bit RGBA (row 0 = top) to a linear texture; the alpha channel kept as it is when the image has
// one (`has_alpha`) that is not 255 everywhere.
texture from_rgba8(const unsigned char* p, int w, int h, std::string source, bool has_alpha) {
  texture t;
  t.width = w;
  t.height = h;
  t.source = std::move(source);
  float table[256];
  for (int i = 0; i < 256; ++i) table[i] = srgb_to_linear(float(i) / 255.0f);
  t.texels.resize(std::size_t(w) * std::size_t(h));
  bool varies = false;
  for (std::size_t i = 0; i < t.texels.size(); ++i) {
    t.texels[i] = glm::vec3(table[p[4 * i]], table[p[4 * i + 1]], table[p[4 * i + 2]]);
    varies = varies || p[4 * i + 3] != 255;
  }
  if (has_alpha && varies) {
    t.alpha.resize(t.texels.size());
    for (std::size_t i = 0; i < t.texels.size(); ++i) t.alpha[i] = p[4 * i + 3];
  }
  return t;
}

// stb_image's channel count says whether the file has an alpha channel (grey + alpha, RGBA).
bool channels_have_alpha(int n) { return n == 2 || n == 4; }

// A texture of the material: embedded ("*N" or a glb's name) or a file next to the model.
texture load_texture(const aiScene* sc, const std::string& model_path, const std::string& ref, const std::string& who) {
  if (const aiTexture* emb = sc->GetEmbeddedTexture(ref.c_str())) {
    const std::string source = "embedded texture '" + ref + "'";
    if (emb->mHeight == 0) {  // compressed (PNG, JPEG, ...): mWidth bytes
      int w = 0, h = 0, n = 0;
      unsigned char* px = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(emb->pcData), int(emb->mWidth), &w, &h, &n, 4);
      if (!px) fail(who + ": " + source + " cannot be decoded: " + stbi_failure_reason());
      texture t = from_rgba8(px, w, h, source, channels_have_alpha(n));
      stbi_image_free(px);
      return t;
    }
    std::vector<unsigned char> rgba(std::size_t(emb->mWidth) * emb->mHeight * 4);
    for (std::size_t i = 0; i < std::size_t(emb->mWidth) * emb->mHeight; ++i) {
      rgba[4 * i] = emb->pcData[i].r;
      rgba[4 * i + 1] = emb->pcData[i].g;
      rgba[4 * i + 2] = emb->pcData[i].b;
      rgba[4 * i + 3] = emb->pcData[i].a;
    }
    return from_rgba8(rgba.data(), int(emb->mWidth), int(emb->mHeight), source, true);
  }
  std::filesystem::path p(ref);
  if (p.is_relative()) p = std::filesystem::path(model_path).parent_path() / p;
  int w = 0, h = 0, n = 0;
  unsigned char* px = stbi_load(p.string().c_str(), &w, &h, &n, 4);
  if (!px) fail(who + ": texture '" + p.string() + "' cannot be read: " + stbi_failure_reason());
  texture t = from_rgba8(px, w, h, p.string(), channels_have_alpha(n));
  stbi_image_free(px);
  return t;
}

// The world transform of every node, by name (lights find theirs this way).
void collect_nodes(const aiNode* node, const aiMatrix4x4& parent, std::vector<std::pair<const aiNode*, aiMatrix4x4>>& out) {
  const aiMatrix4x4 world = parent * node->mTransformation;
  out.emplace_back(node, world);
  for (unsigned i = 0; i < node->mNumChildren; ++i) collect_nodes(node->mChildren[i], world, out);
}

glm::vec3 point(const aiMatrix4x4& m, const aiVector3D& v) {
  const aiVector3D r = m * v;
  return {r.x, r.y, r.z};
}
glm::vec3 direction(const aiMatrix4x4& m, const aiVector3D& v) {
  const aiVector3D r = aiMatrix3x3(m) * v;
  return {r.x, r.y, r.z};
}

std::vector<light> model_lights(const aiScene* sc, const std::map<std::string, aiMatrix4x4>& node_world, const std::string& path) {
  std::vector<light> out;
  for (unsigned i = 0; i < sc->mNumLights; ++i) {
    const aiLight& a = *sc->mLights[i];
    const auto it = node_world.find(a.mName.C_Str());
    const aiMatrix4x4 m = it == node_world.end() ? aiMatrix4x4() : it->second;
    light l;
    l.color = glm::max(glm::vec3(a.mColorDiffuse.r, a.mColorDiffuse.g, a.mColorDiffuse.b), glm::vec3(0.0f));
    l.position = point(m, a.mPosition);
    l.direction = direction(m, a.mDirection);
    switch (a.mType) {
      case aiLightSource_DIRECTIONAL: l.type = light_type::directional; break;
      case aiLightSource_POINT: l.type = light_type::point; break;
      case aiLightSource_SPOT:
        l.type = light_type::spot;
        l.spot_outer = std::clamp(0.5f * a.mAngleOuterCone, 0.0f, 1.5707963f);
        l.spot_inner = std::clamp(0.5f * a.mAngleInnerCone, 0.0f, l.spot_outer);
        break;
      case aiLightSource_AREA:
        l.type = light_type::rect;
        l.tangent = direction(m, a.mUp);
        l.width = a.mSize.x;
        l.height = a.mSize.y;
        break;
      default:
        std::fprintf(stderr, "hemilight_bake: '%s' light %u ('%s') is of a type that cannot be baked; skipped\n", path.c_str(), i,
                     a.mName.C_Str());
        continue;
    }
    out.push_back(l);
  }
  return out;
}

// The opacity of a material whose factors and textures are read (the rules in model_import.hpp):
// alpha_mode and transmission as the file says; opacity, alpha, alpha_cutoff, alpha_texture and
// transmittance as the scene takes them. The alpha texture of a base colour texture is made once
// (alpha_of: texture index -> alpha texture index).
void read_opacity(const aiMaterial* am, float base_alpha, material& mat, model& m, std::map<int, int>& alpha_of, bool ignore) {
  aiString mode;
  if (am->Get(AI_MATKEY_GLTF_ALPHAMODE, mode) == AI_SUCCESS) mat.alpha_mode = mode.C_Str();
  float cutoff = 0.5f, transmission = 0.0f;
  am->Get(AI_MATKEY_GLTF_ALPHACUTOFF, cutoff);
  am->Get(AI_MATKEY_TRANSMISSION_FACTOR, transmission);
  mat.base_alpha = base_alpha;
  mat.gltf_alpha_cutoff = cutoff;
  mat.transmission = std::isfinite(transmission) ? std::clamp(transmission, 0.0f, 1.0f) : 0.0f;
  const bool mask = mat.alpha_mode == "MASK", blend = mat.alpha_mode == "BLEND";
  const float alpha = std::isfinite(base_alpha) ? std::clamp(base_alpha, 0.0f, 1.0f) : 1.0f;
  const texture* tex = mat.base_color_texture >= 0 ? &m.textures[std::size_t(mat.base_color_texture)] : nullptr;
  // What the scene takes, decided first; applied unless `ignore` (then only counted).
  material see;
  bool reads_alpha_texture = false;
  if (mat.transmission > 0.0f || blend) {
    // The fraction a of the surface that is there (BLEND's coverage; 1 otherwise) passes
    // transmission x base colour, the rest passes everything.
    const float a = blend ? alpha * (tex ? tex->mean_alpha() : 1.0f) : 1.0f;
    const glm::vec3 tint = glm::clamp(mat.base_color * (tex ? tex->mean() : glm::vec3(1.0f)), 0.0f, 1.0f);
    see.opacity = surface_opacity::translucent;
    see.transmittance = glm::clamp((1.0f - a) + a * mat.transmission * tint, 0.0f, 1.0f);
  } else if (mask) {
    // Present where alpha x the texture's alpha >= cutoff.
    if (!std::isfinite(cutoff)) cutoff = 0.5f;
    const bool textured = tex && !tex->alpha.empty();
    if (cutoff > 1.0f) {  // glTF allows it: never present
      see.opacity = surface_opacity::alpha_tested;
      see.alpha = 0.0f;
      see.alpha_cutoff = 1.0f;
    } else if (textured || alpha < std::max(cutoff, 0.0f)) {  // else present everywhere: opaque, and drawn as such
      see.opacity = surface_opacity::alpha_tested;
      see.alpha = alpha;
      see.alpha_cutoff = std::max(cutoff, 0.0f);
      reads_alpha_texture = textured;
    }
  }
  if (see.opacity == surface_opacity::opaque) return;
  if (ignore) {
    ++m.ignored_see_through;
    return;
  }
  mat.opacity = see.opacity;
  mat.alpha = see.alpha;
  mat.alpha_cutoff = see.alpha_cutoff;
  mat.transmittance = see.transmittance;
  if (!reads_alpha_texture) return;
  auto it = alpha_of.find(mat.base_color_texture);
  if (it == alpha_of.end()) {
    alpha_image img;
    img.width = tex->width;
    img.height = tex->height;
    img.values = tex->alpha;
    m.alpha_textures.push_back(std::move(img));
    m.alpha_sources.push_back(mat.base_color_texture);
    it = alpha_of.emplace(mat.base_color_texture, int(m.alpha_textures.size() - 1)).first;
  }
  mat.alpha_texture = it->second;
}

// A material's factors, textures (loaded once per reference) and UV channels, and its opacity.
material read_material(const aiScene* sc, unsigned index, const std::string& path, std::map<std::string, int>& loaded,
                       std::map<int, int>& alpha_of, model& m, bool ignore_opacity) {
  std::vector<texture>& textures = m.textures;
  const aiMaterial* am = sc->mMaterials[index];
  material mat;
  mat.name = am->GetName().C_Str();
  const std::string who = "'" + path + "' material " + std::to_string(index) + " ('" + mat.name + "')";
  aiColor4D base(0.8f, 0.8f, 0.8f, 1.0f);
  if (am->Get(AI_MATKEY_BASE_COLOR, base) != AI_SUCCESS) {
    aiColor3D c(0.8f, 0.8f, 0.8f);
    am->Get(AI_MATKEY_COLOR_DIFFUSE, c);
    base = aiColor4D(c.r, c.g, c.b, 1.0f);
  }
  mat.base_color = glm::vec3(base.r, base.g, base.b);
  aiColor3D e(0.0f, 0.0f, 0.0f);
  am->Get(AI_MATKEY_COLOR_EMISSIVE, e);
  mat.emissive = glm::max(glm::vec3(e.r, e.g, e.b), glm::vec3(0.0f));
  int two = 0;
  am->Get(AI_MATKEY_TWOSIDED, two);
  mat.two_sided = two != 0;
  const auto texture_of = [&](std::initializer_list<aiTextureType> types, int& slot, unsigned& channel) {
    for (aiTextureType type : types) {
      aiString ref;
      if (am->GetTextureCount(type) == 0 || am->GetTexture(type, 0, &ref) != AI_SUCCESS) continue;
      int uv = 0;
      if (am->Get(AI_MATKEY_UVWSRC(type, 0), uv) == AI_SUCCESS && uv >= 0) channel = unsigned(uv);
      const std::string key = ref.C_Str();
      auto it = loaded.find(key);
      if (it == loaded.end()) {
        textures.push_back(load_texture(sc, path, key, who));
        it = loaded.emplace(key, int(textures.size() - 1)).first;
      }
      slot = it->second;
      return;
    }
  };
  texture_of({aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE}, mat.base_color_texture, mat.base_color_uv);
  texture_of({aiTextureType_EMISSIVE}, mat.emissive_texture, mat.emissive_uv);
  read_opacity(am, base.a, mat, m, alpha_of, ignore_opacity);
  return mat;
}

// The lightmap UVs the baker takes (bake.hpp's rules): within lightmap_uv_tolerance of [0, 1]
// (it clamps them), and with strict, area wherever there is 3D area (degenerate triangles aside:
// is_degenerate_triangle), by the baker's own threshold (1e-12 of the UV square).
void check_lightmap_uvs(const mesh& out, const std::string& path, bool strict) {
  constexpr float lo = -lightmap_uv_tolerance, hi = 1.0f + lightmap_uv_tolerance;
  for (std::size_t v = 0; v < out.lightmap_uvs.size(); ++v) {
    const glm::vec2 t = out.lightmap_uvs[v];
    if (!(t.x >= lo && t.x <= hi && t.y >= lo && t.y <= hi))
      fail("'" + path + "' " + out.name + " vertex " + std::to_string(v) + ": lightmap UV (" + std::to_string(t.x) + ", " +
           std::to_string(t.y) + ") is outside [0, 1] by more than 0.001");
  }
  for (std::size_t t = 0; strict && t + 2 < out.indices.size(); t += 3) {
    const std::uint32_t* i = &out.indices[t];
    const glm::dvec2 a(glm::clamp(out.lightmap_uvs[i[0]], 0.0f, 1.0f)), b(glm::clamp(out.lightmap_uvs[i[1]], 0.0f, 1.0f)),
        c(glm::clamp(out.lightmap_uvs[i[2]], 0.0f, 1.0f));
    const double uv_area = 0.5 * std::fabs((b - a).x * (c - a).y - (b - a).y * (c - a).x);
    if (!is_degenerate_triangle(out.positions[i[0]], out.positions[i[1]], out.positions[i[2]]) && !(uv_area > 1e-12))
      fail("'" + path + "' " + out.name + " triangle " + std::to_string(t / 3) +
           " has zero area in lightmap UV space (but not in 3D): it would get no texels (--strict)");
  }
}

}  // namespace

void apply_lightmap_uvs(model& m, const unwrap_result& r) {
  std::vector<mesh> out;
  std::size_t first_vertex = 0, first_triangle = 0;
  std::vector<std::uint32_t> local(r.uvs.size(), 0xffffffffu);
  int pages = 1;
  for (mesh& me : m.meshes) {
    const std::size_t T = me.indices.size() / 3;
    std::vector<int> used_pages;
    for (std::size_t t = 0; t < T; ++t) used_pages.push_back(int(r.triangle_page[first_triangle + t]));
    std::sort(used_pages.begin(), used_pages.end());
    used_pages.erase(std::unique(used_pages.begin(), used_pages.end()), used_pages.end());
    for (int page : used_pages) {
      mesh part;
      part.name = used_pages.size() > 1 ? me.name + " (page " + std::to_string(page) + ")" : me.name;
      part.source_mesh = me.source_mesh;
      part.instance = me.instance;
      part.material = me.material;
      part.page = page;
      part.uv_channels.resize(me.uv_channels.size());
      std::vector<std::uint32_t> made;
      for (std::size_t t = 0; t < T; ++t) {
        if (int(r.triangle_page[first_triangle + t]) != page) continue;
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t o = r.indices[3 * (first_triangle + t) + std::size_t(k)];
          if (local[o] == 0xffffffffu) {
            const std::size_t v = r.vertex_source[o] - first_vertex;  // the mesh's own vertex
            local[o] = std::uint32_t(part.positions.size());
            made.push_back(o);
            part.positions.push_back(me.positions[v]);
            part.normals.push_back(me.normals[v]);
            part.lightmap_uvs.push_back(r.uvs[o]);
            for (std::size_t c = 0; c < me.uv_channels.size(); ++c) part.uv_channels[c].push_back(me.uv_channels[c][v]);
          }
          part.indices.push_back(local[o]);
        }
      }
      for (std::uint32_t o : made) local[o] = 0xffffffffu;
      pages = std::max(pages, page + 1);
      out.push_back(std::move(part));
    }
    first_vertex += me.positions.size();
    first_triangle += T;
  }
  m.meshes = std::move(out);
  m.pages = pages;
  m.without_lightmap_uvs.clear();
}

glm::vec3 texture::lookup(glm::vec2 uv) const noexcept {
  if (texels.empty()) return glm::vec3(0.0f);
  const float u = uv.x - std::floor(uv.x), v = uv.y - std::floor(uv.y);
  const int x = std::clamp(int(u * float(width)), 0, width - 1);
  const int y = std::clamp(int((1.0f - v) * float(height)), 0, height - 1);
  return texels[std::size_t(y) * std::size_t(width) + std::size_t(x)];
}

glm::vec3 texture::mean() const noexcept {
  glm::dvec3 s(0.0);
  for (const glm::vec3& t : texels) s += glm::dvec3(t);
  return texels.empty() ? glm::vec3(0.0f) : glm::vec3(s / double(texels.size()));
}

float texture::mean_alpha() const noexcept {
  if (alpha.empty()) return 1.0f;
  double s = 0.0;
  for (std::uint8_t a : alpha) s += a;
  return float(s / (255.0 * double(alpha.size())));
}

hemilight::material material::flat(const std::vector<texture>& textures) const {
  hemilight::material m;
  const glm::vec3 b = base_color_texture >= 0 ? textures[std::size_t(base_color_texture)].mean() : glm::vec3(1.0f);
  const glm::vec3 e = emissive_texture >= 0 ? textures[std::size_t(emissive_texture)].mean() : glm::vec3(1.0f);
  m.albedo = glm::clamp(base_color * b, 0.0f, 1.0f);
  m.emission = glm::max(emissive * e, glm::vec3(0.0f));
  m.two_sided = two_sided;
  m.opacity = opacity;
  m.alpha = alpha;
  m.alpha_cutoff = alpha_cutoff;
  m.alpha_texture = alpha_texture;
  m.transmittance = transmittance;
  return m;
}

std::vector<glm::vec2> mesh_texcoords(const model& m, const mesh& me) {
  const material& mat = m.materials[me.material];
  if (mat.opacity != surface_opacity::alpha_tested || mat.alpha_texture < 0 || mat.base_color_uv >= me.uv_channels.size()) return {};
  std::vector<glm::vec2> out;
  out.reserve(me.uv_channels[mat.base_color_uv].size());
  for (const glm::vec2& t : me.uv_channels[mat.base_color_uv]) out.emplace_back(t.x, 1.0f - t.y);
  return out;
}

std::string opacity_summary(const model& m) {
  std::string list;
  std::size_t count = 0;
  const auto number = [](float v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", double(v));
    return std::string(text);
  };
  for (const material& mat : m.materials) {
    if (mat.opacity == surface_opacity::opaque) continue;
    list += std::string(count++ ? ", " : "") + "'" + mat.name + "' ";
    if (mat.opacity == surface_opacity::alpha_tested) {
      list += "alpha-tested (MASK, cutoff " + number(mat.alpha_cutoff);
      if (mat.alpha < 1.0f) list += ", alpha " + number(mat.alpha);
      if (mat.alpha_texture >= 0) {
        const alpha_image& a = m.alpha_textures[std::size_t(mat.alpha_texture)];
        list += ", alpha texture '" + m.textures[std::size_t(m.alpha_sources[std::size_t(mat.alpha_texture)])].source + "' " +
                std::to_string(a.width) + " x " + std::to_string(a.height);
      }
      list += ")";
    } else {
      const glm::vec3 t = mat.transmittance;
      list += "translucent (" + (mat.transmission > 0.0f ? "transmission " + number(mat.transmission) : mat.alpha_mode) +
              ": transmittance " + (t.x == t.y && t.y == t.z ? number(t.x) : number(t.x) + ", " + number(t.y) + ", " + number(t.z)) + ")";
    }
  }
  std::string line;
  if (count > 0)
    line = std::to_string(count) + " of " + std::to_string(m.materials.size()) + " material" + (m.materials.size() > 1 ? "s" : "") +
           (count > 1 ? " let" : " lets") + " light through: " + list;
  if (m.ignored_see_through > 0)
    line += std::string(line.empty() ? "" : "; ") + std::to_string(m.ignored_see_through) + " see-through material" +
            (m.ignored_see_through > 1 ? "s" : "") + " baked opaque (opacity ignored)";
  return line;
}

model import_model(const std::string& path, unsigned lightmap_channel) {
  import_options o;
  o.lightmap_channel = lightmap_channel;
  return import_model(path, o);
}

model import_model(const std::string& path, const import_options& options) {
  const unsigned lightmap_channel = options.lightmap_channel;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail("cannot read '" + path + "': no such file");
  Assimp::Importer importer;
  const aiScene* sc = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_GenNormals | aiProcess_SortByPType);
  if (!sc || (sc->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !sc->mRootNode) fail("cannot read '" + path + "': " + importer.GetErrorString());
  if (lightmap_channel >= AI_MAX_NUMBER_OF_TEXTURECOORDS) fail("lightmap UV channel " + std::to_string(lightmap_channel) + " is out of range");

  // Step 1: the meshes with triangles, and those without the lightmap channel (all named).
  std::string missing;
  std::size_t missing_count = 0, with_triangles = 0;
  for (unsigned mi = 0; mi < sc->mNumMeshes; ++mi) {
    const aiMesh* mesh = sc->mMeshes[mi];
    if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;  // points and lines: nothing to light
    ++with_triangles;
    if (!mesh->HasTextureCoords(lightmap_channel)) {
      missing += std::string(missing.empty() ? "" : ", ") + "mesh " + std::to_string(mi) + " ('" + mesh->mName.C_Str() + "')";
      ++missing_count;
    }
  }
  if (with_triangles == 0) fail("'" + path + "' has no meshes with triangles: nothing to bake");
  if (missing_count > 0 && !options.allow_missing_lightmap_uvs)
    fail("'" + path + "': " + std::to_string(missing_count) + (missing_count > 1 ? " meshes have" : " mesh has") +
         " no lightmap UVs (UV channel " + std::to_string(lightmap_channel) + "): " + missing +
         (lightmap_channel == 1 ? "; give them a second UV set (glTF TEXCOORD_1), or bake UV channel 0 with --lightmap-uv 0" : ""));

  // Step 2: materials, their textures and their opacity.
  model m;
  std::map<std::string, int> loaded;
  std::map<int, int> alpha_of;
  for (unsigned i = 0; i < sc->mNumMaterials; ++i)
    m.materials.push_back(read_material(sc, i, path, loaded, alpha_of, m, options.ignore_opacity));
  if (m.materials.empty()) m.materials.emplace_back();

  // Step 3: every node's meshes in world space.
  std::vector<std::pair<const aiNode*, aiMatrix4x4>> nodes;
  collect_nodes(sc->mRootNode, aiMatrix4x4(), nodes);
  // glTF stores v downwards (its images' first row at v = 0, the baker's row convention) and
  // assimp flips it to v up: the lightmap UVs are flipped back, so that a page uploaded row 0
  // first is what an engine reading the same file samples with TEXCOORD_1. (Texture lookups use
  // assimp's v-up convention for every format: texture::lookup.)
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  const bool gltf = ext == ".gltf" || ext == ".glb";
  std::vector<unsigned> instances(sc->mNumMeshes, 0);
  for (const auto& [node, world] : nodes) {
    aiMatrix3x3 normal_matrix(world);
    const bool mirrored = normal_matrix.Determinant() < 0.0f;
    normal_matrix.Inverse().Transpose();
    for (unsigned k = 0; k < node->mNumMeshes; ++k) {
      const unsigned mi = node->mMeshes[k];
      const aiMesh* src = sc->mMeshes[mi];
      if (!(src->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
      mesh out;
      out.source_mesh = mi;
      out.instance = instances[mi]++;
      out.page = int(out.instance);
      const bool has_lightmap_uvs = src->HasTextureCoords(lightmap_channel);
      out.name = "mesh " + std::to_string(mi) + " ('" + src->mName.C_Str() + "') at node '" + node->mName.C_Str() + "'";
      out.material = src->mMaterialIndex < m.materials.size() ? src->mMaterialIndex : 0;
      for (unsigned v = 0; v < src->mNumVertices; ++v) {
        out.positions.push_back(point(world, src->mVertices[v]));
        glm::vec3 n(0.0f);
        if (src->HasNormals()) {
          const aiVector3D t = normal_matrix * src->mNormals[v];
          n = glm::vec3(t.x, t.y, t.z);
        }
        out.normals.push_back(n);
        if (!has_lightmap_uvs) continue;
        const aiVector3D& t = src->mTextureCoords[lightmap_channel][v];
        out.lightmap_uvs.emplace_back(t.x, gltf ? 1.0f - t.y : t.y);
      }
      for (unsigned c = 0; c < AI_MAX_NUMBER_OF_TEXTURECOORDS && src->HasTextureCoords(c); ++c) {
        std::vector<glm::vec2> uv(src->mNumVertices);
        for (unsigned v = 0; v < src->mNumVertices; ++v) uv[v] = glm::vec2(src->mTextureCoords[c][v].x, src->mTextureCoords[c][v].y);
        out.uv_channels.push_back(std::move(uv));
      }
      for (unsigned f = 0; f < src->mNumFaces; ++f) {
        const aiFace& face = src->mFaces[f];
        if (face.mNumIndices != 3) continue;
        out.indices.insert(out.indices.end(), {face.mIndices[0], mirrored ? face.mIndices[2] : face.mIndices[1],
                                               mirrored ? face.mIndices[1] : face.mIndices[2]});
      }
      const material& mat = m.materials[out.material];
      if (mat.alpha_texture >= 0 && mat.base_color_uv >= out.uv_channels.size())
        fail("'" + path + "' " + out.name + ": its material " + std::to_string(out.material) + " ('" + mat.name +
             "') reads its alpha texture at UV channel " + std::to_string(mat.base_color_uv) + " (TEXCOORD_" +
             std::to_string(mat.base_color_uv) + "), which the mesh does not have");
      if (has_lightmap_uvs)
        check_lightmap_uvs(out, path, options.strict);
      else
        m.without_lightmap_uvs.push_back(out.name);
      m.pages = std::max(m.pages, out.page + 1);
      m.meshes.push_back(std::move(out));
    }
  }
  if (m.meshes.empty()) fail("'" + path + "' has no node that uses a mesh with triangles: nothing to bake");

  // Step 4: lights, by their nodes' transforms.
  std::map<std::string, aiMatrix4x4> node_world;
  for (const auto& [node, world] : nodes) node_world.emplace(node->mName.C_Str(), world);
  m.lights = model_lights(sc, node_world, path);
  return m;
}

page_images bake_page_materials(const model& m, int page, int width, int height) {
  page_images out;
  bool base_textured = false, emissive_textured = false;
  for (const mesh& me : m.meshes)
    if (me.page == page) {
      const material& mat = m.materials[me.material];
      base_textured = base_textured || mat.base_color_texture >= 0;
      emissive_textured = emissive_textured || mat.emissive_texture >= 0;
    }
  if (!base_textured && !emissive_textured) return out;
  const std::size_t texels = std::size_t(width) * std::size_t(height);
  std::vector<glm::dvec3> albedo(texels, glm::dvec3(0.0)), emission(texels, glm::dvec3(0.0));
  std::vector<double> weight(texels, 0.0);
  for (const mesh& me : m.meshes) {
    if (me.page != page) continue;
    const material& mat = m.materials[me.material];
    const texture* base_tex = mat.base_color_texture >= 0 ? &m.textures[std::size_t(mat.base_color_texture)] : nullptr;
    const texture* emit_tex = mat.emissive_texture >= 0 ? &m.textures[std::size_t(mat.emissive_texture)] : nullptr;
    const auto channel = [&](unsigned c) { return c < me.uv_channels.size() ? &me.uv_channels[c] : nullptr; };
    const std::vector<glm::vec2>* base_uv = channel(mat.base_color_uv);
    const std::vector<glm::vec2>* emit_uv = channel(mat.emissive_uv);
    for (std::size_t t = 0; t + 2 < me.indices.size(); t += 3) {
      const std::uint32_t i0 = me.indices[t], i1 = me.indices[t + 1], i2 = me.indices[t + 2];
      const glm::vec2 a = me.lightmap_uvs[i0] * glm::vec2(width, height), b = me.lightmap_uvs[i1] * glm::vec2(width, height),
                      c = me.lightmap_uvs[i2] * glm::vec2(width, height);
      const float det = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
      if (!(std::fabs(det) > 0.0f)) continue;
      // Supersamples per axis: about two per texture texel a lightmap texel covers (2..16).
      float footprint = 0.0f;
      for (const auto& [tex, uv] : {std::pair{base_tex, base_uv}, std::pair{emit_tex, emit_uv}}) {
        if (!tex || !uv) continue;
        const glm::vec2 ta = (*uv)[i0], tb = (*uv)[i1], tc = (*uv)[i2];
        const float tdet = std::fabs((tb.x - ta.x) * (tc.y - ta.y) - (tb.y - ta.y) * (tc.x - ta.x)) * float(tex->width) * float(tex->height);
        footprint = std::max(footprint, std::sqrt(tdet / std::fabs(det)));
      }
      const int s = std::clamp(int(std::ceil(2.0f * footprint)), 2, 16);
      const auto value_at = [&](float b1, float b2) {
        const float b0 = 1.0f - b1 - b2;
        const auto sample = [&](const texture* tex, const std::vector<glm::vec2>* uv) {
          if (!tex || !uv) return glm::vec3(1.0f);
          return tex->lookup(b0 * (*uv)[i0] + b1 * (*uv)[i1] + b2 * (*uv)[i2]);
        };
        return std::pair{mat.base_color * sample(base_tex, base_uv), mat.emissive * sample(emit_tex, emit_uv)};
      };
      const int x0 = std::clamp(int(std::floor(std::min({a.x, b.x, c.x}))), 0, width - 1);
      const int x1 = std::clamp(int(std::ceil(std::max({a.x, b.x, c.x}))) - 1, 0, width - 1);
      const int y0 = std::clamp(int(std::floor(std::min({a.y, b.y, c.y}))), 0, height - 1);
      const int y1 = std::clamp(int(std::ceil(std::max({a.y, b.y, c.y}))) - 1, 0, height - 1);
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const texel_clip clip = clip_triangle_to_texel(a, b, c, x, y);
          if (!(clip.area > 0.0f)) continue;
          glm::dvec3 sum_a(0.0), sum_e(0.0);
          int inside = 0;
          for (int j = 0; j < s; ++j)
            for (int i = 0; i < s; ++i) {
              const glm::vec2 q(float(x) + (float(i) + 0.5f) / float(s), float(y) + (float(j) + 0.5f) / float(s));
              const float b1 = ((q.x - a.x) * (c.y - a.y) - (q.y - a.y) * (c.x - a.x)) / det;
              const float b2 = ((b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x)) / det;
              if (b1 < 0.0f || b2 < 0.0f || b1 + b2 > 1.0f) continue;
              const auto [va, ve] = value_at(b1, b2);
              sum_a += glm::dvec3(va);
              sum_e += glm::dvec3(ve);
              ++inside;
            }
          if (inside == 0) {  // a sliver between the supersamples: its centroid
            const glm::vec2 q = clip.centroid;
            const float b1 = ((q.x - a.x) * (c.y - a.y) - (q.y - a.y) * (c.x - a.x)) / det;
            const float b2 = ((b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x)) / det;
            const auto [va, ve] = value_at(std::clamp(b1, 0.0f, 1.0f), std::clamp(b2, 0.0f, 1.0f - std::clamp(b1, 0.0f, 1.0f)));
            sum_a = glm::dvec3(va);
            sum_e = glm::dvec3(ve);
            inside = 1;
          }
          const std::size_t k = std::size_t(y) * std::size_t(width) + std::size_t(x);
          albedo[k] += double(clip.area) * sum_a / double(inside);
          emission[k] += double(clip.area) * sum_e / double(inside);
          weight[k] += double(clip.area);
        }
    }
  }
  // Only the kinds that some texture varies (the other is exact per triangle).
  if (base_textured) out.albedo = image::make(width, height, 3);
  if (emissive_textured) out.emission = image::make(width, height, 3);
  for (std::size_t k = 0; k < texels; ++k) {
    if (!(weight[k] > 0.0)) continue;
    const glm::vec3 va = glm::clamp(glm::vec3(albedo[k] / weight[k]), 0.0f, 1.0f);
    const glm::vec3 ve = glm::clamp(glm::vec3(emission[k] / weight[k]), 0.0f, max_radiance);
    for (int ch = 0; ch < 3; ++ch) {
      if (base_textured) out.albedo.pixels[3 * k + std::size_t(ch)] = va[ch];
      if (emissive_textured) out.emission.pixels[3 * k + std::size_t(ch)] = ve[ch];
    }
  }
  return out;
}

}  // namespace hemilight::model_import
