// The C ABI's growable structs (hemilight.h, "Structs that grow") and the one place where each C
// options struct is mapped to its C++ options (not installed). Free of the C ABI's error state, so
// that tests/test_capi_options.cpp can check every field's mapping directly.
#pragma once

#include "hemilight.h"

#include "hemilight/bake.hpp"
#include "hemilight/cache.hpp"
#include "hemilight/cubemap.hpp"
#include "hemilight/unwrap.hpp"

#include <memory>
#include <string>
#include <vector>

namespace hemilight::capi {

/// Copies the caller's options into `out` (which holds the defaults): every field that lies
/// within in->struct_size, the defaults for the others. Returns "" or what is wrong with
/// struct_size ("options->struct_size is 0: ...").
std::string read_sized(const hemilight_cache_options* in, hemilight_cache_options& out);
std::string read_sized(const hemilight_bake_options* in, hemilight_bake_options& out);
std::string read_sized(const hemilight_cubemap_irradiance_options* in, hemilight_cubemap_irradiance_options& out);

/// The defaults, for the whole struct the library knows (struct_size = its sizeof).
hemilight_cache_options default_cache_options();
hemilight_bake_options default_bake_options();
hemilight_cubemap_irradiance_options default_cubemap_irradiance_options();

/// Checks stats->struct_size; returns "" or what is wrong.
std::string check_sized(const hemilight_cache_stats* stats);
std::string check_sized(const hemilight_bake_stats* stats);
/// Writes the fields of `from` that lie within out->struct_size (checked before).
void write_sized(const hemilight_cache_stats& from, hemilight_cache_stats* out);
void write_sized(const hemilight_bake_stats& from, hemilight_bake_stats* out);

/// The sharded bake's info structs: read (the caller's fields within in->struct_size over zeros),
/// checked and written as above; "" or what is wrong with info->struct_size.
std::string read_sized(const hemilight_bake_shard_info* in, hemilight_bake_shard_info& out);
std::string read_sized(const hemilight_bake_pass_state_info* in, hemilight_bake_pass_state_info& out);
std::string check_sized(const hemilight_bake_shard_info* info);
std::string check_sized(const hemilight_bake_pass_state_info* info);
void write_sized(const hemilight_bake_shard_info& from, hemilight_bake_shard_info* out);
void write_sized(const hemilight_bake_pass_state_info& from, hemilight_bake_pass_state_info* out);

/// The C++ options of checked C options (switches already 0 or 1, the weight a known value). The
/// C struct is flat; its fields land in one of three C++ homes: the cache's options (to_cpp), how
/// the call runs (thread_count, progress: cache_run_of) and the sampler's options (resolution,
/// extrapolate_wall_depth, edge_coverage: sampler_options_of).
cache_options to_cpp(const hemilight_cache_options& c);
cache_run cache_run_of(const hemilight_cache_options& c);
sampler_options sampler_options_of(const hemilight_cache_options& c);

/// The C++ bake options of checked C options, with the environment map and the lights already
/// converted (they need checks that name their elements) and the directional outputs asked for.
bake_options to_cpp(const hemilight_bake_options& c, std::shared_ptr<const cubemap> environment, std::vector<light> lights,
                    bool output_sh_l1, bool output_hl2);

/// The filter options of checked C cube-map irradiance options (method and input_size already
/// validated; the method picks the C++ function, so it does not appear here).
filter_options to_cpp(const hemilight_cubemap_irradiance_options& c, edge_fixup mapping);

}  // namespace hemilight::capi

namespace hemilight::capi {

/// hemilight_bake_scene_desc: the defaults (all NULL and 0, emission-only occluders, every triangle
/// opaque), and the caller's fields within its struct_size over them (returns "" or what is wrong
/// with struct_size).
hemilight_bake_scene_desc default_bake_scene_desc();
std::string read_sized(const hemilight_bake_scene_desc* in, hemilight_bake_scene_desc& out);

/// Sets the opacity fields of `m` (opacity, alpha, alpha_cutoff, alpha_texture, transmittance) from
/// a checked C opacity (capi_internal.hpp, opacity_problem); the fields its mode does not use take
/// the C++ defaults. Its other fields are left as they are.
void apply_opacity(const hemilight_opacity& o, material& m);

}  // namespace hemilight::capi

namespace hemilight::capi {

/// hemilight_unwrap_options: the defaults (the C++ defaults), the caller's fields within its
/// struct_size over them, and the C++ options (checked later by validate_unwrap_options).
hemilight_unwrap_options default_unwrap_options();
std::string read_sized(const hemilight_unwrap_options* in, hemilight_unwrap_options& out);
unwrap_options to_cpp(const hemilight_unwrap_options& c);

/// hemilight_unwrap_stats: the struct_size check and the write within it (as for the bake's).
std::string check_sized(const hemilight_unwrap_stats* stats);
void write_sized(const hemilight_unwrap_stats& from, hemilight_unwrap_stats* out);

}  // namespace hemilight::capi
