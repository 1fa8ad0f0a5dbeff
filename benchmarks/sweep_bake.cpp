// End-to-end bake time and accuracy of the built-in and reference scenes.
//   usage: sweep_bake out.csv [sizes...]   (default sizes 256 512)
//          sweep_bake --target out.csv [runs] [--scenes a,b] [--truth-cache DIR] [--bake-only]
//                     [--sizes 512,1024] [--bounces 1,3] [--max-points K] [--level-triangles T]
// Sweep: the hexagon room (tessellation 2, 496 triangles, lit by the sky through its window)
// and the Cornell box (32 triangles), chart UVs from generate_lightmap_uvs (2 texels padding).
// For each lightmap size, bounce count (1, 3) and thread count (1, 2): a bake with N = 64 and
// the default cache (a = 0.2): wall time, coverage time, sampled texels, hemicubes, hemicube
// fraction (hemicubes / (sampled texels x bounces)). Error: against a bake with a hemicube at
// every sampled texel (use_cache = false, same N, same roll, same bounces), over texels valid in
// both: relative RMS of luminance (sqrt(sum dY^2 / sum Y_ref^2)) and the mean of
// |dY| / max(Y_ref, 5% of the mean Y_ref).
// --target: the 654 x 654, N = 64, one-bounce, two-thread bake of three scenes: the hexagon room
// at tessellation 3 (1062 triangles, a closed room lit through a window) and the two open-sky
// stand-ins for real assets, open_pavilion (708 triangles: slabs, thin pillars on plinths, closed
// parts that meet) and open_street (ground, buildings, lamp posts). Per scene `runs` bakes
// (default 3) with the irradiance only (and, for the hexagon room, `runs` with L1 SH + HL2), then
// one reference bake with a hemicube at every texel (what a GPU hemicube lightmapper does). CSV:
// one row per run (time, the cache's placement and rendering time, hemicubes, invalid texels,
// error against the per-texel bake) plus the reference; the load average (/proc/loadavg) before
// and after is printed, since the machine may be shared.
// Converged comparison (out_converged.csv): both bakes against a converged reference (the bakes'
// own sample points, N = 256, the mean of 4 hemicubes rolled by different hashed angles), per texel
// class: "valid" = every 37th texel the per-texel bake calls valid, whatever the cached bake calls
// it (a texel the cache wrongly calls invalid counts with its filled value); "near_contact" =
// every 4th of the valid texels within 8 texels (lightmap distance) of a texel the per-texel bake
// calls invalid (inside geometry), where parts meet and contact shadows lie. wrongly_invalid counts
// the per-texel-valid texels the cached bake calls invalid. --truth-cache DIR keeps the converged
// values between runs (binary files named by scene, class, size and count). --bake-only: the cached
// bakes alone (no SH + HL2 runs, no reference, empty error columns), for paired timing rounds of
// two builds (benchmarks/paired_bake.sh).
// Levels (--scenes arena,keep,city_block,terrain_town, any mix with the scenes above; only when
// named): each named stand-in level (levels.hpp, default size unless --level-triangles) packed by
// make_level for each of --sizes (default 512, 1024) and baked at that size with its sky and its
// sun, N = 64, two threads, for each of --bounces (default 1, 3): `runs` cached bakes, the per-texel
// bake and the converged comparison as above, except that the strides of the two texel classes
// grow so that each has at most --max-points texels (default 4000; every 37th and every 4th would
// be 10-50k texels at 1024^2), and with bounces B > 1 the converged reference's final gather (N =
// 256, 4 rolls) sees the radiance of a per-texel bake of B - 1 bounces (bake_radiance_texture):
// converged in its last gather, the earlier bounces at the per-texel bake's N = 64. The lights'
// direct irradiance is added to every reference value as the bake adds it (the same function at
// the same point: exactly the bake's). Extra columns: bounces, hemicube_share (rendering and
// integrating hemicubes over the bake's wall time), direct_seconds, load1 (before the bake); in
// the converged CSV size, bounces, stride and converged_seconds. Scene labels there:
// NAME_SIZE. The relative RMS is dominated by the sunlit texels (the sun's direct light is
// per texel and exact in every bake); the mean relative error weighs every texel alike.
// Time on two quiet cores (default level size): about 15 minutes per level at 1024^2 (one and three
// bounces), 4 at 512^2.
#include "hemilight/bake.hpp"
#include "hemilight/cache.hpp"
#include "hemilight/levels.hpp"
#include "hemilight/lights.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/reference_scenes.hpp"
#include "hemilight/raster.hpp"

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

