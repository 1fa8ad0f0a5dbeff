// The C ABI: validates every argument, calls the C++ library, and turns exceptions into
// hemilight_status + a thread-local message. Nothing is written to an output before the whole
// result is known, so a failing call leaves the caller's memory untouched.
#include "capi_internal.hpp"

#include "hemilight/error.hpp"
#include "hemilight/geometry.hpp"
#include "hemilight/image_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <string>

namespace {

using hemilight::capi::check_resolution;
using hemilight::capi::guarded;
using hemilight::capi::invalid;

thread_local std::string last_error_message;

bool check_size(const char* function, const char* name, int value, hemilight_status& status) {
  if (value > 0) return true;
  status = invalid(function, std::string(name) + " is " + std::to_string(value) + "; it must be positive");
  return false;
}

}  // namespace

namespace hemilight::capi {

hemilight_status set_error(hemilight_status code, std::string message) {
  last_error_message = std::move(message);
  return code;
}

hemilight_status invalid(const char* function, const std::string& what) {
  return set_error(HEMILIGHT_ERROR_INVALID_ARGUMENT, std::string(function) + ": " + what);
}

}  // namespace hemilight::capi

extern "C" {

const char* hemilight_last_error(void) { return last_error_message.c_str(); }

void hemilight_version(int* major, int* minor, int* patch) {
  if (major) *major = hemilight::version_major;
  if (minor) *minor = hemilight::version_minor;
  if (patch) *patch = hemilight::version_patch;
}

hemilight_status hemilight_hemicube_texel_count(int resolution, size_t* count) {
  const char* fn = "hemilight_hemicube_texel_count";
  return guarded(fn, [&] {
    if (!count) return invalid(fn, "count is NULL");
    if (const hemilight_status st = check_resolution(fn, resolution)) return st;
    *count = hemilight::hemicube_texel_count(resolution);
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_hemicube_texel_info(int resolution, size_t texel, float direction[3], float* solid_angle,
                                               float* projected_solid_angle) {
  const char* fn = "hemilight_hemicube_texel_info";
  return guarded(fn, [&] {
    if (const hemilight_status st = check_resolution(fn, resolution)) return st;
    const std::size_t count = hemilight::hemicube_texel_count(resolution);
    if (texel >= count)
      return invalid(fn, "texel " + std::to_string(texel) + " is out of range: resolution " +
                             std::to_string(resolution) + " has " + std::to_string(count) + " texels");
    const auto table = hemilight::hemicube_table::get(resolution);
    const glm::vec3 d = hemilight::hemicube_texel_direction(resolution, texel);
    if (direction) {
      direction[0] = d.x;
      direction[1] = d.y;
      direction[2] = d.z;
    }
    if (solid_angle) *solid_angle = table->solid_angle()[texel];
    if (projected_solid_angle) *projected_solid_angle = table->projected_solid_angle()[texel];
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_exr_info(const char* path, int* width, int* height, int* is_cubemap) {
  const char* fn = "hemilight_exr_info";
  return guarded(fn, [&] {
    if (!path) return invalid(fn, "path is NULL");
    // The header alone (read_exr's checks but the pixels' decoding): crafted headers claiming huge
    // images fail before anything is allocated.
    const hemilight::exr_header_info info = hemilight::read_exr_header(path);
    if (width) *width = info.width;
    if (height) *height = info.height;
    if (is_cubemap) *is_cubemap = static_cast<long long>(info.height) == 6LL * info.width ? 1 : 0;
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_exr_load_rgb(const char* path, float* rgb, size_t capacity, int* width, int* height) {
  const char* fn = "hemilight_exr_load_rgb";
  return guarded(fn, [&] {
    if (!path) return invalid(fn, "path is NULL");
    if (!rgb) return invalid(fn, "rgb is NULL");
    const auto too_small = [&](int w, int h) {
      return invalid(fn, "capacity " + std::to_string(capacity) + " floats is too small for '" + path + "' (" +
                             std::to_string(w) + " x " + std::to_string(h) + " x 3 = " +
                             std::to_string(3 * std::size_t(w) * std::size_t(h)) + " floats)");
    };
    // The size from the header before any pixel is decoded: a short capacity is refused without
    // decoding the image into a temporary (a 377-byte RLE file can claim 16.5M x 2 pixels).
    const hemilight::exr_header_info info = hemilight::read_exr_header(path);
    if (3 * std::size_t(info.width) * std::size_t(info.height) > capacity) return too_small(info.width, info.height);
    const hemilight::image img = hemilight::read_exr(path, 3);
    if (img.pixels.size() > capacity) return too_small(img.width, img.height);  // the file changed since its header was read
    std::copy(img.pixels.begin(), img.pixels.end(), rgb);
    if (width) *width = img.width;
    if (height) *height = img.height;
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_exr_save_rgb(const char* path, const float* rgb, int width, int height, int half_float) {
  const char* fn = "hemilight_exr_save_rgb";
  return guarded(fn, [&] {
    hemilight_status st = HEMILIGHT_OK;
    if (!path) return invalid(fn, "path is NULL");
    if (!rgb) return invalid(fn, "rgb is NULL");
    if (!check_size(fn, "width", width, st) || !check_size(fn, "height", height, st)) return st;
    if (std::size_t(width) * std::size_t(height) > hemilight::max_image_pixels)
      return invalid(fn, "width x height = " + std::to_string(width) + " x " + std::to_string(height) +
                             " is over the limit of 2^28 pixels");
    hemilight::image img = hemilight::image::make(width, height, 3);
    std::copy(rgb, rgb + img.pixels.size(), img.pixels.begin());
    hemilight::write_exr(path, img, half_float ? hemilight::exr_pixel_type::half16 : hemilight::exr_pixel_type::float32);
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_exr_load_cubemap_rgb(const char* path, float* faces, size_t capacity, int* size) {
  const char* fn = "hemilight_exr_load_cubemap_rgb";
  return guarded(fn, [&] {
    if (!path) return invalid(fn, "path is NULL");
    if (!faces) return invalid(fn, "faces is NULL");
    const auto too_small = [&](int s) {
      return invalid(fn, "capacity " + std::to_string(capacity) + " floats is too small for '" + path + "' (6 x " +
                             std::to_string(s) + " x " + std::to_string(s) + " x 3 = " +
                             std::to_string(18 * std::size_t(s) * std::size_t(s)) + " floats)");
    };
    // The size from the header before any pixel is decoded (as hemilight_exr_load_rgb); a file
    // that is no cube map fails in read_exr_cubemap, from its header too.
    const hemilight::exr_header_info info = hemilight::read_exr_header(path);
    if (info.cube && 18 * std::size_t(info.width) * std::size_t(info.width) > capacity) return too_small(info.width);
    const hemilight::cube_image cube = hemilight::read_exr_cubemap(path, 3);
    if (cube.pixels.size() > capacity) return too_small(cube.size);  // the file changed since its header was read
    std::copy(cube.pixels.begin(), cube.pixels.end(), faces);
    if (size) *size = cube.size;
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_exr_save_cubemap_rgb(const char* path, const float* faces, int size, int half_float) {
  const char* fn = "hemilight_exr_save_cubemap_rgb";
  return guarded(fn, [&] {
    hemilight_status st = HEMILIGHT_OK;
    if (!path) return invalid(fn, "path is NULL");
    if (!faces) return invalid(fn, "faces is NULL");
    if (!check_size(fn, "size", size, st)) return st;
    if (size > hemilight::cubemap_max_size)
      return invalid(fn, "size " + std::to_string(size) + " is over the limit of " + std::to_string(hemilight::cubemap_max_size) +
                             " (six faces of at most 2^28 pixels in all)");
    hemilight::cube_image cube = hemilight::cube_image::make(size, 3);
    std::copy(faces, faces + cube.pixels.size(), cube.pixels.begin());
    hemilight::write_exr_cubemap(path, cube,
                                 half_float ? hemilight::exr_pixel_type::half16 : hemilight::exr_pixel_type::float32);
    return HEMILIGHT_OK;
  });
}

}  // extern "C"
