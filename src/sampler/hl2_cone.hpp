// The HL2 cone of the cache and the baker (internal, not installed): per-texel quadrature
// weights of the cone's Fourier series, and the projection of a hemicube buffer onto them.
// hl2_cone itself and its public operations (rotate, evaluate, hl2_from_cone) are in sampler.hpp.
#pragma once

#include "hemilight/sampler.hpp"
#include "hemilight/hemicube.hpp"

#include <array>
#include <memory>
#include <vector>

namespace hemilight::sampler_detail {


// Per-texel weights of the HL2 cone series (sampler.hpp, hl2_cone): w[term][texel] such that
// coefficient term = sum_i L_i w[term][i], in the hemicube's local frame (reference = +x).
struct cone_weights {
  std::array<std::vector<float>, hl2_cone_terms> w;
};

// The table of resolution n (even, 2..4096, checked by the caller), in the process's table cache
// (table_cache.hpp, like integration_table::get): built on first use (~0.1 s at N = 64), 28 bytes
// per texel.
std::shared_ptr<const cone_weights> make_cone_weights(int n);

// The cone of a rendered hemicube buffer (its resolution that of `weights`): 7 terms x 3 channels
// of weighted sums over its radiance planes (weighted_sums: a fixed order), reference = the
// buffer's tangent `reference` (world space). Cost: 21 multiply-adds per texel.
hl2_cone project_hl2_cone(const hemicube_buffer& buffer, const cone_weights& weights, const glm::vec3& reference);

}  // namespace hemilight::sampler_detail
