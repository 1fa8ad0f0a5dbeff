// hemilight/reference_scenes.hpp — the reference scenes of the project, by name.
//
// Every builder returns a scene_mesh (scene.hpp): pass mesh.desc() to scene::create(). They are
// deterministic (no global state, fixed pseudo-random sequences), in metres, with +y up, and
// closed where the description says so: shared edges are built from bit-identical vertices (no
// T-junctions, scene_mesh::add_grid), so the rasterizer sees no cracks. Surfaces face the space
// they light: room walls, floors and ceilings face into the room, boxes face outwards, ground
// planes and heightfields face up (+y). Hidden faces (box bottoms standing on a floor) are left
// out, so no back face lies on a visible surface.
#pragma once

#include "hemilight/lights.hpp"
#include "hemilight/scene.hpp"

#include <cstddef>

namespace hemilight {

/// The Cornell box: the measured room 0.556 (x) by 0.5488 (y) by 0.5592 (z) m, floor at y = 0,
/// back wall at z = 0.5592, open front at z = 0; red wall at x = 0.556 (albedo 0.63, 0.065, 0.05),
/// green wall at x = 0 (0.14, 0.45, 0.091), the rest white (0.725, 0.71, 0.68). The light: a
/// 0.13 x 0.105 m quad facing down at y = 0.5478 (1 mm under the ceiling), centred at
/// x = 0.278, z = 0.2795, emitting (17, 12, 4). The short and tall boxes use the measured
/// footprints (five faces each). Sky (seen through the open front) 0. 32 triangles.
scene_mesh cornell_box();

/// The hexagon room: a regular hexagonal prism, circumradius 4 m (so 4 m walls), floor y = 0,
/// ceiling y = 3, centred on the y axis (corner i at angle 60 i degrees in the x-z plane). The wall
/// between corners 0 and 1 has a window 1.5 m wide and 1.2 m tall (sill at 0.9 m), centred in the
/// wall: a hole, through which the sky (radiance 1, 1, 1) is seen. All surfaces white (albedo 0.7),
/// nothing emits: the room is lit by the sky only, the ceiling only indirectly.
/// Walls are split at the window's edges into 3 x 3 cells, each cell into `tessellation`^2 quads;
/// floor and ceiling are fans matching the wall edges. Triangles: 106 t^2 + 36 t
/// (t = 1: 142, t = 2: 496, t = 3: 1062). Throws error(invalid_argument) unless 1 <= t <= 64.
scene_mesh hexagon_room(int tessellation = 1);

/// Sky and occluders: a 20 x 20 m ground (albedo 0.5) at y = 0 facing up, four boxes standing on
/// it (albedo 0.7, five faces each, tallest 3 m), sky radiance (1, 1, 1). 42 triangles.
scene_mesh sky_and_occluders();

/// A bumpy heightfield facing up over [-5, 5]^2 m (x, z), heights within +-0.45 m, a k x k grid
/// of quads with k = max(1, round(sqrt(triangle_count / 2))), so about `triangle_count`
/// triangles (exactly 2 k^2). Albedo 0.6, sky (1, 1, 1). Throws error(invalid_argument) for a
/// count over 2^27.
scene_mesh heightfield(std::size_t triangle_count);

/// `box_count` boxes (five faces each, 10 triangles) of pseudo-random sizes (0.2 to 1 m wide, 0.2
/// to 2 m tall) standing on a square ground (2 triangles) of side 3 sqrt(box_count) m, one box per
/// 3 x 3 m cell at a pseudo-random offset. 10 box_count + 2 triangles; albedo 0.7, sky (1, 1, 1).
/// Throws error(invalid_argument) for a count over 2^24.
scene_mesh many_boxes(std::size_t box_count);

/// Open pavilion (the traits of a low-poly game asset under an open sky): a floor slab 12 x 8 x
/// 0.3 m (y = 0 .. 0.3) set 2 cm into a wider step slab (14 x 10 m, y = -0.3 .. 0.02), a roof slab
/// 13 x 9 x 0.4 m (y = 3.8 .. 4.2), and eight thin pillars (octagonal prisms, circumradius 0.12 m)
/// at x = -4.5, -1.5, 1.5, 4.5 and z = -2.8, 2.8, each standing on an octagonal plinth (0.35 m,
/// y = 0.28 .. 0.5, 2 cm into the floor) and topped by an octagonal capital (0.25 m, y = 3.6 ..
/// 3.82, 2 cm into the roof); pillars reach 5 cm into plinth and capital. Every part is a closed
/// solid (caps included), so where parts meet, surface points lie inside geometry (the floor under
/// a plinth, the plinth top under its pillar, the roof above a capital), as in real assets. Slabs
/// are boxes of 12 large triangles; 708 triangles in all. Albedo 0.7 (floor and step 0.6), nothing
/// emits, sky (1, 1, 1) on all sides (also below the step).
scene_mesh open_pavilion();

/// Open street: a 40 x 16 m ground (two triangles, albedo 0.5) at y = 0 under the sky (1, 1, 1),
/// two rows of closed buildings (boxes of pseudo-random size, 3 to 7 m wide, 4 to 9 m deep, 3 to 12 m
/// tall, albedo 0.55 to 0.8) set 1 cm into the ground along both sides of an 8 m street, some of
/// them touching, and sixteen thin closed lamp posts (0.12 x 0.12 x 3.5 m, each on a 0.4 x 0.4 x
/// 0.15 m base) along both kerbs. Every part is a closed box, so ground texels under buildings,
/// bases and posts are inside geometry. Deterministic; 2 + 12 x (buildings + 32) triangles.
scene_mesh open_street();

/// A reference scene lit by analytic lights (lights.hpp) as well as by what its triangles emit.
struct lit_scene {
  scene_mesh mesh;
  std::vector<light> lights;
};

/// The hexagon room (hexagon_room(tessellation), sky 1) with a soft sun shining in through its
/// window: direction of travel 30 degrees below the horizon, straight in through the window's wall
/// (azimuth 30 degrees + 180), irradiance 20 W/m^2 facing it (about 6 x the sky's pi on a
/// horizontal plane), angular radius 0.00465 rad (the sun's).
lit_scene hexagon_room_sunlit(int tessellation = 1);

/// The Cornell box with its ceiling light as a RECT light (the same 0.13 x 0.105 m rectangle, lit
/// side down, radiance (17, 12, 4)); the quad stays in the scene as a surface (albedo 0.78) but
/// emits nothing, so the light is not counted twice.
lit_scene cornell_box_rect_light();

}  // namespace hemilight
