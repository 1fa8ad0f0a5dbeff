// Shared by src/cubemap*.cpp (not installed): face frames and the per-size texel table.
#pragma once

#include "hemilight/cubemap.hpp"

#include <memory>
#include <vector>

namespace hemilight::cubemap_detail {

/// A face's axis (major direction), column axis (u, GL s) and row axis (v, GL t).
struct face_frame {
  glm::vec3 axis, column, row;
};

/// The frame of face 0..5 (GL order).
const face_frame& frame_of(int face) noexcept;

/// axis + u column + v row in double.
inline glm::dvec3 face_point_d(int face, double u, double v) noexcept {
  const face_frame& f = frame_of(face);
  return glm::dvec3(f.axis) + u * glm::dvec3(f.column) + v * glm::dvec3(f.row);
}

/// Throws error(invalid_argument) for an inconsistent or non-finite level; `what` names it.
void validate_level(const char* what, const cube_image& c);

/// For one face size n, per texel (row-major, the same for all six faces): the unit direction
/// of the texel centre in face-local coordinates (u, v, 1) / |(u, v, 1)| in x, y, z and the
/// exact solid angle in w. Built from the (n+1)^2 corner values of the area-element formula.
struct face_table {
  int n = 0;
  std::vector<glm::vec4> texels;
  explicit face_table(int size);
  /// Shared table of one size (in the table cache of hemilight/memory.hpp). Thread-safe.
  static std::shared_ptr<const face_table> get(int size);
};

/// A cube-map level seen through a pointer (the C ABI samples the caller's memory in place).
using raw_cube = cube_level_view;

/// sample_bilinear and sample_lod on raw levels (same behaviour and preconditions).
glm::vec4 sample_bilinear_raw(const raw_cube& level, const glm::vec3& direction, cube_sampling mode) noexcept;
glm::vec4 sample_lod_raw(const raw_cube* levels, int level_count, const glm::vec3& direction, float lod,
                         cube_sampling mode) noexcept;

}  // namespace hemilight::cubemap_detail
