// End-to-end bake time and accuracy of the built-in scenes (issue 6's benchmark).
//   usage: sweep_bake out.csv [sizes...]   (default sizes 256 512)
//          sweep_bake --target out.csv [runs] the GPU comparison case only (below)
// Scenes: the hexagon room (tessellation 2, 496 triangles, lit by the sky through its window)
// and the Cornell box (32 triangles), chart UVs from generate_lightmap_uvs (2 texels padding).
// For each lightmap size, bounce count (1, 3) and thread count (1, 2): a bake with N = 64 and
// the default cache (a = 0.2): wall time, coverage time, sampled texels, hemicubes, hemicube
// fraction (hemicubes / (sampled texels x bounces)). Error: against a bake with a hemicube at
// every sampled texel (use_cache = false, same N, same roll, same bounces), over texels valid in
// both: relative RMS of luminance (sqrt(sum dY^2 / sum Y_ref^2)) and the mean of
// |dY| / max(Y_ref, 5% of the mean Y_ref).
// --target: the comparison with the GPU hemicube lightmapper (a 654 x 654 lightmap of a
// ~731-triangle scene, N = 64, one bounce, under 4 s on two cores at equal or lower error). Scene:
// the hexagon room at tessellation 3 (1062 triangles), 654^2, N = 64, a = 0.2, 1 bounce, 2 threads;
// `runs` bakes (default 3) with the irradiance only and `runs` with both directional outputs (L1
// SH + HL2), then one reference bake with a hemicube at every texel. CSV: one row per run plus the
// reference; the load average (/proc/loadavg) before and after is printed, since the machine may
// be shared.
// "Equal or lower error": the GPU lightmapper renders an N = 64 hemicube per texel, as our
// reference bake does. Both bakes are compared with a converged reference at every 37th sampled
// texel (the bake's own sample points, N = 256, the mean of 4 hemicubes rolled by different
// hashed angles): if the cached bake's error is no larger than the per-texel bake's, the cache
// costs no accuracy against a hemicube-per-texel baker at the same N. Written to
// out_converged.csv next to out.csv.
#include "hemilight/bake.hpp"
#include "hemilight/cache.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/reference_scenes.hpp"

#include <fstream>
#include <sstream>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

std::string load_average() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

// Relative RMS of luminance and mean relative error (definitions at the top) over texels valid in both.
void compare(const bake_result& r, const bake_result& ref, double& rms, double& mean) {
  double mean_ref = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < ref.valid.size(); ++k)
    if (ref.valid[k]) {
      mean_ref += luminance(ref.irradiance.pixels.data() + 3 * k);
      ++n;
    }
  mean_ref /= double(std::max<std::size_t>(n, 1));
  double num = 0, den = 0, rel = 0;
  std::size_t cnt = 0;
  for (std::size_t k = 0; k < ref.valid.size(); ++k)
    if (ref.valid[k] && r.valid[k]) {
      const double a = luminance(r.irradiance.pixels.data() + 3 * k), b = luminance(ref.irradiance.pixels.data() + 3 * k);
      num += (a - b) * (a - b);
      den += b * b;
      rel += std::fabs(a - b) / std::max(b, 0.05 * mean_ref);
      ++cnt;
    }
  rms = std::sqrt(num / den);
  mean = rel / double(std::max<std::size_t>(cnt, 1));
}

