// What exact edge coverage (raster_options::edge_coverage) buys downstream: cost on the reference
// scenes, the irradiance cache's error at a fixed hemicube budget, and the hemicube resolution N at
// which per-point hemicubes reach 1% relative RMS, point sampling against edge coverage
// (docs/raster.md, "Exact edge coverage").
//
//   usage: sweep_edge_downstream out.csv [options]
//     --parts LIST        any of cost,n,cache,silhouette (default all four)
//     --scenes LIST       any of cornell,hexagon,sky,pavilion,street,terrain (default cornell,hexagon,sky;
//                         the open scenes: benchmarks/run.sh edge_downstream_open)
//     --terrain T         triangles of the terrain scene, heightfield(T) (default 10000)
//     --grid K            points per side of each surface (default 64)
//     --stride S          the converged reference (and the per-point sweep) use every S-th point (default 5)
//     --converged N       resolution of the converged reference (default 512)
//     --reference MODE    edge or point: how the converged reference renders (default edge)
//     --check N           also render every --check-stride-th reference point with edge coverage at N
//                         and report the reference's RMS against it (default 1024; 0 = no check)
//     --check-point N     the same with point sampling at N: a check by the other method (default 1024; 0 = none)
//     --check-stride S    (default 8)
//     --ns LIST           resolutions of the per-point sweep (default 16,24,32,48,64,96,128,192,256)
//     --cost-n N          resolution of the cost part (default 64)
//     --rounds R          paired rounds of the cost part (default 7)
//     --cost-points P     surface points per scene in the cost part (default 256)
//     --time-rounds R     paired rounds timing each N of the per-point sweep (default 5)
//     --time-points P     reference points timed per round in the per-point sweep (default 48)
//     --cache-n N         hemicube resolution of the cache part (default 64)
//     --a LIST            the cache's error thresholds with point sampling (default 0.1,0.2,0.4,0.7); edge
//                         coverage gets its own threshold per value, matched to the same hemicube count
//     --threads T         worker threads of the references, the per-point errors and the cache
//                         (default 0 = all cores); every timing is on one thread
//     --truth-cache DIR   keep the references' luminances in DIR (created) so reruns do not render them again
//     --append            append rows to out.csv (header only if the file is empty)
//
// Scenes (reference_scenes.hpp) and points, as benchmarks/sweep_cache.cpp lays them out: the Cornell
// box (32 triangles: floor, back, left and right walls), the hexagon room tessellated 3 x 3 per wall
// cell (hexagon_room(3), 1062 triangles, lit by the sky through its window: the ceiling), and "sky and
// occluders" (42 triangles, the ground around four boxes). A K x K grid of points (texel centres of a
// K x K lightmap of the surface) 1 mm off each surface. Every hemicube goes through
// make_hemicube_sampler (its defaults: rolled, the cache's integrate options), the two ways differing
// only in hemicube_sampler_options::raster.edge_coverage.
// The open scenes (like game content under a sky of 1: thin parts, many silhouettes, terrain; not
// in the default --scenes): "pavilion", open_pavilion() (708 triangles), K x K points on the step's
// top, the floor slab's top and the roof's underside (the roof's top sees nothing but the sky: left
// out); "street", open_street(), K x K on the ground and on each of the two planes of the building
// fronts along the street (z = -4 and 4, up to 12 m high), of those only the points that lie on a
// building; "terrain", heightfield(--terrain), K x K over its square (x, z), each point on the
// heightfield's triangle above it, with that triangle's normal. In each, points inside geometry
// (the step under the floor slab, ground under buildings and posts, ...) are left out by the
// reference's back-face rule (step 1). Nothing in them emits: a hemicube's irradiance is the sky
// that the point sees. Their rows' scene: open_pavilion_708, open_street_554, heightfield_<2 k^2>
// (heightfield_10082 for T = 10000).
//
// Steps (1-4 per scene, 5 once):
// 1. Reference: at every S-th point, a hemicube at --converged N (edge coverage unless --reference
//    point; points whose reference sees > 10% back faces are left out: inside geometry). Checked
//    against edge coverage at --check N and point sampling at --check-point N on every
//    --check-stride-th of those points.
// 2. Cost (part "cost"): hemicubes per second (render + integrate, one thread) at --cost-n on
//    --cost-points area-weighted surface points (bench_points.hpp), the two ways alternated in paired
//    rounds (A B, then B A); a row per way and round.
// 3. Per-point sweep (part "n"): at each N of --ns, both ways, a hemicube at every reference point;
//    RMS and max relative error against the reference; time per hemicube from paired one-thread
//    rounds on --time-points of those points.
// 4. Cache (part "cache"): cache_irradiance (default options, N = --cache-n) over all the grid points;
//    point sampling at each threshold a of --a, then edge coverage with a threshold found so that it
//    renders about as many hemicubes (a scaled by sqrt(hemicubes / target), as the count goes as a^-2 on
//    a surface; up to 5 tries, done within 3%); RMS and max error at the reference points. Every try is a
//    row; the one closest to the target has matched = 1.
// 5. Silhouettes of closed meshes (part "silhouette", once, not per scene): 8 boxes (pseudo-random
//    sizes and places, wholly above the horizon) under a sky of 1, each alone, seen from the origin
//    with normal +z, rendered and integrated at each N of --ns; E against the closed form pi minus
//    Lambert's formula over the faces that face the point. Each box twice: closed (12 triangles) and
//    its front faces only (the back faces left out). Rows: scene closed_box or front_faces, the RMS,
//    max and mean of the signed relative error over the 8 boxes.
// Error (steps 1-4): (E - E_ref) / max(E_ref, 5% of the mean E_ref) in luminance, as sweep_cache
// (umbra points do not divide by ~0).
// Time with the defaults: ~5 min on a shared 2-core VM with the edge coverage of 0.13.0 (299 s).
// The open scenes (--scenes pavilion,street,terrain --parts cost,n,cache): 256 s on the shared
// 2-core VM, of which ~65 s the references and their checks (read back from --truth-cache on reruns).
//
// CSV columns: part,scene,mode,N,a,round,points,hemicubes,seconds,hemicubes_per_s,rms_rel_err,
// max_rel_err,mean_rel_err,target_hemicubes,matched,threads,loadavg. `seconds` is the wall time of the
// row's work (hemicubes_per_s = hemicubes / seconds; 0 for a reference read from --truth-cache);
// mean_rel_err is the mean signed error (a bias shows there, aliasing noise averages out); rows
// without an error (reference, cost, time) have rms and max -1, mean 0. Parts: reference, check,
// cost, time, per_point, cache, silhouette.
#include "bench_util.hpp"
#include "hemilight/cache.hpp"
#include "hemilight/integrate.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/reference_scenes.hpp"

