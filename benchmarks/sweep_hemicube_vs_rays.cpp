// Error against time: hemicubes (rasterizer + integrator) beside cosine-weighted ray casting with
// Embree, for the same points and scenes (docs/integration.md, "Hemicubes against rays").
//   usage: sweep_hemicube_vs_rays out.csv
// Scenes: the closed-form scenes of tests/integrate_scenes.hpp (exact irradiance E). Points: 64
// positions jittered by up to 1 cm around each scene's point (the closed form holds for each). For each method
// and budget: RMS relative error of E over the points, and the time per point on one core
// (median of 3 passes). Hemicubes: N = 8 ... 256. Rays: 16 ... 16384 per point, plain
// cosine-weighted (Malley's method on uniform random numbers) and stratified (one jittered sample
// per cell of a sqrt(M) x sqrt(M) grid), each ray traced with rtcIntersect1; the estimator is
// (pi / M) sum L(hit). Embree's scene is built once per scene (not timed).
#include "hemilight/integrate.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/scene.hpp"

#include "integrate_scenes.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace hemilight;
using namespace hemilight::test;

namespace {

using clock_type = std::chrono::steady_clock;

struct point {
  glm::vec3 x, n;
  double e;  // exact irradiance (channel 0)
};

template <class F>
double median_seconds(F&& f) {
  double t[3];
  for (double& s : t) {
    const auto a = clock_type::now();
    f();
    s = std::chrono::duration<double>(clock_type::now() - a).count();
  }
  std::sort(t, t + 3);
  return t[1];
}

}  // namespace

