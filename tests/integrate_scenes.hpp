// Small scenes with closed-form irradiance, shared by the integration tests and the
// integration accuracy sweep (benchmarks/sweep_integrate.cpp). Each scene gives triangles for
// the reference ray caster and E(x) in closed form (Lambert's polygon formula, with the visible
// part of an emitter clipped exactly where an occluder edge hides it), so gradients can be taken
// by finite differences of the closed form in double precision.
#pragma once

#include "raycast_reference.hpp"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <string>

namespace hemilight::test {

/// Clips a convex polygon by the half-space dot(q - origin, normal) >= 0 (Sutherland-Hodgman).
inline std::vector<glm::dvec3> clip_polygon(const std::vector<glm::dvec3>& poly, const glm::dvec3& origin,
                                            const glm::dvec3& normal) {
  std::vector<glm::dvec3> out;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec3& a = poly[i];
    const glm::dvec3& b = poly[(i + 1) % poly.size()];
    const double da = glm::dot(a - origin, normal), db = glm::dot(b - origin, normal);
    if (da >= 0) out.push_back(a);
    if ((da >= 0) != (db >= 0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

struct closed_form_scene {
  std::string name;
  std::vector<ref_triangle> tris;
  glm::vec3 sky{0.0f};
  glm::dvec3 position;
  glm::dvec3 normal;
  /// Irradiance (one channel; the scenes are grey, radiance 1 scaled per channel by `tint`) at
  /// point x with normal n, exact.
  std::function<double(const glm::dvec3& x, const glm::dvec3& n)> irradiance;
  glm::vec3 tint{1.0f};
};

/// A quad emitter above the point, nothing else (sky 0). E(x, n) = n . Phi(x).
inline closed_form_scene unoccluded_emitter() {
  closed_form_scene s;
  s.name = "unoccluded emitter";
  s.tint = {1.0f, 0.5f, 0.25f};
  const std::vector<glm::dvec3> quad = {{-0.3, -0.2, 1.0}, {-0.3, 0.4, 1.0}, {0.5, 0.4, 1.0}, {0.5, -0.2, 1.0}};
  add_quad(s.tris, quad[0], quad[1], quad[2], quad[3], s.tint);
  s.position = {0.0, 0.0, 0.0};
  s.normal = glm::normalize(glm::dvec3(0.1, -0.05, 1.0));
  s.irradiance = [quad](const glm::dvec3& x, const glm::dvec3& n) { return glm::dot(n, polygon_vector_irradiance(quad, x, 1.0)); };
  return s;
}

/// The same emitter with a large black two-sided occluder a quarter of the way up that hides
/// everything of the emitter seen through x < 0.1 (at height 0.25). The visible part is the
/// emitter clipped by the plane through the point and the occluder's edge.
inline closed_form_scene occluded_emitter() {
  closed_form_scene s;
  s.name = "emitter behind a near occluder edge";
  s.tint = {1.0f, 0.5f, 0.25f};
  const std::vector<glm::dvec3> quad = {{-0.3, -0.2, 1.0}, {-0.3, 0.4, 1.0}, {0.5, 0.4, 1.0}, {0.5, -0.2, 1.0}};
  add_quad(s.tris, quad[0], quad[1], quad[2], quad[3], s.tint);
  const double h = 0.25, edge = 0.1;
  add_quad(s.tris, {-3, -3, h}, {edge, -3, h}, {edge, 3, h}, {-3, 3, h}, glm::vec3(0.0f), true);
  s.position = {0.0, 0.0, 0.0};
  s.normal = {0.0, 0.0, 1.0};
  s.irradiance = [quad, h, edge](const glm::dvec3& x, const glm::dvec3& n) {
    const glm::dvec3 e(edge, x.y, h);  // a point of the occluder's edge line (direction y)
    glm::dvec3 plane_n = glm::cross(glm::dvec3(0, 1, 0), e - x);
    if (plane_n.x < 0) plane_n = -plane_n;  // the visible side is towards +x
    const std::vector<glm::dvec3> visible = clip_polygon(quad, x, plane_n);
    return visible.size() < 3 ? 0.0 : glm::dot(n, polygon_vector_irradiance(visible, x, 1.0));
  };
  return s;
}

/// A point on the ground 0.3 from a tall black wall, under a uniform sky of radiance 1:
/// E = pi - (projected solid angle of the wall rectangle). The wall is seen edge-on at its
/// foot, the hard case for wall-based gradients (docs/integration.md).
inline closed_form_scene beside_wall_under_sky() {
  closed_form_scene s;
  s.name = "beside a tall wall under a sky";
  s.sky = glm::vec3(1.0f);
  const std::vector<glm::dvec3> wall = {{0, -4, 0}, {0, 4, 0}, {0, 4, 3}, {0, -4, 3}};
  add_quad(s.tris, wall[0], wall[1], wall[2], wall[3], glm::vec3(0.0f));
  s.position = {0.3, 0.0, 0.0};
  s.normal = {0.0, 0.0, 1.0};
  s.irradiance = [wall](const glm::dvec3& x, const glm::dvec3& n) {
    return 3.14159265358979323846 - glm::dot(n, polygon_vector_irradiance(wall, x, 1.0));
  };
  return s;
}

/// A point on a wall (normal +x) just under the plane of a horizontal emitter (radiance 1, facing
/// down, 0.05 to 0.35 in front of the wall, 0.3 wide), sky 0: the emitter is seen edge-on, as the
/// Cornell box's walls see its light just under the ceiling. E grows about linearly with the
/// depth under the emitter's plane; the emitter's outline in the hemicube is a sliver about
/// depth / 0.05 rad tall at its near edge.
inline closed_form_scene emitter_seen_edge_on(double depth) {
  closed_form_scene s;
  char name[64];
  std::snprintf(name, sizeof name, "emitter seen edge-on %.3g mm under its plane", 1000.0 * depth);
  s.name = name;
  const std::vector<glm::dvec3> quad = {{0.05, depth, -0.15}, {0.35, depth, -0.15}, {0.35, depth, 0.15}, {0.05, depth, 0.15}};
  add_quad(s.tris, quad[0], quad[1], quad[2], quad[3], glm::vec3(1.0f));
  s.position = {0.0, 0.0, 0.0};
  s.normal = {1.0, 0.0, 0.0};
  s.irradiance = [quad](const glm::dvec3& x, const glm::dvec3& n) {
    if (x.y >= quad[0].y) return 0.0;  // at or above the plane: only its back (or nothing) is seen
    return glm::dot(n, polygon_vector_irradiance(quad, x, 1.0));
  };
  return s;
}

/// A lit room 2 x 2 x 2 (inward-facing quads of different radiance, a bright panel set into the
/// ceiling), the point on the floor 0.15 from the dim left wall. Every quad is convex and fully
/// visible from inside the room, so E(x, n) = sum_q L_q n . Phi(q clipped to the horizon of
/// (x, n)); quads lying in the horizon plane contribute nothing.
inline closed_form_scene lit_room() {
  closed_form_scene s;
  s.name = "near a wall of a lit room";
  struct quad { std::vector<glm::dvec3> v; double l; };
  std::vector<quad> quads = {
      {{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, 0.3},      // floor, facing +z
      {{{-1, -1, 0}, {-1, 1, 0}, {-1, 1, 2}, {-1, -1, 2}}, 0.1},    // left wall x = -1, facing +x
      {{{1, -1, 0}, {1, -1, 2}, {1, 1, 2}, {1, 1, 0}}, 0.6},        // right wall, facing -x
      {{{-1, 1, 0}, {1, 1, 0}, {1, 1, 2}, {-1, 1, 2}}, 0.25},       // back wall y = 1, facing -y
      {{{-1, -1, 0}, {-1, -1, 2}, {1, -1, 2}, {1, -1, 0}}, 0.2},    // front wall, facing +y
      {{{-0.3, -0.3, 2}, {-0.3, 0.3, 2}, {0.3, 0.3, 2}, {0.3, -0.3, 2}}, 5.0},  // panel in the ceiling, facing -z
      // the ceiling around the panel: four quads, facing -z
      {{{-1, -1, 2}, {-1, 1, 2}, {-0.3, 1, 2}, {-0.3, -1, 2}}, 0.4},
      {{{0.3, -1, 2}, {0.3, 1, 2}, {1, 1, 2}, {1, -1, 2}}, 0.4},
      {{{-0.3, -1, 2}, {-0.3, -0.3, 2}, {0.3, -0.3, 2}, {0.3, -1, 2}}, 0.4},
      {{{-0.3, 0.3, 2}, {-0.3, 1, 2}, {0.3, 1, 2}, {0.3, 0.3, 2}}, 0.4},
  };
  for (const quad& q : quads) add_quad(s.tris, q.v[0], q.v[1], q.v[2], q.v[3], glm::vec3(float(q.l)));
  s.position = {-0.85, 0.2, 0.0};
  s.normal = {0.0, 0.0, 1.0};
  s.irradiance = [quads](const glm::dvec3& x, const glm::dvec3& n) {
    double e = 0.0;
    for (const quad& q : quads) {
      // A quad whose plane holds x (the floor under the point) contributes nothing, to first
      // order in any rotation too; one wholly below the horizon contributes nothing.
      const glm::dvec3 qn = glm::normalize(glm::cross(q.v[1] - q.v[0], q.v[2] - q.v[0]));
      if (std::fabs(glm::dot(x - q.v[0], qn)) < 1e-9) continue;
      bool above = false;
      for (const glm::dvec3& v : q.v) above = above || glm::dot(v - x, n) > 1e-12;
      if (!above) continue;
      const std::vector<glm::dvec3> visible = clip_polygon(q.v, x, n);
      if (visible.size() >= 3) e += q.l * glm::dot(n, polygon_vector_irradiance(visible, x, 1.0));
    }
    return e;
  };
  return s;
}

/// Rotation gradient of the closed form by central differences of E(x, n rotated by +-1e-5 rad
/// towards t and b): dE/da towards t is g_r . b, towards b it is -g_r . t.
inline glm::dvec3 closed_form_rotation_gradient(const closed_form_scene& s) {
  const double a = 1e-5;
  const frame f = make_frame(glm::vec3(s.normal));
  const glm::dvec3 t(f.t), b(f.b), n(f.n);
  auto e = [&](const glm::dvec3& axis, double angle) { return s.irradiance(s.position, std::cos(angle) * n + std::sin(angle) * axis); };
  const double towards_t = (e(t, a) - e(t, -a)) / (2 * a), towards_b = (e(b, a) - e(b, -a)) / (2 * a);
  return towards_t * b - towards_b * t;
}

/// The frame of `normal` (make_frame) turned about the normal by `roll` radians. Tests render
/// with a roll so that the hemicube's texel grid is not aligned with the scenes' axis-aligned
/// edges (aligned, texel centres fall exactly on edges and the error is systematic).
inline frame rolled_frame(const glm::dvec3& normal, double roll) {
  const frame base = make_frame(glm::vec3(normal));
  frame f = base;
  f.t = float(std::cos(roll)) * base.t + float(std::sin(roll)) * base.b;
  f.b = glm::cross(f.n, f.t);
  return f;
}

/// Gradient of the closed form by central differences in double (step 1e-5: truncation ~1e-10,
/// rounding ~1e-11 relative), projected on the tangent plane of n. One channel (radiance 1).
inline glm::dvec3 closed_form_translation_gradient(const closed_form_scene& s) {
  const double h = 1e-5;
  const frame f = make_frame(glm::vec3(s.normal));
  const glm::dvec3 t(f.t), b(f.b);
  const double dt = (s.irradiance(s.position + h * t, s.normal) - s.irradiance(s.position - h * t, s.normal)) / (2 * h);
  const double db = (s.irradiance(s.position + h * b, s.normal) - s.irradiance(s.position - h * b, s.normal)) / (2 * h);
  return dt * t + db * b;
}

}  // namespace hemilight::test