#include "bench_points.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

// ---- command line ----------------------------------------------------------------------------

struct settings {
  std::string path;
  std::vector<std::string> parts{"cost", "n", "cache", "silhouette"};
  std::vector<std::string> scenes{"cornell", "hexagon", "sky"};
  int grid = 64, stride = 5, converged = 512, check = 1024, check_point = 1024, check_stride = 8;
  std::vector<int> ns{16, 24, 32, 48, 64, 96, 128, 192, 256};
  int cost_n = 64, rounds = 7, cost_points = 256, time_rounds = 5, time_points = 48, cache_n = 64;
  std::vector<float> thresholds{0.1f, 0.2f, 0.4f, 0.7f};
  bool reference_edge = true;
  int threads = 0;
  std::size_t terrain = 10000;
  std::string truth_dir;
  bool append = false;

  bool has_part(const char* p) const { return std::find(parts.begin(), parts.end(), p) != parts.end(); }
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "sweep_edge_downstream: %s\n"
               "usage: sweep_edge_downstream out.csv [--parts cost,n,cache,silhouette]\n"
               "       [--scenes cornell,hexagon,sky,pavilion,street,terrain] [--terrain T] [--grid K] [--stride S]\n"
               "       [--converged N] [--reference edge|point] [--check N] [--check-point N] [--check-stride S] [--ns N,...]\n"
               "       [--cost-n N] [--rounds R] [--cost-points P] [--time-rounds R] [--time-points P] [--cache-n N]\n"
               "       [--a a,...] [--threads T] [--truth-cache DIR] [--append]\n"
               "(the options are described at the top of benchmarks/sweep_edge_downstream.cpp)\n",
               why.c_str());
  std::exit(2);
}

using bench::split;

// A whole number in [lo, hi] for option `what`; anything else stops with a message naming it.
int to_int(const std::string& s, const char* what, long lo, long hi) {
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || v < lo || v > hi)
    usage(std::string("bad ") + what + " '" + s + "' (a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "])");
  return int(v);
}

// A hemicube resolution: even, 2..4096 (hemicube_sampler_options::resolution).
int to_resolution(const std::string& s, const char* what) {
  const int n = to_int(s, what, 2, 4096);
  if (n % 2 != 0) usage(std::string("bad ") + what + " '" + s + "' (hemicube resolutions are even)");
  return n;
}

settings parse(int argc, char** argv) {
  settings st;
  int positional = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(arg + " needs a value");
      return argv[++i];
    };
    auto list = [&](const std::vector<std::string>& allowed) {
      std::vector<std::string> v = split(value());
      for (const std::string& s : v)
        if (std::find(allowed.begin(), allowed.end(), s) == allowed.end()) usage("bad " + arg + " entry '" + s + "'");
      if (v.empty()) usage(arg + " needs at least one entry");
      return v;
    };
    if (arg == "--parts") st.parts = list({"cost", "n", "cache", "silhouette"});
    else if (arg == "--scenes") st.scenes = list({"cornell", "hexagon", "sky", "pavilion", "street", "terrain"});
    else if (arg == "--terrain") st.terrain = std::size_t(to_int(value(), "--terrain", 2, 1 << 22));
    else if (arg == "--grid") st.grid = to_int(value(), "--grid", 2, 1024);
    else if (arg == "--stride") st.stride = to_int(value(), "--stride", 1, 1 << 20);
    else if (arg == "--converged") st.converged = to_resolution(value(), "--converged");
    else if (arg == "--reference") {
      const std::string v = value();
      if (v != "edge" && v != "point") usage("bad --reference '" + v + "' (edge, point)");
      st.reference_edge = v == "edge";
    } else if (arg == "--check") { const std::string v = value(); st.check = v == "0" ? 0 : to_resolution(v, "--check"); }
    else if (arg == "--check-point") { const std::string v = value(); st.check_point = v == "0" ? 0 : to_resolution(v, "--check-point"); }
    else if (arg == "--check-stride") st.check_stride = to_int(value(), "--check-stride", 1, 1 << 20);
    else if (arg == "--ns") {
      st.ns.clear();
      for (const std::string& s : split(value())) st.ns.push_back(to_resolution(s, "--ns entry"));
      if (st.ns.empty()) usage("--ns needs at least one resolution");
    } else if (arg == "--cost-n") st.cost_n = to_resolution(value(), "--cost-n");
    else if (arg == "--rounds") st.rounds = to_int(value(), "--rounds", 1, 1000);
    else if (arg == "--cost-points") st.cost_points = to_int(value(), "--cost-points", 1, 1 << 20);
    else if (arg == "--time-rounds") st.time_rounds = to_int(value(), "--time-rounds", 1, 1000);
    else if (arg == "--time-points") st.time_points = to_int(value(), "--time-points", 1, 1 << 20);
    else if (arg == "--cache-n") st.cache_n = to_resolution(value(), "--cache-n");
    else if (arg == "--a") {
      st.thresholds.clear();
      for (const std::string& s : split(value())) {
        const float a = std::strtof(s.c_str(), nullptr);
        if (!(a >= 0.001f && a <= 1.0f)) usage("bad --a entry '" + s + "' (cache_options::error_threshold is in [0.001, 1])");
        st.thresholds.push_back(a);
      }
      if (st.thresholds.empty()) usage("--a needs at least one threshold");
    } else if (arg == "--threads") st.threads = to_int(value(), "--threads", 0, 256);
    else if (arg == "--truth-cache") st.truth_dir = value();
    else if (arg == "--append") st.append = true;
    else if (arg.size() > 1 && arg[0] == '-') usage("unknown option " + arg);
    else if (positional++ == 0) st.path = arg;
    else usage("unexpected argument " + arg);
  }
  if (st.path.empty()) usage("no output CSV given");
  return st;
}

