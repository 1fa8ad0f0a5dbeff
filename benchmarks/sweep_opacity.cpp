// The cost of see-through surfaces (docs/materials.md, "Cost"): a foliage stand-in (a ground and
// K overlapping cards with a leaf-like alpha texture, about half of each card present) whose cards
// are opaque, alpha-tested or translucent, at N = 64 on one thread:
//   - hemicube render time per hemicube (thread CPU time), in paired rounds: each round measures
//     every mode once, in a rotating order, and the ratio to the opaque cards is taken within the
//     round (the machine's drift cancels); medians over the rounds;
//   - shadow-ray time per ray towards a sun (occluded() for opaque and alpha-tested cards,
//     transmittance() for translucent ones), in the same rounds;
//   - what the hemicubes see: the share of texels showing a card;
// and ambient occlusion's cost in a bake (AO_OUT.csv): the Cornell box and the hexagon room
// (t = 2) on the unwrapper's UVs, 128², one bounce, two threads, baked without AO, with AO (the default: the cache also
// places records where AO varies) and with AO riding on E's records
// (refine_where_ao_disagrees off), in paired rounds; bake seconds, first-pass hemicubes.
// Usage: sweep_opacity OUT.csv [AO_OUT.csv] [--rounds R] [--cards 250,1000,4000] [--min-time S]
#include "hemilight/bake.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/reference_scenes.hpp"
#include "hemilight/unwrap.hpp"
#include "hemilight/rays.hpp"
#include "hemilight/scene.hpp"

#include "bench_util.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <random>
#include <string>
#include <vector>

using namespace hemilight;

namespace {

constexpr int resolution = 64;
const char* const mode_names[3] = {"opaque", "alpha_tested", "translucent"};

// A 64 x 64 leaf-like alpha: a few overlapping discs, about half the texels present.
alpha_image leaf_alpha() {
  alpha_image a;
  a.width = a.height = 64;
  a.values.assign(64 * 64, 0);
  const float discs[5][3] = {{0.5f, 0.5f, 0.3f}, {0.3f, 0.3f, 0.18f}, {0.7f, 0.35f, 0.17f}, {0.35f, 0.72f, 0.16f}, {0.72f, 0.7f, 0.15f}};
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const float u = (float(x) + 0.5f) / 64.0f, v = (float(y) + 0.5f) / 64.0f;
      for (const auto& d : discs)
        if ((u - d[0]) * (u - d[0]) + (v - d[1]) * (v - d[1]) < d[2] * d[2]) a.values[std::size_t(y) * 64 + std::size_t(x)] = 255;
    }
  return a;
}

// The foliage stand-in with `cards` cards of the given opacity (the same cards for every mode).
std::shared_ptr<const scene> foliage(int cards, surface_opacity mode, double& alpha_share) {
  scene_mesh m;
  material ground;
  ground.albedo = glm::vec3(0.3f);
  m.add_grid({-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}, 20, 20, ground);
  m.texcoords.assign(m.positions.size(), glm::vec2(0.0f));
  material leaf;
  leaf.albedo = glm::vec3(0.2f, 0.5f, 0.1f);
  leaf.emission = glm::vec3(0.05f);
  leaf.two_sided = true;
  leaf.opacity = mode;
  leaf.alpha_texture = mode == surface_opacity::alpha_tested ? 0 : -1;
  leaf.transmittance = glm::vec3(0.4f, 0.6f, 0.3f);
  m.alpha_textures.push_back(leaf_alpha());
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  for (int k = 0; k < cards; ++k) {
    const glm::vec3 c(-9.0f + 18.0f * u01(rng), -9.0f + 18.0f * u01(rng), 0.3f + 2.7f * u01(rng));
    const float yaw = 6.2831853f * u01(rng), tilt = 1.2f * (u01(rng) - 0.5f), size = 0.5f + 0.5f * u01(rng);
    const glm::vec3 a(std::cos(yaw), std::sin(yaw), 0.0f);
    const glm::vec3 b = glm::normalize(glm::vec3(-std::sin(yaw) * std::sin(tilt), std::cos(yaw) * std::sin(tilt), std::cos(tilt)));
    const glm::vec3 h = 0.5f * size * a, v = 0.5f * size * b;
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    m.positions.insert(m.positions.end(), {c - h - v, c + h - v, c + h + v, c - h + v});
    m.texcoords.insert(m.texcoords.end(), {{0, 0}, {1, 0}, {1, 1}, {0, 1}});
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    m.materials.insert(m.materials.end(), {leaf, leaf});
  }
  std::size_t present = 0;
  for (std::uint8_t a : m.alpha_textures[0].values) present += a >= 128 ? 1 : 0;
  alpha_share = double(present) / double(m.alpha_textures[0].values.size());
  return scene::create(m.desc());
}

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct sample {
  double us_hemicube = 0, us_ray = 0;
};

