// Small helpers the sweeps share: luminance, elapsed seconds, the machine's load, lists.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace hemilight::bench {

/// Rec. 709 luminance of a linear RGB value.
inline float lum(const glm::vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

/// Seconds since t0 (steady clock).
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The one-minute load average (/proc/loadavg), or -1 where it cannot be read: written next to
/// timings so that a loaded machine shows in the CSVs.
inline double loadavg() {
  double l = -1.0;
  if (FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf", &l) != 1) l = -1.0;
    std::fclose(f);
  }
  return l;
}

/// k x k points at the texel centres of the parallelogram o + s u + t v (s, t in (0, 1)), normal
/// n, 1 mm off the surface along n (the sweeps' points of a surface), appended to p and normals.
inline void grid_points(std::vector<glm::vec3>& p, std::vector<glm::vec3>& normals, glm::vec3 o, glm::vec3 u, glm::vec3 v,
                        glm::vec3 n, int k) {
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) {
      const float s = (float(i) + 0.5f) / float(k), t = (float(j) + 0.5f) / float(k);
      p.push_back(o + s * u + t * v + 1e-3f * n);
      normals.push_back(n);
    }
}

/// k x k grid points on each of the Cornell box's (reference_scenes.hpp) floor, back wall and
/// side walls, in that order.
inline void cornell_box_grid(std::vector<glm::vec3>& p, std::vector<glm::vec3>& normals, int k) {
  const float W = 0.556f, H = 0.5488f, D = 0.5592f;
  grid_points(p, normals, {0, 0, 0}, {W, 0, 0}, {0, 0, D}, {0, 1, 0}, k);   // floor
  grid_points(p, normals, {0, 0, D}, {W, 0, 0}, {0, H, 0}, {0, 0, -1}, k);  // back wall
  grid_points(p, normals, {0, 0, 0}, {0, 0, D}, {0, H, 0}, {1, 0, 0}, k);   // green wall (x = 0)
  grid_points(p, normals, {W, 0, 0}, {0, 0, D}, {0, H, 0}, {-1, 0, 0}, k);  // red wall
}

/// The comma-separated items of s ("a,b,,c" gives a, b, c).
inline std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::size_t b = 0;
  while (b <= s.size()) {
    const std::size_t e = std::min(s.find(',', b), s.size());
    if (e > b) out.push_back(s.substr(b, e - b));
    b = e + 1;
  }
  return out;
}

}  // namespace hemilight::bench
