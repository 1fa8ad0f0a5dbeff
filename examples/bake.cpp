// hemilight_bake — the command-line lightmap baker (the README's main job).
//
//   hemilight_bake                      bakes the built-in scenes (hexagon room lit by the sky
//                                       through its window, the same with a sun shining in, the
//                                       Cornell box with its emissive light and with it as a RECT
//                                       light) into out/
//   hemilight_bake MODEL [options]      bakes a model file (OBJ, or anything assimp reads)
//
// Writes, per scene NAME, into the output directory: NAME_irradiance.exr (RGB float irradiance
// E), NAME_mask.exr (R = coverage, G = valid, B = sampled), NAME_irradiance.png (tone-mapped
// preview), and with --directional NAME_sh_l1_{0..3}.exr (world-space L1 SH) and/or
// NAME_hl2_{0..2}.exr (Half-Life 2 basis in the lightmap tangent frame; bake.hpp). Shows a
// progress bar with the time left and prints the bake's statistics.
// --environment FILE.exr: an ENVMAP_CUBE EXR as the sky (built-in scenes and models).
// --probes GRID|FILE: also NAME_probes.json, SH9 light probes (probes.hpp) rendered after the bake
// so that they see the baked surfaces (emission + albedo E / pi: bake_radiance_texture), the sky
// and the lights. The file: {"format": "hemilight_probes", "version": 1, "basis": "...",
// "resolution": N, "grid": [A, B, C] or null, "bounds": {"min", "max"} (grids only), "probes":
// [{"position": [x, y, z], "backface_fraction": f, "sh9_rgb": [27 numbers: 3 k + c]}, ...]};
// grid probes are at the cell centres, x fastest, then y, then z. Drop probes whose
// backface_fraction is above ~0.1 (inside geometry).
//
// Models: read with assimp (triangulated, node transforms applied, normals generated when
// missing). Lightmap UVs are the mesh's UV channel 1 if it has one, else channel 0; they must lie
// in [0, 1] and give every triangle a nonzero UV area. Material: diffuse colour (Kd) = albedo
// (clamped to [0, 1]), emissive colour (Ke) = emitted radiance, two-sided flag. All meshes share
// one lightmap. The sky (constant radiance) is --sky.
//
// Lights (lights.hpp): --sun and --point (repeatable) add lights; a model's own punctual and area
// lights (glTF KHR_lights_punctual, FBX, Collada: whatever assimp imports as aiLight) are baked
// too. assimp gives each light's colour already multiplied by its intensity; the values are used
// as they are, in the model's units: a point or spot light's value as intensity (W/sr; glTF's
// candela), a directional light's as irradiance (W/m^2; glTF's lux), with no photometric
// conversion, so that they stay on the scale of the model's emissive colours. Spot cone angles are
// assimp's inner and outer angles (full angles in assimp's convention, halved here); an area light
// becomes a RECT of assimp's size and its colour as radiance. Light positions and directions are
// those assimp reports after its node transforms (aiProcess_PreTransformVertices applies them).
//
// Preview tone mapping: exposure k = 0.5 / (mean luminance of the sampled texels), then Reinhard
// c k / (1 + c k) per channel, then the sRGB transfer curve, 8 bits. The EXR holds the raw values.
#include "hemilight/bake.hpp"
#include "hemilight/cubemap.hpp"
#include "hemilight/image_io.hpp"
#include "hemilight/lights.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/probes.hpp"
#include "hemilight/reference_scenes.hpp"

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <png.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

