// End-to-end bake time and accuracy of the built-in scenes (issue 6's benchmark).
//   usage: sweep_bake out.csv [sizes...]   (default sizes 256 512)
// Scenes: the hexagon room (tessellation 2, 496 triangles, lit by the sky through its window)
// and the Cornell box (32 triangles), chart UVs from generate_lightmap_uvs (2 texels padding).
// For each lightmap size, bounce count (1, 3) and thread count (1, 2): a bake with N = 64 and
// the default cache (a = 0.2): wall time, coverage time, sampled texels, hemicubes, hemicube
// fraction (hemicubes / (sampled texels x bounces)). Error: against a bake with a hemicube at
// every sampled texel (use_cache = false, same N, same roll, same bounces), over texels valid in
// both: relative RMS of luminance (sqrt(sum dY^2 / sum Y_ref^2)) and the mean of
// |dY| / max(Y_ref, 5% of the mean Y_ref).
#include "hemilight/bake.hpp"
#include "hemilight/reference_scenes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

}  // namespace

int main(int argc, char** argv) {
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
        double mean_ref = 0.0;
        std::size_t n = 0;
        for (std::size_t k = 0; k < ref.valid.size(); ++k)
          if (ref.valid[k]) {
            mean_ref += luminance(ref.irradiance.pixels.data() + 3 * k);
            ++n;
          }
        mean_ref /= double(std::max<std::size_t>(n, 1));
        o.use_cache = true;
        for (int threads : {1, 2}) {
          o.thread_count = threads;
          const bake_result r = bake_lightmap(in, o);
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
          const bake_stats& s = r.stats;
          std::fprintf(f, "%s,%zu,%d,%d,%d,%.4f,%.4f,%zu,%zu,%.4f,%.4f,%.5f,%.5f\n", sc.name, m.triangle_count(), size, bounces,
                       threads, s.seconds, s.coverage_seconds, s.sampled_texels, s.hemicubes,
                       double(s.hemicubes) / double(s.sampled_texels * std::size_t(bounces)), ref.stats.seconds,
                       std::sqrt(num / den), rel / double(cnt));
          std::fflush(f);
          std::printf("%s %d^2 %d bounce(s) %d thread(s): %.2f s, %.1f%% hemicubes, rms %.4f (reference %.1f s)\n", sc.name,
                      size, bounces, threads, s.seconds, 100.0 * double(s.hemicubes) / double(s.sampled_texels * std::size_t(bounces)),
                      std::sqrt(num / den), ref.stats.seconds);
          std::fflush(stdout);
        }
      }
    }
  std::fclose(f);
  return 0;
}
