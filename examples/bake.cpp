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
// NAME_hl2_{0..2}.exr (Half-Life 2 basis in the lightmap tangent frame; bake.hpp), with --ao D
// NAME_ao.exr (ambient occlusion within D scene units, the same value in R, G and B). Shows a
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
// Models (model_import.hpp): read with assimp, every node's meshes with its transform (instances
// included), normals generated when missing. Lightmap UVs are UV channel 1 (glTF TEXCOORD_1;
// --lightmap-uv 0 for files with one UV set, like OBJ). When a mesh lacks that channel (or with
// --generate-uvs) the whole model gets lightmap UVs from unwrap.hpp (pages of --size, at the density
// that fills one page or at --texels-per-unit), said in one line, and the model with them is
// written as NAME_lightmap_uvs.glb (TEXCOORD_1), for the engine to render with. UVs up to 0.001
// outside [0, 1] are clamped; degenerate triangles are skipped; a triangle with 3D area but no UV
// area occludes without texels and is named in a warning (an error with --strict); the statistics
// count each. Material:
// base colour (glTF baseColorFactor x baseColorTexture, or Kd x map_Kd) = albedo (clamped to
// [0, 1]), emissive colour x emissive texture = emitted radiance, two-sided flag; textures are
// decoded by stb_image and averaged over each lightmap texel's footprint into per-page albedo and
// emission images (bake_scene). A texture that cannot be read (missing, undecodable) is an error
// naming the material and the file, also when only its alpha is wanted. Opacity (glTF; the rules
// in model_import.hpp): alphaMode MASK is alpha-tested (the base colour alpha factor, alphaCutoff,
// the base colour texture's alpha channel read at its TEXCOORD set), BLEND translucent (1 - alpha),
// KHR_materials_transmission translucent (factor x base colour); one line lists the see-through
// materials; --ignore-opacity bakes them opaque. All meshes share one
// lightmap page, except instances: instance k of a mesh is baked into page k (NAME_pageK_*).
// The sky (constant radiance) is --sky.
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
#include "hemilight/seams.hpp"
#include "hemilight/shards.hpp"

#include "model_export.hpp"
#include "model_import.hpp"
#include "preview.hpp"
#include "shard_files.hpp"


#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

const char* usage =
    "usage: hemilight_bake [MODEL] [options]\n"
    "  With no MODEL: bakes the built-in hexagon room (lit by the sky through a window) and the\n"
    "  Cornell box. With MODEL (glTF, FBX, OBJ or another format assimp reads): bakes its\n"
    "  lightmap UVs (UV channel 1, see --lightmap-uv; made when missing, see --generate-uvs) with its\n"
    "  textures.\n"
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
    "  --ao D             also write NAME_ao.exr: ambient occlusion within D scene units (> 0), the\n"
    "                     cosine-weighted unoccluded fraction of each texel's hemisphere, 1 = open,\n"
    "                     0 = fully occluded, from the first bounce's hemicubes (docs/bake.md)\n"
    "  --probes P         also write NAME_probes.json: SH9 light probes (probes.hpp) that see the\n"
    "                     baked surfaces, at the centres of an AxBxC grid over the scene's bounds\n"
    "                     (P like 8x4x8) or at the points of a text file (x y z per line, # comments)\n"
    "  --preview [CAMERA] also write NAME_preview.png: the baked scene rendered (lightmap x albedo +\n"
    "                     emission, bilinear) from CAMERA = EX,EY,EZ,TX,TY,TZ[,FOV] (eye, target, field\n"
    "                     of view in degrees, (0, 90], default 60) or a view chosen from the scene's\n"
    "                     bounds; built-in scenes always get one\n"
    "  --lightmap-uv C    the model's UV channel holding the lightmap UVs, 0..7 (default 1: glTF's\n"
    "                     TEXCOORD_1; OBJ files have only channel 0)\n"
    "  --generate-uvs     make new lightmap UVs for the whole model (done anyway when a mesh has none):\n"
    "                     charts packed into pages of --size; also writes NAME_lightmap_uvs.glb\n"
    "  --texels-per-unit D  with generated UVs: D texels per scene unit, spilling into several pages\n"
    "                     (default: the density that fills one page)\n"
    "  --strict           a triangle with 3D area but no lightmap UV area is an error (default: a\n"
    "                     warning; it still casts shadows)\n"
    "  --ignore-opacity   bake glTF alpha-tested (MASK) and translucent (BLEND, transmission) materials\n"
    "                     as opaque (default: they let light through; a texture that cannot be read is\n"
    "                     an error naming the material and the file, for its alpha too)\n"
    "  --no-stitch-seams  leave the seams as baked (default: texels along seams between near-coplanar\n"
    "                     faces set so that both sides agree under bilinear filtering; docs/bake.md)\n"
    "  --shards S         bake through S shards (1..4096): the sharded bake's jobs and merges in this\n"
    "                     process (tools/dask_bake.py runs them on a Dask cluster, the same bits)\n"
    "  --shard I/S --pass K  one job of a sharded bake: shard I (0-based) of S of pass K (1-based);\n"
    "                     reads OUT/NAME_pass{K-1}.{exr,json} for K > 1, writes\n"
    "                     OUT/NAME_pass{K}_shard{I}of{S}.{exr,json} (docs/distributed.md)\n"
    "  --merge K          with --shards S: merges pass K's shards (and pass 1's); writes\n"
    "                     OUT/NAME_pass{K}.{exr,json} for the next pass, or the bake's files after the last\n"
    "  --quiet            no progress bar\n"
    "  --help             this text\n";

