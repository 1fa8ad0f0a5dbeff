// An independent reference for tests: renders a hemicube buffer by casting one double-precision
// ray per texel centre against a brute-force list of triangles (Moeller-Trumbore), and the
// closed forms of polygon irradiance (Lambert). Written without using the rasterizer or the
// integrator, so tests of those can compare against it.
#pragma once

#include "hemilight/geometry.hpp"
#include "hemilight/hemicube.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace hemilight::test {

struct ref_triangle {
  glm::dvec3 a, b, c;   // counter-clockwise seen from the front: normal (b - a) x (c - a)
  glm::vec3 radiance;   // outgoing radiance of the front face
  bool two_sided = false;
};

/// Adds the quad p0, p1, p2, p3 (counter-clockwise seen from its front) as two triangles.
inline void add_quad(std::vector<ref_triangle>& tris, glm::dvec3 p0, glm::dvec3 p1, glm::dvec3 p2, glm::dvec3 p3,
                     glm::vec3 radiance, bool two_sided = false) {
  tris.push_back({p0, p1, p2, radiance, two_sided});
  tris.push_back({p0, p2, p3, radiance, two_sided});
}

/// Nearest hit along origin + t dir (t > 0), or t = +inf. Sets `back` when the hit is the back
/// face of a one-sided triangle.
inline double cast(const std::vector<ref_triangle>& tris, const glm::dvec3& o, const glm::dvec3& d, int& hit, bool& back) {
  double best = std::numeric_limits<double>::infinity();
  hit = -1;
  back = false;
  for (std::size_t k = 0; k < tris.size(); ++k) {
    const ref_triangle& t = tris[k];
    const glm::dvec3 e1 = t.b - t.a, e2 = t.c - t.a;
    const glm::dvec3 p = glm::cross(d, e2);
    const double det = glm::dot(e1, p);
    if (std::fabs(det) < 1e-300) continue;
    const double inv = 1.0 / det;
    const glm::dvec3 s = o - t.a;
    const double u = glm::dot(s, p) * inv;
    if (u < 0.0 || u > 1.0) continue;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(d, q) * inv;
    if (v < 0.0 || u + v > 1.0) continue;
    const double dist = glm::dot(e2, q) * inv;
    if (dist > 0.0 && dist < best) {
      best = dist;
      hit = static_cast<int>(k);
      back = !t.two_sided && glm::dot(glm::cross(e1, e2), d) > 0.0;
    }
  }
  return best;
}

/// A hemicube buffer of resolution n at `position` with world frame `basis`, one ray per texel
/// centre. Back faces of one-sided triangles: radiance 0 and texel_back_face; misses: sky.
inline hemicube_buffer raycast_hemicube(const std::vector<ref_triangle>& tris, const glm::vec3& sky,
                                        const glm::dvec3& position, const frame& basis, int n) {
  hemicube_buffer buf;
  buf.resize(n);
  buf.position = glm::vec3(position);
  buf.basis = basis;
  const glm::dvec3 t(basis.t), b(basis.b), nn(basis.n);
  for (std::size_t i = 0; i < buf.texel_count(); ++i) {
    const hemicube_texel tx = hemicube_texel_from_index(n, i);
    const glm::dvec2 lo = hemicube_texel_min_corner(n, tx);
    const glm::dvec3 local = glm::normalize(hemicube_face_point(tx.face, lo.x + 1.0 / n, lo.y + 1.0 / n));
    const glm::dvec3 d = glm::normalize(t * local.x + b * local.y + nn * local.z);
    int hit;
    bool back;
    const double dist = cast(tris, position, d, hit, back);
    glm::vec3 l = sky;
    std::uint8_t flag = texel_miss;
    if (hit >= 0) {
      l = back ? glm::vec3(0.0f) : tris[std::size_t(hit)].radiance;
      flag = back ? texel_back_face : texel_hit_front;
    }
    buf.set_radiance(i, l);
    buf.distance[i] = hit >= 0 ? static_cast<float>(dist) : std::numeric_limits<float>::infinity();
    buf.flags[i] = flag;
  }
  return buf;
}

/// Vector irradiance Phi = (L/2) sum beta_i gamma_i of a polygon of constant radiance L seen from
/// p (Lambert). E(n) = n . Phi while the whole polygon is above the horizon of n. The sign is
/// chosen so that Phi points towards the polygon.
inline glm::dvec3 polygon_vector_irradiance(const std::vector<glm::dvec3>& poly, const glm::dvec3& p, double radiance) {
  glm::dvec3 sum(0.0), centroid(0.0);
  for (const glm::dvec3& v : poly) centroid += v;
  centroid /= double(poly.size());
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec3 a = glm::normalize(poly[i] - p), b = glm::normalize(poly[(i + 1) % poly.size()] - p);
    const glm::dvec3 c = glm::cross(a, b);
    sum += std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)) * glm::normalize(c);
  }
  glm::dvec3 phi = 0.5 * radiance * sum;
  if (glm::dot(phi, centroid - p) < 0.0) phi = -phi;
  return phi;
}

}  // namespace hemilight::test
