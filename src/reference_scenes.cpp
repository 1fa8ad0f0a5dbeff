#include "hemilight/reference_scenes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace hemilight {

namespace {

material white(float a = 0.7f) { return {glm::vec3(0.0f), glm::vec3(a), false}; }

// A quad (a, b, c, d in order around it) whose front faces along `facing`.
void add_facing(scene_mesh& m, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d,
                const glm::vec3& facing, const material& mat, int nu = 1, int nv = 1) {
  const bool flip = glm::dot(glm::cross(b - a, d - a), facing) < 0.0f;
  m.add_grid(a, b, c, d, nu, nv, mat, flip);
}

// A prism standing on y = 0 over the convex footprint (x, z) given in order, up to `height`:
// the sides face away from the footprint's centre, the top faces up; no bottom.
void add_open_prism(scene_mesh& m, const glm::vec2* footprint, int count, float height, const material& mat) {
  glm::vec2 centre(0.0f);
  for (int i = 0; i < count; ++i) centre += footprint[i] / static_cast<float>(count);
  for (int i = 0; i < count; ++i) {
    const glm::vec2 p = footprint[i], q = footprint[(i + 1) % count];
    const glm::vec2 out = 0.5f * (p + q) - centre;
    add_facing(m, {p.x, 0, p.y}, {q.x, 0, q.y}, {q.x, height, q.y}, {p.x, height, p.y}, {out.x, 0, out.y}, mat);
  }
  // Top: a fan (convex footprint), facing up.
  for (int i = 1; i + 1 < count; ++i) {
    const glm::vec3 a(footprint[0].x, height, footprint[0].y), b(footprint[i].x, height, footprint[i].y),
        c(footprint[i + 1].x, height, footprint[i + 1].y);
    if (glm::cross(b - a, c - a).y >= 0.0f)
      m.add_triangle(a, b, c, mat);
    else
      m.add_triangle(a, c, b, mat);
  }
}

void add_open_box(scene_mesh& m, float x0, float z0, float x1, float z1, float height, const material& mat) {
  const glm::vec2 fp[4] = {{x0, z0}, {x1, z0}, {x1, z1}, {x0, z1}};
  add_open_prism(m, fp, 4, height, mat);
}

// A closed prism between heights y0 and y1 over the regular polygon of `sides` corners of
// circumradius r around (cx, cz), the first corner at angle `phase`: sides face outwards, the
// top faces up, the bottom down.
void add_closed_prism(scene_mesh& m, float cx, float cz, float r, int sides, float phase, float y0, float y1,
                      const material& mat) {
  const double pi = 3.14159265358979323846;
  std::vector<glm::vec2> fp(static_cast<std::size_t>(sides));
  for (int i = 0; i < sides; ++i) {
    const double t = phase + 2.0 * pi * i / sides;
    fp[static_cast<std::size_t>(i)] = {cx + static_cast<float>(r * std::cos(t)), cz + static_cast<float>(r * std::sin(t))};
  }
  for (int i = 0; i < sides; ++i) {
    const glm::vec2 p = fp[static_cast<std::size_t>(i)], q = fp[static_cast<std::size_t>((i + 1) % sides)];
    const glm::vec2 out = 0.5f * (p + q) - glm::vec2(cx, cz);
    add_facing(m, {p.x, y0, p.y}, {q.x, y0, q.y}, {q.x, y1, q.y}, {p.x, y1, p.y}, {out.x, 0, out.y}, mat);
  }
  for (int level = 0; level < 2; ++level) {
    const float y = level ? y1 : y0;
    for (int i = 1; i + 1 < sides; ++i) {
      const glm::vec3 a(fp[0].x, y, fp[0].y), b(fp[static_cast<std::size_t>(i)].x, y, fp[static_cast<std::size_t>(i)].y),
          c(fp[static_cast<std::size_t>(i + 1)].x, y, fp[static_cast<std::size_t>(i + 1)].y);
      const bool up = glm::cross(b - a, c - a).y >= 0.0f;
      if (up == (level == 1))
        m.add_triangle(a, b, c, mat);
      else
        m.add_triangle(a, c, b, mat);
    }
  }
}

// A small deterministic generator (splitmix64): the same scene on every platform.
struct splitmix {
  std::uint64_t state;
  float next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return static_cast<float>(z >> 40) / static_cast<float>(1ull << 24);  // [0, 1)
  }
};

}  // namespace