// The seams' line: what stitching did and the step left along the seams (measure_seams).
void print_seams(const scene_bake_input& in, const scene_bake_result& sr, const bake_stats& st) {
  const seam_report r = measure_seams(in, sr);
  if (r.coplanar.pieces + r.walled.pieces == 0) return;
  if (st.seam_texels > 0) std::printf("  seams: %zu texels stitched, %.2f s\n", st.seam_texels, st.stitch_seconds);
  std::printf("  seam step (bilinear, near-coplanar seams, %.0f texels long): RMS %.2f%%, p95 %.2f%%, max %.2f%%", r.coplanar.length_texels,
              100.0 * r.coplanar.rms, 100.0 * r.coplanar.p95, 100.0 * r.coplanar.max);
  if (r.walled.pieces > 0) std::printf("; %.0f texels under walls, not stitched", r.walled.length_texels);
  if (r.hidden_length_texels > 0.0) std::printf("; %.0f texels with a side inside geometry, not counted", r.hidden_length_texels);
  std::printf("\n");
}

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
  unsigned lightmap_uv = 1;  // --lightmap-uv: the model's UV channel holding the lightmap UVs
  bool ignore_opacity = false;  // --ignore-opacity: every material opaque
  bool generate_uvs = false; // --generate-uvs (also when a mesh has no lightmap UVs)
  float texels_per_unit = 0.0f;  // --texels-per-unit: generated UVs' density (0: fill one page)
  bool preview = false;      // --preview: a rendered picture of each baked model (built-in scenes: always)
  bool has_camera = false;   // --preview EX,EY,EZ,TX,TY,TZ[,FOV]
  preview::camera camera;
  std::string probes;  // --probes: "AxBxC" or a file of points; empty: none
  // Sharded bakes (shards.hpp): --shards S alone bakes through S shards in this process;
  // --shard I/S --pass K runs one job; --merge K --shards S merges pass K.
  int shards = 0;       // 0: not sharded
  int shard = -1;       // --shard I/S: I (-1: no job)
  int pass = 0;         // --pass K (with --shard)
  int merge = 0;        // --merge K (0: no merge)
};

