// The cache's brute-force interpolation over a list of records, for tests and tools (cache.hpp:
// record_weight, record_is_behind, interpolate_records, interpolate_records_sh_l1,
// interpolate_records_ao). The placement's own interpolation through its search structures is in
// placement.cpp.
#include "weights.hpp"

#include "hemilight/cache.hpp"

namespace hemilight {

using cache_detail::extrapolate;
using cache_detail::is_behind;
using cache_detail::prediction_order;
using cache_detail::weight_of;

float record_weight(const cache_record& r, const glm::vec3& x, const glm::vec3& n, const cache_options& o) {
  return weight_of(r, x, n, o);
}

bool record_is_behind(const cache_record& r, const glm::vec3& x, const glm::vec3& n) { return is_behind(r, x, n); }

glm::vec3 interpolate_records(const std::vector<cache_record>& records, const glm::vec3& x, const glm::vec3& n,
                              const cache_options& o, float* weight_sum) {
  glm::vec3 sum(0.0f);
  float wsum = 0.0f;
  for (const cache_record& r : records) {
    const float w = record_weight(r, x, n, o);
    if (w <= 0.0f || record_is_behind(r, x, n)) continue;
    sum += w * extrapolate(r, x, n, prediction_order(o), o.error_threshold);
    wsum += w;
  }
  if (weight_sum) *weight_sum = wsum;
  return wsum > 0.0f ? glm::max(sum / wsum, glm::vec3(0.0f)) : glm::vec3(0.0f);
}

std::array<glm::vec3, 4> interpolate_records_sh_l1(const std::vector<cache_record>& records, const glm::vec3& x,
                                                   const glm::vec3& n, const cache_options& o) {
  std::array<glm::vec3, 4> sum{};
  float wsum = 0.0f;
  for (const cache_record& r : records) {
    const float w = record_weight(r, x, n, o);
    if (w <= 0.0f || record_is_behind(r, x, n)) continue;
    for (std::size_t k = 0; k < 4; ++k) sum[k] += w * r.sh_l1[k];
    wsum += w;
  }
  if (wsum > 0.0f)
    for (glm::vec3& c : sum) c /= wsum;
  return sum;
}

float interpolate_records_ao(const std::vector<cache_record>& records, const glm::vec3& x, const glm::vec3& n,
                             const cache_options& o) {
  float sum = 0.0f, wsum = 0.0f;
  for (const cache_record& r : records) {
    const float w = record_weight(r, x, n, o);
    if (w <= 0.0f || record_is_behind(r, x, n)) continue;
    sum += w * r.ao;
    wsum += w;
  }
  return wsum > 0.0f ? sum / wsum : 0.0f;
}

}  // namespace hemilight