const char* usage =
    "usage: hemilight_bake [MODEL] [options]\n"
    "  With no MODEL: bakes the built-in hexagon room (lit by the sky through a window) and the\n"
    "  Cornell box. With MODEL (OBJ or another format assimp reads): bakes its lightmap UVs\n"
    "  (UV channel 1 if present, else 0; they must lie in [0, 1]).\n"
    "options:\n"
    "  --size N           lightmap width and height in texels, 1..8192 (default 256)\n"
    "  --resolution N     hemicube resolution, even, 2..4096 (default 64)\n"
    "  --error A          irradiance cache error threshold (Ward's a), [0.001, 1] (default 0.2)\n"
    "  --bounces K        light bounces, 1 = direct only, 1..64 (default 3)\n"
    "  --threads T        worker threads, 0 = all cores (default 0)\n"
    "  --out DIR          output directory (default out)\n"
    "  --sky R,G,B        sky radiance for a model (default 1,1,1)\n"
    "  --indirect-only    store everything but the first bounce\n"
    "  --no-cache         a hemicube at every texel (reference; slow)\n"
    "  --directional K    also write directional lightmaps: sh (L1 SH, 4 EXRs), hl2 (Half-Life 2\n"
    "                     basis, 3 EXRs) or both (default: none)\n"
    "  --environment F    sky from an OpenEXR cube map (ENVMAP_CUBE) instead of the constant sky\n"
    "  --sun DX,DY,DZ,E[,A]  a sun: direction of travel, irradiance facing it (W/m^2), angular\n"
    "                     radius in radians (default 0.00465, the sun's; 0 = hard)\n"
    "  --point X,Y,Z,I[,R]   a point light (repeatable): position, intensity (W/sr), radius (default 0)\n"
    "  --shadow-mask      also write NAME_shadow_mask.exr: the visibility of the first four lights\n"
    "  --probes P         also write NAME_probes.json: SH9 light probes (probes.hpp) that see the\n"
    "                     baked surfaces, at the centres of an AxBxC grid over the scene's bounds\n"
    "                     (P like 8x4x8) or at the points of a text file (x y z per line, # comments)\n"
    "  --quiet            no progress bar\n"
    "  --help             this text\n";

struct cli_error {
  std::string message;
  int code;
};

bool bar_open = false;  // a progress line is on stderr without its newline

[[noreturn]] void fail(const std::string& message, int code = 1) { throw cli_error{message, code}; }

struct settings {
  std::string model, out = "out", environment;
  bake_options options;
  glm::vec3 sky{1.0f};
  bool quiet = false, shadow_mask = false;
  std::string probes;  // --probes: "AxBxC" or a file of points; empty: none
};

// "a,b,c,d[,e]": 4 or 5 finite numbers.
std::vector<float> parse_list(const std::string& name, const std::string& text, const char* form) {
  std::vector<float> v;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t comma = text.find(',', at);
    const std::string item = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    char* end = nullptr;
    const float x = std::strtof(item.c_str(), &end);
    if (item.empty() || *end || !std::isfinite(x)) fail(name + " " + text + " is invalid: it must be " + form, 2);
    v.push_back(x);
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  if (v.size() < 4 || v.size() > 5) fail(name + " " + text + " is invalid: it must be " + form, 2);
  return v;
}

int parse_int(const std::string& name, const char* text, long lo, long hi) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text, &end, 10);
  if (!*text || *end || errno != 0 || v < lo || v > hi)
    fail(name + " " + text + " is invalid: it must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", 2);
  return int(v);
}

float parse_float(const std::string& name, const char* text, float lo, float hi, bool open_lo) {
  char* end = nullptr;
  const float v = std::strtof(text, &end);
  if (!*text || *end || !std::isfinite(v) || v > hi || (open_lo ? v <= lo : v < lo))
    fail(name + " " + text + " is invalid: it must be a number in " + (open_lo ? "(" : "[") + std::to_string(lo) + ", " +
             std::to_string(hi) + "]", 2);
  return v;
}

