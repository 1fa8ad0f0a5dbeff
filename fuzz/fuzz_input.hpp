// Reads typed values from a fuzzer's bytes (fuzz/*.cpp), and the contract checks every harness
// makes: on HEMILIGHT_OK every output is finite; on failure the outputs are untouched.
#pragma once

#include "hemilight.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

namespace fuzz {

class input {
 public:
  input(const std::uint8_t* data, std::size_t size) : p_(data), left_(size) {}
  bool empty() const { return left_ == 0; }
  std::uint8_t byte() {
    if (left_ == 0) return 0;
    --left_;
    return *p_++;
  }
  std::uint32_t u32() {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= std::uint32_t(byte()) << (8 * i);
    return v;
  }
  int small(int lo, int hi) { return lo + int(unsigned(byte()) % unsigned(hi - lo + 1)); }  // [lo, hi], hi - lo <= 255
  // Any float bit pattern a quarter of the time (NaN, Inf, subnormals, huge), else a value in
  // [-range, range] on a coarse grid (so that geometry meets and touches).
  float any_float(float range = 4.0f) {
    if ((byte() & 3) == 0) {
      const std::uint32_t bits = u32();
      float f;
      std::memcpy(&f, &bits, sizeof f);
      return f;
    }
    return range * (float(int(byte()) - 128) / 128.0f);
  }
  std::vector<float> floats(std::size_t n, float range = 4.0f) {
    std::vector<float> v(n);
    for (float& f : v) f = any_float(range);
    return v;
  }

 private:
  const std::uint8_t* p_;
  std::size_t left_;
};

// A finding: libFuzzer reports the crash with its input; `what` says which promise broke.
[[noreturn]] inline void violated(const char* what) {
  std::fprintf(stderr, "hemilight contract violated: %s (last error: %s)\n", what, hemilight_last_error());
  __builtin_trap();
}

inline void check_finite(hemilight_status st, const float* out, std::size_t n) {
  if (st != HEMILIGHT_OK) return;
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(out[i])) violated("a non-finite output on HEMILIGHT_OK");
}

// Fills with a sentinel; untouched() checks it is still there.
inline void fill(void* p, std::size_t bytes) { std::memset(p, 0xa5, bytes); }
inline void check_untouched(hemilight_status st, const void* p, std::size_t bytes) {
  if (st == HEMILIGHT_OK) return;
  const unsigned char* c = static_cast<const unsigned char*>(p);
  for (std::size_t i = 0; i < bytes; ++i)
    if (c[i] != 0xa5) violated("an output written although the call failed");
}

// A scene of up to 8 triangles (positions, indices and radiance from the bytes, some bad), or null.
inline hemilight_scene* make_scene(input& in) {
  const std::size_t vertices = std::size_t(in.small(0, 12)), triangles = std::size_t(in.small(0, 8));
  const std::vector<float> pos = in.floats(3 * vertices);
  std::vector<std::uint32_t> idx(3 * triangles);
  for (std::uint32_t& i : idx) i = std::uint32_t(in.small(0, 13));
  std::vector<float> rad = in.floats(3 * triangles, 2.0f);
  const std::vector<float> sky = in.floats(3, 2.0f);
  hemilight_scene* s = nullptr;
  if (hemilight_scene_create(pos.data(), vertices, idx.data(), triangles, rad.data(), sky.data(), &s) != HEMILIGHT_OK) return nullptr;
  return s;
}

// Up to 3 lights from the bytes (any type, any field values), or the scene itself.
inline hemilight_scene* with_lights(input& in, hemilight_scene* s) {
  const std::size_t count = std::size_t(in.small(0, 3));
  if (count == 0) return s;
  std::vector<hemilight_light> lights(count);
  for (hemilight_light& l : lights) {
    hemilight_light_init(&l, hemilight_light_type(in.small(0, 4)));
    for (float& f : l.color) f = in.any_float(8.0f);
    for (float& f : l.position) f = in.any_float();
    for (float& f : l.direction) f = in.any_float();
    for (float& f : l.tangent) f = in.any_float();
    l.width = in.any_float(2.0f);
    l.height = in.any_float(2.0f);
    l.radius = in.any_float(0.5f);
    l.spot_inner = in.any_float(1.0f);
    l.spot_outer = in.any_float(1.6f);
    l.casts_shadows = in.small(0, 2);
  }
  hemilight_scene* lit = nullptr;
  if (hemilight_scene_with_lights(s, lights.data(), count, &lit) != HEMILIGHT_OK) return s;
  hemilight_scene_release(s);
  return lit;
}

}  // namespace fuzz
