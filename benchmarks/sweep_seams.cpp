// Seam stitching (bake_options::stitch_seams, seams.hpp; docs/bake.md, "Seams"): the step along
// the seams before and after, against the bake's own error, what stitching does to the texels,
// and its cost.
//   usage: sweep_seams out.csv [--cost-csv path] [--parts seams,cost] [--scenes a,b] [--sizes 256,512]
//                              [--runs R] [--reference-n N] [--truth-cache DIR] [--threads T]
//                              [--cost-cases scene@size,...]
// Part "seams" (out.csv): each of --scenes at each of --sizes (default 256, 512):
//   - the built-in scenes (reference_scenes.hpp) cornell_box, hexagon_room_t3 (hexagon_room(3)),
//     open_pavilion and open_street on the unwrapper's UVs (generate_lightmap_uvs with
//     unwrap_options::page_size = the size: one page, 2 texels of padding), uvs "generated";
//   - the stand-in levels (levels.hpp) at the smallest size each accepts (arena, keep: 10,000
//     triangles; city_block, terrain_town: 50,000), with their sun and sky: arena and terrain_town
//     on their own UVs (make_level's charts packed for the size; city_block does not fit 256^2),
//     uvs "own", and terrain_town_generated (any LEVEL_generated: the level on the unwrapper's UVs).
// The default options (cache on, N = 64, a = 0.2, one bounce, --threads threads, default 2): one
// bake with stitch_seams off, then R bakes with it on (default 3; timing columns: their medians;
// the rest from the first, every run checked to give its bytes). Per row:
//   - the seams of the input (measure_seams, default seam_options): pieces and length in texels,
//     coplanar (the headline), walled, crease;
//   - the coplanar figures (relative step RMS, p95, max, the share of the length over 2%) of the
//     bake without stitching (_off), with it (_on) and of the reference (_ref: a hemicube per
//     texel, use_cache = false, N = --reference-n, default 128, stitching off); the walled RMS;
//   - the error of both bakes against the reference: relative RMS of luminance,
//     sqrt(sum dY^2 / sum Y_ref^2), over the texels valid in both (error_off, error_on; as
//     sweep_unwrap's bakes), and over the stitched texels among them (seam_error_off, _on);
//   - what stitching changes, the relative RMS change sqrt(sum (Y_on - Y_off)^2 / sum Y_off^2)
//     over the sampled texels it does not set (interior_change), all sampled texels (all_change)
//     and the sampled texels it sets (seam_change); the largest change of a sampled texel it does
//     not set, relative to max(Y_off, 5% of the mean). The stitcher's texels (the bilinear
//     footprints of its seam points) are rebuilt here with the baker's internal seam search
//     (src/bake/stitch_seams.hpp) and checked against bake_stats::seam_texels
//     (stitched_texels_check);
//   - seam_texels, stitch_seconds (median), search_seconds (the seam search alone, as the bake
//     runs it, timed here once), the bake's seconds without stitching (one run) and with (median);
//   - diagnostics: sides of the stitched pieces whose bilinear footprint at the piece's middle
//     holds no valid sampled texel (padding or texels inside geometry only: sides_without_valid)
//     or a sampled texel inside geometry (sides_with_invalid); the three pieces with the largest
//     step after stitching are printed (position, length, what their sides read).
// --truth-cache DIR keeps the references (irradiance, valid, sampled, their bake time) between
// runs, named by scene, size, N and a hash of the input: delete them after a change to the baker.
// Part "cost" (--cost-csv, default out.csv with "_cost" before .csv): the stitching cost at larger
// sizes, for each --cost-cases entry SCENE@SIZE (default open_street@1024, open_street@2048,
// terrain_town@1024): R stitched bakes as above; seam_texels, the coplanar pieces and their
// length, stitch_seconds (median, min, max), search_seconds (median), the bake's seconds
// (median), texels and sampled texels. plot_seams.py fits stitch_seconds against seam_texels over
// these rows and the part's rows of the same scenes (log-log).
// Time on two cores: see docs/bake.md, "Seams" (the references are most of the first run).
#include "hemilight/bake.hpp"
#include "hemilight/levels.hpp"
#include "hemilight/reference_scenes.hpp"
#include "hemilight/scene.hpp"
#include "hemilight/seams.hpp"
#include "hemilight/unwrap.hpp"

