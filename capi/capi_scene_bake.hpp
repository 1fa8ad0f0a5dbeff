// The steps of a C scene bake that hemilight_bake_scene (capi_bake.cpp) and the sharded bakes
// (capi_shards.cpp) share (not installed): the description and options checked in the caller's
// terms and converted to the C++ input and options, and a result's outputs written to the pages.
#pragma once

#include "hemilight.h"

#include "hemilight/bake.hpp"

#include <memory>

namespace hemilight::capi {

/// A checked C scene bake, ready for the C++ library.
struct scene_bake_call {
  hemilight_bake_scene_desc desc{};     ///< the caller's description over the defaults (its pointers: the caller's memory)
  bool mask = false;                    ///< some options->shadow_mask_lights index names a light
  bool ao = false;                      ///< options->ao_distance > 0
  std::shared_ptr<const void> storage;  ///< the concatenated meshes input.geometry points into
  scene_bake_input input;
  bake_options options;                 ///< with the directional maps some page asks for
};

/// Steps 1 and 2 of hemilight_bake_scene: reads and checks the description, the options, every
/// page (sizes, output buffers and capacities, material images), the AO buffers, the lights, the
/// placements, the opacities and the meshes, naming `fn` and the field; on HEMILIGHT_OK `call`
/// holds the C++ input and options. Otherwise returns the status it set. May throw (run it in
/// guarded).
hemilight_status prepare_scene_bake(const char* fn, const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options,
                                    const hemilight_bake_stats* stats, scene_bake_call& call);

/// Step 4 of hemilight_bake_scene: INVALID_ARGUMENT ("... overflows float") and nothing written
/// when a page is not finite; else every page's buffers, its AO and the statistics (may be NULL).
hemilight_status write_scene_bake(const char* fn, const scene_bake_call& call, const scene_bake_result& r, hemilight_bake_stats* stats);

}  // namespace hemilight::capi
