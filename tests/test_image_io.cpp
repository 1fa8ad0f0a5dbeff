// Tests of image_io.hpp. Every bad file is written by the test itself.
#include "hemilight/geometry.hpp"
#include "hemilight/image_io.hpp"

#include "test_support.hpp"

#include <ImfChannelList.h>
#include <ImfEnvmap.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

using namespace hemilight;
using hemilight::test::require_error;
using hemilight::test::tmp_path;
namespace fs = std::filesystem;

namespace {

image random_image(int w, int h, int c, unsigned seed) {
  image img = image::make(w, h, c);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-10.0f, 1000.0f);
  for (float& v : img.pixels) v = u(rng);
  return img;
}

std::vector<char> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_bytes(const std::string& path, const std::vector<char>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace

TEST_CASE("exr: float RGB and RGBA round-trip exactly", "[image_io]") {
  for (int c : {3, 4}) {
    const image img = random_image(37, 23, c, 1u + unsigned(c));
    const std::string path = tmp_path("roundtrip_" + std::to_string(c) + ".exr");
    write_exr(path, img);
    const image back = read_exr(path);
    REQUIRE(back.width == 37);
    REQUIRE(back.height == 23);
    REQUIRE(back.channels == c);
    REQUIRE(back.pixels == img.pixels);  // bitwise: float32 storage is lossless
  }
}

TEST_CASE("exr: half round-trip within half precision", "[image_io]") {
  const image img = random_image(16, 9, 3, 5);
  const std::string path = tmp_path("half.exr");
  write_exr(path, img, exr_pixel_type::half16);
  const image back = read_exr(path, 3);
  REQUIRE(back.pixels.size() == img.pixels.size());
  for (std::size_t i = 0; i < img.pixels.size(); ++i) {
    // half has an 11-bit significand: round-to-nearest gives relative error <= 2^-11; values
    // below the normal range (|v| < 6.1e-5) get an absolute error <= 2^-25.
    REQUIRE(std::fabs(back.pixels[i] - img.pixels[i]) <= std::fabs(img.pixels[i]) * 0x1p-11f + 0x1p-25f);
  }
}

TEST_CASE("exr: row 0 is the first scanline (top of the image)", "[image_io]") {
  image img = image::make(2, 3, 3, 0.0f);
  img.at(1, 0)[0] = 7.0f;  // row 0, column 1
  const std::string path = tmp_path("order.exr");
  write_exr(path, img);
  // Read with OpenEXR directly: the data window starts at y = 0 = first scanline.
  Imf::InputFile file(path.c_str());
  std::vector<float> r(6, -1.0f);
  Imf::FrameBuffer fb;
  fb.insert("R", Imf::Slice::Make(Imf::FLOAT, r.data(), file.header().dataWindow(), sizeof(float), 2 * sizeof(float)));
  file.setFrameBuffer(fb);
  file.readPixels(0, 2);
  CHECK(r[1] == 7.0f);
  CHECK(r[0] == 0.0f);
}

TEST_CASE("exr: an RGB file read as RGBA gets alpha 1, RGBA read as RGB drops alpha", "[image_io]") {
  const image rgb = random_image(4, 4, 3, 9);
  write_exr(tmp_path("rgb.exr"), rgb);
  const image rgba = read_exr(tmp_path("rgb.exr"), 4);
  REQUIRE(rgba.channels == 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      CHECK(rgba.at(x, y)[3] == 1.0f);
      CHECK(rgba.at(x, y)[1] == rgb.at(x, y)[1]);
    }
  write_exr(tmp_path("rgba.exr"), rgba);
  CHECK(read_exr(tmp_path("rgba.exr"), 3).pixels == rgb.pixels);
}

TEST_CASE("exr: a missing file names the file", "[image_io]") {
  require_error([] { read_exr(tmp_path("does_not_exist.exr")); }, status::io, "does_not_exist.exr': no such file");
  require_error([] { read_exr(tmp_path("")); }, status::io, "directory");
}

TEST_CASE("exr: a truncated file is an I/O error, and the caller's image is untouched", "[image_io]") {
  const std::string path = tmp_path("truncated.exr");
  write_exr(path, random_image(64, 64, 3, 2));
  std::vector<char> bytes = read_bytes(path);
  for (std::size_t keep : {bytes.size() / 2, bytes.size() - 10, std::size_t(12), std::size_t(3)}) {
    write_bytes(path, std::vector<char>(bytes.begin(), bytes.begin() + std::ptrdiff_t(keep)));
    image mine = image::make(2, 2, 3, 42.0f);
    const image before = mine;
    INFO("kept " << keep << " bytes");
    require_error([&] { mine = read_exr(path); }, status::io, "truncated.exr");
    CHECK(mine.pixels == before.pixels);
  }
}

TEST_CASE("exr: corrupted bytes are an I/O error, never a crash", "[image_io]") {
  const std::string path = tmp_path("corrupt.exr");
  write_exr(path, random_image(32, 32, 3, 4));
  const std::vector<char> good = read_bytes(path);
  // Not an EXR at all.
  write_bytes(path, std::vector<char>(good.size(), 'x'));
  require_error([&] { read_exr(path); }, status::io, "not a readable EXR file");
  // Valid header, garbage in the scanline data: either an I/O error or (ZIP permitting) some
  // image; what must not happen is a crash or a sanitizer report. Several positions, fixed seed.
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<char> bad = good;
    std::uniform_int_distribution<std::size_t> pos(good.size() / 3, good.size() - 1);
    for (int k = 0; k < 16; ++k) bad[pos(rng)] = static_cast<char>(rng());
    write_bytes(path, bad);
    try {
      const image img = read_exr(path);
      CHECK(img.pixels.size() == 32u * 32u * 3u);
    } catch (const error& e) {
      CHECK(e.code() == status::io);
      CHECK(std::string(e.what()).find("corrupt.exr") != std::string::npos);
    }
  }
}

