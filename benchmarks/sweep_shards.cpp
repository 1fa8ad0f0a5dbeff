// The sharded bake (shards.hpp; docs/distributed.md) on the public stand-in levels: for S shards,
// the jobs and merges run one by one through the public functions (as a farm runs them), and per S:
//   - the error of the irradiance against a hemicube at every texel (use_cache = false: the bake's
//     converged reference at its N), relative RMS over the reference's valid texels (luminance),
//     and the same for S = 1 (the unsharded bake, bitwise bake_scene) as the bake's own error;
//   - hemicubes (all passes) and their spread over the shards (largest shard / mean);
//   - time: the jobs' summed and largest wall times, a job's set-up alone (a job of S = 4096 on a
//     shard of a few samples), the merges' time;
//   - transfer per pass: the shards' values (bytes of float32 values) and the state (atlas x 16 bytes).
// Usage: sweep_shards OUT.csv [--levels arena:20000:256,keep:20000:256,city_block:50000:512]
//                     [--shards 1,2,4,8,16,32,64] [--bounces 2] [--threads 2] [--n 64]
#include "hemilight/levels.hpp"
#include "hemilight/shards.hpp"

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

struct level_spec {
  std::string name;
  std::size_t triangles = 0;
  int size = 256;
};

struct settings {
  std::vector<level_spec> levels = {{"arena", 20000, 256}, {"keep", 20000, 256}, {"city_block", 50000, 512}};
  std::vector<int> shards = {1, 2, 4, 8, 16, 32, 64};
  int bounces = 2, threads = 2, n = 64;
};

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

double relative_rms(const bake_result& a, const bake_result& ref) {
  double se = 0.0, sr = 0.0;
  for (std::size_t k = 0; k < ref.valid.size(); ++k) {
    if (!ref.valid[k]) continue;
    const auto lum = [k](const image& img) {
      return 0.2126 * img.pixels[3 * k] + 0.7152 * img.pixels[3 * k + 1] + 0.0722 * img.pixels[3 * k + 2];
    };
    const double d = lum(a.irradiance) - lum(ref.irradiance);
    se += d * d;
    sr += lum(ref.irradiance) * lum(ref.irradiance);
  }
  return std::sqrt(se / std::max(sr, 1e-300));
}

std::vector<int> parse_ints(const char* text) {
  std::vector<int> v;
  for (const char* p = text; *p;) {
    v.push_back(std::atoi(p));
    p = std::strchr(p, ',');
    if (!p) break;
    ++p;
  }
  return v;
}

// What one sharded bake measured.
struct sharded_run {
  scene_bake_result result;
  std::size_t hemicubes = 0, largest_shard_hemicubes = 0;
  double job_seconds = 0.0, largest_job_seconds = 0.0, merge_seconds = 0.0;
  double shard_bytes = 0.0, state_bytes = 0.0;  // per pass (means over the passes)
};