// ---- scenes and points -------------------------------------------------------------------------

struct point_set {
  std::string key;   // the --scenes entry
  std::string name;  // the CSV's scene column
  std::string file;  // the --truth-cache files' scene part (the key, with the terrain's triangle count)
  scene_mesh mesh;
  std::shared_ptr<const scene> sc;
  std::vector<glm::vec3> p, n;
};

// k x k points on the parallelogram o + s u + t v, normal n (bench::grid_points).
void grid(point_set& ps, glm::vec3 o, glm::vec3 u, glm::vec3 v, glm::vec3 n, int k) {
  bench::grid_points(ps.p, ps.n, o, u, v, n, k);
}

// The corners of triangle t of m.
void corners(const scene_mesh& m, std::size_t t, glm::dvec3 c[3]) {
  for (int j = 0; j < 3; ++j) c[j] = glm::dvec3(m.positions[m.indices[3 * t + std::size_t(j)]]);
}

// Does q lie on the triangle with corners c (within 1e-4 m of its plane, and within its edges in
// the plane, 1e-6 relative slack)?
bool on_triangle(const glm::dvec3 c[3], const glm::dvec3& q) {
  const glm::dvec3 e1 = c[1] - c[0], e2 = c[2] - c[0], g = glm::cross(e1, e2);
  const double len = glm::length(g);
  if (len == 0.0) return false;
  const glm::dvec3 d = q - c[0];
  if (std::fabs(glm::dot(d, g)) / len > 1e-4) return false;
  const double u = glm::dot(glm::cross(d, e2), g) / (len * len), v = glm::dot(glm::cross(e1, d), g) / (len * len);
  return u >= -1e-6 && v >= -1e-6 && u + v <= 1.0 + 1e-6;
}

// Appends the k x k points of the parallelogram (grid_points) that lie on a triangle of m facing
// along n: the parts of a plane the mesh covers (the building fronts along a street).
void grid_on_mesh(point_set& ps, glm::vec3 o, glm::vec3 u, glm::vec3 v, glm::vec3 n, int k) {
  point_set all;
  grid(all, o, u, v, n, k);
  std::vector<std::size_t> facing;  // the triangles whose front faces along n
  for (std::size_t t = 0; t < ps.mesh.triangle_count(); ++t) {
    glm::dvec3 c[3];
    corners(ps.mesh, t, c);
    const glm::dvec3 g = glm::cross(c[1] - c[0], c[2] - c[0]);
    if (glm::length(g) > 0.0 && glm::dot(g, glm::dvec3(n)) > 0.999 * glm::length(g)) facing.push_back(t);
  }
  for (std::size_t i = 0; i < all.p.size(); ++i) {
    const glm::dvec3 q = glm::dvec3(all.p[i]) - 1e-3 * glm::dvec3(n);  // on the plane (grid_points lifts by 1 mm)
    for (const std::size_t t : facing) {
      glm::dvec3 c[3];
      corners(ps.mesh, t, c);
      if (on_triangle(c, q)) {
        ps.p.push_back(all.p[i]);
        ps.n.push_back(all.n[i]);
        break;
      }
    }
  }
}