TEST_CASE("exr: a file without R, G, B names the missing channel", "[image_io]") {
  const std::string path = tmp_path("luminance.exr");
  {
    Imf::Header header(4, 4);
    header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
    std::vector<float> y(16, 1.0f);
    Imf::FrameBuffer fb;
    fb.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(y.data()), sizeof(float), 4 * sizeof(float)));
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(4);
  }
  require_error([&] { read_exr(path); }, status::unsupported, "missing channel 'R' (file has Y)");
}

TEST_CASE("exr: bad arguments to the writers and readers", "[image_io]") {
  image img = image::make(4, 4, 3);
  img.pixels.pop_back();
  require_error([&] { write_exr(tmp_path("x.exr"), img); }, status::invalid_argument, "width x height x channels");
  require_error([&] { read_exr(tmp_path("rgb.exr"), 2); }, status::invalid_argument, "channels is 2");
  require_error([] { image::make(0, 4, 3); }, status::invalid_argument, "positive");
  require_error([] { image::make(1 << 20, 1 << 20, 3); }, status::out_of_memory, "exceeds the limit");
  require_error([] { cube_image::make(-1, 3); }, status::invalid_argument, "positive");
  require_error([&] { write_exr(tmp_path("no/such/dir/x.exr"), image::make(2, 2, 3)); }, status::io, "cannot write");
}

TEST_CASE("exr: a failed write leaves the existing file as it was", "[image_io]") {
  const std::string path = tmp_path("keep.exr");
  const image original = random_image(8, 8, 3, 21);
  write_exr(path, original);
  image broken = image::make(8, 8, 3);
  broken.channels = 5;
  CHECK_THROWS_AS(write_exr(path, broken), error);
  CHECK(read_exr(path).pixels == original.pixels);
  CHECK_FALSE(fs::exists(path + ".hemilight-partial"));
}

TEST_CASE("exr cube maps: round-trip and height check", "[image_io]") {
  for (int size : {1, 2, 5, 16}) {
    cube_image cube = cube_image::make(size, 3);
    std::mt19937 rng{static_cast<unsigned>(size)};
    std::uniform_real_distribution<float> u(0.0f, 5.0f);
    for (float& v : cube.pixels) v = u(rng);
    const std::string path = tmp_path("cube" + std::to_string(size) + ".exr");
    write_exr_cubemap(path, cube);
    const cube_image back = read_exr_cubemap(path);
    REQUIRE(back.size == size);
    REQUIRE(back.pixels == cube.pixels);
  }
  write_exr(tmp_path("not_cube.exr"), image::make(4, 20, 3));
  require_error([] { read_exr_cubemap(tmp_path("not_cube.exr")); }, status::unsupported, "must be w x 6w pixels; this file is 4 x 20");
}

TEST_CASE("exr cube maps: every texel lands where OpenEXR says its direction is", "[image_io]") {
  // Reference: OpenEXR's own Imf::CubeMap::direction for each pixel of the written file. Each
  // GL texel stores its own centre direction; in the file, pixel (i, j) must hold a direction
  // within one texel of what OpenEXR assigns to it (OpenEXR puts edge pixel centres on the cube
  // edges, GL half a texel inside, so they differ by up to half a texel; a wrong face,
  // flip or transpose would be off by the face size).
  for (int size : {4, 9}) {
    cube_image cube = cube_image::make(size, 3);
    for (int f = 0; f < 6; ++f)
      for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
          const glm::vec3 d = glm::normalize(
              cube_direction_from_face(static_cast<cube_face>(f), (float(x) + 0.5f) / float(size), (float(y) + 0.5f) / float(size)));
          float* p = cube.at(f, x, y);
          p[0] = d.x;
          p[1] = d.y;
          p[2] = d.z;
        }
    const std::string path = tmp_path("cube_dirs.exr");
    write_exr_cubemap(path, cube);
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    REQUIRE(Imf::CubeMap::sizeOfFace(dw) == size);
    std::vector<float> rgb(std::size_t(size) * std::size_t(6 * size) * 3);
    Imf::FrameBuffer fb;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c)
      fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, rgb.data() + c, dw, 3 * sizeof(float), std::size_t(size) * 3 * sizeof(float)));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    const float texel_angle = 2.0f / float(size);  // > one texel's angular size anywhere on a face
    for (int f = 0; f < 6; ++f)
      for (int j = 0; j < size; ++j)
        for (int i = 0; i < size; ++i) {
          const auto face = static_cast<Imf::CubeMapFace>(f);
          const Imath::V2f pif{static_cast<float>(i), static_cast<float>(j)};
          const Imath::V3f e = Imf::CubeMap::direction(face, dw, pif).normalized();
          const Imath::V2f pos = Imf::CubeMap::pixelPosition(face, dw, pif);
          const float* p = rgb.data() + (std::size_t(pos.y) * std::size_t(size) + std::size_t(pos.x)) * 3;
          const float cosang = p[0] * e.x + p[1] * e.y + p[2] * e.z;
          INFO("face " << f << " pixel " << i << "," << j);
          REQUIRE(std::acos(std::min(1.0f, cosang)) < texel_angle);
        }
  }
}