settings parse(int argc, char** argv) {
  settings s;
  s.options.width = s.options.height = 256;
  s.options.bounces = 3;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> const char* {
      if (i + 1 >= argc) fail(a + " needs a value (see --help)", 2);
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::fputs(usage, stdout);
      std::exit(0);
    } else if (a == "--size") {
      s.options.width = s.options.height = parse_int("--size", value(), 1, max_lightmap_size);
    } else if (a == "--resolution") {
      s.options.resolution = parse_int("--resolution", value(), 2, 4096);
      if (s.options.resolution % 2) fail("--resolution " + std::to_string(s.options.resolution) + " is invalid: it must be even", 2);
    } else if (a == "--error") {
      s.options.cache.error_threshold = parse_float("--error", value(), 0.001f, 1.0f, false);
    } else if (a == "--bounces") {
      s.options.bounces = parse_int("--bounces", value(), 1, 64);
    } else if (a == "--threads") {
      s.options.thread_count = parse_int("--threads", value(), 0, 256);
    } else if (a == "--out") {
      s.out = value();
    } else if (a == "--sky") {
      const std::string v = value();
      float r, g, b;
      char tail;
      if (std::sscanf(v.c_str(), "%f,%f,%f%c", &r, &g, &b, &tail) != 3 || !(r >= 0 && g >= 0 && b >= 0) ||
          !std::isfinite(r + g + b))
        fail("--sky " + v + " is invalid: it must be three finite numbers >= 0 like 1,1,1", 2);
      s.sky = {r, g, b};
    } else if (a == "--indirect-only") {
      s.options.indirect_only = true;
    } else if (a == "--no-cache") {
      s.options.use_cache = false;
    } else if (a == "--directional") {
      const std::string v = value();
      if (v != "sh" && v != "hl2" && v != "both") fail("--directional " + v + " is invalid: it must be sh, hl2 or both", 2);
      s.options.output_sh_l1 = v != "hl2";
      s.options.output_hl2 = v != "sh";
    } else if (a == "--environment") {
      s.environment = value();
    } else if (a == "--sun") {
      const std::vector<float> v = parse_list("--sun", value(), "DX,DY,DZ,E[,ANGLE] like 0.3,-1,0.2,20");
      light l;
      l.type = light_type::directional;
      l.direction = {v[0], v[1], v[2]};
      l.color = glm::vec3(v[3]);
      l.radius = v.size() > 4 ? v[4] : 0.00465f;
      s.options.lights.push_back(l);
    } else if (a == "--point") {
      const std::vector<float> v = parse_list("--point", value(), "X,Y,Z,I[,RADIUS] like 0,2.5,0,10");
      light l;
      l.type = light_type::point;
      l.position = {v[0], v[1], v[2]};
      l.color = glm::vec3(v[3]);
      l.radius = v.size() > 4 ? v[4] : 0.0f;
      s.options.lights.push_back(l);
    } else if (a == "--shadow-mask") {
      s.shadow_mask = true;
    } else if (a == "--probes") {
      s.probes = value();
    } else if (a == "--quiet") {
      s.quiet = true;
    } else if (a.size() > 1 && a[0] == '-') {
      fail("unknown option " + a + " (see --help)", 2);
    } else if (s.model.empty()) {
      s.model = a;
    } else {
      fail("more than one model given: " + s.model + " and " + a, 2);
    }
  }
  if (!s.probes.empty() && s.options.indirect_only)
    fail("--probes cannot be used with --indirect-only: the probes see the surfaces' whole baked light", 2);
  return s;
}

// --probes: the probe positions, from "AxBxC" (cell centres of that grid over [lo, hi]) or a file.
std::vector<glm::vec3> probe_positions(const std::string& spec, const glm::vec3& lo, const glm::vec3& hi, int (&grid)[3]) {
  std::vector<glm::vec3> p;
  int a = 0, b = 0, c = 0;
  char tail;
  if (std::sscanf(spec.c_str(), "%dx%dx%d%c", &a, &b, &c, &tail) == 3) {
    if (a < 1 || b < 1 || c < 1 || double(a) * b * c > 1e7)
      fail("--probes " + spec + " is invalid: each count must be >= 1 and the grid at most 10^7 probes", 2);
    grid[0] = a, grid[1] = b, grid[2] = c;
    for (int k = 0; k < c; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < a; ++i)
          p.push_back(lo + (hi - lo) * glm::vec3((float(i) + 0.5f) / float(a), (float(j) + 0.5f) / float(b), (float(k) + 0.5f) / float(c)));
    return p;
  }
  std::FILE* f = std::fopen(spec.c_str(), "r");
  if (!f) fail("--probes " + spec + ": not a grid like 8x4x8, and the file cannot be read: " + std::strerror(errno), 2);
  char line[1024];
  int number = 0;
  while (std::fgets(line, sizeof line, f)) {
    ++number;
    const char* t = line + std::strspn(line, " \t\r\n");
    if (*t == '#' || *t == '\0') continue;
    float x, y, z;
    char extra;
    if (std::sscanf(t, "%f %f %f %c", &x, &y, &z, &extra) != 3 || !std::isfinite(x + y + z)) {
      std::fclose(f);
      fail("--probes " + spec + ": line " + std::to_string(number) + " is not three finite numbers x y z", 2);
    }
    p.push_back({x, y, z});
  }
  std::fclose(f);
  if (p.empty()) fail("--probes " + spec + ": the file holds no points", 2);
  return p;
}