sample measure(const scene& s, hemicube_rasterizer& r, const std::vector<glm::vec3>& points, const glm::vec3& sun,
               double min_time) {
  hemicube_buffer buf;
  const frame up{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  sample out;
  std::size_t count = 0;
  double t0 = thread_cpu_seconds(), t = 0;
  do {
    for (const glm::vec3& p : points) r.render(p, up, resolution, buf);
    count += points.size();
    t = thread_cpu_seconds() - t0;
  } while (t < min_time);
  out.us_hemicube = 1e6 * t / double(count);
  const bool translucent = !s.see_through_triangles().empty() &&
                           s.triangle_material(s.see_through_triangles()[0].index).opacity == surface_opacity::translucent;
  count = 0;
  volatile float sink = 0.0f;
  t0 = thread_cpu_seconds();
  do {
    for (int rep = 0; rep < 50; ++rep)
      for (const glm::vec3& p : points) {
        const glm::vec3 o = p + glm::vec3(0.001f * float(rep), 0.0f, 0.0f);
        sink = sink + (translucent ? transmittance(s, o, sun, INFINITY).x : (occluded(s, o, sun, INFINITY) ? 0.0f : 1.0f));
      }
    count += 50 * points.size();
    t = thread_cpu_seconds() - t0;
  } while (t < 0.5 * min_time);
  out.us_ray = 1e6 * t / double(count);
  return out;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t h = v.size() / 2;
  return v.empty() ? 0.0 : (v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]));
}

}  // namespace

// AO's cost in bakes (see the top), in paired rounds.
void ao_cost(const char* path, int rounds) {
  std::FILE* f = std::fopen(path, "w");
  if (!f) return;
  std::fprintf(f, "scene,size,ao_distance,variant,seconds,ratio_vs_no_ao,hemicubes,rounds,load_average\n");
  struct row {
    const char* name;
    scene_mesh mesh;
    float d;
  };
  const row rows[] = {{"cornell_box", cornell_box(), 0.1f}, {"hexagon_room", hexagon_room(2), 0.5f}};
  const char* const variants[3] = {"no_ao", "ao", "ao_without_rule"};
  for (const row& r : rows) {
    scene_mesh mesh = r.mesh;
    generate_lightmap_uvs(mesh, 128, 2);  // chart UVs, 2 texels of padding
    bake_input in;
    in.scene = mesh.desc();
    std::vector<double> seconds[3], ratio[3];
    std::size_t hemicubes[3] = {};
    for (int round = 0; round < rounds; ++round) {
      double got[3] = {};
      for (int k = 0; k < 3; ++k) {
        const int v = (round + k) % 3;
        bake_options o;
        o.width = o.height = 128;
        o.thread_count = 2;
        o.ao_distance = v == 0 ? 0.0f : r.d;
        o.cache.expert.refine_where_ao_disagrees = v != 2;
        const auto t0 = std::chrono::steady_clock::now();
        const bake_result b = bake_lightmap(in, o);
        got[v] = bench::seconds_since(t0);
        hemicubes[v] = b.stats.hemicubes;
      }
      for (int v = 0; v < 3; ++v) {
        seconds[v].push_back(got[v]);
        ratio[v].push_back(got[v] / got[0]);
      }
    }
    for (int v = 0; v < 3; ++v) {
      std::fprintf(f, "%s,128,%g,%s,%.4f,%.3f,%zu,%d,%.2f\n", r.name, double(r.d), variants[v], median(seconds[v]), median(ratio[v]),
                   hemicubes[v], rounds, bench::loadavg());
      std::printf("%-13s AO %-16s %.3f s (x%.3f of no AO)  %zu hemicubes\n", r.name, variants[v], median(seconds[v]), median(ratio[v]),
                  hemicubes[v]);
    }
  }
  std::fclose(f);
}

