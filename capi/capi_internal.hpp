// Shared by the C ABI's implementation files (not installed): status conversion, the
// thread-local last error, and the exception guard every entry point runs in.
#pragma once

#include "hemilight.h"

#include "hemilight/error.hpp"
#include "hemilight/cubemap.hpp"
#include "hemilight/geometry.hpp"
#include "hemilight/lights.hpp"
#include "hemilight/scene.hpp"

#include <memory>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <vector>

/// The opaque scene handle of the C ABI: a shared, immutable C++ scene.
struct hemilight_scene {
  std::shared_ptr<const hemilight::scene> scene;
  std::shared_ptr<const hemilight::cubemap> sky;  ///< optional environment sky (null: the scene's constant sky)
  std::shared_ptr<const hemilight::light_set> lights;  ///< optional lights (null: none)
  bool edge_coverage = false;  ///< hemicubes with exact edge coverage (hemilight_scene_with_edge_coverage)
};

namespace hemilight::capi {

/// Stores `message` as the calling thread's last error and returns `code`.
hemilight_status set_error(hemilight_status code, std::string message);

/// set_error(HEMILIGHT_ERROR_INVALID_ARGUMENT, "function: what").
hemilight_status invalid(const char* function, const std::string& what);

inline hemilight_status to_c(status s) { return static_cast<hemilight_status>(static_cast<int>(s)); }

/// A C++ error's message in the C caller's terms: "read_exr: 'x.exr': ..." becomes
/// "hemilight_exr_load_rgb: 'x.exr': ..." (the leading C++ function name, if any, replaced by the C
/// function's); messages that already name a C function are kept.
inline std::string c_message(const char* function, const std::string& m) {
  if (m.compare(0, 10, "hemilight_") == 0) return m;
  const std::size_t colon = m.find(": ");
  if (colon != std::string::npos && m.find(' ') > colon) return std::string(function) + ": " + m.substr(colon + 2);
  return std::string(function) + ": " + m;
}

/// Runs f() (which returns HEMILIGHT_OK or a status it set) and turns every exception into a
/// status with a message: hemilight::error keeps its code (its message named after the C
/// function: c_message), bad_alloc is OUT_OF_MEMORY, anything else is INTERNAL. No exception leaves.
template <class F>
hemilight_status guarded(const char* function, F&& f) noexcept {
  try {
    return f();
  } catch (const error& e) {
    return set_error(to_c(e.code()), c_message(function, e.what()));
  } catch (const std::bad_alloc&) {
    return set_error(HEMILIGHT_ERROR_OUT_OF_MEMORY, std::string(function) + ": out of memory");
  } catch (const std::exception& e) {
    return set_error(HEMILIGHT_ERROR_INTERNAL, std::string(function) + ": internal error: " + e.what());
  } catch (...) {
    return set_error(HEMILIGHT_ERROR_INTERNAL, std::string(function) + ": internal error (unknown exception)");
  }
}

/// The int a C caller passed as an enum. Read through memcpy: in C++ merely loading an enum object
/// whose value is outside the enumerators' range (say -1) is undefined behaviour, and C callers
/// may pass any int.
template <class E>
int enum_value(const E& e) noexcept {
  static_assert(sizeof(E) == sizeof(int), "C enums are int-sized on every supported ABI");
  int v = 0;
  std::memcpy(&v, &e, sizeof v);
  return v;
}

/// HEMILIGHT_OK, or INVALID_ARGUMENT with "function: <name> N is invalid: it must be even and in
/// [2, 4096]" (the rule's one message: hemicube_resolution_problem, geometry.hpp) when N is not a
/// valid hemicube resolution. `name`: the argument in the C caller's terms.
inline hemilight_status check_resolution(const char* function, int resolution, const char* name = "resolution") {
  if (is_valid_hemicube_resolution(resolution)) return HEMILIGHT_OK;
  return invalid(function, hemicube_resolution_problem(resolution, name));
}

/// The C lights as C++ lights, checked: on a bad one, sets the error "function: what[i].field ..."
/// (what = "lights" or "options->lights") and returns INVALID_ARGUMENT; else HEMILIGHT_OK.
hemilight_status to_lights(const char* function, const char* what, const hemilight_light* lights, std::size_t count,
                           std::vector<light>& out);

/// The checks of a C mesh's arrays that hemilight_scene_create and the bake entries share, in the
/// caller's terms. "" or what is wrong with 3 * vertex_count positions named `name` ("positions",
/// "meshes[1].positions"): "<name>[4] (vertex 1) = nan; it must be finite and at most 1e18 in
/// magnitude".
std::string positions_problem(const float* positions, std::size_t vertex_count, const std::string& name);
/// "" or what is wrong with 3 * triangle_count vertex indices named `name`: "<name>[8] = 900 is out
/// of range: 7 vertices".
std::string indices_problem(const std::uint32_t* indices, std::size_t triangle_count, std::size_t vertex_count,
                            const std::string& name);

/// The largest side of an alpha texture (scene.hpp, alpha_texture: each side in [1, 16384]).
inline constexpr int max_alpha_texture_size = 16384;

/// The checks of the C opacities (hemilight.h, "opacity") that hemilight_scene_with_opacity and
/// hemilight_bake_scene share, in the caller's terms (capi_opacity.cpp; the mapping to the C++
/// material: capi_options.hpp, apply_opacity). Each check returns "" or what is wrong.
/// `count` textures named `name` ("alpha_textures", "scene->alpha_textures"): NULL with a count,
/// a side outside [1, 16384], NULL values ("<name>[1]: width x height = 0 x 4 is invalid ...").
std::string alpha_textures_problem(const hemilight_alpha_texture* textures, std::size_t count, const std::string& name);
/// One opacity named `name` ("opacities[5]"): the fields its mode uses ("<name>.alpha_cutoff = 1.5
/// is outside [0, 1]"), its texture index against alpha_texture_count (the textures named
/// `textures_name`), a texture without texcoords (named `texcoords_name`), an unknown mode.
std::string opacity_problem(const hemilight_opacity& o, const std::string& name, std::size_t alpha_texture_count,
                            const std::string& textures_name, bool has_texcoords, const std::string& texcoords_name);
/// NULL, or 2 * vertex_count finite floats named `name` ("<name>[7] (vertex 3, v) = nan; it must be finite").
std::string texcoords_problem(const float* texcoords, std::size_t vertex_count, const std::string& name);
/// The C++ views of checked C alpha textures (the caller's memory).
std::vector<alpha_texture> alpha_texture_views(const hemilight_alpha_texture* textures, std::size_t count);

/// True if all `count` floats are finite.
inline bool all_finite(const float* v, std::size_t count) noexcept {
  for (std::size_t i = 0; i < count; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

}  // namespace hemilight::capi
