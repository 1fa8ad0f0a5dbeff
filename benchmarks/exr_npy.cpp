// Converts an EXR file to a NumPy .npy array (float32, shape (height, width, 3), rows in the
// file's scanline order: row 0 = the first scanline), so that Python scripts without an EXR module
// can read lightmaps (benchmarks/cycles_compare.py reads Cycles' and hemilight's bakes through it).
//   usage: exr_npy IN.exr OUT.npy
// Reads through hemilight's read_exr (image_io.hpp): any pixel type, R, G, B channels.
#include "hemilight/image_io.hpp"

#include <cstdio>
#include <exception>
#include <string>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: exr_npy IN.exr OUT.npy\n");
    return 2;
  }
  try {
    const hemilight::image img = hemilight::read_exr(argv[1], 3);
    std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + std::to_string(img.height) + ", " +
                         std::to_string(img.width) + ", 3), }";
    // NPY 1.0: magic, version, a little-endian uint16 header length; header padded with spaces
    // and ended by '\n' so that magic + length + header is a multiple of 64 bytes.
    const std::size_t unpadded = 10 + header.size() + 1;
    header.append((64 - unpadded % 64) % 64, ' ');
    header += '\n';
    std::FILE* f = std::fopen(argv[2], "wb");
    if (!f) {
      std::fprintf(stderr, "exr_npy: cannot write %s\n", argv[2]);
      return 1;
    }
    const unsigned char magic[8] = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0};
    const unsigned char len[2] = {static_cast<unsigned char>(header.size() & 0xff), static_cast<unsigned char>(header.size() >> 8)};
    bool ok = std::fwrite(magic, 1, 8, f) == 8 && std::fwrite(len, 1, 2, f) == 2 &&
              std::fwrite(header.data(), 1, header.size(), f) == header.size() &&
              std::fwrite(img.pixels.data(), sizeof(float), img.pixels.size(), f) == img.pixels.size();  // x86-64: little-endian
    ok = std::fclose(f) == 0 && ok;
    if (!ok) {
      std::fprintf(stderr, "exr_npy: writing %s failed\n", argv[2]);
      return 1;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "exr_npy: %s\n", e.what());
    return 1;
  }
  return 0;
}
