// sweep_lod OUT.csv [--points K] [--rounds R]: what raster_options::lod_texels changes on the
// stand-in levels (docs/raster.md, "Level of detail"): per level, N (32, 64, 128) and threshold
// (1, 2, 4, 8 texels), the relative RMS and worst error of the irradiance of K hemicubes at
// surface points (as a bake places them) against the exact render, the nodes drawn from proxies,
// and the time per hemicube against the exact render's in paired interleaved rounds (median of the
// per-round ratios). Culling as by default (on: the levels are over diagnostics.occlusion_min_triangles).
#include "hemilight/integrate.hpp"
#include "hemilight/levels.hpp"
#include "hemilight/raster.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

struct point {
  glm::vec3 p, n;
};

// K points on the level's surfaces, 1 cm above them, from a fixed splitmix64 stream.
std::vector<point> surface_points(const scene_mesh& m, std::size_t k) {
  std::vector<point> out;
  std::uint64_t state = 0x9e3779b97f4a7c15ull;
  const auto next = [&] {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  };
  const auto unit = [&] { return double(next() >> 11) / double(1ull << 53); };
  while (out.size() < k) {
    const std::size_t t = next() % m.triangle_count();
    const glm::dvec3 a(m.positions[m.indices[3 * t]]), b(m.positions[m.indices[3 * t + 1]]), c(m.positions[m.indices[3 * t + 2]]);
    const glm::dvec3 nn = glm::cross(b - a, c - a);
    if (!(glm::length(nn) > 1e-9 * glm::dot(b - a, b - a))) continue;
    double r1 = unit(), r2 = unit();
    if (r1 + r2 > 1.0) r1 = 1.0 - r1, r2 = 1.0 - r2;
    const glm::dvec3 n = glm::normalize(nn);
    out.push_back({glm::vec3(a + r1 * (b - a) + r2 * (c - a) + 0.01 * n), glm::vec3(n)});
  }
  return out;
}

float luminance(const glm::vec3& e) { return 0.2126f * e.x + 0.7152f * e.y + 0.0722f * e.z; }

// The luminance of the irradiance at every point; the seconds it took through *seconds.
std::vector<float> irradiance(hemicube_rasterizer& r, const std::vector<point>& pts, int n, double* seconds, double* lod_nodes) {
  std::vector<float> out(pts.size());
  hemicube_buffer b;
  double nodes = 0.0;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < pts.size(); ++i) {
    r.render(pts[i].p, make_frame(pts[i].n), n, b);
    out[i] = luminance(integrate(b).irradiance);
    nodes += double(r.statistics().lod_nodes);
  }
  *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (lod_nodes) *lod_nodes = nodes / double(pts.size());
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: sweep_lod OUT.csv [--points K] [--rounds R]\n");
    return 2;
  }
  std::size_t k = 200;
  int rounds = 5;
  for (int i = 2; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--points")) k = std::strtoull(argv[i + 1], nullptr, 10);
    if (!std::strcmp(argv[i], "--rounds")) rounds = std::atoi(argv[i + 1]);
  }
  FILE* out = std::fopen(argv[1], "w");
  if (!out) return 1;
  std::fprintf(out, "level,triangles,N,lod_texels,rms_error,max_error,lod_nodes,exact_us,lod_us,time_ratio\n");
  for (const std::string& name : level_names()) {
    scene_mesh m = make_level(name).mesh;
    // Each material emits its albedo and the sky is 1: every surface shows up in the hemicubes.
    for (material& mat : m.materials) mat.emission = mat.albedo;
    m.sky_radiance = glm::vec3(1.0f);
    const auto s = scene::create(m.desc());
    const std::vector<point> pts = surface_points(m, k);
    for (int n : {32, 64, 128}) {
      hemicube_rasterizer exact(s);
      double t_exact = 0.0;
      const std::vector<float> ref = irradiance(exact, pts, n, &t_exact, nullptr);
      for (float lt : {1.0f, 2.0f, 4.0f, 8.0f}) {
        raster_options o;
        o.lod_texels = lt;
        hemicube_rasterizer lod(s, o);
        double t = 0.0, nodes = 0.0;
        const std::vector<float> e = irradiance(lod, pts, n, &t, &nodes);
        double sum = 0.0, worst = 0.0;
        for (std::size_t i = 0; i < pts.size(); ++i) {
          const double err = std::fabs(double(e[i]) - ref[i]) / std::max(double(ref[i]), 1e-6);
          sum += err * err;
          worst = std::max(worst, err);
        }
        // Paired rounds: exact and LOD in turn, the median of the per-round time ratios.
        std::vector<double> ratio, te, tl;
        for (int r = 0; r < rounds; ++r) {
          double a = 0.0, b = 0.0;
          irradiance(exact, pts, n, &a, nullptr);
          irradiance(lod, pts, n, &b, nullptr);
          ratio.push_back(b / a);
          te.push_back(a);
          tl.push_back(b);
        }
        const auto median = [](std::vector<double> v) {
          std::sort(v.begin(), v.end());
          return v[v.size() / 2];
        };
        const double us = 1e6 / double(pts.size());
        std::fprintf(out, "%s,%zu,%d,%g,%.6g,%.6g,%.3f,%.2f,%.2f,%.4f\n", name.c_str(), m.triangle_count(), n, double(lt),
                     std::sqrt(sum / double(pts.size())), worst, nodes, us * median(te), us * median(tl), median(ratio));
        std::fflush(out);
        std::printf("%s N=%d lod %.0f: RMS %.4f%% max %.3f%%, %.1f proxies, time x%.3f\n", name.c_str(), n, double(lt),
                    100.0 * std::sqrt(sum / double(pts.size())), 100.0 * worst, nodes, median(ratio));
      }
    }
  }
  std::fclose(out);
  return 0;
}
