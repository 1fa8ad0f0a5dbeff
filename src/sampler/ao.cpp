// The sampler's ambient occlusion (ao.hpp).
#include "ao.hpp"

#include <cassert>
#include <limits>

namespace hemilight::sampler_detail {

namespace {

// sum_i vz[i] [dist[i] > d] over `count` texels (a multiple of 4: 3 N^2 for an even N): four
// lanes of float partial sums per block of 1024 texels (a block's weights sum to well under 1),
// each block's lanes added in a fixed order into double. With d = -inf every texel counts, in the
// same order, so a hemicube that sees nothing within d gives exactly the total.
double open_weight(const float* dist, const float* vz, std::size_t count, float d) {
  double sum = 0.0;
  for (std::size_t b0 = 0; b0 < count; b0 += 1024) {
    const std::size_t b1 = b0 + 1024 < count ? b0 + 1024 : count;
    float lanes[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (std::size_t i = b0; i < b1; i += 4)
      for (std::size_t j = 0; j < 4; ++j) lanes[j] += dist[i + j] > d ? vz[i + j] : 0.0f;
    sum += double((lanes[0] + lanes[1]) + (lanes[2] + lanes[3]));
  }
  return sum;
}

}  // namespace

std::shared_ptr<const ao_weights> make_ao_weights(int n) {
  auto w = std::make_shared<ao_weights>();
  w->table = integration_table::get(n);
  const std::vector<float> nothing_hit(w->table->vz.size(), std::numeric_limits<float>::infinity());
  w->total = open_weight(nothing_hit.data(), w->table->vz.data(), nothing_hit.size(), -std::numeric_limits<float>::infinity());
  return w;
}

float unoccluded_fraction(const hemicube_buffer& buffer, const ao_weights& weights, float d) {
  const std::vector<float>& vz = weights.table->vz;
  assert(buffer.distance.size() == vz.size() && vz.size() % 4 == 0);
  return float(open_weight(buffer.distance.data(), vz.data(), vz.size(), d) / weights.total);
}

}  // namespace hemilight::sampler_detail
