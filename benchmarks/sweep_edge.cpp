// Exact edge coverage (raster_options::edge_coverage) against point sampling: accuracy on a
// family of polygon emitters against Lambert's closed form, and cost on the reference scenes.
//   usage: sweep_edge accuracy.csv cost.csv [rounds]
// Accuracy: each polygon (radiance 1, two-sided, sky 0) is rendered by the rasterizer and
// integrated (hemicube_integrator); E is compared with Lambert's formula for the polygon clipped
// to the point's upper hemisphere (computed here in double, independent of the library).
// Families: the rectangle of docs/raster.md's figures (and it stretched across the top/side face
// boundary), rectangles aligned with the texel grid at random positions, rotated rectangles,
// slivers (thin triangles), polygons straddling a top/side face boundary, and walls straddling the
// horizon.
// Cost: hemicubes per second (render + integrate, N = 32, 64, 128) on the reference scenes at
// 256 surface points each, point sampling and edge coverage alternated in paired rounds; the CSV
// has every round, the chart the medians of the per-round ratios.
#include "hemilight/integrate.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/reference_scenes.hpp"

#include "bench_points.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <string>
#include <vector>

using namespace hemilight;
using glm::dvec3;

namespace {

constexpr double pi = 3.14159265358979323846;

// Lambert's formula: the projected solid angle (= irradiance for radiance 1) of the convex
// polygon `poly` (relative to the point) clipped to n . p >= 0.
double lambert(const std::vector<dvec3>& poly, const dvec3& n) {
  std::vector<dvec3> clipped;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const dvec3 &a = poly[i], &b = poly[(i + 1) % poly.size()];
    const double da = glm::dot(n, a), db = glm::dot(n, b);
    if (da >= 0) clipped.push_back(a);
    if ((da >= 0) != (db >= 0)) clipped.push_back(a + (da / (da - db)) * (b - a));
  }
  double sum = 0;
  for (std::size_t i = 0; i < clipped.size(); ++i) {
    const dvec3 u = glm::normalize(clipped[i]), v = glm::normalize(clipped[(i + 1) % clipped.size()]);
    const dvec3 g = glm::cross(u, v);
    const double len = glm::length(g);
    if (len == 0) continue;
    sum += std::atan2(len, glm::dot(u, v)) * glm::dot(n, g) / len;
  }
  return 0.5 * std::fabs(sum);
}

struct polygon_case {
  std::string family;
  int instance;
  std::vector<dvec3> poly;  // world = local frame (the point at the origin, normal +z)
};

std::vector<dvec3> rectangle(const dvec3& centre, const dvec3& u, const dvec3& v) {
  return {centre - u - v, centre + u - v, centre + u + v, centre - u + v};
}

std::vector<polygon_case> cases() {
  std::vector<polygon_case> out;
  const dvec3 eye(0.05, -0.02, 0.0);
  // The rectangle [-0.5, 0.5] x [0.3, 0.9] at z = 1 seen from (0.05, -0.02, 0); stretched to y = 1.3.
  const auto rectangle_to = [&](double y1) {
    return std::vector<dvec3>{dvec3(-0.5, 0.3, 1) - eye, dvec3(0.5, 0.3, 1) - eye, dvec3(0.5, y1, 1) - eye,
                              dvec3(-0.5, y1, 1) - eye};
  };
  out.push_back({"rectangle", 0, rectangle_to(0.9)});
  out.push_back({"rectangle_stretched", 0, rectangle_to(1.3)});
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.0, 1.0);
  const int count = 24;
  for (int i = 0; i < count; ++i) {
    // Grid-aligned rectangles on the plane z = h, inside the top face's view (|x|, |y| < h).
    const double h = 0.6 + 0.8 * pos(rng);
    const double cx = 0.5 * h * u(rng), cy = 0.5 * h * u(rng);
    const double hx = h * (0.05 + 0.3 * pos(rng)), hy = h * (0.05 + 0.3 * pos(rng));
    out.push_back({"grid_aligned", i, rectangle({cx, cy, h}, {hx, 0, 0}, {0, hy, 0})});
  }
  for (int i = 0; i < count; ++i) {
    // Rectangles rotated about the normal and tilted, anywhere in the upper hemisphere.
    const double h = 0.6 + 0.8 * pos(rng);
    const double a = pi * pos(rng), tilt = 0.6 * u(rng);
    const dvec3 du(std::cos(a), std::sin(a), 0), dv(-std::sin(a) * std::cos(tilt), std::cos(a) * std::cos(tilt), std::sin(tilt));
    const dvec3 c(0.8 * h * u(rng), 0.8 * h * u(rng), h);
    out.push_back({"rotated", i, rectangle(c, (0.05 + 0.3 * pos(rng)) * du, (0.05 + 0.3 * pos(rng)) * dv)});
  }
  for (int i = 0; i < count; ++i) {
    // Slivers: triangles 0.3-0.8 long and 0.005-0.03 wide at their base, at random angles.
    const double h = 0.6 + 0.8 * pos(rng);
    const double a = pi * pos(rng);
    const dvec3 d(std::cos(a), std::sin(a), 0.1 * u(rng)), side(-std::sin(a), std::cos(a), 0);
    const dvec3 c(0.6 * h * u(rng), 0.6 * h * u(rng), h);
    const double len = 0.3 + 0.5 * pos(rng), w = 0.005 + 0.025 * pos(rng);
    out.push_back({"sliver", i, {c - 0.5 * len * d - w * side, c - 0.5 * len * d + w * side, c + 0.5 * len * d}});
  }
  for (int i = 0; i < count; ++i) {
    // Rectangles on z = 1 crossing the top face's edge y = 1 (or x = 1) onto a side face.
    const double cx = 0.6 * u(rng), cy = 1.0 + 0.2 * u(rng);
    const bool swap_xy = i % 2 == 1;
    std::vector<dvec3> r = rectangle({cx, cy, 1.0}, {0.1 + 0.3 * pos(rng), 0, 0}, {0, 0.15 + 0.3 * pos(rng), 0});
    if (swap_xy)
      for (dvec3& p : r) p = dvec3(p.y, -p.x, p.z);
    out.push_back({"face_boundary", i, r});
  }
  for (int i = 0; i < count; ++i) {
    // Walls facing the point, crossing the horizon: part below z = 0 is not seen.
    const double a = 2 * pi * pos(rng), d = 0.5 + pos(rng);
    const dvec3 toward(std::cos(a), std::sin(a), 0), side(-std::sin(a), std::cos(a), 0);
    const double z0 = -0.3 * pos(rng) - 0.05, z1 = 0.1 + 0.8 * pos(rng), w = 0.1 + 0.5 * pos(rng);
    const dvec3 c = d * toward + 0.3 * u(rng) * side;
    out.push_back({"horizon", i, {c - w * side + dvec3(0, 0, z0), c + w * side + dvec3(0, 0, z0), c + w * side + dvec3(0, 0, z1),
                                  c - w * side + dvec3(0, 0, z1)}});
  }
  return out;
}