int main(int argc, char** argv) {
  const char* path = argc > 1 ? argv[1] : "hemicube_vs_rays.csv";
  FILE* out = std::fopen(path, "w");
  if (!out) {
    std::fprintf(stderr, "sweep_hemicube_vs_rays: cannot write '%s'\n", path);
    return 1;
  }
  std::fprintf(out, "scene,method,budget,rms_rel_err,seconds_per_point\n");
  RTCDevice device = rtcNewDevice("threads=1");
  for (const closed_form_scene& s : {unoccluded_emitter(), occluded_emitter(), lit_room()}) {
    // The same triangles for both renderers.
    scene_mesh mesh;
    for (const ref_triangle& t : s.tris) {
      material m;
      m.emission = t.radiance;
      m.two_sided = t.two_sided;
      mesh.add_triangle(glm::vec3(t.a), glm::vec3(t.b), glm::vec3(t.c), m);
    }
    mesh.sky_radiance = s.sky;
    auto sc = scene::create(mesh.desc());

    RTCScene rs = rtcNewScene(device);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), mesh.positions.size()));
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(unsigned), mesh.triangle_count()));
    for (std::size_t i = 0; i < mesh.positions.size(); ++i)
      for (int c = 0; c < 3; ++c) vb[3 * i + std::size_t(c)] = mesh.positions[i][c];
    for (std::size_t i = 0; i < mesh.indices.size(); ++i) ib[i] = mesh.indices[i];
    rtcCommitGeometry(geom);
    rtcAttachGeometry(rs, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(rs);

    // Points near the scene's point, each with its exact E.
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> jitter(-0.01f, 0.01f);  // keeps every point partly lit
    std::vector<point> pts;
    const frame f0 = make_frame(glm::vec3(s.normal));
    for (int k = 0; k < 64; ++k) {
      const glm::vec3 x = glm::vec3(s.position) + jitter(rng) * f0.t + jitter(rng) * f0.b;
      pts.push_back({x, glm::vec3(s.normal), s.irradiance(glm::dvec3(x), s.normal)});
    }

    // Hemicubes.
    for (int n = 8; n <= 256; n *= 2) {
      hemicube_rasterizer raster(sc);
      integrate_options io;
      io.translation = translation_estimator::none;  // irradiance only, like the rays
      io.rotation_gradient = false;
      hemicube_integrator integ(n, io);
      hemicube_buffer buf;
      std::vector<double> e(pts.size());
      const double secs = median_seconds([&] {
        for (std::size_t i = 0; i < pts.size(); ++i) {
          const float roll = 0.7f * float(i);
          frame f = make_frame(pts[i].n);
          const glm::vec3 t = std::cos(roll) * f.t + std::sin(roll) * f.b;
          f.b = glm::cross(f.n, t);
          f.t = t;
          raster.render(pts[i].x, f, n, buf);
          e[i] = integ.integrate(buf).irradiance.x;
        }
      });
      double sum = 0;
      for (std::size_t i = 0; i < pts.size(); ++i) sum += std::pow((e[i] - pts[i].e) / pts[i].e, 2.0);
      std::fprintf(out, "%s,hemicube,%d,%.6g,%.6g\n", s.name.c_str(), n, std::sqrt(sum / double(pts.size())), secs / double(pts.size()));
    }

    // Rays.
    for (bool stratified : {false, true})
      for (int m = 16; m <= 16384; m *= 4) {
        const int side = int(std::lround(std::sqrt(double(m))));
        std::vector<double> e(pts.size());
        const double secs = median_seconds([&] {
          std::mt19937 r2(11);
          std::uniform_real_distribution<float> u01(0.0f, 1.0f);
          RTCIntersectContext ctx;
          rtcInitIntersectContext(&ctx);
          for (std::size_t i = 0; i < pts.size(); ++i) {
            const frame f = make_frame(pts[i].n);
            double sum = 0.0;
            for (int k = 0; k < m; ++k) {
              float u1 = u01(r2), u2 = u01(r2);
              if (stratified) {
                u1 = (float(k % side) + u1) / float(side);
                u2 = (float(k / side) + u2) / float(side);
              }
              // Malley: uniform on the disc, lifted to the hemisphere: cosine-weighted.
              const float rr = std::sqrt(u1), phi = 6.2831853f * u2;
              const glm::vec3 d = f.to_world({rr * std::cos(phi), rr * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u1))});
              RTCRayHit rh;
              rh.ray.org_x = pts[i].x.x;
              rh.ray.org_y = pts[i].x.y;
              rh.ray.org_z = pts[i].x.z;
              rh.ray.dir_x = d.x;
              rh.ray.dir_y = d.y;
              rh.ray.dir_z = d.z;
              rh.ray.tnear = 1e-5f;
              rh.ray.tfar = INFINITY;
              rh.ray.mask = 0xffffffffu;
              rh.ray.flags = 0;
              rh.ray.time = 0;
              rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
              rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
              rtcIntersect1(rs, &ctx, &rh);
              if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
                sum += s.sky.x;
              } else {
                const material& mat = mesh.materials[rh.hit.primID];
                // Embree's geometric normal is (v1 - v0) x (v2 - v0)... for its winding; a hit on the
                // front face has dot(Ng, d) < 0.
                const bool front = mat.two_sided || (rh.hit.Ng_x * d.x + rh.hit.Ng_y * d.y + rh.hit.Ng_z * d.z) < 0.0f;
                sum += front ? mat.emission.x : 0.0f;
              }
            }
            e[i] = 3.14159265358979 * sum / double(m);
          }
        });
        double sum = 0;
        for (std::size_t i = 0; i < pts.size(); ++i) sum += std::pow((e[i] - pts[i].e) / pts[i].e, 2.0);
        std::fprintf(out, "%s,%s,%d,%.6g,%.6g\n", s.name.c_str(), stratified ? "rays_stratified" : "rays", m,
                     std::sqrt(sum / double(pts.size())), secs / double(pts.size()));
      }
    rtcReleaseScene(rs);
    std::printf("%s done\n", s.name.c_str());
    std::fflush(stdout);
  }
  rtcReleaseDevice(device);
  std::fclose(out);
  std::printf("wrote %s\n", path);
  return 0;
}
