// Tests of the command-line baker's model importer (examples/model_import.hpp) on a glTF 2.0 file
// this test writes itself: two meshes (one used by two nodes: an instance), a node transform, a
// PNG base colour texture (written with stb_image_write) and an emissive factor. Checks the
// scene that reaches the baker: world-space positions, the lightmap UVs of TEXCOORD_1 in glTF's
// convention, instances on their own pages, materials and the per-texel albedo averaged over
// each lightmap texel's footprint, and the errors for a missing texture and missing lightmap UVs.
#include "model_export.hpp"
#include "model_import.hpp"

#include "hemilight/levels.hpp"

#include "test_support.hpp"

#include <catch2/catch.hpp>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

std::string base64(const std::vector<unsigned char>& d) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < d.size(); i += 3) {
    const unsigned v = unsigned(d[i]) << 16 | (i + 1 < d.size() ? unsigned(d[i + 1]) << 8 : 0u) | (i + 2 < d.size() ? d[i + 2] : 0u);
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += i + 1 < d.size() ? t[(v >> 6) & 63] : '=';
    out += i + 2 < d.size() ? t[v & 63] : '=';
  }
  return out;
}

template <class T>
void put(std::vector<unsigned char>& buf, std::initializer_list<T> values) {
  for (T v : values) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof v);
    buf.insert(buf.end(), b, b + sizeof v);
  }
}

// The floor: a unit quad at y = 0 facing up; texture UVs cover the texture, lightmap UVs
// (TEXCOORD_1, glTF's v-down convention) the left half of the page. The wall: a unit quad at
// z = 0 facing +z, lightmap UVs in the right half, no texture.
struct written_model {
  std::string path;
};

// Writes the model into its own directory under the test scratch directory (tests run in parallel).
written_model write_model(const std::string& name, bool with_texture_file, bool with_texcoord1) {
  const std::string dir = std::string(HEMILIGHT_TEST_TMPDIR) + "/" + name;
  std::filesystem::create_directories(dir);
  std::filesystem::remove(dir + "/checker.png");
  // The texture: 8 x 8, left half black, right half white (sRGB 0 and 255: linear 0 and 1).
  std::vector<unsigned char> png(8 * 8 * 3);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c) png[std::size_t(3 * (8 * y + x) + c)] = x < 4 ? 0 : 255;
  if (with_texture_file) REQUIRE(stbi_write_png((dir + "/checker.png").c_str(), 8, 8, 3, png.data(), 8 * 3) != 0);
  std::vector<unsigned char> buf;
  // floor: positions, normals, texcoord0, texcoord1 (4 vertices), indices (6)
  put<float>(buf, {0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0});  // 0: 48 bytes
  put<float>(buf, {0, 0, 0, 1, 1, 1, 1, 0});              // 48: texcoord0 (32): u = 2 x lightmap u
  put<float>(buf, {0, 0, 0, 1, 0.5f, 1, 0.5f, 0});        // 80: texcoord1 (32): u in [0, 0.5]
  put<std::uint16_t>(buf, {0, 1, 2, 0, 2, 3});            // 112: 12 bytes
  // wall: positions, texcoord1, indices
  put<float>(buf, {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});  // 124: 48
  put<float>(buf, {0.5f, 0, 1, 0, 1, 1, 0.5f, 1});        // 172: 32: u in [0.5, 1]
  put<std::uint16_t>(buf, {0, 1, 2, 0, 2, 3});            // 204: 12
  const std::string uri = "data:application/octet-stream;base64," + base64(buf);
  const std::string floor_attrs = with_texcoord1 ? R"({"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2})" : R"({"POSITION": 0, "TEXCOORD_0": 1})";
  const std::string gltf = R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0, 1, 2]}],
  "nodes": [
    {"name": "floor", "mesh": 0, "translation": [10, 0, 0], "scale": [2, 2, 2]},
    {"name": "wall", "mesh": 1},
    {"name": "wall_copy", "mesh": 1, "translation": [0, 0, 5]}
  ],
  "meshes": [
    {"name": "Floor", "primitives": [{"attributes": )" + floor_attrs + R"(, "indices": 3, "material": 0}]},
    {"name": "Wall", "primitives": [{"attributes": {"POSITION": 4, "TEXCOORD_0": 5, "TEXCOORD_1": 5}, "indices": 6, "material": 1}]}
  ],
  "materials": [
    {"name": "Checker", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 1, 1, 1], "baseColorTexture": {"index": 0}}},
    {"name": "Glow", "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.3, 0.4, 1]}, "emissiveFactor": [1, 0.5, 0], "doubleSided": true}
  ],
  "textures": [{"source": 0}],
  "images": [{"uri": "checker.png"}],
  "buffers": [{"byteLength": )" + std::to_string(buf.size()) + R"(, "uri": ")" + uri + R"("}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32},
    {"buffer": 0, "byteOffset": 80, "byteLength": 32}, {"buffer": 0, "byteOffset": 112, "byteLength": 12},
    {"buffer": 0, "byteOffset": 124, "byteLength": 48}, {"buffer": 0, "byteOffset": 172, "byteLength": 32},
    {"buffer": 0, "byteOffset": 204, "byteLength": 12}
  ],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 0, 1]},
    {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
    {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"},
    {"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 5, "componentType": 5126, "count": 4, "type": "VEC2"},
    {"bufferView": 6, "componentType": 5123, "count": 6, "type": "SCALAR"}
  ]
})";
  written_model w;
  w.path = dir + "/two_meshes.gltf";
  std::ofstream(w.path) << gltf;
  return w;
}

}  // namespace

