// Cube-map sweeps (CSV out; benchmarks/plot_cubemap.py draws the charts):
//
//   sweep_cubemap <seams.csv>   writes <seams.csv> and, next to it, cubemap_warp.csv and
//                               cubemap_accuracy.csv (the path's directory, same prefix).
//
// 1. Seams (<seams.csv>): the procedural sky (256^2) filtered to sizes 4..256 with lobes of
//    sigma = 1, 2, 4 output texels (p = (size / (2 sigma))^2), sampled like hardware. For each
//    of the 12 edges, at up to 32 points along it: the zero-order jump |f(+e) - f(-e)| across
//    the edge (e = 1e-4 texel) and the first-order kink |(f(+h) - f(+e)) - (f(-e) - f(-h))|
//    (h = one texel), normalised by the same quantities inside the faces nearby: the mean step
//    between neighbouring texels |f(x + h) - f(x)| and the mean second difference
//    |f(x+h) - 2f(x) + f(x-h)| at the texel centres 1.5 to 3.5 texels from the edge on the same
//    paths. A method without a seam reads about 1 for the kink (bilinear interpolation has the
//    same slope changes inside the face) and about 0 for the jump. At the 8 corners: the spread
//    (max - min) of the three faces' values at e from the corner, normalised like the jump.
//    f is the mean of R, G, B. Interior distortion: the RMS and max difference, at random
//    directions 1.5 texels or more from the edges, between the method's lookup and the plain
//    texel-centre map's, relative to the mean value. Methods:
//      none             texel-centre directions, per-face clamp-to-edge bilinear
//      stretch          stretch directions, per-face, no lookup fixup
//      warp             warp directions, per-face (warp needs no fixup)
//      stretch_fixup    stretch directions, per-face, fixup_lookup(d, size, -1)
//      stretch_fixup_lod  a stretch mip chain from 256 (gloss mapping with the same sigma),
//                       level log2(256/size) read at that explicit LOD through
//                       fixup_lookup(d, 256, lod) with per-face trilinear sampling
//      seamless         texel-centre directions, seamless bilinear across faces
// 2. Warp fixup exactness (cubemap_warp.csv): for sizes 2..1024, how far (in texels) per-face
//    sampling after the (n - 1)/n fixup lands from where the warp (or stretch) mapping put the
//    direction, max over the face coordinate, and where.
// 3. Speed against accuracy (cubemap_accuracy.csv): the 256^2 radiance chain for several
//    texels_per_sigma and cutoffs: seconds for 1 and 2 threads and the max relative error
//    against filter_reference at 150 random texels per level.
#include "hemilight/cubemap.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace hemilight;

// Face axis, column and row of GL face f (the same table as cube_face_point).
glm::dvec3 face_axis(int f) { return glm::dvec3(cube_face_point(static_cast<cube_face>(f), 0, 0)); }

struct method_result {
  double jump = 0, jump_max = 0, kink = 0, kink_max = 0, step = 0, second = 0;
  double corner = 0, corner_max = 0;
  double distortion_rms = 0, distortion_max = 0;
  int edge_samples = 0, interior_samples = 0, corners = 0;
};

float lum(const glm::vec4& v) { return (v.x + v.y + v.z) / 3.0f; }

// Measures one method; `look` returns the sampled value along a direction.
template <class Lookup>
method_result measure(int n, Lookup look) {
  method_result r;
  const double h = 2.0 / n;  // one texel in face coordinates
  const double e = 1e-4 * h;
  const int k_count = std::min(n, 32);
  for (int a = 0; a < 6; ++a)
    for (int b = a + 1; b < 6; ++b) {
      const glm::dvec3 na = face_axis(a), nb = face_axis(b);
      if (glm::dot(na, nb) != 0.0) continue;  // opposite faces share no edge
      const glm::dvec3 along = glm::cross(na, nb);
      for (int k = 0; k < k_count; ++k) {
        const double t = -1.0 + (2.0 * k + 1.0) / k_count;
        const glm::dvec3 edge = na + nb + t * along;
        // the path: into face a is -nb, into face b is -na; s < 0 on a, s > 0 on b
        const auto f = [&](double s) {
          const glm::dvec3 p = s < 0 ? edge + s * nb : edge - s * na;
          return static_cast<double>(lum(look(glm::vec3(glm::normalize(p)))));
        };
        const double fa_e = f(-e), fb_e = f(e), fa_h = f(-h), fb_h = f(h);
        const double jump = std::fabs(fb_e - fa_e), kink = std::fabs((fb_h - fb_e) - (fa_e - fa_h));
        r.jump += jump;
        r.jump_max = std::max(r.jump_max, jump);
        r.kink += kink;
        r.kink_max = std::max(r.kink_max, kink);
        ++r.edge_samples;
        // local interior references on the same paths: at the texel centres 1.5, 2.5 and 3.5
        // texels from the edge (as far as the face reaches; the path crosses the face at s = 2)
        for (double side : {-1.0, 1.0})
          for (double s0 = 1.5 * h; s0 <= 3.5 * h + 1e-12 && s0 + h <= 2.0 - 0.5 * h + 1e-12; s0 += h) {
            const double x0 = f(side * s0), xp = f(side * (s0 + h)), xm = f(side * (s0 - h));
            r.step += std::fabs(xp - x0);
            r.second += std::fabs(xp - 2.0 * x0 + xm);
            ++r.interior_samples;
          }
      }
    }
  // corners: the three faces meeting at (sx, sy, sz)
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 corner(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1);
    double lo = 1e30, hi = -1e30;
    for (int axis = 0; axis < 3; ++axis) {
      glm::dvec3 p = corner;
      for (int o = 0; o < 3; ++o)
        if (o != axis) p[o] -= corner[o] * e;  // step into the face whose major axis is `axis`
      const double v = lum(look(glm::vec3(glm::normalize(p))));
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    r.corner += hi - lo;
    r.corner_max = std::max(r.corner_max, hi - lo);
    ++r.corners;
  }
  return r;
}

