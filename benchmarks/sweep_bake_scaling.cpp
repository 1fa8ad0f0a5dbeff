// Scaling study of the lightmap baker: how bake wall time and peak memory grow with the triangle
// count, the lightmap size and the thread count.
//   usage: sweep_bake_scaling out.csv [--quick]
//          sweep_bake_scaling --one SCENE T SIZE THREADS   (internal: one bake, one CSV row on stdout)
// The full run takes about 4 minutes on two cores and peaks at about 3.5 GiB (the 4096^2 bake);
// --quick runs the reduced set below.
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
// Sweeps (CSV: study, scene, triangles, size, threads, seconds, coverage_seconds, sampled_texels,
// hemicubes, records, peak_mib, scene_mib; seconds = bake_stats::seconds, the whole bake's wall
// time; triangles = the heightfield's actual 2 k^2):
//   triangles: T = 10^3, 10^4, 10^5, 10^6 at 512^2, 2 threads   (--quick: up to 10^5)
//   size:      T = 10^4 at 256^2, 512^2, 1024^2, 2048^2, 4096^2, 2 threads   (--quick: up to 1024^2)
//   threads:   T = 10^4 at 1024^2, 1 and 2 threads
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
// Measured figures and the chart: docs/bake.md, "Scaling with triangles, lightmap size and threads".
#include "hemilight/bake.hpp"
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

// The scene of a configuration with its lightmap UVs: "heightfield" (planar UVs) or
// "many_boxes" ((T - 2) / 10 boxes, chart UVs for a size x size map). Throws for another name.
scene_mesh build_scene(const std::string& name, std::size_t triangles, int size) {
  if (name == "heightfield") {
    scene_mesh m = heightfield(triangles);
    planar_heightfield_uvs(m);
    return m;
  }
  if (name == "many_boxes") {
    scene_mesh m = many_boxes(std::max<std::size_t>(1, triangles > 2 ? (triangles - 2) / 10 : 1));
    generate_lightmap_uvs(m, size, 2);
    return m;
  }
  throw_invalid_argument("unknown scene '" + name + "' (heightfield, many_boxes)");
}

// --one mode: builds the scene, bakes it once and prints one CSV row (everything but the study
// column) on stdout. Returns the process exit code.
int bake_one(const std::string& scene_name, std::size_t triangles, int size, int threads) {
  const scene_mesh m = build_scene(scene_name, triangles, size);
  const double scene_mib = peak_rss_mib();
  bake_input in;
  in.scene = m.desc();
  bake_options o;
  o.width = o.height = size;
  o.sampler.resolution = 64;
  o.bounces = 1;
  o.thread_count = threads;
  const bake_result r = bake_lightmap(in, o);
  const double peak_mib = peak_rss_mib();
  const bake_stats& s = r.stats;
  std::printf("%s,%zu,%d,%d,%.4f,%.4f,%zu,%zu,%zu,%.1f,%.1f\n", scene_name.c_str(), m.triangle_count(), size, threads,
              s.seconds, s.coverage_seconds, s.sampled_texels, s.hemicubes, s.records, peak_mib, scene_mib);
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

// The configurations of the full sweep, or of the reduced --quick one (top of the file).
std::vector<config> sweep_configs(bool quick) {
  std::vector<config> c;
  for (std::size_t t : {std::size_t{1000}, std::size_t{10000}, std::size_t{100000}, std::size_t{1000000}})
    if (!quick || t <= 100000) c.push_back({"triangles", "heightfield", t, 512, 2});
  for (int size : {256, 512, 1024, 2048, 4096})
    if (!quick || size <= 1024) c.push_back({"size", "heightfield", 10000, size, 2});
  for (int threads : {1, 2}) c.push_back({"threads", "heightfield", 10000, 1024, threads});
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
int sweep(const std::string& self, const char* path, bool quick) {
  std::FILE* f = std::fopen(path, "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", path);
    return 1;
  }
  std::fprintf(f, "study,scene,triangles,size,threads,seconds,coverage_seconds,sampled_texels,hemicubes,records,peak_mib,"
                  "scene_mib\n");
  const std::vector<config> configs = sweep_configs(quick);
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
    const bool quick = argc == 3 && std::string(argv[2]) == "--quick";
    if ((argc != 2 && !quick) || argv[1][0] == '-') {
      std::fprintf(stderr, "usage: sweep_bake_scaling out.csv [--quick]\n");
      return 2;
    }
    return sweep(self_path(argv[0]), argv[1], quick);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sweep_bake_scaling: %s\n", e.what());
    return 1;
  }
}
