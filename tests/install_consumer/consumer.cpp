// Consumes the installed C++ library: the texel weights must sum to pi.
#include <hemilight/hemilight.hpp>

#include <cmath>
#include <cstdio>

int main() {
  const auto table = hemilight::hemicube_table::get(8);
  double sum = 0;
  for (std::size_t i = 0; i < table->size(); ++i) sum += table->projected_solid_angle()[i];
  if (std::fabs(sum - 3.14159265358979) > 1e-5) return 1;
  std::printf("consumer_cpp: ok (sum %.7f)\n", sum);
  return 0;
}