// The texel classes of the converged comparison (see the top): per-texel-valid texels, and among
// them those within contact_reach texels (Chebyshev distance in the lightmap) of a texel the
// per-texel bake calls invalid, where parts meet.
constexpr int contact_reach = 8;

std::vector<std::uint8_t> near_contact(const bake_result& per_texel, int w, int h) {
  std::vector<std::uint8_t> out(per_texel.valid.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t k = std::size_t(y) * std::size_t(w) + std::size_t(x);
      if (!per_texel.sampled[k] || per_texel.valid[k]) continue;  // an invalid texel marks its surroundings
      for (int dy = -contact_reach; dy <= contact_reach; ++dy)
        for (int dx = -contact_reach; dx <= contact_reach; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const std::size_t q = std::size_t(ny) * std::size_t(w) + std::size_t(nx);
          if (per_texel.sampled[q] && per_texel.valid[q]) out[q] = 1;
        }
    }
  return out;
}

// Converged luminance at the bake's own sample points of `texels` (N = 256, the mean of `rolls`
// hemicubes rolled by different hashed angles), read from / written to truth_dir when given.
// `texture` (bounces > 1): the radiance the hemicubes see, else the triangles' emission; the
// bake's lights (o.lights) are added at each point as the bake adds them (direct_irradiance at the
// same offset point with the same options: bit for bit the bake's own E_L).
std::vector<double> converged_truth(const bake_input& in, const bake_options& o, const std::vector<std::size_t>& texels,
                                    const std::string& name, const std::string& truth_dir, double& seconds,
                                    const radiance_texture* texture = nullptr) {
  const int n = 256, rolls = 4;
  std::vector<double> truth(texels.size());
  const std::string file = truth_dir.empty() ? "" : truth_dir + "/" + name + "_" + std::to_string(o.width) + "_n" +
                                                      std::to_string(n) + "_" + std::to_string(texels.size()) + ".bin";
  seconds = 0.0;
  if (!file.empty()) {
    std::ifstream f(file, std::ios::binary);
    if (f.read(reinterpret_cast<char*>(truth.data()), std::streamsize(truth.size() * sizeof(double)))) return truth;
  }
  const lightmap_samples s = compute_lightmap_samples(in, o.width, o.height);
  const auto sc = scene::create(in.scene);
  const float min_offset = 2.0f * default_near_distance(*sc);  // bake.hpp, step 2
  sampler_options so;
  so.resolution = n;
  sampler_pass pass;
  pass.texture = texture;
  const irradiance_sampler sampler = make_hemicube_sampler(sc, so, o.thread_count, pass);
  const light_set lights(o.lights.data(), o.lights.size());
  const auto t0 = std::chrono::steady_clock::now();
  parallel_for(texels.size(), o.thread_count, 16, [&](int worker, std::size_t b, std::size_t e) {
    for (std::size_t j = b; j < e; ++j) {
      const std::size_t k = texels[j];
      const glm::vec3 p = s.position[k] + std::max(min_offset, o.offset_texels * s.texel_world_size[k]) * s.normal[k];
      double sum = 0.0;
      for (int r = 0; r < rolls; ++r) {
        // r float ulps along one coordinate (< 1e-6 m): another hashed roll, the same point.
        glm::vec3 q = p;
        for (int u = 0; u < r; ++u) q.x = std::nextafter(q.x, 1e30f);
        const glm::vec3 e3 = sampler(worker, q, s.normal[k]).irradiance;
        sum += 0.2126 * e3.x + 0.7152 * e3.y + 0.0722 * e3.z;
      }
      double direct = 0.0;
      if (!lights.empty()) {
        const glm::vec3 d = direct_irradiance(*sc, lights, p, s.normal[k], o.direct);
        direct = 0.2126 * d.x + 0.7152 * d.y + 0.0722 * d.z;
      }
      truth[j] = sum / rolls + direct;
    }
  });
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!file.empty()) {
    std::ofstream f(file, std::ios::binary);
    f.write(reinterpret_cast<const char*>(truth.data()), std::streamsize(truth.size() * sizeof(double)));
  }
  return truth;
}

