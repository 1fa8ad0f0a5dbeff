// Scaling study of the lightmap baker: how bake wall time and peak memory grow with the triangle
// count, the lightmap size and the thread count, on a heightfield and on the stand-in levels.
//   usage: sweep_bake_scaling out.csv [--quick] [--studies a,b,...] [--append] [--level-size S]
//          sweep_bake_scaling --one SCENE T SIZE THREADS   (internal: one bake, one CSV row on stdout)
// The heightfield studies (triangles, size, threads) take about 4 minutes on two cores and peak at
// about 3.5 GiB (the 4096^2 bake); the level studies (closed, open) 40-60 minutes (the 1M-triangle
// levels take most of it; each bake's time is printed as it ends). --quick runs the reduced set
// below (about 3 minutes). --studies runs only the named studies (triangles, size, threads,
// closed, open); --append adds the rows to an existing CSV instead of starting it again (e.g. the
// level studies alone after the heightfield ones); --level-size S bakes the levels at S^2
// instead of 512^2 (256^2 with --quick).
//
// Every configuration is baked in a child process (the program re-executes itself in --one mode
// with fork + exec and reads the row through a pipe), because peak memory is read from VmHWM in
// /proc/self/status, which is per process and never goes down. The child builds the scene, reads
// VmHWM (scene_mib: the process's baseline plus the mesh and its UVs), bakes once, reads VmHWM
// again (peak_mib) and prints its row; the parent prefixes the study and writes the CSV.
//
// Scene: heightfield(T) (reference_scenes.hpp), a bumpy ground of 2 k^2 triangles over
// [-5, 5]^2 m under a uniform sky, with ONE planar-projection UV set, u = (x + 5) / 10,
// v = (z + 5) / 10 (valid: the heightfield has no overlaps in x, z). Not generate_lightmap_uvs:
// no two neighbouring triangles of the bumpy surface are coplanar, so it makes every triangle a
// chart of its own with 2 texels of padding; at 512^2 that leaves a few texels per triangle at
// T = 10^4 and does not pack at all beyond ~6.5 x 10^4 charts (every chart needs at least 2 x 2
// texels of padding), so the texel workload would change with T and the triangle sweep would not
// run. With the planar set every texel of the map is covered, so sampled_texels = size^2 for every
// T and the triangle sweep changes only the geometry. (--one many_boxes T SIZE THREADS bakes
// many_boxes((T - 2) / 10) with generate_lightmap_uvs instead, for comparisons by hand.)
// Bake: N = 64, one bounce, the default cache (a = 0.2, automatic radii), one run per configuration.
//
// Levels (levels.hpp, docs/levels.md; --one arena|keep|city_block|terrain_town T SIZE THREADS):
// make_level(NAME) with target_triangles = T (closed levels accept 10^4 to 4 x 10^6, open ones
// 5 x 10^4 up), its sky and its sun (bake_options::lights), degenerate triangles included, baked
// at a FIXED LIGHTMAP SIZE (512^2 unless --level-size) whatever T: the level's UVs as make_level
// packs them for its default lightmap (1024^2 up to 75,000 triangles, 2048^2 up to 300,000, 4096^2
// above), read at SIZE^2. So, as for the heightfield, the texel workload stays about the same
// (sampled texels within a few tens of percent) and the triangle sweep changes the geometry;
// above 75,000 triangles charts share texels (overlapping_texels): a texel's sample lies on one
// of them (bake.hpp). A fixed texel density instead would grow the texels with T (a 1M-triangle
// level needs 4096^2 at the default density: hours per bake on two cores).
//
// Sweeps (CSV: study, scene, triangles, size, threads, seconds, coverage_seconds, sampled_texels,
// hemicubes, records, peak_mib, scene_mib, render_seconds, direct_seconds, invalid_texels,
// overlapping_texels, target, packing; seconds = bake_stats::seconds, the whole bake's wall time;
// render_seconds = the cache's rendering and integrating of hemicubes, summed over the passes;
// triangles = the scene's actual count (the heightfield's 2 k^2); target = the T asked for;
// packing = the lightmap size the level's UVs were packed for, 0 for the heightfield):
//   triangles: heightfield, T = 10^3, 10^4, 10^5, 10^6 at 512^2, 2 threads   (--quick: up to 10^5)
//   size:      heightfield, T = 10^4 at 256^2, 512^2, 1024^2, 2048^2, 4096^2, 2 threads   (--quick: up to 1024^2)
//   threads:   heightfield, T = 10^4 at 1024^2, 1 and 2 threads
//   closed:    arena and keep, T = 10^4, 3 x 10^4, 10^5, 3 x 10^5, 10^6 at 512^2, 2 threads
//              (--quick: arena, 10^4 and 3 x 10^4, at 256^2)
//   open:      city_block and terrain_town, T = 5 x 10^4, 10^5, 3 x 10^5, 10^6 at 512^2, 2 threads
//              (--quick: city_block, 5 x 10^4, at 256^2)
//
// Expected orders (what the study checks):
//   time ~ hemicubes x (cost per hemicube) / threads, plus O(texels) for coverage, sample
//     set-up, interpolation and dilation. Hemicubes grow with the sampled texels for a given a
//     (the automatic min_radius is the median point spacing / a, so finer maps get smaller records
//     where the irradiance changes), sublinearly where it is smooth.
//   cost per hemicube ~ log T for the BVH culling (nodes visited) plus the set-up of every
//     triangle that survives culling: on the heightfield every triangle above the horizon of a
//     texel is visible from it, so the per-visible-triangle term can grow up to ~T.
//   threads: ~1/p on the hemicube part (parallel_for), the serial parts of placement stay.
//   memory ~ O(texels) (the per-texel arrays of the samples, the cache points and the outputs;
//     bake.hpp says about 100 bytes per texel) + O(T) (the mesh here, and the scene the bake
//     builds: about 140 bytes per triangle, scene.hpp).
//   levels: time ~ hemicubes x cost per hemicube / threads as above. With occlusion culling
//     (raster.hpp; on for scenes of >= 8192 triangles) a hemicube should draw what is visible
//     from its point, not what is in view: in a closed level that grows with the detail of the
//     rooms around the point (the tessellation of curved parts grows as T^(1/3): levels.hpp), not
//     with the rooms behind the walls, so the cost per hemicube should grow as log T (traversal)
//     plus the visible detail, far below T. Open levels see further (streets, the terrain to the
//     horizon): between that and the heightfield's growth. Memory O(T) (the level's mesh, make_level's
//     peak of 150-200 bytes per triangle, and the scene) + O(texels).
// Measured figures and the chart: docs/bake.md, "Scaling with triangles, lightmap size and threads".
#include "hemilight/bake.hpp"
#include "hemilight/levels.hpp"
#include "hemilight/reference_scenes.hpp"

