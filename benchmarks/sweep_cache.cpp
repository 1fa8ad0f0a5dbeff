// Speed against accuracy of the irradiance cache (docs/cache.md, "Measured").
//
//   usage: sweep_cache out.csv [grid] [options]
//     --grid K            points per side of each surface (default 128; also the 2nd positional argument)
//     --n N[,N...]        hemicube resolutions to sweep (default 64)
//     --scenes LIST       any of cornell,hexagon,sky (default all three)
//     --a LIST            thresholds a (default 0.05,0.1,0.15,0.2,0.3,0.4,0.5)
//     --converged N       resolution of the converged reference (default 256)
//     --stride S          the converged reference is rendered at every S-th point (default 7)
//     --rolls R           the converged reference is the mean of R hemicubes per point, each rolled
//                         by a different hashed angle (the point nudged by r float ulps in its
//                         plane, r = 0..R-1, i.e. < 1e-6 m): averages the aliasing noise (default 1)
//     --check N           also render every --check-stride-th point of that subset at N (> the
//                         converged N) and report the converged reference's own RMS error against
//                         it, so "converged" can be verified (default: no check)
//     --check-stride S    (default 4)
//     --truth-cache DIR   keep the converged (and check) luminances in DIR/*.bin (DIR is created) keyed by scene,
//                         grid, N and stride, so split runs do not render them twice
//     --append            append rows to out.csv (header only if the file is empty)
//     --gradients LIST    any of yes,no (default yes,no)
//     --threads T         worker threads (default 0 = all cores)
//     --lone-record-change-limit F     cache_options::expert.lone_record_change_limit (default: the
//                                      option's default; 0 = off)
//     --lone-record-neighbour-reach F  cache_options::expert.lone_record_neighbour_reach (default: the
//                                      option's default; 0 = off)
//     --lone-record-reach F            cache_options::expert.lone_record_reach (default: the option's
//                                      default; 1 = off)
//     --weight W          cache_options::weight: ward, ward_continuous or tabellion_lamorlette
//                         (default: the option's default)
//     --second-order yes|no  cache_options::second_order (default: the option's default, yes)
//     --space-finest yes|no  cache_expert_options::space_finest_seeds (default: the option's default)
//     --worst K           print the K points of largest error against the per-point reference
//     --extrapolate-wall-depth yes|no  integrate_options::extrapolate_wall_depth of the cache's hemicubes
//     --record-regions    Cornell box: print where the records are (floor / walls, dark or lit, the
//                         walls' rows under the emitter's plane), how many sit at min_radius, and
//                         each region's points, share of the squared error and RMS (per point)
//     --variant NAME      written to the last CSV column (default "default"): which cache options
//   With --truth-cache the per-point reference (a hemicube at every point) is kept there too
//   (stride 1, 1 roll), so reruns with other cache options do not render it again.
//   `sweep_cache out.csv` alone gives the default run of `bash benchmarks/run.sh cache`.
//
// Scenes (reference_scenes.hpp): the Cornell box floor and walls; the hexagon room's ceiling
// (lit by the sky through the window); the ground of "sky and occluders". Points lie on a grid
// over those surfaces (under the boxes they are inside geometry: invalid, filled, and left out of
// the error). Two references:
// - per point: a hemicube at every point with the same sampler (same N, same hashed roll), so
//   the error against it is the cache's interpolation error alone;
// - converged: a hemicube of --converged resolution at every --stride-th point (points whose
//   converged hemicube sees > 10% back faces are left out). The error against it is the total
//   error of the cache; the same error of the per-point reference is the hemicube's own error
//   at N (aliasing of small emitters and windows, different from point to point because every
//   hemicube is rolled by a hashed angle), which bounds what "error against per point" can mean.
// For each N, a and with/without gradients: fraction of points given a hemicube, RMS and max
// relative error (luminance; relative to max(E_ref, 5% of the mean E_ref), so umbra points do not
// divide by ~0) against both references, wall time, and the 1-minute load average at the start of
// the run (the machine may be shared: times are indicative).
#include "bench_util.hpp"
#include "hemilight/cache.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/reference_scenes.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

