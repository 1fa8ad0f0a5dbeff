// OpenEXR reading and writing for hemilight::image and hemilight::cube_image.
#include "hemilight/image_io.hpp"

#include "hemilight/geometry.hpp"

#include <ImfChannelList.h>
#include <ImfEnvmap.h>
#include <ImfEnvmapAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfMultiPartInputFile.h>
#include <ImfOutputFile.h>
#include <ImfPartType.h>
#include <ImfStandardAttributes.h>
#include <Imath/half.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <system_error>

namespace hemilight {

namespace {

[[noreturn]] void fail(status code, const char* function, const std::string& path, const std::string& problem) {
  throw error(code, std::string(function) + ": '" + path + "': " + problem);
}

std::size_t checked_pixel_count(long long width, long long height, long long layers, const char* what) {
  if (width <= 0 || height <= 0) throw_invalid_argument(std::string(what) + ": size must be positive");
  const long long limit = static_cast<long long>(max_image_pixels);
  if (width > limit || height > limit || layers > limit || width * height > limit / layers)
    throw error(status::out_of_memory, std::string(what) + ": " + std::to_string(width) + " x " +
                                           std::to_string(height) + (layers > 1 ? " x 6" : "") +
                                           " pixels exceeds the limit of 2^28 pixels");
  return static_cast<std::size_t>(width * height * layers);
}

void check_channels_arg(int channels, const char* function, bool allow_zero) {
  if (!(channels == 3 || channels == 4 || (allow_zero && channels == 0)))
    throw_invalid_argument(std::string(function) + ": channels is " + std::to_string(channels) +
                           (allow_zero ? "; it must be 0 (as in the file), 3 or 4" : "; it must be 3 or 4"));
}

// Reads the whole data window of a file as float RGB(A). Throws with the file name on any failure.
struct raw_read {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;
  bool has_envmap = false;
  Imf::Envmap envmap = Imf::ENVMAP_LATLONG;
};

// Walks the header(s) of an EXR file before OpenEXR parses them: every attribute's size must fit
// in what is left of the file, so that a crafted size field fails here instead of making the
// parser allocate it (a 599-byte file claiming a 1.6 GB attribute). Layout: magic, version, then
// per part attributes (name\0 type\0 int32 size, value) ended by an empty name; multi-part files
// end their list of headers with an empty header.
void check_header_sizes(const std::string& path, const char* function) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(status::io, function, path, "cannot be opened");
  in.seekg(0, std::ios::end);
  const long long file_size = static_cast<long long>(in.tellg());
  in.seekg(0, std::ios::beg);
  unsigned char head[8];
  if (!in.read(reinterpret_cast<char*>(head), 8)) fail(status::io, function, path, "not a readable EXR file (shorter than its header)");
  if (!(head[0] == 0x76 && head[1] == 0x2f && head[2] == 0x31 && head[3] == 0x01)) return;  // OpenEXR names the problem
  const bool multipart = (head[5] & 0x10) != 0;  // version flag 0x1000
  const auto read_string = [&](std::string& s) {
    s.clear();
    for (int i = 0; i < 256; ++i) {
      const int c = in.get();
      if (c == EOF) fail(status::io, function, path, "not a readable EXR file (its header is cut short)");
      if (c == 0) return;
      s.push_back(static_cast<char>(c));
    }
    fail(status::io, function, path, "not a readable EXR file (a header name is longer than 255 bytes)");
  };
  for (int part = 0;; ++part) {
    std::string name, type;
    int attributes = 0;
    for (;; ++attributes) {
      read_string(name);
      if (name.empty()) break;
      read_string(type);
      unsigned char b[4];
      if (!in.read(reinterpret_cast<char*>(b), 4)) fail(status::io, function, path, "not a readable EXR file (its header is cut short)");
      const long long size = static_cast<long long>(static_cast<std::int32_t>(std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 |
                                                                              std::uint32_t(b[2]) << 16 | std::uint32_t(b[3]) << 24));
      const long long left = file_size - static_cast<long long>(in.tellg());
      if (size < 0 || size > left)
        fail(status::io, function, path,
             "not a readable EXR file (header attribute '" + name + "' claims " + std::to_string(size) + " bytes; " +
                 std::to_string(left) + " are left in the file)");
      in.seekg(size, std::ios::cur);
    }
    if (!multipart || attributes == 0) return;
    if (in.peek() == 0) return;  // the empty header that ends a multi-part list
  }
}

// cube: the image must be a cube map (w x 6w, no latlong envmap attribute), checked from the
// header before any pixel is decoded.
raw_read read_raw(const std::string& path, int channels, const char* function, bool pixels = true, bool cube = false) {
  check_channels_arg(channels, function, true);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(status::io, function, path, "no such file");
  if (std::filesystem::is_directory(path, ec)) fail(status::io, function, path, "is a directory, not an EXR file");
  check_header_sizes(path, function);
  try {
    // The header and the offset table through MultiPartInputFile, which allocates no line buffers:
    // InputFile's decompressors take up to 2.5 scanlines up front (248 MB of address space for a
    // 377-byte RLE file claiming 16,514,819 x 2 pixels). InputFile is opened to decode, once every
    // check passed, and for deep data (which it flattens) as before.
    Imf::MultiPartInputFile parts(path.c_str());
    const Imf::Header& header = parts.header(0);
    std::unique_ptr<Imf::InputFile> file;
    if (header.hasType() && Imf::isDeepData(header.type())) file = std::make_unique<Imf::InputFile>(path.c_str());
    const Imath::Box2i dw = header.dataWindow();
    const long long w = static_cast<long long>(dw.max.x) - dw.min.x + 1;
    const long long h = static_cast<long long>(dw.max.y) - dw.min.y + 1;
    if (w <= 0 || h <= 0) fail(status::io, function, path, "empty or inverted data window");
    const Imf::ChannelList& list = header.channels();
    std::string present;
    for (auto it = list.begin(); it != list.end(); ++it) present += (present.empty() ? "" : ", ") + std::string(it.name());
    for (const char* name : {"R", "G", "B"})
      if (!list.findChannel(name))
        fail(status::unsupported, function, path,
             std::string("missing channel '") + name + "' (file has " + (present.empty() ? "no channels" : present) +
                 "); hemilight reads R, G, B and optionally A");
    for (const char* name : {"R", "G", "B", "A"}) {
      const Imf::Channel* c = list.findChannel(name);
      if (c && (c->xSampling != 1 || c->ySampling != 1))
        fail(status::unsupported, function, path, std::string("channel '") + name + "' is subsampled");
    }
    const bool file_alpha = list.findChannel("A") != nullptr;
    raw_read out;
    out.channels = channels == 0 ? (file_alpha ? 4 : 3) : channels;
    out.width = static_cast<int>(w);
    out.height = static_cast<int>(h);
    const std::size_t count = checked_pixel_count(w, h, 1, function);
    // Before anything is allocated: a header claiming a huge image in a short file stops here.
    if (!(file ? file->isComplete() : parts.partComplete(0)))
      fail(status::io, function, path, "file is truncated (not all scanlines are present)");
    if (Imf::hasEnvmap(header)) {
      out.has_envmap = true;
      out.envmap = Imf::envmap(header);
    }
    if (cube && out.has_envmap && out.envmap != Imf::ENVMAP_CUBE)
      fail(status::unsupported, function, path, "envmap attribute is latlong, not cube");
    if (cube && h != 6 * w)
      fail(status::unsupported, function, path,
           "a cube map must be w x 6w pixels; this file is " + std::to_string(w) + " x " + std::to_string(h));
    if (!pixels) return out;
    if (!file) file = std::make_unique<Imf::InputFile>(path.c_str());
    if (file->header().dataWindow() != dw) fail(status::io, function, path, "the file changed while it was read");
    out.pixels.assign(count * static_cast<std::size_t>(out.channels), 0.0f);
    Imf::FrameBuffer fb;
    const std::size_t xs = sizeof(float) * static_cast<std::size_t>(out.channels);
    const std::size_t ys = xs * static_cast<std::size_t>(w);
    const char* names[4] = {"R", "G", "B", "A"};
    for (int c = 0; c < out.channels; ++c)
      fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, out.pixels.data() + c, dw, xs, ys, 1, 1, c == 3 ? 1.0 : 0.0));
    file->setFrameBuffer(fb);
    file->readPixels(dw.min.y, dw.max.y);
    return out;
  } catch (const error&) {
    throw;
  } catch (const std::bad_alloc&) {
    fail(status::out_of_memory, function, path, "out of memory while reading");
  } catch (const std::exception& e) {
    fail(status::io, function, path, std::string("not a readable EXR file (") + e.what() + ")");
  }
}