// See the top: the cached bake `cached` and the per-texel bake `per_texel` against a converged
// reference at every 37th sampled texel.
void converged_comparison(const std::string& path, const bake_input& in, const bake_options& o, const bake_result& cached,
                          const bake_result& per_texel) {
  const int stride = 37, rolls = 4, n = 256;
  const lightmap_samples s = compute_lightmap_samples(in, o.width, o.height);
  const auto sc = scene::create(in.scene);
  const float min_offset = 2.0f * default_near_distance(*sc);  // bake.hpp, step 2
  std::vector<std::size_t> texel;
  std::vector<glm::vec3> p, nrm;
  std::size_t sampled = 0;
  for (std::size_t k = 0; k < s.coverage.size(); ++k) {
    if (s.sample_triangle[k] == lightmap_samples::no_triangle || !(s.coverage[k] >= o.min_coverage) || !(s.coverage[k] > 0.0f))
      continue;
    if (sampled++ % stride || !cached.valid[k] || !per_texel.valid[k]) continue;
    texel.push_back(k);
    p.push_back(s.position[k] + std::max(min_offset, o.offset_texels * s.texel_world_size[k]) * s.normal[k]);
    nrm.push_back(s.normal[k]);
  }
  hemicube_sampler_options so;
  so.resolution = n;
  const int threads = o.thread_count;
  const irradiance_sampler sampler = make_hemicube_sampler(sc, so, threads);
  std::vector<double> truth(texel.size());
  const auto t0 = std::chrono::steady_clock::now();
  parallel_for(texel.size(), threads, 16, [&](int worker, std::size_t b, std::size_t e) {
    for (std::size_t j = b; j < e; ++j) {
      double sum = 0.0;
      for (int r = 0; r < rolls; ++r) {
        // r float ulps along one coordinate (< 1e-6 m): another hashed roll, the same point.
        glm::vec3 q = p[j];
        for (int u = 0; u < r; ++u) q.x = std::nextafter(q.x, 1e30f);
        const glm::vec3 e3 = sampler(worker, q, nrm[j]).irradiance;
        sum += 0.2126 * e3.x + 0.7152 * e3.y + 0.0722 * e3.z;
      }
      truth[j] = sum / rolls;
    }
  });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  double mean_truth = 0.0;
  for (double t : truth) mean_truth += t;
  mean_truth /= double(std::max<std::size_t>(truth.size(), 1));
  // The same two measures as compare(): relative RMS and mean relative error (5% floor).
  const auto errors = [&](const bake_result& r, double& rms, double& mean) {
    double num = 0.0, den = 0.0, rel = 0.0;
    for (std::size_t j = 0; j < texel.size(); ++j) {
      const double y = luminance(r.irradiance.pixels.data() + 3 * texel[j]);
      num += (y - truth[j]) * (y - truth[j]);
      den += truth[j] * truth[j];
      rel += std::fabs(y - truth[j]) / std::max(truth[j], 0.05 * mean_truth);
    }
    rms = std::sqrt(num / std::max(den, 1e-300));
    mean = rel / double(std::max<std::size_t>(texel.size(), 1));
  };
  double cache_rms, cache_mean, texel_rms, texel_mean;
  errors(cached, cache_rms, cache_mean);
  errors(per_texel, texel_rms, texel_mean);
  std::string out = path;
  const std::size_t dot = out.rfind(".csv");
  out = (dot == std::string::npos ? out : out.substr(0, dot)) + "_converged.csv";
  std::FILE* f = std::fopen(out.c_str(), "w");
  if (f) {
    std::fprintf(f, "bake,points,converged_resolution,converged_rolls,rms_error,mean_error\n");
    std::fprintf(f, "cache_a0.2_n64,%zu,%d,%d,%.5f,%.5f\n", texel.size(), n, rolls, cache_rms, cache_mean);
    std::fprintf(f, "per_texel_n64,%zu,%d,%d,%.5f,%.5f\n", texel.size(), n, rolls, texel_rms, texel_mean);
    std::fclose(f);
  }
  std::printf("against a converged reference (N = %d, %d rolls, %zu texels, %.1f s): cached bake RMS %.4f, mean %.4f; "
              "hemicube per texel RMS %.4f, mean %.4f\n",
              n, rolls, texel.size(), seconds, cache_rms, cache_mean, texel_rms, texel_mean);
}

