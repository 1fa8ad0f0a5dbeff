// The lightmap unwrapper (unwrap.hpp) on the built-in scenes, stand-in levels and 1M-triangle
// meshes, and bakes on its UVs against a converged reference.
//   usage: sweep_unwrap out.csv [--parts unwrap,bake] [--scenes a,b,...] [--repeat R] [--threads T]
//                               [--bake-csv path] [--bake-size S]
//          sweep_unwrap - [--threads T] --peak-memory CASE   (one unwrap of a case: its peak memory)
// Part "unwrap" (out.csv), per case (a mesh and its options; the cases are listed in
// unwrap_cases: the built-in scenes, the stand-in levels of levels.hpp at their own UVs' size and
// larger, the 1M-triangle arena, a 1M-triangle heightfield and 100,000 boxes): charts (planar ones
// too), pages, texel density, atlas utilisation (texels with exact UV coverage > 0, clipped here,
// over the pages' texels), for a level at its own size the utilisation of its own UVs (make_level's
// shelf packer) as a baseline, UV area over the pages' area, Sander's L2 and L-infinity stretch,
// seams (texels), and the wall time of unwrap_lightmap: the median, min and max of R runs (default
// 5), with the load average before and after (the machine may be shared). same_bytes: every run
// gave the same bytes (and a run with one thread too).
// Part "bake" (bake-csv, default out.csv with "_bake" before .csv): each built-in scene baked at
// S x S (default 128; two bounces, N = 64, the default cache, 2 threads, the scene's lights) on the
// UVs of generate_lightmap_uvs(mesh, unwrap_options) and, as a baseline, on the built-in scenes'
// shelf charts (generate_lightmap_uvs(mesh, S, 2)); likewise the arena at 10,000 triangles at
// 256 x 256 against its own UVs; each against a converged reference on the same UVs (use_cache =
// false at N = 256): relative RMS of luminance over texels valid in both (sqrt(sum dY^2 / sum
// Y_ref^2)), invalid texels (sampled, inside geometry), overlapping texels.
#include "hemilight/bake.hpp"
#include "hemilight/levels.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/reference_scenes.hpp"
#include "hemilight/unwrap.hpp"

#include "bench_util.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

struct unwrap_case {
  std::string name;
  std::function<scene_mesh()> make;
  unwrap_options options;
  bool own_baseline = false;  // a level at the page size of its own UVs: their utilisation is the baseline
};

// A stand-in level (levels.hpp) of about `triangles` triangles (0: its default), with its own UVs
// (make_level's charts, packed on shelves), which the unwrapper ignores: the baseline.
std::function<scene_mesh()> level_mesh(const char* name, std::size_t triangles) {
  return [name, triangles] {
    level_options lo;
    lo.target_triangles = triangles;
    return make_level(name, lo).mesh;
  };
}

unwrap_options target(int page_size) {
  unwrap_options o;
  o.page_size = page_size;
  return o;
}

unwrap_options padded(unwrap_options o, int padding) {
  o.padding = padding;
  return o;
}

unwrap_options density(float texels_per_unit, int page_size) {
  unwrap_options o;
  o.texels_per_unit = texels_per_unit;
  o.page_size = page_size;
  o.max_pages = 4096;
  return o;
}

// The cases of part "unwrap", in the CSV's order. The levels at the page size of their own UVs
// (levels.hpp: 1024 up to 75,000 triangles, 2048 up to 300,000, 4096 up to 1,200,000).
std::vector<unwrap_case> unwrap_cases() {
  return {
      {"arena", level_mesh("arena", 0), target(1024), true},
      {"arena_padding1", level_mesh("arena", 0), padded(target(1024), 1)},
      {"arena_2048", level_mesh("arena", 0), target(2048)},
      {"arena_4096", level_mesh("arena", 0), target(4096)},
      {"keep", level_mesh("keep", 0), target(1024), true},
      {"keep_4096", level_mesh("keep", 0), target(4096)},
      {"city_block", level_mesh("city_block", 0), target(2048), true},
      {"terrain_town", level_mesh("terrain_town", 0), target(2048), true},
      {"arena_1m", level_mesh("arena", 1000000), target(4096), true},
      {"cornell_box", [] { return cornell_box(); }, target(256)},
      {"hexagon_room_t3", [] { return hexagon_room(3); }, target(512)},
      {"sky_and_occluders", [] { return sky_and_occluders(); }, target(256)},
      {"open_pavilion", [] { return open_pavilion(); }, target(512)},
      {"open_street", [] { return open_street(); }, target(512)},
      {"many_boxes_1000", [] { return many_boxes(1000); }, target(1024)},
      {"heightfield_20k", [] { return heightfield(20000); }, target(1024)},
      {"many_boxes_100k", [] { return many_boxes(100000); }, target(4096)},
      {"heightfield_1m", [] { return heightfield(1000000); }, target(4096)},
      {"many_boxes_100k_4tpm", [] { return many_boxes(100000); }, density(4.0f, 4096)},
  };
}

