// Lights (lights.hpp) in bakes: cost, penumbra accuracy and the cache on the indirect part.
//   usage: sweep_lights OUT_PREFIX [--runs R] [--only direct,penumbra,cornell] [--penumbra-samples K]
//                       [--cornell-sizes 128,256,512] [--cornell-resolutions 64,256] [--reference-cache DIR]
// Writes OUT_PREFIX_direct.csv, OUT_PREFIX_penumbra.csv and OUT_PREFIX_cornell.csv (a trailing
// "_sweep.csv" or ".csv" is dropped from OUT_PREFIX: `bash benchmarks/run.sh lights` passes
// docs/bench/lights_sweep.csv and gets docs/bench/lights_*.csv, drawn by plot_lights.py).
// About 50 minutes on two cores (the Cornell references: a hemicube per texel at N = 256, up to
// 512 x 512: 14 minutes alone).
//
// direct: the hexagon room at tessellation 3 (1062 triangles), 654 x 654, N = 64, one bounce, two
//   threads, lit by the sky through its window and by seven lights: the soft sun of
//   hexagon_room_sunlit, four point lights of radius 0.1 m, one spot and one RECT on the ceiling.
//   Per run: the bake's direct-light stage (bake_stats::direct_seconds: every sampled texel, every
//   light, shadow rays included) and the whole bake.
// penumbra: sample points (offset as the baker offsets them) of three scenes: the hexagon room of
//   `direct` (every 13th sampled texel), the Cornell box with its RECT light and a small sphere
//   light (256^2, every texel; the boxes cast the penumbrae) and sky_and_occluders under the sun
//   (0.00465 rad) and a wider sun (0.05 rad) (512^2, every 2nd texel). Each light's direct_light
//   with the default direct_options against a 4096-sample reference
//   (probe_samples = penumbra_samples = 4096), for every point where either finds a penumbra
//   (0 < visibility < 1) and a deterministic tenth of the others. Per light: RMS and largest
//   |E - E_ref| / E_unoccluded over the reference's penumbra points, and the points where the
//   default's probes agreed (visibility 0 or 1) although the reference differs by over 1%.
// cornell: the Cornell box at 128 x 128, 256 x 256 and 512 x 512 (--cornell-sizes; the emissive
//   quad at 128 x 128 only), 3 bounces, indirect only (what the cache interpolates),
//   with its light as the emissive quad (hemicubes see it) and as a RECT light (direct light per
//   texel, the cache sees only the bounces): the cached bake at N = 64 and 256 for several
//   error thresholds against a hemicube-per-texel bake at N = 256 of the same lighting: hemicube
//   fraction (hemicubes / (sampled texels x bounces)) and relative RMS of luminance over texels
//   valid in both.
#include "hemilight/bake.hpp"
#include "hemilight/lights.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/reference_scenes.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

std::string load_average() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

double luminance(const glm::vec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }
double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

const char* type_name(light_type t) {
  switch (t) {
    case light_type::directional: return "sun";
    case light_type::point: return "sphere";
    case light_type::spot: return "spot";
    case light_type::rect: return "rect";
  }
  return "?";
}

// The hexagon room's seven lights (see the top).
std::vector<light> room_lights() {
  std::vector<light> ls = hexagon_room_sunlit(3).lights;
  for (int k = 0; k < 4; ++k) {
    light p;
    p.type = light_type::point;
    p.position = glm::vec3(k % 2 ? 1.5f : -1.5f, 2.4f, k / 2 ? 1.5f : -1.5f);
    p.radius = 0.1f;
    p.color = glm::vec3(3.0f, 2.7f, 2.2f);
    ls.push_back(p);
  }
  light spot;
  spot.type = light_type::spot;
  spot.position = glm::vec3(0.0f, 2.9f, 0.0f);
  spot.direction = glm::vec3(0.2f, -1.0f, 0.1f);
  spot.spot_inner = 0.3f;
  spot.spot_outer = 0.6f;
  spot.radius = 0.05f;
  spot.color = glm::vec3(8.0f);
  ls.push_back(spot);
  light rect;
  rect.type = light_type::rect;
  rect.position = glm::vec3(-1.0f, 2.99f, 0.5f);
  rect.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  rect.tangent = glm::vec3(1.0f, 0.0f, 0.0f);
  rect.width = 1.0f;
  rect.height = 0.5f;
  rect.color = glm::vec3(2.0f);
  ls.push_back(rect);
  return ls;
}

