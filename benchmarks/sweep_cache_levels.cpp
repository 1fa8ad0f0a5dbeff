// The irradiance cache on the public stand-in levels (fixtures: make_level; docs/levels.md):
// what share of the texels gets a hemicube, the error against a converged reference and what
// limits the records' radii (cache_stats' counters). docs/cache.md, "Levels".
//   usage: sweep_cache_levels out.csv [--levels arena,keep] [--sizes 512,1024] [--n 64] [--a 0.2]
//            [--no-cache-sizes 256,512] [--stride 37] [--rolls 2] [--truth-cache DIR] [--variant NAME]
//            [--append] [--threads 2] [--bounces 1] [--sun]
//            [--min-radius-spacings K] [--space-finest yes|no] [--clamp-normals yes|no] [--pretest yes|no] [--legacy]
// Per level and lightmap size (the level's UVs packed for that size): one bake (bake_lightmap,
// N = 64 unless --n, one bounce, sky only unless --sun, two threads) through the cache, and with
// --no-cache-sizes one with a hemicube at every texel (use_cache = false) at those sizes, for the
// time ratio and the error against it. Converged reference: every `stride`-th sampled texel, at the
// bake's own sample point, N = 256, the mean of `rolls` hemicubes rolled by different hashed angles
// (the point nudged by r float ulps); its valid texels are those whose first roll sees at most
// invalid_backface_fraction back faces. Errors (luminance): rel_rms = sqrt(sum dY^2 / sum Y^2) (the
// bake targets' relative RMS) and point_rms = RMS of |dY| / max(Y, 5% of the mean Y) (docs/cache.md's),
// over the converged valid texels; a texel the cached bake calls invalid counts with its filled
// value (wrongly_invalid counts them). The flags after --variant set cache options for experiments
// (a variant's name goes into the CSV); --legacy gives the cache as it was before the levels work:
// min_radius the median nearest-point distance / a (found here by brute force, as the cache found
// it), no spaced finest seeds, no inside test (the bake still passes point_spacing, which an
// explicit min_radius overrides).
#include "hemilight/bake.hpp"
#include "hemilight/cache.hpp"
#include "hemilight/levels.hpp"
#include "hemilight/parallel.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

double luminance(const glm::vec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }
double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

std::string load_average() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream list(s);
  for (std::string item; std::getline(list, item, ',');) out.push_back(item);
  return out;
}

struct settings {
  std::vector<std::string> levels = {"arena", "keep"};
  std::vector<int> sizes = {512, 1024};
  std::vector<int> no_cache_sizes;
  int n = 64, stride = 37, rolls = 2, threads = 2, bounces = 1;
  float a = 0.2f;
  bool sun = false, append = false, legacy = false;
  std::string truth_dir, variant = "default";
  cache_options cache;
};

// The converged reference at `texels` (see the top): luminance and whether the first roll is valid.
struct truth {
  std::vector<double> y;
  std::vector<std::uint8_t> valid;
  double seconds = 0.0;
};

