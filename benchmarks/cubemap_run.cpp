// cubemap_run: one cube-map job from the command line, timed in stages (read, filter, write), for
// thread-scaling rounds and for benchmarks/cmft_compare.sh (the same job as cmft's).
//
//   cubemap_run [options]
//     --input PATH        ENVMAP_CUBE EXR to read (default: the procedural sky, --size texels)
//     --size N            procedural sky size (default 256)
//     --job J             radiance (cmft's lobes, 9 levels; the default), radiance_gloss (the gloss
//                         mapping), sh9, sh25, irradiance_filter
//     --out-size N        output size (default: the input's for radiance, 32 for irradiance)
//     --threads N         filter threads (0: all cores; default 0)
//     --output PATH       write the result (radiance: PATH with _mipK.exr per level; irradiance:
//                         PATH as one EXR); nothing is written without it
//     --half              write half floats (default: 32-bit floats)
//     --exr-threads N     OpenEXR's global thread pool for writing (default 0: none)
//     --write-dds PATH    write the input as an RGBA32F DDS cube map (the same floats, for cmft)
//                         and exit
//     --repeat R          run the filter R times, print each (default 1)
//     --errors            also print, per output level, the max and RMS relative error (over R, G,
//                         B) against filter_reference (brute force) at 300 random texels (every
//                         texel of levels with fewer): lines "error,<level>,<max>,<rms>"
//     --compare-dds PATH  instead of filtering, read PATH (an RGBA32F DDS cube map with mips, as
//                         cmft writes it) as the job's output and print its errors as --errors
//     --dds-scale S       multiply what --compare-dds reads by S (cmft's irradiance is E / pi: use
//                         3.14159265)
//     --per-level         radiance jobs: filter level by level (filter_cosine_power each) and
//                         print one line per level (level in the job column)
//
// Prints one CSV line per repeat: job,threads,size,out_size,read_s,filter_s,filter_cpu_s,write_s.
// The filter time covers the filter call alone (input already in memory); read and write are
// timed apart. filter_cpu_s is the process's CPU time (user + system) during the filter:
// filter_cpu_s / filter_s is how many cores it actually had (the scheduler shares the cores
// between process groups, so on a loaded machine a second thread may get no second core).
#include "hemilight/cubemap.hpp"
#include "hemilight/image_io.hpp"

#include <ImfThreading.h>
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace hemilight;
using clock_type = std::chrono::steady_clock;

double seconds_since(clock_type::time_point t0) {
  return std::chrono::duration<double>(clock_type::now() - t0).count();
}