#include "bake/stitch_seams.hpp"  // the stitcher's texels (internal: src/ is on this target's include path)
#include "bench_util.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

using namespace hemilight;

namespace {

double luminance(const float* p) { return 0.2126 * double(p[0]) + 0.7152 * double(p[1]) + 0.0722 * double(p[2]); }
double luminance(const bake_result& r, std::size_t k) { return luminance(r.irradiance.pixels.data() + 3 * k); }

// A scene of the sweep with its lightmap UVs for one size.
struct seam_scene {
  std::string name;
  std::string uvs;  // "own" (a level's make_level UVs) or "generated" (generate_lightmap_uvs)
  scene_mesh mesh;
  std::vector<light> lights;
};

level make_small_level(const std::string& name, int size) {
  level_options lo;
  lo.target_triangles = (name == "arena" || name == "keep") ? 10000 : 50000;  // the smallest each accepts (levels.hpp)
  lo.lightmap_size = size;
  return make_level(name, lo);
}

void unwrap_for(scene_mesh& m, int size) {
  unwrap_options o;
  o.page_size = size;
  const unwrap_result r = generate_lightmap_uvs(m, o);
  if (r.stats.pages != 1) {
    std::fprintf(stderr, "sweep_seams: the unwrap took %d pages at %d^2\n", r.stats.pages, size);
    std::exit(1);
  }
}

// The scenes of part "seams" by name (see the top).
seam_scene make_scene(const std::string& name, int size) {
  seam_scene s;
  s.name = name;
  if (name == "cornell_box" || name == "hexagon_room_t3" || name == "open_pavilion" || name == "open_street") {
    s.mesh = name == "cornell_box"       ? cornell_box()
             : name == "hexagon_room_t3" ? hexagon_room(3)
             : name == "open_pavilion"   ? open_pavilion()
                                         : open_street();
    unwrap_for(s.mesh, size);
    s.uvs = "generated";
  } else if (name.size() > 10 && name.compare(name.size() - 10, 10, "_generated") == 0) {
    level l = make_small_level(name.substr(0, name.size() - 10), size);
    s.mesh = std::move(l.mesh);
    s.lights = std::move(l.lights);
    unwrap_for(s.mesh, size);
    s.uvs = "generated";
  } else {
    level l = make_small_level(name, size);
    s.mesh = std::move(l.mesh);
    s.lights = std::move(l.lights);
    s.uvs = "own";
  }
  return s;
}

const std::vector<std::string> default_scenes = {"cornell_box", "hexagon_room_t3", "open_pavilion", "open_street",
                                                 "arena",       "terrain_town",    "terrain_town_generated"};

bake_options default_bake(int size, int threads, const std::vector<light>& lights, bool stitch) {
  bake_options o;  // cache on, N = 64, a = 0.2, one bounce
  o.width = o.height = size;
  o.thread_count = threads;
  o.lights = lights;
  o.stitch_seams = stitch;
  return o;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

bool same_bytes(const bake_result& a, const bake_result& b) {
  return a.irradiance.pixels.size() == b.irradiance.pixels.size() &&
         std::memcmp(a.irradiance.pixels.data(), b.irradiance.pixels.data(), a.irradiance.pixels.size() * sizeof(float)) == 0 &&
         a.valid == b.valid;
}

// FNV-1a over the bytes of the input that decide a reference bake.
std::uint64_t input_hash(const scene_mesh& m, const std::vector<light>& lights, int n) {
  std::uint64_t h = 1469598103934665603ull;
  const auto add = [&h](const void* p, std::size_t bytes) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ c[i]) * 1099511628211ull;
  };
  add(m.positions.data(), m.positions.size() * sizeof(glm::vec3));
  add(m.indices.data(), m.indices.size() * sizeof(std::uint32_t));
  add(m.lightmap_uvs.data(), m.lightmap_uvs.size() * sizeof(glm::vec2));
  for (const material& x : m.materials) {  // field by field: the structs' padding bytes are not part of the value
    add(&x.emission, sizeof x.emission);
    add(&x.albedo, sizeof x.albedo);
    add(&x.two_sided, sizeof x.two_sided);
  }
  add(&m.sky_radiance, sizeof m.sky_radiance);
  for (const light& l : lights) {
    add(&l.type, sizeof l.type);
    add(&l.color, sizeof l.color);
    add(&l.position, sizeof l.position);
    add(&l.direction, sizeof l.direction);
    add(&l.tangent, sizeof l.tangent);
    const float f[5] = {l.width, l.height, l.radius, l.spot_inner, l.spot_outer};
    add(f, sizeof f);
    add(&l.casts_shadows, sizeof l.casts_shadows);
  }
  add(&n, sizeof n);
  return h;
}