// Writes header + framebuffer to a temporary file and renames it over `path` when complete.
void write_raw(const std::string& path, int width, int height, int channels, const float* pixels, exr_pixel_type type,
               bool cube, const char* function) {
  const std::string tmp = path + ".hemilight-partial";
  try {
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    if (cube) Imf::addEnvmap(header, Imf::ENVMAP_CUBE);
    const Imf::PixelType pt = type == exr_pixel_type::half16 ? Imf::HALF : Imf::FLOAT;
    const char* names[4] = {"R", "G", "B", "A"};
    for (int c = 0; c < channels; ++c) header.channels().insert(names[c], Imf::Channel(pt));
    Imf::FrameBuffer fb;
    const Imath::Box2i dw(Imath::V2i(0, 0), Imath::V2i(width - 1, height - 1));
    const std::size_t values = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
                               static_cast<std::size_t>(channels);
    std::vector<Imath::half> halves;  // OpenEXR does not convert float slices to half channels
    if (pt == Imf::HALF) {
      halves.resize(values);
      for (std::size_t i = 0; i < values; ++i) halves[i] = Imath::half(pixels[i]);
    }
    const std::size_t elem = pt == Imf::HALF ? sizeof(Imath::half) : sizeof(float);
    const std::size_t xs = elem * static_cast<std::size_t>(channels);
    const std::size_t ys = xs * static_cast<std::size_t>(width);
    for (int c = 0; c < channels; ++c) {
      const void* base = pt == Imf::HALF ? static_cast<const void*>(halves.data() + c) : static_cast<const void*>(pixels + c);
      fb.insert(names[c], Imf::Slice::Make(pt, base, dw, xs, ys));
    }
    {
      Imf::OutputFile file(tmp.c_str(), header);
      file.setFrameBuffer(fb);
      file.writePixels(height);
    }
    std::filesystem::rename(tmp, path);
  } catch (const std::exception& e) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    fail(status::io, function, path, std::string("cannot write (") + e.what() + ")");
  }
}