int main(int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') {
    std::fprintf(stderr, "usage: sweep_opacity OUT.csv [AO_OUT.csv] [--rounds R] [--cards 250,1000,4000] [--min-time S]\n");
    return 2;
  }
  int rounds = 7;
  double min_time = 0.3;
  std::vector<int> card_counts = {250, 1000, 4000};
  const char* ao_path = argc > 2 && argv[2][0] != '-' ? argv[2] : nullptr;
  for (int i = ao_path ? 3 : 2; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--rounds") rounds = std::max(1, std::atoi(argv[i + 1]));
    else if (a == "--min-time") min_time = std::atof(argv[i + 1]);
    else if (a == "--cards") {
      card_counts.clear();
      for (const std::string& c : bench::split(argv[i + 1])) card_counts.push_back(std::atoi(c.c_str()));
    }
  }
  std::FILE* f = std::fopen(argv[1], "w");
  if (!f) return 1;
  std::fprintf(f, "cards,triangles,mode,alpha_share,card_texel_share,us_per_hemicube,ratio_vs_opaque,us_per_ray,ray_ratio_vs_opaque,rounds,load_average\n");
  const glm::vec3 sun = glm::normalize(glm::vec3(0.3f, 0.2f, 1.0f));
  for (int cards : card_counts) {
    std::shared_ptr<const scene> scenes[3];
    double alpha_share = 0.0;
    for (int m = 0; m < 3; ++m) scenes[m] = foliage(cards, static_cast<surface_opacity>(m), alpha_share);
    // 64 ground points among the cards.
    std::vector<glm::vec3> points;
    std::mt19937 rng(99);
    std::uniform_real_distribution<float> u(-8.0f, 8.0f);
    for (int k = 0; k < 64; ++k) points.push_back({u(rng), u(rng), 1e-3f});
    // What the hemicubes see: the share of texels showing a card (scene triangles past the ground's 800).
    double share[3] = {};
    for (int m = 0; m < 3; ++m) {
      hemicube_rasterizer r(scenes[m]);
      hemicube_buffer buf;
      std::size_t card = 0, total = 0;
      for (const glm::vec3& p : points) {
        r.render(p, {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, resolution, buf);
        for (std::size_t t = 0; t < buf.texel_count(); ++t) {
          const std::uint32_t seen = r.seen_triangle(t);
          if (seen != hemicube_rasterizer::no_triangle && seen >= 800u) ++card;
        }
        total += buf.texel_count();
      }
      share[m] = double(card) / double(total);
    }
    std::vector<double> us[3], ray[3], ratio[3], ray_ratio[3];
    std::vector<hemicube_rasterizer> rasterizers;
    for (int m = 0; m < 3; ++m) rasterizers.emplace_back(scenes[m]);
    for (int round = 0; round < rounds; ++round) {
      sample got[3];
      for (int k = 0; k < 3; ++k) {
        const int m = (round + k) % 3;
        got[m] = measure(*scenes[m], rasterizers[std::size_t(m)], points, sun, min_time);
      }
      for (int m = 0; m < 3; ++m) {
        us[m].push_back(got[m].us_hemicube);
        ray[m].push_back(got[m].us_ray);
        ratio[m].push_back(got[m].us_hemicube / got[0].us_hemicube);
        ray_ratio[m].push_back(got[m].us_ray / got[0].us_ray);
      }
    }
    for (int m = 0; m < 3; ++m) {
      std::fprintf(f, "%d,%zu,%s,%.3f,%.4f,%.2f,%.3f,%.4f,%.3f,%d,%.2f\n", cards, scenes[m]->triangle_count(), mode_names[m],
                   alpha_share, share[m], median(us[m]), median(ratio[m]), median(ray[m]), median(ray_ratio[m]), rounds,
                   bench::loadavg());
      std::printf("cards %5d %-12s  %8.1f us/hemicube (x%.2f of opaque)  %.3f us/ray (x%.2f)  card texels %.1f%%\n", cards,
                  mode_names[m], median(us[m]), median(ratio[m]), median(ray[m]), median(ray_ratio[m]), 100.0 * share[m]);
      std::fflush(stdout);
    }
  }
  std::fclose(f);
  if (ao_path) ao_cost(ao_path, rounds);
  return 0;
}
