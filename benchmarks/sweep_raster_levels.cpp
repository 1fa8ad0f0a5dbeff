// What a hemicube costs on the stand-in levels against the 1,062-triangle hexagon room, the ratio
// with targets (at most 3x on the ~50k-triangle closed level, 10x on the 1M ones),
// measured in paired interleaved rounds.
//   usage: sweep_raster_levels OUT.csv [--rounds R] [--levels a,b,...] [--levels-1m a,b,...|none]
//                              [--threads 1,2] [--culling on,off] [--min-time S] [--quick]
// Scenes: hexagon_room(3) (1,062 triangles, the reference), the levels of levels.hpp at their
// default size (arena and keep ~50k triangles, city_block and terrain_town ~150k; --levels) and at
// ~1M triangles (--levels-1m, default all four; "none" for none). Each scene gets the 256 points of
// bench_raster (bench_points.hpp: area-weighted on its triangles, lifted by 1e-4 of the scene
// size along the face normal; on the levels some lie on faces hidden inside other solids, as a
// bake's texels do), N = 64, render only (hemicube_rasterizer::render, no integration).
//
// A measurement renders whole passes over the 256 points until at least --min-time seconds
// (default 0.3) have passed: on one thread timed in the thread's CPU time, on two threads
// (parallel_for over the points, dynamic chunks of 4, one rasterizer per worker) in wall time.
// Cost per hemicube = time / hemicubes. Rounds: in each round every case (level, culling on or off,
// threads) is measured next to a measurement of the room on the same thread count, the room first
// in even rounds and second in odd ones; the round's ratio is case / room. The summary is the
// median of the rounds' ratios (and their range): the machine's speed drifts from minute to minute
// (docs/raster.md), and a ratio of two measurements taken within a second of each other does not.
// Culling: raster_options::diagnostics.occlusion_culling (on by default on scenes of >= 8192
// triangles; the room is always drawn without it, below that threshold).
//
// CSV (one row per round and case): round, scene, level, target_triangles, triangles, culling,
// threads, hemicubes, seconds, us_per_hemicube, room_us_per_hemicube, ratio, steal, room_steal,
// load1, and the scene's per-hemicube figures from one untimed pass over its points (one
// rasterizer, the case's culling): triangles_tested, face_triangles (the (triangle, face) pairs
// drawn), nodes_occluded, triangles_occluded, seen (distinct triangles seen through the texel
// centres) and inside (the share of points whose hemicube sees back faces through over 10% of its
// texels: points inside geometry). steal: the share of all CPU time the hypervisor gave to other
// guests during the measurement (host_steal.hpp).
// Time: about 4 minutes on two cores with the defaults (7 rounds; the unculled 1M levels take most
// of it); --quick (3 rounds, the ~50k levels and arena_1M, 0.2 s) under a minute.
// Chart: benchmarks/plot_raster_levels.py (docs/raster.md, "Occlusion culling on the levels").
#include "hemilight/levels.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/reference_scenes.hpp"

#include "bench_points.hpp"
#include "bench_util.hpp"
#include "host_steal.hpp"

#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <vector>

using namespace hemilight;

