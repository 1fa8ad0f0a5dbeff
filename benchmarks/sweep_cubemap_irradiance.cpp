// Irradiance from a cube map: error against a brute-force cosine integral, against time.
//
//   sweep_cubemap_irradiance <out.csv> [input_size] [output_size]
//
// The procedural sky (input_size^2, default 256, with its sun) to an output_size^2 irradiance map
// (default 32) by:
//   sh9                 project_sh9 + irradiance_from_sh9 (bands 0-2)
//   sh25                project_sh25 + irradiance_from_sh25 (bands 0-4, what cmft computes)
//   filter_N            filter_irradiance reading the N^2 mip (irradiance_input_size = N)
// against filter_reference(power 0): every input texel, exact solid angles, double, at every
// output texel. Errors are relative, per channel, over all 6 output_size^2 texels (max and RMS).
// Time: the median of 7 runs of the whole job (projection or filter, input already in memory),
// 1 thread and 2 threads, wall and process CPU time.
#include "hemilight/cubemap.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

namespace {

using namespace hemilight;

double process_cpu_seconds() {
  rusage r{};
  getrusage(RUSAGE_SELF, &r);
  return static_cast<double>(r.ru_utime.tv_sec + r.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(r.ru_utime.tv_usec + r.ru_stime.tv_usec);
}

struct timing {
  double wall = 0, cpu = 0;
};

timing median_time(const std::function<cube_image()>& job) {
  std::vector<double> wall, cpu;
  for (int i = 0; i < 7; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = process_cpu_seconds();
    const cube_image e = job();
    wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    cpu.push_back(process_cpu_seconds() - c0);
    if (e.pixels.empty()) std::abort();
  }
  std::sort(wall.begin(), wall.end());
  std::sort(cpu.begin(), cpu.end());
  return {wall[3], cpu[3]};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: sweep_cubemap_irradiance <out.csv> [input_size] [output_size]\n");
    return 2;
  }
  const int in_size = argc > 2 ? std::atoi(argv[2]) : 256, out_size = argc > 3 ? std::atoi(argv[3]) : 32;
  const cubemap in = cubemap::from_image(procedural_environment(in_size), false);
  const std::vector<float> ref = filter_reference(in.levels[0], 0.0f, out_size, edge_fixup::none, {});
  struct method {
    std::string name;
    std::function<cube_image(int threads)> run;
  };
  std::vector<method> methods = {
      {"sh9", [&](int t) { return irradiance_from_sh9(project_sh9(in.levels[0], t), out_size, edge_fixup::none, 3, t); }},
      {"sh25",
       [&](int t) { return irradiance_from_sh25(project_sh25(in.levels[0], t), out_size, edge_fixup::none, 3, t); }},
  };
  for (int n = 4; n <= std::min(in_size, 128); n *= 2)
    methods.push_back({"filter_" + std::to_string(n), [&, n](int t) {
                         filter_options o;
                         o.thread_count = t;
                         o.irradiance_input_size = n;
                         return filter_irradiance(in, out_size, o);
                       }});
  std::FILE* f = std::fopen(argv[1], "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", argv[1]);
    return 1;
  }
  std::fprintf(f, "method,input_size,output_size,max_rel_error,rms_rel_error,wall_1t_s,cpu_1t_s,wall_2t_s,cpu_2t_s\n");
  for (const method& m : methods) {
    const cube_image e = m.run(0);
    double worst = 0, sq = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) {
      const double r = std::fabs(static_cast<double>(e.pixels[i]) / ref[i] - 1.0);
      worst = std::max(worst, r);
      sq += r * r;
    }
    const double rms = std::sqrt(sq / static_cast<double>(ref.size()));
    const timing t1 = median_time([&] { return m.run(1); }), t2 = median_time([&] { return m.run(2); });
    std::fprintf(f, "%s,%d,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", m.name.c_str(), in_size, out_size, worst, rms, t1.wall,
                 t1.cpu, t2.wall, t2.cpu);
    std::printf("%-10s max %.4f%% rms %.4f%%  1t %.2f ms (cpu %.2f)  2t %.2f ms (cpu %.2f)\n", m.name.c_str(),
                100 * worst, 100 * rms, 1e3 * t1.wall, 1e3 * t1.cpu, 1e3 * t2.wall, 1e3 * t2.cpu);
    std::fflush(stdout);
  }
  std::fclose(f);
  return 0;
}
