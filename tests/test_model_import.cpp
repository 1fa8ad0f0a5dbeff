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
