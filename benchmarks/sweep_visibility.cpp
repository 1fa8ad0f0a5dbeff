// How much of what a hemicube sees its neighbours see too: the measure behind an amortised
// visibility design (drawing a hemicube from the triangles seen by a few hemicubes near it rather
// than from the whole level), which is not built. Deterministic counts, no timing.
//   usage: sweep_visibility OUT.csv [--points P] [--levels a,b,...]
// Per level (levels.hpp at its default size; default arena, keep and city_block) P points by area
// (bench_points.hpp, default 200), N = 64. Around each point, a cluster of K points (the point and
// K - 1 others uniform in the square of half side r on its tangent plane, the same frame; r =
// 0.25, 0.5, 1, 2 m, K = 1, 4, 9) and 4 held-out points in the same square. Points whose hemicube
// sees back faces through over 10% of its texels (moved into a solid or off its face) are drawn
// again (up to 16 tries, else skipped). Columns: level, triangles, radius_m, cluster_points,
// clusters, seen (distinct triangles through the texel centres of one hemicube, mean), union (the
// cluster's distinct triangles), union_leaves (the BVH leaves holding them), miss_texels (the share
// of the held-out hemicubes' texels whose triangle is not in the union: what a render from the
// union would get wrong), miss_texels_leaves (not in the union's leaves), tested, drawn (the
// culled render's triangles tested and (triangle, face) pairs drawn at the held-out points, for
// scale). Time: about a minute on one core.
#include "hemilight/levels.hpp"
#include "hemilight/raster.hpp"

#include "bench_points.hpp"

#include <cstdio>
#include <cstdlib>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <vector>

using namespace hemilight;

namespace {

constexpr int resolution = 64;

struct row {
  double seen = 0, union_size = 0, union_leaves = 0, miss = 0, miss_leaves = 0, tested = 0, drawn = 0;
  std::size_t clusters = 0, held = 0;
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc < 2) {
    std::fprintf(stderr, "usage: sweep_visibility OUT.csv [--points P] [--levels a,b,...]\n");
    return 2;
  }
  std::size_t points = 200;
  std::vector<std::string> levels = {"arena", "keep", "city_block"};
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--points") points = std::strtoul(argv[i + 1], nullptr, 10);
    else if (flag == "--levels") levels = split(argv[i + 1]);
    else throw std::invalid_argument("unknown flag " + flag);
  }
  FILE* out = std::fopen(argv[1], "w");
  if (!out) throw std::runtime_error(std::string("cannot write ") + argv[1]);
  std::fprintf(out, "level,triangles,radius_m,cluster_points,clusters,seen,union,union_leaves,miss_texels,miss_texels_leaves,"
                    "tested,drawn\n");
  for (const std::string& name : levels) {
    const level lv = make_level(name);
    const auto sc = scene::create(lv.mesh.desc());
    const bench::sample_points p = bench::surface_points(lv.mesh, points, 1e-4f * sc->size());
    // The BVH leaf of each triangle (scene_desc numbering).
    std::vector<std::uint32_t> leaf_of(sc->triangle_count(), hemicube_rasterizer::no_triangle);
    for (std::size_t ni = 0; ni < sc->bvh().size(); ++ni) {
      const bvh_node& node = sc->bvh()[ni];
      for (std::uint32_t k = 0; k < node.count; ++k) leaf_of[sc->triangles()[node.first + k].index] = std::uint32_t(ni);
    }
    hemicube_rasterizer r(sc, raster_options{});
    hemicube_buffer b;
    std::vector<std::uint32_t> ids;
    // Renders at x; false when it looks inside geometry (over 10% back-face texels).
    const auto render = [&](const glm::vec3& x, const frame& f) {
      r.render(x, f, resolution, b);
      ids.resize(b.texel_count());
      std::size_t back = 0;
      for (std::size_t i = 0; i < ids.size(); ++i) {
        ids[i] = r.seen_triangle(i);
        back += (b.flags[i] & texel_back_face) ? 1u : 0u;
      }
      return back * 10 <= ids.size();
    };
    for (const float radius : {0.25f, 0.5f, 1.0f, 2.0f})
      for (const int k : {1, 4, 9}) {
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> u(-1.0f, 1.0f);
        row w;
        for (std::size_t c = 0; c < p.points.size(); ++c) {
          const frame& f = p.frames[c];
          const auto near = [&](int tries, bool centre) -> bool {
            for (int t = 0; t < tries; ++t) {
              const glm::vec3 x = centre ? p.points[c] : p.points[c] + radius * u(rng) * f.t + radius * u(rng) * f.b;
              if (render(x, f)) return true;
              if (centre) return false;
            }
            return false;
          };
          std::unordered_set<std::uint32_t> seen_union, leaves;
          double seen = 0;
          int members = 0;
          for (int s = 0; s < k; ++s) {
            if (!near(16, s == 0)) continue;
            ++members;
            const std::unordered_set<std::uint32_t> one(ids.begin(), ids.end());
            seen += double(one.size());
            for (const std::uint32_t t : ids)
              if (t != hemicube_rasterizer::no_triangle) {
                seen_union.insert(t);
                leaves.insert(leaf_of[t]);
              }
          }
          if (members < k) continue;  // the centre or a member inside geometry
          ++w.clusters;
          w.seen += seen / k;
          w.union_size += double(seen_union.size());
          w.union_leaves += double(leaves.size());
          for (int h = 0; h < 4; ++h) {
            if (!near(16, false)) continue;
            std::size_t miss = 0, miss_leaves = 0;
            for (const std::uint32_t t : ids) {
              if (t == hemicube_rasterizer::no_triangle) continue;
              miss += seen_union.count(t) ? 0u : 1u;
              miss_leaves += leaves.count(leaf_of[t]) ? 0u : 1u;
            }
            w.miss += double(miss) / double(ids.size());
            w.miss_leaves += double(miss_leaves) / double(ids.size());
            w.tested += double(r.statistics().triangles_tested);
            w.drawn += double(r.statistics().face_triangles);
            ++w.held;
          }
        }
        const double nc = double(std::max<std::size_t>(w.clusters, 1)), nh = double(std::max<std::size_t>(w.held, 1));
        std::fprintf(out, "%s,%zu,%.2f,%d,%zu,%.1f,%.1f,%.1f,%.6f,%.6f,%.0f,%.0f\n", name.c_str(), lv.mesh.triangle_count(),
                     double(radius), k, w.clusters, w.seen / nc, w.union_size / nc, w.union_leaves / nc, w.miss / nh,
                     w.miss_leaves / nh, w.tested / nh, w.drawn / nh);
        std::fflush(out);
        std::printf("%s r = %.2f m, K = %d: %zu clusters, seen %.0f, union %.0f (%.0f leaves), held-out texels missing %.3f%% "
                    "(leaves %.3f%%), culled render tests %.0f, draws %.0f\n",
                    name.c_str(), double(radius), k, w.clusters, w.seen / nc, w.union_size / nc, w.union_leaves / nc,
                    100.0 * w.miss / nh, 100.0 * w.miss_leaves / nh, w.tested / nh, w.drawn / nh);
      }
  }
  std::fclose(out);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "sweep_visibility: %s\n", e.what());
  return 1;
}