// The reference: a hemicube per texel at N = n, stitching off; from / to truth_dir when given.
bake_result reference_bake(const seam_scene& s, const bake_input& in, int size, int n, int threads, const std::string& truth_dir,
                           double& seconds) {
  char hash[32];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(input_hash(s.mesh, s.lights, n)));
  const std::string file =
      truth_dir.empty() ? "" : truth_dir + "/" + s.name + "_" + std::to_string(size) + "_n" + std::to_string(n) + "_" + hash + ".bin";
  const std::size_t texels = std::size_t(size) * std::size_t(size);
  bake_result r;
  if (!file.empty()) {
    std::ifstream f(file, std::ios::binary);
    r.irradiance = image::make(size, size, 3);
    r.valid.resize(texels);
    r.sampled.resize(texels);
    if (f.read(reinterpret_cast<char*>(&seconds), sizeof seconds) &&
        f.read(reinterpret_cast<char*>(r.irradiance.pixels.data()), std::streamsize(texels * 3 * sizeof(float))) &&
        f.read(reinterpret_cast<char*>(r.valid.data()), std::streamsize(texels)) &&
        f.read(reinterpret_cast<char*>(r.sampled.data()), std::streamsize(texels)))
      return r;
  }
  bake_options o = default_bake(size, threads, s.lights, false);
  o.use_cache = false;
  o.sampler.resolution = n;
  r = bake_lightmap(in, o);
  seconds = r.stats.seconds;
  if (!file.empty()) {
    std::ofstream f(file, std::ios::binary);
    f.write(reinterpret_cast<const char*>(&seconds), sizeof seconds);
    f.write(reinterpret_cast<const char*>(r.irradiance.pixels.data()), std::streamsize(texels * 3 * sizeof(float)));
    f.write(reinterpret_cast<const char*>(r.valid.data()), std::streamsize(texels));
    f.write(reinterpret_cast<const char*>(r.sampled.data()), std::streamsize(texels));
  }
  return r;
}

// Relative RMS of luminance, sqrt(sum (Y - Y_ref)^2 / sum Y_ref^2), over the texels k with keep(k).
template <class Keep>
double relative_rms(const bake_result& r, const bake_result& ref, Keep keep) {
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < ref.sampled.size(); ++k)
    if (keep(k)) {
      const double a = luminance(r, k), b = luminance(ref, k);
      num += (a - b) * (a - b);
      den += b * b;
    }
  return den > 0.0 ? std::sqrt(num / den) : 0.0;
}

// The baker's seams for this input (the internal search the bake runs) and the stitcher's texels.
struct seam_layout {
  std::vector<bake_detail::seam_piece> pieces;
  std::vector<std::uint8_t> stitched;  // per texel: set by the stitcher
  std::size_t stitched_count = 0;
};

// The unstitched bake's irradiance at its sampled texels (0 elsewhere): what write_outputs hands
// the stitcher.
image sampled_irradiance(const bake_result& off, int size) {
  image img = image::make(size, size, 3);
  for (std::size_t k = 0; k < off.sampled.size(); ++k)
    if (off.sampled[k]) std::memcpy(img.pixels.data() + 3 * k, off.irradiance.pixels.data() + 3 * k, 3 * sizeof(float));
  return img;
}

