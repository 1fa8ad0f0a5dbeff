// Dilation of lightmaps (dilate.hpp; bake.hpp: dilate): rings of empty texels next to filled
// ones take the mean of their filled neighbours.
#include "dilate.hpp"

#include "hemilight/bake.hpp"

#include <algorithm>
#include <string>

namespace hemilight {

namespace bake_detail {

std::size_t dilate_masked(image& img, std::vector<std::uint8_t>& filled, int rings, const std::uint8_t* blocked) {
  const std::size_t texels = std::size_t(img.width) * std::size_t(img.height);
  const int w = img.width, h = img.height, ch = img.channels;
  const auto neighbours = [&](std::size_t k, auto&& f) {
    const int x = int(k % std::size_t(w)), y = int(k / std::size_t(w));
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int nx = x + dx, ny = y + dy;
        if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
        f(std::size_t(ny) * std::size_t(w) + std::size_t(nx), nx, ny);
      }
  };
  // Candidates of a ring: empty texels next to a texel filled before it (the first ring: next to
  // any filled texel; later rings: next to the previous ring's texels). Kept sorted, so each
  // ring's writes are in texel order (they do not depend on it: a ring reads only older texels).
  std::vector<std::size_t> candidates, fresh;
  std::vector<std::uint8_t> queued(texels, 0);
  for (std::size_t k = 0; k < texels; ++k)
    if (!filled[k] && !(blocked && blocked[k])) {
      bool next_to_filled = false;
      neighbours(k, [&](std::size_t q, int, int) { next_to_filled = next_to_filled || filled[q]; });
      if (next_to_filled) {
        candidates.push_back(k);
        queued[k] = 1;
      }
    }
  std::size_t total = 0;
  for (int ring = 0; (rings < 0 || ring < rings) && !candidates.empty(); ++ring) {
    fresh.clear();
    for (std::size_t k : candidates) {
      float acc[4] = {0, 0, 0, 0};
      int n = 0;
      neighbours(k, [&](std::size_t q, int nx, int ny) {
        if (!filled[q]) return;
        const float* p = img.at(nx, ny);
        for (int c = 0; c < ch; ++c) acc[c] += p[c];
        ++n;
      });
      if (n == 0) continue;
      float* p = img.pixels.data() + k * std::size_t(ch);
      for (int c = 0; c < ch; ++c) p[c] = acc[c] / float(n);
      fresh.push_back(k);
    }
    // Marked after the ring: a ring reads only texels filled before it (order independent).
    for (std::size_t k : fresh) filled[k] = 1;
    total += fresh.size();
    candidates.clear();
    for (std::size_t k : fresh)
      neighbours(k, [&](std::size_t q, int, int) {
        if (!filled[q] && !queued[q] && !(blocked && blocked[q])) {
          queued[q] = 1;
          candidates.push_back(q);
        }
      });
    std::sort(candidates.begin(), candidates.end());
  }
  return total;
}

}  // namespace bake_detail

std::size_t dilate(image& img, std::vector<std::uint8_t>& filled, int rings) {
  const std::size_t texels = std::size_t(img.width) * std::size_t(img.height);
  if (filled.size() != texels)
    throw_invalid_argument("dilate: filled has " + std::to_string(filled.size()) + " entries, the image " +
                           std::to_string(texels));
  if (rings < -1) throw_invalid_argument("dilate: rings " + std::to_string(rings) + " must be >= -1");
  return bake_detail::dilate_masked(img, filled, rings, nullptr);
}

}  // namespace hemilight