// Texels of each page that a triangle covers (exact clipped area > 0), over all the pages' texels;
// uvs and indices as unwrap_result's (or a mesh's own, with every triangle on page 0).
double utilisation(std::size_t triangles, const std::vector<glm::vec2>& uvs, const std::vector<std::uint32_t>& indices,
                   const std::vector<std::uint32_t>* triangle_page, int pages, int size) {
  const std::size_t texels = std::size_t(size) * std::size_t(size);
  std::vector<std::uint8_t> covered(texels * std::size_t(pages), 0);
  for (std::size_t t = 0; t < triangles; ++t) {
    glm::vec2 q[3];
    for (int k = 0; k < 3; ++k) q[k] = uvs[indices[3 * t + std::size_t(k)]] * float(size);
    const int x0 = std::max(0, int(std::floor(std::min({q[0].x, q[1].x, q[2].x})))), x1 = std::min(size - 1, int(std::max({q[0].x, q[1].x, q[2].x})));
    const int y0 = std::max(0, int(std::floor(std::min({q[0].y, q[1].y, q[2].y})))), y1 = std::min(size - 1, int(std::max({q[0].y, q[1].y, q[2].y})));
    std::uint8_t* page = covered.data() + texels * (triangle_page ? (*triangle_page)[t] : 0u);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        std::uint8_t& c = page[std::size_t(y) * std::size_t(size) + std::size_t(x)];
        if (!c && clip_triangle_to_texel(q[0], q[1], q[2], x, y).area > 0.0f) c = 1;
      }
  }
  std::size_t n = 0;
  for (std::uint8_t c : covered) n += c;
  return double(n) / double(covered.size());
}

double utilisation(const scene_mesh& m, const unwrap_result& r, int size) {
  return utilisation(m.triangle_count(), r.uvs, r.indices, &r.triangle_page, r.stats.pages, size);
}

bool same_bytes(const unwrap_result& a, const unwrap_result& b) {
  return a.vertex_source == b.vertex_source && a.indices == b.indices && a.triangle_page == b.triangle_page &&
         a.uvs.size() == b.uvs.size() && std::memcmp(a.uvs.data(), b.uvs.data(), a.uvs.size() * sizeof(glm::vec2)) == 0;
}

void run_unwrap(const std::string& csv, const std::vector<std::string>& scenes, int repeat, int threads) {
  std::FILE* f = std::fopen(csv.c_str(), "w");
  if (!f) {
    std::perror(csv.c_str());
    std::exit(1);
  }
  std::fprintf(f, "scene,triangles,page_size,texels_per_unit_option,charts,planar_charts,degenerate,pages,texels_per_unit,utilisation,own_utilisation,"
                  "uv_area_fraction,stretch_l2,stretch_linf,seam_texels,vertices_out,seconds_median,seconds_min,seconds_max,runs,"
                  "threads,same_bytes,load_before,load_after\n");
  for (const unwrap_case& c : unwrap_cases()) {
    if (!scenes.empty() && std::find(scenes.begin(), scenes.end(), c.name) == scenes.end()) continue;
    const scene_mesh m = c.make();
    unwrap_options o = c.options;
    o.thread_count = threads;
    const double load_before = bench::loadavg();
    std::vector<double> seconds;
    unwrap_result first;
    bool same = true;
    for (int i = 0; i < repeat; ++i) {
      unwrap_result r = unwrap_lightmap(m.positions.data(), m.positions.size(), m.indices.data(), m.triangle_count(), o);
      seconds.push_back(r.stats.seconds);
      if (i == 0)
        first = std::move(r);
      else
        same = same && same_bytes(first, r);
    }
    const double load_after = bench::loadavg();
    unwrap_options one = o;
    one.thread_count = 1;
    same = same && same_bytes(first, unwrap_lightmap(m.positions.data(), m.positions.size(), m.indices.data(), m.triangle_count(), one));
    std::sort(seconds.begin(), seconds.end());
    const unwrap_stats& s = first.stats;
    const double util = utilisation(m, first, o.page_size);
    const double own = c.own_baseline ? utilisation(m.triangle_count(), m.lightmap_uvs, m.indices, nullptr, 1, o.page_size) : -1.0;
    std::fprintf(f, "%s,%zu,%d,%g,%zu,%zu,%zu,%d,%.6g,%.4f,%.4f,%.4f,%.6f,%.6f,%.1f,%zu,%.4f,%.4f,%.4f,%d,%d,%d,%.2f,%.2f\n", c.name.c_str(),
                 m.triangle_count(), o.page_size, double(o.texels_per_unit), s.charts, s.planar_charts, s.degenerate_triangles, s.pages,
                 double(s.texels_per_unit), util, own, s.uv_area_fraction, s.stretch_l2, s.stretch_linf, s.seam_texels, first.uvs.size(),
                 seconds[seconds.size() / 2], seconds.front(), seconds.back(), repeat, resolve_thread_count(threads), same ? 1 : 0,
                 load_before, load_after);
    std::fflush(f);
    std::printf("%-22s %8zu tris: %6zu charts (%zu planar), %d page(s) of %d^2 at %.4g texels/unit, utilisation %.1f%% (own UVs %.1f%%), "
                "stretch L2 %.4f Linf %.3f, seams %.0f texels, %.3f s (median of %d)%s\n",
                c.name.c_str(), m.triangle_count(), s.charts, s.planar_charts, s.pages, o.page_size, double(s.texels_per_unit),
                100.0 * util, 100.0 * own, s.stretch_l2, s.stretch_linf, s.seam_texels, seconds[seconds.size() / 2], repeat, same ? "" : " NOT DETERMINISTIC");
  }
  std::fclose(f);
}

