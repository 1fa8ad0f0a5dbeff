// Hemicubes per second through the C ABI's point entries, beside the C++ rasterizer + integrator
// on the same points (docs/capi.md).
//   usage: sweep_capi OUT_sweep.csv [--rounds R] [--points P]
// Scenes: the Cornell box (32 triangles) and the hexagon room at tessellation 2; P area-weighted
// points on their surfaces (bench_points.hpp, lifted 1e-4 x the scene's size), with their
// triangles' normals. Per round, on the same points at N = 32 and 64, in this order:
//   cpp          hemicube_rasterizer::render + hemicube_integrator::integrate, one thread, the frame
//                the C ABI builds (make_frame of the normal): the C++ throughput
//   sample       hemilight_sample_irradiance, one call per point (from C)
//   sampler      hemilight_sampler_irradiance, one sampler (from C)
//   batch_1 / batch_2  hemilight_sample_irradiance_batch on 1 and 2 threads (from C)
// Each C mode's results are checked bitwise against the cpp mode's irradiance (the same work).
// Rounds alternate the modes, so machine drift hits all alike: per mode the median time over the
// rounds, hemicubes per second from it, and the median over rounds of the per-round ratio to cpp.
// Probes (OUT's "_sweep.csv" replaced by "_probes.csv"): hemilight_sample_probes per second at
// N = 32 and 64 on 1 and 2 threads, at points lifted 1% of the scene's size off its surfaces, and
// the error of hemilight_sh9_irradiance at each point's normal against hemilight_sample_irradiance
// at N = 64 there (relative RMS of luminance, and mean absolute error over mean irradiance): what
// the band limit costs.
// The C loops are in capi_timing.c (C99). About a minute on two cores.
#include "bench_points.hpp"
#include "capi_timing.h"