// The seams and the texels stitching sets, as the baker finds them (its stitcher on the unstitched
// bake's values: points on discontinuities dropped).
seam_layout baker_seams(const bake_input& in, const bake_result& off, int size) {
  seam_layout l;
  const auto sc = scene::create(in.scene);
  l.pieces = bake_detail::lightmap_seams(in, size, size, seam_stitch_degrees, *sc);
  const std::vector<bake_detail::page_rect> pages = {bake_detail::page_rect{0, 0, size, size}};
  const bake_detail::seam_stitcher stitcher(l.pieces, pages, size, false, sampled_irradiance(off, size), off.sampled, nullptr);
  l.stitched.assign(std::size_t(size) * std::size_t(size), 0);
  for (std::size_t k : stitcher.texels()) l.stitched[k] = 1;
  for (std::uint8_t s : l.stitched) l.stitched_count += s;
  return l;
}

// The stitching of one bake's irradiance in its parts, timed here with the baker's internal
// classes as write_outputs runs them (medians of `runs`): the seam search (lightmap_seams), the
// systems' assembly and factorisation (seam_stitcher), the solve of one image (seam_stitcher::
// stitch, with its start values) on the unstitched bake's values at the sampled texels.
struct stitch_parts {
  double search = 0.0, build = 0.0, solve = 0.0;
};

stitch_parts time_stitching(const bake_input& in, const bake_result& off, int size, int runs) {
  const auto sc = scene::create(in.scene);
  const std::vector<bake_detail::page_rect> pages = {bake_detail::page_rect{0, 0, size, size}};
  std::vector<double> search, build, solve;
  for (int run = 0; run < runs; ++run) {
    auto t = std::chrono::steady_clock::now();
    const std::vector<bake_detail::seam_piece> pieces = bake_detail::lightmap_seams(in, size, size, seam_stitch_degrees, *sc);
    search.push_back(bench::seconds_since(t));
    image img = sampled_irradiance(off, size);
    std::vector<std::uint8_t> filled = off.sampled;
    t = std::chrono::steady_clock::now();
    const bake_detail::seam_stitcher stitcher(pieces, pages, size, false, img, filled, nullptr);
    build.push_back(bench::seconds_since(t));
    t = std::chrono::steady_clock::now();
    stitcher.stitch(img, filled, nullptr, 0.0f, std::numeric_limits<float>::max());
    solve.push_back(bench::seconds_since(t));
  }
  return {median(search), median(build), median(solve)};
}

// What a side of a piece reads at the piece's middle: some valid sampled texel (weight > 0), and
// some sampled texel inside geometry.
struct side_read {
  bool valid = false, invalid = false;
};

side_read read_side(const bake_result& r, const bake_detail::seam_side& s, int size) {
  const bake_detail::footprint f =
      bake_detail::bilinear_footprint(bake_detail::page_rect{0, 0, size, size}, std::size_t(size), 0.5f * (s.t0 + s.t1));
  side_read out;
  for (std::size_t k = 0; k < 4; ++k) {
    if (!(f.weight[k] > 0.0f) || !r.sampled[f.texel[k]]) continue;
    if (r.valid[f.texel[k]]) out.valid = true;
    else out.invalid = true;
  }
  return out;
}

// The relative steps along a piece at measure_seams' sample points (seams.hpp; default
// seam_options: 4 per texel of length), each with the length it stands for.
std::vector<std::pair<double, double>> piece_steps(const bake_result& r, const bake_detail::seam_piece& p, int size, double floor) {
  const auto n = std::size_t(std::max(1.0, std::ceil(double(seam_options{}.samples_per_texel) * double(p.length_texels))));
  const bake_detail::page_rect page{0, 0, size, size};
  const auto lookup = [&](const glm::vec2& t) {
    const bake_detail::footprint f = bake_detail::bilinear_footprint(page, std::size_t(size), t);
    double y = 0.0;
    for (std::size_t k = 0; k < 4; ++k) y += double(f.weight[k]) * luminance(r, f.texel[k]);
    return y;
  };
  std::vector<std::pair<double, double>> out;
  for (std::size_t j = 0; j < n; ++j) {
    const float t = (float(j) + 0.5f) / float(n);
    const double ya = lookup(p.a.t0 + t * (p.a.t1 - p.a.t0)), yb = lookup(p.b.t0 + t * (p.b.t1 - p.b.t0));
    const double scale = std::max(0.5 * (ya + yb), floor);
    out.emplace_back(scale > 0.0 ? std::fabs(ya - yb) / scale : 0.0, double(p.length_texels) / double(n));
  }
  return out;
}