void check_image(const image& img, const char* function) {
  check_channels_arg(img.channels, function, false);
  const std::size_t count = checked_pixel_count(img.width, img.height, 1, function);
  if (img.pixels.size() != count * static_cast<std::size_t>(img.channels))
    throw_invalid_argument(std::string(function) + ": image has " + std::to_string(img.pixels.size()) +
                           " floats; width x height x channels is " +
                           std::to_string(count * static_cast<std::size_t>(img.channels)));
}

void check_cube(const cube_image& cube, const char* function) {
  check_channels_arg(cube.channels, function, false);
  const std::size_t count = checked_pixel_count(cube.size, cube.size, 6, function);
  if (cube.pixels.size() != count * static_cast<std::size_t>(cube.channels))
    throw_invalid_argument(std::string(function) + ": cube map has " + std::to_string(cube.pixels.size()) +
                           " floats; 6 x size x size x channels is " +
                           std::to_string(count * static_cast<std::size_t>(cube.channels)));
}

// (s, t) of direction d on a given GL face (no major-axis choice): the GL table for that face.
glm::vec2 coords_on_face(cube_face face, const glm::vec3& d) {
  switch (face) {
    case cube_face::pos_x: return {0.5f * (-d.z / d.x + 1.0f), 0.5f * (-d.y / d.x + 1.0f)};
    case cube_face::neg_x: return {0.5f * (d.z / -d.x + 1.0f), 0.5f * (-d.y / -d.x + 1.0f)};
    case cube_face::pos_y: return {0.5f * (d.x / d.y + 1.0f), 0.5f * (d.z / d.y + 1.0f)};
    case cube_face::neg_y: return {0.5f * (d.x / -d.y + 1.0f), 0.5f * (-d.z / -d.y + 1.0f)};
    case cube_face::pos_z: return {0.5f * (d.x / d.z + 1.0f), 0.5f * (-d.y / d.z + 1.0f)};
    case cube_face::neg_z: return {0.5f * (-d.x / -d.z + 1.0f), 0.5f * (-d.y / -d.z + 1.0f)};
  }
  return {0.5f, 0.5f};
}