// Relative RMS and mean relative error (5% floor) of a bake's luminance against `truth`.
void errors_against(const bake_result& r, const std::vector<std::size_t>& texels, const std::vector<double>& truth, double& rms,
                    double& mean) {
  double mean_truth = 0.0;
  for (double t : truth) mean_truth += t;
  mean_truth /= double(std::max<std::size_t>(truth.size(), 1));
  double num = 0.0, den = 0.0, rel = 0.0;
  for (std::size_t j = 0; j < texels.size(); ++j) {
    const double y = luminance(r.irradiance.pixels.data() + 3 * texels[j]);
    num += (y - truth[j]) * (y - truth[j]);
    den += truth[j] * truth[j];
    rel += std::fabs(y - truth[j]) / std::max(truth[j], 0.05 * mean_truth);
  }
  rms = std::sqrt(num / std::max(den, 1e-300));
  mean = rel / double(std::max<std::size_t>(texels.size(), 1));
}

// The cached bake and the per-texel bake against a converged reference, per texel class (top of
// the file): every 37th texel the per-texel bake calls valid ("valid", whatever the cached bake
// calls it: its filled values count), and every 4th of those near a contact ("near_contact"); with
// max_points > 0 the strides grow so that each class has at most about max_points texels (the
// levels). Rows appended to `f` (converged CSV). `texture`, `bounces`: converged_truth's and the
// rows' (bounces > 1: the radiance the reference's final gather sees).
void converged_comparison(std::FILE* f, const std::string& name, const bake_input& in, const bake_options& o,
                          const bake_result& cached, const bake_result& per_texel, const std::string& truth_dir,
                          std::size_t max_points = 0, const radiance_texture* texture = nullptr) {
  const std::vector<std::uint8_t> contact = near_contact(per_texel, o.width, o.height);
  std::size_t valid_count = 0, contact_count = 0;
  for (std::size_t k = 0; k < per_texel.valid.size(); ++k)
    if (per_texel.sampled[k] && per_texel.valid[k]) {
      ++valid_count;
      if (contact[k]) ++contact_count;
    }
  std::size_t valid_stride = 37, contact_stride = 4;
  if (max_points > 0) {
    valid_stride = std::max(valid_stride, (valid_count + max_points - 1) / max_points);
    contact_stride = std::max(contact_stride, (contact_count + max_points - 1) / max_points);
  }
  std::size_t wrongly_invalid = 0, valid_texels = 0, contact_texels = 0;
  std::vector<std::size_t> all, near;
  for (std::size_t k = 0; k < per_texel.valid.size(); ++k) {
    if (!per_texel.sampled[k] || !per_texel.valid[k]) continue;
    if (!cached.valid[k]) ++wrongly_invalid;
    if (valid_texels++ % valid_stride == 0) all.push_back(k);
    if (contact[k] && contact_texels++ % contact_stride == 0) near.push_back(k);
  }
  const struct {
    const char* label;
    const std::vector<std::size_t>& texels;
    std::size_t stride;
  } classes[] = {{"valid", all, valid_stride}, {"near_contact", near, contact_stride}};
  for (const auto& c : classes) {
    if (c.texels.empty()) continue;
    double seconds = 0.0;
    const std::string truth_name = name + "_" + c.label + (o.bounces > 1 ? "_b" + std::to_string(o.bounces) : "");
    const std::vector<double> truth = converged_truth(in, o, c.texels, truth_name, truth_dir, seconds, texture);
    double cache_rms, cache_mean, texel_rms, texel_mean;
    errors_against(cached, c.texels, truth, cache_rms, cache_mean);
    errors_against(per_texel, c.texels, truth, texel_rms, texel_mean);
    std::fprintf(f, "%s,cache_a0.2_n64,%s,%zu,256,4,%.5f,%.5f,%zu,%d,%d,%zu,%.1f\n", name.c_str(), c.label, c.texels.size(), cache_rms,
                 cache_mean, wrongly_invalid, o.width, o.bounces, c.stride, seconds);
    std::fprintf(f, "%s,per_texel_n64,%s,%zu,256,4,%.5f,%.5f,0,%d,%d,%zu,%.1f\n", name.c_str(), c.label, c.texels.size(), texel_rms,
                 texel_mean, o.width, o.bounces, c.stride, seconds);
    std::fflush(f);
    std::printf("  %s against a converged reference (N = 256, 4 rolls, %zu texels, every %zu, %.1f s): cached bake RMS %.4f, mean %.4f; "
                "hemicube per texel RMS %.4f, mean %.4f; %zu per-texel-valid texels the cached bake calls invalid\n",
                c.label, c.texels.size(), c.stride, seconds, cache_rms, cache_mean, texel_rms, texel_mean, wrongly_invalid);
    std::fflush(stdout);
  }
}