// NAME_probes.json: the probes (probes.hpp's basis and order), see the usage text.
void write_probes_json(const std::string& path, const std::vector<glm::vec3>& p, const probe_result& r, int resolution,
                       const int (&grid)[3], const glm::vec3& lo, const glm::vec3& hi) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) fail("cannot write '" + path + "': " + std::strerror(errno));
  std::fprintf(f, "{\n  \"format\": \"hemilight_probes\",\n  \"version\": 1,\n");
  std::fprintf(f, "  \"basis\": \"real SH, bands 0-2, world axes; sh9_rgb[3 k + c], k: (l,m) = (0,0) (1,-1) (1,0) (1,1) (2,-2) "
                  "(2,-1) (2,0) (2,1) (2,2); coefficient = integral of L Y_k d omega\",\n");
  std::fprintf(f, "  \"resolution\": %d,\n", resolution);
  if (grid[0] > 0)
    std::fprintf(f, "  \"grid\": [%d, %d, %d],\n  \"bounds\": {\"min\": [%.9g, %.9g, %.9g], \"max\": [%.9g, %.9g, %.9g]},\n", grid[0],
                 grid[1], grid[2], double(lo.x), double(lo.y), double(lo.z), double(hi.x), double(hi.y), double(hi.z));
  else
    std::fprintf(f, "  \"grid\": null,\n");
  std::fprintf(f, "  \"probes\": [\n");
  for (std::size_t i = 0; i < p.size(); ++i) {
    std::fprintf(f, "    {\"position\": [%.9g, %.9g, %.9g], \"backface_fraction\": %.6g, \"sh9_rgb\": [", double(p[i].x), double(p[i].y),
                 double(p[i].z), double(r.backface_fraction[i]));
    for (std::size_t k = 0; k < 9; ++k)
      for (int c = 0; c < 3; ++c) std::fprintf(f, "%s%.9g", k + std::size_t(c) ? ", " : "", double(r.probes[i][k][c]));
    std::fprintf(f, "]}%s\n", i + 1 < p.size() ? "," : "");
  }
  std::fprintf(f, "  ]\n}\n");
  if (std::fclose(f) != 0) fail("cannot write '" + path + "'");
}

// A model as the baker needs it (arrays owned here).
struct model {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> indices;
  std::vector<material> materials;
  std::vector<light> lights;
};