TEST_CASE("Model import: a glTF with two meshes, an instance, a transform and a texture reaches the baker as written", "[model_import]") {
  const written_model w = write_model("import_gltf", true, true);
  const model_import::model m = model_import::import_model(w.path);
  REQUIRE(m.meshes.size() == 3);  // floor, wall, wall_copy
  REQUIRE(m.pages == 2);          // the wall's second instance on page 1
  const model_import::mesh* floor = nullptr;
  std::vector<const model_import::mesh*> walls;
  for (const model_import::mesh& me : m.meshes) {
    if (me.name.find("'Floor'") != std::string::npos) floor = &me;
    if (me.name.find("'Wall'") != std::string::npos) walls.push_back(&me);
  }
  REQUIRE(floor);
  REQUIRE(walls.size() == 2);
  CHECK(floor->name.find("node 'floor'") != std::string::npos);
  CHECK(floor->instance == 0);
  CHECK(walls[0]->instance + walls[1]->instance == 1);  // one on page 0, one on page 1
  // The node transform: x -> 2 x + 10, z -> 2 z (exact in float).
  REQUIRE(floor->positions.size() == 4);
  CHECK(floor->positions[2] == glm::vec3(12.0f, 0.0f, 2.0f));
  // The copy moved by (0, 0, 5).
  const model_import::mesh* copy = walls[0]->instance == 1 ? walls[0] : walls[1];
  CHECK(copy->name.find("node 'wall_copy'") != std::string::npos);
  CHECK(copy->positions[2] == glm::vec3(1.0f, 1.0f, 5.0f));
  // Lightmap UVs are TEXCOORD_1 as the file stores them (glTF's v-down convention).
  REQUIRE(floor->lightmap_uvs.size() == 4);
  CHECK(floor->lightmap_uvs[1] == glm::vec2(0.0f, 1.0f));
  CHECK(floor->lightmap_uvs[2] == glm::vec2(0.5f, 1.0f));
  // Normals follow the transform (a uniform scale: still +y).
  CHECK(glm::length(glm::normalize(floor->normals[0]) - glm::vec3(0, 1, 0)) < 1e-6f);
  // Materials: factors, the texture (decoded, sRGB 0 / 255 -> linear 0 / 1), emission, two-sided.
  REQUIRE(m.textures.size() == 1);
  CHECK(m.textures[0].width == 8);
  const model_import::material& checker = m.materials[floor->material];
  CHECK(checker.name == "Checker");
  CHECK(checker.base_color == glm::vec3(0.5f, 1.0f, 1.0f));
  CHECK(checker.base_color_texture == 0);
  const material flat = checker.flat(m.textures);  // factor x texture mean (half black, half white)
  CHECK(flat.albedo == glm::vec3(0.25f, 0.5f, 0.5f));
  const model_import::material& glow = m.materials[walls[0]->material];
  CHECK(glow.emissive == glm::vec3(1.0f, 0.5f, 0.0f));
  CHECK(glow.two_sided);
  CHECK(glow.flat(m.textures).albedo == glm::vec3(0.2f, 0.3f, 0.4f));

  // Per-texel albedo of page 0 (16 x 8): the floor covers columns 0..7 with texture u = 2 x
  // lightmap u, so texel x sees exactly texture column x: black for x < 4, factor x white for
  // 4..7; the wall's columns 8..15 get its factor. Exact: every supersample of a texel reads the
  // same texture texel, and 0 and 1 are exact in sRGB decoding.
  const model_import::page_images img = model_import::bake_page_materials(m, 0, 16, 8);
  REQUIRE(img.albedo.width == 16);
  CHECK(img.emission.width == 0);  // no emissive texture: the triangles' emission is exact
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) {
      const glm::vec3 a(img.albedo.at(x, y)[0], img.albedo.at(x, y)[1], img.albedo.at(x, y)[2]);
      const glm::vec3 want = x < 4 ? glm::vec3(0.0f) : x < 8 ? glm::vec3(0.5f, 1.0f, 1.0f) : glm::vec3(0.2f, 0.3f, 0.4f);
      INFO("texel (" << x << ", " << y << ")");
      CHECK(glm::length(a - want) < 1e-6f);
    }
  // Page 1 holds only the untextured wall copy: no images.
  CHECK(model_import::bake_page_materials(m, 1, 16, 8).albedo.width == 0);
}

TEST_CASE("Model import: a missing texture and meshes without lightmap UVs are one-line errors naming them", "[model_import]") {
  {
    const written_model w = write_model("import_no_texture", false, true);
    try {
      model_import::import_model(w.path);
      FAIL("no error for the missing texture");
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      INFO(what);
      CHECK(what.find("material 0 ('Checker')") != std::string::npos);
      CHECK(what.find("checker.png' cannot be read") != std::string::npos);
      CHECK(what.find('\n') == std::string::npos);
    }
  }
  {
    const written_model w = write_model("import_no_uv1", true, false);
    try {
      model_import::import_model(w.path);
      FAIL("no error for the floor without TEXCOORD_1");
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      INFO(what);
      CHECK(what.find("1 mesh has no lightmap UVs (UV channel 1): mesh 0 ('Floor')") != std::string::npos);
    }
  }
  try {
    model_import::import_model(std::string(HEMILIGHT_TEST_TMPDIR) + "/no_such_model.gltf");
    FAIL("no error for a missing file");
  } catch (const std::runtime_error& e) {
    CHECK(std::string(e.what()).find("no such file") != std::string::npos);
  }
}

// ---- previews (examples/preview.hpp) ---------------------------------------------------------------

#include "preview.hpp"

namespace {

// Two floor quads under a uniform sky (E = pi at every texel, so radiance = albedo exactly), one
// per page (the second page narrower, placed by scale and offset).
struct two_floors {
  scene_mesh mesh;
  scene_bake_input in;
  two_floors() {
    material a, b;
    a.albedo = glm::vec3(0.5f);
    b.albedo = glm::vec3(0.25f);
    mesh.add_quad({0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}, a);
    mesh.add_quad({1.5f, 0, 0}, {1.5f, 0, 1}, {2.5f, 0, 1}, {2.5f, 0, 0}, b);
    // Quad 1 fills its page; quad 2's UVs are in [2, 3] x [0, 1], offset by -2 into its page.
    mesh.lightmap_uvs = {{0, 0}, {0, 1}, {1, 1}, {1, 0}, {2, 0}, {2, 1}, {3, 1}, {3, 0}};
    in.geometry.scene = mesh.desc();
    in.geometry.scene.sky_radiance = glm::vec3(1.0f);
    lightmap_page p0, p1;
    p0.width = p0.height = 16;
    p1.width = 8;
    p1.height = 12;
    in.pages = {p0, p1};
    bake_mesh m0, m1;
    m0.triangle_count = 2;
    m0.page = 0;
    m1.first_triangle = 2;
    m1.triangle_count = 2;
    m1.page = 1;
    m1.uv_offset = glm::vec2(-2.0f, 0.0f);
    in.meshes = {m0, m1};
  }
};

}  // namespace

