// hemilight/geometry.hpp — hemicube layout and exact texel weights, OpenGL cube-map faces,
// orthonormal frames.
//
// Everything else in hemilight stands on these conventions (docs/conventions.md):
//
// Hemicube of resolution N (even, 2..4096) in its local frame, normal = +z:
//
//   face     index  plane    forward a   column axis c   row axis r   size (cols x rows)
//   top        0    z = +1      +z          +x              +y          N x N
//   pos_x      1    x = +1      +x          +y              +z          N x N/2
//   neg_x      2    x = -1      -x          -y              +z          N x N/2
//   pos_y      3    y = +1      +y          -x              +z          N x N/2
//   neg_y      4    y = -1      -y          +x              +z          N x N/2
//
// The column axis of a side face is c = z x a, so the four side faces are the same face turned
// by 90 degrees about z (pos_x -> pos_y -> neg_x -> neg_y), and every face has c x r = a.
// Texel (col x, row y) of a face covers face coordinates
//   u in [-1 + 2x/N, -1 + 2(x+1)/N]   along c,
//   v in [-1 + 2y/N, -1 + 2(y+1)/N]   along r (top face), or
//   v in [     2y/N,      2(y+1)/N]   along r = +z (side faces: row 0 touches the horizon),
// and its unnormalised direction is a + u c + v r. So texel (0, 0) of the top face is the
// corner (-1, -1); rows go towards +y on the top face and upwards (towards +z) on the sides.
//
// Texels are numbered face by face in the order above, row-major inside a face:
//   index = face_offset(face) + y * N + x,  face_offset = 0, N^2, N^2 + N^2/2, ...  (3 N^2 total).
//
// Weights are exact: the solid angle of a texel from the area-element formula
// A(u, v) = atan2(u v, sqrt(u^2 + v^2 + 1)), the projected solid angle (integral of cos(theta)
// d omega) from Lambert's polygon formula on the four corner directions. They sum to 2 pi and pi.
#pragma once

#include "hemilight/error.hpp"

#include <glm/glm.hpp>

#include <array>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace hemilight {

// ---------------------------------------------------------------------------------------------
// Hemicube layout
// ---------------------------------------------------------------------------------------------

/// Smallest and largest hemicube resolution N accepted anywhere in hemilight.
inline constexpr int hemicube_min_resolution = 2;
inline constexpr int hemicube_max_resolution = 4096;

/// The five hemicube faces, in texel-index order.
enum class hemicube_face : int { top = 0, pos_x = 1, neg_x = 2, pos_y = 3, neg_y = 4 };
inline constexpr int hemicube_face_count = 5;

/// A texel addressed by face, column and row.
struct hemicube_texel {
  hemicube_face face;
  int x;  ///< column, 0..N-1
  int y;  ///< row, 0..N-1 on the top face, 0..N/2-1 on the side faces
};

/// Orientation of one face in the local frame: forward axis a (the face plane is a.p = 1),
/// column axis c and row axis r, with c x r = a.
struct hemicube_face_axes {
  glm::vec3 forward, column, row;
};

/// True when N is a valid hemicube resolution: even and in [2, 4096].
constexpr bool is_valid_hemicube_resolution(int n) noexcept {
  return n >= hemicube_min_resolution && n <= hemicube_max_resolution && n % 2 == 0;
}

/// The one statement of the rule above for messages: "" when N is valid, else
/// "<name> <N> is invalid: it must be even and in [2, 4096]", where `name` is the argument in the
/// caller's terms ("resolution", "options->resolution", ...). Every check of a hemicube
/// resolution builds its message here (callers prefix their function's name). Cost: one short
/// string when N is invalid, nothing otherwise.
std::string hemicube_resolution_problem(int n, const std::string& name = "resolution");

/// Throws error(invalid_argument) "<function>: <hemicube_resolution_problem(n, name)>" when N is
/// not a valid hemicube resolution; does nothing otherwise.
void check_hemicube_resolution(int n, const char* function, const std::string& name = "resolution");

/// Total number of texels, 3 N^2. Precondition: N valid.
constexpr std::size_t hemicube_texel_count(int n) noexcept {
  return 3u * static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
}

