// The sample points the benchmarks render hemicubes at, shared so that the timed benchmarks
// (bench_raster, bench_integrate) and the instruction-count driver (count_hemicubes) measure the
// same workload.
#pragma once

#include "hemilight/geometry.hpp"
#include "hemilight/scene.hpp"

#include <algorithm>
#include <cstddef>
#include <random>
#include <vector>

namespace hemilight::bench {

struct sample_points {
  std::vector<glm::vec3> points;
  std::vector<frame> frames;
};

/// `count` area-weighted pseudo-random points on the triangles of `m` (fixed seed 2024), each
/// with the frame of its triangle's front normal, lifted along it by `lift` (scene units).
/// Zero-area triangles are never picked.
inline sample_points surface_points(const scene_mesh& m, std::size_t count, float lift) {
  std::vector<double> cumulative(m.triangle_count());
  double total = 0;
  for (std::size_t i = 0; i < m.triangle_count(); ++i) {
    const glm::dvec3 a(m.positions[m.indices[3 * i]]), p(m.positions[m.indices[3 * i + 1]]),
        c(m.positions[m.indices[3 * i + 2]]);
    total += glm::length(glm::cross(p - a, c - a));
    cumulative[i] = total;
  }
  sample_points out;
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  while (out.points.size() < count && total > 0) {
    const double x = u(rng) * total;
    const auto i = static_cast<std::size_t>(std::lower_bound(cumulative.begin(), cumulative.end(), x) - cumulative.begin());
    if (i >= m.triangle_count()) continue;
    const glm::vec3 a = m.positions[m.indices[3 * i]], p = m.positions[m.indices[3 * i + 1]],
                    c = m.positions[m.indices[3 * i + 2]];
    glm::vec3 n = glm::cross(p - a, c - a);
    if (glm::length(n) == 0.0f) continue;
    n = glm::normalize(n);
    double s = u(rng), t = u(rng);
    if (s + t > 1) {
      s = 1 - s;
      t = 1 - t;
    }
    out.points.push_back(a + static_cast<float>(s) * (p - a) + static_cast<float>(t) * (c - a) + lift * n);
    out.frames.push_back(make_frame(n));
  }
  return out;
}

/// The points of the render + integrate target, 20k hemicubes/s (bench_integrate): an 8 x 8 grid
/// on the Cornell box's floor (1 mm above it, normal +y) interleaved with one on its back wall
/// (normal -z), 128 points.
inline sample_points cornell_floor_and_back_wall() {
  sample_points out;
  for (int k = 0; k < 64; ++k) {
    const float u = (float(k % 8) + 0.5f) / 8.0f, v = (float(k / 8) + 0.5f) / 8.0f;
    out.points.push_back({0.556f * u, 0.001f, 0.559f * v});
    out.frames.push_back(make_frame({0, 1, 0}));
    out.points.push_back({0.556f * u, 0.5488f * v, 0.558f});
    out.frames.push_back(make_frame({0, 0, -1}));
  }
  return out;
}

}  // namespace hemilight::bench
