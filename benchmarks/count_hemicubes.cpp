// A fixed hemicube workload for instruction counts, which do not drift with the machine's speed
// the way timings on a shared VM do (docs/raster.md):
//
//   valgrind --tool=callgrind build-bench/benchmarks/count_hemicubes SCENE [N] [--integrate]
//   callgrind_annotate --inclusive=yes callgrind.out.* | grep -E 'render\(|integrate\('
//
// renders one hemicube (and integrates it with the default options, with --integrate) at each of
// the 256 points bench_raster uses for SCENE (bench_points.hpp), or, for SCENE =
// cornell_floor_and_back_wall, at the 128 points of bench_integrate's render + integrate target.
// Divide the inclusive counts of hemicube_rasterizer::render and hemicube_integrator::integrate
// by the printed hemicube count. N defaults to 64. Prints the rasterizer's statistics per
// hemicube and a checksum (the summed irradiance) so runs can be compared.
#include "hemilight/integrate.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/reference_scenes.hpp"

#include "bench_points.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>

using namespace hemilight;

int main(int argc, char** argv) try {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: count_hemicubes SCENE [N] [--integrate]\n"
                 "  SCENE: cornell_box_32, hexagon_room_496, hexagon_room_1062, heightfield_10k, "
                 "cornell_floor_and_back_wall\n");
    return 2;
  }
  const std::string name = argv[1];
  int n = 64;
  bool integrate_too = false;
  for (int a = 2; a < argc; ++a) {
    if (std::strcmp(argv[a], "--integrate") == 0) integrate_too = true;
    else n = std::atoi(argv[a]);
  }
  scene_mesh mesh;
  if (name == "cornell_box_32" || name == "cornell_floor_and_back_wall") mesh = cornell_box();
  else if (name == "hexagon_room_496") mesh = hexagon_room(2);
  else if (name == "hexagon_room_1062") mesh = hexagon_room(3);
  else if (name == "heightfield_10k") mesh = heightfield(10000);
  else {
    std::fprintf(stderr, "count_hemicubes: unknown scene '%s'\n", name.c_str());
    return 2;
  }
  const auto sc = scene::create(mesh.desc());
  const bench::sample_points pts =
      name == "cornell_floor_and_back_wall" ? bench::cornell_floor_and_back_wall() : bench::surface_points(mesh, 256, 1e-4f * sc->size());
  hemicube_rasterizer raster(sc);
  hemicube_integrator integrator(n);  // throws for an invalid N, with the message
  hemicube_buffer buf;
  double checksum = 0.0;
  raster_statistics total;
  for (std::size_t k = 0; k < pts.points.size(); ++k) {
    raster.render(pts.points[k], pts.frames[k], n, buf);
    const raster_statistics& s = raster.statistics();
    total.triangles_tested += s.triangles_tested;
    total.face_triangles += s.face_triangles;
    total.clipped += s.clipped;
    total.spans += s.spans;
    total.fragments += s.fragments;
    if (integrate_too) checksum += integrator.integrate(buf).irradiance.x;
  }
  const double h = static_cast<double>(pts.points.size());
  std::printf("%s N=%d: %zu hemicubes%s; per hemicube: %.1f triangles tested, %.1f (triangle, face) pairs, "
              "%.1f clipped, %.1f spans, %.1f span texels; checksum %.9g\n",
              name.c_str(), n, pts.points.size(), integrate_too ? " (rendered and integrated)" : " (rendered)",
              static_cast<double>(total.triangles_tested) / h, static_cast<double>(total.face_triangles) / h,
              static_cast<double>(total.clipped) / h, static_cast<double>(total.spans) / h,
              static_cast<double>(total.fragments) / h, checksum);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "count_hemicubes: %s\n", e.what());
  return 1;
}