double max_step(const std::vector<std::pair<double, double>>& steps) {
  double m = 0.0;
  for (const auto& [d, l] : steps) m = std::max(m, d);
  return m;
}

// Length-weighted RMS of the steps (measure_seams' rms).
struct rms_sum {
  double sum2 = 0.0, length = 0.0;
  void add(const std::vector<std::pair<double, double>>& steps) {
    for (const auto& [d, l] : steps) {
      sum2 += l * d * d;
      length += l;
    }
  }
  double rms() const { return length > 0.0 ? std::sqrt(sum2 / length) : 0.0; }
};

std::string figures_csv(const seam_figures& f) {
  char b[160];
  std::snprintf(b, sizeof b, "%.6f,%.6f,%.6f,%.5f", f.rms, f.p95, f.max, f.step_fraction);
  return b;
}

const char* describe(const side_read& r) {
  return r.valid ? (r.invalid ? "valid+inside" : "valid") : (r.invalid ? "inside only" : "padding only");
}

void run_seams(const std::string& csv, const std::vector<std::string>& scenes, const std::vector<int>& sizes, int runs, int ref_n,
               const std::string& truth_dir, int threads) {
  std::FILE* f = std::fopen(csv.c_str(), "w");
  if (!f) {
    std::perror(csv.c_str());
    std::exit(1);
  }
  std::fprintf(f, "scene,uvs,size,triangles,sampled_texels,invalid_texels,"
                  "coplanar_pieces,coplanar_length,walled_pieces,walled_length,crease_pieces,crease_length,"
                  "rms_off,p95_off,max_off,step_fraction_off,rms_on,p95_on,max_on,step_fraction_on,"
                  "rms_ref,p95_ref,max_ref,step_fraction_ref,walled_rms_off,walled_rms_on,"
                  "clean_pieces,clean_length,rms_off_clean,rms_on_clean,max_on_clean,sides_without_valid,sides_with_invalid,"
                  "reference_n,reference_seconds,error_off,error_on,seam_error_off,seam_error_on,"
                  "interior_change,all_change,seam_change,interior_max_change,seam_texels,stitched_texels_check,"
                  "stitch_seconds,stitch_seconds_off,search_seconds,build_seconds,solve_seconds,seconds_off,seconds_on,"
                  "runs,deterministic,load_before,load_after\n");
  for (const std::string& name : scenes)
    for (int size : sizes) {
      seam_scene s;
      try {
        s = make_scene(name, size);
      } catch (const std::exception& e) {  // a level whose charts do not fit the size
        std::printf("%s at %d^2 skipped: %s\n", name.c_str(), size, e.what());
        continue;
      }
      bake_input in;
      in.scene = s.mesh.desc();
      const double load_before = bench::loadavg();
      // The unstitched bake once, then the stitched one R times (the first kept).
      const bake_result off = bake_lightmap(in, default_bake(size, threads, s.lights, false));
      std::vector<double> sec_on, stitch;
      bake_result on;
      bool deterministic = true;
      for (int run = 0; run < runs; ++run) {
        bake_result b = bake_lightmap(in, default_bake(size, threads, s.lights, true));
        sec_on.push_back(b.stats.seconds);
        stitch.push_back(b.stats.stitch_seconds);
        if (run == 0) on = std::move(b);
        else deterministic = deterministic && same_bytes(on, b);
      }
      const stitch_parts parts = time_stitching(in, off, size, runs);
      const double load_after = bench::loadavg();
      const seam_report m_off = measure_seams(in, off), m_on = measure_seams(in, on);
      double ref_seconds = 0.0;
      const bake_result ref = reference_bake(s, in, size, ref_n, threads, truth_dir, ref_seconds);
      const seam_report m_ref = measure_seams(in, ref);
      const seam_layout layout = baker_seams(in, off, size);

      const auto valid_both = [&](const bake_result& r) {
        return [&](std::size_t k) { return r.sampled[k] && r.valid[k] && ref.sampled[k] && ref.valid[k]; };
      };
      const double error_off = relative_rms(off, ref, valid_both(off)), error_on = relative_rms(on, ref, valid_both(on));
      const auto seam_valid = [&](const bake_result& r) {
        return [&](std::size_t k) { return layout.stitched[k] && r.sampled[k] && r.valid[k] && ref.sampled[k] && ref.valid[k]; };
      };
      const double seam_error_off = relative_rms(off, ref, seam_valid(off)), seam_error_on = relative_rms(on, ref, seam_valid(on));
      // What stitching changes, against the unstitched bake.
      const double interior_change = relative_rms(on, off, [&](std::size_t k) { return off.sampled[k] && !layout.stitched[k]; });
      const double all_change = relative_rms(on, off, [&](std::size_t k) { return off.sampled[k] != 0; });
      const double seam_change = relative_rms(on, off, [&](std::size_t k) { return off.sampled[k] && layout.stitched[k]; });
      double interior_max = 0.0, mean_y = 0.0;
      std::size_t sampled = 0;
      for (std::size_t k = 0; k < off.sampled.size(); ++k)
        if (off.sampled[k]) {
          mean_y += luminance(off, k);
          ++sampled;
        }
      mean_y /= double(std::max<std::size_t>(sampled, 1));
      for (std::size_t k = 0; k < off.sampled.size(); ++k)
        if (off.sampled[k] && !layout.stitched[k])
          interior_max = std::max(interior_max, std::fabs(luminance(on, k) - luminance(off, k)) / std::max(luminance(off, k), 0.05 * mean_y));
      // The stitched pieces (coplanar, not walled): sides that read no valid texel or a texel
      // inside geometry; the step over the "clean" pieces, both of whose sides read a valid texel.
      std::size_t without_valid = 0, with_invalid = 0, clean = 0;
      double clean_length = 0.0, clean_max_on = 0.0;
      rms_sum clean_off, clean_on;
      struct worst_piece {
        double step;
        std::size_t index;
      };
      std::vector<worst_piece> worst;
      for (std::size_t i = 0; i < layout.pieces.size(); ++i) {
        const bake_detail::seam_piece& p = layout.pieces[i];
        if (!p.coplanar || p.walled) continue;
        const side_read ra = read_side(off, p.a, size), rb = read_side(off, p.b, size);
        without_valid += std::size_t(!ra.valid) + std::size_t(!rb.valid);
        with_invalid += std::size_t(ra.invalid) + std::size_t(rb.invalid);
        const auto steps_on = piece_steps(on, p, size, m_on.floor);
        if (ra.valid && rb.valid) {
          ++clean;
          clean_length += double(p.length_texels);
          clean_off.add(piece_steps(off, p, size, m_off.floor));
          clean_on.add(steps_on);
          clean_max_on = std::max(clean_max_on, max_step(steps_on));
        }
        worst.push_back({max_step(steps_on), i});
      }
      std::sort(worst.begin(), worst.end(), [](const worst_piece& x, const worst_piece& y) { return x.step > y.step; });

      std::fprintf(f, "%s,%s,%d,%zu,%zu,%zu,%zu,%.1f,%zu,%.1f,%zu,%.1f,%s,%s,%s,%.6f,%.6f,%zu,%.1f,%.6f,%.6f,%.6f,%zu,%zu,"
                      "%d,%.2f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%zu,%zu,%.5f,%.5f,%.5f,%.5f,%.5f,%.4f,%.4f,%d,%d,%.2f,%.2f\n",
                   s.name.c_str(), s.uvs.c_str(), size, s.mesh.triangle_count(), off.stats.sampled_texels, off.stats.invalid_texels,
                   m_off.coplanar.pieces, m_off.coplanar.length_texels, m_off.walled.pieces, m_off.walled.length_texels,
                   m_off.crease.pieces, m_off.crease.length_texels, figures_csv(m_off.coplanar).c_str(), figures_csv(m_on.coplanar).c_str(),
                   figures_csv(m_ref.coplanar).c_str(), m_off.walled.rms, m_on.walled.rms, clean, clean_length, clean_off.rms(),
                   clean_on.rms(), clean_max_on, without_valid, with_invalid, ref_n, ref_seconds, error_off, error_on, seam_error_off,
                   seam_error_on, interior_change, all_change, seam_change, interior_max, on.stats.seam_texels, layout.stitched_count,
                   median(stitch), off.stats.stitch_seconds, parts.search, parts.build, parts.solve, off.stats.seconds, median(sec_on), runs,
                   deterministic ? 1 : 0, load_before, load_after);
      std::fflush(f);
      std::printf("%-16s %-9s %4d^2 %6zu tris: coplanar %zu pieces (%.0f texels), walled %zu (%.0f), crease %zu (%.0f)\n"
                  "  seam RMS %.4f -> %.4f (p95 %.4f -> %.4f, max %.3f -> %.3f, over 2%%: %.3f -> %.3f); reference N = %d: RMS %.4f, "
                  "max %.3f (%.1f s)\n"
                  "  pieces with a valid texel on both sides: %zu (%.0f texels), RMS %.4f -> %.4f, max after %.3f; sides without a "
                  "valid texel %zu, with one inside geometry %zu\n"
                  "  error against the reference %.4f / %.4f (seam texels %.4f / %.4f); change: interior %.2e (max %.2e), all %.2e, "
                  "seam texels %.4f\n"
                  "  seam_texels %zu (rebuilt: %zu), stitch_seconds %.3f (off: %.3f; search %.4f, build %.4f, solve %.4f) of %.2f s "
                  "(off %.2f s)%s\n",
                  s.name.c_str(), s.uvs.c_str(), size, s.mesh.triangle_count(), m_off.coplanar.pieces, m_off.coplanar.length_texels,
                  m_off.walled.pieces, m_off.walled.length_texels, m_off.crease.pieces, m_off.crease.length_texels, m_off.coplanar.rms,
                  m_on.coplanar.rms, m_off.coplanar.p95, m_on.coplanar.p95, m_off.coplanar.max, m_on.coplanar.max,
                  m_off.coplanar.step_fraction, m_on.coplanar.step_fraction, ref_n, m_ref.coplanar.rms, m_ref.coplanar.max, ref_seconds,
                  clean, clean_length, clean_off.rms(), clean_on.rms(), clean_max_on, without_valid, with_invalid, error_off, error_on,
                  seam_error_off, seam_error_on, interior_change, interior_max, all_change, seam_change, on.stats.seam_texels,
                  layout.stitched_count, median(stitch), off.stats.stitch_seconds, parts.search, parts.build, parts.solve, median(sec_on),
                  off.stats.seconds, deterministic ? "" : " NOT DETERMINISTIC");
      for (std::size_t w = 0; w < std::min<std::size_t>(3, worst.size()); ++w) {
        const bake_detail::seam_piece& p = layout.pieces[worst[w].index];
        const glm::vec3 mid = 0.5f * (p.p0 + p.p1);
        std::printf("    worst after: step %.3f, piece %zu at (%.2f, %.2f, %.2f), %.1f texels, sides at texel (%.1f, %.1f) %s / (%.1f, %.1f) %s\n",
                    worst[w].step, worst[w].index, double(mid.x), double(mid.y), double(mid.z), double(p.length_texels),
                    double(0.5f * (p.a.t0.x + p.a.t1.x)), double(0.5f * (p.a.t0.y + p.a.t1.y)), describe(read_side(off, p.a, size)),
                    double(0.5f * (p.b.t0.x + p.b.t1.x)), double(0.5f * (p.b.t0.y + p.b.t1.y)), describe(read_side(off, p.b, size)));
      }
    }
  std::fclose(f);
}