// A model's lights as lights.hpp's (see the top of this file for the mapping).
std::vector<light> model_lights(const aiScene* sc, const std::string& path) {
  std::vector<light> out;
  for (unsigned i = 0; i < sc->mNumLights; ++i) {
    const aiLight& a = *sc->mLights[i];
    light l;
    l.color = glm::max(glm::vec3(a.mColorDiffuse.r, a.mColorDiffuse.g, a.mColorDiffuse.b), glm::vec3(0.0f));
    l.position = {a.mPosition.x, a.mPosition.y, a.mPosition.z};
    l.direction = {a.mDirection.x, a.mDirection.y, a.mDirection.z};
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
        l.tangent = {a.mUp.x, a.mUp.y, a.mUp.z};
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

model load_model(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail("cannot read '" + path + "': no such file");
  Assimp::Importer importer;
  const aiScene* sc = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_GenNormals |
                                                  aiProcess_SortByPType);
  if (!sc || (sc->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !sc->mRootNode)
    fail("cannot read '" + path + "': " + importer.GetErrorString());
  model m;
  for (unsigned mi = 0; mi < sc->mNumMeshes; ++mi) {
    const aiMesh* mesh = sc->mMeshes[mi];
    if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;  // points and lines: nothing to light
    const std::string name = "'" + path + "' mesh " + std::to_string(mi) + " ('" + mesh->mName.C_Str() + "')";
    const unsigned channel = mesh->HasTextureCoords(1) ? 1u : 0u;
    if (!mesh->HasTextureCoords(channel)) fail(name + " has no texture coordinates to use as lightmap UVs");
    material mat;
    if (mesh->mMaterialIndex < sc->mNumMaterials) {
      const aiMaterial* am = sc->mMaterials[mesh->mMaterialIndex];
      aiColor3D c(0.8f, 0.8f, 0.8f);
      am->Get(AI_MATKEY_COLOR_DIFFUSE, c);
      mat.albedo = glm::clamp(glm::vec3(c.r, c.g, c.b), 0.0f, 1.0f);
      aiColor3D e(0.0f, 0.0f, 0.0f);
      am->Get(AI_MATKEY_COLOR_EMISSIVE, e);
      mat.emission = glm::max(glm::vec3(e.r, e.g, e.b), glm::vec3(0.0f));
      int two = 0;
      am->Get(AI_MATKEY_TWOSIDED, two);
      mat.two_sided = two != 0;
    }
    const auto base = std::uint32_t(m.positions.size());
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      const aiVector3D& t = mesh->mTextureCoords[channel][v];
      if (!(t.x >= 0.0f && t.x <= 1.0f && t.y >= 0.0f && t.y <= 1.0f))
        fail(name + " vertex " + std::to_string(v) + ": lightmap UV (" + std::to_string(t.x) + ", " + std::to_string(t.y) +
             ") is outside [0, 1]");
      m.positions.emplace_back(p.x, p.y, p.z);
      m.uvs.emplace_back(t.x, t.y);
      m.normals.push_back(mesh->HasNormals() ? glm::vec3(mesh->mNormals[v].x, mesh->mNormals[v].y, mesh->mNormals[v].z)
                                             : glm::vec3(0.0f));
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      const glm::vec2 a = m.uvs[base + face.mIndices[0]], b = m.uvs[base + face.mIndices[1]], c = m.uvs[base + face.mIndices[2]];
      const glm::vec3 pa = m.positions[base + face.mIndices[0]], pb = m.positions[base + face.mIndices[1]],
                      pc = m.positions[base + face.mIndices[2]];
      const float uv_area = std::fabs((b - a).x * (c - a).y - (b - a).y * (c - a).x);
      if (uv_area == 0.0f && glm::length(glm::cross(pb - pa, pc - pa)) > 0.0f)
        fail(name + " triangle " + std::to_string(f) + " has zero area in lightmap UV space");
      for (int k = 0; k < 3; ++k) m.indices.push_back(base + face.mIndices[k]);
      m.materials.push_back(mat);
    }
  }
  if (m.indices.empty()) fail("'" + path + "' has no triangles");
  m.lights = model_lights(sc, path);
  return m;
}

// The preview: exposure, Reinhard, sRGB, 8-bit PNG through libpng's simplified API.
void write_png_preview(const std::string& path, const bake_result& r) {
  const image& e = r.irradiance;
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < r.sampled.size(); ++k)
    if (r.sampled[k]) {
      sum += 0.2126 * e.pixels[3 * k] + 0.7152 * e.pixels[3 * k + 1] + 0.0722 * e.pixels[3 * k + 2];
      ++n;
    }
  const double mean = n ? sum / double(n) : 0.0;
  const double k = mean > 0.0 ? 0.5 / mean : 1.0;
  std::vector<unsigned char> rgb(e.pixels.size());
  for (std::size_t i = 0; i < e.pixels.size(); ++i) {
    const double x = std::max(0.0, double(e.pixels[i])) * k;
    const double t = x / (1.0 + x);
    const double s = t <= 0.0031308 ? 12.92 * t : 1.055 * std::pow(t, 1.0 / 2.4) - 0.055;
    rgb[i] = static_cast<unsigned char>(std::lround(std::clamp(s, 0.0, 1.0) * 255.0));
  }
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  img.width = png_uint_32(e.width);
  img.height = png_uint_32(e.height);
  img.format = PNG_FORMAT_RGB;
  if (!png_image_write_to_file(&img, path.c_str(), 0, rgb.data(), 0, nullptr))
    fail("cannot write '" + path + "': " + img.message);
}