TEST_CASE("Preview: every pixel shows lightmap x albedo exactly where the bake is uniform, across pages, or the sky", "[preview]") {
  const two_floors s;
  bake_options o;
  o.sampler.resolution = 16;
  o.bounces = 2;
  o.thread_count = 2;
  const scene_bake_result r = bake_scene(s.in, o);
  const std::vector<image> radiance = preview::page_radiance(s.in, r);
  preview::camera cam;
  cam.eye = {1.25f, 2.0f, 0.5f};
  cam.target = {1.25f, 0.0f, 0.5f};
  cam.fov_degrees = 80.0f;
  const image pic = preview::render(s.in, radiance, cam, 64);
  REQUIRE(pic.width == 64);
  int a = 0, b = 0, sky = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const float v = pic.at(x, y)[0];
      // Up-facing floors see only the sky: E = pi (float sums of exact hemicube weights, 1e-4
      // relative), radiance = albedo E / pi. Any bleeding between pages or black at a page's
      // border would show as another value.
      if (std::fabs(v - 0.5f) < 1e-4f) ++a;
      else if (std::fabs(v - 0.25f) < 1e-4f) ++b;
      else if (v == 1.0f) ++sky;
      else FAIL_CHECK("pixel (" << x << ", " << y << ") = " << v);
    }
  CHECK(a > 300);
  CHECK(b > 300);
  CHECK(sky > 300);
  // Looking straight down (-y) with +z at the top of the picture, +x points left (right =
  // forward x up = -x): the first floor (x < 1) is on the right.
  CHECK(std::fabs(pic.at(44, 32)[0] - 0.5f) < 1e-4f);
  CHECK(std::fabs(pic.at(20, 32)[0] - 0.25f) < 1e-4f);
}

TEST_CASE("Preview: the default camera sees a closed room from inside and cameras are checked", "[preview]") {
  scene_mesh room;
  material grey;
  grey.albedo = glm::vec3(0.5f);
  room.add_box({0, 0, 0}, {4, 3, 5}, grey, true);
  generate_lightmap_uvs(room, 32, 2);
  scene_bake_input in;
  in.geometry.scene = room.desc();
  lightmap_page page;
  page.width = page.height = 32;
  in.pages = {page};
  bake_mesh all;
  all.triangle_count = room.triangle_count();
  all.page = 0;
  in.meshes = {all};
  const std::vector<image> radiance(1, image::make(32, 32, 3, 1.0f));
  const preview::camera cam = preview::default_camera(in, radiance);
  // Inside the room's bounds (from outside every wall shows its back).
  for (int c = 0; c < 3; ++c) {
    CHECK(cam.eye[c] > 0.0f);
    CHECK(cam.eye[c] < (c == 0 ? 4.0f : c == 1 ? 3.0f : 5.0f));
  }
  preview::camera parsed;
  CHECK(preview::parse_camera("1,2,3,4,5,6", parsed));
  CHECK(parsed.fov_degrees == 60.0f);
  CHECK(preview::parse_camera("1,2,3,4,5,6,45", parsed));
  CHECK(parsed.fov_degrees == 45.0f);
  CHECK_FALSE(preview::parse_camera("1,2,3,1,2,3", parsed));     // eye at the target
  CHECK_FALSE(preview::parse_camera("1,2,3,4,5,6,120", parsed)); // wider than a hemicube face
  CHECK_FALSE(preview::parse_camera("1,2,3,4,5", parsed));
  CHECK_FALSE(preview::parse_camera("model.gltf", parsed));
  test::require_error([&] { preview::render(in, radiance, cam, 8); }, status::invalid_argument, "size 8 is not in [16, 4096]");
}

TEST_CASE("Model export: a stand-in level written as glb reads back with the same triangles, lightmap UVs and albedos",
          "[model_import][levels]") {
  // The arena at its default size, degenerate triangles included (hemilight_make_level's path).
  const level l = make_level("arena");
  const std::string dir = std::string(HEMILIGHT_TEST_TMPDIR) + "/export_level";
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/arena.glb";
  model_export::write_glb(l.mesh, path);
  const model_import::model m = model_import::import_model(path);
  // One mesh per distinct albedo, in order of first use, each with its triangles in order.
  std::vector<glm::vec3> albedos;
  std::vector<std::size_t> of(l.mesh.triangle_count());
  for (std::size_t t = 0; t < l.mesh.triangle_count(); ++t) {
    const glm::vec3 a = l.mesh.materials[t].albedo;
    const auto it = std::find(albedos.begin(), albedos.end(), a);
    of[t] = static_cast<std::size_t>(it - albedos.begin());
    if (it == albedos.end()) albedos.push_back(a);
  }
  REQUIRE(m.meshes.size() == albedos.size());
  CHECK(m.pages == 1);
  std::size_t triangles = 0, moved = 0, degenerate = 0;
  float uv_error = 0.0f;
  for (std::size_t k = 0; k < m.meshes.size(); ++k) {
    const model_import::mesh& me = m.meshes[k];
    INFO(me.name);
    CHECK(m.materials[me.material].base_color == albedos[k]);
    REQUIRE(me.lightmap_uvs.size() == me.positions.size());
    std::size_t f = 0;
    for (std::size_t t = 0; t < l.mesh.triangle_count(); ++t) {
      if (of[t] != k) continue;
      REQUIRE(3 * f + 2 < me.indices.size());
      glm::dvec3 p[3];
      for (std::size_t c = 0; c < 3; ++c) {
        const std::uint32_t mine = l.mesh.indices[3 * t + c], theirs = me.indices[3 * f + c];
        moved += l.mesh.positions[mine] != me.positions[theirs];  // exact: float32 in the file, identity node
        uv_error = std::max(uv_error, glm::length(l.mesh.lightmap_uvs[mine] - me.lightmap_uvs[theirs]));
        p[c] = glm::dvec3(me.positions[theirs]);
      }
      const double longest = std::max({glm::dot(p[1] - p[0], p[1] - p[0]), glm::dot(p[2] - p[1], p[2] - p[1]), glm::dot(p[0] - p[2], p[0] - p[2])});
      degenerate += 0.5 * glm::length(glm::cross(p[1] - p[0], p[2] - p[0])) <= 1e-10 * longest;
      ++f;
    }
    CHECK(3 * f == me.indices.size());
    triangles += f;
  }
  CHECK(triangles == l.mesh.triangle_count());
  CHECK(moved == 0);
  CHECK(degenerate == l.degenerate_triangles);
  // The writer stores 1 - v for assimp, which writes 1 - that; the importer flips twice more: each
  // 1 - x rounds by at most 2^-25 (3e-8) for x < 0.5 and is exact above.
  CHECK(uv_error <= 1e-7f);
}