/// Columns of a face (always N).
constexpr int hemicube_face_width(int n, hemicube_face) noexcept { return n; }

/// Rows of a face: N for the top face, N/2 for a side face.
constexpr int hemicube_face_height(int n, hemicube_face face) noexcept {
  return face == hemicube_face::top ? n : n / 2;
}

/// Index of the first texel of a face.
constexpr std::size_t hemicube_face_offset(int n, hemicube_face face) noexcept {
  const std::size_t nn = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  const int f = static_cast<int>(face);
  return f == 0 ? 0 : nn + static_cast<std::size_t>(f - 1) * (nn / 2);
}

/// Axes of a face (see the table at the top of this header). Exact (components are 0 or +-1).
inline hemicube_face_axes hemicube_axes(hemicube_face face) noexcept {
  switch (face) {
    case hemicube_face::top: return {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
    case hemicube_face::pos_x: return {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    case hemicube_face::neg_x: return {{-1, 0, 0}, {0, -1, 0}, {0, 0, 1}};
    case hemicube_face::pos_y: return {{0, 1, 0}, {-1, 0, 0}, {0, 0, 1}};
    case hemicube_face::neg_y: return {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}};
  }
  return {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
}

/// Texel index of (face, x, y). Precondition: N valid, x and y inside the face (asserted).
inline std::size_t hemicube_texel_index(int n, hemicube_texel t) noexcept {
  assert(is_valid_hemicube_resolution(n));
  assert(t.x >= 0 && t.x < n && t.y >= 0 && t.y < hemicube_face_height(n, t.face));
  return hemicube_face_offset(n, t.face) + static_cast<std::size_t>(t.y) * static_cast<std::size_t>(n) +
         static_cast<std::size_t>(t.x);
}

/// (face, x, y) of a texel index. Precondition: N valid, index < 3 N^2 (asserted).
inline hemicube_texel hemicube_texel_from_index(int n, std::size_t index) noexcept {
  assert(is_valid_hemicube_resolution(n) && index < hemicube_texel_count(n));
  const std::size_t nn = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  const std::size_t un = static_cast<std::size_t>(n);
  if (index < nn) return {hemicube_face::top, static_cast<int>(index % un), static_cast<int>(index / un)};
  const std::size_t side = (index - nn) / (nn / 2);
  const std::size_t local = (index - nn) % (nn / 2);
  return {static_cast<hemicube_face>(1 + side), static_cast<int>(local % un), static_cast<int>(local / un)};
}

/// Face coordinates (u, v) of a texel's lower corner (the corner with the smallest u and v).
/// The texel spans [u, u + 2/N] x [v, v + 2/N]. Exact in double for every valid N.
inline glm::dvec2 hemicube_texel_min_corner(int n, hemicube_texel t) noexcept {
  const double s = 2.0 / n;
  const double v0 = t.face == hemicube_face::top ? -1.0 : 0.0;
  return {-1.0 + s * t.x, v0 + s * t.y};
}

/// Unnormalised direction a + u c + v r of face coordinates (u, v) on a face, in the local
/// frame (a point on the unit cube's surface). Any u, v are accepted.
inline glm::dvec3 hemicube_face_point(hemicube_face face, double u, double v) noexcept {
  const hemicube_face_axes ax = hemicube_axes(face);
  return glm::dvec3(ax.forward) + u * glm::dvec3(ax.column) + v * glm::dvec3(ax.row);
}

/// Unit direction through the centre of a texel, in the local frame (z >= 0). Precondition as
/// hemicube_texel_from_index. Cost: a few flops and one square root.
inline glm::vec3 hemicube_texel_direction(int n, std::size_t index) noexcept {
  const hemicube_texel t = hemicube_texel_from_index(n, index);
  const glm::dvec2 c = hemicube_texel_min_corner(n, t) + glm::dvec2(1.0 / n);
  return glm::vec3(glm::normalize(hemicube_face_point(t.face, c.x, c.y)));
}

/// Unit directions of the four corners of a texel, in the local frame, in the order
/// (u0, v0), (u1, v0), (u1, v1), (u0, v1): counter-clockwise seen from outside the cube
/// looking back at the origin (c x r = a). Precondition as hemicube_texel_from_index.
std::array<glm::dvec3, 4> hemicube_texel_corners(int n, std::size_t index) noexcept;

/// Solid angle of the planar rectangle [u0, u1] x [v0, v1] on a plane at distance 1 from the
/// origin, with (0, 0) the foot of the perpendicular (sr). Exact formula, double precision.
/// Negative when u1 < u0 or v1 < v0 (signed area).
double rectangle_solid_angle(double u0, double v0, double u1, double v1) noexcept;

/// Lambert's polygon formula: the projected solid angle (integral of n.w over the polygon's
/// solid angle) of a spherical polygon with unit vertex directions
/// `dirs` seen from the origin, with respect to the unit normal n. Exact when the polygon is
/// entirely on the side n.w >= 0. The sign follows the vertex order; callers take abs().
/// Uses atan2 for the arc angles, so it stays accurate for tiny polygons.
double lambert_projected_solid_angle(const glm::dvec3* dirs, std::size_t count, const glm::dvec3& n) noexcept;

/// Exact solid angle of one texel (sr), computed on the fly in double. Cost: 4 atan2.
double hemicube_texel_solid_angle(int n, std::size_t index) noexcept;

/// Exact projected solid angle (integral of cos(theta) over the texel, sr) of one texel,
/// computed on the fly in double with Lambert's formula. Cost: 4 atan2, 4 cross products.
double hemicube_texel_projected_solid_angle(int n, std::size_t index) noexcept;

/// Per-texel weights of one resolution, computed once and shared (immutable, thread-safe).
///
/// Memory: 8 bytes per texel, 24 N^2 bytes (N = 64: 98 KiB; N = 512: 6 MiB; N = 4096: 384 MiB).
/// get() keeps tables in the process's table cache (memory.hpp: least recently used ones are
/// dropped beyond its byte budget; a table in use lives while held).
class hemicube_table {
 public:
  /// The shared table of resolution N, built on first use (cost: O(N^2), split over all cores).
  /// Thread-safe.
  /// Throws error(invalid_argument) if N is odd or outside [2, 4096].
  static std::shared_ptr<const hemicube_table> get(int n);

  int resolution() const noexcept { return n_; }
  std::size_t size() const noexcept { return solid_angle_.size(); }
  /// Exact solid angle of each texel (sr), rounded to float; sums to 2 pi.
  const float* solid_angle() const noexcept { return solid_angle_.data(); }
  /// Exact projected solid angle of each texel (sr), rounded to float; sums to pi.
  const float* projected_solid_angle() const noexcept { return projected_solid_angle_.data(); }

  explicit hemicube_table(int n);  ///< builds a private table; prefer get()

 private:
  int n_;
  std::vector<float> solid_angle_;
  std::vector<float> projected_solid_angle_;
};

// ---------------------------------------------------------------------------------------------
// OpenGL cube-map faces
// ---------------------------------------------------------------------------------------------

/// Cube-map faces in OpenGL order (GL_TEXTURE_CUBE_MAP_POSITIVE_X + i).
enum class cube_face : int { pos_x = 0, neg_x = 1, pos_y = 2, neg_y = 3, pos_z = 4, neg_z = 5 };
inline constexpr int cube_face_count = 6;

/// A point on a cube-map face: s, t in [0, 1] as in the OpenGL specification's table
/// (s = (sc / |ma| + 1) / 2, t = (tc / |ma| + 1) / 2). Texel (x, y) of a size-n face covers
/// s in [x/n, (x+1)/n], t in [y/n, (y+1)/n]; row y = 0 is the first row of the face's data.
struct cube_coord {
  cube_face face;
  float s, t;
};

/// Face and (s, t) of a direction, following the OpenGL cube-map face table:
///
///   face  major axis  sc    tc          face  major axis  sc    tc
///   +X    +rx         -rz   -ry         -X    -rx         +rz   -ry
///   +Y    +ry         +rx   +rz         -Y    -ry         +rx   -rz
///   +Z    +rz         +rx   -ry         -Z    -rz         -rx   -ry
///
/// Ties (|rx| = |ry| or |rx| = |rz| or |ry| = |rz| at the maximum, i.e. edges and corners) go to
/// the first axis in the order x, y, z. The direction need not be normalised. Bad input: a zero
/// or non-finite direction returns {pos_x, 0.5, 0.5} (never NaN); validate first if that matters.
inline cube_coord cube_face_from_direction(const glm::vec3& d) noexcept {
  const float ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
  cube_face face;
  float ma, sc, tc;
  if (ax >= ay && ax >= az) {
    ma = ax;
    face = d.x >= 0 ? cube_face::pos_x : cube_face::neg_x;
    sc = d.x >= 0 ? -d.z : d.z;
    tc = -d.y;
  } else if (ay >= az) {
    ma = ay;
    face = d.y >= 0 ? cube_face::pos_y : cube_face::neg_y;
    sc = d.x;
    tc = d.y >= 0 ? d.z : -d.z;
  } else {
    ma = az;
    face = d.z >= 0 ? cube_face::pos_z : cube_face::neg_z;
    sc = d.z >= 0 ? d.x : -d.x;
    tc = -d.y;
  }
  if (!(ma > 0.0f) || !std::isfinite(ma)) return {cube_face::pos_x, 0.5f, 0.5f};
  if (ma < 1e-30f) {  // 1 / ma would overflow for subnormal ma: divide instead (|sc|, |tc| <= ma)
    sc /= ma;
    tc /= ma;
    ma = 1.0f;
  }
  const float inv = 1.0f / ma;
  return {face, 0.5f * (sc * inv + 1.0f), 0.5f * (tc * inv + 1.0f)};
}

/// The (unnormalised, major component +-1) direction of face coordinates (s, t): the inverse of
/// cube_face_from_direction. Any s, t are accepted (values outside [0, 1] extrapolate the face
/// plane). Exact: only sign changes and 2s - 1.
inline glm::vec3 cube_direction_from_face(cube_face face, float s, float t) noexcept {
  const float sc = 2.0f * s - 1.0f, tc = 2.0f * t - 1.0f;
  switch (face) {
    case cube_face::pos_x: return {1.0f, -tc, -sc};
    case cube_face::neg_x: return {-1.0f, -tc, sc};
    case cube_face::pos_y: return {sc, 1.0f, tc};
    case cube_face::neg_y: return {sc, -1.0f, -tc};
    case cube_face::pos_z: return {sc, -tc, 1.0f};
    case cube_face::neg_z: return {-sc, -tc, -1.0f};
  }
  return {1.0f, 0.0f, 0.0f};
}

// ---------------------------------------------------------------------------------------------
// Orthonormal frames
// ---------------------------------------------------------------------------------------------

/// A right-handed orthonormal frame (t, b, n): t x b = n.
struct frame {
  glm::vec3 t, b, n;

  /// Local (x along t, y along b, z along n) to world.
  glm::vec3 to_world(const glm::vec3& local) const noexcept { return t * local.x + b * local.y + n * local.z; }
  /// World to local.
  glm::vec3 to_local(const glm::vec3& world) const noexcept {
    return {glm::dot(world, t), glm::dot(world, b), glm::dot(world, n)};
  }
};

/// Orthonormal frame around a unit normal (Duff et al. 2017, "Building an orthonormal basis,
/// revisited"): branch-free, no division by anything smaller than 1, so no NaN anywhere,
/// including n = (0, 0, -1) and near the poles. Orthonormal to ~1e-7 for unit n.
///
/// Continuity: no tangent field is continuous over the whole sphere (hairy-ball theorem); this
/// one is continuous everywhere except across the equator n.z = 0, where t and b jump. Results
/// that depend on the roll of the frame (hemicube texel boundaries) change there only by their
/// discretisation error. Precondition: |n| = 1 (asserted to 1e-3); n is stored as given.
inline frame make_frame(const glm::vec3& n) noexcept {
  assert(std::fabs(glm::length(n) - 1.0f) < 1e-3f);
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float b = n.x * n.y * a;
  return {{1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x}, {b, sign + n.y * n.y * a, -n.y}, n};
}

}  // namespace hemilight