scene_mesh cornell_box() {
  scene_mesh m;
  const float w = 0.556f, h = 0.5488f, d = 0.5592f;
  const material wall = {glm::vec3(0.0f), {0.725f, 0.71f, 0.68f}, false};
  const material red = {glm::vec3(0.0f), {0.63f, 0.065f, 0.05f}, false};
  const material green = {glm::vec3(0.0f), {0.14f, 0.45f, 0.091f}, false};
  add_facing(m, {0, 0, 0}, {w, 0, 0}, {w, 0, d}, {0, 0, d}, {0, 1, 0}, wall);    // floor
  add_facing(m, {0, h, 0}, {w, h, 0}, {w, h, d}, {0, h, d}, {0, -1, 0}, wall);   // ceiling
  add_facing(m, {0, 0, d}, {w, 0, d}, {w, h, d}, {0, h, d}, {0, 0, -1}, wall);   // back wall
  add_facing(m, {w, 0, 0}, {w, 0, d}, {w, h, d}, {w, h, 0}, {-1, 0, 0}, red);    // left wall (x = w)
  add_facing(m, {0, 0, 0}, {0, 0, d}, {0, h, d}, {0, h, 0}, {1, 0, 0}, green);   // right wall (x = 0)
  const material light = {{17.0f, 12.0f, 4.0f}, glm::vec3(0.78f), false};
  const float ly = h - 0.001f, cx = 0.278f, cz = 0.2795f, hx = 0.065f, hz = 0.0525f;
  add_facing(m, {cx - hx, ly, cz - hz}, {cx + hx, ly, cz - hz}, {cx + hx, ly, cz + hz}, {cx - hx, ly, cz + hz},
             {0, -1, 0}, light);
  const glm::vec2 short_box[4] = {{0.130f, 0.065f}, {0.082f, 0.225f}, {0.240f, 0.272f}, {0.290f, 0.114f}};
  const glm::vec2 tall_box[4] = {{0.423f, 0.247f}, {0.265f, 0.296f}, {0.314f, 0.456f}, {0.472f, 0.406f}};
  add_open_prism(m, short_box, 4, 0.165f, wall);
  add_open_prism(m, tall_box, 4, 0.330f, wall);
  m.sky_radiance = glm::vec3(0.0f);
  return m;
}

scene_mesh hexagon_room(int tessellation) {
  if (tessellation < 1 || tessellation > 64)
    throw_invalid_argument("hexagon_room: tessellation " + std::to_string(tessellation) + " must be in [1, 64]");
  const int t = tessellation;
  scene_mesh m;
  const float radius = 4.0f, height = 3.0f;
  const float split_s[4] = {0.0f, 1.25f / 4.0f, 2.75f / 4.0f, 1.0f};  // window 1.5 m wide, centred
  const float split_h[4] = {0.0f, 0.9f, 2.1f, height};                 // 1.2 m tall, sill at 0.9 m
  const double pi = 3.14159265358979323846;
  glm::vec3 corner[6];
  for (int i = 0; i < 6; ++i)
    corner[i] = {static_cast<float>(radius * std::cos(pi / 3 * i)), 0.0f, static_cast<float>(radius * std::sin(pi / 3 * i))};
  const material mat = white();
  // One expression for every wall point, so shared edges are bit-identical.
  const auto wall_point = [&](int wall, float s, float y) {
    glm::vec3 p = (1.0f - s) * corner[wall] + s * corner[(wall + 1) % 6];
    p.y = y;
    return p;
  };
  for (int wall = 0; wall < 6; ++wall) {
    const glm::vec3 mid = 0.5f * (corner[wall] + corner[(wall + 1) % 6]);
    const glm::vec3 inward(-mid.x, 0.0f, -mid.z);
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        if (wall == 0 && i == 1 && j == 1) continue;  // the window
        add_facing(m, wall_point(wall, split_s[i], split_h[j]), wall_point(wall, split_s[i + 1], split_h[j]),
                   wall_point(wall, split_s[i + 1], split_h[j + 1]), wall_point(wall, split_s[i], split_h[j + 1]), inward,
                   mat, t, t);
      }
  }
  // Floor and ceiling: fans from the axis to the wall's edge points (computed as add_grid does:
  // (1 - s) a + s b between the cell corners), so they meet the walls without T-junctions.
  for (int level = 0; level < 2; ++level) {
    const float y = level == 0 ? 0.0f : height;
    const glm::vec3 centre(0.0f, y, 0.0f);
    for (int wall = 0; wall < 6; ++wall)
      for (int i = 0; i < 3; ++i) {
        const glm::vec3 a = wall_point(wall, split_s[i], y), b = wall_point(wall, split_s[i + 1], y);
        for (int k = 0; k < t; ++k) {
          const float s0 = static_cast<float>(k) / static_cast<float>(t), s1 = static_cast<float>(k + 1) / static_cast<float>(t);
          const glm::vec3 p = (1.0f - s0) * a + s0 * b, q = (1.0f - s1) * a + s1 * b;
          // Corners run counter-clockwise seen from above (+y): (centre, p, q) faces down.
          if (level == 0)
            m.add_triangle(centre, q, p, mat);
          else
            m.add_triangle(centre, p, q, mat);
        }
      }
  }
  m.sky_radiance = glm::vec3(1.0f);
  return m;
}