void direct_target(const std::string& path, int runs) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    std::exit(1);
  }
  std::fprintf(f, "run,scene,triangles,size,lights,sampled_texels,direct_seconds,bake_seconds\n");
  scene_mesh m = hexagon_room(3);
  generate_lightmap_uvs(m, 654, 2);
  bake_input in;
  in.scene = m.desc();
  bake_options o;
  o.width = o.height = 654;
  o.sampler.resolution = 64;
  o.bounces = 1;
  o.thread_count = 2;
  o.lights = room_lights();
  for (int run = 0; run < runs; ++run) {
    const bake_result r = bake_lightmap(in, o);
    std::printf("direct: run %d: direct light %.3f s of %.3f s (%zu texels, %zu lights)\n", run, r.stats.direct_seconds,
                r.stats.seconds, r.stats.sampled_texels, o.lights.size());
    std::fprintf(f, "%d,hexagon_room_t3,%zu,654,%zu,%zu,%.4f,%.4f\n", run, m.triangle_count(), o.lights.size(),
                 r.stats.sampled_texels, r.stats.direct_seconds, r.stats.seconds);
    std::fflush(f);
  }
  std::fclose(f);
}

// A scene of the penumbra study: a mesh with chart UVs, its lights, the lightmap size and which
// sampled texels to take (every stride-th).
struct penumbra_scene {
  std::string name;
  scene_mesh mesh;
  std::vector<light> lights;
  int size, stride;
};

std::vector<penumbra_scene> penumbra_scenes() {
  std::vector<penumbra_scene> out;
  out.push_back({"hexagon_room_t3", hexagon_room(3), room_lights(), 654, 13});
  // The Cornell box: its RECT light and a small sphere light; the boxes cast the penumbrae.
  lit_scene c = cornell_box_rect_light();
  light sphere;
  sphere.type = light_type::point;
  sphere.position = glm::vec3(0.42f, 0.45f, 0.15f);
  sphere.radius = 0.03f;
  sphere.color = glm::vec3(0.05f);
  c.lights.push_back(sphere);
  out.push_back({"cornell_box", c.mesh, c.lights, 256, 1});
  // Sky and occluders: boxes on a ground under the sun (0.00465 rad) and a wider sun (0.05 rad).
  std::vector<light> suns;
  for (float radius : {0.00465f, 0.05f}) {
    light sun;
    sun.type = light_type::directional;
    sun.direction = glm::vec3(0.4f, -0.8f, 0.3f);
    sun.color = glm::vec3(10.0f);
    sun.radius = radius;
    suns.push_back(sun);
  }
  out.push_back({"sky_and_occluders", sky_and_occluders(), suns, 512, 2});
  return out;
}

void penumbra(const std::string& path, const direct_options& tested) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    std::exit(1);
  }
  std::fprintf(f, "scene,light,type,radius,points,penumbra_points,rms_error,max_error,missed_penumbrae,seconds_default,"
                  "seconds_reference\n");
  for (penumbra_scene& ps : penumbra_scenes()) {
    generate_lightmap_uvs(ps.mesh, ps.size, 2);
    bake_input in;
    in.scene = ps.mesh.desc();
    const auto sc = scene::create(in.scene);
    const lightmap_samples s = compute_lightmap_samples(in, ps.size, ps.size);
    const float min_offset = 2.0f * default_near_distance(*sc);
    std::vector<glm::vec3> p, n;
    std::size_t sampled = 0;
    for (std::size_t k = 0; k < s.coverage.size(); ++k) {
      if (s.sample_triangle[k] == lightmap_samples::no_triangle || !(s.coverage[k] >= 0.01f)) continue;
      if (sampled++ % std::size_t(ps.stride) != 0) continue;
      const float offset = std::max(min_offset, 0.05f * s.texel_world_size[k]);
      p.push_back(s.position[k] + offset * s.normal[k]);
      n.push_back(s.normal[k]);
    }
    const light_set lights(ps.lights.data(), ps.lights.size());
    direct_options ref_o;
    ref_o.probe_samples = ref_o.penumbra_samples = 4096;
    for (std::size_t l = 0; l < lights.size(); ++l) {
      struct result {
        bool compared = false;
        float e = 0, e_ref = 0, unocc = 0, vis = 0, vis_ref = 0;
      };
      std::vector<result> r(p.size());
      const auto t0 = std::chrono::steady_clock::now();
      parallel_for(p.size(), 2, 64, [&](int, std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
          const light_sample d = direct_light(*sc, lights, l, p[i], n[i], tested);
          r[i].e = float(luminance(d.irradiance));
          r[i].unocc = float(luminance(d.unoccluded));
          r[i].vis = d.visibility;
        }
      });
      const double t_default = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const auto t1 = std::chrono::steady_clock::now();
      parallel_for(p.size(), 2, 16, [&](int, std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
          if (!(r[i].unocc > 0.0f)) continue;
          const bool partial = r[i].vis > 0.0f && r[i].vis < 1.0f;
          if (!partial && i % 10 != 0) continue;
          const light_sample d = direct_light(*sc, lights, l, p[i], n[i], ref_o);
          r[i].compared = true;
          r[i].e_ref = float(luminance(d.irradiance));
          r[i].vis_ref = d.visibility;
        }
      });
      const double t_ref = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
      double sum2 = 0.0, worst = 0.0;
      std::size_t count = 0, missed = 0;
      for (const result& x : r) {
        if (!x.compared || !(x.vis_ref > 0.0f && x.vis_ref < 1.0f)) continue;
        const double err = (double(x.e) - double(x.e_ref)) / double(x.unocc);
        sum2 += err * err;
        worst = std::max(worst, std::fabs(err));
        ++count;
        if ((x.vis == 0.0f || x.vis == 1.0f) && std::fabs(err) > 0.01) ++missed;
      }
      const double rms = count ? std::sqrt(sum2 / double(count)) : 0.0;
      std::printf("penumbra: %s light %zu (%s, radius %g): %zu points, %zu in penumbra: RMS %.4f, max %.4f, %zu missed; %.2f s "
                  "default, %.2f s reference\n",
                  ps.name.c_str(), l, type_name(lights[l].type), double(lights[l].radius), p.size(), count, rms, worst, missed,
                  t_default, t_ref);
      std::fprintf(f, "%s,%zu,%s,%g,%zu,%zu,%.5f,%.5f,%zu,%.3f,%.3f\n", ps.name.c_str(), l, type_name(lights[l].type),
                   double(lights[l].radius), p.size(), count, rms, worst, missed, t_default, t_ref);
      std::fflush(f);
    }
  }
  std::fclose(f);
}