void run_cost(const std::string& csv, const std::vector<std::string>& cases, int runs, int threads) {
  std::FILE* f = std::fopen(csv.c_str(), "w");
  if (!f) {
    std::perror(csv.c_str());
    std::exit(1);
  }
  std::fprintf(f, "scene,uvs,size,triangles,texels,sampled_texels,coplanar_pieces,coplanar_length,seam_texels,stitch_seconds,"
                  "stitch_seconds_min,stitch_seconds_max,stitch_seconds_off,search_seconds,build_seconds,solve_seconds,seconds,seconds_off,"
                  "runs,load_before,load_after\n");
  for (const std::string& c : cases) {
    const std::size_t at = c.find('@');
    const std::string name = c.substr(0, at);
    const int size = at == std::string::npos ? 1024 : std::atoi(c.c_str() + at + 1);
    const seam_scene s = make_scene(name, size);
    bake_input in;
    in.scene = s.mesh.desc();
    const double load_before = bench::loadavg();
    const bake_result off = bake_lightmap(in, default_bake(size, threads, s.lights, false));
    std::vector<double> stitch, seconds;
    bake_result first;
    for (int run = 0; run < runs; ++run) {
      bake_result r = bake_lightmap(in, default_bake(size, threads, s.lights, true));
      stitch.push_back(r.stats.stitch_seconds);
      seconds.push_back(r.stats.seconds);
      if (run == 0) first = std::move(r);
    }
    const stitch_parts parts = time_stitching(in, off, size, runs);
    const double load_after = bench::loadavg();
    const seam_report m = measure_seams(in, first);
    std::fprintf(f, "%s,%s,%d,%zu,%zu,%zu,%zu,%.1f,%zu,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.4f,%.4f,%d,%.2f,%.2f\n", s.name.c_str(),
                 s.uvs.c_str(), size, s.mesh.triangle_count(), first.stats.texels, first.stats.sampled_texels, m.coplanar.pieces,
                 m.coplanar.length_texels, first.stats.seam_texels, median(stitch), *std::min_element(stitch.begin(), stitch.end()),
                 *std::max_element(stitch.begin(), stitch.end()), off.stats.stitch_seconds, parts.search, parts.build, parts.solve,
                 median(seconds), off.stats.seconds, runs, load_before, load_after);
    std::fflush(f);
    std::printf("cost %-22s %4d^2: %zu seam texels (%zu coplanar pieces, %.0f texels long), stitch_seconds %.4f (median of %d; off: "
                "%.4f; search %.4f, build %.4f, solve %.4f) of %.2f s\n",
                s.name.c_str(), size, first.stats.seam_texels, m.coplanar.pieces, m.coplanar.length_texels, median(stitch), runs,
                off.stats.stitch_seconds, parts.search, parts.build, parts.solve, median(seconds));
  }
  std::fclose(f);
}