scene_mesh sky_and_occluders() {
  scene_mesh m;
  add_facing(m, {-10, 0, -10}, {10, 0, -10}, {10, 0, 10}, {-10, 0, 10}, {0, 1, 0}, white(0.5f));
  add_open_box(m, -3.5f, -2.5f, -2.5f, -1.5f, 2.0f, white());
  add_open_box(m, 1.0f, 0.25f, 3.0f, 1.75f, 1.0f, white());
  add_open_box(m, -0.5f, 3.5f, 0.5f, 4.5f, 3.0f, white());
  add_open_box(m, -1.75f, 2.25f, -1.25f, 2.75f, 0.5f, white());
  m.sky_radiance = glm::vec3(1.0f);
  return m;
}

scene_mesh heightfield(std::size_t triangle_count) {
  if (triangle_count > (std::size_t(1) << 27))
    throw_invalid_argument("heightfield: triangle_count " + std::to_string(triangle_count) + " is over 2^27");
  const int k = std::max(1, static_cast<int>(std::lround(std::sqrt(static_cast<double>(triangle_count) / 2.0))));
  scene_mesh m;
  m.positions.reserve(static_cast<std::size_t>(k + 1) * static_cast<std::size_t>(k + 1));
  for (int j = 0; j <= k; ++j)
    for (int i = 0; i <= k; ++i) {
      const float x = -5.0f + 10.0f * static_cast<float>(i) / static_cast<float>(k);
      const float z = -5.0f + 10.0f * static_cast<float>(j) / static_cast<float>(k);
      const float y = 0.3f * std::sin(1.7f * x) * std::cos(1.3f * z) + 0.15f * std::sin(5.1f * x + 2.3f * z);
      m.positions.push_back({x, y, z});
    }
  const auto row = static_cast<std::uint32_t>(k + 1);
  for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(k); ++j)
    for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(k); ++i) {
      const std::uint32_t p00 = j * row + i, p10 = p00 + 1, p01 = p00 + row, p11 = p01 + 1;
      // x right, z towards the viewer seen from above: (p00, p01, p11) is counter-clockwise from +y.
      m.indices.insert(m.indices.end(), {p00, p01, p11, p00, p11, p10});
    }
  m.materials.assign(m.indices.size() / 3, white(0.6f));
  m.sky_radiance = glm::vec3(1.0f);
  return m;
}

scene_mesh many_boxes(std::size_t box_count) {
  if (box_count > (std::size_t(1) << 24))
    throw_invalid_argument("many_boxes: box_count " + std::to_string(box_count) + " is over 2^24");
  scene_mesh m;
  const int cells = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(box_count)))));
  const float cell = 3.0f, half = 0.5f * cell * static_cast<float>(cells);
  add_facing(m, {-half, 0, -half}, {half, 0, -half}, {half, 0, half}, {-half, 0, half}, {0, 1, 0}, white(0.5f));
  splitmix rng{12345};
  for (std::size_t b = 0; b < box_count; ++b) {
    const auto ci = static_cast<float>(b % static_cast<std::size_t>(cells));
    const auto cj = static_cast<float>(b / static_cast<std::size_t>(cells));
    const float wx = 0.2f + 0.8f * rng.next(), wz = 0.2f + 0.8f * rng.next(), hy = 0.2f + 1.8f * rng.next();
    const float x0 = -half + cell * ci + (cell - wx) * rng.next(), z0 = -half + cell * cj + (cell - wz) * rng.next();
    add_open_box(m, x0, z0, x0 + wx, z0 + wz, hy, white());
  }
  m.sky_radiance = glm::vec3(1.0f);
  return m;
}