TEST_CASE("Model import: meshes without lightmap UVs get generated ones, written back as TEXCOORD_1 and read back", "[model_import]") {
  // The floor has no TEXCOORD_1; with allow_missing_lightmap_uvs it comes without lightmap UVs, named.
  const written_model w = write_model("import_generate", true, false);
  model_import::import_options io;
  io.allow_missing_lightmap_uvs = true;
  model_import::model m = model_import::import_model(w.path, io);
  REQUIRE(m.without_lightmap_uvs.size() == 1);
  CHECK(m.without_lightmap_uvs[0].find("mesh 0 ('Floor')") != std::string::npos);
  CHECK(m.meshes[0].lightmap_uvs.empty());
  // The model's world positions unwrapped as one (the bake's path, examples/bake.cpp).
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
  std::size_t triangles = 0;
  for (const model_import::mesh& me : m.meshes) {
    const auto base = std::uint32_t(positions.size());
    positions.insert(positions.end(), me.positions.begin(), me.positions.end());
    for (std::uint32_t i : me.indices) indices.push_back(base + i);
    triangles += me.indices.size() / 3;
  }
  unwrap_options o;
  o.page_size = 64;
  const unwrap_result r = unwrap_lightmap(positions.data(), positions.size(), indices.data(), triangles, o);
  const std::vector<model_import::mesh> before = m.meshes;
  model_import::apply_lightmap_uvs(m, r);
  REQUIRE(m.meshes.size() == before.size());  // one page: no mesh is split
  CHECK(m.pages == 1);
  for (std::size_t k = 0; k < m.meshes.size(); ++k) {
    const model_import::mesh& me = m.meshes[k];
    REQUIRE(me.indices.size() == before[k].indices.size());
    REQUIRE(me.lightmap_uvs.size() == me.positions.size());
    for (std::size_t i = 0; i < me.indices.size(); ++i) CHECK(me.positions[me.indices[i]] == before[k].positions[before[k].indices[i]]);
  }
  // Written as glb and read back: the same triangles and UVs (to float rounding of 1 - v: 6e-8).
  const std::string glb = std::string(HEMILIGHT_TEST_TMPDIR) + "/import_generate/with_uvs.glb";
  model_export::write_glb(m, glb);
  const model_import::model back = model_import::import_model(glb);
  REQUIRE(back.meshes.size() == m.meshes.size());
  float uv_error = 0.0f;
  for (std::size_t k = 0; k < m.meshes.size(); ++k) {
    REQUIRE(back.meshes[k].indices.size() == m.meshes[k].indices.size());
    for (std::size_t i = 0; i < m.meshes[k].indices.size(); ++i) {
      CHECK(back.meshes[k].positions[back.meshes[k].indices[i]] == m.meshes[k].positions[m.meshes[k].indices[i]]);
      uv_error = std::max(uv_error, glm::length(back.meshes[k].lightmap_uvs[back.meshes[k].indices[i]] -
                                                m.meshes[k].lightmap_uvs[m.meshes[k].indices[i]]));
    }
  }
  CHECK(uv_error <= 1e-7f);
  CHECK(back.materials[back.meshes[0].material].base_color_texture >= 0);  // the checker texture, by its file
}

// A floor quad (y = 0, facing up) whose TEXCOORD_0 and TEXCOORD_1 are `uv` (glTF's convention).
std::string write_quad(const std::string& name, const float (&uv)[8]) {
  const std::string dir = std::string(HEMILIGHT_TEST_TMPDIR) + "/" + name;
  std::filesystem::create_directories(dir);
  std::vector<unsigned char> buf;
  put<float>(buf, {0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0});
  put<float>(buf, {uv[0], uv[1], uv[2], uv[3], uv[4], uv[5], uv[6], uv[7]});
  put<std::uint16_t>(buf, {0, 1, 2, 0, 2, 3});
  const std::string gltf = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"name": "floor", "mesh": 0}],
  "meshes": [{"name": "Floor", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 1}, "indices": 2}]}],
  "buffers": [{"byteLength": )" + std::to_string(buf.size()) + R"(, "uri": "data:application/octet-stream;base64,)" + base64(buf) + R"("}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                  {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 0, 1]},
                {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}]})";
  const std::string path = dir + "/quad.gltf";
  std::ofstream(path) << gltf;
  return path;
}

void import_fails(const std::string& path, const model_import::import_options& io, const std::string& needle) {
  try {
    model_import::import_model(path, io);
    FAIL("no error; expected " << needle);
  } catch (const std::runtime_error& e) {
    INFO(e.what());
    CHECK(std::string(e.what()).find(needle) != std::string::npos);
  }
}

TEST_CASE("Model import: UVs a hair outside [0, 1] are taken, UV-less triangles refused only when strict", "[model_import]") {
  model_import::import_options io, strict;
  strict.strict = true;
  // u = -0.00048 (a packer's margin, within lightmap_uv_tolerance): taken as it is (the bake clamps).
  const model_import::model m = model_import::import_model(write_quad("import_margin", {-0.00048f, 0, -0.00048f, 1, 1, 1, 1, 0}), io);
  CHECK(m.meshes[0].lightmap_uvs[0].x == -0.00048f);
  import_fails(write_quad("import_outside", {-0.002f, 0, 0, 1, 1, 1, 1, 0}), io, "vertex 0: lightmap UV (-0.002000, 0.000000) is outside [0, 1] by more than 0.001");
  // Vertex 2's UV on vertex 1's: triangle 0 (0, 1, 2) has no UV area, triangle 1 (0, 2, 3) has.
  const std::string flat = write_quad("import_flat", {0, 0, 0, 1, 0, 1, 1, 0});
  CHECK_NOTHROW(model_import::import_model(flat, io));
  import_fails(flat, strict, "mesh 0 ('Floor') at node 'floor' triangle 0 has zero area in lightmap UV space");
}

