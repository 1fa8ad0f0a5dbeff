// preview.hpp — a rendered picture of a baked scene for the command-line baker (hemilight_bake
// --preview): what an engine would show, each surface's lightmap (bilinear) times its albedo plus
// its emission, seen from a camera. Rendered with the hemicube rasterizer (raster.hpp): the top
// face of a hemicube at the eye looking at the target is a 90-degree perspective view; a narrower
// field of view is its centre at a higher N. Part of the examples, not of the library.
#pragma once

#include "hemilight/bake.hpp"

#include <string>
#include <vector>

namespace hemilight::preview {

/// A pinhole camera: eye, target (world), vertical and horizontal field of view in degrees (the
/// picture is square), in (0, 90]. up: the world's +y (a camera looking straight up or down
/// uses +z).
struct camera {
  glm::vec3 eye{0.0f}, target{0.0f, 0.0f, -1.0f};
  float fov_degrees = 60.0f;
};

/// Parses "EX,EY,EZ,TX,TY,TZ[,FOV]" (7 or 6 finite numbers, FOV in (0, 90], default 60, eye !=
/// target). Returns false (camera untouched) for anything else.
bool parse_camera(const std::string& text, camera& out);

/// Parses "a,b,c,..." (comma-separated finite floats, no spaces, at least one) into out. Returns
/// false, out unspecified, if an item is empty, not a number or not finite.
bool parse_numbers(const std::string& text, std::vector<float>& out);

/// What a picture shows per lightmap texel of each page: emission + albedo x E / pi, E the
/// page's baked irradiance; albedo and emission from the page's images where it has them, else
/// the area-weighted materials of the page's triangles in the texel. Dilated 2 rings around the
/// covered texels (bilinear lookups at chart borders). `result` must be bake_scene's for `in`.
std::vector<image> page_radiance(const scene_bake_input& in, const scene_bake_result& result);

/// The scene seen from `cam` as a size x size linear RGB image (row 0 at the top): surfaces show
/// their page_radiance (bilinear, clamp-to-edge inside each page, as an engine samples the
/// pages), the sky its radiance, back faces of one-sided triangles black. Occluder-only meshes
/// show black. Throws error(invalid_argument) for size outside [16, 4096] or a bad camera.
/// Cost: one hemicube at N = size / tan(fov / 2) (capped at 4096) plus the radiance textures.
image render(const scene_bake_input& in, const std::vector<image>& radiance, const camera& cam, int size);

/// A default camera for the scene: among views from outside its bounds (four diagonals, 60
/// degrees) and from inside (near each side wall looking across, 75 degrees), the one whose
/// picture hits the most front faces (so a closed room is seen from inside, an object from
/// outside). Cost: eight hemicubes at N = 64.
camera default_camera(const scene_bake_input& in, const std::vector<image>& radiance);

/// Writes a picture (RGB) as an 8-bit sRGB PNG (libpng) with the baker's tone mapping: exposure
/// k = 0.5 / mean_luminance (1 if it is not > 0), Reinhard c k / (1 + c k), sRGB curve. Throws
/// std::runtime_error naming the file on failure.
void write_png(const std::string& path, const image& picture, double mean_luminance);

/// write_png with the mean luminance of all pixels.
void write_png(const std::string& path, const image& picture);

}  // namespace hemilight::preview
