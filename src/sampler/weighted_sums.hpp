// The directional projections' one SIMD kernel (internal, not installed): weighted sums of a
// hemicube buffer's three radiance planes in a fixed order (bitwise the same on every path).
#pragma once

#include <cstddef>

namespace hemilight::sampler_detail {

// out[c] += sum_i plane_c[i] w[i] for the three planes r, g, b of `count` texels (a multiple of
// 4): four lanes of float partial sums per block of 1024 texels, each block's lanes summed in a
// fixed order into double. SSE2 where available; the scalar path does the same operations in the
// same order.
// Cost: 3 multiply-adds per texel.
void weighted_sums(const float* r, const float* g, const float* b, const float* w, std::size_t count, double (&out)[3]);

}  // namespace hemilight::sampler_detail