// ---- opacity: glTF alpha modes, alpha textures, transmission --------------------------------------

namespace {

// An RGBA (or RGB: channels 3) PNG in memory, made by stb_image_write.
std::vector<unsigned char> png_bytes(int w, int h, int channels, const std::vector<unsigned char>& pixels) {
  std::vector<unsigned char> out;
  const auto append = [](void* context, void* data, int size) {
    auto* v = static_cast<std::vector<unsigned char>*>(context);
    v->insert(v->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
  };
  REQUIRE(stbi_write_png_to_func(append, &out, w, h, channels, pixels.data(), w * channels) != 0);
  return out;
}

// 4 x 4 RGBA: alpha 255 in the top-left quadrant (rows 0-1, columns 0-1), 0 elsewhere; red.
std::vector<unsigned char> quadrants_rgba() {
  std::vector<unsigned char> p(4 * 4 * 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      unsigned char* t = &p[std::size_t(4 * (4 * y + x))];
      t[0] = 255, t[1] = 0, t[2] = 0, t[3] = x < 2 && y < 2 ? 255 : 0;
    }
  return p;
}

// 4 x 1 RGBA: alphas 0, 85, 170, 255 (mean 0.5); white.
std::vector<unsigned char> stripes_rgba() {
  std::vector<unsigned char> p(4 * 4, 255);
  for (std::size_t x = 0; x < 4; ++x) p[4 * x + 3] = static_cast<unsigned char>(85 * x);
  return p;
}

// A glTF of unit floor quads (x, z in [0, 1] x [-1, 0], facing up), one mesh per entry of
// `material_of_mesh` (its material), node k at translations[k]. Every mesh has TEXCOORD_0 = (x, 1 + z)
// (v = 0 at the far edge z = -1: the image's first row there) and TEXCOORD_1 = (x, -z) (the
// lightmap UVs). `materials` and `images` are the JSON arrays' contents; texture k uses image k.
std::string write_quads(const std::string& name, const std::string& materials, const std::vector<std::string>& image_uris,
                        const std::vector<int>& material_of_mesh, const std::vector<glm::vec3>& translations) {
  const std::string dir = std::string(HEMILIGHT_TEST_TMPDIR) + "/" + name;
  std::filesystem::create_directories(dir);
  std::vector<unsigned char> buf;
  put<float>(buf, {0, 0, 0, 1, 0, 0, 1, 0, -1, 0, 0, -1});  // 0: positions (48)
  put<float>(buf, {0, 1, 1, 1, 1, 0, 0, 0});              // 48: TEXCOORD_0 (32)
  put<float>(buf, {0, 0, 1, 0, 1, 1, 0, 1});              // 80: TEXCOORD_1 (32)
  put<std::uint16_t>(buf, {0, 1, 2, 0, 2, 3});            // 112: indices (12)
  std::string meshes, nodes, scene_nodes, textures, images;
  for (std::size_t k = 0; k < material_of_mesh.size(); ++k) {
    const std::string sep = k ? ", " : "";
    meshes += sep + R"({"name": "Quad)" + std::to_string(k) +
              R"(", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2}, "indices": 3, "material": )" +
              std::to_string(material_of_mesh[k]) + "}]}";
    const glm::vec3 t = translations[k];
    nodes += sep + R"({"name": "quad)" + std::to_string(k) + R"(", "mesh": )" + std::to_string(k) + R"(, "translation": [)" +
             std::to_string(t.x) + ", " + std::to_string(t.y) + ", " + std::to_string(t.z) + "]}";
    scene_nodes += sep + std::to_string(k);
  }
  for (std::size_t k = 0; k < image_uris.size(); ++k) {
    const std::string sep = k ? ", " : "";
    textures += sep + R"({"source": )" + std::to_string(k) + "}";
    images += sep + R"({"uri": ")" + image_uris[k] + R"("})";
  }
  const std::string gltf = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [)" + scene_nodes + R"(]}],
  "extensionsUsed": ["KHR_materials_transmission"],
  "nodes": [)" + nodes + R"(], "meshes": [)" + meshes + R"(], "materials": [)" + materials + "]," +
                           (image_uris.empty() ? "" : R"("textures": [)" + textures + R"(], "images": [)" + images + "],") + R"(
  "buffers": [{"byteLength": )" + std::to_string(buf.size()) + R"(, "uri": "data:application/octet-stream;base64,)" + base64(buf) + R"("}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                  {"buffer": 0, "byteOffset": 80, "byteLength": 32}, {"buffer": 0, "byteOffset": 112, "byteLength": 12}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, -1], "max": [1, 0, 0]},
                {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
                {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}]})";
  const std::string path = dir + "/quads.gltf";
  std::ofstream(path) << gltf;
  return path;
}

// Each mesh at (2k, 0, 0).
std::vector<glm::vec3> side_by_side(std::size_t n) {
  std::vector<glm::vec3> t;
  for (std::size_t k = 0; k < n; ++k) t.emplace_back(2.0f * float(k), 0.0f, 0.0f);
  return t;
}

// The files of the opacity tests: quadrants.png (RGBA, next to the model), opaque.png (RGB), the
// stripes as a data URI (embedded), broken.png (not a PNG).
struct opacity_files {
  std::string dir, stripes_uri;
  explicit opacity_files(const std::string& name) : dir(std::string(HEMILIGHT_TEST_TMPDIR) + "/" + name) {
    std::filesystem::create_directories(dir);
    REQUIRE(stbi_write_png((dir + "/quadrants.png").c_str(), 4, 4, 4, quadrants_rgba().data(), 16) != 0);
    const std::vector<unsigned char> grey(4 * 4 * 3, 128);
    REQUIRE(stbi_write_png((dir + "/opaque.png").c_str(), 4, 4, 3, grey.data(), 12) != 0);
    std::ofstream(dir + "/broken.png") << "not a PNG at all";
    std::filesystem::remove(dir + "/missing.png");
    stripes_uri = "data:image/png;base64," + base64(png_bytes(4, 1, 4, stripes_rgba()));
  }
};

