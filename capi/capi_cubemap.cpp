// The cube-map part of the C ABI: validates every argument, runs the C++ functions of
// hemilight/cubemap.hpp, and copies results to the caller only when everything succeeded.
#include "capi_internal.hpp"
#include "capi_options.hpp"

#include "hemilight/cubemap.hpp"


#include <algorithm>
#include <cmath>
#include <string>

namespace {

using hemilight::capi::all_finite;
using hemilight::capi::enum_value;
using hemilight::capi::guarded;
using hemilight::capi::invalid;

bool check_cube_size(const char* fn, const char* name, int size, hemilight_status& st) {
  if (size >= 1 && size <= hemilight::cubemap_max_size) return true;
  st = invalid(fn, std::string(name) + " " + std::to_string(size) + " is outside [1, " +
                       std::to_string(hemilight::cubemap_max_size) + "]");
  return false;
}

bool check_fixup(const char* fn, int f, hemilight_status& st) {
  if (f >= 0 && f <= 2) return true;
  st = invalid(fn, "fixup " + std::to_string(f) + " is not HEMILIGHT_EDGE_FIXUP_NONE, _STRETCH or _WARP");
  return false;
}

// The arguments every filter entry point shares; false (with st set) on the first bad one.
bool check_filter_args(const char* fn, const float* input, int input_size, const float* output, int output_size,
                       int fixup, hemilight_status& st) {
  if (!input) {
    st = invalid(fn, "input is NULL");
    return false;
  }
  if (!output) {
    st = invalid(fn, "output is NULL");
    return false;
  }
  return check_cube_size(fn, "input_size", input_size, st) && check_cube_size(fn, "output_size", output_size, st) &&
         check_fixup(fn, fixup, st);
}

std::size_t face_floats(int size) { return 6u * std::size_t(size) * std::size_t(size) * 3u; }

// Copies an RGB cube map from the caller (validated: finite values within +-max_radiance, so that
// every weighted sum stays finite) into a cubemap of one level.
hemilight::cubemap load_input(const char* fn, const float* input, int size) {
  hemilight::cube_image img = hemilight::cube_image::make(size, 3);
  std::copy(input, input + img.pixels.size(), img.pixels.begin());
  for (std::size_t i = 0; i < img.pixels.size(); ++i)
    if (!(std::fabs(img.pixels[i]) <= hemilight::max_radiance))
      throw hemilight::error(hemilight::status::invalid_argument, std::string(fn) + ": input value " + std::to_string(i) + " = " +
                                                                      std::to_string(img.pixels[i]) +
                                                                      " is not finite or beyond +-1e30");
  return hemilight::cubemap::from_image(std::move(img), false);
}

int chain_levels(int size) {
  int levels = 1;
  while ((size >> levels) >= 1) ++levels;
  return levels;
}

std::size_t chain_floats(int size, int levels) {
  std::size_t total = 0;
  for (int l = 0; l < levels; ++l) total += face_floats(std::max(1, size >> l));
  return total;
}

}  // namespace