int target(const char* path, int runs) {
  std::FILE* f = std::fopen(path, "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", path);
    return 1;
  }
  std::printf("load average before: %s\n", load_average().c_str());
  scene_mesh m = hexagon_room(3);
  const int size = 654;
  generate_lightmap_uvs(m, size, 2);
  bake_input in;
  in.scene = m.desc();
  bake_options o;
  o.width = o.height = size;
  o.resolution = 64;
  o.bounces = 1;
  o.thread_count = 2;
  std::fprintf(f, "run,scene,triangles,size,directional,seconds,sampled_texels,hemicubes,hemicube_fraction,rms_error,mean_error\n");
  std::vector<bake_result> results;
  std::vector<std::string> rows;
  for (int directional = 0; directional < 2; ++directional)
    for (int run = 0; run < runs; ++run) {
      o.output_sh_l1 = o.output_hl2 = directional == 1;
      bake_result r = bake_lightmap(in, o);
      std::printf("run %d%s: %.3f s, %zu hemicubes for %zu sampled texels\n", run, directional ? " (SH + HL2)" : "", r.stats.seconds,
                  r.stats.hemicubes, r.stats.sampled_texels);
      std::fflush(stdout);
      results.push_back(std::move(r));
    }
  o.output_sh_l1 = o.output_hl2 = false;
  o.use_cache = false;
  const bake_result ref = bake_lightmap(in, o);
  for (std::size_t i = 0; i < results.size(); ++i) {
    const bake_result& r = results[i];
    double rms, mean;
    compare(r, ref, rms, mean);
    std::fprintf(f, "%zu,hexagon_room_t3,%zu,%d,%d,%.4f,%zu,%zu,%.4f,%.5f,%.5f\n", i % std::size_t(runs), m.triangle_count(), size,
                 int(i / std::size_t(runs)), r.stats.seconds, r.stats.sampled_texels, r.stats.hemicubes,
                 double(r.stats.hemicubes) / double(r.stats.sampled_texels), rms, mean);
  }
  std::fprintf(f, "reference,hexagon_room_t3,%zu,%d,0,%.4f,%zu,%zu,1,0,0\n", m.triangle_count(), size, ref.stats.seconds,
               ref.stats.sampled_texels, ref.stats.hemicubes);
  std::fclose(f);
  double rms, mean;
  compare(results[0], ref, rms, mean);
  std::printf("reference (hemicube per texel): %.2f s; cache vs reference: relative RMS %.4f, mean relative %.4f\n",
              ref.stats.seconds, rms, mean);
  converged_comparison(path, in, o, results[0], ref);
  std::printf("load average after: %s\n", load_average().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 3 && std::string(argv[1]) == "--target") return target(argv[2], argc >= 4 ? std::max(1, std::atoi(argv[3])) : 3);
  if (argc < 2) {
    std::fprintf(stderr, "usage: sweep_bake out.csv [sizes...]\n");
    return 2;
  }
  std::vector<int> sizes;
  for (int i = 2; i < argc; ++i) sizes.push_back(std::atoi(argv[i]));
  if (sizes.empty()) sizes = {256, 512};
  std::FILE* f = std::fopen(argv[1], "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", argv[1]);
    return 1;
  }
  std::fprintf(f, "scene,triangles,size,bounces,threads,seconds,coverage_seconds,sampled_texels,hemicubes,hemicube_fraction,"
                  "reference_seconds,rms_error,mean_error\n");
  const struct {
    const char* name;
    scene_mesh mesh;
  } scenes[] = {{"hexagon_room", hexagon_room(2)}, {"cornell_box", cornell_box()}};
  for (const auto& sc : scenes)
    for (int size : sizes) {
      scene_mesh m = sc.mesh;
      generate_lightmap_uvs(m, size, 2);
      bake_input in;
      in.scene = m.desc();
      for (int bounces : {1, 3}) {
        bake_options o;
        o.width = o.height = size;
        o.resolution = 64;
        o.bounces = bounces;
        o.thread_count = 2;
        o.use_cache = false;
        const bake_result ref = bake_lightmap(in, o);
        o.use_cache = true;
        for (int threads : {1, 2}) {
          o.thread_count = threads;
          const bake_result r = bake_lightmap(in, o);
          double rms = 0.0, mean = 0.0;
          compare(r, ref, rms, mean);
          const bake_stats& s = r.stats;
          std::fprintf(f, "%s,%zu,%d,%d,%d,%.4f,%.4f,%zu,%zu,%.4f,%.4f,%.5f,%.5f\n", sc.name, m.triangle_count(), size, bounces,
                       threads, s.seconds, s.coverage_seconds, s.sampled_texels, s.hemicubes,
                       double(s.hemicubes) / double(s.sampled_texels * std::size_t(bounces)), ref.stats.seconds, rms,
                       mean);
          std::fflush(f);
          std::printf("%s %d^2 %d bounce(s) %d thread(s): %.2f s, %.1f%% hemicubes, rms %.4f (reference %.1f s)\n", sc.name,
                      size, bounces, threads, s.seconds, 100.0 * double(s.hemicubes) / double(s.sampled_texels * std::size_t(bounces)),
                      rms, ref.stats.seconds);
          std::fflush(stdout);
        }
      }
    }
  std::fclose(f);
  return 0;
}