const model_import::material& material_named(const model_import::model& m, const std::string& name) {
  for (const model_import::material& mat : m.materials)
    if (mat.name == name) return mat;
  FAIL("no material '" << name << "'");
  return m.materials.front();
}

const model_import::mesh& mesh_with_material(const model_import::model& m, const std::string& name) {
  for (const model_import::mesh& me : m.meshes)
    if (m.materials[me.material].name == name) return me;
  FAIL("no mesh with material '" << name << "'");
  return m.meshes.front();
}

// The model's meshes as one scene, as hemilight_bake builds it (examples/bake.cpp, model_scene):
// flat materials, the texcoords of the meshes whose material reads an alpha texture, the alpha
// textures.
struct model_scene_arrays {
  scene_mesh mesh;
  std::vector<std::size_t> first_triangle;  // per model mesh
  explicit model_scene_arrays(const model_import::model& m) {
    bool textured = false;
    for (const model_import::mesh& me : m.meshes) textured = textured || m.materials[me.material].alpha_texture >= 0;
    for (const model_import::mesh& me : m.meshes) {
      first_triangle.push_back(mesh.triangle_count());
      const auto base = std::uint32_t(mesh.positions.size());
      mesh.positions.insert(mesh.positions.end(), me.positions.begin(), me.positions.end());
      mesh.lightmap_uvs.insert(mesh.lightmap_uvs.end(), me.lightmap_uvs.begin(), me.lightmap_uvs.end());
      for (std::uint32_t i : me.indices) mesh.indices.push_back(base + i);
      mesh.materials.insert(mesh.materials.end(), me.indices.size() / 3, m.materials[me.material].flat(m.textures));
      if (!textured) continue;
      std::vector<glm::vec2> tc = model_import::mesh_texcoords(m, me);
      tc.resize(me.positions.size(), glm::vec2(0.0f));
      mesh.texcoords.insert(mesh.texcoords.end(), tc.begin(), tc.end());
    }
    mesh.alpha_textures = m.alpha_textures;
  }
};