// A bake of the target: a scene with its lightmap UVs, lights, size and bounce count.
struct target_job {
  std::string name;
  scene_mesh mesh;
  std::vector<light> lights;
  int size = 654;
  int bounces = 1;
  bool level = false;
};

// The jobs of --target: the three scenes at 654^2, one bounce (chart UVs from
// generate_lightmap_uvs), then each named level at each of level_sizes and bounce_counts (its UVs
// packed by make_level for that size, its sun). `only` empty: the three scenes.
std::vector<target_job> target_jobs(const std::vector<std::string>& only, const std::vector<int>& level_sizes,
                                    const std::vector<int>& bounce_counts, std::size_t level_triangles) {
  const auto wanted = [&](const std::string& n) { return only.empty() || std::find(only.begin(), only.end(), n) != only.end(); };
  std::vector<target_job> jobs;
  const struct {
    const char* name;
    scene_mesh (*build)();
  } scenes[] = {{"hexagon_room_t3", [] { return hexagon_room(3); }}, {"open_pavilion", [] { return open_pavilion(); }},
                {"open_street", [] { return open_street(); }}};
  for (const auto& sc : scenes)
    if (wanted(sc.name)) {
      target_job j;
      j.name = sc.name;
      j.mesh = sc.build();
      generate_lightmap_uvs(j.mesh, j.size, 2);
      jobs.push_back(std::move(j));
    }
  for (const std::string& l : level_names())
    if (!only.empty() && wanted(l))
      for (int size : level_sizes) {
        level_options lo;
        lo.lightmap_size = size;
        lo.target_triangles = level_triangles;
        level lv = make_level(l, lo);
        for (int b : bounce_counts) {
          target_job j;
          j.name = l;
          j.mesh = lv.mesh;
          j.lights = lv.lights;
          j.size = size;
          j.bounces = b;
          j.level = true;
          jobs.push_back(std::move(j));
        }
      }
  return jobs;
}

// Wall time of rendering and integrating hemicubes, all passes (a per-texel pass is all hemicubes:
// its cache_stats has only `seconds`).
double hemicube_seconds(const bake_stats& s) {
  double t = 0.0;
  for (const cache_stats& p : s.passes) t += p.render_seconds > 0.0 || p.placement_seconds > 0.0 ? p.render_seconds : p.seconds;
  return t;
}

