// Writes the EXR seeds of fuzz/corpus/exr: one small file per compression OpenEXR writes (NONE,
// RLE, ZIPS, ZIP, PIZ, PXR24, B44, B44A, DWAA, DWAB), half RGB scanline images of 64 x 32 with a
// smooth gradient and a few sharp texels (so that every compressor has something to do), plus a
// float RGB one for PXR24 (its 24-bit float path), a tiled ZIP image with mip levels and a ZIP
// cube map (16 x 96, envmap = cube). Not part of the build (fuzz/README.md says how to run it):
//   g++ -std=c++17 fuzz/make_exr_seeds.cpp $(pkg-config --cflags --libs OpenEXR) -o make_exr_seeds
//   ./make_exr_seeds fuzz/corpus/exr
#include <ImfChannelList.h>
#include <ImfStandardAttributes.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfTiledOutputFile.h>

#include <half.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

// The value of channel c (0..2) at (x, y): a gradient, with a few bright texels.
float value(int x, int y, int c) {
  const float v = 0.3f + 0.2f * std::sin(0.11f * float(x) + 0.7f * float(c)) * std::cos(0.13f * float(y));
  return ((x * 7 + y * 3 + c) % 97 == 0) ? 40.0f * v + 1.0f : v;
}

template <class T>
void write_scanline(const std::string& path, int w, int h, Imf::Compression compression, Imf::PixelType type,
                    bool cube = false) {
  Imf::Header header(w, h);
  header.compression() = compression;
  if (cube) Imf::addEnvmap(header, Imf::ENVMAP_CUBE);
  const char* names[3] = {"R", "G", "B"};
  std::vector<T> planes[3];
  Imf::FrameBuffer fb;
  for (int c = 0; c < 3; ++c) {
    header.channels().insert(names[c], Imf::Channel(type));
    planes[c].resize(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) planes[c][std::size_t(y) * std::size_t(w) + std::size_t(x)] = T(value(x, y, c));
    fb.insert(names[c], Imf::Slice(type, reinterpret_cast<char*>(planes[c].data()), sizeof(T), sizeof(T) * std::size_t(w)));
  }
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(fb);
  file.writePixels(h);
}

void write_tiled_mips(const std::string& path) {
  const int w = 16, h = 12;
  Imf::Header header(w, h);
  header.compression() = Imf::ZIP_COMPRESSION;
  header.setTileDescription(Imf::TileDescription(8, 8, Imf::MIPMAP_LEVELS, Imf::ROUND_DOWN));
  const char* names[3] = {"R", "G", "B"};
  for (const char* n : names) header.channels().insert(n, Imf::Channel(Imf::HALF));
  Imf::TiledOutputFile file(path.c_str(), header);
  for (int level = 0; level < file.numLevels(); ++level) {
    const int lw = file.levelWidth(level), lh = file.levelHeight(level);
    std::vector<half> planes[3];
    Imf::FrameBuffer fb;
    for (int c = 0; c < 3; ++c) {
      planes[c].resize(std::size_t(lw) * std::size_t(lh));
      for (int y = 0; y < lh; ++y)
        for (int x = 0; x < lw; ++x) planes[c][std::size_t(y) * std::size_t(lw) + std::size_t(x)] = half(value(x, y, c));
      fb.insert(names[c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(planes[c].data()), sizeof(half),
                                     sizeof(half) * std::size_t(lw)));
    }
    file.setFrameBuffer(fb);
    file.writeTiles(0, file.numXTiles(level) - 1, 0, file.numYTiles(level) - 1, level);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_DIRECTORY\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  const struct {
    const char* name;
    Imf::Compression compression;
  } kinds[] = {{"none", Imf::NO_COMPRESSION},       {"rle", Imf::RLE_COMPRESSION},   {"zips", Imf::ZIPS_COMPRESSION},
               {"zip", Imf::ZIP_COMPRESSION},       {"piz", Imf::PIZ_COMPRESSION},   {"pxr24", Imf::PXR24_COMPRESSION},
               {"b44", Imf::B44_COMPRESSION},       {"b44a", Imf::B44A_COMPRESSION}, {"dwaa", Imf::DWAA_COMPRESSION},
               {"dwab", Imf::DWAB_COMPRESSION}};
  for (const auto& k : kinds) write_scanline<half>(dir + "/seed_" + k.name + "_half.exr", 64, 32, k.compression, Imf::HALF);
  write_scanline<float>(dir + "/seed_pxr24_float.exr", 64, 32, Imf::PXR24_COMPRESSION, Imf::FLOAT);
  write_tiled_mips(dir + "/seed_zip_tiled_mips.exr");
  write_scanline<half>(dir + "/seed_zip_cube.exr", 16, 96, Imf::ZIP_COMPRESSION, Imf::HALF, true);
  return 0;
}
