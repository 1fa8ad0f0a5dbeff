// L1 SH: the sampler's projection (sh_l1.hpp) and their evaluation (sampler.hpp).
#include "sh_l1.hpp"

#include "weighted_sums.hpp"

#include "hemilight/sampler.hpp"

namespace hemilight {

namespace sampler_detail {

std::array<glm::vec3, 4> project_sh_l1(const hemicube_buffer& buffer, const hemicube_table& table, const glm::vec3& irradiance,
                                       const std::array<glm::vec3, 3>& rotation_gradient, const glm::vec3& n) {
  // Band 0: solid-angle-weighted radiance; band 1: Y1 times Phi = E n + g_r x n (per channel).
  constexpr double y00 = 0.282094791773878143, y1 = 0.488602511902919921;
  double s0[3] = {0.0, 0.0, 0.0};
  weighted_sums(buffer.channel(0), buffer.channel(1), buffer.channel(2), table.solid_angle(), buffer.texel_count(), s0);
  std::array<glm::vec3, 4> sh{};
  for (int ch = 0; ch < 3; ++ch) {
    const glm::dvec3 phi =
        double(irradiance[ch]) * glm::dvec3(n) + glm::cross(glm::dvec3(rotation_gradient[std::size_t(ch)]), glm::dvec3(n));
    sh[0][ch] = float(y00 * s0[ch]);
    sh[1][ch] = float(y1 * phi.y);
    sh[2][ch] = float(y1 * phi.z);
    sh[3][ch] = float(y1 * phi.x);
  }
  return sh;
}

}  // namespace sampler_detail

glm::vec3 sh_l1_irradiance(const std::array<glm::vec3, 4>& sh, const glm::vec3& d) noexcept {
  // pi Y00 = sqrt(pi) / 2 and (2 pi / 3) Y1 = sqrt(pi / 3): the clamped-cosine kernel's band 0 and
  // band 1 factors (pi, 2 pi / 3) times the basis functions' constants (integrate.hpp).
  constexpr float k0 = 0.886226925f;  // sqrt(pi) / 2
  constexpr float k1 = 1.023326708f;  // sqrt(pi / 3)
  const glm::vec3 e = k0 * sh[0] + k1 * (d.x * sh[3] + d.y * sh[1] + d.z * sh[2]);
  return glm::max(e, glm::vec3(0.0f));
}

std::array<glm::vec3, 3> hl2_from_sh_l1(const std::array<glm::vec3, 4>& sh, const frame& f) noexcept {
  std::array<glm::vec3, 3> out;
  for (std::size_t k = 0; k < 3; ++k)
    out[k] = sh_l1_irradiance(sh, f.to_world(glm::vec3(hl2_basis[k][0], hl2_basis[k][1], hl2_basis[k][2])));
  return out;
}

}  // namespace hemilight
