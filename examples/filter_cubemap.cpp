// filter_cubemap: filters an environment cube map into a radiance mip chain (cosine-power lobes,
// gloss mapping of cubemap.hpp) and an irradiance map, and writes them as OpenEXR cube maps.
//
//   usage: filter_cubemap [input.exr | -] [output directory] [fixup] [size] [half | float]
//     input.exr         an ENVMAP_CUBE EXR (w x 6w); "-" or nothing: the procedural sky
//     output directory  default "cubemap_out" (created if missing)
//     fixup             none | stretch | warp (default stretch: sample with the lookup fixup,
//                       include/hemilight/shaders/cubemap_fixup.glsl, when filtering per face)
//     size              top-level output size (default: the input's size; 128 for the sky)
//     half | float      the files' pixels (default half: 16-bit floats, relative error <= 2^-11,
//                       values up to 65504; a 256^2 cube writes ~4x faster and is ~17x smaller,
//                       docs/cubemap.md "Writing EXR files, timed apart"); float for 32-bit
//
// Writes radiance_mip<i>.exr (level i, size >> i), irradiance.exr (cosine filter, 32^2) and
// irradiance_sh.exr (9-coefficient SH, 32^2). Errors are one line on stderr, exit code 1.
#include "hemilight/cubemap.hpp"
#include "hemilight/image_io.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  const std::string input = argc > 1 ? argv[1] : "-";
  const std::string out_dir = argc > 2 ? argv[2] : "cubemap_out";
  const std::string fixup_name = argc > 3 ? argv[3] : "stretch";
  const std::string pixels = argc > 5 ? argv[5] : "half";
  if (pixels != "half" && pixels != "float") {
    std::fprintf(stderr, "filter_cubemap: pixels '%s' must be half or float\n", pixels.c_str());
    return 1;
  }
  const hemilight::exr_pixel_type pixel_type =
      pixels == "half" ? hemilight::exr_pixel_type::half16 : hemilight::exr_pixel_type::float32;
  double write_seconds = 0.0;
  try {
    hemilight::filter_options options;
    if (fixup_name == "none") {
      options.fixup = hemilight::edge_fixup::none;
    } else if (fixup_name == "stretch") {
      options.fixup = hemilight::edge_fixup::stretch;
    } else if (fixup_name == "warp") {
      options.fixup = hemilight::edge_fixup::warp;
    } else {
      std::fprintf(stderr, "filter_cubemap: unknown fixup '%s' (use none, stretch or warp)\n", fixup_name.c_str());
      return 1;
    }
    const hemilight::cube_image top =
        input == "-" ? hemilight::procedural_environment(128) : hemilight::read_exr_cubemap(input, 3);
    int size = top.size;
    if (argc > 4) {
      char* end = nullptr;
      const long s = std::strtol(argv[4], &end, 10);
      if (*end != '\0' || s < 1 || s > hemilight::cubemap_max_size) {
        std::fprintf(stderr, "filter_cubemap: size '%s' is not an integer in [1, %d]\n", argv[4],
                     hemilight::cubemap_max_size);
        return 1;
      }
      size = static_cast<int>(s);
    }
    const hemilight::cubemap env = hemilight::cubemap::from_image(top, false);  // validates: finite values
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    if (ec) {
      std::fprintf(stderr, "filter_cubemap: cannot create '%s': %s\n", out_dir.c_str(), ec.message().c_str());
      return 1;
    }

    auto t0 = std::chrono::steady_clock::now();
    const hemilight::cubemap chain = hemilight::filter_mip_chain(env, size, options);
    std::printf("radiance chain: %d levels from %d^2 to %d^2 (%s) in %.3f s\n", chain.level_count(), size,
                chain.levels.back().size, fixup_name.c_str(), seconds_since(t0));
    for (int l = 0; l < chain.level_count(); ++l) {
      const std::string path = out_dir + "/radiance_mip" + std::to_string(l) + ".exr";
      const auto tw = std::chrono::steady_clock::now();
      hemilight::write_exr_cubemap(path, chain.levels[static_cast<std::size_t>(l)], pixel_type);
      write_seconds += seconds_since(tw);
      std::printf("  %s  size %d  specular power %.4g\n", path.c_str(), chain.levels[static_cast<std::size_t>(l)].size,
                  static_cast<double>(hemilight::gloss_power(size, l)));
    }

    t0 = std::chrono::steady_clock::now();
    const hemilight::cube_image irradiance = hemilight::filter_irradiance(env, 32, options);
    std::printf("irradiance (cosine filter, 32^2) in %.4f s\n", seconds_since(t0));
    auto tw = std::chrono::steady_clock::now();
    hemilight::write_exr_cubemap(out_dir + "/irradiance.exr", irradiance, pixel_type);
    write_seconds += seconds_since(tw);

    t0 = std::chrono::steady_clock::now();
    const hemilight::cube_image irradiance_sh =
        hemilight::irradiance_from_sh9(hemilight::project_sh9(env.levels[0]), 32, options.fixup);
    std::printf("irradiance (SH9, 32^2) in %.4f s\n", seconds_since(t0));
    tw = std::chrono::steady_clock::now();
    hemilight::write_exr_cubemap(out_dir + "/irradiance_sh.exr", irradiance_sh, pixel_type);
    write_seconds += seconds_since(tw);
    std::printf("wrote %s/ (%s pixels) in %.3f s, apart from the filters' times above\n", out_dir.c_str(), pixels.c_str(),
                write_seconds);
  } catch (const hemilight::error& e) {
    std::fprintf(stderr, "filter_cubemap: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "filter_cubemap: %s\n", e.what());
    return 1;
  }
  return 0;
}