// A progress bar on stderr with the time left (linear in the bake fraction).
struct progress_bar {
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  std::string label;
  bool quiet = false;
  int last_percent = -1;
  double last_draw = -1.0;
  bool operator()(float f) {
    if (quiet) return true;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // Redraw when the percentage changes, at most 10 times a second.
    const int percent = int(f * 100.0f);
    if (percent == last_percent || (elapsed - last_draw < 0.1 && percent < 100)) return true;
    last_percent = percent;
    last_draw = elapsed;
    const int width = 30, filled = int(std::lround(std::clamp(f, 0.0f, 1.0f) * width));
    std::string bar(std::size_t(filled), '#');
    bar.append(std::size_t(width - filled), '.');
    char left[32] = "  ?";
    if (f > 0.02f) std::snprintf(left, sizeof left, "%5.1f s", elapsed * (1.0 - f) / f);
    std::fprintf(stderr, "\r%-14s [%s] %3d%%  left %s ", label.c_str(), bar.c_str(), percent, left);
    std::fflush(stderr);
    bar_open = true;
    return true;
  }
};

void bake_and_write(const std::string& name, const bake_input& in, const settings& s, const std::vector<light>& scene_lights) {
  bake_options o = s.options;
  o.lights.insert(o.lights.end(), scene_lights.begin(), scene_lights.end());
  if (s.shadow_mask)
    for (std::size_t c = 0; c < 4 && c < o.lights.size(); ++c) o.shadow_mask_lights[c] = int(c);
  progress_bar bar;
  bar.label = name;
  bar.quiet = s.quiet;
  o.progress = [&bar](float f) { return bar(f); };
  const bake_result r = bake_lightmap(in, o);
  if (bar_open) std::fprintf(stderr, "\n");
  bar_open = false;
  const std::string base = s.out + "/" + name;
  const std::vector<std::string> written = write_bake_exrs(r, base);
  write_png_preview(base + "_irradiance.png", r);
  const bake_stats& st = r.stats;
  std::printf("%s: %zu triangles, %d x %d lightmap, N = %d, %d bounce%s%s, %d threads\n", name.c_str(), in.scene.triangle_count,
              o.width, o.height, o.resolution, o.bounces, o.bounces > 1 ? "s" : "", o.indirect_only ? " (indirect only)" : "",
              resolve_thread_count(o.thread_count));
  std::printf("  texels: %zu sampled of %zu covered, %zu invalid (inside geometry), %zu dilated, %zu overlapping\n",
              st.sampled_texels, st.covered_texels, st.invalid_texels, st.dilated_texels, st.overlapping_texels);
  for (std::size_t p = 0; p < st.passes.size(); ++p)
    std::printf("  pass %zu: %zu hemicubes (%.1f%% of sampled texels), %zu records, %.2f s\n", p + 1, st.passes[p].hemicubes,
                100.0 * double(st.passes[p].hemicubes) / double(st.sampled_texels), st.passes[p].records, st.passes[p].seconds);
  std::string suffixes;
  for (const std::string& w : written) suffixes += w.substr(base.size() + 1) + ",";
  if (!o.lights.empty())
    std::printf("  %zu light%s: direct light %.2f s\n", o.lights.size(), o.lights.size() > 1 ? "s" : "", st.direct_seconds);
  std::printf("  total %.2f s (coverage %.3f s); wrote %s_{%sirradiance.png}\n", st.seconds, st.coverage_seconds, base.c_str(),
              suffixes.c_str());
  if (s.probes.empty()) return;
  // Probes that see the baked surfaces (emission + albedo E / pi), the sky and the lights.
  const auto t0 = std::chrono::steady_clock::now();
  const std::shared_ptr<const scene> sc = scene::create(in.scene);
  int grid[3] = {0, 0, 0};
  const std::vector<glm::vec3> points = probe_positions(s.probes, sc->bounds_lo(), sc->bounds_hi(), grid);
  const image texture = bake_radiance_texture(in, o, r);
  const radiance_texture view(texture);
  probe_options po;
  po.resolution = o.resolution;
  po.thread_count = o.thread_count;
  po.sky = o.environment;
  po.texture = &view;
  if (!o.lights.empty()) po.lights = std::make_shared<const light_set>(o.lights.data(), o.lights.size());
  const probe_result pr = sample_probes(sc, points.data(), points.size(), po);
  write_probes_json(base + "_probes.json", points, pr, o.resolution, grid, sc->bounds_lo(), sc->bounds_hi());
  std::size_t inside = 0;
  for (float b : pr.backface_fraction) inside += b > 0.1f ? 1 : 0;
  std::printf("  %zu probes (%zu inside geometry: back-face fraction > 0.1), %.2f s; wrote %s_probes.json\n", points.size(), inside,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), base.c_str());
}