// Calls f(exr_x, exr_y, gl_face, gl_x, gl_y) for every texel of a size x 6 size ENVMAP_CUBE
// image. OpenEXR places pixel centres 0..size-1 at face coordinates -1..1 and orients each face
// its own way; GL's face coordinates are linear in the texel index too, so each face is a
// flip/transpose, found here through the directions OpenEXR assigns (Imf::CubeMap::direction).
template <class F>
void for_each_cube_texel(int size, F&& f) {
  const Imath::Box2i dw(Imath::V2i(0, 0), Imath::V2i(size - 1, 6 * size - 1));
  const float last = static_cast<float>(size - 1);
  for (int ef = 0; ef < 6; ++ef) {
    const auto exr_face = static_cast<Imf::CubeMapFace>(ef);
    const Imath::V3f centre = Imf::CubeMap::direction(exr_face, dw, Imath::V2f(0.5f * last, 0.5f * last));
    const cube_face gl_face = cube_face_from_direction({centre.x, centre.y, centre.z}).face;
    for (int j = 0; j < size; ++j)
      for (int i = 0; i < size; ++i) {
        const Imath::V2f pif(static_cast<float>(i), static_cast<float>(j));
        const Imath::V3f d = Imf::CubeMap::direction(exr_face, dw, pif);
        const Imath::V2f pos = Imf::CubeMap::pixelPosition(exr_face, dw, pif);
        const glm::vec2 st = coords_on_face(gl_face, {d.x, d.y, d.z});
        const int gx = static_cast<int>(std::lround(st.x * last));
        const int gy = static_cast<int>(std::lround(st.y * last));
        f(static_cast<int>(std::lround(pos.x)), static_cast<int>(std::lround(pos.y)), static_cast<int>(gl_face), gx, gy);
      }
  }
}

}  // namespace

image image::make(int width, int height, int channels, float value) {
  check_channels_arg(channels, "image::make", false);
  const std::size_t count = checked_pixel_count(width, height, 1, "image::make");
  image img;
  img.width = width;
  img.height = height;
  img.channels = channels;
  img.pixels.assign(count * static_cast<std::size_t>(channels), value);
  return img;
}

cube_image cube_image::make(int size, int channels, float value) {
  check_channels_arg(channels, "cube_image::make", false);
  const std::size_t count = checked_pixel_count(size, size, 6, "cube_image::make");
  cube_image cube;
  cube.size = size;
  cube.channels = channels;
  cube.pixels.assign(count * static_cast<std::size_t>(channels), value);
  return cube;
}

exr_header_info read_exr_header(const std::string& path) {
  const raw_read raw = read_raw(path, 0, "read_exr_header", false);
  exr_header_info info;
  info.width = raw.width;
  info.height = raw.height;
  info.cube = static_cast<long long>(raw.height) == 6LL * raw.width && (!raw.has_envmap || raw.envmap == Imf::ENVMAP_CUBE);
  return info;
}

image read_exr(const std::string& path, int channels) {
  raw_read raw = read_raw(path, channels, "read_exr");
  image img;
  img.width = raw.width;
  img.height = raw.height;
  img.channels = raw.channels;
  img.pixels = std::move(raw.pixels);
  return img;
}

void write_exr(const std::string& path, const image& img, exr_pixel_type type) {
  check_image(img, "write_exr");
  write_raw(path, img.width, img.height, img.channels, img.pixels.data(), type, false, "write_exr");
}

cube_image read_exr_cubemap(const std::string& path, int channels) {
  // The shape is checked from the header (read_raw's cube): a file that is no cube map fails
  // before its pixels are decoded.
  raw_read raw = read_raw(path, channels, "read_exr_cubemap", true, true);
  cube_image cube;
  cube.size = raw.width;
  cube.channels = raw.channels;
  cube.pixels.assign(raw.pixels.size(), 0.0f);
  const std::size_t nc = static_cast<std::size_t>(raw.channels);
  for_each_cube_texel(cube.size, [&](int ex, int ey, int face, int gx, int gy) {
    const float* src = raw.pixels.data() + (std::size_t(ey) * std::size_t(raw.width) + std::size_t(ex)) * nc;
    std::copy(src, src + nc, cube.at(face, gx, gy));
  });
  return cube;
}

void write_exr_cubemap(const std::string& path, const cube_image& cube, exr_pixel_type type) {
  check_cube(cube, "write_exr_cubemap");
  const std::size_t nc = static_cast<std::size_t>(cube.channels);
  std::vector<float> flat(cube.pixels.size());
  for_each_cube_texel(cube.size, [&](int ex, int ey, int face, int gx, int gy) {
    const float* src = cube.at(face, gx, gy);
    std::copy(src, src + nc, flat.data() + (std::size_t(ey) * std::size_t(cube.size) + std::size_t(ex)) * nc);
  });
  write_raw(path, cube.size, 6 * cube.size, cube.channels, flat.data(), type, true, "write_exr_cubemap");
}

}  // namespace hemilight