// ---- part "bake" --------------------------------------------------------------------------------

double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

// Relative RMS of luminance over texels valid in both.
double relative_rms(const bake_result& r, const bake_result& ref) {
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < ref.valid.size(); ++k)
    if (ref.valid[k] && r.valid[k]) {
      const double a = luminance(r.irradiance.pixels.data() + 3 * k), b = luminance(ref.irradiance.pixels.data() + 3 * k);
      num += (a - b) * (a - b);
      den += b * b;
    }
  return std::sqrt(num / std::max(den, 1e-300));
}

struct bake_case {
  std::string name;
  std::function<lit_scene()> make;
  int size = 0;  // lightmap size, or 0: the --bake-size
  // The baseline UVs: the shelf charts of the built-in scenes (generate_lightmap_uvs(mesh, size, 2)),
  // or a level's own (make_level packs them for its lightmap_size).
  std::function<void(lit_scene&, int)> baseline = [](lit_scene& ls, int texels) { generate_lightmap_uvs(ls.mesh, texels, 2); };
};

// The arena at 10,000 triangles with its own UVs packed for size x size, its sun.
lit_scene small_arena(int size) {
  level_options lo;
  lo.target_triangles = 10000;
  lo.lightmap_size = size;
  level l = make_level("arena", lo);
  return {std::move(l.mesh), std::move(l.lights)};
}