// "a,b,c,d[,e]": 4 or 5 finite numbers.
std::vector<float> parse_list(const std::string& name, const std::string& text, const char* form) {
  std::vector<float> v;
  if (!preview::parse_numbers(text, v) || v.size() < 4 || v.size() > 5) fail(name + " " + text + " is invalid: it must be " + form, 2);
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
      s.options.sampler.resolution = parse_int("--resolution", value(), 2, 4096);
      if (s.options.sampler.resolution % 2) fail("--resolution " + std::to_string(s.options.sampler.resolution) + " is invalid: it must be even", 2);
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
    } else if (a == "--ao") {
      s.options.ao_distance = parse_float("--ao", value(), 0.0f, 1e18f, true);
    } else if (a == "--probes") {
      s.probes = value();
    } else if (a == "--preview") {
      s.preview = true;
      // An optional camera: the next argument if it reads as one (a model path does not).
      if (i + 1 < argc && argv[i + 1][0] != '-') {
        preview::camera cam;
        if (preview::parse_camera(argv[i + 1], cam)) {
          s.camera = cam;
          s.has_camera = true;
          ++i;
        } else if (std::strchr(argv[i + 1], ',')) {
          fail(std::string("--preview ") + argv[i + 1] + " is invalid: the camera is EX,EY,EZ,TX,TY,TZ[,FOV] with FOV in (0, 90] "
               "degrees and the eye away from the target", 2);
        }
      }
    } else if (a == "--lightmap-uv") {
      s.lightmap_uv = unsigned(parse_int("--lightmap-uv", value(), 0, 7));
    } else if (a == "--generate-uvs") {
      s.generate_uvs = true;
    } else if (a == "--texels-per-unit") {
      s.texels_per_unit = parse_float("--texels-per-unit", value(), 0.0f, 1e6f, true);
    } else if (a == "--strict") {
      s.options.strict = true;
    } else if (a == "--ignore-opacity") {
      s.ignore_opacity = true;
    } else if (a == "--no-stitch-seams") {
      s.options.stitch_seams = false;
    } else if (a == "--quiet") {
      s.quiet = true;
    } else if (a == "--shards") {
      const int n = parse_int("--shards", value(), 1, max_bake_shards);
      if (s.shards != 0 && s.shards != n) fail("--shards " + std::to_string(n) + " disagrees with --shard's count " + std::to_string(s.shards), 2);
      s.shards = n;
    } else if (a == "--shard") {
      const std::string v = value();
      int index = -1, n = 0;
      char tail;
      if (std::sscanf(v.c_str(), "%d/%d%c", &index, &n, &tail) != 2 || n < 1 || n > max_bake_shards || index < 0 || index >= n)
        fail("--shard " + v + " is invalid: it must be I/S with 0 <= I < S <= " + std::to_string(max_bake_shards), 2);
      if (s.shards != 0 && s.shards != n) fail("--shard " + v + " disagrees with --shards " + std::to_string(s.shards), 2);
      s.shard = index;
      s.shards = n;
    } else if (a == "--pass") {
      s.pass = parse_int("--pass", value(), 1, 64);
    } else if (a == "--merge") {
      s.merge = parse_int("--merge", value(), 1, 64);
    } else if (a.size() > 1 && a[0] == '-') {
      fail("unknown option " + a + " (see --help)", 2);
    } else if (s.model.empty()) {
      s.model = a;
    } else {
      fail("more than one model given: " + s.model + " and " + a, 2);
    }
  }
  if (s.shard >= 0 && s.pass == 0) fail("--shard needs --pass K (the pass the job computes)", 2);
  if (s.pass > 0 && s.shard < 0) fail("--pass needs --shard I/S", 2);
  if (s.merge > 0 && (s.shard >= 0 || s.shards == 0)) fail("--merge K needs --shards S and no --shard", 2);
  if (std::max(s.pass, s.merge) > s.options.bounces)
    fail((s.merge > 0 ? "--merge " + std::to_string(s.merge) : "--pass " + std::to_string(s.pass)) + " is past the last pass (--bounces " +
             std::to_string(s.options.bounces) + ")", 2);
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

// A model as bake_scene needs it: the imported meshes concatenated (arrays owned here), each a
// mesh of the scene bake on the page of its instance (model_import.hpp).
struct scene_arrays {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> indices;
  std::vector<material> materials;
  std::vector<glm::vec2> texcoords;            // where alpha textures are read (when a material has one)
  std::vector<alpha_texture> alpha_textures;   // views of the model's
};