truth converged(const bake_input& in, const bake_options& o, const lightmap_samples& s, const std::vector<std::size_t>& texels,
                const std::string& name, const settings& st) {
  const int n = 256;
  truth t;
  t.y.resize(texels.size());
  t.valid.resize(texels.size());
  const std::string file = st.truth_dir.empty() ? "" : st.truth_dir + "/" + name + "_" + std::to_string(o.width) + "_n" +
                                                         std::to_string(n) + "_r" + std::to_string(st.rolls) + "_b" +
                                                         std::to_string(o.bounces) + (st.sun ? "_sun" : "") + "_" +
                                                         std::to_string(texels.size()) + ".bin";
  if (!file.empty()) {
    std::ifstream f(file, std::ios::binary);
    if (f.read(reinterpret_cast<char*>(t.y.data()), std::streamsize(t.y.size() * sizeof(double))) &&
        f.read(reinterpret_cast<char*>(t.valid.data()), std::streamsize(t.valid.size())))
      return t;
  }
  if (o.bounces != 1) {
    std::fprintf(stderr, "the converged reference is one bounce only\n");
    std::exit(1);
  }
  const auto sc = scene::create(in.scene);
  const float min_offset = 2.0f * default_near_distance(*sc);  // bake.hpp, step 2
  sampler_options so;
  so.resolution = n;
  const irradiance_sampler sampler = make_hemicube_sampler(sc, so, o.thread_count);
  const auto t0 = std::chrono::steady_clock::now();
  parallel_for(texels.size(), o.thread_count, 16, [&](int worker, std::size_t b, std::size_t e) {
    for (std::size_t j = b; j < e; ++j) {
      const std::size_t k = texels[j];
      const glm::vec3 p = s.position[k] + std::max(min_offset, o.offset_texels * s.texel_world_size[k]) * s.normal[k];
      double sum = 0.0;
      for (int r = 0; r < st.rolls; ++r) {
        glm::vec3 q = p;  // r float ulps along one coordinate: another hashed roll, the same point
        for (int u = 0; u < r; ++u) q.x = std::nextafter(q.x, 1e30f);
        const sampler_result sr = sampler(worker, q, s.normal[k]);
        sum += luminance(sr.irradiance);
        if (r == 0) t.valid[j] = sr.backface_fraction > o.cache.invalid_backface_fraction ? 0 : 1;
      }
      t.y[j] = sum / st.rolls;
    }
  });
  t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!file.empty()) {
    std::ofstream f(file, std::ios::binary);
    f.write(reinterpret_cast<const char*>(t.y.data()), std::streamsize(t.y.size() * sizeof(double)));
    f.write(reinterpret_cast<const char*>(t.valid.data()), std::streamsize(t.valid.size()));
  }
  return t;
}

struct errors {
  double rel_rms = 0.0, point_rms = 0.0, max = 0.0;
  std::size_t points = 0, wrongly_invalid = 0;
};

errors against(const bake_result& r, const std::vector<std::size_t>& texels, const truth& t) {
  errors e;
  double mean = 0.0;
  for (std::size_t j = 0; j < texels.size(); ++j)
    if (t.valid[j]) {
      mean += t.y[j];
      ++e.points;
    }
  mean /= double(std::max<std::size_t>(e.points, 1));
  double num = 0.0, den = 0.0, rel2 = 0.0;
  for (std::size_t j = 0; j < texels.size(); ++j) {
    if (!t.valid[j]) continue;
    const std::size_t k = texels[j];
    const double y = luminance(r.irradiance.pixels.data() + 3 * k), d = y - t.y[j];
    num += d * d;
    den += t.y[j] * t.y[j];
    const double rel = std::fabs(d) / std::max(t.y[j], 0.05 * mean);
    rel2 += rel * rel;
    e.max = std::max(e.max, rel);
    if (!r.valid[k]) ++e.wrongly_invalid;
  }
  e.rel_rms = std::sqrt(num / std::max(den, 1e-300));
  e.point_rms = std::sqrt(rel2 / double(std::max<std::size_t>(e.points, 1)));
  return e;
}

