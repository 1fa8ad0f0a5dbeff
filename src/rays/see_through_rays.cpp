// Ray queries against the see-through triangles (scene::see_through_triangles()) without Embree:
// the fallback's share of rays.hpp's contract for alpha-tested and translucent triangles. They are
// few next to the opaque ones (foliage cards, panes), so each query tests them all in turn with a
// double-precision Moller-Trumbore test (hits at 0 < t < t_max, either face). Not watertight at
// shared edges: a ray through an edge of two see-through triangles, within rounding, may miss both
// (Embree's robust test, which serves every scene it can build, is watertight).
#include "ray_accel.hpp"

#include <cmath>

namespace hemilight {
namespace detail {

namespace {

// t (units of |d|) and barycentrics (b1, b2) of the ray's hit on tri, or false.
bool hit_triangle(const scene::triangle& tri, const glm::vec3& o, const glm::vec3& d, float t_max, double& t, double& b1,
                  double& b2) noexcept {
  const glm::dvec3 v0(tri.v0), e1 = glm::dvec3(tri.v1) - v0, e2 = glm::dvec3(tri.v2) - v0, dd(d);
  const glm::dvec3 p = glm::cross(dd, e2);
  const double det = glm::dot(e1, p);
  if (det == 0.0 || !std::isfinite(det)) return false;
  const double inv = 1.0 / det;
  const glm::dvec3 s = glm::dvec3(o) - v0;
  b1 = glm::dot(s, p) * inv;
  if (b1 < 0.0 || b1 > 1.0) return false;
  const glm::dvec3 q = glm::cross(s, e1);
  b2 = glm::dot(dd, q) * inv;
  if (b2 < 0.0 || b1 + b2 > 1.0) return false;
  t = glm::dot(e2, q) * inv;
  return t > 0.0 && t < double(t_max);
}

}  // namespace

bool see_through_occluded(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept {
  for (const scene::triangle& tri : s.see_through_triangles()) {
    double t, b1, b2;
    if (hit_triangle(tri, origin, direction, t_max, t, b1, b2) &&
        s.alpha_present(tri.index, static_cast<float>(b1), static_cast<float>(b2)))
      return true;
  }
  return false;
}

glm::vec3 see_through_transmittance(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept {
  glm::vec3 through(1.0f);
  // The translucent crossings counted so far (a ray through an edge two triangles of one pane
  // share hits both: counted once, same_layer).
  constexpr int max_seen = 16;
  std::uint32_t seen_tri[max_seen];
  float seen_t[max_seen];
  int seen = 0;
  for (const scene::triangle& tri : s.see_through_triangles()) {
    double t, b1, b2;
    if (!hit_triangle(tri, origin, direction, t_max, t, b1, b2)) continue;
    const material& m = s.triangle_material(tri.index);
    if (m.opacity == surface_opacity::translucent) {
      bool again = false;
      for (int k = 0; k < seen && !again; ++k) again = same_layer(s, seen_tri[k], seen_t[k], tri.index, float(t));
      if (again) continue;
      if (seen < max_seen) {
        seen_tri[seen] = tri.index;
        seen_t[seen++] = float(t);
      }
      through *= m.transmittance;
    } else if (s.alpha_present(tri.index, static_cast<float>(b1), static_cast<float>(b2)))
      return glm::vec3(0.0f);
  }
  return through;
}

bool see_through_closest(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max,
                         ray_hit& hit) noexcept {
  const std::vector<scene::triangle>& tris = s.see_through_triangles();
  double best = double(t_max);
  std::size_t found = tris.size();
  for (std::size_t j = 0; j < tris.size(); ++j) {
    double t, b1, b2;
    if (!hit_triangle(tris[j], origin, direction, t_max, t, b1, b2) || !(t < best)) continue;
    if (!s.alpha_present(tris[j].index, static_cast<float>(b1), static_cast<float>(b2))) continue;
    best = t;
    found = j;
  }
  if (found == tris.size()) return false;
  const scene::triangle& tri = tris[found];
  hit.distance = static_cast<float>(best);
  hit.drawable = static_cast<std::uint32_t>(s.triangles().size() + found);
  hit.triangle = tri.index;
  hit.front_face = glm::dot(glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0), direction) < 0.0f;
  return true;
}

}  // namespace detail
}  // namespace hemilight