double placement_seconds(const bake_stats& s) {
  double t = 0.0;
  for (const cache_stats& p : s.passes) t += p.placement_seconds;
  return t;
}

int target(const char* path, int runs, const std::vector<std::string>& only, const std::string& truth_dir, bool bake_only,
           const std::vector<int>& level_sizes, const std::vector<int>& bounce_counts, std::size_t max_points,
           std::size_t level_triangles) {
  std::FILE* f = std::fopen(path, "w");
  std::string conv_path = path;
  const std::size_t dot = conv_path.rfind(".csv");
  conv_path = (dot == std::string::npos ? conv_path : conv_path.substr(0, dot)) + "_converged.csv";
  std::FILE* fc = bake_only ? nullptr : std::fopen(conv_path.c_str(), "w");
  if (!f || (!bake_only && !fc)) {
    std::fprintf(stderr, "cannot write %s or %s\n", path, conv_path.c_str());
    return 1;
  }
  std::printf("load average before: %s\n", load_average().c_str());
  std::fprintf(f, "run,scene,triangles,size,directional,seconds,placement_seconds,render_seconds,sampled_texels,hemicubes,"
                  "hemicube_fraction,invalid_texels,rms_error,mean_error,bounces,hemicube_share,direct_seconds,load1\n");
  if (fc)
    std::fprintf(fc, "scene,bake,class,points,converged_resolution,converged_rolls,rms_error,mean_error,wrongly_invalid,size,"
                     "bounces,stride,converged_seconds\n");
  for (target_job& ts : target_jobs(only, level_sizes, bounce_counts, level_triangles)) {
    bake_input in;
    in.scene = ts.mesh.desc();
    bake_options o;
    o.width = o.height = ts.size;
    o.sampler.resolution = 64;
    o.bounces = ts.bounces;
    o.thread_count = 2;
    o.lights = ts.lights;
    std::printf("%s: %zu triangles, %d^2, %d bounce(s)%s\n", ts.name.c_str(), ts.mesh.triangle_count(), ts.size, ts.bounces,
                ts.lights.empty() ? "" : ", with its sun");
    std::fflush(stdout);
    std::vector<bake_result> results;
    std::vector<double> loads;
    // The directional runs only for the hexagon room (the figure the docs have tracked).
    const int directional_modes = ts.name == "hexagon_room_t3" && !bake_only ? 2 : 1;
    for (int directional = 0; directional < directional_modes; ++directional)
      for (int run = 0; run < runs; ++run) {
        o.output_sh_l1 = o.output_hl2 = directional == 1;
        loads.push_back(std::atof(load_average().c_str()));
        bake_result r = bake_lightmap(in, o);
        std::printf("  run %d%s: %.3f s (placement %.3f s, rendering %.3f s), %zu hemicubes for %zu sampled texels\n", run,
                    directional ? " (SH + HL2)" : "", r.stats.seconds, placement_seconds(r.stats), hemicube_seconds(r.stats),
                    r.stats.hemicubes, r.stats.sampled_texels);
        std::fflush(stdout);
        results.push_back(std::move(r));
      }
    const auto row = [&](const std::string& run, const bake_result& r, int directional, const char* rms, const char* mean, double load) {
      const bake_stats& st = r.stats;
      std::fprintf(f, "%s,%s,%zu,%d,%d,%.4f,%.4f,%.4f,%zu,%zu,%.4f,%zu,%s,%s,%d,%.4f,%.4f,%.2f\n", run.c_str(), ts.name.c_str(),
                   ts.mesh.triangle_count(), ts.size, directional, st.seconds, placement_seconds(st), hemicube_seconds(st),
                   st.sampled_texels, st.hemicubes,
                   double(st.hemicubes) / double(st.sampled_texels * std::size_t(ts.bounces)), st.invalid_texels, rms, mean, ts.bounces,
                   hemicube_seconds(st) / st.seconds, st.direct_seconds, load);
    };
    if (bake_only) {  // the cached bakes alone (paired timing rounds): no reference, no error columns
      for (std::size_t i = 0; i < results.size(); ++i) row(std::to_string(i), results[i], 0, "", "", loads[i]);
      std::fflush(f);
      continue;
    }
    o.output_sh_l1 = o.output_hl2 = false;
    o.use_cache = false;
    const double ref_load = std::atof(load_average().c_str());
    const bake_result ref = bake_lightmap(in, o);
    for (std::size_t i = 0; i < results.size(); ++i) {
      double rms, mean;
      compare(results[i], ref, rms, mean);
      char a[32], b[32];
      std::snprintf(a, sizeof a, "%.5f", rms);
      std::snprintf(b, sizeof b, "%.5f", mean);
      row(std::to_string(i % std::size_t(runs)), results[i], int(i / std::size_t(runs)), a, b, loads[i]);
    }
    row("reference", ref, 0, "0", "0", ref_load);
    std::fflush(f);
    double rms, mean;
    compare(results[0], ref, rms, mean);
    std::printf("  reference (hemicube per texel): %.2f s; cache vs reference: relative RMS %.4f, mean relative %.4f\n",
                ref.stats.seconds, rms, mean);
    std::fflush(stdout);
    // Bounces > 1: the reference's final gather sees the radiance of a per-texel bake of one bounce
    // fewer (bake_radiance_texture), so the reference is converged in its last gather only.
    image previous;
    radiance_texture texture;
    if (ts.bounces > 1) {
      bake_options ob = o;
      ob.bounces = ts.bounces - 1;
      const bake_result prev = bake_lightmap(in, ob);
      previous = bake_radiance_texture(in, ob, prev);
      texture = radiance_texture(previous);
      std::printf("  per-texel bake of %d bounce(s) for the reference's radiance: %.1f s\n", ob.bounces, prev.stats.seconds);
    }
    const std::string label = ts.level ? ts.name + "_" + std::to_string(ts.size) : ts.name;
    converged_comparison(fc, label, in, o, results[0], ref, truth_dir, ts.level ? max_points : 0,
                         ts.bounces > 1 ? &texture : nullptr);
  }
  std::fclose(f);
  if (fc) std::fclose(fc);
  std::printf("load average after: %s\n", load_average().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 3 && std::string(argv[1]) == "--target") {
    int runs = 3;
    std::vector<std::string> only;
    std::string truth_dir;
    bool bake_only = false;
    std::vector<int> level_sizes = {512, 1024}, bounce_counts = {1, 3};
    std::size_t max_points = 4000, level_triangles = 0;
    const auto ints = [](const char* text) {
      std::vector<int> v;
      std::stringstream list(text);
      for (std::string item; std::getline(list, item, ',');) v.push_back(std::atoi(item.c_str()));
      return v;
    };
    for (int i = 3; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--scenes" && i + 1 < argc) {
        std::stringstream list(argv[++i]);
        for (std::string item; std::getline(list, item, ',');) only.push_back(item);
      } else if (a == "--truth-cache" && i + 1 < argc) {
        truth_dir = argv[++i];
      } else if (a == "--bake-only") {
        bake_only = true;
      } else if (a == "--sizes" && i + 1 < argc) {
        level_sizes = ints(argv[++i]);
      } else if (a == "--bounces" && i + 1 < argc) {
        bounce_counts = ints(argv[++i]);
      } else if (a == "--level-triangles" && i + 1 < argc) {
        level_triangles = std::size_t(std::max(0, std::atoi(argv[++i])));
      } else if (a == "--max-points" && i + 1 < argc) {
        max_points = std::size_t(std::max(0, std::atoi(argv[++i])));
      } else {
        runs = std::max(1, std::atoi(argv[i]));
      }
    }
    try {
      return target(argv[2], runs, only, truth_dir, bake_only, level_sizes, bounce_counts, max_points, level_triangles);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "sweep_bake: %s\n", e.what());
      return 1;
    }
  }
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
        o.sampler.resolution = 64;
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
