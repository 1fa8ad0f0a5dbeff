// The baker's checks of its inputs and options (internal, not installed): each names the C++
// function (`who`) and the field or index at fault, and throws error(invalid_argument).
#pragma once

#include "hemilight/bake.hpp"

#include <string>

namespace hemilight::bake_detail {

// v with 9 significant digits, for messages.
std::string num(double v);

// width and height in [1, max_lightmap_size]. Cost: O(1).
void check_size(const char* who, int width, int height);

// What compute_lightmap_samples reads (scene::create checks the rest later): index and position
// arrays present, lightmap UVs present and at most lightmap_uv_tolerance outside [0, 1] (or only
// finite with uvs_in_unit_square false), indices in range, albedo in [0, 1], positions and
// normals finite. Cost: O(vertices + triangles).
void check_input(const char* who, const bake_input& in, bool uvs_in_unit_square = true);

// A checked input with its lightmap UVs clamped onto [0, 1] (those check_input let through within
// lightmap_uv_tolerance): `input` points at a copy of the UVs when some needed it, else at the
// caller's. `clamped` counts the vertices moved and `warning` names the first ("" if none).
// Not copyable (input may point into uvs). Cost: O(vertices).
struct clamped_input {
  bake_input input;
  std::vector<glm::vec2> uvs;
  std::size_t clamped = 0;
  std::string warning;

  clamped_input() = default;
  clamped_input(const clamped_input&) = delete;
  clamped_input& operator=(const clamped_input&) = delete;
};
void clamp_lightmap_uvs(const char* who, const bake_input& in, clamped_input& out);

// The warning of bake_stats for `count` triangles with 3D area but no lightmap UV area, the first
// named by `first` ("triangle 34", "meshes[2] triangle 4 (scene triangle 40)").
std::string no_uv_area_warning(const char* who, std::size_t count, const std::string& first);

// The bake options' ranges (size only with `size`), the cache options whatever use_cache says,
// the lights, the direct-light options and the shadow-mask channels. Cost: O(lights).
void check_options(const bake_options& o, const char* who = "bake_lightmap", bool size = true);

// The environment sky, when there is one. Cost: O(its texels).
void check_environment(const char* who, const bake_options& o);

}  // namespace hemilight::bake_detail