std::vector<int> ints(const std::string& s) {
  std::vector<int> v;
  for (const std::string& item : bench::split(s)) v.push_back(std::atoi(item.c_str()));
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: sweep_seams out.csv [--cost-csv path] [--parts seams,cost] [--scenes a,b] [--sizes 256,512] [--runs R] "
                         "[--reference-n N] [--truth-cache DIR] [--threads T] [--cost-cases scene@size,...]\n");
    return 2;
  }
  const std::string csv = argv[1];
  std::string cost_csv = csv.size() > 4 ? csv.substr(0, csv.size() - 4) + "_cost.csv" : csv + "_cost.csv";
  std::vector<std::string> parts = {"seams", "cost"}, scenes = default_scenes,
                           cost_cases = {"open_street@1024", "open_street@2048", "terrain_town@1024"};
  std::vector<int> sizes = {256, 512};
  int runs = 3, ref_n = 128, threads = 2;
  std::string truth_dir;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--cost-csv") cost_csv = v;
    else if (a == "--parts") parts = bench::split(v);
    else if (a == "--scenes") scenes = bench::split(v);
    else if (a == "--sizes") sizes = ints(v);
    else if (a == "--runs") runs = std::max(1, std::atoi(v.c_str()));
    else if (a == "--reference-n") ref_n = std::atoi(v.c_str());
    else if (a == "--truth-cache") truth_dir = v;
    else if (a == "--threads") threads = std::atoi(v.c_str());
    else if (a == "--cost-cases") cost_cases = bench::split(v);
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const auto t0 = std::chrono::steady_clock::now();
  std::printf("load average before: %.2f (the machine may be shared: times are medians of %d runs)\n", bench::loadavg(), runs);
  try {
    if (std::find(parts.begin(), parts.end(), "seams") != parts.end()) run_seams(csv, scenes, sizes, runs, ref_n, truth_dir, threads);
    if (std::find(parts.begin(), parts.end(), "cost") != parts.end()) run_cost(cost_csv, cost_cases, runs, threads);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sweep_seams: %s\n", e.what());
    return 1;
  }
  std::printf("load average after: %.2f; %.0f s in all\n", bench::loadavg(), bench::seconds_since(t0));
  return 0;
}