struct point_set {
  std::string key, name;
  scene_mesh mesh;
  std::vector<glm::vec3> p, n;
};

// k x k points on the parallelogram o + s u + t v, normal n (bench::grid_points).
void grid(point_set& ps, glm::vec3 o, glm::vec3 u, glm::vec3 v, glm::vec3 n, int k) {
  bench::grid_points(ps.p, ps.n, o, u, v, n, k);
}

using bench::lum;
using bench::loadavg;
using bench::seconds_since;

[[noreturn]] void usage(const char* why) {
  std::fprintf(stderr,
               "sweep_cache: %s\nusage: sweep_cache out.csv [grid] [--grid K] [--n N,...] [--scenes cornell,hexagon,sky]\n"
               "       [--a a,...] [--converged N] [--stride S] [--check N] [--check-stride S] [--truth-cache DIR] [--append]\n",
               why);
  std::exit(2);
}

using bench::split;

int to_int(const std::string& s, const char* what) {
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || v <= 0 || v > 1 << 20) usage((std::string("bad ") + what + " '" + s + "'").c_str());
  return int(v);
}

// Luminance of `sampler` at the given points, optionally kept in / read from a cache file.
// Entries are (point index, luminance, backface fraction).
struct truth_entry {
  std::uint32_t index;
  float luminance, backface;
};