// The automatic min_radius before point_spacing (--legacy): the median distance from a point to
// its nearest other point, over up to 1024 evenly strided sample points, / a (the cache's
// median_spacing, found here by brute force).
float legacy_min_radius(const bake_input& in, const bake_options& o) {
  const lightmap_samples s = compute_lightmap_samples(in, o.width, o.height);
  const auto sc = scene::create(in.scene);
  const float min_offset = 2.0f * default_near_distance(*sc);
  std::vector<glm::vec3> p;
  for (std::size_t k = 0; k < s.coverage.size(); ++k)
    if (s.sample_triangle[k] != lightmap_samples::no_triangle && s.coverage[k] >= o.min_coverage && s.coverage[k] > 0.0f)
      p.push_back(s.position[k] + std::max(min_offset, o.offset_texels * s.texel_world_size[k]) * s.normal[k]);
  std::vector<float> nn;
  const std::size_t stride = std::max<std::size_t>(1, p.size() / 1024);
  for (std::size_t i = 0; i < p.size(); i += stride) {
    float best = std::numeric_limits<float>::infinity();
    for (const glm::vec3& q : p) {
      const float d = glm::length(q - p[i]);
      if (d > 0.0f) best = std::min(best, d);
    }
    nn.push_back(best);
  }
  std::nth_element(nn.begin(), nn.begin() + std::ptrdiff_t(nn.size() / 2), nn.end());
  return nn[nn.size() / 2] / o.cache.error_threshold;
}

// Relative RMS of the cached bake against the per-texel one over texels valid in both.
double against_per_texel(const bake_result& r, const bake_result& ref) {
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < ref.valid.size(); ++k)
    if (ref.sampled[k] && ref.valid[k] && r.valid[k]) {
      const double a = luminance(r.irradiance.pixels.data() + 3 * k), b = luminance(ref.irradiance.pixels.data() + 3 * k);
      num += (a - b) * (a - b);
      den += b * b;
    }
  return std::sqrt(num / std::max(den, 1e-300));
}