scene_mesh open_pavilion() {
  scene_mesh m;
  const material stone = white(0.6f), wood = white(0.7f);
  const float octagon = 3.14159265f / 8.0f;  // corners at 22.5 + 45 k degrees: faces along the axes
  m.add_box({-7.0f, -0.3f, -5.0f}, {7.0f, 0.02f, 5.0f}, stone);  // step
  m.add_box({-6.0f, 0.0f, -4.0f}, {6.0f, 0.3f, 4.0f}, stone);    // floor slab, 2 cm into the step
  m.add_box({-6.5f, 3.8f, -4.5f}, {6.5f, 4.2f, 4.5f}, wood);     // roof slab
  for (float x : {-4.5f, -1.5f, 1.5f, 4.5f})
    for (float z : {-2.8f, 2.8f}) {
      add_closed_prism(m, x, z, 0.35f, 8, octagon, 0.28f, 0.5f, stone);  // plinth, 2 cm into the floor
      add_closed_prism(m, x, z, 0.12f, 8, octagon, 0.45f, 3.65f, wood);  // pillar, 5 cm into plinth and capital
      add_closed_prism(m, x, z, 0.25f, 8, octagon, 3.6f, 3.82f, wood);   // capital, 2 cm into the roof
    }
  m.sky_radiance = glm::vec3(1.0f);
  return m;
}

scene_mesh open_street() {
  scene_mesh m;
  add_facing(m, {-20, 0, -8}, {20, 0, -8}, {20, 0, 8}, {-20, 0, 8}, {0, 1, 0}, white(0.5f));
  splitmix rng{2024};
  // Buildings: each side of the street (|z| >= 4) from x = -19 onwards, some flush with the
  // previous one (touching), some with a gap.
  for (int side = 0; side < 2; ++side) {
    float x = -19.0f;
    while (x < 17.0f) {
      const float w = std::min(3.0f + 4.0f * rng.next(), 19.0f - x), d = 4.0f + 5.0f * rng.next();
      const float h = 3.0f + 9.0f * rng.next(), albedo = 0.55f + 0.25f * rng.next();
      const float z0 = side ? 4.0f : -4.0f - d, z1 = side ? 4.0f + d : -4.0f;
      m.add_box({x, -0.01f, std::max(z0, -7.9f)}, {x + w, h, std::min(z1, 7.9f)}, white(albedo));
      x += w + (rng.next() < 0.5f ? 0.0f : 0.5f + 1.5f * rng.next());
    }
  }
  // Lamp posts on bases along both kerbs (z = +-3.4).
  for (int i = 0; i < 8; ++i)
    for (float z : {-3.4f, 3.4f}) {
      const float x = -17.5f + 5.0f * static_cast<float>(i);
      m.add_box({x - 0.2f, -0.01f, z - 0.2f}, {x + 0.2f, 0.15f, z + 0.2f}, white(0.6f));
      m.add_box({x - 0.06f, 0.13f, z - 0.06f}, {x + 0.06f, 3.5f, z + 0.06f}, white(0.7f));
    }
  m.sky_radiance = glm::vec3(1.0f);
  return m;
}

lit_scene hexagon_room_sunlit(int tessellation) {
  lit_scene out;
  out.mesh = hexagon_room(tessellation);
  // The window's wall lies between corners 0 (0 degrees) and 1 (60 degrees): its outward normal
  // points at azimuth 30 degrees. The sun travels inwards along it and 30 degrees down.
  const float az = glm::radians(30.0f), el = glm::radians(30.0f);
  light sun;
  sun.type = light_type::directional;
  sun.direction = glm::vec3(-std::cos(az) * std::cos(el), -std::sin(el), -std::sin(az) * std::cos(el));
  sun.color = glm::vec3(20.0f);
  sun.radius = 0.00465f;
  out.lights.push_back(sun);
  return out;
}

lit_scene cornell_box_rect_light() {
  lit_scene out;
  out.mesh = cornell_box();
  glm::vec3 radiance(0.0f);
  for (material& m : out.mesh.materials)
    if (m.emission != glm::vec3(0.0f)) {
      radiance = m.emission;
      m.emission = glm::vec3(0.0f);
    }
  light rect;
  rect.type = light_type::rect;
  rect.position = glm::vec3(0.278f, 0.5478f, 0.2795f);
  rect.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  rect.tangent = glm::vec3(1.0f, 0.0f, 0.0f);
  rect.width = 0.13f;
  rect.height = 0.105f;
  rect.color = radiance;
  out.lights.push_back(rect);
  return out;
}

}  // namespace hemilight
