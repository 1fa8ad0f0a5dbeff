// hemilight_make_level — writes one of the stand-in levels (levels.hpp) as a glTF binary that
// hemilight_bake reads, and prints its figures, its sun and sky, and the command that bakes it.
//
//   hemilight_make_level NAME OUT.glb [--triangles N] [--lightmap-size S] [--padding P] [--seed K]
//                        [--no-degenerate] [--hemicubes K]
//
// The file (model_export.hpp): one node, one mesh per material (baseColorFactor = albedo), the
// lightmap UVs as TEXCOORD_1 and a copy as TEXCOORD_0. glTF has no sky and the sun is not
// written as a light: both are printed as hemilight_bake options (--sun, --sky).
// --hemicubes K: what a hemicube costs on the level, as docs/levels.md reports it: K points drawn
// by area over the non-degenerate triangles (a fixed sequence), 1 mm in front of them, a hemicube
// at N = 64 on one thread at each; prints the mean time, the triangles tested, the (triangle,
// face) pairs drawn and the distinct triangles seen, and the same for the hexagon room of 1,062
// triangles (reference_scenes.hpp) for scale. Exit codes: 0
// done, 1 the file could not be written, 2 a bad command line (an unknown level, an option out of
// its range, charts that do not fit the lightmap size).
#include "hemilight/levels.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/reference_scenes.hpp"

#include "model_export.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unordered_set>
#include <vector>

using namespace hemilight;