namespace {

constexpr int resolution = 64;

struct bench_scene {
  std::string name;   // row label: hexagon_room_1062, arena, arena_1M, ...
  std::string level;  // levels.hpp name, empty for the room
  std::size_t target = 0;
  std::size_t triangles = 0;
  std::shared_ptr<const scene> built;
  std::vector<glm::vec3> points;
  std::vector<frame> frames;
};

// Per-hemicube figures of a scene and culling setting, from one untimed pass.
struct figures {
  double tested = 0, drawn = 0, nodes_occluded = 0, triangles_occluded = 0, seen = 0, inside = 0;
};

bench_scene make_scene(const std::string& name, const std::string& level, std::size_t target) {
  bench_scene b;
  b.name = name;
  b.level = level;
  b.target = target;
  scene_mesh m;
  if (level.empty()) {
    m = hexagon_room(3);
  } else {
    level_options o;
    o.target_triangles = target;
    m = make_level(level, o).mesh;
  }
  b.triangles = m.triangle_count();
  b.built = scene::create(m.desc());
  bench::sample_points p = bench::surface_points(m, 256, 1e-4f * b.built->size());
  b.points = std::move(p.points);
  b.frames = std::move(p.frames);
  return b;
}

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct measurement {
  std::size_t hemicubes = 0;
  double seconds = 0, steal = -1;
  double us() const { return 1e6 * seconds / double(std::max<std::size_t>(hemicubes, 1)); }
};

// Renders whole passes over the scene's points until min_time has passed (see the top).
measurement measure(const bench_scene& b, bool culling, int threads, double min_time,
                    std::vector<hemicube_rasterizer>& rasterizers, std::vector<hemicube_buffer>& buffers) {
  raster_options o;
  o.diagnostics.occlusion_culling = culling;
  for (hemicube_rasterizer& r : rasterizers) r.bind(b.built, o);
  measurement m;
  const bench::cpu_ticks before = bench::read_cpu_ticks();
  if (threads == 1) {
    const double t0 = thread_cpu_seconds();
    do {
      for (std::size_t i = 0; i < b.points.size(); ++i) rasterizers[0].render(b.points[i], b.frames[i], resolution, buffers[0]);
      m.hemicubes += b.points.size();
      m.seconds = thread_cpu_seconds() - t0;
    } while (m.seconds < min_time);
  } else {
    const auto t0 = std::chrono::steady_clock::now();
    do {
      parallel_for(b.points.size(), threads, 4, [&](int worker, std::size_t begin, std::size_t end) {
        const auto w = static_cast<std::size_t>(worker);
        for (std::size_t i = begin; i < end; ++i) rasterizers[w].render(b.points[i], b.frames[i], resolution, buffers[w]);
      });
      m.hemicubes += b.points.size();
      m.seconds = bench::seconds_since(t0);
    } while (m.seconds < min_time);
  }
  m.steal = bench::steal_fraction(before, bench::read_cpu_ticks());
  return m;
}

figures count_figures(const bench_scene& b, bool culling) {
  raster_options o;
  o.diagnostics.occlusion_culling = culling;
  hemicube_rasterizer r(b.built, o);
  hemicube_buffer buf;
  figures f;
  std::unordered_set<std::uint32_t> ids;
  for (std::size_t i = 0; i < b.points.size(); ++i) {
    r.render(b.points[i], b.frames[i], resolution, buf);
    const raster_statistics& s = r.statistics();
    f.tested += double(s.triangles_tested);
    f.drawn += double(s.face_triangles);
    f.nodes_occluded += double(s.nodes_occluded);
    f.triangles_occluded += double(s.triangles_occluded);
    ids.clear();
    std::size_t back = 0;
    for (std::size_t t = 0; t < buf.texel_count(); ++t) {
      if (r.seen_triangle(t) != hemicube_rasterizer::no_triangle) ids.insert(r.seen_triangle(t));
      if (buf.flags[t] & texel_back_face) ++back;
    }
    f.seen += double(ids.size());
    if (double(back) > 0.1 * double(buf.texel_count())) f.inside += 1;
  }
  const double n = double(b.points.size());
  f.tested /= n;
  f.drawn /= n;
  f.nodes_occluded /= n;
  f.triangles_occluded /= n;
  f.seen /= n;
  f.inside /= n;
  return f;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

struct case_spec {
  std::size_t scene;  // index into the scene list
  bool culling;
  int threads;
  std::vector<double> ratios, us, room_us;
};

int usage() {
  std::fprintf(stderr,
               "usage: sweep_raster_levels OUT.csv [--rounds R] [--levels a,b,...] [--levels-1m a,b,...|none]\n"
               "                           [--threads 1,2] [--culling on,off] [--min-time S] [--quick]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return usage();
  int rounds = 7;
  double min_time = 0.3;
  std::vector<std::string> levels = level_names(), levels_1m = level_names(), culling = {"on", "off"};
  std::vector<int> thread_counts = {1, 2};
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--quick") {
      rounds = 3;
      min_time = 0.2;
      levels = {"arena", "keep"};
      levels_1m = {"arena"};
    } else if (a == "--rounds" && has_value) {
      rounds = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--levels" && has_value) {
      levels = bench::split(argv[++i]);
    } else if (a == "--levels-1m" && has_value) {
      const std::string v = argv[++i];
      levels_1m = v == "none" ? std::vector<std::string>{} : bench::split(v);
    } else if (a == "--threads" && has_value) {
      thread_counts.clear();
      for (const std::string& t : bench::split(argv[++i])) thread_counts.push_back(std::max(1, std::atoi(t.c_str())));
    } else if (a == "--culling" && has_value) {
      culling = bench::split(argv[++i]);
    } else if (a == "--min-time" && has_value) {
      min_time = std::atof(argv[++i]);
    } else {
      return usage();
    }
  }
  std::FILE* f = std::fopen(argv[1], "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", argv[1]);
    return 1;
  }
  try {
    std::printf("sweep_raster_levels: load average before %.2f; building the scenes ...\n", bench::loadavg());
    std::fflush(stdout);
    std::vector<bench_scene> scenes;
    scenes.push_back(make_scene("hexagon_room_1062", "", 0));
    for (const std::string& l : levels) scenes.push_back(make_scene(l, l, 0));
    for (const std::string& l : levels_1m) scenes.push_back(make_scene(l + "_1M", l, 1000000));
    for (const bench_scene& b : scenes) std::printf("  %s: %zu triangles, %zu points\n", b.name.c_str(), b.triangles, b.points.size());

    // Per-hemicube figures (untimed), per scene and culling setting.
    std::vector<std::vector<figures>> figs(scenes.size(), std::vector<figures>(2));
    std::vector<case_spec> cases;
    for (std::size_t s = 1; s < scenes.size(); ++s)
      for (const std::string& c : culling) {
        const bool on = c == "on";
        if (!on && c != "off") throw std::runtime_error("--culling takes on and off, not " + c);
        figs[s][on ? 1 : 0] = count_figures(scenes[s], on);
        for (int t : thread_counts) cases.push_back({s, on, t, {}, {}, {}});
      }
    figs[0][1] = figs[0][0] = count_figures(scenes[0], true);  // below the threshold: the same either way

    int max_threads = 1;
    for (int t : thread_counts) max_threads = std::max(max_threads, t);
    std::vector<hemicube_rasterizer> rasterizers(static_cast<std::size_t>(max_threads), hemicube_rasterizer(scenes[0].built));
    std::vector<hemicube_buffer> buffers(static_cast<std::size_t>(max_threads));

    std::fprintf(f, "round,scene,level,target_triangles,triangles,culling,threads,hemicubes,seconds,us_per_hemicube,"
                    "room_us_per_hemicube,ratio,steal,room_steal,load1,triangles_tested,face_triangles,nodes_occluded,"
                    "triangles_occluded,seen,inside\n");
    const auto start = std::chrono::steady_clock::now();
    for (int round = 0; round < rounds; ++round) {
      const double load = bench::loadavg();
      for (case_spec& c : cases) {
        const bench_scene& b = scenes[c.scene];
        measurement room, level;
        if (round % 2 == 0) {
          room = measure(scenes[0], false, c.threads, min_time, rasterizers, buffers);
          level = measure(b, c.culling, c.threads, min_time, rasterizers, buffers);
        } else {
          level = measure(b, c.culling, c.threads, min_time, rasterizers, buffers);
          room = measure(scenes[0], false, c.threads, min_time, rasterizers, buffers);
        }
        const double ratio = level.us() / room.us();
        c.ratios.push_back(ratio);
        c.us.push_back(level.us());
        c.room_us.push_back(room.us());
        const figures& g = figs[c.scene][c.culling ? 1 : 0];
        std::fprintf(f, "%d,%s,%s,%zu,%zu,%s,%d,%zu,%.4f,%.3f,%.3f,%.4f,%.4f,%.4f,%.2f,%.1f,%.1f,%.1f,%.1f,%.1f,%.4f\n", round,
                     b.name.c_str(), b.level.c_str(), b.target, b.triangles, c.culling ? "on" : "off", c.threads, level.hemicubes,
                     level.seconds, level.us(), room.us(), ratio, level.steal, room.steal, load, g.tested, g.drawn,
                     g.nodes_occluded, g.triangles_occluded, g.seen, g.inside);
        std::fflush(f);
      }
      std::printf("round %d/%d done (%.0f s, load average %.2f)\n", round + 1, rounds, bench::seconds_since(start), load);
      std::fflush(stdout);
    }
    std::fclose(f);
    const figures& room = figs[0][0];
    std::printf("\nhexagon_room_1062: %zu triangles, %.0f tested, %.0f (triangle, face) drawn, %.0f seen per hemicube\n",
                scenes[0].triangles, room.tested, room.drawn, room.seen);
    std::printf("%-18s %9s %7s %7s %12s %12s %24s %9s %9s %9s %7s\n", "scene", "triangles", "culling", "threads", "us/hemicube",
                "room us", "ratio median [range]", "tested", "drawn", "seen", "inside");
    for (const case_spec& c : cases) {
      const bench_scene& b = scenes[c.scene];
      const figures& g = figs[c.scene][c.culling ? 1 : 0];
      const auto [lo, hi] = std::minmax_element(c.ratios.begin(), c.ratios.end());
      std::printf("%-18s %9zu %7s %7d %12.1f %12.1f %10.2fx [%.2f-%.2f] %9.0f %9.0f %9.0f %6.0f%%\n", b.name.c_str(), b.triangles,
                  c.culling ? "on" : "off", c.threads, median(c.us), median(c.room_us), median(c.ratios), *lo, *hi, g.tested,
                  g.drawn, g.seen, 100.0 * g.inside);
    }
    std::printf("done in %.0f s; load average after %.2f\n", bench::seconds_since(start), bench::loadavg());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sweep_raster_levels: %s\n", e.what());
    return 1;
  }
  return 0;
}