// k x k points over the heightfield's square [-5, 5]^2 (x, z; texel centres as grid_points), each
// on the topmost upward-facing triangle above it (the heightfield has one), with that triangle's
// front normal, 1 mm off it along the normal. The triangles are binned by their x-z bounds on a
// b x b grid (b^2 ~ triangles / 2), so each point tests a few: O(T + k^2) for T triangles.
void heightfield_grid(point_set& ps, int k) {
  const scene_mesh& m = ps.mesh;
  const int b = std::max(1, int(std::sqrt(double(m.triangle_count()) / 2.0)));
  const auto bin = [b](double v) { return std::clamp(int(std::floor((v + 5.0) / 10.0 * b)), 0, b - 1); };
  std::vector<std::vector<std::size_t>> bins(std::size_t(b) * std::size_t(b));
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    glm::dvec3 c[3];
    corners(m, t, c);
    if (glm::cross(c[1] - c[0], c[2] - c[0]).y <= 0.0) continue;  // faces down or edge-on
    const glm::dvec3 lo = glm::min(c[0], glm::min(c[1], c[2])), hi = glm::max(c[0], glm::max(c[1], c[2]));
    for (int j = bin(lo.z); j <= bin(hi.z); ++j)
      for (int i = bin(lo.x); i <= bin(hi.x); ++i) bins[std::size_t(j) * std::size_t(b) + std::size_t(i)].push_back(t);
  }
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) {
      const double x = -5.0 + 10.0 * (i + 0.5) / k, z = -5.0 + 10.0 * (j + 0.5) / k;
      bool found = false;
      double best_y = 0.0;
      glm::dvec3 best_n(0.0);
      for (const std::size_t t : bins[std::size_t(bin(z)) * std::size_t(b) + std::size_t(bin(x))]) {
        glm::dvec3 c[3];
        corners(m, t, c);
        const glm::dvec3 g = glm::cross(c[1] - c[0], c[2] - c[0]);
        // Barycentric coordinates of (x, z) in the triangle's x-z projection (g.y is twice its area).
        const double ax = c[0].x - x, az = c[0].z - z, bx = c[1].x - x, bz = c[1].z - z, cx = c[2].x - x, cz = c[2].z - z;
        const double w0 = (bz * cx - bx * cz) / g.y, w1 = (cz * ax - cx * az) / g.y, w2 = (az * bx - ax * bz) / g.y;
        if (w0 < -1e-9 || w1 < -1e-9 || w2 < -1e-9) continue;
        const double y = w0 * c[0].y + w1 * c[1].y + w2 * c[2].y;
        if (!found || y > best_y) {
          found = true;
          best_y = y;
          best_n = glm::normalize(g);
        }
      }
      if (!found) continue;  // outside the heightfield (not for points inside its square)
      const glm::vec3 nrm(best_n);
      ps.p.push_back(glm::vec3(float(x), float(best_y), float(z)) + 1e-3f * nrm);
      ps.n.push_back(nrm);
    }
}

point_set make_points(const std::string& key, int k, std::size_t terrain_triangles) {
  point_set ps;
  ps.key = ps.file = key;
  if (key == "cornell") {
    ps.name = "cornell_box_32";
    ps.mesh = cornell_box();
    bench::cornell_box_grid(ps.p, ps.n, k);
  } else if (key == "hexagon") {
    ps.name = "hexagon_room_1062";
    ps.mesh = hexagon_room(3);
    point_set square;
    grid(square, {-4, 3, -4}, {8, 0, 0}, {0, 0, 8}, {0, -1, 0}, k);  // the ceiling's bounding square
    for (std::size_t i = 0; i < square.p.size(); ++i) {
      // inside the hexagon (circumradius 4, corners at 60 i degrees), with a margin
      const float x = std::fabs(square.p[i].x), z = std::fabs(square.p[i].z);
      if (z < 3.4f && x < 3.95f - z / 1.7320508f) {
        ps.p.push_back(square.p[i]);
        ps.n.push_back(square.n[i]);
      }
    }
  } else if (key == "sky") {
    ps.name = "sky_and_occluders_42";
    ps.mesh = sky_and_occluders();
    grid(ps, {-10, 0, -10}, {20, 0, 0}, {0, 0, 20}, {0, 1, 0}, k);  // the ground
  } else if (key == "pavilion") {
    ps.mesh = open_pavilion();
    grid(ps, {-7, 0.02f, -5}, {14, 0, 0}, {0, 0, 10}, {0, 1, 0}, k);     // the step's top (its middle under the floor slab)
    grid(ps, {-6, 0.3f, -4}, {12, 0, 0}, {0, 0, 8}, {0, 1, 0}, k);       // the floor slab's top (parts under plinths)
    grid(ps, {-6.5f, 3.8f, -4.5f}, {13, 0, 0}, {0, 0, 9}, {0, -1, 0}, k);  // the roof's underside (parts above capitals)
  } else if (key == "street") {
    ps.mesh = open_street();
    grid(ps, {-20, 0, -8}, {40, 0, 0}, {0, 0, 16}, {0, 1, 0}, k);  // the ground (parts under buildings and posts)
    // The building fronts along the street (the planes z = -4 facing +z and z = 4 facing -z, up to
    // the tallest building): the points on a building.
    grid_on_mesh(ps, {-19, 0, -4}, {38, 0, 0}, {0, 12, 0}, {0, 0, 1}, k);
    grid_on_mesh(ps, {-19, 0, 4}, {38, 0, 0}, {0, 12, 0}, {0, 0, -1}, k);
  } else {
    ps.mesh = heightfield(terrain_triangles);
    ps.file = key + "_t" + std::to_string(terrain_triangles);
    heightfield_grid(ps, k);
  }
  if (ps.name.empty()) {
    const char* base = key == "pavilion" ? "open_pavilion_" : key == "street" ? "open_street_" : "heightfield_";
    ps.name = base + std::to_string(ps.mesh.triangle_count());
  }
  ps.sc = scene::create(ps.mesh.desc());
  return ps;
}

// ---- rendering ---------------------------------------------------------------------------------

using bench::lum;
using bench::loadavg;
using bench::seconds_since;