sharded_run run_sharded(const scene_bake_input& in, const bake_options& o, int shards) {
  sharded_run r;
  std::vector<bake_shard_result> first, current;
  bake_pass_state state;
  for (int pass = 1; pass <= o.bounces; ++pass) {
    current.clear();
    std::vector<std::size_t> per_shard(std::size_t(shards), 0);
    for (int s = 0; s < shards; ++s) {
      current.push_back(bake_scene_shard(in, o, s, shards, pass, pass > 1 ? &state : nullptr));
      const bake_shard_result& j = current.back();
      r.hemicubes += j.hemicubes;
      r.job_seconds += j.seconds;
      r.largest_job_seconds = std::max(r.largest_job_seconds, j.seconds);
      per_shard[std::size_t(s)] = j.hemicubes;
      r.shard_bytes += double(j.values.size()) * 4.0 / double(o.bounces);
    }
    r.largest_shard_hemicubes = std::max(r.largest_shard_hemicubes, *std::max_element(per_shard.begin(), per_shard.end()));
    if (pass == 1) first = current;
    const double t0 = now();
    if (pass == o.bounces) {
      r.result = finish_sharded_bake(in, o, current.data(), current.size(), first.data(), pass > 1 ? &state : nullptr);
      r.merge_seconds += now() - t0;
      break;
    }
    state = merge_bake_pass(in, o, pass, current.data(), current.size(), first.data(), pass > 1 ? &state : nullptr);
    r.merge_seconds += now() - t0;
    r.state_bytes = double(state.radiance.pixels.size()) * 4.0 + double(state.valid.size()) * 4.0;  // as the RGBA float EXR holds it
  }
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: sweep_shards OUT.csv [--levels NAME:TRIANGLES:SIZE,...] [--shards 1,2,4] [--bounces B] [--threads T] [--n N]\n");
    return 2;
  }
  settings st;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--shards") st.shards = parse_ints(argv[i + 1]);
    else if (a == "--bounces") st.bounces = std::atoi(argv[i + 1]);
    else if (a == "--threads") st.threads = std::atoi(argv[i + 1]);
    else if (a == "--n") st.n = std::atoi(argv[i + 1]);
    else if (a == "--levels") {
      st.levels.clear();
      std::string all = argv[i + 1];
      for (std::size_t at = 0; at < all.size();) {
        std::size_t end = all.find(',', at);
        if (end == std::string::npos) end = all.size();
        const std::string item = all.substr(at, end - at);
        level_spec l;
        const std::size_t c1 = item.find(':'), c2 = item.rfind(':');
        l.name = item.substr(0, c1);
        l.triangles = std::size_t(std::atoll(item.c_str() + c1 + 1));
        l.size = std::atoi(item.c_str() + c2 + 1);
        st.levels.push_back(l);
        at = end + 1;
      }
    } else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  std::FILE* f = std::fopen(argv[1], "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", argv[1]);
    return 1;
  }
  std::fprintf(f, "level,kind,triangles,size,bounces,n,threads,shards,sampled_texels,hemicubes,largest_shard_hemicubes,"
                  "shard_imbalance,job_seconds,largest_job_seconds,setup_seconds,merge_seconds,shard_bytes_per_pass,"
                  "state_bytes_per_pass,rel_rms_vs_per_texel,own_rel_rms_vs_per_texel,per_texel_hemicubes,per_texel_seconds\n");
  for (const level_spec& spec : st.levels) {
    level_options lo;
    lo.target_triangles = spec.triangles;
    lo.lightmap_size = spec.size;
    const level L = make_level(spec.name, lo);
    scene_bake_input in;
    in.geometry.scene = L.mesh.desc();
    lightmap_page page;
    page.width = page.height = spec.size;
    in.pages.push_back(page);
    bake_mesh all;
    all.triangle_count = L.mesh.triangle_count();
    all.page = 0;
    in.meshes.push_back(all);
    bake_options o;
    o.sampler.resolution = st.n;
    o.bounces = st.bounces;
    o.thread_count = st.threads;
    o.lights = L.lights;
    bake_options ref_o = o;
    ref_o.use_cache = false;
    double t0 = now();
    const scene_bake_result ref = bake_scene(in, ref_o);
    const double ref_seconds = now() - t0;
    // A job's set-up alone: a job of the largest shard count has a handful of samples.
    t0 = now();
    (void)bake_scene_shard(in, o, 0, max_bake_shards, 1, nullptr);
    const double setup_seconds = now() - t0;
    const char* kind = spec.name == "arena" || spec.name == "keep" ? "closed" : "open";
    std::printf("%s (%zu triangles, %d²): per texel %zu hemicubes, %.1f s; a job's set-up %.2f s\n", spec.name.c_str(),
                L.mesh.triangle_count(), spec.size, ref.stats.hemicubes, ref_seconds, setup_seconds);
    double own = 0.0;
    for (int shards : st.shards) {
      const sharded_run r = run_sharded(in, o, shards);
      const double e = relative_rms(r.result.pages[0], ref.pages[0]);
      if (shards == 1) own = e;
      const double imbalance = double(r.largest_shard_hemicubes) * double(shards) / std::max(1.0, double(r.hemicubes) / st.bounces);
      std::printf("  S = %3d: %zu hemicubes, largest shard %zu (x%.2f of the mean), jobs %.1f s (largest %.2f s), merges %.2f s, "
                  "relative RMS %.4f (S = 1: %.4f)\n",
                  shards, r.hemicubes, r.largest_shard_hemicubes, imbalance, r.job_seconds, r.largest_job_seconds, r.merge_seconds, e, own);
      std::fflush(stdout);
      std::fprintf(f, "%s,%s,%zu,%d,%d,%d,%d,%d,%zu,%zu,%zu,%.4f,%.4f,%.4f,%.4f,%.4f,%.0f,%.0f,%.6f,%.6f,%zu,%.3f\n", spec.name.c_str(), kind,
                   L.mesh.triangle_count(), spec.size, st.bounces, st.n, st.threads, shards, r.result.stats.sampled_texels, r.hemicubes,
                   r.largest_shard_hemicubes, imbalance, r.job_seconds, r.largest_job_seconds, setup_seconds, r.merge_seconds,
                   r.shard_bytes, r.state_bytes, e, own, ref.stats.hemicubes, ref_seconds);
      std::fflush(f);
    }
  }
  std::fclose(f);
  return 0;
}
