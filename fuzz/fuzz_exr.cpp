// libFuzzer harness: the bytes as an EXR file through hemilight_exr_info, hemilight_exr_load_rgb
// and hemilight_exr_load_cubemap_rgb (seeded with small files of every compression OpenEXR
// writes: fuzz/corpus/exr). Checks the contract: finite outputs on OK (a file may hold NaN or
// Inf pixels: those are passed on as stored, so only sizes are checked here), untouched ones on
// failure, and no allocation beyond what the file can hold (ASan's allocation limit; run.sh --ci
// gives this harness -malloc_limit_mb=64). Images over 2^16 pixels are loaded into a buffer of 48
// floats: the loaders must refuse them from the header, before decoding anything.
#include "fuzz_input.hpp"

#include <cstdio>
#include <string>
#include <unistd.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = "/tmp/hemilight_fuzz_exr_" + std::to_string(getpid()) + ".exr";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  int w = -7, h = -7, cube = -7;
  const hemilight_status st = hemilight_exr_info(path.c_str(), &w, &h, &cube);
  if (st != HEMILIGHT_OK && (w != -7 || h != -7 || cube != -7)) fuzz::violated("exr_info wrote its outputs although it failed");
  if (st == HEMILIGHT_OK && (w < 1 || h < 1 || (std::size_t(w) * std::size_t(h) > (std::size_t(1) << 28))))
    fuzz::violated("exr_info gave a size outside [1, 2^28 pixels]");
  if (st == HEMILIGHT_OK && std::size_t(w) * std::size_t(h) <= (std::size_t(1) << 16)) {
    std::vector<float> rgb(3 * std::size_t(w) * std::size_t(h) + 1);
    fuzz::fill(rgb.data(), rgb.size() * sizeof(float));
    const hemilight_status sl = hemilight_exr_load_rgb(path.c_str(), rgb.data(), rgb.size() - 1, nullptr, nullptr);
    fuzz::check_untouched(sl, rgb.data(), rgb.size() * sizeof(float));
    if (cube == 1) {
      int s = -7;
      fuzz::fill(rgb.data(), rgb.size() * sizeof(float));
      const hemilight_status sc = hemilight_exr_load_cubemap_rgb(path.c_str(), rgb.data(), rgb.size() - 1, &s);
      fuzz::check_untouched(sc, rgb.data(), rgb.size() * sizeof(float));
    }
  } else if (st == HEMILIGHT_OK) {
    float small[48];
    fuzz::fill(small, sizeof small);
    if (hemilight_exr_load_rgb(path.c_str(), small, 48, nullptr, nullptr) == HEMILIGHT_OK)
      fuzz::violated("exr_load_rgb accepted a capacity of 48 floats for an image over 2^16 pixels");
    fuzz::check_untouched(HEMILIGHT_ERROR_INVALID_ARGUMENT, small, sizeof small);
    int s = -7;
    if (hemilight_exr_load_cubemap_rgb(path.c_str(), small, 48, &s) == HEMILIGHT_OK)
      fuzz::violated("exr_load_cubemap_rgb accepted a capacity of 48 floats for an image over 2^16 pixels");
    fuzz::check_untouched(HEMILIGHT_ERROR_INVALID_ARGUMENT, small, sizeof small);
    if (s != -7) fuzz::violated("exr_load_cubemap_rgb wrote its size although it failed");
  }
  return 0;
}