scene_bake_input model_scene(const model_import::model& m, const settings& s, scene_arrays& a) {
  scene_bake_input in;
  const bool alpha_textured = std::any_of(m.meshes.begin(), m.meshes.end(), [&](const model_import::mesh& me) {
    return m.materials[me.material].alpha_texture >= 0;
  });
  for (const model_import::mesh& me : m.meshes) {
    bake_mesh bm;
    bm.first_triangle = a.indices.size() / 3;
    bm.triangle_count = me.indices.size() / 3;
    bm.page = me.page;
    in.meshes.push_back(bm);
    const auto base = std::uint32_t(a.positions.size());
    a.positions.insert(a.positions.end(), me.positions.begin(), me.positions.end());
    a.normals.insert(a.normals.end(), me.normals.begin(), me.normals.end());
    a.uvs.insert(a.uvs.end(), me.lightmap_uvs.begin(), me.lightmap_uvs.end());
    for (std::uint32_t i : me.indices) a.indices.push_back(base + i);
    const material flat = m.materials[me.material].flat(m.textures);
    a.materials.insert(a.materials.end(), me.indices.size() / 3, flat);
    if (!alpha_textured) continue;
    std::vector<glm::vec2> tc = model_import::mesh_texcoords(m, me);  // empty: its material reads no alpha texture
    tc.resize(me.positions.size(), glm::vec2(0.0f));
    a.texcoords.insert(a.texcoords.end(), tc.begin(), tc.end());
  }
  for (const alpha_image& t : m.alpha_textures) a.alpha_textures.push_back({t.values.data(), t.width, t.height});
  in.geometry.scene.texcoords = alpha_textured ? a.texcoords.data() : nullptr;
  in.geometry.scene.alpha_textures = a.alpha_textures.empty() ? nullptr : a.alpha_textures.data();
  in.geometry.scene.alpha_texture_count = a.alpha_textures.size();
  in.geometry.scene.positions = a.positions.data();
  in.geometry.scene.vertex_count = a.positions.size();
  in.geometry.scene.indices = a.indices.data();
  in.geometry.scene.triangle_count = a.indices.size() / 3;
  in.geometry.scene.materials = a.materials.data();
  in.geometry.scene.lightmap_uvs = a.uvs.data();
  in.geometry.scene.sky_radiance = s.sky;
  in.geometry.normals = a.normals.data();
  for (int p = 0; p < m.pages; ++p) {
    lightmap_page page;
    page.width = s.options.width;
    page.height = s.options.height;
    model_import::page_images images = model_import::bake_page_materials(m, p, page.width, page.height);
    page.albedo = std::move(images.albedo);
    page.emission = std::move(images.emission);
    in.pages.push_back(std::move(page));
  }
  return in;
}

// The atlas preview: preview::write_png's tone mapping, exposed for the mean over sampled texels.
void write_png_preview(const std::string& path, const bake_result& r) {
  const image& e = r.irradiance;
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < r.sampled.size(); ++k)
    if (r.sampled[k]) {
      sum += 0.2126 * e.pixels[3 * k] + 0.7152 * e.pixels[3 * k + 1] + 0.0722 * e.pixels[3 * k + 2];
      ++n;
    }
  try {
    preview::write_png(path, e, n ? sum / double(n) : 0.0);
  } catch (const std::runtime_error& err) {
    fail(err.what());
  }
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

// The input the bake went past, in one line each: the degenerate triangles it skipped, and its
// warnings (triangles without UV area, clamped UVs), with meshes[i] named as the model names it.
void print_skipped_input(const bake_stats& st, const std::vector<std::string>& mesh_names) {
  if (st.degenerate_triangles > 0)
    std::printf("  skipped %zu degenerate triangle%s (no area at float precision: no texels, no shadows)\n", st.degenerate_triangles,
                st.degenerate_triangles > 1 ? "s" : "");
  for (const std::string& w : st.warnings) {
    std::string line = w;
    const std::size_t at = line.find("meshes[");
    if (at != std::string::npos) {
      const std::size_t i = std::size_t(std::strtoul(line.c_str() + at + 7, nullptr, 10));
      if (i < mesh_names.size()) line += " (meshes[" + std::to_string(i) + "] is " + mesh_names[i] + ")";
    }
    std::printf("  warning: %s\n", line.c_str());
  }
}