const char* const opacity_materials = R"(
  {"name": "Leaves", "alphaMode": "MASK", "alphaCutoff": 0.3,
   "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.9], "baseColorTexture": {"index": 0}}},
  {"name": "LeavesToo", "alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
  {"name": "Cutout", "alphaMode": "MASK", "alphaCutoff": 0.6, "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.5]}},
  {"name": "Solid mask", "alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.7], "baseColorTexture": {"index": 1}}},
  {"name": "Veil", "alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 0.4]}},
  {"name": "Striped veil", "alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.5], "baseColorTexture": {"index": 2}}},
  {"name": "Glass", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 1, 1, 1]},
   "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.8}}},
  {"name": "Frosted", "alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 0, 0.5]},
   "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.5}}},
  {"name": "Plain", "alphaMode": "OPAQUE", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.3]}},
  {"name": "Leaves1", "alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}}},
  {"name": "Striped mask", "alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorTexture": {"index": 2}}}
)";

}  // namespace

TEST_CASE("Model import: glTF alpha modes, cutoffs, factors, alpha textures and transmission become the scene's opacity",
          "[model_import]") {
  const opacity_files files("import_opacity");
  const std::vector<int> mesh_materials = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  const std::string path =
      write_quads("import_opacity", opacity_materials, {"quadrants.png", "opaque.png", files.stripes_uri}, mesh_materials,
                  side_by_side(mesh_materials.size()));
  const model_import::model m = model_import::import_model(path);
  REQUIRE(m.meshes.size() == mesh_materials.size());
  // Alpha-tested: the factor, the cutoff (default 0.5), the image's alpha channel as the texture,
  // one per image (two materials share the quadrants), decoded exactly.
  const model_import::material& leaves = material_named(m, "Leaves");
  CHECK(leaves.opacity == surface_opacity::alpha_tested);
  CHECK(leaves.alpha == 0.9f);
  CHECK(leaves.alpha_cutoff == 0.3f);
  CHECK(leaves.alpha_mode == "MASK");
  REQUIRE(leaves.alpha_texture == 0);
  const model_import::material& leaves_too = material_named(m, "LeavesToo");
  CHECK(leaves_too.opacity == surface_opacity::alpha_tested);
  CHECK(leaves_too.alpha == 1.0f);
  CHECK(leaves_too.alpha_cutoff == 0.5f);
  CHECK(leaves_too.alpha_texture == 0);
  const model_import::material& striped_mask = material_named(m, "Striped mask");
  REQUIRE(striped_mask.alpha_texture == 1);  // the embedded image
  REQUIRE(m.alpha_textures.size() == 2);
  const std::vector<unsigned char> quadrants = quadrants_rgba();
  CHECK(m.alpha_textures[0].width == 4);
  CHECK(m.alpha_textures[0].height == 4);
  REQUIRE(m.alpha_textures[0].values.size() == 16);
  for (std::size_t i = 0; i < 16; ++i) CHECK(m.alpha_textures[0].values[i] == quadrants[4 * i + 3]);
  CHECK(m.alpha_textures[1].values == std::vector<std::uint8_t>{0, 85, 170, 255});
  CHECK(m.textures[std::size_t(m.alpha_sources[0])].source.find("quadrants.png") != std::string::npos);
  CHECK(m.textures[std::size_t(m.alpha_sources[1])].source.find("embedded") != std::string::npos);
  // The alpha factor alone below the cutoff: alpha-tested without a texture (never present).
  const model_import::material& cutout = material_named(m, "Cutout");
  CHECK(cutout.opacity == surface_opacity::alpha_tested);
  CHECK(cutout.alpha == 0.5f);
  CHECK(cutout.alpha_cutoff == 0.6f);
  CHECK(cutout.alpha_texture == -1);
  // MASK with an RGB texture (no alpha channel) and the factor above the cutoff: present everywhere.
  CHECK(material_named(m, "Solid mask").opacity == surface_opacity::opaque);
  CHECK(material_named(m, "Solid mask").alpha_texture == -1);
  // BLEND: 1 - alpha (grey), alpha = factor x the texture's mean alpha.
  const model_import::material& veil = material_named(m, "Veil");
  CHECK(veil.opacity == surface_opacity::translucent);
  CHECK(glm::length(veil.transmittance - glm::vec3(0.6f)) < 1e-6f);
  CHECK(glm::length(material_named(m, "Striped veil").transmittance - glm::vec3(0.75f)) < 1e-6f);
  // Transmission: factor x base colour; with BLEND: (1 - a) + a x that.
  const model_import::material& glass = material_named(m, "Glass");
  CHECK(glass.opacity == surface_opacity::translucent);
  CHECK(glass.transmission == 0.8f);
  CHECK(glm::length(glass.transmittance - glm::vec3(0.4f, 0.8f, 0.8f)) < 1e-6f);
  CHECK(glm::length(material_named(m, "Frosted").transmittance - glm::vec3(0.75f, 0.625f, 0.5f)) < 1e-6f);
  // OPAQUE ignores the factor's alpha; the default material assimp adds is opaque.
  CHECK(material_named(m, "Plain").opacity == surface_opacity::opaque);
  std::size_t see_through = 0;
  for (const model_import::material& mat : m.materials) see_through += mat.opacity != surface_opacity::opaque;
  CHECK(see_through == 9);
  // flat() carries it to the scene's material.
  const material flat = leaves.flat(m.textures);
  CHECK(flat.opacity == surface_opacity::alpha_tested);
  CHECK(flat.alpha == 0.9f);
  CHECK(flat.alpha_cutoff == 0.3f);
  CHECK(flat.alpha_texture == 0);
  CHECK(glass.flat(m.textures).transmittance == glass.transmittance);
  // The texcoords: the texture's own set as the file stores it (glTF's v), not the lightmap UVs.
  const std::vector<glm::vec2> tc0 = model_import::mesh_texcoords(m, mesh_with_material(m, "Leaves"));
  CHECK(tc0 == std::vector<glm::vec2>{{0, 1}, {1, 1}, {1, 0}, {0, 0}});
  const std::vector<glm::vec2> tc1 = model_import::mesh_texcoords(m, mesh_with_material(m, "Leaves1"));
  CHECK(tc1 == std::vector<glm::vec2>{{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  CHECK(model_import::mesh_texcoords(m, mesh_with_material(m, "Cutout")).empty());  // no texture read
  CHECK(model_import::mesh_texcoords(m, mesh_with_material(m, "Glass")).empty());
  // One line names them.
  const std::string line = model_import::opacity_summary(m);
  INFO(line);
  CHECK(line.find("9 of " + std::to_string(m.materials.size()) + " materials let light through") == 0);
  CHECK(line.find("'Leaves' alpha-tested (MASK, cutoff 0.3, alpha 0.9, alpha texture '") != std::string::npos);
  CHECK(line.find("quadrants.png' 4 x 4)") != std::string::npos);
  CHECK(line.find("'Glass' translucent (transmission 0.8: transmittance 0.4, 0.8, 0.8)") != std::string::npos);
  CHECK(line.find("'Veil' translucent (BLEND: transmittance 0.6)") != std::string::npos);
  CHECK(line.find('\n') == std::string::npos);
  // Without see-through materials: no line.
  CHECK(model_import::opacity_summary(model_import::import_model(write_quad("import_opaque_quad", {0, 0, 0, 1, 1, 1, 1, 0}))).empty());
}

TEST_CASE("Model import: the alpha texture reaches the scene the right way round (row 0 at v = 0, u along the columns)",
          "[model_import]") {
  // The quadrants texture: present in its top-left quadrant only (rows 0-1, columns 0-1). On the
  // quad, TEXCOORD_0 = (x, 1 + z): the top-left quadrant is x < 0.5, z < -0.5.
  const opacity_files files("import_alpha_orientation");
  const std::string path = write_quads("import_alpha_orientation", opacity_materials, {"quadrants.png", "opaque.png", files.stripes_uri},
                                       {0, 9}, side_by_side(2));
  const model_import::model m = model_import::import_model(path);
  const model_scene_arrays a(m);
  const std::shared_ptr<const scene> sc = scene::create(a.mesh.desc());
  for (std::size_t k = 0; k < m.meshes.size(); ++k) {
    const model_import::mesh& me = m.meshes[k];
    // The texture's own UV set: TEXCOORD_0 = (x, 1 + z) for 'Leaves', TEXCOORD_1 = (x, -z) for 'Leaves1'.
    const bool set1 = m.materials[me.material].name == "Leaves1";
    for (std::size_t t = 0; t < 2; ++t) {
      const std::size_t tri = a.first_triangle[k] + t;
      const std::uint32_t* v = &me.indices[3 * t];
      // Points at the quadrants' centres inside this triangle (barycentrics from the positions).
      const glm::vec3 p0 = me.positions[v[0]], e1 = me.positions[v[1]] - p0, e2 = me.positions[v[2]] - p0;
      for (const glm::vec2 q : {glm::vec2(0.25f, -0.75f), glm::vec2(0.75f, -0.75f), glm::vec2(0.25f, -0.25f), glm::vec2(0.75f, -0.25f)}) {
        const glm::vec2 d(q.x + 2.0f * float(k) - p0.x, q.y - p0.z);  // the point in the triangle's plane (y = 0)
        const float det = e1.x * e2.z - e1.z * e2.x;
        const float b1 = (d.x * e2.z - d.y * e2.x) / det, b2 = (e1.x * d.y - e1.z * d.x) / det;
        if (b1 < 0.0f || b2 < 0.0f || b1 + b2 > 1.0f) continue;  // in the other triangle
        const glm::vec2 uv = set1 ? glm::vec2(q.x, -q.y) : glm::vec2(q.x, 1.0f + q.y);
        const bool want = uv.x < 0.5f && uv.y < 0.5f;
        INFO(m.materials[me.material].name << " triangle " << t << " at (x, z) = (" << q.x << ", " << q.y << ")");
        CHECK(sc->alpha_present(tri, b1, b2) == want);
      }
    }
  }
}

TEST_CASE("Model import: a texture an alpha-tested material cannot read, or cannot find UVs for, is an error naming it",
          "[model_import]") {
  const opacity_files files("import_opacity_errors");
  const std::string mask = R"({"name": "Leaves", "alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})";
  const model_import::import_options io;
  import_fails(write_quads("import_opacity_errors", mask, {"missing.png"}, {0}, side_by_side(1)), io,
               "material 0 ('Leaves'): texture '");
  import_fails(write_quads("import_opacity_errors", mask, {"missing.png"}, {0}, side_by_side(1)), io, "missing.png' cannot be read");
  import_fails(write_quads("import_opacity_errors", mask, {"broken.png"}, {0}, side_by_side(1)), io, "broken.png' cannot be read");
  const std::string set2 = R"({"name": "Leaves", "alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 2}}})";
  import_fails(write_quads("import_opacity_errors", set2, {"quadrants.png"}, {0}, side_by_side(1)), io,
               "mesh 0 ('Quad0') at node 'quad0': its material 0 ('Leaves') reads its alpha texture at UV channel 2 (TEXCOORD_2), "
               "which the mesh does not have");
  // ignore_opacity: every material opaque and counted; textures are still read (and still fail).
  model_import::import_options ignore;
  ignore.ignore_opacity = true;
  const model_import::model m = model_import::import_model(
      write_quads("import_opacity_errors", opacity_materials, {"quadrants.png", "opaque.png", files.stripes_uri},
                  {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, side_by_side(11)),
      ignore);
  for (const model_import::material& mat : m.materials) CHECK(mat.opacity == surface_opacity::opaque);
  CHECK(m.alpha_textures.empty());
  CHECK(m.ignored_see_through == 9);  // the always-present MASK is opaque anyway
  CHECK(model_import::opacity_summary(m) == "9 see-through materials baked opaque (opacity ignored)");
  import_fails(write_quads("import_opacity_errors", mask, {"broken.png"}, {0}, side_by_side(1)), ignore, "broken.png' cannot be read");
}