std::vector<truth_entry> render_luminance(const point_set& ps, const std::vector<std::size_t>& idx, int resolution,
                                          int rolls, int threads, const std::string& cache_file, double& secs) {
  std::vector<truth_entry> t(idx.size());
  if (!cache_file.empty())
    if (FILE* f = std::fopen(cache_file.c_str(), "rb")) {
      std::uint64_t n = 0;
      const bool ok = std::fread(&n, sizeof n, 1, f) == 1 && n == idx.size() &&
                      std::fread(t.data(), sizeof(truth_entry), t.size(), f) == t.size();
      std::fclose(f);
      bool same = ok;
      for (std::size_t i = 0; same && i < idx.size(); ++i) same = t[i].index == idx[i];
      if (same) {
        secs = 0.0;
        std::printf("  read %s\n", cache_file.c_str());
        return t;
      }
    }
  auto sc = scene::create(ps.mesh.desc());
  sampler_options so;
  so.resolution = resolution;
  const irradiance_sampler sampler = make_hemicube_sampler(sc, so, threads);
  const auto t0 = std::chrono::steady_clock::now();
  parallel_for(idx.size(), threads, 4, [&](int w, std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const glm::vec3 n = ps.n[idx[k]];
      // nudge the in-plane coordinate (the normal's smallest component) by r ulps: another roll
      const int c = std::fabs(n.x) <= std::fabs(n.y) && std::fabs(n.x) <= std::fabs(n.z) ? 0 : std::fabs(n.y) <= std::fabs(n.z) ? 1 : 2;
      double l = 0.0, bf = 0.0;
      for (int r = 0; r < rolls; ++r) {
        glm::vec3 x = ps.p[idx[k]];
        for (int u = 0; u < r; ++u) x[c] = std::nextafter(x[c], 1e30f);
        const irradiance_sample s = sampler(w, x, n);
        l += double(lum(s.irradiance));
        bf += double(s.backface_fraction);
      }
      t[k] = {std::uint32_t(idx[k]), float(l / rolls), float(bf / rolls)};
    }
  });
  secs = seconds_since(t0);
  if (!cache_file.empty())
    if (FILE* f = std::fopen(cache_file.c_str(), "wb")) {
      const std::uint64_t n = t.size();
      std::fwrite(&n, sizeof n, 1, f);
      std::fwrite(t.data(), sizeof(truth_entry), t.size(), f);
      std::fclose(f);
    }
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  std::string path = "cache_sweep.csv", truth_dir;
  int k = 128, converged_n = 256, stride = 7, rolls = 1, check_n = 0, check_stride = 4, thread_arg = 0;
  bool append = false;
  std::vector<bool> gradient_modes{true, false};
  std::string variant = "default";
  int worst_k = 0;
  float lone_record_change_limit = cache_options{}.expert.lone_record_change_limit;
  float lone_record_neighbour_reach = cache_options{}.expert.lone_record_neighbour_reach;
  float lone_record_reach = cache_options{}.expert.lone_record_reach;
  cache_weight weight = cache_options{}.weight;
  bool extrapolate_wall_depth = integrate_options{}.extrapolate_wall_depth;
  bool second_order = cache_options{}.second_order;
  bool space_finest = cache_options{}.expert.space_finest_seeds;
  bool record_regions = false;
  std::vector<int> resolutions{64};
  std::vector<float> thresholds{0.05f, 0.1f, 0.15f, 0.2f, 0.3f, 0.4f, 0.5f};
  std::vector<std::string> scene_keys{"cornell", "hexagon", "sky"};
  int positional = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage((arg + " needs a value").c_str());
      return argv[++i];
    };
    if (arg == "--grid") k = to_int(value(), "grid");
    else if (arg == "--n") {
      resolutions.clear();
      for (const std::string& s : split(value())) resolutions.push_back(to_int(s, "resolution"));
    } else if (arg == "--scenes") scene_keys = split(value());
    else if (arg == "--a") {
      thresholds.clear();
      for (const std::string& s : split(value())) {
        const float a = std::strtof(s.c_str(), nullptr);
        if (!(a > 0.0f && a <= 1.0f)) usage(("bad a '" + s + "'").c_str());
        thresholds.push_back(a);
      }
    } else if (arg == "--converged") converged_n = to_int(value(), "converged resolution");
    else if (arg == "--stride") stride = to_int(value(), "stride");
    else if (arg == "--rolls") rolls = to_int(value(), "rolls");
    else if (arg == "--check") check_n = to_int(value(), "check resolution");
    else if (arg == "--check-stride") check_stride = to_int(value(), "check stride");
    else if (arg == "--truth-cache") truth_dir = value();
    else if (arg == "--append") append = true;
    else if (arg == "--variant") {
      variant = value();
      if (variant.find_first_of(",\"\n") != std::string::npos) usage("--variant must not contain commas, quotes or newlines (it is a CSV field)");
    }
    else if (arg == "--lone-record-change-limit") {
      const std::string v = value();
      lone_record_change_limit = std::strtof(v.c_str(), nullptr);
      if (!(lone_record_change_limit >= 0.0f && lone_record_change_limit < 1e6f))
        usage(("bad --lone-record-change-limit '" + v + "'").c_str());
    } else if (arg == "--lone-record-neighbour-reach") {
      const std::string v = value();
      lone_record_neighbour_reach = std::strtof(v.c_str(), nullptr);
      if (!(lone_record_neighbour_reach >= 0.0f && lone_record_neighbour_reach <= 16.0f))
        usage(("bad --lone-record-neighbour-reach '" + v + "'").c_str());
    } else if (arg == "--weight") {
      const std::string v = value();
      if (v == "ward") weight = cache_weight::ward;
      else if (v == "ward_continuous") weight = cache_weight::ward_continuous;
      else if (v == "tabellion_lamorlette") weight = cache_weight::tabellion_lamorlette;
      else usage(("bad --weight '" + v + "' (ward, ward_continuous, tabellion_lamorlette)").c_str());
    } else if (arg == "--lone-record-reach") {
      const std::string v = value();
      lone_record_reach = std::strtof(v.c_str(), nullptr);
      if (!(lone_record_reach > 0.0f && lone_record_reach <= 1.0f)) usage(("bad --lone-record-reach '" + v + "'").c_str());
    } else if (arg == "--extrapolate-wall-depth") {
      const std::string v = value();
      if (v != "yes" && v != "no") usage(("bad --extrapolate-wall-depth '" + v + "' (yes, no)").c_str());
      extrapolate_wall_depth = v == "yes";
    } else if (arg == "--second-order") {
      const std::string v = value();
      if (v != "yes" && v != "no") usage(("bad --second-order '" + v + "' (yes, no)").c_str());
      second_order = v == "yes";
    } else if (arg == "--space-finest") {
      const std::string v = value();
      if (v != "yes" && v != "no") usage(("bad --space-finest '" + v + "' (yes, no)").c_str());
      space_finest = v == "yes";
    } else if (arg == "--record-regions") {
      record_regions = true;
    } else if (arg == "--worst") worst_k = to_int(value(), "worst");
    else if (arg == "--threads") thread_arg = to_int(value(), "threads");
    else if (arg == "--gradients") {
      gradient_modes.clear();
      for (const std::string& s : split(value())) {
        if (s != "yes" && s != "no") usage(("bad --gradients '" + s + "' (yes, no)").c_str());
        gradient_modes.push_back(s == "yes");
      }
    }
    else if (arg.size() > 1 && arg[0] == '-') usage(("unknown option " + arg).c_str());
    else if (positional == 0) path = arg, ++positional;
    else if (positional == 1) k = to_int(arg, "grid"), ++positional;
    else usage(("unexpected argument " + arg).c_str());
  }
  if (resolutions.empty() || thresholds.empty() || scene_keys.empty() || gradient_modes.empty()) usage("empty list");

  bool write_header = true;
  if (append)
    if (FILE* f = std::fopen(path.c_str(), "rb")) {
      write_header = std::fgetc(f) == EOF;
      std::fclose(f);
    }
  FILE* out = std::fopen(path.c_str(), append ? "a" : "w");
  if (!out) {
    std::fprintf(stderr, "sweep_cache: cannot write '%s'\n", path.c_str());
    return 1;
  }
  if (write_header)
    std::fprintf(out, "scene,grid,resolution,points,a,gradients,hemicubes,fraction,rms_rel_err,max_rel_err,"
                      "rms_rel_err_converged,max_rel_err_converged,reference_rms_rel_err_converged,"
                      "reference_max_rel_err_converged,seconds,reference_seconds,converged_resolution,"
                      "converged_rolls,converged_points,check_resolution,check_points,converged_rms_rel_err_check,"
                      "converged_max_rel_err_check,threads,loadavg,variant\n");

  std::vector<point_set> sets;
  for (const std::string& key : scene_keys) {
    point_set ps;
    ps.key = key;
    if (key == "cornell") {
      ps.name = "cornell box";
      ps.mesh = cornell_box();
      bench::cornell_box_grid(ps.p, ps.n, k);
    } else if (key == "hexagon") {
      ps.name = "hexagon room ceiling";
      ps.mesh = hexagon_room();
      point_set tmp;
      grid(tmp, {-4, 3, -4}, {8, 0, 0}, {0, 0, 8}, {0, -1, 0}, k);
      for (std::size_t i = 0; i < tmp.p.size(); ++i) {
        // inside the hexagon (circumradius 4, corners at 60 i degrees): |x| <= 4 - |z| / sqrt3 and |z| <= 2 sqrt3
        const float x = std::fabs(tmp.p[i].x), z = std::fabs(tmp.p[i].z);
        if (z < 3.4f && x < 3.95f - z / 1.7320508f) {
          ps.p.push_back(tmp.p[i]);
          ps.n.push_back(tmp.n[i]);
        }
      }
    } else if (key == "sky") {
      ps.name = "sky and occluders";
      ps.mesh = sky_and_occluders();
      grid(ps, {-10, 0, -10}, {20, 0, 0}, {0, 0, 20}, {0, 1, 0}, k);
    } else {
      usage(("unknown scene '" + key + "' (cornell, hexagon, sky)").c_str());
    }
    sets.push_back(std::move(ps));
  }

  if (!truth_dir.empty()) {
    // Without the folder nothing would be kept, silently, and every run would render its references again.
    std::error_code ec;
    std::filesystem::create_directories(truth_dir, ec);
    if (ec) usage(("cannot create --truth-cache folder '" + truth_dir + "': " + ec.message()).c_str());
  }
  const int threads = resolve_thread_count(thread_arg);
  for (point_set& ps : sets) {
    const std::size_t count = ps.p.size();
    auto sc = scene::create(ps.mesh.desc());
    auto cache_file = [&](int n, int s, int r) {
      if (truth_dir.empty()) return std::string();
      return truth_dir + "/truth_" + ps.key + "_k" + std::to_string(k) + "_N" + std::to_string(n) + "_s" +
             std::to_string(s) + "_r" + std::to_string(r) + ".bin";
    };

    // Converged reference at every stride-th point; points inside geometry are dropped.
    std::vector<std::size_t> every;
    for (std::size_t i = 0; i < count; i += std::size_t(stride)) every.push_back(i);
    double truth_seconds = 0.0;
    const double load0 = loadavg();
    const std::vector<truth_entry> rendered =
        render_luminance(ps, every, converged_n, rolls, threads, cache_file(converged_n, stride, rolls), truth_seconds);
    std::vector<std::size_t> subset;
    std::vector<double> truth;
    for (const truth_entry& t : rendered)
      if (t.backface <= 0.1f) {
        subset.push_back(t.index);
        truth.push_back(double(t.luminance));
      }
    double truth_mean = 0.0;
    for (double t : truth) truth_mean += t;
    truth_mean /= double(std::max<std::size_t>(truth.size(), 1));
    std::printf("%s: %zu points; converged reference N = %d x %d rolls at %zu points (every %d-th, valid): %.1f s (load %.2f)\n",
                ps.name.c_str(), count, converged_n, rolls, subset.size(), stride, truth_seconds, load0);
    std::fflush(stdout);

    // Is the converged reference converged? Compare it with a finer one on part of the subset.
    double check_rms = -1.0, check_max = -1.0;
    std::size_t check_points = 0;
    if (check_n > 0) {
      std::vector<std::size_t> cidx, cpos;
      for (std::size_t j = 0; j < subset.size(); j += std::size_t(check_stride)) {
        cidx.push_back(subset[j]);
        cpos.push_back(j);
      }
      double check_seconds = 0.0;
      const std::vector<truth_entry> fine =
          render_luminance(ps, cidx, check_n, 1, threads, cache_file(check_n, stride * check_stride, 1), check_seconds);
      double sum = 0.0, worst = 0.0, bias = 0.0;
      for (std::size_t j = 0; j < fine.size(); ++j) {
        const double f = fine[j].luminance;
        const double err = std::fabs(truth[cpos[j]] - f) / std::max(f, 0.05 * truth_mean);
        bias += (truth[cpos[j]] - f) / std::max(f, 0.05 * truth_mean);
        sum += err * err;
        worst = std::max(worst, err);
      }
      check_points = fine.size();
      check_rms = std::sqrt(sum / double(std::max<std::size_t>(check_points, 1)));
      check_max = worst;
      std::printf("  check: converged N = %d x %d rolls against N = %d at %zu points: RMS %.4f%%, max %.3f%%, mean "
                  "signed %.4f%% (%.1f s)\n",
                  converged_n, rolls, check_n, check_points, 100.0 * check_rms, 100.0 * check_max,
                  100.0 * bias / double(std::max<std::size_t>(check_points, 1)), check_seconds);
      std::fflush(stdout);
    }
    // RMS and max error against the converged reference of the luminance value_of(point index).
    auto vs_converged = [&](auto value_of, double& rms, double& worst) {
      double sum = 0.0;
      worst = 0.0;
      for (std::size_t j = 0; j < subset.size(); ++j) {
        const double err = std::fabs(double(value_of(subset[j])) - truth[j]) / std::max(truth[j], 0.05 * truth_mean);
        sum += err * err;
        worst = std::max(worst, err);
      }
      rms = std::sqrt(sum / double(std::max<std::size_t>(subset.size(), 1)));
    };

    for (int resolution : resolutions) {
      sampler_options so;
      so.resolution = resolution;
      so.integrate.extrapolate_wall_depth = extrapolate_wall_depth;
      const irradiance_sampler sampler = make_hemicube_sampler(sc, so, threads);
      // Per-point reference: a hemicube at every point (luminance, backface fraction; stride 1,
      // one roll = no nudge, the same sampler calls as the cache makes).
      std::vector<std::size_t> all(count);
      for (std::size_t i = 0; i < count; ++i) all[i] = i;
      const double load_ref = loadavg();
      double ref_seconds = 0.0;
      const std::vector<truth_entry> ref = render_luminance(ps, all, resolution, 1, threads, cache_file(resolution, 1, 1), ref_seconds);
      double mean = 0.0;
      std::size_t valid = 0;
      for (std::size_t i = 0; i < count; ++i)
        if (ref[i].backface <= 0.1f) {
          mean += ref[i].luminance;
          ++valid;
        }
      mean /= double(std::max<std::size_t>(valid, 1));
      double ref_rms = 0.0, ref_max = 0.0;
      vs_converged([&](std::size_t i) { return ref[i].luminance; }, ref_rms, ref_max);
      std::printf(" N = %d: per-point reference %.1f s (%.0f hemicubes/s on %d threads, load %.2f); its own error "
                  "vs converged: RMS %.3f%%, max %.1f%%\n",
                  resolution, ref_seconds, double(count) / ref_seconds, threads, load_ref, 100.0 * ref_rms,
                  100.0 * ref_max);
      std::fflush(stdout);
      for (float a : thresholds)
        for (bool gradients : gradient_modes) {
          cache_options o;
          o.error_threshold = a;
          o.use_gradients = gradients;
          o.expert.lone_record_change_limit = lone_record_change_limit;
          o.expert.lone_record_neighbour_reach = lone_record_neighbour_reach;
          o.expert.lone_record_reach = lone_record_reach;
          o.weight = weight;
          o.second_order = second_order;
          o.expert.space_finest_seeds = space_finest;
          cache_run run;
          run.thread_count = threads;
          const double load = loadavg();
          const cache_result r = cache_irradiance(ps.p.data(), ps.n.data(), count, sampler, o, run);
          // Relative error of each point against the per-point reference; -1 where left out (inside
          // geometry, or filled).
          std::vector<double> err_of(count, -1.0);
          double sum = 0.0, worst = 0.0;
          std::size_t m = 0;
          for (std::size_t i = 0; i < count; ++i) {
            if (ref[i].backface > 0.1f || !r.valid[i]) continue;
            const double e_ref = ref[i].luminance;
            const double err = std::fabs(lum(r.irradiance[i]) - e_ref) / std::max(e_ref, 0.05 * mean);
            err_of[i] = err;
            sum += err * err;
            worst = std::max(worst, err);
            ++m;
          }
          const double rms = std::sqrt(sum / double(std::max<std::size_t>(m, 1)));
          if (worst_k > 0) {  // the worst points against the per-point reference
            std::vector<std::pair<double, std::size_t>> errs;
            for (std::size_t i = 0; i < count; ++i)
              if (err_of[i] >= 0.0) errs.push_back({err_of[i], i});
            const std::size_t kk = std::min<std::size_t>(std::size_t(worst_k), errs.size());
            std::partial_sort(errs.begin(), errs.begin() + std::ptrdiff_t(kk), errs.end(), std::greater<>());
            for (std::size_t j = 0; j < kk; ++j) {
              const std::size_t i = errs[j].second;
              std::printf("    worst %zu: point %zu (%.4f, %.4f, %.4f) n (%.0f, %.0f, %.0f) ref %.4f cache %.4f err %.1f%%\n", j, i,
                          ps.p[i].x, ps.p[i].y, ps.p[i].z, ps.n[i].x, ps.n[i].y, ps.n[i].z, ref[i].luminance,
                          lum(r.irradiance[i]), 100.0 * errs[j].first);
            }
          }
          if (record_regions && ps.key == "cornell") {
            // Where the records are (docs/cache.md, "Where the error and the records are"): the
            // floor and the walls, dark (E < 0.3 x the mean record E) or not, and the walls' rows
            // under the emitter's plane.
            double mean_e = 0.0;
            for (const cache_record& rec : r.records) mean_e += double(lum(rec.irradiance));
            mean_e /= double(std::max<std::size_t>(r.records.size(), 1));
            const char* names[6] = {"floor, dark", "floor, lit", "walls, top 3 rows", "walls, 6 rows below them",
                                    "walls, dark", "walls, rest"};
            const auto region = [&](const glm::vec3& p, const glm::vec3& n, double e) {
              const bool dark = e < 0.3 * mean_e;
              const int wall_row = int(p.y / 0.5488f * float(k));
              return n.y > 0.5f ? (dark ? 0 : 1) : wall_row >= k - 3 ? 2 : wall_row >= k - 9 ? 3 : dark ? 4 : 5;
            };
            std::size_t in[6] = {}, at_min[6] = {}, points[6] = {};
            for (const cache_record& rec : r.records) {
              const int c = region(rec.position, rec.normal, double(lum(rec.irradiance)));
              ++in[c];
              if (rec.radius <= r.stats.min_radius * 1.0001f) ++at_min[c];
            }
            // Each region's share of the squared error against the per-point reference (points
            // classified like the records, "dark" by their reference E), so the RMS can be read
            // region by region: sqrt(share x RMS^2 x valid / points in region) is its own RMS.
            double sq[6] = {};
            for (std::size_t i = 0; i < count; ++i) {
              if (err_of[i] < 0.0) continue;
              const int c = region(ps.p[i], ps.n[i], ref[i].luminance);
              sq[c] += err_of[i] * err_of[i];
              ++points[c];
            }
            for (int c = 0; c < 6; ++c)
              std::printf("    records, %-26s %6zu = %5.2f%% of the points (%zu at min_radius); %6zu points, "
                          "%5.1f%% of the squared error, RMS %.3f%%\n",
                          names[c], in[c], 100.0 * double(in[c]) / double(count), at_min[c], points[c],
                          sum > 0.0 ? 100.0 * sq[c] / sum : 0.0,
                          100.0 * std::sqrt(sq[c] / double(std::max<std::size_t>(points[c], 1))));
          }
          double total = 0.0, total_max = 0.0;
          vs_converged([&](std::size_t i) { return lum(r.irradiance[i]); }, total, total_max);
          std::fprintf(out, "%s,%d,%d,%zu,%.2f,%d,%zu,%.5f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.4f,%.4f,%d,%d,%zu,%d,%zu,%.6f,%.6f,%d,%.2f,%s\n",
                       ps.name.c_str(), k, resolution, count, double(a), gradients ? 1 : 0, r.stats.hemicubes,
                       double(r.stats.hemicubes) / double(count), rms, worst, total, total_max, ref_rms, ref_max,
                       r.stats.seconds, ref_seconds, converged_n, rolls, subset.size(), check_n, check_points, check_rms,
                       check_max, threads, load, variant.c_str());
          std::fflush(out);
          std::printf("  a = %.2f %-12s %6zu hemicubes (%5.2f%%)  vs per-point RMS %.3f%% max %.1f%%  vs converged RMS "
                      "%.3f%% max %.1f%%  %.2f s (load %.2f)\n",
                      double(a), gradients ? "gradients" : "no gradients", r.stats.hemicubes,
                      100.0 * double(r.stats.hemicubes) / double(count), 100.0 * rms, 100.0 * worst, 100.0 * total,
                      100.0 * total_max, r.stats.seconds, load);
          std::fflush(stdout);
        }
    }
  }
  std::fclose(out);
  std::printf("wrote %s\n", path.c_str());
  return 0;
}