irradiance_sampler sampler_for(const point_set& ps, int n, bool edge, int workers) {
  sampler_options so;
  so.resolution = n;
  so.raster.edge_coverage = edge;
  return make_hemicube_sampler(ps.sc, so, workers);
}

struct luminances {
  std::vector<float> value, backface;  // per index of the list rendered
};

// Luminance and back-face fraction of a hemicube (N = n, edge coverage or not) at the points
// idx, on `threads` workers; the wall time in *secs. With a truth folder, kept in / read from a
// file keyed by what was rendered (then *secs = 0).
luminances render(const settings& st, const point_set& ps, const std::vector<std::size_t>& idx, int n, bool edge,
                  const std::string& cache_key, double* secs) {
  luminances out;
  out.value.resize(idx.size());
  out.backface.resize(idx.size());
  std::string file;
  if (!st.truth_dir.empty() && !cache_key.empty()) {
    file = st.truth_dir + "/edge_downstream_" + ps.file + "_k" + std::to_string(st.grid) + "_" + cache_key + "_N" +
           std::to_string(n) + (edge ? "_edge" : "_point") + ".bin";
    if (FILE* f = std::fopen(file.c_str(), "rb")) {
      std::uint64_t count = 0;
      const bool ok = std::fread(&count, sizeof count, 1, f) == 1 && count == idx.size() &&
                      std::fread(out.value.data(), sizeof(float), idx.size(), f) == idx.size() &&
                      std::fread(out.backface.data(), sizeof(float), idx.size(), f) == idx.size();
      std::fclose(f);
      if (ok) {
        *secs = 0.0;
        std::printf("  read %s\n", file.c_str());
        return out;
      }
    }
  }
  const int workers = resolve_thread_count(st.threads);
  const irradiance_sampler sampler = sampler_for(ps, n, edge, workers);
  const auto t0 = std::chrono::steady_clock::now();
  parallel_for(idx.size(), workers, 4, [&](int w, std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const sampler_result s = sampler(w, ps.p[idx[k]], ps.n[idx[k]]);
      out.value[k] = lum(s.irradiance);
      out.backface[k] = s.backface_fraction;
    }
  });
  *secs = seconds_since(t0);
  if (!file.empty())
    if (FILE* f = std::fopen(file.c_str(), "wb")) {
      const std::uint64_t count = idx.size();
      std::fwrite(&count, sizeof count, 1, f);
      std::fwrite(out.value.data(), sizeof(float), idx.size(), f);
      std::fwrite(out.backface.data(), sizeof(float), idx.size(), f);
      std::fclose(f);
    }
  return out;
}

// Hemicubes per second of `sampler` on one thread (worker 0) over the points.
double rate(const irradiance_sampler& sampler, const std::vector<glm::vec3>& p, const std::vector<glm::vec3>& n,
            double* secs) {
  volatile float sink = 0.0f;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < p.size(); ++i) sink = sink + sampler(0, p[i], n[i]).irradiance.x;
  *secs = seconds_since(t0);
  return double(p.size()) / *secs;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// ---- output ------------------------------------------------------------------------------------

struct row {
  const char* part;
  std::string scene;
  const char* mode;
  int n = 0;
  double a = 0.0;
  int round = -1;
  std::size_t points = 0, hemicubes = 0;
  double seconds = 0.0, rms = -1.0, worst = -1.0, mean = 0.0;
  std::size_t target = 0;
  int matched = 0, threads = 1;
};

void write(FILE* out, const row& r) {
  std::fprintf(out, "%s,%s,%s,%d,%.4f,%d,%zu,%zu,%.5f,%.2f,%.6f,%.6f,%.6f,%zu,%d,%d,%.2f\n", r.part, r.scene.c_str(), r.mode,
               r.n, r.a, r.round, r.points, r.hemicubes, r.seconds, r.seconds > 0 ? double(r.hemicubes) / r.seconds : 0.0,
               r.rms, r.worst, r.mean, r.target, r.matched, r.threads, loadavg());
  std::fflush(out);
}

const char* mode_name(bool edge) { return edge ? "edge" : "point"; }

// ---- part "silhouette" -------------------------------------------------------------------------

// Lambert's formula: the projected solid angle (normal +z) of the convex polygon `poly` (relative
// to the point), all of it above the horizon.
double lambert(const std::vector<glm::dvec3>& poly) {
  double sum = 0.0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec3 u = glm::normalize(poly[i]), v = glm::normalize(poly[(i + 1) % poly.size()]);
    const glm::dvec3 g = glm::cross(u, v);
    const double len = glm::length(g);
    if (len > 0.0) sum += std::atan2(len, glm::dot(u, v)) * g.z / len;
  }
  return 0.5 * std::fabs(sum);
}