int run(const std::string& path, const settings& st) {
  std::FILE* f = std::fopen(path.c_str(), st.append ? "a" : "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    return 1;
  }
  if (!st.append)
    std::fprintf(f,
                 "level,size,variant,n,a,triangles,sampled_texels,hemicubes,hemicube_share,records,invalid_samples,"
                 "invalid_samples_deep,invalid_points,presumed_inside,known_inside,seconds,placement_seconds,render_seconds,"
                 "no_cache_seconds,time_ratio,rel_rms_vs_per_texel,rel_rms_vs_converged,point_rms_vs_converged,"
                 "max_vs_converged,per_texel_rel_rms_vs_converged,converged_points,wrongly_invalid,min_radius,median_radius,"
                 "median_harmonic,at_min_radius,limit_split_sphere,limit_max_radius,limit_gradient,limit_contact,"
                 "limit_neighbour,limit_disagreement,min_split_sphere,min_max_radius,min_gradient,min_contact,min_neighbour,"
                 "min_disagreement,open_uncovered,open_disagree,open_lone_change,open_lone_reach,open_nearby,"
                 "neighbour_clamps,clamps_across_normals,load_average\n");
  for (const std::string& name : st.levels)
    for (int size : st.sizes) {
      level_options lo;
      lo.lightmap_size = size;
      level L;
      try {
        L = make_level(name, lo);
      } catch (const error& e) {  // the level's charts do not fit this size: no row
        std::printf("%s %d²: skipped (%s)\n", name.c_str(), size, e.what());
        continue;
      }
      bake_input in;
      in.scene = L.mesh.desc();
      bake_options o;
      o.width = o.height = size;
      o.sampler.resolution = st.n;
      o.bounces = st.bounces;
      o.thread_count = st.threads;
      o.cache = st.cache;
      o.cache.error_threshold = st.a;
      if (st.sun) o.lights = L.lights;
      if (st.legacy) {  // the cache as it was before point_spacing, space_finest_seeds and inside_test
        o.cache.min_radius = legacy_min_radius(in, o);
        o.cache.expert.space_finest_seeds = false;
        o.cache.expert.pretest_inside = false;
      }
      const std::string load = load_average();
      const bake_result r = bake_lightmap(in, o);
      const cache_stats& cs = r.stats.passes.front();
      std::printf("%s %d² %s: %zu sampled texels, %zu hemicubes (%.1f%%), %zu records, %zu invalid samples, %.1f s (placement %.1f s)\n",
                  name.c_str(), size, st.variant.c_str(), r.stats.sampled_texels, r.stats.hemicubes,
                  100.0 * double(r.stats.hemicubes) / double(r.stats.sampled_texels * std::size_t(st.bounces)), r.stats.records,
                  cs.invalid_samples, r.stats.seconds, cs.placement_seconds);
      std::fflush(stdout);
      bake_result ref;
      double no_cache_seconds = 0.0, vs_per_texel = std::nan("");
      const bool per_texel = std::find(st.no_cache_sizes.begin(), st.no_cache_sizes.end(), size) != st.no_cache_sizes.end();
      if (per_texel) {
        bake_options on = o;
        on.use_cache = false;
        ref = bake_lightmap(in, on);
        no_cache_seconds = ref.stats.seconds;
        vs_per_texel = against_per_texel(r, ref);
        std::printf("  no cache: %.1f s (cached/no cache %.2f); cached vs per texel: relative RMS %.4f\n", no_cache_seconds,
                    r.stats.seconds / no_cache_seconds, vs_per_texel);
      }
      errors e, ep;
      if (st.stride > 0) {
        const lightmap_samples s = compute_lightmap_samples(in, size, size);
        std::vector<std::size_t> texels;
        std::size_t sampled = 0;
        for (std::size_t k = 0; k < r.sampled.size(); ++k)
          if (r.sampled[k] && sampled++ % std::size_t(st.stride) == 0) texels.push_back(k);
        const truth t = converged(in, o, s, texels, name, st);
        e = against(r, texels, t);
        if (per_texel) ep = against(ref, texels, t);
        std::printf("  vs converged (N = 256, %d rolls, %zu valid texels%s): relative RMS %.4f, point RMS %.4f, max %.3f, "
                    "wrongly invalid %zu%s\n",
                    st.rolls, e.points, t.seconds > 0 ? (", " + std::to_string(int(t.seconds)) + " s").c_str() : "", e.rel_rms,
                    e.point_rms, e.max, e.wrongly_invalid,
                    per_texel ? ("; per texel relative RMS " + std::to_string(ep.rel_rms) + ", point RMS " + std::to_string(ep.point_rms)).c_str() : "");
      }
      const auto& L1 = cs.records_by_limit;
      const auto& M = cs.records_at_min_radius_by_limit;
      const auto& R = cs.hemicubes_by_reason;
      std::printf("  radii: min %.3f, median %.3f, median split sphere %.3f; at min %zu of %zu; by limit (at min): split %zu (%zu), max "
                  "%zu (%zu), gradient %zu (%zu), contact %zu (%zu), neighbour %zu (%zu), disagreement %zu (%zu); clamps %zu (%zu "
                  "across normals)\n  hemicubes by reason: uncovered %zu, disagree %zu, lone change %zu, lone reach %zu, nearby "
                  "%zu; invalid samples %zu (deep %zu), presumed %zu, known %zu\n",
                  cs.min_radius, cs.median_radius, cs.median_harmonic_distance, cs.records_at_min_radius, cs.records, L1[0], M[0],
                  L1[1], M[1], L1[2], M[2], L1[3], M[3], L1[4], M[4], L1[5], M[5], cs.neighbour_clamps,
                  cs.neighbour_clamps_across_normals, R[0], R[1], R[2], R[3], R[4], cs.invalid_samples, cs.invalid_samples_deep,
                  cs.presumed_inside_points, cs.known_inside_points);
      std::printf("  inside tests %zu, inside by test %zu, rounds %zu\n", cs.inside_tests, cs.inside_by_test, cs.rounds);
      std::fflush(stdout);
      const auto opt = [](double v) { return std::isnan(v) ? std::string() : std::to_string(v); };
      std::fprintf(f, "%s,%d,%s,%d,%.3f,%zu,%zu,%zu,%.5f,%zu,%zu,%zu,%zu,%zu,%zu,%.3f,%.3f,%.3f,%s,%s,%s,%.5f,%.5f,%.4f,%s,%zu,%zu,%.4f,%.4f,%.4f,%zu",
                   name.c_str(), size, st.variant.c_str(), st.n, double(st.a), L.mesh.triangle_count(), r.stats.sampled_texels,
                   r.stats.hemicubes, double(r.stats.hemicubes) / double(r.stats.sampled_texels * std::size_t(st.bounces)),
                   r.stats.records, cs.invalid_samples, cs.invalid_samples_deep, cs.invalid_points, cs.presumed_inside_points,
                   cs.known_inside_points, r.stats.seconds, cs.placement_seconds, cs.render_seconds,
                   per_texel ? opt(no_cache_seconds).c_str() : "", per_texel ? opt(r.stats.seconds / no_cache_seconds).c_str() : "",
                   opt(vs_per_texel).c_str(), e.rel_rms, e.point_rms, e.max, per_texel ? opt(ep.rel_rms).c_str() : "", e.points,
                   e.wrongly_invalid, double(cs.min_radius), double(cs.median_radius), double(cs.median_harmonic_distance),
                   cs.records_at_min_radius);
      for (std::size_t k = 0; k < radius_limit_count; ++k) std::fprintf(f, ",%zu", L1[k]);
      for (std::size_t k = 0; k < radius_limit_count; ++k) std::fprintf(f, ",%zu", M[k]);
      for (std::size_t k = 0; k < open_reason_count; ++k) std::fprintf(f, ",%zu", R[k]);
      std::fprintf(f, ",%zu,%zu,%s\n", cs.neighbour_clamps, cs.neighbour_clamps_across_normals, load.c_str());
      std::fflush(f);
    }
  std::fclose(f);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: sweep_cache_levels out.csv [options] (see the top of sweep_cache_levels.cpp)\n");
    return 2;
  }
  settings st;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    const bool more = i + 1 < argc;
    if (a == "--levels" && more) {
      st.levels = split(argv[++i]);
    } else if (a == "--sizes" && more) {
      st.sizes.clear();
      for (const std::string& v : split(argv[++i])) st.sizes.push_back(std::atoi(v.c_str()));
    } else if (a == "--no-cache-sizes" && more) {
      for (const std::string& v : split(argv[++i])) st.no_cache_sizes.push_back(std::atoi(v.c_str()));
    } else if (a == "--n" && more) {
      st.n = std::atoi(argv[++i]);
    } else if (a == "--a" && more) {
      st.a = float(std::atof(argv[++i]));
    } else if (a == "--stride" && more) {
      st.stride = std::atoi(argv[++i]);
    } else if (a == "--rolls" && more) {
      st.rolls = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--threads" && more) {
      st.threads = std::atoi(argv[++i]);
    } else if (a == "--bounces" && more) {
      st.bounces = std::atoi(argv[++i]);
    } else if (a == "--truth-cache" && more) {
      st.truth_dir = argv[++i];
    } else if (a == "--variant" && more) {
      st.variant = argv[++i];
    } else if (a == "--legacy") {
      st.legacy = true;
    } else if (a == "--append") {
      st.append = true;
    } else if (a == "--sun") {
      st.sun = true;
    } else if (a == "--min-radius" && more) {
      st.cache.min_radius = float(std::atof(argv[++i]));
    } else if (a == "--min-radius-spacings" && more) {
      st.cache.min_radius_spacings = float(std::atof(argv[++i]));
    } else if (a == "--space-finest" && more) {
      st.cache.expert.space_finest_seeds = std::string(argv[++i]) == "yes";
    } else if (a == "--clamp-normals" && more) {
      st.cache.expert.clamp_across_normals = std::string(argv[++i]) == "yes";
    } else if (a == "--pretest" && more) {
      st.cache.expert.pretest_inside = std::string(argv[++i]) == "yes";
    } else {
      std::fprintf(stderr, "unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  return run(argv[1], st);
}