// The bake, plain or sharded (settings: shards, shard, pass, merge). A job (--shard I/S --pass K)
// writes its shard's files; a merge of pass K < bounces writes the state for pass K + 1; both
// print one line and return nothing. The merge of the last pass and --shards S alone return the
// bake's result, written as a plain bake's.
std::optional<scene_bake_result> run_bake(const std::string& name, const std::string& base, const scene_bake_input& in,
                                          const bake_options& o, const settings& s) {
  if (s.shards == 0) return bake_scene(in, o);
  if (s.shard < 0 && s.merge == 0) return bake_scene_sharded(in, o, s.shards);
  const auto t0 = std::chrono::steady_clock::now();
  // Each file is checked against this bake as it is read, so that a refusal names the file (the
  // library checks the same again, and the rest: sizes, channels).
  const std::uint64_t key = bake_key(in, o);
  const auto foreign = [&](const std::string& file, std::uint64_t k) {
    fail(file + " was made by another bake (another scene or options: key " + shard_files::key_text(k) + ", this bake's " +
         shard_files::key_text(key) + ")");
  };
  const auto read_shard = [&](int pass, int i) {
    const std::string stem = shard_files::shard_stem(base, pass, i, s.shards);
    bake_shard_result r = shard_files::read_shard(stem);
    if (r.key != key) foreign(stem + ".json", r.key);
    if (r.pass != pass || r.shard != i || r.shard_count != s.shards)
      fail(stem + ".json holds shard " + std::to_string(r.shard) + " of " + std::to_string(r.shard_count) + " of pass " +
           std::to_string(r.pass));
    return r;
  };
  const auto read_state = [&](int pass) {
    const std::string stem = shard_files::state_stem(base, pass);
    bake_pass_state st = shard_files::read_state(stem);
    if (st.key != key) foreign(stem + ".json", st.key);
    if (st.pass != pass || st.shard_count != s.shards)
      fail(stem + ".json is the state after pass " + std::to_string(st.pass) + " of " + std::to_string(st.shard_count) + " shards");
    return st;
  };
  if (s.shard >= 0) {
    std::optional<bake_pass_state> previous;
    if (s.pass > 1) previous = read_state(s.pass - 1);
    const bake_shard_result r = bake_scene_shard(in, o, s.shard, s.shards, s.pass, previous ? &*previous : nullptr);
    const std::string stem = shard_files::shard_stem(base, s.pass, s.shard, s.shards);
    shard_files::write_shard(stem, name, r);
    if (bar_open) std::fprintf(stderr, "\n");
    bar_open = false;
    std::printf("%s: pass %d shard %d of %d: %zu samples, %zu hemicubes, %.2f s; wrote %s.{exr,json}\n", name.c_str(), s.pass, s.shard,
                s.shards, r.sample_count, r.hemicubes, r.seconds, stem.c_str());
    return std::nullopt;
  }
  // A merge: pass K's shards, pass 1's (their lights and AO), the state after pass K - 1.
  const auto read_pass = [&](int pass) {
    std::vector<bake_shard_result> shards;
    for (int i = 0; i < s.shards; ++i) shards.push_back(read_shard(pass, i));
    return shards;
  };
  const std::vector<bake_shard_result> these = read_pass(s.merge);
  const std::vector<bake_shard_result> first = s.merge == 1 ? these : read_pass(1);
  std::optional<bake_pass_state> previous;
  if (s.merge > 1) previous = read_state(s.merge - 1);
  const bake_pass_state* prev = previous ? &*previous : nullptr;
  if (s.merge == o.bounces) return finish_sharded_bake(in, o, these.data(), these.size(), first.data(), prev);
  const bake_pass_state state = merge_bake_pass(in, o, s.merge, these.data(), these.size(), first.data(), prev);
  const std::string stem = shard_files::state_stem(base, s.merge);
  shard_files::write_state(stem, name, state);
  std::size_t hemicubes = 0;
  for (const bake_shard_result& r : these) hemicubes += r.hemicubes;
  std::printf("%s: pass %d merged from %d shards (%zu hemicubes), %.2f s; wrote %s.{exr,json}\n", name.c_str(), s.merge, s.shards,
              hemicubes, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), stem.c_str());
  return std::nullopt;
}

