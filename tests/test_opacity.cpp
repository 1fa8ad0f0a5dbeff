// See-through surfaces (scene.hpp's surface_opacity): alpha-tested and translucent triangles in
// the hemicubes (raster.hpp), the ray queries (rays.hpp), the lights' shadow rays (lights.hpp), the
// bake's lightmap and shadow mask, and the probes. References are closed forms: which checker cell
// a texel's ray crosses (plane geometry), products of transmittances, the fraction of open cells.
#include "hemilight/bake.hpp"
#include "hemilight/lights.hpp"
#include "hemilight/probes.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/rays.hpp"
#include "hemilight/scene.hpp"

#include "rays/ray_accel.hpp"
#include "test_support.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <vector>

using namespace hemilight;
using hemilight::test::require_error;

namespace {

constexpr int checker_cells = 8;

// An 8 x 8 checker alpha texture: texel (x, y) is 255 (present) where x + y is even, else 0.
// Sampled bilinearly with cutoff 0.5, the boundaries fall exactly on the texel edges.
alpha_image checker_alpha() {
  alpha_image a;
  a.width = a.height = checker_cells;
  for (int y = 0; y < checker_cells; ++y)
    for (int x = 0; x < checker_cells; ++x) a.values.push_back((x + y) % 2 == 0 ? 255 : 0);
  return a;
}

// Whether the checker card over [-1, 1]^2 (texcoord (x + 1) / 2, (y + 1) / 2) is present at (x, y);
// `margin` (texcoord cells) away from a cell edge, else `unsure`.
bool checker_present(double x, double y, double margin, bool& unsure) {
  const double cx = (x + 1.0) / 2.0 * checker_cells, cy = (y + 1.0) / 2.0 * checker_cells;
  const auto near_edge = [&](double c) { return std::fabs(c - std::round(c)) < margin; };
  unsure = near_edge(cx) || near_edge(cy);
  const int ix = static_cast<int>(std::floor(cx)), iy = static_cast<int>(std::floor(cy));
  return (ix + iy) % 2 == 0;
}

material see_through(surface_opacity o) {
  material m;
  m.opacity = o;
  m.two_sided = true;
  return m;
}

// A horizontal quad over [-s, s]^2 at height z, its front facing -z (down), with texcoords
// (x + s) / 2s, (y + s) / 2s; `tc` receives them.
void add_card(scene_mesh& mesh, float s, float z, const material& m) {
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  mesh.positions.insert(mesh.positions.end(), {{-s, -s, z}, {-s, s, z}, {s, s, z}, {s, -s, z}});
  mesh.texcoords.resize(mesh.positions.size() - 4);
  mesh.texcoords.insert(mesh.texcoords.end(), {{0.0f, 0.0f}, {0.0f, 1.0f}, {1.0f, 1.0f}, {1.0f, 0.0f}});
  mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  mesh.materials.insert(mesh.materials.end(), {m, m});
}

// The card scene: an emissive ceiling (radiance 1, facing down) at z = 2 over [-8, 8]^2 and a
// checker card (alpha-tested, emission 0.5) at z = 1 over [-1, 1]^2.
scene_mesh checker_scene() {
  scene_mesh mesh;
  material ceiling;
  ceiling.emission = glm::vec3(1.0f);
  add_card(mesh, 8.0f, 2.0f, ceiling);
  material card = see_through(surface_opacity::alpha_tested);
  card.emission = glm::vec3(0.5f);
  card.alpha_texture = 0;
  add_card(mesh, 1.0f, 1.0f, card);
  mesh.alpha_textures.push_back(checker_alpha());
  return mesh;
}

const frame up{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

bool same_buffer(const hemicube_buffer& a, const hemicube_buffer& b) {
  return a.radiance == b.radiance && a.distance == b.distance && a.flags == b.flags;
}

}  // namespace

TEST_CASE("opacity: scene::create checks the opacity fields, naming the material or texture", "[opacity]") {
  scene_mesh mesh = checker_scene();
  mesh.materials[2].alpha_cutoff = 1.5f;
  require_error([&] { scene::create(mesh.desc()); }, status::invalid_argument, "materials[2].alpha_cutoff is 1.5");
  mesh = checker_scene();
  mesh.materials[3].alpha_texture = 4;
  require_error([&] { scene::create(mesh.desc()); }, status::invalid_argument, "materials[3].alpha_texture = 4");
  mesh = checker_scene();
  mesh.materials[2].alpha = std::nanf("");
  require_error([&] { scene::create(mesh.desc()); }, status::invalid_argument, "materials[2].alpha is nan");
  mesh = checker_scene();
  mesh.materials[0].opacity = surface_opacity::translucent;
  mesh.materials[0].transmittance = glm::vec3(0.5f, -0.1f, 0.5f);
  require_error([&] { scene::create(mesh.desc()); }, status::invalid_argument, "materials[0].transmittance.g");
  mesh = checker_scene();
  mesh.materials[0].opacity = static_cast<surface_opacity>(7);
  require_error([&] { scene::create(mesh.desc()); }, status::invalid_argument, "materials[0].opacity is 7");
  mesh = checker_scene();
  mesh.texcoords.clear();
  require_error([&] { scene::create(mesh.desc()); }, status::invalid_argument, "texcoords is null");
  mesh = checker_scene();
  mesh.texcoords[5].x = INFINITY;
  require_error([&] { scene::create(mesh.desc()); }, status::invalid_argument, "texcoords[5].u is inf");
  mesh = checker_scene();
  scene_desc d = mesh.desc();
  alpha_texture bad{nullptr, 0, 4};
  d.alpha_textures = &bad;
  require_error([&] { scene::create(d); }, status::invalid_argument, "alpha_textures[0] size 0 x 4");
  bad.width = 4;
  require_error([&] { scene::create(d); }, status::invalid_argument, "alpha_textures[0].values is null");
  // Valid: the see-through triangles are kept apart from the BVH's.
  mesh = checker_scene();
  const auto s = scene::create(mesh.desc());
  CHECK(s->triangles().size() == 2);
  CHECK(s->see_through_triangles().size() == 2);
  CHECK(s->drawable_triangle_count() == 4);
}

TEST_CASE("opacity: alpha_present reads the texture bilinearly with repeat wrap", "[opacity]") {
  const auto s = scene::create(checker_scene().desc());
  // Triangle 2 is (-1,-1), (-1,1), (1,1) with texcoords (0,0), (0,1), (1,1): b1, b2 of v1, v2.
  // Its texcoord at (b1, b2) is (b2, b1 + b2).
  for (double u = 0.03; u < 1.0; u += 0.0625)
    for (double v = u + 0.01; v < 1.0; v += 0.0625) {
      bool unsure;
      const bool expected = checker_present(2.0 * u - 1.0, 2.0 * v - 1.0, 0.02, unsure);
      if (unsure) continue;
      const auto b2 = static_cast<float>(u), b1 = static_cast<float>(v - u);
      CHECK(s->alpha_present(2, b1, b2) == expected);
    }
  // An opaque triangle is always present.
  CHECK(s->alpha_present(0, 0.3f, 0.3f));
  // An alpha factor below the cutoff without a texture: never present, so not even kept.
  scene_mesh mesh = checker_scene();
  for (int t = 2; t < 4; ++t) {
    mesh.materials[std::size_t(t)].alpha_texture = -1;
    mesh.materials[std::size_t(t)].alpha = 0.4f;
  }
  CHECK(scene::create(mesh.desc())->see_through_triangles().empty());
}

TEST_CASE("opacity: a hemicube sees the ceiling through the checker card's open cells, texel by texel", "[opacity]") {
  const auto s = scene::create(checker_scene().desc());
  for (int n : {64, 128}) {
    hemicube_rasterizer r(s);
    hemicube_buffer buf;
    r.render({0.0f, 0.0f, 0.0f}, up, n, buf);
    CHECK(r.statistics().see_through_tested == 2);
    std::size_t card = 0, through = 0, skipped = 0;
    for (std::size_t i = 0; i < buf.texel_count(); ++i) {
      // The reference: where the texel centre's ray meets the card's plane z = 1 (closed form).
      const glm::dvec3 d(hemicube_texel_direction(n, i));
      const double x = d.x / d.z, y = d.y / d.z;
      bool unsure = false;
      const bool on_card = std::fabs(x) < 1.0 && std::fabs(y) < 1.0;
      const bool edge = std::fabs(std::fabs(x) - 1.0) < 1e-3 || std::fabs(std::fabs(y) - 1.0) < 1e-3;
      const bool present = on_card && checker_present(x, y, 1e-3, unsure);
      if (unsure || edge) {
        ++skipped;
        continue;
      }
      const bool ceiling = std::fabs(2.0 * x) < 8.0 && std::fabs(2.0 * y) < 8.0;
      const float expected = present ? 0.5f : (ceiling ? 1.0f : 0.0f);
      INFO("N " << n << " texel " << i << " at (" << x << ", " << y << ")");
      REQUIRE(buf.radiance_at(i).x == expected);
      if (present) {
        ++card;
        CHECK(buf.distance[i] == Approx(1.0 / d.z).epsilon(1e-5));
        CHECK(s->triangle_material(r.seen_triangle(i)).opacity == surface_opacity::alpha_tested);
      } else if (on_card) {
        ++through;
        CHECK(buf.distance[i] == Approx(2.0 / d.z).epsilon(1e-5));
      }
    }
    CHECK(card > 100);
    CHECK(through > 100);
    CHECK(skipped < buf.texel_count() / 10);
  }
}

TEST_CASE("opacity: the back of a one-sided see-through card is black but not a back face", "[opacity]") {
  // The card at z = 1 faces down (add_card), towards the point; flipped, the point sees its back.
  for (surface_opacity o : {surface_opacity::opaque, surface_opacity::alpha_tested}) {
    scene_mesh mesh;
    material card;
    card.emission = glm::vec3(0.5f);
    card.opacity = o;
    add_card(mesh, 1.0f, 1.0f, card);
    std::swap(mesh.indices[1], mesh.indices[2]);
    std::swap(mesh.indices[4], mesh.indices[5]);
    const auto s = scene::create(mesh.desc());
    hemicube_rasterizer r(s);
    hemicube_buffer buf;
    r.render({0.0f, 0.0f, 0.0f}, up, 32, buf);
    const std::size_t centre = hemicube_texel_index(32, {hemicube_face::top, 16, 16});
    CHECK(buf.radiance_at(centre) == glm::vec3(0.0f));
    CHECK(buf.distance[centre] == Approx(1.0f / hemicube_texel_direction(32, centre).z).epsilon(1e-5));
    CHECK(buf.flags[centre] == (o == surface_opacity::opaque ? texel_back_face : texel_hit_front));
  }
}

TEST_CASE("opacity: see-through renders are bitwise the same on every path and with occlusion culling", "[opacity]") {
  scene_mesh mesh = checker_scene();
  // Enough opaque triangles behind the card for the culling to matter: a floor grid below the point.
  mesh.add_grid({-4, -4, -0.5f}, {4, -4, -0.5f}, {4, 4, -0.5f}, {-4, 4, -0.5f}, 40, 40, material{});
  material pane = see_through(surface_opacity::translucent);
  pane.transmittance = glm::vec3(0.5f, 0.25f, 1.0f);
  pane.emission = glm::vec3(0.1f, 0.0f, 0.0f);
  add_card(mesh, 0.6f, 0.5f, pane);
  // An opaque wall at x = 0.5 hides part of the card and the pane from points at x < 0.5.
  material wall;
  wall.emission = glm::vec3(0.3f);
  mesh.add_grid({0.5f, -3, 0.1f}, {0.5f, 3, 0.1f}, {0.5f, 3, 3}, {0.5f, -3, 3}, 4, 4, wall);
  mesh.texcoords.resize(mesh.positions.size());
  const auto s = scene::create(mesh.desc());
  const glm::vec3 p(0.3f, -0.2f, 0.0f);
  const frame tilted = make_frame(glm::normalize(glm::vec3(0.3f, 0.2f, 1.0f)));
  for (const frame& f : {up, tilted}) {
    raster_options reference;
    reference.diagnostics.simd = false;
    reference.diagnostics.occlusion_culling = false;
    hemicube_buffer want;
    hemicube_rasterizer(s, reference).render(p, f, 64, want);
    for (int variant = 0; variant < 3; ++variant) {
      raster_options o;
      o.diagnostics.occlusion_min_triangles = 0;
      if (variant == 1) o.diagnostics.avx2 = false;
      if (variant == 2) o.diagnostics.occlusion_culling = false;
      hemicube_buffer got;
      hemicube_rasterizer r(s, o);
      r.render(p, f, 64, got);
      CHECK(same_buffer(want, got));
      if (variant == 0 && f.n.z == 1.0f) CHECK(r.statistics().see_through_occluded > 0);
    }
  }
}

TEST_CASE("opacity: with exact edge coverage a texel an alpha-tested card wins keeps what its centre sees", "[opacity]") {
  const auto s = scene::create(checker_scene().desc());
  raster_options edge;
  edge.edge_coverage = true;
  hemicube_rasterizer point_sampled(s), covered(s, edge);
  hemicube_buffer a, b;
  point_sampled.render({0.05f, -0.03f, 0.0f}, up, 64, a);
  covered.render({0.05f, -0.03f, 0.0f}, up, 64, b);
  std::size_t card = 0, blended = 0;
  const auto cutout = [&](std::uint32_t t) {
    return t != hemicube_rasterizer::no_triangle && s->triangle_material(t).opacity == surface_opacity::alpha_tested;
  };
  for (std::size_t i = 0; i < a.texel_count(); ++i) {
    const bool on_card = cutout(point_sampled.seen_triangle(i));
    CHECK(on_card == cutout(covered.seen_triangle(i)));
    if (on_card) {
      ++card;
      CHECK(b.radiance_at(i) == a.radiance_at(i));
      CHECK(b.distance[i] == a.distance[i]);
    } else if (b.radiance_at(i) != a.radiance_at(i)) {
      ++blended;  // the ceiling's own edges (and the card's geometric edges) may be blended
    }
  }
  CHECK(card > 100);
  CHECK(blended < a.texel_count() / 10);
}

TEST_CASE("opacity: an always-present alpha-tested box renders bitwise as the opaque box (watertight)", "[opacity]") {
  // A closed room of 6 x 6 grids around the point: the see-through pass must cover every texel
  // centre exactly where the opaque paths do (the same planes, so the same depths).
  for (int variant = 0; variant < 2; ++variant) {
    scene_mesh opaque_room, cutout_room;
    material wall;
    wall.emission = glm::vec3(0.25f, 0.5f, 1.0f);
    material cut = wall;
    cut.opacity = variant == 0 ? surface_opacity::alpha_tested : surface_opacity::translucent;
    cut.transmittance = glm::vec3(0.0f);  // a black pane over the sky: what it sends itself
    cut.two_sided = false;
    const glm::vec3 lo(-1.3f, -0.7f, -1.1f), hi(0.9f, 1.6f, 1.4f);
    const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                            {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    const int faces[6][4] = {{0, 1, 2, 3}, {7, 6, 5, 4}, {0, 4, 5, 1}, {2, 6, 7, 3}, {0, 3, 7, 4}, {1, 5, 6, 2}};
    for (const auto& q : faces) {
      opaque_room.add_grid(c[q[0]], c[q[1]], c[q[2]], c[q[3]], 6, 6, wall);
      cutout_room.add_grid(c[q[0]], c[q[1]], c[q[2]], c[q[3]], 6, 6, cut);
    }
    const auto so = scene::create(opaque_room.desc()), sc = scene::create(cutout_room.desc());
    REQUIRE(sc->triangles().empty());
    for (const frame& f : {up, make_frame(glm::normalize(glm::vec3(-0.4f, 0.7f, 0.5f)))}) {
      hemicube_buffer a, b;
      hemicube_rasterizer(so).render({0.1f, 0.2f, -0.05f}, f, 64, a);
      hemicube_rasterizer(sc).render({0.1f, 0.2f, -0.05f}, f, 64, b);
      std::size_t misses = 0;
      for (std::uint8_t fl : b.flags) misses += (fl & texel_miss) ? 1 : 0;
      CHECK(misses == (variant == 0 ? 0u : b.texel_count()));  // a pane never hides the sky
      if (variant == 0) {
        // Radiance and flags bit for bit; distances to within rounding: a texel centre within the
        // opaque paths' snapping (1/512 texel) of an edge may go to the neighbouring triangle of
        // the same wall, whose plane's float coefficients differ in the last bits.
        CHECK(a.radiance == b.radiance);
        CHECK(a.flags == b.flags);
        for (std::size_t i = 0; i < a.texel_count(); ++i) REQUIRE(b.distance[i] == Approx(a.distance[i]).epsilon(1e-5));
      } else {
        CHECK(a.radiance == b.radiance);  // sky 0 x transmittance 0 + the wall's own radiance
      }
    }
  }
}

TEST_CASE("opacity: translucent panes multiply what is behind them and add their own radiance, far to near", "[opacity]") {
  scene_mesh mesh;
  material ceiling;
  ceiling.emission = glm::vec3(1.0f);
  add_card(mesh, 8.0f, 2.0f, ceiling);
  material far_pane = see_through(surface_opacity::translucent), near_pane = far_pane;
  far_pane.transmittance = glm::vec3(0.5f, 0.25f, 1.0f);
  far_pane.emission = glm::vec3(0.1f, 0.0f, 0.0f);
  near_pane.transmittance = glm::vec3(0.5f, 1.0f, 0.75f);
  near_pane.emission = glm::vec3(0.0f, 0.2f, 0.0f);
  add_card(mesh, 1.0f, 0.5f, near_pane);  // added first: the order of the scene does not matter
  add_card(mesh, 1.0f, 1.0f, far_pane);
  const auto s = scene::create(mesh.desc());
  hemicube_rasterizer r(s);
  hemicube_buffer buf;
  r.render({0.0f, 0.0f, 0.0f}, up, 64, buf);
  const glm::vec3 near_only = near_pane.transmittance * glm::vec3(1.0f) + near_pane.emission;
  const glm::vec3 far_first = far_pane.transmittance * glm::vec3(1.0f) + far_pane.emission;
  const glm::vec3 two_panes = near_pane.transmittance * far_first + near_pane.emission;
  std::size_t both = 0, near_alone = 0;
  for (std::size_t i = 0; i < buf.texel_count(); ++i) {
    const glm::dvec3 d(hemicube_texel_direction(64, i));
    if (!(d.z > 0.0)) continue;
    const double x1 = d.x / d.z, y1 = d.y / d.z;  // on the far pane (z = 1)
    const double x5 = 0.5 * x1, y5 = 0.5 * y1;    // on the near pane (z = 0.5), which spans a wider angle
    const auto inside = [](double x, double y, double e) { return std::fabs(x) < 1.0 - e && std::fabs(y) < 1.0 - e; };
    const auto outside = [](double x, double y, double e) { return std::fabs(x) > 1.0 + e || std::fabs(y) > 1.0 + e; };
    INFO("texel " << i);
    glm::vec3 want;
    if (inside(x1, y1, 1e-3)) {  // then inside the near one too
      ++both;
      want = two_panes;
    } else if (outside(x1, y1, 1e-3) && inside(x5, y5, 1e-3)) {
      ++near_alone;
      want = near_only;
    } else {
      continue;
    }
    CHECK(buf.radiance_at(i).x == Approx(want.x).epsilon(1e-6));
    CHECK(buf.radiance_at(i).y == Approx(want.y).epsilon(1e-6));
    CHECK(buf.radiance_at(i).z == Approx(want.z).epsilon(1e-6));
    CHECK(buf.distance[i] == Approx(2.0 / d.z).epsilon(1e-5));  // the ceiling's: panes do not hide it
  }
  CHECK(both > 100);
  CHECK(near_alone > 100);
  CHECK(r.statistics().translucent_fragments > 2 * both);
}

TEST_CASE("opacity: ray queries honour alpha and transmittance, through Embree and the fallback", "[opacity][rays]") {
  scene_mesh mesh = checker_scene();
  material pane = see_through(surface_opacity::translucent);
  pane.transmittance = glm::vec3(0.5f, 0.25f, 1.0f);
  add_card(mesh, 1.0f, -1.0f, pane);  // below the point: a downward ray passes it
  add_card(mesh, 2.0f, -1.5f, pane);
  for (int fallback = 0; fallback < 2; ++fallback) {
    detail::fail_embree_builds_for_testing(fallback == 1);
    const auto s = scene::create(mesh.desc());
    CHECK(detail::rays_use_embree(*s) == (fallback == 0));
    detail::fail_embree_builds_for_testing(false);
    std::size_t checked = 0;
    for (double x = -0.97; x < 1.0; x += 0.0731)
      for (double y = -0.95; y < 1.0; y += 0.0677) {
        bool unsure;
        const bool present = checker_present(x, y, 0.01, unsure);
        if (unsure) continue;
        ++checked;
        const glm::vec3 o(0.0f, 0.0f, 0.0f), d(float(x), float(y), 1.0f);
        INFO("fallback " << fallback << " at (" << x << ", " << y << ")");
        // Up: the card where present, else the ceiling at t = 2.
        ray_hit hit;
        REQUIRE(intersect(*s, o, d, 10.0f, hit));
        CHECK(hit.distance == Approx(present ? 1.0 : 2.0).epsilon(1e-5));
        CHECK(hit.triangle >= (present ? 2u : 0u));
        CHECK(hit.triangle < (present ? 4u : 2u));
        CHECK(occluded(*s, o, d, 1.5f) == present);
        CHECK(transmittance(*s, o, d, 1.5f) == glm::vec3(present ? 0.0f : 1.0f));
        CHECK(transmittance(*s, o, d, 3.0f) == glm::vec3(0.0f));  // the ceiling
        // Down: through both panes; a translucent pane is a surface to occluded() and intersect().
        const glm::vec3 down(float(x), float(y), -1.0f);
        const glm::vec3 t = transmittance(*s, o, down, 10.0f);
        CHECK(t.x == Approx(0.25f));
        CHECK(t.y == Approx(0.0625f));
        CHECK(t.z == Approx(1.0f));
        CHECK(transmittance(*s, o, down, 1.2f).y == Approx(0.25f));
        CHECK(occluded(*s, o, down, 10.0f));
        REQUIRE(intersect(*s, o, down, 10.0f, hit));
        CHECK(hit.distance == Approx(1.0).epsilon(1e-5));
        CHECK(hit.drawable >= s->triangles().size());
      }
    CHECK(checked > 200);
  }
}

namespace {

// A floor over [-2, 2]^2 (z = 0, facing up, lightmap UVs in u [0, 0.5]) under a card at z = 1
// over [-1, 1]^2 (UVs in u [0.5, 1]); `card` is its material. No sky, black surfaces: the
// lightmap is the sun's direct light alone.
struct card_bake {
  test::uv_mesh mesh;
  std::vector<glm::vec2> texcoords;
  std::vector<alpha_image> textures;
  std::vector<alpha_texture> views;

  explicit card_bake(const material& card) {
    material floor;
    floor.albedo = glm::vec3(0.0f);
    mesh.quad({-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}, {0.0f, 0.0f}, {0.5f, 0.0f}, {0.5f, 1.0f}, {0.0f, 1.0f}, floor);
    mesh.quad({-1, -1, 1}, {-1, 1, 1}, {1, 1, 1}, {1, -1, 1}, {0.55f, 0.05f}, {0.55f, 0.95f}, {0.95f, 0.95f}, {0.95f, 0.05f},
              card);
    texcoords.assign(6, glm::vec2(0.0f));
    // The card's two triangles: (a, b, c), (a, c, d) with texcoords (x + 1) / 2, (y + 1) / 2.
    const glm::vec2 ta(0, 0), tb(0, 1), tc(1, 1), td(1, 0);
    texcoords.insert(texcoords.end(), {ta, tb, tc, ta, tc, td});
    textures.push_back(checker_alpha());
    for (const alpha_image& a : textures) views.push_back({a.values.data(), a.width, a.height});
  }
  bake_input input() const {
    bake_input in = mesh.input();
    in.scene.texcoords = texcoords.data();
    in.scene.alpha_textures = views.data();
    in.scene.alpha_texture_count = views.size();
    return in;
  }
};

bake_options sun_options() {
  bake_options o;
  o.width = 128;
  o.height = 64;
  o.bounces = 1;
  o.thread_count = 2;
  light sun;
  sun.type = light_type::directional;
  sun.direction = glm::vec3(0.0f, 0.0f, -1.0f);
  sun.color = glm::vec3(3.0f, 2.0f, 1.0f);
  o.lights.push_back(sun);
  o.shadow_mask_lights = {{0, -1, -1, -1}};
  return o;
}

}  // namespace

TEST_CASE("opacity: a checker card casts the checker's shadow into the lightmap, the shadow mask and probes", "[opacity][bake]") {
  material card = see_through(surface_opacity::alpha_tested);
  card.alpha_texture = 0;
  const card_bake b(card);
  const bake_options o = sun_options();
  const bake_result r = bake_lightmap(b.input(), o);
  // Floor texels (x < 64) whose centre is under the card, away from the cells' edges: the sun
  // (straight down) reaches them exactly where the cell above is open.
  double open_mean = 0.0;
  std::size_t counted = 0, open = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const std::size_t i = std::size_t(y) * 128 + std::size_t(x);
      if (!r.valid[i]) continue;
      const double px = -2.0 + 4.0 * (x + 0.5) / 64.0, py = -2.0 + 4.0 * (y + 0.5) / 64.0;
      if (std::fabs(px) >= 1.0 || std::fabs(py) >= 1.0) continue;
      bool unsure;
      const bool present = checker_present(px, py, 0.2, unsure);
      if (unsure) continue;
      const glm::vec3 e(r.irradiance.pixels[3 * i], r.irradiance.pixels[3 * i + 1], r.irradiance.pixels[3 * i + 2]);
      const float mask = r.shadow_mask.pixels[4 * i];
      INFO("texel (" << x << ", " << y << ")");
      CHECK(e.x == Approx(present ? 0.0 : 3.0).margin(1e-5));
      CHECK(e.z == Approx(present ? 0.0 : 1.0).margin(1e-5));
      CHECK(mask == (present ? 0.0f : 1.0f));
      ++counted;
      open += present ? 0 : 1;
      open_mean += e.x / 3.0;
    }
  REQUIRE(counted > 100);
  // Half the cells are open: the texels away from edges split evenly (8 x 8 cells, 4 texels each).
  CHECK(double(open) / double(counted) == Approx(0.5).margin(0.02));
  CHECK(open_mean / double(counted) == Approx(double(open) / double(counted)).margin(1e-6));

  // Probes at cell centres under the card: the sun's direct part arrives where the cell is open.
  scene_desc d = b.input().scene;
  const auto s = scene::create(d);
  probe_options po;
  po.resolution = 16;
  po.lights = std::make_shared<light_set>(o.lights.data(), o.lights.size());
  std::vector<glm::vec3> points;
  for (int cy = 0; cy < checker_cells; ++cy)
    for (int cx = 0; cx < checker_cells; ++cx)
      points.push_back({-1.0f + 0.25f * (float(cx) + 0.5f), -1.0f + 0.25f * (float(cy) + 0.5f), 0.5f});
  const probe_result pr = sample_probes(s, points.data(), points.size(), po);
  double lit = 0.0;  // the probes' mean up irradiance over the sun's, facing it
  for (std::size_t k = 0; k < points.size(); ++k) {
    const int cx = int(k) % checker_cells, cy = int(k) / checker_cells;
    const bool present = (cx + cy) % 2 == 0;
    // SH9 holds a delta source facing it as 1.0625 x its irradiance (probes.hpp).
    const float up_irradiance = sh9_irradiance(pr.probes[k], {0.0f, 0.0f, 1.0f}).x;
    INFO("probe " << k);
    CHECK(up_irradiance == Approx(present ? 0.0 : 3.0 * 1.0625).margin(1e-4));
    lit += up_irradiance / (3.0 * 1.0625);
  }
  CHECK(lit / double(points.size()) == Approx(0.5).margin(1e-4));  // the fraction of open cells
}

TEST_CASE("opacity: a tinted pane passes sun x transmittance into the lightmap and the shadow mask", "[opacity][bake]") {
  material pane = see_through(surface_opacity::translucent);
  pane.transmittance = glm::vec3(0.5f, 0.25f, 1.0f);
  const card_bake b(pane);
  const bake_result r = bake_lightmap(b.input(), sun_options());
  std::size_t counted = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const std::size_t i = std::size_t(y) * 128 + std::size_t(x);
      const double px = -2.0 + 4.0 * (x + 0.5) / 64.0, py = -2.0 + 4.0 * (y + 0.5) / 64.0;
      if (!r.valid[i] || std::fabs(px) > 0.9 || std::fabs(py) > 0.9) continue;
      ++counted;
      INFO("texel (" << x << ", " << y << ")");
      CHECK(r.irradiance.pixels[3 * i] == Approx(3.0 * 0.5).epsilon(1e-6));
      CHECK(r.irradiance.pixels[3 * i + 1] == Approx(2.0 * 0.25).epsilon(1e-6));
      CHECK(r.irradiance.pixels[3 * i + 2] == Approx(1.0 * 1.0).epsilon(1e-6));
      CHECK(r.shadow_mask.pixels[4 * i] == Approx((0.5 + 0.25 + 1.0) / 3.0).epsilon(1e-6));
    }
  CHECK(counted > 400);
}