std::shared_ptr<const scene> emitter_scene(const std::vector<dvec3>& poly) {
  scene_mesh m;
  const material emitter{glm::vec3(1.0f), glm::vec3(0.0f), true};
  for (std::size_t k = 1; k + 1 < poly.size(); ++k)
    m.add_triangle(glm::vec3(poly[0]), glm::vec3(poly[k]), glm::vec3(poly[k + 1]), emitter);
  return scene::create(m.desc());
}

void accuracy(FILE* out) {
  std::fprintf(out, "family,instance,N,mode,E,E_ref,rel_err\n");
  const frame f{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int ns[] = {16, 24, 32, 48, 64, 96, 128, 192, 256, 384, 512};
  for (const polygon_case& c : cases()) {
    const double ref = lambert(c.poly, dvec3(0, 0, 1));
    const auto s = emitter_scene(c.poly);
    for (int mode = 0; mode < 2; ++mode) {
      raster_options o;
      o.edge_coverage = mode == 1;
      hemicube_rasterizer r(s, o);
      hemicube_buffer buf;
      for (const int n : ns) {
        r.render({0, 0, 0}, f, n, buf);
        hemicube_integrator integ(n);
        const double e = integ.integrate(buf).irradiance.x;
        std::fprintf(out, "%s,%d,%d,%s,%.9g,%.9g,%.6g\n", c.family.c_str(), c.instance, n, mode ? "edge" : "point", e, ref,
                     (e - ref) / ref);
      }
    }
  }
}

void cost(FILE* out, int rounds) {
  std::fprintf(out, "scene,N,round,point_hemicubes_per_s,edge_hemicubes_per_s,time_ratio\n");
  struct entry {
    const char* name;
    std::function<scene_mesh()> make;
  };
  const entry scenes[] = {{"cornell_box_32", [] { return cornell_box(); }},
                          {"hexagon_room_496", [] { return hexagon_room(2); }},
                          {"hexagon_room_1062", [] { return hexagon_room(3); }},
                          {"heightfield_10k", [] { return heightfield(10000); }}};
  for (const entry& e : scenes) {
    const scene_mesh m = e.make();
    const auto s = scene::create(m.desc());
    const bench::sample_points p = bench::surface_points(m, 256, 1e-4f * s->size());
    raster_options on;
    on.edge_coverage = true;
    hemicube_rasterizer point(s), edge(s, on);
    hemicube_buffer buf;
    for (const int n : {32, 64, 128}) {
      hemicube_integrator integ(n);
      const auto time = [&](hemicube_rasterizer& r) {
        volatile float sink = 0;
        const auto t0 = std::chrono::steady_clock::now();
        for (std::size_t i = 0; i < p.points.size(); ++i) {
          r.render(p.points[i], p.frames[i], n, buf);
          sink = sink + integ.integrate(buf).irradiance.x;
        }
        const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        return static_cast<double>(p.points.size()) / secs;
      };
      time(point);  // warm-up (tables, scratch)
      time(edge);
      for (int k = 0; k < rounds; ++k) {
        // Paired: A then B in even rounds, B then A in odd ones.
        double a, b;
        if (k % 2 == 0) {
          a = time(point);
          b = time(edge);
        } else {
          b = time(edge);
          a = time(point);
        }
        std::fprintf(out, "%s,%d,%d,%.1f,%.1f,%.4f\n", e.name, n, k, a, b, a / b);
        std::fflush(out);
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: sweep_edge accuracy.csv cost.csv [rounds]\n");
    return 1;
  }
  FILE* a = std::fopen(argv[1], "w");
  if (!a) {
    std::fprintf(stderr, "sweep_edge: cannot write '%s'\n", argv[1]);
    return 1;
  }
  accuracy(a);
  std::fclose(a);
  std::printf("wrote %s\n", argv[1]);
  if (std::string(argv[2]) == "-") return 0;
  FILE* c = std::fopen(argv[2], "w");
  if (!c) {
    std::fprintf(stderr, "sweep_edge: cannot write '%s'\n", argv[2]);
    return 1;
  }
  cost(c, argc > 3 ? std::atoi(argv[3]) : 7);
  std::fclose(c);
  std::printf("wrote %s\n", argv[2]);
  return 0;
}
