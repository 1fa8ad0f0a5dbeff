// Ambient occlusion from a hemicube buffer (internal, not installed): the sampler's AO
// (sampler_pass::ao_distance in sampler.hpp; the definition: docs/bake.md, "Ambient occlusion").
#pragma once

#include "hemilight/hemicube.hpp"
#include "hemilight/integrate.hpp"

#include <memory>

namespace hemilight::sampler_detail {

// The cosine weights of one resolution: the integrator's own table (its vz, the projected solid
// angle of each texel: the irradiance weights) and their sum in double (pi to float rounding of
// the entries).
struct ao_weights {
  std::shared_ptr<const integration_table> table;
  double total = 0.0;
};

// The weights of resolution N (the shared integration_table of N; O(N^2) for the sum).
std::shared_ptr<const ao_weights> make_ao_weights(int n);

// sum_i vz_i [distance_i > d] / sum_i vz_i over the buffer's texels, in [0, 1]: 1 where every
// texel sees nothing nearer than d (misses are +inf), 0 where every texel sees geometry within d.
// Back faces count like front faces (the buffer holds their distance). Precondition: the buffer's
// resolution is the weights'. Cost: one compare and one add per texel.
float unoccluded_fraction(const hemicube_buffer& buffer, const ao_weights& weights, float d);

}  // namespace hemilight::sampler_detail