std::string dir_of(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

double seconds(const std::chrono::steady_clock::time_point& t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void seams(const std::string& path, const cubemap& env) {
  std::ofstream csv(path);
  csv << "method,size,lobe_texels,power,edge_jump,edge_jump_max,edge_kink,edge_kink_max,corner_jump,"
         "corner_jump_max,distortion_rms,distortion_max\n";
  const int top = 256;
  for (float lobe : {1.0f, 2.0f, 4.0f}) {
    filter_options stretch_options;
    stretch_options.fixup = edge_fixup::stretch;
    const cubemap chain = filter_mip_chain(env, top, stretch_options, lobe);
    for (int n = 4; n <= top; n *= 2) {
      const float p = static_cast<float>((n / (2.0 * lobe)) * (n / (2.0 * lobe)));
      filter_options o;
      o.fixup = edge_fixup::none;
      const cube_image centre = filter_cosine_power(env, p, n, o);
      o.fixup = edge_fixup::stretch;
      const cube_image stretch = filter_cosine_power(env, p, n, o);
      o.fixup = edge_fixup::warp;
      const cube_image warp = filter_cosine_power(env, p, n, o);
      const int lod = static_cast<int>(std::lround(std::log2(double(top) / n)));
      const auto clamp = [](const cube_image& c) {
        return [&c](const glm::vec3& d) { return sample_bilinear(c, d, cube_sampling::clamp_per_face); };
      };
      struct named {
        const char* name;
        std::function<glm::vec4(const glm::vec3&)> look;
      };
      const std::vector<named> methods = {
          {"none", clamp(centre)},
          {"stretch", clamp(stretch)},
          {"warp", clamp(warp)},
          {"stretch_fixup",
           [&](const glm::vec3& d) { return sample_bilinear(stretch, fixup_lookup(d, n, -1.0f), cube_sampling::clamp_per_face); }},
          {"stretch_fixup_lod",
           [&](const glm::vec3& d) {
             return sample_lod(chain, fixup_lookup(d, top, float(lod)), float(lod), cube_sampling::clamp_per_face);
           }},
          {"seamless", [&](const glm::vec3& d) { return sample_bilinear(centre, d, cube_sampling::seamless); }},
      };
      // interior directions for the distortion measure: 1.5 texels or more from every edge
      std::mt19937 rng(7);
      const double limit = std::max(0.0, 1.0 - 3.0 / n);
      std::uniform_real_distribution<double> uni(-limit, limit);
      std::vector<glm::vec3> interior(600);
      for (std::size_t i = 0; i < interior.size(); ++i)
        interior[i] = glm::normalize(cube_face_point(static_cast<cube_face>(i % 6), float(uni(rng)), float(uni(rng))));
      double mean_ref = 0;
      for (const glm::vec3& d : interior) mean_ref += lum(sample_bilinear(centre, d, cube_sampling::clamp_per_face));
      mean_ref /= double(interior.size());
      for (const named& m : methods) {
        method_result r = measure(n, m.look);
        double sq = 0, mx = 0;
        for (const glm::vec3& d : interior) {
          const double diff = lum(m.look(d)) - lum(sample_bilinear(centre, d, cube_sampling::clamp_per_face));
          sq += diff * diff;
          mx = std::max(mx, std::fabs(diff));
        }
        const double step = r.interior_samples ? r.step / r.interior_samples : 0.0;
        const double second = r.interior_samples ? r.second / r.interior_samples : 0.0;
        const auto norm = [](double v, double ref) { return ref > 0 ? v / ref : 0.0; };
        char line[512];
        std::snprintf(line, sizeof line, "%s,%d,%g,%g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", m.name, n,
                      double(lobe), double(p), norm(r.jump / r.edge_samples, step), norm(r.jump_max, step),
                      norm(r.kink / r.edge_samples, second), norm(r.kink_max, second),
                      norm(r.corner / r.corners, step), norm(r.corner_max, step),
                      std::sqrt(sq / double(interior.size())) / mean_ref, mx / mean_ref);
        csv << line;
      }
      std::printf("seams: lobe %g size %d done\n", double(lobe), n);
      std::fflush(stdout);
    }
  }
}

// How far (texels) per-face sampling after the fixup lands from the mapping's own position.
void warp_exactness(const std::string& path) {
  std::ofstream csv(path);
  csv << "size,mapping,max_error_texels,at_u\n";
  for (int n = 2; n <= 1024; n *= 2)
    for (edge_fixup m : {edge_fixup::warp, edge_fixup::stretch}) {
      const double a = m == edge_fixup::warp ? double(n) * n / ((n - 1.0) * (n - 1.0) * (n - 1.0)) : 0.0;
      double worst = 0, at = 0;
      for (int k = 0; k <= 20000; ++k) {
        const double u = -1.0 + 2.0 * k / 20000;
        // continuous texel index x with mapping(x) = u, by bisection
        double lo = -0.5, hi = n - 0.5;
        for (int it = 0; it < 80; ++it) {
          const double mid = 0.5 * (lo + hi);
          const double c = (2 * mid + 1) / n - 1;
          const double mapped = m == edge_fixup::warp ? c + a * c * c * c : 2.0 * mid / (n - 1) - 1.0;
          (mapped < u ? lo : hi) = mid;
        }
        const double landed = (u * (n - 1) / n + 1) * n / 2 - 0.5;
        if (std::fabs(landed - lo) > worst) {
          worst = std::fabs(landed - lo);
          at = u;
        }
      }
      csv << n << "," << (m == edge_fixup::warp ? "warp" : "stretch") << "," << worst << "," << at << "\n";
    }
}

void accuracy(const std::string& path, const cubemap& env) {
  std::ofstream csv(path);
  csv << "texels_per_sigma,cutoff,seconds_1_thread,seconds_2_threads,max_rel_error\n";
  // the reference at fixed random texels of every level, computed once
  std::vector<std::vector<std::size_t>> texels(9);
  std::vector<std::vector<float>> refs(9);
  std::mt19937 rng(13);
  for (int l = 0; l < 9; ++l) {
    const int n = 256 >> l;
    const std::size_t count = 6u * std::size_t(n) * std::size_t(n);
    for (int k = 0; k < 150; ++k) texels[std::size_t(l)].push_back(count <= 150 ? std::size_t(k) % count : rng() % count);
    refs[std::size_t(l)] = filter_reference(env.levels[0], gloss_power(256, l), n, edge_fixup::none, texels[std::size_t(l)]);
  }
  for (float cutoff : {1e-3f, 1e-4f, 1e-5f})
    for (float r : {1.0f, 1.5f, 2.5f, 4.0f}) {
      filter_options o;
      o.cutoff = cutoff;
      o.texels_per_sigma = r;
      double secs[2] = {0, 0};
      cubemap chain;
      for (int threads = 1; threads <= 2; ++threads) {
        o.thread_count = threads;
        double best = 1e30;
        for (int rep = 0; rep < 2; ++rep) {
          const auto t0 = std::chrono::steady_clock::now();
          chain = filter_mip_chain(env, 256, o);
          best = std::min(best, seconds(t0));
        }
        secs[threads - 1] = best;
      }
      double worst = 0;
      for (std::size_t l = 0; l < 9; ++l)
        for (std::size_t k = 0; k < texels[l].size(); ++k)
          for (std::size_t c = 0; c < 3; ++c) {
            const double ref = refs[l][k * 3 + c], v = chain.levels[l].pixels[texels[l][k] * 3 + c];
            worst = std::max(worst, std::fabs(v - ref) / std::fabs(ref));
          }
      csv << r << "," << cutoff << "," << secs[0] << "," << secs[1] << "," << worst << "\n";
      std::printf("accuracy: r %g cutoff %g: %.3f s / %.3f s, max error %.4f\n", double(r), double(cutoff), secs[0],
                  secs[1], worst);
      std::fflush(stdout);
    }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: sweep_cubemap <seams.csv>\n");
    return 2;
  }
  const std::string seams_path = argv[1], dir = dir_of(seams_path);
  try {
    const cubemap env = cubemap::from_image(procedural_environment(256), false);
    warp_exactness(dir + "/cubemap_warp.csv");
    seams(seams_path, env);
    accuracy(dir + "/cubemap_accuracy.csv", env);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sweep_cubemap: %s\n", e.what());
    return 1;
  }
  return 0;
}
