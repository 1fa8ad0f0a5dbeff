// libFuzzer harness: every cube-map entry of the C ABI (texel directions, the lookup fixup, the
// cosine-power and irradiance filters, mip chains, sampling) on small maps and parameters from the
// bytes. Checks the contract: finite outputs on OK, untouched ones on failure.
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::input in(data, size);
  const int n = in.small(0, 9), out_n = in.small(0, 9);  // sizes, 0 bad
  const hemilight_edge_fixup fixup = hemilight_edge_fixup(in.small(0, 3));
  std::vector<float> map(std::size_t(6 * 3) * std::size_t(n) * std::size_t(n) + 1);
  for (float& f : map) f = in.small(0, 7) == 0 ? in.any_float(4.0f) : float(in.small(0, 255)) / 64.0f;
  float d[3], dir[3];
  for (float& f : dir) f = in.any_float(2.0f);
  fuzz::fill(d, sizeof d);
  hemilight_status st = hemilight_cubemap_texel_direction(n, in.small(-1, 6), in.small(-1, 9), in.small(-1, 9), fixup, d);
  fuzz::check_finite(st, d, 3);
  fuzz::check_untouched(st, d, sizeof d);
  fuzz::fill(d, sizeof d);
  st = hemilight_cubemap_fixup_lookup(dir, n, in.any_float(4.0f), d);
  fuzz::check_finite(st, d, 3);
  fuzz::check_untouched(st, d, sizeof d);
  const std::size_t out_floats = std::size_t(6 * 3) * std::size_t(out_n) * std::size_t(out_n);
  std::vector<float> out(out_floats + 1);
  fuzz::fill(out.data(), out.size() * sizeof(float));
  st = hemilight_cubemap_filter_cosine_power(map.data(), n, in.any_float(64.0f), fixup, out_n, out.data());
  fuzz::check_finite(st, out.data(), out_floats);
  fuzz::check_untouched(st, out.data(), out.size() * sizeof(float));
  fuzz::fill(out.data(), out.size() * sizeof(float));
  st = hemilight_cubemap_filter_irradiance(map.data(), n, fixup, out_n, in.small(0, 2), out.data());
  fuzz::check_finite(st, out.data(), out_floats);
  fuzz::check_untouched(st, out.data(), out.size() * sizeof(float));
  std::size_t chain_floats = 0;
  int levels = 0;
  if (hemilight_cubemap_chain_floats(out_n, &chain_floats, &levels) == HEMILIGHT_OK && chain_floats < (1u << 16)) {
    std::vector<float> chain(chain_floats + 1);
    fuzz::fill(chain.data(), chain.size() * sizeof(float));
    const std::size_t capacity = in.small(0, 7) == 0 ? chain_floats - 1 : chain_floats;
    st = hemilight_cubemap_filter_mip_chain(map.data(), n, fixup, out_n, in.any_float(2.0f), chain.data(), capacity);
    fuzz::check_finite(st, chain.data(), chain_floats);
    fuzz::check_untouched(st, chain.data(), chain.size() * sizeof(float));
    if (st == HEMILIGHT_OK) {
      float rgb[3];
      fuzz::fill(rgb, sizeof rgb);
      st = hemilight_cubemap_sample(chain.data(), out_n, in.small(0, levels + 1), dir, in.any_float(4.0f),
                                    hemilight_cube_sampling(in.small(0, 2)), in.small(0, 2), rgb);
      fuzz::check_finite(st, rgb, 3);
      fuzz::check_untouched(st, rgb, sizeof rgb);
    }
  }
  return 0;
}
