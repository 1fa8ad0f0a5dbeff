// hemicube_weights: prints the exact texel weights of hemicubes of several resolutions and
// writes the projected-solid-angle weights of one as an EXR unfolded cross.
//
//   usage: hemicube_weights [output.exr] [N]      (defaults: hemicube_weights.exr, 64)
//
// The cross shows the top face in the middle and each side face folded out next to the edge it
// shares with the top face, so the cos(theta) falloff of the weights is visible as one picture.
#include "hemilight/hemilight.hpp"

#include <cstdio>
#include <cstdlib>
#include <string>

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : "hemicube_weights.exr";
  const int n = argc > 2 ? std::atoi(argv[2]) : 64;
  try {
    std::printf("%6s %10s %22s %22s\n", "N", "texels", "sum solid angle / 2pi", "sum projected / pi");
    for (int res : {2, 16, 64, 256, 1024}) {
      const auto table = hemilight::hemicube_table::get(res);
      double sa = 0, psa = 0;
      for (std::size_t i = 0; i < table->size(); ++i) {
        sa += table->solid_angle()[i];
        psa += table->projected_solid_angle()[i];
      }
      std::printf("%6d %10zu %22.12f %22.12f\n", res, table->size(), sa / (2 * 3.14159265358979323846),
                  psa / 3.14159265358979323846);
    }

    const auto table = hemilight::hemicube_table::get(n);  // throws a clear error for a bad N
    // Unfolded cross, 2N x 2N: top face at [N/2, 3N/2)^2; side faces around it. Image row 0 is
    // the top of the picture, so hemicube +y points up in the picture.
    hemilight::image cross = hemilight::image::make(2 * n, 2 * n, 3, 0.0f);
    const float peak = table->projected_solid_angle()[hemilight::hemicube_texel_index(n, {hemilight::hemicube_face::top, n / 2, n / 2})];
    for (std::size_t i = 0; i < table->size(); ++i) {
      const glm::ivec2 px = hemilight::hemicube_cross_pixel(n, hemilight::hemicube_texel_from_index(n, i));
      float* p = cross.at(px.x, px.y);
      const float w = table->projected_solid_angle()[i] / peak;
      p[0] = p[1] = p[2] = w;
    }
    hemilight::write_exr(path, cross);
    std::printf("wrote %s: projected solid angle of each texel of an N = %d hemicube, relative to the centre texel\n",
                path.c_str(), n);
    return 0;
  } catch (const hemilight::error& e) {
    std::fprintf(stderr, "hemicube_weights: %s\n", e.what());
    return 1;
  }
}
