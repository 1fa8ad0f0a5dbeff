// Speed against accuracy of the irradiance cache (issue 5's benchmark).
//   usage: sweep_cache out.csv [grid]      (grid: points per side of each surface, default 128)
// Scenes (reference_scenes.hpp): the Cornell box floor and walls; the hexagon room's ceiling
// (lit by the sky through the window); the ground of "sky and occluders". Points lie on a grid
// over those surfaces (under the boxes they are inside geometry: invalid, filled, and left out of
// the error). Reference: a hemicube at every point with the same sampler (N = 64, same roll), so
// the error is the cache's interpolation error alone. For each a in {0.05 ... 0.5}, with and
// without gradients: fraction of points given a hemicube, RMS and max relative error (luminance;
// relative to max(E_ref, 5% of the mean E_ref), so umbra points do not divide by ~0), wall time.
// A second, converged reference (N = 256 at every 7th point) gives the total error of the cache
// and, for comparison, of the N = 64 hemicube at every point: near grazing emitters and small
// windows the N = 64 hemicubes alias by several percent from point to point, which the first
// error counts against the cache although the cache is not the one that is wrong.
#include "hemilight/cache.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/reference_scenes.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

struct point_set {
  std::string name;
  scene_mesh mesh;
  std::vector<glm::vec3> p, n;
};

// Grid of k x k points on the parallelogram o + s u + t v (s, t in (0, 1)), normal n, offset 1 mm
// along n so the points sit just off their surface.
void grid(point_set& ps, glm::vec3 o, glm::vec3 u, glm::vec3 v, glm::vec3 n, int k) {
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) {
      const float s = (float(i) + 0.5f) / float(k), t = (float(j) + 0.5f) / float(k);
      ps.p.push_back(o + s * u + t * v + 1e-3f * n);
      ps.n.push_back(n);
    }
}

float lum(const glm::vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

}  // namespace