namespace {

const char* usage =
    "usage: hemilight_make_level NAME OUT.glb [options]\n"
    "  Writes the stand-in level NAME (arena, keep, city_block or terrain_town; docs/levels.md)\n"
    "  as glTF binary with its lightmap UVs (TEXCOORD_1), and prints the hemilight_bake options\n"
    "  for its sun and sky.\n"
    "options:\n"
    "  --triangles N      triangles to aim for (default: 50000 closed, 150000 open levels;\n"
    "                     closed 10000..4000000, open 50000..4000000)\n"
    "  --lightmap-size S  the lightmap the UVs are packed for, 256..16384 (default by size:\n"
    "                     1024 up to 75000 triangles, 2048, 4096, then 8192 above 1.2M)\n"
    "  --padding P        texels between charts, 1..64 (default 2)\n"
    "  --seed K           layout seed, 0..2^64-1 (default 1)\n"
    "  --no-degenerate    without the ~1.5% degenerate triangles\n"
    "  --hemicubes K      also measure K hemicubes (N = 64, one thread) on points drawn by area, and\n"
    "                     as many on the 1,062-triangle hexagon room, 1..100000 (default: none)\n"
    "  --help             this text\n";

struct cli_error {
  std::string message;
  int code;
};
[[noreturn]] void fail(const std::string& message, int code) { throw cli_error{message, code}; }

unsigned long long parse_number(const std::string& name, const char* text, unsigned long long lo, unsigned long long hi) {
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(text, &end, 10);
  if (!*text || *text == '-' || *end || errno != 0 || v < lo || v > hi)
    fail(name + " " + text + " is invalid: it must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", 2);
  return v;
}

// K hemicubes at N = 64 on points drawn by area (splitmix64) 1 mm in front of the mesh's
// non-degenerate triangles; prints the means.
void measure_hemicubes(const char* name, const scene_mesh& mesh, int count) {
  std::vector<double> cumulative;
  std::vector<std::size_t> which;
  double total = 0.0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const glm::dvec3 a(mesh.positions[mesh.indices[3 * t]]), b(mesh.positions[mesh.indices[3 * t + 1]]),
        c(mesh.positions[mesh.indices[3 * t + 2]]);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double longest = std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
    if (0.5 * glm::length(n) <= 1e-10 * longest) continue;
    total += 0.5 * glm::length(n);
    cumulative.push_back(total);
    which.push_back(t);
  }
  std::uint64_t state = 0x5eed;
  const auto uniform = [&] {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return static_cast<double>((z ^ (z >> 31)) >> 11) / 9007199254740992.0;
  };
  hemicube_rasterizer r(scene::create(mesh.desc()));
  hemicube_buffer buffer;
  double seconds = 0.0, tested = 0.0, drawn = 0.0, seen = 0.0;
  std::unordered_set<std::uint32_t> ids;
  for (int k = 0; k < count; ++k) {
    const std::size_t i =
        static_cast<std::size_t>(std::lower_bound(cumulative.begin(), cumulative.end(), uniform() * total) - cumulative.begin());
    const std::size_t t = which[std::min(i, which.size() - 1)];
    const glm::vec3 a = mesh.positions[mesh.indices[3 * t]], b = mesh.positions[mesh.indices[3 * t + 1]],
                    c = mesh.positions[mesh.indices[3 * t + 2]];
    double u = uniform(), v = uniform();
    if (u + v > 1.0) {
      u = 1.0 - u;
      v = 1.0 - v;
    }
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    const glm::vec3 p = a + static_cast<float>(u) * (b - a) + static_cast<float>(v) * (c - a) + 1e-3f * n;
    const auto t0 = std::chrono::steady_clock::now();
    r.render(p, make_frame(n), 64, buffer);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    tested += static_cast<double>(r.statistics().triangles_tested);
    drawn += static_cast<double>(r.statistics().face_triangles);
    ids.clear();
    for (std::size_t texel = 0; texel < 3 * 64 * 64; ++texel)
      if (r.seen_triangle(texel) != hemicube_rasterizer::no_triangle) ids.insert(r.seen_triangle(texel));
    seen += static_cast<double>(ids.size());
  }
  const double k = count;
  std::printf(
      "hemicubes on %s (%zu triangles): %.3f ms each, %.0f triangles tested, %.0f (triangle, face) pairs drawn, %.0f distinct "
      "triangles seen\n",
      name, mesh.triangle_count(), 1e3 * seconds / k, tested / k, drawn / k, seen / k);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::string name, out;
    level_options o;
    int hemicubes = 0;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      const auto value = [&]() -> const char* {
        if (i + 1 >= argc) fail(a + " needs a value (see --help)", 2);
        return argv[++i];
      };
      if (a == "--help" || a == "-h") {
        std::fputs(usage, stdout);
        return 0;
      } else if (a == "--triangles") {
        o.target_triangles = static_cast<std::size_t>(parse_number(a, value(), 1, 4000000));
      } else if (a == "--lightmap-size") {
        o.lightmap_size = static_cast<int>(parse_number(a, value(), 256, 16384));
      } else if (a == "--padding") {
        o.padding = static_cast<int>(parse_number(a, value(), 1, 64));
      } else if (a == "--seed") {
        o.seed = parse_number(a, value(), 0, ~0ull);
      } else if (a == "--no-degenerate") {
        o.degenerate_triangles = false;
      } else if (a == "--hemicubes") {
        hemicubes = static_cast<int>(parse_number(a, value(), 1, 100000));
      } else if (!a.empty() && a[0] == '-') {
        fail("unknown option " + a + " (see --help)", 2);
      } else if (name.empty()) {
        name = a;
      } else if (out.empty()) {
        out = a;
      } else {
        fail("unexpected argument " + a + " (see --help)", 2);
      }
    }
    if (out.empty()) fail("needs a level name and an output file (see --help)", 2);
    const auto t0 = std::chrono::steady_clock::now();
    const level l = make_level(name, o);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    model_export::write_glb(l.mesh, out);
    std::printf(
        "%s: %zu triangles (%zu degenerate), %zu vertices, %zu charts in %d x %d texels (padding %d, %.3f texels/m, %.1f%% "
        "covered), made in %.2f s\n",
        l.name.c_str(), l.mesh.triangle_count(), l.degenerate_triangles, l.mesh.positions.size(), l.charts, l.lightmap_size,
        l.lightmap_size, l.padding, static_cast<double>(l.texels_per_metre), 100.0 * l.utilisation, seconds);
    const light& sun = l.lights[0];
    const glm::vec3 sky = l.mesh.sky_radiance;
    std::printf(
        "sun: direction of travel (%.6g, %.6g, %.6g), irradiance %g W/m^2, angular radius %g rad; sky radiance (%g, %g, %g)\n",
        static_cast<double>(sun.direction.x), static_cast<double>(sun.direction.y), static_cast<double>(sun.direction.z),
        static_cast<double>(sun.color.x), static_cast<double>(sun.radius), static_cast<double>(sky.x), static_cast<double>(sky.y),
        static_cast<double>(sky.z));
    std::printf("bake: hemilight_bake %s --size %d --sun %.6g,%.6g,%.6g,%g,%g --sky %g,%g,%g\n", out.c_str(), l.lightmap_size,
                static_cast<double>(sun.direction.x), static_cast<double>(sun.direction.y), static_cast<double>(sun.direction.z),
                static_cast<double>(sun.color.x), static_cast<double>(sun.radius), static_cast<double>(sky.x),
                static_cast<double>(sky.y), static_cast<double>(sky.z));
    if (hemicubes > 0) {
      measure_hemicubes(l.name.c_str(), l.mesh, hemicubes);
      measure_hemicubes("the hexagon room", hexagon_room(3), hemicubes);
    }
    return 0;
  } catch (const cli_error& e) {
    std::fprintf(stderr, "hemilight_make_level: %s\n", e.message.c_str());
    return e.code;
  } catch (const error& e) {  // make_level: a bad name or option value is a bad command line
    std::fprintf(stderr, "hemilight_make_level: %s\n", e.what());
    return e.code() == status::invalid_argument ? 2 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hemilight_make_level: %s\n", e.what());
    return 1;
  }
}