#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

// Peak resident set size of this process so far (VmHWM of /proc/self/status) in MiB; -1 if it
// cannot be read.
double peak_rss_mib() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.compare(0, 6, "VmHWM:") == 0) return std::strtod(line.c_str() + 6, nullptr) / 1024.0;  // kB
  return -1.0;
}

// The three load averages of /proc/loadavg (the machine may be shared).
std::string load_average() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

// Gives a heightfield (which covers x, z in [-5, 5] without overlaps) the planar-projection
// lightmap UVs u = (x + 5) / 10, v = (z + 5) / 10, clamped to [0, 1] against rounding.
void planar_heightfield_uvs(scene_mesh& m) {
  m.lightmap_uvs.resize(m.positions.size());
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const glm::vec3& p = m.positions[i];
    m.lightmap_uvs[i] = glm::clamp(glm::vec2((p.x + 5.0f) / 10.0f, (p.z + 5.0f) / 10.0f), 0.0f, 1.0f);
  }
}

// Whether `name` is a stand-in level (levels.hpp).
bool is_level(const std::string& name) {
  const std::vector<std::string> names = level_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

// The scene of a configuration with its lightmap UVs and lights: "heightfield" (planar UVs),
// "many_boxes" ((T - 2) / 10 boxes, chart UVs for a size x size map) or a level (its own UVs,
// packed for its default lightmap size, and its sun). Throws for another name.
struct built_scene {
  scene_mesh mesh;
  std::vector<light> lights;
  int packing = 0;  // lightmap size the UVs were packed for (levels), else 0
};

built_scene build_scene(const std::string& name, std::size_t triangles, int size) {
  built_scene b;
  if (name == "heightfield") {
    b.mesh = heightfield(triangles);
    planar_heightfield_uvs(b.mesh);
    return b;
  }
  if (name == "many_boxes") {
    b.mesh = many_boxes(std::max<std::size_t>(1, triangles > 2 ? (triangles - 2) / 10 : 1));
    generate_lightmap_uvs(b.mesh, size, 2);
    return b;
  }
  if (is_level(name)) {
    level_options o;
    o.target_triangles = triangles;
    level l = make_level(name, o);
    b.mesh = std::move(l.mesh);
    b.lights = std::move(l.lights);
    b.packing = l.lightmap_size;
    return b;
  }
  throw_invalid_argument("unknown scene '" + name + "' (heightfield, many_boxes, arena, keep, city_block, terrain_town)");
}

// --one mode: builds the scene, bakes it once and prints one CSV row (everything but the study
// column) on stdout. Returns the process exit code.
int bake_one(const std::string& scene_name, std::size_t triangles, int size, int threads) {
  const built_scene b = build_scene(scene_name, triangles, size);
  const scene_mesh& m = b.mesh;
  const double scene_mib = peak_rss_mib();
  bake_input in;
  in.scene = m.desc();
  bake_options o;
  o.width = o.height = size;
  o.sampler.resolution = 64;
  o.bounces = 1;
  o.thread_count = threads;
  o.lights = b.lights;
  const bake_result r = bake_lightmap(in, o);
  const double peak_mib = peak_rss_mib();
  const bake_stats& s = r.stats;
  double render_seconds = 0.0;
  for (const cache_stats& p : s.passes) render_seconds += p.render_seconds;
  std::printf("%s,%zu,%d,%d,%.4f,%.4f,%zu,%zu,%zu,%.1f,%.1f,%.4f,%.4f,%zu,%zu,%zu,%d\n", scene_name.c_str(), m.triangle_count(), size,
              threads, s.seconds, s.coverage_seconds, s.sampled_texels, s.hemicubes, s.records, peak_mib, scene_mib, render_seconds,
              s.direct_seconds, s.invalid_texels, s.overlapping_texels, triangles, b.packing);
  return 0;
}

// One configuration of a sweep.
struct config {
  const char* study;
  const char* scene;
  std::size_t triangles;
  int size, threads;
};

// Runs `self --one ...` for `c` in a child process (fork + exec, stdout through a pipe; stderr is
// inherited) and returns the last line it printed, or an empty string if it failed.
std::string run_child(const std::string& self, const config& c) {
  const std::string t = std::to_string(c.triangles), size = std::to_string(c.size), threads = std::to_string(c.threads);
  std::vector<std::string> args = {self, "--one", c.scene, t, size, threads};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  int fd[2];
  if (pipe(fd) != 0) {
    std::fprintf(stderr, "pipe: %s\n", std::strerror(errno));
    return {};
  }
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = fork();
  if (pid < 0) {
    std::fprintf(stderr, "fork: %s\n", std::strerror(errno));
    close(fd[0]);
    close(fd[1]);
    return {};
  }
  if (pid == 0) {  // child: stdout into the pipe, then become `self --one ...`
    close(fd[0]);
    if (dup2(fd[1], STDOUT_FILENO) < 0) _exit(127);
    close(fd[1]);
    execv(self.c_str(), argv.data());
    std::fprintf(stderr, "exec %s: %s\n", self.c_str(), std::strerror(errno));
    _exit(127);
  }
  close(fd[1]);
  std::string out;
  char buf[4096];
  for (;;) {
    const ssize_t n = read(fd[0], buf, sizeof buf);
    if (n > 0)
      out.append(buf, static_cast<std::size_t>(n));
    else if (n == 0 || errno != EINTR)
      break;
  }
  close(fd[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    if (WIFSIGNALED(status))
      std::fprintf(stderr, "child killed by signal %d\n", WTERMSIG(status));
    else
      std::fprintf(stderr, "child exited with status %d\n", WEXITSTATUS(status));
    return {};
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  const std::size_t nl = out.rfind('\n');
  return nl == std::string::npos ? out : out.substr(nl + 1);
}

// The studies, in the order they run.
const std::vector<std::string> all_studies = {"triangles", "size", "threads", "closed", "open"};

// The configurations of the full sweep, or of the reduced --quick one (top of the file), of the
// named studies; the levels at level_size^2.
std::vector<config> sweep_configs(bool quick, const std::vector<std::string>& studies, int level_size) {
  const auto wanted = [&](const char* s) { return std::find(studies.begin(), studies.end(), s) != studies.end(); };
  std::vector<config> c;
  if (wanted("triangles"))
    for (std::size_t t : {std::size_t{1000}, std::size_t{10000}, std::size_t{100000}, std::size_t{1000000}})
      if (!quick || t <= 100000) c.push_back({"triangles", "heightfield", t, 512, 2});
  if (wanted("size"))
    for (int size : {256, 512, 1024, 2048, 4096})
      if (!quick || size <= 1024) c.push_back({"size", "heightfield", 10000, size, 2});
  if (wanted("threads"))
    for (int threads : {1, 2}) c.push_back({"threads", "heightfield", 10000, 1024, threads});
  if (wanted("closed"))
    for (const char* level : {"arena", "keep"})
      for (std::size_t t : {std::size_t{10000}, std::size_t{30000}, std::size_t{100000}, std::size_t{300000}, std::size_t{1000000}})
        if (!quick || (std::string(level) == "arena" && t <= 30000)) c.push_back({"closed", level, t, level_size, 2});
  if (wanted("open"))
    for (const char* level : {"city_block", "terrain_town"})
      for (std::size_t t : {std::size_t{50000}, std::size_t{100000}, std::size_t{300000}, std::size_t{1000000}})
        if (!quick || (std::string(level) == "city_block" && t <= 50000)) c.push_back({"open", level, t, level_size, 2});
  return c;
}

// The path this executable can be re-executed by: /proc/self/exe, else argv[0].
std::string self_path(const char* argv0) {
  std::vector<char> buf(4096);
  const ssize_t n = readlink("/proc/self/exe", buf.data(), buf.size() - 1);
  if (n > 0) return std::string(buf.data(), static_cast<std::size_t>(n));
  return argv0;
}

// Sweep mode: runs every configuration in a child and writes the CSV. Returns the exit code
// (1 if the CSV cannot be written or any configuration failed).
int sweep(const std::string& self, const char* path, bool quick, const std::vector<std::string>& studies, bool append,
          int level_size) {
  std::FILE* existing = append ? std::fopen(path, "r") : nullptr;
  if (existing) std::fclose(existing);
  std::FILE* f = std::fopen(path, existing ? "a" : "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", path);
    return 1;
  }
  if (!existing)
    std::fprintf(f, "study,scene,triangles,size,threads,seconds,coverage_seconds,sampled_texels,hemicubes,records,peak_mib,"
                    "scene_mib,render_seconds,direct_seconds,invalid_texels,overlapping_texels,target,packing\n");
  const std::vector<config> configs = sweep_configs(quick, studies, level_size);
  std::printf("sweep_bake_scaling%s: %zu bakes; load average before: %s\n", quick ? " --quick" : "", configs.size(),
              load_average().c_str());
  const auto start = std::chrono::steady_clock::now();
  int failed = 0;
  for (std::size_t i = 0; i < configs.size(); ++i) {
    const config& c = configs[i];
    std::printf("[%zu/%zu] %s: %s T = %zu, %d^2, %d thread(s) ...\n", i + 1, configs.size(), c.study, c.scene, c.triangles,
                c.size, c.threads);
    const auto t0 = std::chrono::steady_clock::now();
    const std::string row = run_child(self, c);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (row.empty()) {
      std::printf("    FAILED (%.1f s)\n", wall);
      ++failed;
      continue;
    }
    std::fprintf(f, "%s,%s\n", c.study, row.c_str());
    std::fflush(f);
    std::printf("    %s  (child %.1f s in all)\n", row.c_str(), wall);
  }
  std::fclose(f);
  std::printf("done in %.1f s, %d failed; load average after: %s\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), failed, load_average().c_str());
  return failed ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc == 6 && std::string(argv[1]) == "--one") {
      const long long t = std::atoll(argv[3]);
      const int size = std::atoi(argv[4]), threads = std::atoi(argv[5]);
      if (t <= 0 || size <= 0 || threads < 0) {
        std::fprintf(stderr, "--one: bad T %s, size %s or threads %s\n", argv[3], argv[4], argv[5]);
        return 2;
      }
      return bake_one(argv[2], static_cast<std::size_t>(t), size, threads);
    }
    bool quick = false, append = false, bad = argc < 2 || argv[1][0] == '-';
    std::vector<std::string> studies = all_studies;
    int level_size = 0;  // 0: 512, or 256 with --quick
    for (int i = 2; i < argc && !bad; ++i) {
      const std::string a = argv[i];
      if (a == "--quick") {
        quick = true;
      } else if (a == "--append") {
        append = true;
      } else if (a == "--studies" && i + 1 < argc) {
        studies.clear();
        std::string list = argv[++i];
        for (std::size_t b = 0; b <= list.size();) {
          const std::size_t e = std::min(list.find(',', b), list.size());
          if (e > b) studies.push_back(list.substr(b, e - b));
          b = e + 1;
        }
        for (const std::string& st : studies)
          if (std::find(all_studies.begin(), all_studies.end(), st) == all_studies.end()) bad = true;
      } else if (a == "--level-size" && i + 1 < argc) {
        level_size = std::atoi(argv[++i]);
        if (level_size < 1 || level_size > max_lightmap_size) bad = true;
      } else {
        bad = true;
      }
    }
    if (bad) {
      std::fprintf(stderr,
                   "usage: sweep_bake_scaling out.csv [--quick] [--studies triangles,size,threads,closed,open] [--append] "
                   "[--level-size S]\n");
      return 2;
    }
    if (level_size == 0) level_size = quick ? 256 : 512;
    return sweep(self_path(argv[0]), argv[1], quick, studies, append, level_size);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sweep_bake_scaling: %s\n", e.what());
    return 1;
  }
}