void bake_and_write(const std::string& name, const scene_bake_input& in, const settings& s, const std::vector<light>& scene_lights,
                    const std::vector<std::string>& mesh_names = {}) {
  bake_options o = s.options;
  o.lights.insert(o.lights.end(), scene_lights.begin(), scene_lights.end());
  if (s.shadow_mask)
    for (std::size_t c = 0; c < 4 && c < o.lights.size(); ++c) o.shadow_mask_lights[c] = int(c);
  if (!s.probes.empty() && in.pages.size() > 1)
    fail("--probes needs a model baked into one lightmap page; '" + s.model + "' has instanced meshes (" +
         std::to_string(in.pages.size()) + " pages)", 2);
  progress_bar bar;
  bar.label = name;
  bar.quiet = s.quiet;
  o.progress = [&bar](float f) { return bar(f); };
  const std::string base = s.out + "/" + name;
  const std::optional<scene_bake_result> baked = run_bake(name, base, in, o, s);
  if (bar_open) std::fprintf(stderr, "\n");
  bar_open = false;
  if (!baked) return;  // a job, or the merge of a pass before the last: its files are written
  const scene_bake_result& sr = *baked;
  // Page 0 keeps the names of a one-lightmap bake (NAME_irradiance.exr ...); page p > 0 is NAME_pageP_*.
  const auto page_base = [&](std::size_t p) { return p == 0 ? base : base + "_page" + std::to_string(p); };
  std::string suffixes;
  for (std::size_t p = 0; p < sr.pages.size(); ++p) {
    const std::vector<std::string> written = write_bake_exrs(sr.pages[p], page_base(p));
    write_png_preview(page_base(p) + "_irradiance.png", sr.pages[p]);
    if (p == 0)
      for (const std::string& w : written) suffixes += w.substr(base.size() + 1) + ",";
  }
  std::string preview_line;
  if (s.preview || s.model.empty()) {
    const std::vector<image> radiance = preview::page_radiance(in, sr);
    const preview::camera cam = s.has_camera ? s.camera : preview::default_camera(in, radiance);
    preview::write_png(base + "_preview.png", preview::render(in, radiance, cam, 512));
    char line[256];
    std::snprintf(line, sizeof line, "  preview from (%.3g, %.3g, %.3g) towards (%.3g, %.3g, %.3g), %.3g degrees: %s_preview.png\n",
                  double(cam.eye.x), double(cam.eye.y), double(cam.eye.z), double(cam.target.x), double(cam.target.y),
                  double(cam.target.z), double(cam.fov_degrees), base.c_str());
    preview_line = line;
  }
  const bake_stats& st = sr.stats;
  std::printf("%s: %zu triangles, %zu page%s of %d x %d, N = %d, %d bounce%s%s, %d threads\n", name.c_str(),
              in.geometry.scene.triangle_count, sr.pages.size(), sr.pages.size() > 1 ? "s" : "", o.width, o.height, o.sampler.resolution,
              o.bounces, o.bounces > 1 ? "s" : "", o.indirect_only ? " (indirect only)" : "", resolve_thread_count(o.thread_count));
  const bool textured = std::any_of(in.pages.begin(), in.pages.end(), [](const lightmap_page& p) { return p.albedo.width > 0 || p.emission.width > 0; });
  if (textured) std::printf("  per-texel albedo/emission from the model's textures\n");
  std::printf("  texels: %zu sampled of %zu covered, %zu invalid (inside geometry), %zu dilated, %zu overlapping\n",
              st.sampled_texels, st.covered_texels, st.invalid_texels, st.dilated_texels, st.overlapping_texels);
  print_skipped_input(st, mesh_names);
  for (std::size_t p = 0; p < st.passes.size(); ++p)
    std::printf("  pass %zu: %zu hemicubes (%.1f%% of sampled texels), %zu records, %.2f s\n", p + 1, st.passes[p].hemicubes,
                100.0 * double(st.passes[p].hemicubes) / double(st.sampled_texels), st.passes[p].records, st.passes[p].seconds);
  if (!o.lights.empty())
    std::printf("  %zu light%s: direct light %.2f s\n", o.lights.size(), o.lights.size() > 1 ? "s" : "", st.direct_seconds);
  if (o.ao_distance > 0.0f) {
    double sum = 0.0;
    float lowest = 1.0f;
    std::size_t n = 0;
    for (const bake_result& page : sr.pages)
      for (std::size_t k = 0; k < page.sampled.size(); ++k)
        if (page.sampled[k]) {
          sum += double(page.ao.pixels[3 * k]);
          lowest = std::min(lowest, page.ao.pixels[3 * k]);
          ++n;
        }
    std::printf("  ambient occlusion within %g: mean %.3f, lowest %.3f over the sampled texels\n", double(o.ao_distance),
                n ? sum / double(n) : 0.0, double(lowest));
  }
  print_seams(in, sr, st);
  std::printf("  total %.2f s (coverage %.3f s); wrote %s_{%sirradiance.png}%s\n", st.seconds, st.coverage_seconds, base.c_str(),
              suffixes.c_str(), sr.pages.size() > 1 ? (" and the same for pages 1.." + std::to_string(sr.pages.size() - 1) + " (" + base + "_pageP_*)").c_str() : "");
  std::fputs(preview_line.c_str(), stdout);
  if (s.probes.empty()) return;
  // Probes that see the baked surfaces (emission + albedo E / pi), the sky and the lights.
  const auto t0 = std::chrono::steady_clock::now();
  const std::shared_ptr<const scene> sc = scene::create(in.geometry.scene);
  int grid[3] = {0, 0, 0};
  const std::vector<glm::vec3> points = probe_positions(s.probes, sc->bounds_lo(), sc->bounds_hi(), grid);
  const image texture = bake_radiance_texture(in.geometry, o, sr.pages[0]);
  const radiance_texture view(texture);
  probe_options po;
  po.resolution = o.sampler.resolution;
  po.thread_count = o.thread_count;
  po.raster.sky = o.sampler.raster.sky;
  po.texture = &view;
  if (!o.lights.empty()) po.lights = std::make_shared<const light_set>(o.lights.data(), o.lights.size());
  const probe_result pr = sample_probes(sc, points.data(), points.size(), po);
  write_probes_json(base + "_probes.json", points, pr, o.sampler.resolution, grid, sc->bounds_lo(), sc->bounds_hi());
  std::size_t inside = 0;
  for (float b : pr.backface_fraction) inside += b > 0.1f ? 1 : 0;
  std::printf("  %zu probes (%zu inside geometry: back-face fraction > 0.1), %.2f s; wrote %s_probes.json\n", points.size(), inside,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), base.c_str());
}

