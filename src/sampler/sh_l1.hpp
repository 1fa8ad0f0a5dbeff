// L1 spherical harmonics from a hemicube buffer (internal, not installed): the sampler's cheap
// projection (sampler_pass::sh_l1 in sampler.hpp). Evaluating L1 SH (sh_l1_irradiance,
// hl2_from_sh_l1) is public, in sampler.hpp.
#pragma once

#include "hemilight/geometry.hpp"
#include "hemilight/hemicube.hpp"

#include <array>

namespace hemilight::sampler_detail {

// World-space L1 SH (integrate.hpp's order and constants) of a rendered hemicube buffer with the
// frame normal `n`: band 0 = Y00 sum_i L_i Omega_i (the texel solid angles of `table`, summed in
// double by weighted_sums), band 1 = Y1 Phi with the vector irradiance Phi = E n + g_r x n per
// channel from the sample's `irradiance` and `rotation_gradient`. Cost: 3 multiply-adds per texel.
std::array<glm::vec3, 4> project_sh_l1(const hemicube_buffer& buffer, const hemicube_table& table, const glm::vec3& irradiance,
                                       const std::array<glm::vec3, 3>& rotation_gradient, const glm::vec3& n);

}  // namespace hemilight::sampler_detail
