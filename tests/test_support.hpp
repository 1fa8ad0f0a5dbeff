// Helpers shared by the Catch2 test files (not part of the library).
#pragma once

#include "hemilight/bake.hpp"
#include "hemilight/error.hpp"

#include <catch2/catch.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace hemilight::test {

/// A path in the test scratch directory (build/tests/tmp).
inline std::string tmp_path(const std::string& name) { return std::string(HEMILIGHT_TEST_TMPDIR) + "/" + name; }

/// Checks that f() throws hemilight::error with the given code and a message containing `needle`.
template <class F>
void require_error(F&& f, status code, const std::string& needle) {
  try {
    f();
    FAIL("no exception thrown; expected one containing '" << needle << "'");
  } catch (const error& e) {
    INFO("message: " << e.what());
    CHECK(e.code() == code);
    CHECK(std::string(e.what()).find(needle) != std::string::npos);
  }
}

/// k x k points 1 mm off the Cornell box's (reference_scenes.hpp) floor and back wall, at the
/// centres of a k x k grid on each, the two surfaces' points interleaved (floor, wall) per grid
/// cell, appended to p with their normals appended to n.
inline void cornell_floor_and_wall_points(int k, std::vector<glm::vec3>& p, std::vector<glm::vec3>& n) {
  const float H = 0.5488f, D = 0.5592f, W = 0.556f;
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) {
      p.push_back({(float(i) + 0.5f) / float(k) * W, 1e-3f, (float(j) + 0.5f) / float(k) * D});
      n.push_back({0.0f, 1.0f, 0.0f});
      p.push_back({(float(i) + 0.5f) / float(k) * W, (float(j) + 0.5f) / float(k) * H, D - 1e-3f});
      n.push_back({0.0f, 0.0f, -1.0f});
    }
}

/// A mesh with explicit lightmap UVs: triangles given as (3D, UV) vertex triples, each with its
/// own three vertices.
struct uv_mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> indices;
  std::vector<material> materials;
  glm::vec3 sky{0.0f};  ///< the scene's sky radiance
  void add(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec2 ua, glm::vec2 ub, glm::vec2 uc, material m = {}) {
    const auto base = std::uint32_t(positions.size());
    positions.insert(positions.end(), {a, b, c});
    uvs.insert(uvs.end(), {ua, ub, uc});
    indices.insert(indices.end(), {base, base + 1, base + 2});
    materials.push_back(m);
  }
  /// The quad a, b, c, d (counter-clockwise from its front) with UVs ua..ud, as (a, b, c), (a, c, d).
  void quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::vec2 ua, glm::vec2 ub, glm::vec2 uc, glm::vec2 ud,
            material m = {}) {
    add(a, b, c, ua, ub, uc, m);
    add(a, c, d, ua, uc, ud, m);
  }
  /// A view of the arrays (valid while the mesh lives and is not modified).
  bake_input input() const {
    bake_input in;
    in.scene.positions = positions.data();
    in.scene.vertex_count = positions.size();
    in.scene.indices = indices.data();
    in.scene.triangle_count = indices.size() / 3;
    in.scene.materials = materials.data();
    in.scene.lightmap_uvs = uvs.data();
    in.scene.sky_radiance = sky;
    return in;
  }
};

}  // namespace hemilight::test