#include "hemilight/hemicube.hpp"
#include "hemilight/integrate.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/reference_scenes.hpp"
#include "hemilight/scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The scene as the C ABI sees it: one-sided triangles with their emission as radiance.
scene_mesh one_sided(const scene_mesh& m) {
  scene_mesh out = m;
  for (material& mat : out.materials) mat.two_sided = false;
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: sweep_capi OUT.csv [--rounds R] [--points P]\n");
    return 2;
  }
  int rounds = 7;
  std::size_t count = 5000;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--rounds") rounds = std::max(1, std::atoi(argv[i + 1]));
    else if (a == "--points") count = std::size_t(std::max(1, std::atoi(argv[i + 1])));
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  std::FILE* f = std::fopen(argv[1], "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", argv[1]);
    return 1;
  }
  std::fprintf(f, "scene,triangles,mode,resolution,threads,points,rounds,median_seconds,hemicubes_per_second,ratio_to_cpp\n");
  // The probes' CSV beside it: OUT with "_sweep.csv" (or ".csv") replaced by "_probes.csv".
  std::string probes_path = argv[1];
  for (const char* tail : {"_sweep.csv", ".csv"})
    if (probes_path.size() > std::strlen(tail) && probes_path.compare(probes_path.size() - std::strlen(tail), std::string::npos, tail) == 0) {
      probes_path.erase(probes_path.size() - std::strlen(tail));
      break;
    }
  probes_path += "_probes.csv";
  std::FILE* fp = std::fopen(probes_path.c_str(), "w");
  if (!fp) {
    std::fprintf(stderr, "cannot write %s\n", probes_path.c_str());
    return 1;
  }
  std::fprintf(fp, "scene,triangles,resolution,threads,probes,rounds,median_seconds,probes_per_second,sh9_rms_error,sh9_mean_error\n");
  const struct {
    const char* name;
    scene_mesh mesh;
  } scenes[] = {{"cornell_box", one_sided(cornell_box())}, {"hexagon_room_t2", one_sided(hexagon_room(2))}};
  const char* modes[] = {"cpp", "sample", "sampler", "batch_1", "batch_2"};
  for (const auto& sc : scenes) {
    const scene_mesh& m = sc.mesh;
    const std::shared_ptr<const scene> cpp_scene = scene::create(m.desc());
    std::vector<float> radiance(3 * m.triangle_count());
    for (std::size_t t = 0; t < m.triangle_count(); ++t)
      for (int c = 0; c < 3; ++c) radiance[3 * t + std::size_t(c)] = m.materials[t].emission[c];
    hemilight_scene* c_scene = nullptr;
    const float sky[3] = {m.sky_radiance.x, m.sky_radiance.y, m.sky_radiance.z};
    if (hemilight_scene_create(&m.positions[0].x, m.positions.size(), m.indices.data(), m.triangle_count(), radiance.data(), sky,
                               &c_scene) != HEMILIGHT_OK) {
      std::fprintf(stderr, "hemilight_scene_create: %s\n", hemilight_last_error());
      return 1;
    }
    const bench::sample_points p = bench::surface_points(m, count, 1e-4f * cpp_scene->size());
    std::vector<float> pos(3 * p.points.size()), nrm(3 * p.points.size());
    for (std::size_t i = 0; i < p.points.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        pos[3 * i + std::size_t(c)] = p.points[i][c];
        nrm[3 * i + std::size_t(c)] = p.frames[i].n[c];
      }
    const std::size_t n_points = p.points.size();
    for (const int n : {32, 64}) {
      hemicube_rasterizer raster(cpp_scene);
      hemicube_integrator integrator(n);
      hemicube_buffer buffer;
      hemilight_sampler* sampler = nullptr;
      if (hemilight_sampler_create(c_scene, n, &sampler) != HEMILIGHT_OK) {
        std::fprintf(stderr, "hemilight_sampler_create: %s\n", hemilight_last_error());
        return 1;
      }
      std::vector<float> cpp_e(n_points);
      std::vector<hemilight_irradiance> out(n_points);
      std::map<std::string, std::vector<double>> seconds, ratios;
      // One warm-up round (tables, page faults), then the timed rounds.
      for (int r = -1; r < rounds; ++r) {
        std::map<std::string, double> t;
        {
          const auto t0 = std::chrono::steady_clock::now();
          for (std::size_t i = 0; i < n_points; ++i) {
            const glm::vec3 normal(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
            raster.render(p.points[i], make_frame(normal / glm::length(normal)), n, buffer);
            cpp_e[i] = integrator.integrate(buffer).irradiance.x;
          }
          t["cpp"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        }
        for (const char* mode : modes) {
          const std::string md = mode;
          if (md == "cpp") continue;
          std::fill(out.begin(), out.end(), hemilight_irradiance{});
          double s = -1.0;
          if (md == "sample") s = capi_time_sample_irradiance(c_scene, pos.data(), nrm.data(), n_points, n, out.data());
          if (md == "sampler") s = capi_time_sampler(sampler, pos.data(), nrm.data(), n_points, out.data());
          if (md == "batch_1") s = capi_time_batch(c_scene, pos.data(), nrm.data(), n_points, n, 1, out.data());
          if (md == "batch_2") s = capi_time_batch(c_scene, pos.data(), nrm.data(), n_points, n, 2, out.data());
          if (s < 0.0) return 1;
          for (std::size_t i = 0; i < n_points; ++i)
            if (std::memcmp(&out[i].irradiance[0], &cpp_e[i], sizeof(float)) != 0) {
              std::fprintf(stderr, "%s: %s differs from the C++ result at point %zu\n", sc.name, mode, i);
              return 1;
            }
          t[md] = s;
        }
        if (r < 0) continue;
        for (const auto& [md, s] : t) {
          seconds[md].push_back(s);
          ratios[md].push_back(t["cpp"] / s);  // > 1: faster than C++
        }
      }
      for (const char* mode : modes) {
        const double med = median(seconds[mode]);
        const int threads = std::strcmp(mode, "batch_2") == 0 ? 2 : 1;
        const double rate = double(n_points) / med, ratio = median(ratios[mode]);
        std::printf("%s N = %d %-8s: %8.0f hemicubes/s (%d thread%s), %.3f of C++\n", sc.name, n, mode, rate, threads,
                    threads > 1 ? "s" : "", ratio);
        std::fprintf(f, "%s,%zu,%s,%d,%d,%zu,%d,%.5f,%.0f,%.4f\n", sc.name, m.triangle_count(), mode, n, threads, n_points, rounds,
                     med, rate, ratio);
        std::fflush(f);
      }
      hemilight_sampler_release(sampler);
    }
    // Probes: per second on 1 and 2 threads (medians of the rounds), and the SH9 irradiance at
    // each point's normal against the hemicube's irradiance there (N = 64), at points lifted 1% of
    // the scene's size off the surface (a probe's lower half then sees the surface, not its plane).
    {
      const bench::sample_points q = bench::surface_points(m, std::min<std::size_t>(count, 1000), 0.01f * cpp_scene->size());
      const std::size_t np = q.points.size();
      std::vector<float> qp(3 * np), qn(3 * np), sh(27 * np);
      for (std::size_t i = 0; i < np; ++i)
        for (int c = 0; c < 3; ++c) {
          qp[3 * i + std::size_t(c)] = q.points[i][c];
          qn[3 * i + std::size_t(c)] = q.frames[i].n[c];
        }
      std::vector<hemilight_irradiance> hc(np);
      if (capi_time_batch(c_scene, qp.data(), qn.data(), np, 64, 2, hc.data()) < 0.0) return 1;
      for (const int n : {32, 64})
        for (const int threads : {1, 2}) {
          std::vector<double> t;
          for (int r = -1; r < rounds; ++r) {
            const double s = capi_time_probes(c_scene, qp.data(), np, n, threads, sh.data());
            if (s < 0.0) return 1;
            if (r >= 0) t.push_back(s);
          }
          double num = 0.0, den = 0.0, abs_err = 0.0, sum_ref = 0.0;
          for (std::size_t i = 0; i < np; ++i) {
            float e[3];
            if (hemilight_sh9_irradiance(&sh[27 * i], &qn[3 * i], e) != HEMILIGHT_OK) return 1;
            const double y = 0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2];
            const double y_ref = 0.2126 * hc[i].irradiance[0] + 0.7152 * hc[i].irradiance[1] + 0.0722 * hc[i].irradiance[2];
            num += (y - y_ref) * (y - y_ref);
            den += y_ref * y_ref;
            abs_err += std::fabs(y - y_ref);
            sum_ref += y_ref;
          }
          const double med = median(t), rms = std::sqrt(num / den), mean = abs_err / sum_ref;
          std::printf("%s N = %d probes  : %8.0f probes/s (%d thread%s); SH9 irradiance against the hemicube's: RMS %.4f, "
                      "mean %.4f\n", sc.name, n, double(np) / med, threads, threads > 1 ? "s" : "", rms, mean);
          std::fprintf(fp, "%s,%zu,%d,%d,%zu,%d,%.5f,%.0f,%.5f,%.5f\n", sc.name, m.triangle_count(), n, threads, np, rounds, med,
                       double(np) / med, rms, mean);
          std::fflush(fp);
        }
    }
    hemilight_scene_release(c_scene);
  }
  std::fclose(f);
  std::fclose(fp);
  return 0;
}