// Boxes under a sky of 1, closed and with their front faces only: the closed form E = pi - the
// front faces' projected solid angle holds for both (the back faces are hidden behind the front).
void silhouette_part(const settings& st, FILE* out) {
  constexpr double pi = 3.14159265358979323846;
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.0, 1.0);
  struct box_case {
    std::vector<glm::dvec3> quads[6];  // outward-facing, counter-clockwise seen from outside
    bool front[6];
    double e_ref;
  };
  std::vector<box_case> boxes(8);
  for (box_case& b : boxes) {
    const glm::dvec3 c(0.8 * u(rng), 0.8 * u(rng), 1.0 + 0.8 * pos(rng));
    const glm::dvec3 h(0.1 + 0.25 * pos(rng), 0.1 + 0.25 * pos(rng), 0.1 + 0.3 * pos(rng));
    double occluded = 0.0;
    for (int f = 0; f < 6; ++f) {
      const int ax = f / 2, a1 = (ax + 1) % 3, a2 = (ax + 2) % 3;
      const double side = f % 2 ? 1.0 : -1.0;
      const double corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      for (const auto& k : corners) {
        glm::dvec3 p = c;
        p[ax] += side * h[ax];
        p[a1] += k[0] * h[a1];
        p[a2] += k[1] * h[a2];
        b.quads[f].push_back(p);
      }
      glm::dvec3 n(0.0);
      n[ax] = side;
      std::vector<glm::dvec3>& q = b.quads[f];
      if (glm::dot(glm::cross(q[1] - q[0], q[2] - q[0]), n) < 0.0) std::swap(q[1], q[3]);
      b.front[f] = glm::dot(n, q[0]) < 0.0;  // the face faces the origin
      if (b.front[f]) occluded += lambert(q);
    }
    b.e_ref = pi - occluded;
  }
  const material occluder{glm::vec3(0.0f), glm::vec3(0.5f), false};
  const frame basis{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const bool closed : {true, false})
    for (const bool edge : {false, true})
      for (const int n : st.ns) {
        double sum = 0.0, signed_sum = 0.0, worst = 0.0;
        for (const box_case& b : boxes) {
          scene_mesh m;
          m.sky_radiance = glm::vec3(1.0f);
          for (int f = 0; f < 6; ++f)
            if (closed || b.front[f]) {
              const std::vector<glm::dvec3>& q = b.quads[f];
              m.add_triangle(glm::vec3(q[0]), glm::vec3(q[1]), glm::vec3(q[2]), occluder);
              m.add_triangle(glm::vec3(q[0]), glm::vec3(q[2]), glm::vec3(q[3]), occluder);
            }
          raster_options o;
          o.edge_coverage = edge;
          hemicube_rasterizer r(scene::create(m.desc()), o);
          hemicube_buffer buf;
          r.render({0, 0, 0}, basis, n, buf);
          hemicube_integrator integ(n);
          const double err = (double(integ.integrate(buf).irradiance.x) - b.e_ref) / b.e_ref;
          sum += err * err;
          signed_sum += err;
          worst = std::max(worst, std::fabs(err));
        }
        row r{"silhouette", closed ? "closed_box" : "front_faces", mode_name(edge)};
        r.n = n;
        r.points = boxes.size();
        r.rms = std::sqrt(sum / double(boxes.size()));
        r.worst = worst;
        r.mean = signed_sum / double(boxes.size());
        write(out, r);
        if (n == 64)
          std::printf("silhouettes, %s, %s, N = 64: mean %+.4f%%, max |%.4f%%| over %zu boxes\n",
                      closed ? "closed boxes" : "front faces only", edge ? "edge coverage" : "point sampling",
                      100.0 * r.mean, 100.0 * worst, boxes.size());
      }
  std::fflush(stdout);
}

// ---- the reference -----------------------------------------------------------------------------

struct reference {
  std::vector<std::size_t> idx;  // valid reference points (indices into the point set)
  std::vector<double> e;         // their reference luminance
  double mean = 0.0;

  // RMS, max and mean of the relative error (value - E_ref) / max(E_ref, 5% of the mean) over the
  // reference points (the mean signed: a bias shows there, aliasing noise averages out).
  template <class F>
  void error(F value_at, row& r) const {
    double sum = 0.0, signed_sum = 0.0;
    r.worst = 0.0;
    for (std::size_t j = 0; j < idx.size(); ++j) {
      const double err = (double(value_at(j)) - e[j]) / std::max(e[j], 0.05 * mean);
      sum += err * err;
      signed_sum += err;
      r.worst = std::max(r.worst, std::fabs(err));
    }
    const double count = double(std::max<std::size_t>(idx.size(), 1));
    r.rms = std::sqrt(sum / count);
    r.mean = signed_sum / count;
  }
};