void run_bake(const std::string& csv, const std::vector<std::string>& scenes, int default_size, int threads) {
  std::FILE* f = std::fopen(csv.c_str(), "w");
  if (!f) {
    std::perror(csv.c_str());
    std::exit(1);
  }
  std::fprintf(f, "scene,uvs,size,charts,utilisation,sampled_texels,invalid_texels,overlapping_texels,hemicubes,seconds,"
                  "reference_seconds,rms_error\n");
  const std::vector<bake_case> cases = {
      {"cornell_box", [] { return lit_scene{cornell_box(), {}}; }},
      {"hexagon_room_t3", [] { return lit_scene{hexagon_room(3), {}}; }},
      {"hexagon_room_sun", [] { return hexagon_room_sunlit(2); }},
      {"sky_and_occluders", [] { return lit_scene{sky_and_occluders(), {}}; }},
      {"open_pavilion", [] { return lit_scene{open_pavilion(), {}}; }},
      {"arena_10k", [] { return small_arena(256); }, 256, [](lit_scene&, int) {}},
  };
  for (const bake_case& c : cases) {
    if (!scenes.empty() && std::find(scenes.begin(), scenes.end(), c.name) == scenes.end()) continue;
    const int size = c.size > 0 ? c.size : default_size;
    for (const char* uvs : {"unwrap", "shelf"}) {
      lit_scene ls = c.make();
      std::size_t charts = 0;
      double util = 0.0;
      if (std::strcmp(uvs, "unwrap") == 0) {
        unwrap_options o;
        o.page_size = size;
        o.thread_count = threads;
        const scene_mesh before = ls.mesh;
        const unwrap_result r = generate_lightmap_uvs(ls.mesh, o);
        charts = r.stats.charts;
        util = utilisation(before, r, size);
      } else {
        c.baseline(ls, size);
        util = utilisation(ls.mesh.triangle_count(), ls.mesh.lightmap_uvs, ls.mesh.indices, nullptr, 1, size);
      }
      bake_input in;
      in.scene = ls.mesh.desc();
      bake_options o;
      o.width = o.height = size;
      o.bounces = 2;
      o.thread_count = threads;
      o.lights = ls.lights;
      const bake_result r = bake_lightmap(in, o);
      bake_options ref_o = o;
      ref_o.use_cache = false;
      ref_o.sampler.resolution = 256;
      const bake_result ref = bake_lightmap(in, ref_o);
      const double rms = relative_rms(r, ref);
      std::fprintf(f, "%s,%s,%d,%s,%.4f,%zu,%zu,%zu,%zu,%.3f,%.3f,%.5f\n", c.name.c_str(), uvs, size,
                   charts > 0 ? std::to_string(charts).c_str() : "", util, r.stats.sampled_texels,
                   r.stats.invalid_texels, r.stats.overlapping_texels, r.stats.hemicubes, r.stats.seconds, ref.stats.seconds, rms);
      std::fflush(f);
      std::printf("%-18s %-6s %d^2: %zu sampled, %zu invalid, %zu overlapping, %.2f s; against N = 256 per texel (%.1f s): "
                  "relative RMS %.4f\n",
                  c.name.c_str(), uvs, size, r.stats.sampled_texels, r.stats.invalid_texels, r.stats.overlapping_texels, r.stats.seconds,
                  ref.stats.seconds, rms);
    }
  }
  std::fclose(f);
}

// The process's peak resident set in KiB (VmHWM), or 0.
long peak_kib() {
  long v = 0;
  if (std::FILE* f = std::fopen("/proc/self/status", "r")) {
    char line[256];
    while (std::fgets(line, sizeof line, f))
      if (std::sscanf(line, "VmHWM: %ld", &v) == 1) break;
    std::fclose(f);
  }
  return v;
}

// --peak-memory CASE: one unwrap of the case in this process; the peak resident set it adds over
// the input mesh, per triangle.
int peak_memory(const std::string& name, int threads) {
  for (const unwrap_case& c : unwrap_cases()) {
    if (c.name != name) continue;
    const scene_mesh m = c.make();
    unwrap_options o = c.options;
    o.thread_count = threads;
    const long before = peak_kib();
    const unwrap_result r = unwrap_lightmap(m.positions.data(), m.positions.size(), m.indices.data(), m.triangle_count(), o);
    const long after = peak_kib();
    std::printf("%s: %zu triangles, %zu charts; peak resident set %ld MiB with the input, %ld MiB more for unwrap_lightmap: %.0f bytes "
                "per triangle\n",
                name.c_str(), m.triangle_count(), r.stats.charts, before / 1024, (after - before) / 1024,
                double(after - before) * 1024.0 / double(m.triangle_count()));
    return 0;
  }
  std::fprintf(stderr, "no case %s\n", name.c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: sweep_unwrap out.csv [--parts unwrap,bake] [--scenes a,b] [--repeat R] [--threads T] "
                         "[--bake-csv path] [--bake-size S]\n");
    return 2;
  }
  const std::string csv = argv[1];
  std::vector<std::string> parts = {"unwrap", "bake"}, scenes;
  int repeat = 5, threads = 2, bake_size = 128;
  std::string bake_csv = csv.size() > 4 ? csv.substr(0, csv.size() - 4) + "_bake.csv" : csv + "_bake.csv";
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--parts") parts = bench::split(v);
    else if (a == "--scenes") scenes = bench::split(v);
    else if (a == "--repeat") repeat = std::max(1, std::atoi(v.c_str()));
    else if (a == "--threads") threads = std::atoi(v.c_str());
    else if (a == "--bake-csv") bake_csv = v;
    else if (a == "--bake-size") bake_size = std::atoi(v.c_str());
    else if (a == "--peak-memory") return peak_memory(v, threads);
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::printf("load average before: %.2f (the machine may be shared: times are medians of %d runs)\n", bench::loadavg(), repeat);
  if (std::find(parts.begin(), parts.end(), "unwrap") != parts.end()) run_unwrap(csv, scenes, repeat, threads);
  if (std::find(parts.begin(), parts.end(), "bake") != parts.end()) run_bake(bake_csv, scenes, bake_size, threads);
  return 0;
}