// Lightmap UVs for the whole model (unwrap.hpp) when a mesh has none or --generate-uvs asks: its
// meshes' world positions unwrapped as one, into pages of --size (at --texels-per-unit, or the
// density that fills one page); the model takes the new vertices and pages; the model with its new
// UVs is written as OUT/NAME_lightmap_uvs.glb. One line says why and what was made.
void generate_model_uvs(model_import::model& m, const settings& s, const std::string& name) {
  if (!s.generate_uvs)
    std::printf("%s: %zu of %zu meshes have no lightmap UVs (UV channel %u), e.g. %s: generating lightmap UVs for the whole model\n",
                name.c_str(), m.without_lightmap_uvs.size(), m.meshes.size(), s.lightmap_uv, m.without_lightmap_uvs[0].c_str());
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
  for (const model_import::mesh& me : m.meshes) {
    const auto base = std::uint32_t(positions.size());
    positions.insert(positions.end(), me.positions.begin(), me.positions.end());
    for (std::uint32_t i : me.indices) indices.push_back(base + i);
  }
  unwrap_options o;
  o.page_size = s.options.width;
  o.padding = s.options.width >= 16 ? 2 : 0;
  o.texels_per_unit = s.texels_per_unit;
  o.max_pages = 4096;
  o.thread_count = s.options.thread_count;
  if (o.page_size < 16 || s.options.height != s.options.width)
    fail("--generate-uvs needs square pages of at least 16 texels (--size)", 2);
  const unwrap_result r = unwrap_lightmap(positions.data(), positions.size(), indices.data(), indices.size() / 3, o);
  model_import::apply_lightmap_uvs(m, r);
  const std::string glb = s.out + "/" + name + "_lightmap_uvs.glb";
  try {
    model_export::write_glb(m, glb);
  } catch (const std::runtime_error& e) {
    fail(e.what());
  }
  const unwrap_stats& st = r.stats;
  std::printf("%s: lightmap UVs: %zu charts (%zu planar), %d page%s of %d x %d at %.4g texels per unit, %.1f%% of the pages' area, "
              "stretch %.3f (L2) %.3f (max), %.2f s; wrote %s\n",
              name.c_str(), st.charts, st.planar_charts, st.pages, st.pages > 1 ? "s" : "", o.page_size, o.page_size,
              double(st.texels_per_unit), 100.0 * st.uv_area_fraction, st.stretch_l2, st.stretch_linf, st.seconds, glb.c_str());
}