reference make_reference(const settings& st, const point_set& ps, FILE* out) {
  std::vector<std::size_t> every;
  for (std::size_t i = 0; i < ps.p.size(); i += std::size_t(st.stride)) every.push_back(i);
  double secs = 0.0;
  const luminances l = render(st, ps, every, st.converged, st.reference_edge, "s" + std::to_string(st.stride), &secs);
  reference ref;
  for (std::size_t j = 0; j < every.size(); ++j)
    if (l.backface[j] <= 0.1f) {
      ref.idx.push_back(every[j]);
      ref.e.push_back(double(l.value[j]));
    }
  for (double v : ref.e) ref.mean += v;
  ref.mean /= double(std::max<std::size_t>(ref.e.size(), 1));
  row r{"reference", ps.name, mode_name(st.reference_edge)};
  r.n = st.converged;
  r.points = ref.idx.size();
  r.hemicubes = secs > 0 ? every.size() : 0;
  r.seconds = secs;
  r.threads = resolve_thread_count(st.threads);
  write(out, r);
  std::printf("%s: %zu points, reference (%s, N = %d) at %zu of them (every %d-th, valid): %.1f s\n", ps.name.c_str(),
              ps.p.size(), st.reference_edge ? "edge coverage" : "point sampling", st.converged, ref.idx.size(), st.stride,
              secs);
  std::fflush(stdout);

  // Is it converged? The reference against edge coverage at a higher N and against point sampling
  // at a higher N still, on every check_stride-th reference point.
  std::vector<std::size_t> cpos, cidx;
  for (std::size_t j = 0; j < ref.idx.size(); j += std::size_t(st.check_stride)) {
    cpos.push_back(j);
    cidx.push_back(ref.idx[j]);
  }
  for (const bool edge : {true, false}) {
    const int n = edge ? st.check : st.check_point;
    if (n == 0 || cidx.empty()) continue;
    const luminances c = render(st, ps, cidx, n, edge, "s" + std::to_string(st.stride) + "c" + std::to_string(st.check_stride), &secs);
    double sum = 0.0, worst = 0.0, bias = 0.0;
    for (std::size_t k = 0; k < cidx.size(); ++k) {
      const double f = c.value[k], d = (ref.e[cpos[k]] - f) / std::max(f, 0.05 * ref.mean);
      sum += d * d;
      bias += d;
      worst = std::max(worst, std::fabs(d));
    }
    row cr{"check", ps.name, mode_name(edge)};
    cr.n = n;
    cr.points = cidx.size();
    cr.hemicubes = secs > 0 ? cidx.size() : 0;
    cr.seconds = secs;
    cr.rms = std::sqrt(sum / double(cidx.size()));
    cr.worst = worst;
    cr.mean = bias / double(cidx.size());
    cr.threads = resolve_thread_count(st.threads);
    write(out, cr);
    std::printf("  check: reference against %s at N = %d on %zu points: RMS %.4f%%, max %.3f%%, mean signed %.4f%% (%.1f s)\n",
                edge ? "edge coverage" : "point sampling", n, cidx.size(), 100.0 * cr.rms, 100.0 * worst,
                100.0 * bias / double(cidx.size()), secs);
    std::fflush(stdout);
  }
  return ref;
}

// ---- the parts ---------------------------------------------------------------------------------

// Part "cost": hemicubes/s at cost_n, one thread, both ways in paired rounds.
void cost_part(const settings& st, const point_set& ps, FILE* out) {
  const bench::sample_points sp = bench::surface_points(ps.mesh, std::size_t(st.cost_points), 1e-4f * ps.sc->size());
  std::vector<glm::vec3> normals;
  for (const frame& f : sp.frames) normals.push_back(f.n);
  const irradiance_sampler point = sampler_for(ps, st.cost_n, false, 1), edge = sampler_for(ps, st.cost_n, true, 1);
  double secs = 0.0;
  rate(point, sp.points, normals, &secs);  // warm-up (tables, scratch)
  rate(edge, sp.points, normals, &secs);
  std::vector<double> ratios;
  for (int k = 0; k < st.rounds; ++k) {
    double rp = 0.0, re = 0.0, sp_s = 0.0, se_s = 0.0;
    if (k % 2 == 0) {
      rp = rate(point, sp.points, normals, &sp_s);
      re = rate(edge, sp.points, normals, &se_s);
    } else {
      re = rate(edge, sp.points, normals, &se_s);
      rp = rate(point, sp.points, normals, &sp_s);
    }
    for (const bool e : {false, true}) {
      row r{"cost", ps.name, mode_name(e)};
      r.n = st.cost_n;
      r.round = k;
      r.points = r.hemicubes = sp.points.size();
      r.seconds = e ? se_s : sp_s;
      write(out, r);
    }
    ratios.push_back(rp / re);
  }
  std::printf("  cost at N = %d: edge coverage takes %.1fx the time (median of %d paired rounds)\n", st.cost_n,
              median(ratios), st.rounds);
  std::fflush(stdout);
}

// Part "n": per-point hemicubes at every N, both ways: error against the reference, and time per
// hemicube from paired one-thread rounds on time_points of the reference points.
void n_part(const settings& st, const point_set& ps, const reference& ref, FILE* out) {
  std::vector<glm::vec3> tp, tn;
  const std::size_t count = std::min(ref.idx.size(), std::size_t(st.time_points));
  for (std::size_t j = 0; j < count; ++j) {  // spread over all the surfaces
    const std::size_t i = ref.idx[j * ref.idx.size() / count];
    tp.push_back(ps.p[i]);
    tn.push_back(ps.n[i]);
  }
  for (const int n : st.ns) {
    double first_rms[2] = {}, first_mean[2] = {};
    for (const bool edge : {false, true}) {
      double secs = 0.0;
      const luminances l = render(st, ps, ref.idx, n, edge, "", &secs);
      row r{"per_point", ps.name, mode_name(edge)};
      ref.error([&](std::size_t j) { return l.value[j]; }, r);
      r.n = n;
      r.points = r.hemicubes = ref.idx.size();
      r.seconds = secs;
      r.threads = resolve_thread_count(st.threads);
      write(out, r);
      first_rms[edge ? 1 : 0] = r.rms;
      first_mean[edge ? 1 : 0] = r.mean;
    }
    const irradiance_sampler point = sampler_for(ps, n, false, 1), edge = sampler_for(ps, n, true, 1);
    double secs = 0.0;
    rate(point, tp, tn, &secs);  // warm-up
    rate(edge, tp, tn, &secs);
    std::vector<double> per[2];
    for (int k = 0; k < st.time_rounds; ++k)
      for (int m = 0; m < 2; ++m) {
        const bool e = (m == 1) != (k % 2 == 1);  // A B, then B A
        rate(e ? edge : point, tp, tn, &secs);
        per[e ? 1 : 0].push_back(secs / double(tp.size()));
        row r{"time", ps.name, mode_name(e)};
        r.n = n;
        r.round = k;
        r.points = r.hemicubes = tp.size();
        r.seconds = secs;
        write(out, r);
      }
    std::printf("  N = %4d: RMS (mean signed) point %.3f%% (%+.3f%%), edge %.3f%% (%+.3f%%); per hemicube point %.0f us, "
                "edge %.0f us\n",
                n, 100.0 * first_rms[0], 100.0 * first_mean[0], 100.0 * first_rms[1], 100.0 * first_mean[1],
                1e6 * median(per[0]), 1e6 * median(per[1]));
    std::fflush(stdout);
  }
}

