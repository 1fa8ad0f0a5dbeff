// Where the cache errs: per-texel error maps of the built-in scenes' cached bakes against a
// hemicube per texel (docs/bake.md, "Where the cache errs").
//   usage: sweep_error_maps OUT.csv [--size S] [--maps DIR]
// The scenes of the command-line baker's main job (hexagon_room, hexagon_room_sun, cornell_box,
// cornell_box_rect), chart UVs for S x S (default 256; generate_lightmap_uvs, 2 texels of
// padding), N = 64, 3 bounces, all cores: the cached bake (a = 0.2, the baker's default) and the
// reference with a hemicube at every sampled texel (use_cache = false, same N, same roll).
// Per texel valid in both: the signed relative error of luminance,
// (Y - Y_ref) / max(Y_ref, 5% of the mean Y_ref) (the cache's own measure, docs/cache.md).
// OUT.csv: per scene the relative RMS, the 99th percentile and the largest |error|, the hemicube
// fraction and both bakes' times. The maps (S x S float32, row-major, NaN where a texel is not
// valid in both) go to DIR/error_map_NAME.f32 (default build-bench/error_maps), which
// benchmarks/plot_error_maps.py draws in false colour into docs/bench/error_maps.png.
// About 1-2 minutes on two cores at 256 (the per-texel references dominate).
#include "hemilight/bake.hpp"
#include "hemilight/reference_scenes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') {
    std::fprintf(stderr, "usage: sweep_error_maps OUT.csv [--size S] [--maps DIR]\n");
    return 2;
  }
  int size = 256;
  std::string maps = "build-bench/error_maps";
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--size") size = std::clamp(std::atoi(argv[i + 1]), 16, 4096);
    else if (a == "--maps") maps = argv[i + 1];
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  std::error_code ec;
  std::filesystem::create_directories(maps, ec);
  std::FILE* csv = std::fopen(argv[1], "w");
  if (!csv) {
    std::fprintf(stderr, "cannot write %s\n", argv[1]);
    return 1;
  }
  std::fprintf(csv, "scene,size,resolution,error_threshold,bounces,valid_texels,hemicube_fraction,rms_rel_err,p99_abs_rel_err,max_abs_rel_err,"
                    "cached_seconds,reference_seconds\n");
  const struct {
    const char* name;
    lit_scene scene;
  } scenes[] = {{"hexagon_room", {hexagon_room(2), {}}},
                {"hexagon_room_sun", hexagon_room_sunlit(2)},
                {"cornell_box", {cornell_box(), {}}},
                {"cornell_box_rect", cornell_box_rect_light()}};
  for (const auto& sc : scenes) {
    scene_mesh m = sc.scene.mesh;
    generate_lightmap_uvs(m, size, 2);
    bake_input in;
    in.scene = m.desc();
    bake_options o;
    o.width = o.height = size;
    o.sampler.resolution = 64;
    o.bounces = 3;
    o.lights = sc.scene.lights;
    const bake_result cached = bake_lightmap(in, o);
    o.use_cache = false;
    const bake_result ref = bake_lightmap(in, o);
    // Step 1: the mean reference luminance over texels valid in both (the error's floor).
    const std::size_t texels = ref.valid.size();
    double mean = 0.0;
    std::size_t valid = 0;
    for (std::size_t k = 0; k < texels; ++k)
      if (ref.valid[k] && cached.valid[k]) {
        mean += luminance(&ref.irradiance.pixels[3 * k]);
        ++valid;
      }
    mean /= double(std::max<std::size_t>(valid, 1));
    // Step 2: the map and its statistics.
    std::vector<float> map(texels, std::numeric_limits<float>::quiet_NaN());
    std::vector<double> magnitudes;
    double sum2 = 0.0;
    for (std::size_t k = 0; k < texels; ++k) {
      if (!ref.valid[k] || !cached.valid[k]) continue;
      const double y = luminance(&cached.irradiance.pixels[3 * k]), y_ref = luminance(&ref.irradiance.pixels[3 * k]);
      const double e = (y - y_ref) / std::max(y_ref, 0.05 * mean);
      map[k] = float(e);
      sum2 += e * e;
      magnitudes.push_back(std::fabs(e));
    }
    std::sort(magnitudes.begin(), magnitudes.end());
    const double rms = magnitudes.empty() ? 0.0 : std::sqrt(sum2 / double(magnitudes.size()));
    const double p99 = magnitudes.empty() ? 0.0 : magnitudes[std::min(magnitudes.size() - 1, magnitudes.size() * 99 / 100)];
    const double worst = magnitudes.empty() ? 0.0 : magnitudes.back();
    const double fraction = double(cached.stats.hemicubes) / double(cached.stats.sampled_texels * 3);
    const std::string path = maps + "/error_map_" + sc.name + ".f32";
    if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
      std::fwrite(map.data(), sizeof(float), map.size(), f);
      std::fclose(f);
    }
    std::printf("%s: %zu texels valid in both, hemicubes %.1f%%, RMS %.2f%%, p99 %.2f%%, max %.1f%%; %.2f s cached, %.2f s reference\n",
                sc.name, valid, 100.0 * fraction, 100.0 * rms, 100.0 * p99, 100.0 * worst, cached.stats.seconds, ref.stats.seconds);
    std::fflush(stdout);
    std::fprintf(csv, "%s,%d,64,0.2,3,%zu,%.5f,%.5f,%.5f,%.5f,%.3f,%.3f\n", sc.name, size, valid, fraction, rms, p99, worst,
                 cached.stats.seconds, ref.stats.seconds);
    std::fflush(csv);
  }
  std::fclose(csv);
  return 0;
}