// Relative RMS of luminance over texels valid (and lit) in both.
double relative_rms(const bake_result& a, const bake_result& ref) {
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < ref.valid.size(); ++k) {
    if (!a.valid[k] || !ref.valid[k]) continue;
    const double y = luminance(&a.irradiance.pixels[3 * k]), y_ref = luminance(&ref.irradiance.pixels[3 * k]);
    num += (y - y_ref) * (y - y_ref);
    den += y_ref * y_ref;
  }
  return den > 0.0 ? std::sqrt(num / den) : 0.0;
}

// The cache on indirect light at each lightmap size in `sizes`: the emissive quad (at 128 x 128
// only: it is the slow half, and its trend is the RECT's) and the RECT light; the cached bakes at
// N = 64 and 256 for each error threshold against a hemicube per texel at N = 256.
// --reference-cache DIR: the references are kept in DIR (cornell_rect_SIZE.bin,
// cornell_quad_SIZE.bin: the reference's wall time as a double, then the W x H RGB irradiance as
// floats, then the W x H valid flags), read when present instead of baked again. The references
// do not depend on the cache, so they stay valid across cache changes.
bool read_reference(const std::string& file, int size, bake_result& ref) {
  std::FILE* f = std::fopen(file.c_str(), "rb");
  if (!f) return false;
  const std::size_t texels = std::size_t(size) * std::size_t(size);
  ref.irradiance = image::make(size, size, 3);
  ref.valid.resize(texels);
  const bool ok = std::fread(&ref.stats.seconds, sizeof(double), 1, f) == 1 &&
                  std::fread(ref.irradiance.pixels.data(), sizeof(float), 3 * texels, f) == 3 * texels &&
                  std::fread(ref.valid.data(), 1, texels, f) == texels;
  std::fclose(f);
  return ok;
}
void write_reference(const std::string& file, const bake_result& ref) {
  std::FILE* f = std::fopen(file.c_str(), "wb");
  if (!f) return;
  std::fwrite(&ref.stats.seconds, sizeof(double), 1, f);
  std::fwrite(ref.irradiance.pixels.data(), sizeof(float), ref.irradiance.pixels.size(), f);
  std::fwrite(ref.valid.data(), 1, ref.valid.size(), f);
  std::fclose(f);
}