TEST_CASE("Model export: the alpha mode, cutoff, base alpha and transmission of an imported model are written back", "[model_import]") {
  const opacity_files files("export_opacity");
  const model_import::model m = model_import::import_model(
      write_quads("export_opacity", opacity_materials, {"quadrants.png", "opaque.png", files.stripes_uri},
                  {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, side_by_side(11)));
  const std::string glb = files.dir + "/back.glb";
  model_export::write_glb(m, glb);
  const model_import::model back = model_import::import_model(glb);
  for (const char* name : {"Leaves", "LeavesToo", "Cutout", "Solid mask", "Veil", "Glass", "Frosted", "Plain", "Leaves1"}) {
    INFO(name);
    const model_import::material &a = material_named(m, name), &b = material_named(back, name);
    CHECK(b.alpha_mode == a.alpha_mode);
    CHECK(b.base_alpha == a.base_alpha);
    CHECK(b.gltf_alpha_cutoff == a.gltf_alpha_cutoff);
    CHECK(b.transmission == a.transmission);
    CHECK(b.opacity == a.opacity);
    CHECK(b.alpha == a.alpha);
    CHECK(b.alpha_cutoff == a.alpha_cutoff);
    CHECK(glm::length(b.transmittance - a.transmittance) < 1e-6f);
    CHECK((b.alpha_texture >= 0) == (a.alpha_texture >= 0));  // the file texture (quadrants.png) is written
  }
}

TEST_CASE("Model import: a half-open alpha-textured card from glTF shades the floor under its closed quadrant only", "[model_import][opacity]") {
  // The floor (material 'Plain', lightmap UVs over the page) and the 'Leaves' card 0.5 above it:
  // present in the quadrant x < 0.5, z < -0.5 only (alpha 0.9 x texture >= 0.3). A hard sun of
  // irradiance 2 straight down, sky 0, one bounce: the floor texels under that quadrant 0, the
  // rest 2 (texels whose footprint reaches the quadrant's edge left out).
  const opacity_files files("import_opacity_shadow");
  const std::string path = write_quads("import_opacity_shadow", opacity_materials, {"quadrants.png", "opaque.png", files.stripes_uri},
                                       {8, 0}, {glm::vec3(0.0f), glm::vec3(0.0f, 0.5f, 0.0f)});
  const model_import::model m = model_import::import_model(path);
  REQUIRE(m.meshes.size() == 2);
  const model_scene_arrays a(m);
  scene_bake_input in;
  in.geometry.scene = a.mesh.desc();
  lightmap_page page;
  page.width = page.height = 8;
  in.pages = {page};
  for (std::size_t k = 0; k < 2; ++k) {
    bake_mesh bm;
    bm.first_triangle = a.first_triangle[k];
    bm.triangle_count = 2;
    bm.page = m.materials[m.meshes[k].material].name == "Plain" ? 0 : -1;  // the card: an occluder
    in.meshes.push_back(bm);
  }
  bake_options o;
  o.sampler.resolution = 16;
  o.thread_count = 2;
  light sun;
  sun.type = light_type::directional;
  sun.direction = {0, -1, 0};
  sun.color = glm::vec3(2.0f);
  o.lights = {sun};
  const scene_bake_result r = bake_scene(in, o);
  // Page texel (x, y): lightmap UV = (x, -z) of the floor, so x < 4 and y >= 4 lie under the quadrant.
  int wrong = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      if (x == 3 || x == 4 || y == 3 || y == 4) continue;  // next to the quadrant's edges
      const float want = x < 4 && y >= 4 ? 0.0f : 2.0f, e = r.pages[0].irradiance.at(x, y)[0];
      if (!(std::fabs(e - want) < 1e-5f)) {
        ++wrong;
        UNSCOPED_INFO("texel (" << x << ", " << y << ") = " << e << ", expected " << want);
      }
    }
  CHECK(wrong == 0);
}
