// hemilight/image_io.hpp — float images and cube maps, read and written as OpenEXR.
//
// Memory layout (both types): float, channels interleaved (R, G, B[, A]), rows stored one after
// another, no padding.
//   image:      pixel (x, y) at pixels[(y * width + x) * channels]; row 0 is the top row of the
//               EXR file (its first scanline, data window minimum y).
//   cube_image: six square faces in OpenGL order (+X, -X, +Y, -Y, +Z, -Z), face-major; texel
//               (x, y) of face f at pixels[((f * size + y) * size + x) * channels], where
//               x grows with the GL s coordinate and y with t (geometry.hpp, cube_coord).
//
// On disk, cube maps use OpenEXR's ENVMAP_CUBE layout (a size x 6 size image with the envmap
// attribute set to cube). The faces there have OpenEXR's own orientation; the conversion goes
// through directions (Imf::CubeMap), so a texel keeps the direction it represents.
//
// Errors: every function throws hemilight::error whose message names the file and the problem
// (status::io for a missing, unreadable, truncated or corrupt file or a failed write;
// status::unsupported for a wrong channel set, a cube map whose height is not 6x its width, or a
// tiled or deep file; status::invalid_argument for an inconsistent image passed in;
// status::out_of_memory for an image over max_image_pixels). The output is only assigned after
// the whole file has been read, so on failure the caller's object is untouched. Writes go to a
// temporary file in the same directory that is renamed over the target only when complete.
#pragma once

#include "hemilight/error.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace hemilight {

/// Largest image or cube map (in pixels, all faces together) that the readers accept: 2^28
/// (268 M pixels, 4 GiB as RGBA float). Larger headers are refused before anything is allocated.
inline constexpr std::size_t max_image_pixels = std::size_t(1) << 28;

/// A float RGB or RGBA image (layout above).
struct image {
  int width = 0;
  int height = 0;
  int channels = 0;  ///< 3 (RGB) or 4 (RGBA)
  std::vector<float> pixels;

  /// A width x height image of `channels` channels filled with `value`.
  /// Throws error(invalid_argument) for non-positive sizes or channels not 3 or 4, and
  /// error(out_of_memory) above max_image_pixels.
  static image make(int width, int height, int channels, float value = 0.0f);
  float* at(int x, int y) noexcept { return pixels.data() + (std::size_t(y) * std::size_t(width) + std::size_t(x)) * std::size_t(channels); }
  const float* at(int x, int y) const noexcept { return pixels.data() + (std::size_t(y) * std::size_t(width) + std::size_t(x)) * std::size_t(channels); }
};

/// Six float RGB or RGBA square faces in OpenGL order (layout above).
struct cube_image {
  int size = 0;      ///< texels per face edge
  int channels = 0;  ///< 3 or 4
  std::vector<float> pixels;

  /// A cube map of six size x size faces filled with `value`. Errors as image::make.
  static cube_image make(int size, int channels, float value = 0.0f);
  float* at(int face, int x, int y) noexcept { return pixels.data() + ((std::size_t(face) * std::size_t(size) + std::size_t(y)) * std::size_t(size) + std::size_t(x)) * std::size_t(channels); }
  const float* at(int face, int x, int y) const noexcept { return pixels.data() + ((std::size_t(face) * std::size_t(size) + std::size_t(y)) * std::size_t(size) + std::size_t(x)) * std::size_t(channels); }
};

/// Storage type of the channels written to an EXR file.
enum class exr_pixel_type {
  float32,  ///< 32-bit float: round-trips exactly
  half16,   ///< 16-bit half: relative error <= 2^-11, values above 65504 become +inf
};

/// What an EXR file's header says (read_exr_header).
struct exr_header_info {
  int width = 0, height = 0;
  bool cube = false;  ///< width x 6 width pixels and not marked as a latlong map
};

/// The size of an EXR image from its header alone, with read_exr's checks short of decoding the
/// pixels (channels R, G, B present and not subsampled, every scanline or tile present, at most
/// max_image_pixels). Throws as read_exr. Cost: reads the header and the offset table only; a
/// file whose pixel data is corrupt passes here and fails in read_exr.
exr_header_info read_exr_header(const std::string& path);

/// Reads a scanline EXR file as float RGB (channels = 3) or RGBA (channels = 4). The file must
/// have R, G and B channels (any pixel type); when RGBA is asked for and the file has no A, alpha
/// is 1. Other channels are ignored. channels = 0 means "as in the file": 4 if it has A, else 3.
/// Throws as described at the top of this header; the path appears in every message.
image read_exr(const std::string& path, int channels = 0);

/// Writes an image as a scanline EXR (ZIP compression) with channels R, G, B[, A].
/// Throws error(invalid_argument) if the image is inconsistent (sizes, channel count, pixel
/// count), error(io) if the file cannot be written. Existing files are replaced atomically.
void write_exr(const std::string& path, const image& img, exr_pixel_type type = exr_pixel_type::float32);

/// Reads an OpenEXR ENVMAP_CUBE file (width w, height 6 w, envmap attribute = cube) into GL face
/// order. A file without the envmap attribute is accepted when its height is exactly 6x its width.
/// Channels as read_exr. Throws error(unsupported) for an envmap of another kind (latlong) or a
/// height that is not 6x the width (both from the header, before any pixel is decoded), and as
/// read_exr otherwise.
cube_image read_exr_cubemap(const std::string& path, int channels = 0);

/// Writes a cube map as an OpenEXR ENVMAP_CUBE file. Errors as write_exr.
void write_exr_cubemap(const std::string& path, const cube_image& cube,
                       exr_pixel_type type = exr_pixel_type::float32);

}  // namespace hemilight