extern "C" {

hemilight_status hemilight_cubemap_texel_direction(int size, int face, int x, int y, hemilight_edge_fixup fixup,
                                                   float direction[3]) {
  const char* fn = "hemilight_cubemap_texel_direction";
  return guarded(fn, [&] {
    hemilight_status st = HEMILIGHT_OK;
    if (!direction) return invalid(fn, "direction is NULL");
    const int fixup_value = enum_value(fixup);
    if (!check_cube_size(fn, "size", size, st) || !check_fixup(fn, fixup_value, st)) return st;
    if (face < 0 || face > 5) return invalid(fn, "face " + std::to_string(face) + " is outside [0, 5]");
    if (x < 0 || x >= size || y < 0 || y >= size)
      return invalid(fn, "texel (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside a face of size " +
                             std::to_string(size));
    const glm::vec3 d =
        hemilight::cubemap_texel_direction(size, face, x, y, static_cast<hemilight::edge_fixup>(fixup_value));
    direction[0] = d.x;
    direction[1] = d.y;
    direction[2] = d.z;
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_cubemap_fixup_lookup(const float direction[3], int size, float lod,
                                                float out_direction[3]) {
  const char* fn = "hemilight_cubemap_fixup_lookup";
  return guarded(fn, [&] {
    hemilight_status st = HEMILIGHT_OK;
    if (!direction) return invalid(fn, "direction is NULL");
    if (!out_direction) return invalid(fn, "out_direction is NULL");
    if (!all_finite(direction, 3)) return invalid(fn, "direction has a NaN or infinite component");
    if (!std::isfinite(lod)) return invalid(fn, "lod is NaN or infinite");
    if (!check_cube_size(fn, "size", size, st)) return st;
    const glm::vec3 d = hemilight::fixup_lookup({direction[0], direction[1], direction[2]}, size, lod);
    out_direction[0] = d.x;
    out_direction[1] = d.y;
    out_direction[2] = d.z;
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_cubemap_filter_cosine_power(const float* input, int input_size, float specular_power,
                                                       hemilight_edge_fixup fixup, int output_size, float* output) {
  const char* fn = "hemilight_cubemap_filter_cosine_power";
  return guarded(fn, [&] {
    hemilight_status st = HEMILIGHT_OK;
    const int fixup_value = enum_value(fixup);
    if (!check_filter_args(fn, input, input_size, output, output_size, fixup_value, st)) return st;
    if (!std::isfinite(specular_power) || !(specular_power > 0.0f))
      return invalid(fn, "specular_power " + std::to_string(specular_power) + " must be finite and > 0");
    const hemilight::cubemap in = load_input(fn, input, input_size);
    hemilight::filter_options o;
    o.fixup = static_cast<hemilight::edge_fixup>(fixup_value);
    const hemilight::cube_image out = hemilight::filter_cosine_power(in, specular_power, output_size, o);
    std::copy(out.pixels.begin(), out.pixels.end(), output);
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_cubemap_filter_irradiance(const float* input, int input_size, hemilight_edge_fixup fixup,
                                                     int output_size, int use_sh, float* output) {
  const char* fn = "hemilight_cubemap_filter_irradiance";
  return guarded(fn, [&] {
    hemilight_status st = HEMILIGHT_OK;
    const int fixup_value = enum_value(fixup);
    if (!check_filter_args(fn, input, input_size, output, output_size, fixup_value, st)) return st;
    if (use_sh != 0 && use_sh != 1) return invalid(fn, "use_sh is " + std::to_string(use_sh) + "; it must be 0 or 1");
    const hemilight::cubemap in = load_input(fn, input, input_size);
    const auto mapping = static_cast<hemilight::edge_fixup>(fixup_value);
    hemilight::cube_image out;
    if (use_sh) {
      out = hemilight::irradiance_from_sh9(hemilight::project_sh9(in.levels[0]), output_size, mapping, 3);
    } else {
      hemilight::filter_options o;
      o.fixup = mapping;
      out = hemilight::filter_irradiance(in, output_size, o);
    }
    std::copy(out.pixels.begin(), out.pixels.end(), output);
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_cubemap_irradiance(const float* input, int input_size, hemilight_edge_fixup fixup,
                                              int output_size, const hemilight_cubemap_irradiance_options* options,
                                              float* output) {
  const char* fn = "hemilight_cubemap_irradiance";
  return guarded(fn, [&] {
    hemilight_status st = HEMILIGHT_OK;
    const int fixup_value = enum_value(fixup);
    if (!check_filter_args(fn, input, input_size, output, output_size, fixup_value, st)) return st;
    hemilight_cubemap_irradiance_options o = hemilight::capi::default_cubemap_irradiance_options();
    if (options) {
      const std::string problem = hemilight::capi::read_sized(options, o);
      if (!problem.empty()) return invalid(fn, problem);
    }
    const int method = enum_value(o.method);
    if (method < HEMILIGHT_IRRADIANCE_FILTER || method > HEMILIGHT_IRRADIANCE_SH25)
      return invalid(fn, "options->method is " + std::to_string(method) +
                             "; it must be HEMILIGHT_IRRADIANCE_FILTER, _SH9 or _SH25");
    if (method == HEMILIGHT_IRRADIANCE_FILTER && !check_cube_size(fn, "options->input_size", o.input_size, st)) return st;
    const hemilight::cubemap in = load_input(fn, input, input_size);
    const auto mapping = static_cast<hemilight::edge_fixup>(fixup_value);
    const hemilight::filter_options fo = hemilight::capi::to_cpp(o, mapping);
    hemilight::cube_image out;
    if (method == HEMILIGHT_IRRADIANCE_SH9) {
      out = hemilight::irradiance_from_sh9(hemilight::project_sh9(in.levels[0], fo.thread_count), output_size, mapping,
                                           3, fo.thread_count);
    } else if (method == HEMILIGHT_IRRADIANCE_SH25) {
      out = hemilight::irradiance_from_sh25(hemilight::project_sh25(in.levels[0], fo.thread_count), output_size,
                                            mapping, 3, fo.thread_count);
    } else {
      out = hemilight::filter_irradiance(in, output_size, fo);
    }
    std::copy(out.pixels.begin(), out.pixels.end(), output);
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_cubemap_chain_floats(int size, size_t* floats, int* levels) {
  const char* fn = "hemilight_cubemap_chain_floats";
  return guarded(fn, [&] {
    hemilight_status st = HEMILIGHT_OK;
    if (!check_cube_size(fn, "size", size, st)) return st;
    const int l = chain_levels(size);
    if (floats) *floats = chain_floats(size, l);
    if (levels) *levels = l;
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_cubemap_filter_mip_chain(const float* input, int input_size, hemilight_edge_fixup fixup,
                                                    int output_size, float lobe_texels, float* output,
                                                    size_t capacity) {
  const char* fn = "hemilight_cubemap_filter_mip_chain";
  return guarded(fn, [&] {
    hemilight_status st = HEMILIGHT_OK;
    const int fixup_value = enum_value(fixup);
    if (!check_filter_args(fn, input, input_size, output, output_size, fixup_value, st)) return st;
    if (!std::isfinite(lobe_texels)) return invalid(fn, "lobe_texels is NaN or infinite");
    const std::size_t need = chain_floats(output_size, chain_levels(output_size));
    if (capacity < need)
      return invalid(fn, "capacity " + std::to_string(capacity) + " floats is too small: the chain needs " +
                             std::to_string(need));
    const hemilight::cubemap in = load_input(fn, input, input_size);
    hemilight::filter_options o;
    o.fixup = static_cast<hemilight::edge_fixup>(fixup_value);
    const hemilight::cubemap out =
        hemilight::filter_mip_chain(in, output_size, o, lobe_texels > 0.0f ? lobe_texels : 1.0f);
    float* dst = output;
    for (const hemilight::cube_image& level : out.levels) dst = std::copy(level.pixels.begin(), level.pixels.end(), dst);
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_cubemap_sample(const float* chain, int size, int level_count, const float direction[3],
                                          float lod, hemilight_cube_sampling sampling, int apply_fixup,
                                          float rgb[3]) {
  const char* fn = "hemilight_cubemap_sample";
  return guarded(fn, [&] {
    hemilight_status st = HEMILIGHT_OK;
    if (!chain) return invalid(fn, "chain is NULL");
    if (!direction) return invalid(fn, "direction is NULL");
    if (!rgb) return invalid(fn, "rgb is NULL");
    if (!check_cube_size(fn, "size", size, st)) return st;
    const int max_levels = chain_levels(size);
    if (level_count < 1 || level_count > max_levels)
      return invalid(fn, "level_count " + std::to_string(level_count) + " is outside [1, " +
                             std::to_string(max_levels) + "] for size " + std::to_string(size));
    if (!all_finite(direction, 3)) return invalid(fn, "direction has a NaN or infinite component");
    if (direction[0] == 0.0f && direction[1] == 0.0f && direction[2] == 0.0f) return invalid(fn, "direction is zero");
    if (!std::isfinite(lod)) return invalid(fn, "lod is NaN or infinite");
    const int sampling_value = enum_value(sampling);
    if (sampling_value != HEMILIGHT_CUBE_SAMPLING_CLAMP_PER_FACE && sampling_value != HEMILIGHT_CUBE_SAMPLING_SEAMLESS)
      return invalid(fn, "sampling " + std::to_string(sampling_value) + " is unknown");
    if (apply_fixup != 0 && apply_fixup != 1)
      return invalid(fn, "apply_fixup is " + std::to_string(apply_fixup) + "; it must be 0 or 1");
    hemilight::cube_level_view levels[32];  // sampled in place: no copy of the chain
    const float* src = chain;
    for (int l = 0; l < level_count; ++l) {
      const int s = std::max(1, size >> l);
      levels[l] = {src, s, 3};
      src += face_floats(s);
    }
    glm::vec3 d(direction[0], direction[1], direction[2]);
    if (apply_fixup) d = hemilight::fixup_lookup(d, size, lod);
    const auto mode = sampling_value == HEMILIGHT_CUBE_SAMPLING_SEAMLESS ? hemilight::cube_sampling::seamless
                                                                   : hemilight::cube_sampling::clamp_per_face;
    const glm::vec4 v = hemilight::sample_lod(levels, level_count, d, std::max(0.0f, lod), mode);
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
      return invalid(fn, "the sample is not finite: the chain holds NaN, Inf or values near the float limit");
    rgb[0] = v.x;
    rgb[1] = v.y;
    rgb[2] = v.z;
    return HEMILIGHT_OK;
  });
}

}  // extern "C"