// Part "cache": the cache at cache_n, point sampling at each threshold, edge coverage at a threshold
// matched to the same hemicube count.
void cache_part(const settings& st, const point_set& ps, const reference& ref, FILE* out) {
  const int workers = resolve_thread_count(st.threads);
  const irradiance_sampler samplers[2] = {sampler_for(ps, st.cache_n, false, workers), sampler_for(ps, st.cache_n, true, workers)};
  const auto cache = [&](bool edge, float a, std::size_t target) {
    cache_options o;
    o.error_threshold = a;
    cache_run run;
    run.thread_count = workers;
    const cache_result res = cache_irradiance(ps.p.data(), ps.n.data(), ps.p.size(), samplers[edge ? 1 : 0], o, run);
    row r{"cache", ps.name, mode_name(edge)};
    r.n = st.cache_n;
    r.a = double(a);
    r.points = ps.p.size();
    r.hemicubes = res.stats.hemicubes;
    r.seconds = res.stats.seconds;
    r.target = target;
    r.threads = workers;
    ref.error([&](std::size_t j) { return lum(res.irradiance[ref.idx[j]]); }, r);
    return r;
  };
  for (const float a : st.thresholds) {
    row p = cache(false, a, 0);
    p.matched = 1;
    write(out, p);
    // Step 4: edge coverage's threshold for the same count (hemicubes ~ a^-2 on a surface).
    std::vector<row> tries;
    float ae = a;
    for (int t = 0; t < 5; ++t) {
      tries.push_back(cache(true, ae, p.hemicubes));
      const double ratio = double(tries.back().hemicubes) / double(std::max<std::size_t>(p.hemicubes, 1));
      if (std::fabs(ratio - 1.0) <= 0.03) break;
      ae = std::clamp(float(double(ae) * std::sqrt(ratio)), 0.001f, 1.0f);
      if (ae == float(tries.back().a)) break;  // clamped: no other threshold to try
    }
    std::size_t best = 0;
    for (std::size_t t = 1; t < tries.size(); ++t)
      if (std::fabs(double(tries[t].hemicubes) - double(p.hemicubes)) <
          std::fabs(double(tries[best].hemicubes) - double(p.hemicubes)))
        best = t;
    tries[best].matched = 1;
    for (const row& r : tries) write(out, r);
    const row& e = tries[best];
    std::printf("  cache N = %d: point a = %.3f %zu hemicubes RMS %.3f%% max %.1f%% mean %+.3f%% (%.1f s); edge a = %.3f %zu "
                "hemicubes RMS %.3f%% max %.1f%% mean %+.3f%% (%.1f s, %zu tries)\n",
                st.cache_n, p.a, p.hemicubes, 100.0 * p.rms, 100.0 * p.worst, 100.0 * p.mean, p.seconds, e.a, e.hemicubes,
                100.0 * e.rms, 100.0 * e.worst, 100.0 * e.mean, e.seconds, tries.size());
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const settings st = parse(argc, argv);
  if (!st.truth_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(st.truth_dir, ec);
    if (ec) usage("cannot create --truth-cache folder '" + st.truth_dir + "': " + ec.message());
  }
  bool header = true;
  if (st.append)
    if (FILE* f = std::fopen(st.path.c_str(), "rb")) {
      header = std::fgetc(f) == EOF;
      std::fclose(f);
    }
  FILE* out = std::fopen(st.path.c_str(), st.append ? "a" : "w");
  if (!out) {
    std::fprintf(stderr, "sweep_edge_downstream: cannot write '%s'\n", st.path.c_str());
    return 1;
  }
  if (header)
    std::fprintf(out, "part,scene,mode,N,a,round,points,hemicubes,seconds,hemicubes_per_s,rms_rel_err,max_rel_err,"
                      "mean_rel_err,target_hemicubes,matched,threads,loadavg\n");
  const auto t0 = std::chrono::steady_clock::now();
  if (st.has_part("silhouette")) silhouette_part(st, out);
  for (const std::string& key : st.scenes) {
    const point_set ps = make_points(key, st.grid, st.terrain);
    if (st.has_part("cost")) {
      std::printf("%s:\n", ps.name.c_str());
      cost_part(st, ps, out);
    }
    if (!st.has_part("n") && !st.has_part("cache")) continue;
    const reference ref = make_reference(st, ps, out);
    if (ref.idx.empty()) {
      std::printf("  no valid reference point (every one sees > 10%% back faces): no errors for %s\n", ps.name.c_str());
      continue;
    }
    if (st.has_part("n")) n_part(st, ps, ref, out);
    if (st.has_part("cache")) cache_part(st, ps, ref, out);
  }
  std::fclose(out);
  std::printf("wrote %s (%.0f s)\n", st.path.c_str(), seconds_since(t0));
  return 0;
}