void cornell(const std::string& path, const std::vector<int>& sizes, const std::vector<int>& resolutions,
             const std::string& reference_cache) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    std::exit(1);
  }
  std::fprintf(f, "light,size,resolution,error_threshold,sampled_texels,hemicubes,hemicube_fraction,seconds,rms_error,reference_seconds\n");
  const int bounces = 3;
  for (const int size : sizes)
    for (const bool rect : {false, true}) {
      if (!rect && size != 128) continue;
      lit_scene ls = rect ? cornell_box_rect_light() : lit_scene{cornell_box(), {}};
      generate_lightmap_uvs(ls.mesh, size, 2);
      bake_input in;
      in.scene = ls.mesh.desc();
      bake_options o;
      o.width = o.height = size;
      o.bounces = bounces;
      o.indirect_only = true;
      o.thread_count = 2;
      o.lights = ls.lights;
      o.use_cache = false;
      o.sampler.resolution = 256;
      bake_result ref;
      const std::string cached = reference_cache.empty() ? std::string()
                                                         : reference_cache + "/cornell_" + (rect ? "rect_" : "quad_") + std::to_string(size) + ".bin";
      const bool from_cache = !cached.empty() && read_reference(cached, size, ref);
      if (!from_cache) {
        ref = bake_lightmap(in, o);
        if (!cached.empty()) write_reference(cached, ref);
      }
      std::printf("cornell %d^2 (%s): reference (hemicube per texel, N = 256): %.1f s%s\n", size, rect ? "rect light" : "emissive quad",
                  ref.stats.seconds, from_cache ? " (kept in the reference cache)" : "");
      std::fflush(stdout);
      o.use_cache = true;
      for (const int n : resolutions)
        for (const float a : {0.1f, 0.2f, 0.35f, 0.5f, 0.7f, 1.0f}) {
          o.sampler.resolution = n;
          o.cache.error_threshold = a;
          const bake_result r = bake_lightmap(in, o);
          const double fraction = double(r.stats.hemicubes) / double(r.stats.sampled_texels * std::size_t(bounces));
          const double rms = relative_rms(r, ref);
          std::printf("  N = %d, a = %.2f: %.2f%% hemicubes, RMS %.4f, %.2f s\n", n, double(a), 100.0 * fraction, rms, r.stats.seconds);
          std::fflush(stdout);
          std::fprintf(f, "%s,%d,%d,%.2f,%zu,%zu,%.5f,%.3f,%.5f,%.2f\n", rect ? "rect" : "emissive_quad", size, n, double(a),
                       r.stats.sampled_texels, r.stats.hemicubes, fraction, r.stats.seconds, rms, ref.stats.seconds);
          std::fflush(f);
        }
    }
  std::fclose(f);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') {
    std::fprintf(stderr, "usage: sweep_lights OUT_PREFIX [--runs R] [--only direct,penumbra,cornell] [--penumbra-samples K] [--cornell-sizes 128,256,512] [--cornell-resolutions 64,256] [--reference-cache DIR]\n");
    return 2;
  }
  // run.sh passes docs/bench/lights_sweep.csv: the prefix is then docs/bench/lights.
  std::string prefix = argv[1];
  for (const char* tail : {"_sweep.csv", ".csv"})
    if (prefix.size() > std::strlen(tail) && prefix.compare(prefix.size() - std::strlen(tail), std::string::npos, tail) == 0) {
      prefix.erase(prefix.size() - std::strlen(tail));
      break;
    }
  int runs = 3;
  std::string only = "direct,penumbra,cornell";
  direct_options tested;  // the defaults unless --penumbra-samples
  std::vector<int> cornell_sizes = {128, 256, 512}, cornell_resolutions = {64, 256};
  std::string reference_cache;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--runs") runs = std::max(1, std::atoi(argv[i + 1]));
    else if (a == "--only") only = argv[i + 1];
    else if (a == "--reference-cache") reference_cache = argv[i + 1];
    else if (a == "--penumbra-samples") tested.penumbra_samples = std::atoi(argv[i + 1]);
    else if (a == "--cornell-sizes" || a == "--cornell-resolutions") {
      std::vector<int>& list = a == "--cornell-sizes" ? cornell_sizes : cornell_resolutions;
      list.clear();
      std::stringstream items(argv[i + 1]);
      for (std::string item; std::getline(items, item, ',');) list.push_back(std::max(a == "--cornell-sizes" ? 16 : 2, std::atoi(item.c_str())));
    }
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  const auto wants = [&](const char* part) { return ("," + only + ",").find(std::string(",") + part + ",") != std::string::npos; };
  std::printf("load average before: %s\n", load_average().c_str());
  if (wants("direct")) direct_target(prefix + "_direct.csv", runs);
  if (wants("penumbra")) penumbra(prefix + "_penumbra.csv", tested);
  if (wants("cornell")) cornell(prefix + "_cornell.csv", cornell_sizes, cornell_resolutions, reference_cache);
  std::printf("load average after: %s\n", load_average().c_str());
  return 0;
}