void run_scenes(const settings& s);

void run(const settings& s) {
  std::error_code ec;
  std::filesystem::create_directories(s.out, ec);
  if (!std::filesystem::is_directory(s.out, ec)) fail("cannot create the output directory '" + s.out + "'");
  settings with_env = s;
  if (!s.environment.empty()) {
    if (!std::filesystem::is_regular_file(s.environment, ec)) fail("cannot read '" + s.environment + "': no such file");
    with_env.options.environment = std::make_shared<const cubemap>(cubemap::from_image(read_exr_cubemap(s.environment, 3), false));
  }
  run_scenes(with_env);
}

void run_scenes(const settings& s) {
  if (s.model.empty()) {
    // Built-in scenes: chart UVs generated for the lightmap size (2 texels of padding).
    const struct {
      const char* name;
      lit_scene scene;
    } scenes[] = {{"hexagon_room", {hexagon_room(2), {}}},
                  {"hexagon_room_sun", hexagon_room_sunlit(2)},
                  {"cornell_box", {cornell_box(), {}}},
                  {"cornell_box_rect", cornell_box_rect_light()}};
    for (const auto& sc : scenes) {
      scene_mesh m = sc.scene.mesh;
      generate_lightmap_uvs(m, std::max(8, s.options.width), std::max(8, s.options.width) >= 16 ? 2 : 0);
      bake_input in;
      in.scene = m.desc();
      bake_and_write(sc.name, in, s, sc.scene.lights);
    }
    return;
  }
  if (s.options.width < 1 || s.options.width > max_lightmap_size) fail("--size is out of range");
  model m = load_model(s.model);
  bake_input in;
  in.scene.positions = m.positions.data();
  in.scene.vertex_count = m.positions.size();
  in.scene.indices = m.indices.data();
  in.scene.triangle_count = m.indices.size() / 3;
  in.scene.materials = m.materials.data();
  in.scene.lightmap_uvs = m.uvs.data();
  in.scene.sky_radiance = s.sky;
  in.normals = m.normals.data();
  std::string name = std::filesystem::path(s.model).stem().string();
  if (name.empty()) name = "model";
  if (!m.lights.empty()) std::printf("%s: %zu light%s from the model\n", name.c_str(), m.lights.size(), m.lights.size() > 1 ? "s" : "");
  bake_and_write(name, in, s, m.lights);
}

}  // namespace

// One line on stderr for every failure (after ending a progress line, if one is open).
int report(const char* message, int code) {
  std::fprintf(stderr, "%shemilight_bake: %s\n", bar_open ? "\n" : "", message);
  return code;
}

int main(int argc, char** argv) {
  try {
    run(parse(argc, argv));
    return 0;
  } catch (const cli_error& e) {
    return report(e.message.c_str(), e.code);
  } catch (const std::exception& e) {
    return report(e.what(), 1);
  }
}