void run_scenes(const settings& s);

void run(const settings& s) {
  std::error_code ec;
  std::filesystem::create_directories(s.out, ec);
  if (!std::filesystem::is_directory(s.out, ec)) fail("cannot create the output directory '" + s.out + "'");
  settings with_env = s;
  if (!s.environment.empty()) {
    if (!std::filesystem::is_regular_file(s.environment, ec)) fail("cannot read '" + s.environment + "': no such file");
    with_env.options.sampler.raster.sky = std::make_shared<const cubemap>(cubemap::from_image(read_exr_cubemap(s.environment, 3), false));
  }
  run_scenes(with_env);
}

void run_scenes(const settings& s) {
  if (s.model.empty()) {
    // Built-in scenes: chart UVs generated for the lightmap size (2 texels of padding); one page,
    // one mesh (bitwise what bake_lightmap gives).
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
      scene_bake_input in;
      in.geometry.scene = m.desc();
      lightmap_page page;
      page.width = s.options.width;
      page.height = s.options.height;
      in.pages.push_back(page);
      bake_mesh all;
      all.triangle_count = m.triangle_count();
      all.page = 0;
      in.meshes.push_back(all);
      bake_and_write(sc.name, in, s, sc.scene.lights);
    }
    return;
  }
  if (s.options.width < 1 || s.options.width > max_lightmap_size) fail("--size is out of range");
  model_import::model m;
  try {
    model_import::import_options io;
    io.lightmap_channel = s.lightmap_uv;
    io.allow_missing_lightmap_uvs = true;
    io.strict = s.options.strict;
    io.ignore_opacity = s.ignore_opacity;
    m = model_import::import_model(s.model, io);
  } catch (const std::runtime_error& e) {
    fail(e.what());
  }
  std::string name = std::filesystem::path(s.model).stem().string();
  if (name.empty()) name = "model";
  const bool generated = s.generate_uvs || !m.without_lightmap_uvs.empty();
  if (const std::string line = model_import::opacity_summary(m); !line.empty()) std::printf("%s: %s\n", name.c_str(), line.c_str());
  if (generated) generate_model_uvs(m, s, name);
  scene_arrays arrays;
  const scene_bake_input in = model_scene(m, s, arrays);
  if (!m.lights.empty()) std::printf("%s: %zu light%s from the model\n", name.c_str(), m.lights.size(), m.lights.size() > 1 ? "s" : "");
  if (m.pages > 1 && !generated)
    std::printf("%s: instanced meshes: instance k of each mesh is baked into page k (%d pages)\n", name.c_str(), m.pages);
  std::vector<std::string> mesh_names;
  for (const model_import::mesh& me : m.meshes) mesh_names.push_back(me.name);
  bake_and_write(name, in, s, m.lights, mesh_names);
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