int main(int argc, char** argv) {
  const char* path = argc > 1 ? argv[1] : "cache_sweep.csv";
  const int k = argc > 2 ? std::atoi(argv[2]) : 128;
  FILE* out = std::fopen(path, "w");
  if (!out) {
    std::fprintf(stderr, "sweep_cache: cannot write '%s'\n", path);
    return 1;
  }
  std::fprintf(out, "scene,points,a,gradients,hemicubes,fraction,rms_rel_err,max_rel_err,rms_rel_err_converged,"
                    "reference_rms_rel_err_converged,seconds,reference_seconds\n");

  std::vector<point_set> sets(3);
  sets[0].name = "cornell box";
  sets[0].mesh = cornell_box();
  const float W = 0.556f, H = 0.5488f, D = 0.5592f;
  grid(sets[0], {0, 0, 0}, {W, 0, 0}, {0, 0, D}, {0, 1, 0}, k);        // floor
  grid(sets[0], {0, 0, D}, {W, 0, 0}, {0, H, 0}, {0, 0, -1}, k);       // back wall
  grid(sets[0], {0, 0, 0}, {0, 0, D}, {0, H, 0}, {1, 0, 0}, k);        // green wall (x = 0)
  grid(sets[0], {W, 0, 0}, {0, 0, D}, {0, H, 0}, {-1, 0, 0}, k);       // red wall
  sets[1].name = "hexagon room ceiling";
  sets[1].mesh = hexagon_room();
  {
    point_set tmp;
    grid(tmp, {-4, 3, -4}, {8, 0, 0}, {0, 0, 8}, {0, -1, 0}, k);
    for (std::size_t i = 0; i < tmp.p.size(); ++i) {
      // inside the hexagon (circumradius 4, corners at 60 i degrees): |x| <= 4 - |z| / sqrt3 and |z| <= 2 sqrt3
      const float x = std::fabs(tmp.p[i].x), z = std::fabs(tmp.p[i].z);
      if (z < 3.4f && x < 3.95f - z / 1.7320508f) {
        sets[1].p.push_back(tmp.p[i]);
        sets[1].n.push_back(tmp.n[i]);
      }
    }
  }
  sets[2].name = "sky and occluders";
  sets[2].mesh = sky_and_occluders();
  grid(sets[2], {-10, 0, -10}, {20, 0, 0}, {0, 0, 20}, {0, 1, 0}, k);

  const int threads = resolve_thread_count(0);
  for (point_set& ps : sets) {
    auto sc = scene::create(ps.mesh.desc());
    hemicube_sampler_options so;
    so.resolution = 64;
    const irradiance_sampler sampler = make_hemicube_sampler(sc, so, threads);
    // Reference: a hemicube at every point.
    const std::size_t count = ps.p.size();
    std::vector<irradiance_sample> ref(count);
    const auto t0 = std::chrono::steady_clock::now();
    parallel_for(count, threads, 64, [&](int w, std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) ref[i] = sampler(w, ps.p[i], ps.n[i]);
    });
    const double ref_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    double mean = 0.0;
    std::size_t valid = 0;
    for (std::size_t i = 0; i < count; ++i)
      if (ref[i].backface_fraction <= 0.1f) {
        mean += lum(ref[i].irradiance);
        ++valid;
      }
    mean /= double(std::max<std::size_t>(valid, 1));
    // Converged reference on a subset.
    std::vector<std::size_t> subset;
    for (std::size_t i = 0; i < count; i += 7)
      if (ref[i].backface_fraction <= 0.1f) subset.push_back(i);
    hemicube_sampler_options fine = so;
    fine.resolution = 256;
    const irradiance_sampler fine_sampler = make_hemicube_sampler(sc, fine, threads);
    std::vector<float> truth(subset.size());
    parallel_for(subset.size(), threads, 16, [&](int w, std::size_t b, std::size_t e) {
      for (std::size_t k2 = b; k2 < e; ++k2) truth[k2] = lum(fine_sampler(w, ps.p[subset[k2]], ps.n[subset[k2]]).irradiance);
    });
    auto rms_converged = [&](auto value_of) {
      double sum = 0.0;
      for (std::size_t k2 = 0; k2 < subset.size(); ++k2) {
        const double err = (double(value_of(subset[k2])) - truth[k2]) / std::max(double(truth[k2]), 0.05 * mean);
        sum += err * err;
      }
      return std::sqrt(sum / double(std::max<std::size_t>(subset.size(), 1)));
    };
    const double ref_total = rms_converged([&](std::size_t i) { return lum(ref[i].irradiance); });
    std::printf("%s: %zu points (%zu valid), reference %.2f s (%.0f hemicubes/s on %d threads)\n", ps.name.c_str(), count,
                valid, ref_seconds, double(count) / ref_seconds, threads);
    for (float a : {0.05f, 0.1f, 0.15f, 0.2f, 0.3f, 0.4f, 0.5f})
      for (bool gradients : {true, false}) {
        cache_options o;
        o.error_threshold = a;
        o.use_gradients = gradients;
        const cache_result r = cache_irradiance(ps.p.data(), ps.n.data(), count, sampler, o);
        double sum = 0.0, worst = 0.0;
        std::size_t m = 0;
        for (std::size_t i = 0; i < count; ++i) {
          if (ref[i].backface_fraction > 0.1f || !r.valid[i]) continue;
          const double e_ref = lum(ref[i].irradiance);
          const double err = std::fabs(lum(r.irradiance[i]) - e_ref) / std::max(e_ref, 0.05 * mean);
          sum += err * err;
          worst = std::max(worst, err);
          ++m;
        }
        const double rms = std::sqrt(sum / double(std::max<std::size_t>(m, 1)));
        const double total = rms_converged([&](std::size_t i) { return lum(r.irradiance[i]); });
        std::fprintf(out, "%s,%zu,%.2f,%d,%zu,%.5f,%.6f,%.6f,%.6f,%.6f,%.4f,%.4f\n", ps.name.c_str(), count, double(a),
                     gradients ? 1 : 0, r.stats.hemicubes, double(r.stats.hemicubes) / double(count), rms, worst, total,
                     ref_total, r.stats.seconds, ref_seconds);
        std::printf("  a = %.2f %-13s %6zu hemicubes (%5.2f%%)  RMS %.4f  max %.3f  vs converged %.4f (N=64 everywhere: %.4f)  %.2f s\n",
                    double(a), gradients ? "gradients" : "no gradients", r.stats.hemicubes,
                    100.0 * double(r.stats.hemicubes) / double(count), rms, worst, total, ref_total, r.stats.seconds);
        std::fflush(stdout);
      }
  }
  std::fclose(out);
  std::printf("wrote %s\n", path);
  return 0;
}
