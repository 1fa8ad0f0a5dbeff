// weighted_sums (weighted_sums.hpp): SSE2 where available, else the same operations in scalar code.
#include "weighted_sums.hpp"

#include <algorithm>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hemilight::sampler_detail {

void weighted_sums(const float* r, const float* g, const float* b, const float* w, std::size_t count, double (&out)[3]) {
  for (std::size_t b0 = 0; b0 < count; b0 += 1024) {
    const std::size_t b1 = std::min(count, b0 + 1024);
    float lanes[3][4];
#if defined(__SSE2__)
    __m128 ar = _mm_setzero_ps(), ag = _mm_setzero_ps(), ab = _mm_setzero_ps();
    for (std::size_t i = b0; i < b1; i += 4) {
      const __m128 wv = _mm_loadu_ps(w + i);
      ar = _mm_add_ps(ar, _mm_mul_ps(_mm_loadu_ps(r + i), wv));
      ag = _mm_add_ps(ag, _mm_mul_ps(_mm_loadu_ps(g + i), wv));
      ab = _mm_add_ps(ab, _mm_mul_ps(_mm_loadu_ps(b + i), wv));
    }
    _mm_storeu_ps(lanes[0], ar);
    _mm_storeu_ps(lanes[1], ag);
    _mm_storeu_ps(lanes[2], ab);
#else
    for (auto& lane : lanes)
      for (float& v : lane) v = 0.0f;
    for (std::size_t i = b0; i < b1; i += 4)
      for (std::size_t j = 0; j < 4; ++j) {
        lanes[0][j] += r[i + j] * w[i + j];
        lanes[1][j] += g[i + j] * w[i + j];
        lanes[2][j] += b[i + j] * w[i + j];
      }
#endif
    for (int c = 0; c < 3; ++c) out[c] += double((lanes[c][0] + lanes[c][1]) + (lanes[c][2] + lanes[c][3]));
  }
}

}  // namespace hemilight::sampler_detail