double process_cpu_seconds() {
  rusage r{};
  getrusage(RUSAGE_SELF, &r);
  return static_cast<double>(r.ru_utime.tv_sec + r.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(r.ru_utime.tv_usec + r.ru_stime.tv_usec);
}

// cmft's default gloss mapping (glossScale 10, glossBias 1): p = 2^(10 (1 - l / 8) + 1).
float cmft_power(int level) { return std::exp2(10.0f * (1.0f - static_cast<float>(level) / 8.0f) + 1.0f); }

// A DDS cube map (DX10 header, DXGI_FORMAT_R32G32B32A32_FLOAT, one mip), faces +X -X +Y -Y +Z -Z
// as stored (the DDS face order is GL's, rows top to bottom as cube_image's).
void write_dds_rgba32f(const std::string& path, const cube_image& c) {
  std::ofstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot write " + path);
  const auto u32 = [&](std::uint32_t v) { f.write(reinterpret_cast<const char*>(&v), 4); };
  const std::uint32_t n = static_cast<std::uint32_t>(c.size);
  u32(0x20534444);  // "DDS "
  u32(124);
  u32(0x1 | 0x2 | 0x4 | 0x1000 | 0x8);  // caps, height, width, pixel format, pitch
  u32(n);
  u32(n);
  u32(n * 16);  // pitch
  u32(0);       // depth
  u32(1);       // mip count
  for (int i = 0; i < 11; ++i) u32(0);
  u32(32);          // pixel format size
  u32(0x4);         // DDPF_FOURCC
  u32(0x30315844);  // "DX10"
  for (int i = 0; i < 5; ++i) u32(0);
  u32(0x1000 | 0x8);  // DDSCAPS_TEXTURE | COMPLEX
  u32(0x200 | 0xfc00);  // DDSCAPS2_CUBEMAP | all faces
  u32(0);
  u32(0);
  u32(0);
  u32(2);   // DXGI_FORMAT_R32G32B32A32_FLOAT
  u32(3);   // D3D10_RESOURCE_DIMENSION_TEXTURE2D
  u32(4);   // D3D10_RESOURCE_MISC_TEXTURECUBE
  u32(1);   // array size
  u32(0);
  std::vector<float> rgba(std::size_t(6) * n * n * 4);
  for (std::size_t i = 0; i < std::size_t(6) * n * n; ++i)
    for (std::size_t k = 0; k < 4; ++k)
      rgba[i * 4 + k] = k < std::size_t(c.channels) ? c.pixels[i * std::size_t(c.channels) + k] : 1.0f;
  f.write(reinterpret_cast<const char*>(rgba.data()), static_cast<std::streamsize>(rgba.size() * sizeof(float)));
  if (!f) throw std::runtime_error("cannot write " + path);
}

// Reads an RGBA32F DDS cube map (legacy FourCC 116 or DX10 format 2), all faces and mips, into
// levels of RGB cube images (DDS stores face after face, each with its mips).
std::vector<cube_image> read_dds_rgba32f(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const auto u32 = [&](std::size_t at) {
    if (at + 4 > bytes.size()) throw std::runtime_error(path + ": not a DDS file (too short)");
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  if (u32(0) != 0x20534444) throw std::runtime_error(path + ": not a DDS file");
  const int n = static_cast<int>(u32(16));
  const int mips = std::max(1, static_cast<int>(u32(28)));
  std::size_t at = 128;
  if (u32(84) == 0x30315844) {
    if (u32(128) != 2) throw std::runtime_error(path + ": DX10 format " + std::to_string(u32(128)) + ", expected 2");
    at = 148;
  } else if (u32(84) != 116) {
    throw std::runtime_error(path + ": FourCC " + std::to_string(u32(84)) + ", expected 116 (RGBA32F)");
  }
  std::vector<cube_image> levels;
  for (int l = 0; l < mips; ++l) levels.push_back(cube_image::make(std::max(1, n >> l), 3));
  for (int face = 0; face < 6; ++face)
    for (int l = 0; l < mips; ++l) {
      cube_image& c = levels[std::size_t(l)];
      for (int y = 0; y < c.size; ++y)
        for (int x = 0; x < c.size; ++x, at += 16) {
          if (at + 16 > bytes.size()) throw std::runtime_error(path + ": cut short");
          float rgba[4];
          std::memcpy(rgba, bytes.data() + at, 16);
          float* p = c.at(face, x, y);
          for (int k = 0; k < 3; ++k) p[k] = rgba[k];
        }
    }
  return levels;
}

// Max and RMS relative error of `level` (power p; p <= 0: irradiance) against brute force.
void print_errors(const cube_image& input, const cube_image& level, int index, float power) {
  const std::size_t count = 6u * std::size_t(level.size) * std::size_t(level.size);
  std::vector<std::size_t> texels;
  std::mt19937 rng(17);
  if (count <= 300) {
    for (std::size_t i = 0; i < count; ++i) texels.push_back(i);
  } else {
    for (int k = 0; k < 300; ++k) texels.push_back(rng() % count);
  }
  const std::vector<float> ref = filter_reference(input, power, level.size, edge_fixup::none, texels);
  double worst = 0, sq = 0;
  for (std::size_t k = 0; k < texels.size(); ++k)
    for (std::size_t c = 0; c < 3; ++c) {
      const double r = ref[k * 3 + c], v = level.pixels[texels[k] * 3 + c];
      const double e = std::fabs(v - r) / std::fabs(r);
      worst = std::max(worst, e);
      sq += e * e;
    }
  std::printf("error,%d,%.6g,%.6g\n", index, worst, std::sqrt(sq / static_cast<double>(3 * texels.size())));
}

int usage() {
  std::fprintf(stderr, "usage: cubemap_run [--input PATH | --size N] [--job radiance|radiance_gloss|sh9|sh25|"
                       "irradiance_filter] [--out-size N] [--threads N] [--output PATH] [--half] "
                       "[--exr-threads N] [--write-dds PATH] [--repeat R]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) try {
  std::string input, job = "radiance", output, dds;
  int size = 256, out_size = 0, threads = 0, exr_threads = 0, repeat = 1;
  bool half = false, per_level = false, errors = false;
  std::string compare;
  double dds_scale = 1.0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--input") input = next();
    else if (a == "--size") size = std::atoi(next().c_str());
    else if (a == "--job") job = next();
    else if (a == "--out-size") out_size = std::atoi(next().c_str());
    else if (a == "--threads") threads = std::atoi(next().c_str());
    else if (a == "--output") output = next();
    else if (a == "--half") half = true;
    else if (a == "--exr-threads") exr_threads = std::atoi(next().c_str());
    else if (a == "--write-dds") dds = next();
    else if (a == "--repeat") repeat = std::atoi(next().c_str());
    else if (a == "--per-level") per_level = true;
    else if (a == "--errors") errors = true;
    else if (a == "--compare-dds") compare = next();
    else if (a == "--dds-scale") dds_scale = std::atof(next().c_str());
    else return usage();
  }
  if (repeat < 1) return usage();
  Imf::setGlobalThreadCount(exr_threads);

  clock_type::time_point t0 = clock_type::now();
  cube_image top = input.empty() ? procedural_environment(size) : read_exr_cubemap(input, 3);
  const double read_s = input.empty() ? 0.0 : seconds_since(t0);
  if (!dds.empty()) {
    write_dds_rgba32f(dds, top);
    return 0;
  }
  const cubemap in = cubemap::from_image(std::move(top), false);
  const bool radiance = job == "radiance" || job == "radiance_gloss";
  if (out_size <= 0) out_size = radiance ? in.size() : 32;
  filter_options o;
  o.thread_count = threads;
  const exr_pixel_type type = half ? exr_pixel_type::half16 : exr_pixel_type::float32;
  // the power of output level l (0: irradiance)
  const auto level_power = [&](int l) {
    if (!radiance) return 0.0f;
    return job == "radiance" ? cmft_power(l) : gloss_power(out_size, l);
  };
  if (!compare.empty()) {
    std::vector<cube_image> levels = read_dds_rgba32f(compare);
    for (cube_image& c : levels)
      for (float& v : c.pixels) v = static_cast<float>(v * dds_scale);
    for (std::size_t l = 0; l < levels.size(); ++l)
      print_errors(in.levels[0], levels[l], static_cast<int>(l), level_power(static_cast<int>(l)));
    return 0;
  }
  if (per_level && radiance) {
    for (int r = 0; r < repeat; ++r)
      for (int l = 0; l < 9 && (out_size >> l) >= 1; ++l) {
        const float p = job == "radiance" ? cmft_power(l) : gloss_power(out_size, l);
        t0 = clock_type::now();
        const double c0 = process_cpu_seconds();
        const cube_image level = filter_cosine_power(in, p, out_size >> l, o);
        const double filter_s = seconds_since(t0), cpu_s = process_cpu_seconds() - c0;
        std::printf("%s_level%d,%d,%d,%d,%.4f,%.4f,%.4f,%.4f\n", job.c_str(), l, threads, in.size(), level.size, read_s,
                    filter_s, cpu_s, 0.0);
      }
    return 0;
  }
  for (int r = 0; r < repeat; ++r) {
    cubemap result;
    t0 = clock_type::now();
    const double c0 = process_cpu_seconds();
    if (job == "radiance") {
      std::vector<float> powers;
      for (int l = 0; l < 9 && (out_size >> l) >= 1; ++l) powers.push_back(cmft_power(l));
      result = filter_mip_chain_powers(in, out_size, powers, o);
    } else if (job == "radiance_gloss") {
      result = filter_mip_chain(in, out_size, o);
    } else if (job == "sh9") {
      result.levels.push_back(irradiance_from_sh9(project_sh9(in.levels[0], threads), out_size, o.fixup, 3, threads));
    } else if (job == "sh25") {
      result.levels.push_back(irradiance_from_sh25(project_sh25(in.levels[0], threads), out_size, o.fixup, 3, threads));
    } else if (job == "irradiance_filter") {
      result.levels.push_back(filter_irradiance(in, out_size, o));
    } else {
      return usage();
    }
    const double filter_s = seconds_since(t0), cpu_s = process_cpu_seconds() - c0;
    double write_s = 0;
    if (!output.empty()) {
      t0 = clock_type::now();
      if (result.levels.size() == 1) {
        write_exr_cubemap(output, result.levels[0], type);
      } else {
        for (std::size_t l = 0; l < result.levels.size(); ++l)
          write_exr_cubemap(output + "_mip" + std::to_string(l) + ".exr", result.levels[l], type);
      }
      write_s = seconds_since(t0);
    }
    std::printf("%s,%d,%d,%d,%.4f,%.4f,%.4f,%.4f\n", job.c_str(), threads, in.size(), out_size, read_s, filter_s, cpu_s,
                write_s);
    std::fflush(stdout);
    if (errors && r == 0)
      for (int l = 0; l < result.level_count(); ++l)
        print_errors(in.levels[0], result.levels[std::size_t(l)], l, level_power(l));
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "cubemap_run: %s\n", e.what());
  return 1;
}
