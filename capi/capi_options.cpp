// Growable C structs and the C-to-C++ options mappings (capi_options.hpp).
#include "capi_options.hpp"

#include <algorithm>
#include <cstddef>
#include <cstring>

namespace hemilight::capi {

namespace {

// Where a field lies in its struct.
struct span {
  std::size_t offset, size;
};
#define HEMILIGHT_SPAN(T, f) span { offsetof(T, f), sizeof(static_cast<T*>(nullptr)->f) }

// Fields of each growable struct, in order. A later version appends fields that start at or
// after the previous version's sizeof (so they never lie in an older caller's tail padding):
// when a struct grows, add its old size to the static_asserts below.
const span cache_options_fields[] = {
    HEMILIGHT_SPAN(hemilight_cache_options, struct_size), HEMILIGHT_SPAN(hemilight_cache_options, resolution),
    HEMILIGHT_SPAN(hemilight_cache_options, error_threshold), HEMILIGHT_SPAN(hemilight_cache_options, min_radius),
    HEMILIGHT_SPAN(hemilight_cache_options, max_radius), HEMILIGHT_SPAN(hemilight_cache_options, use_gradients),
    HEMILIGHT_SPAN(hemilight_cache_options, thread_count), HEMILIGHT_SPAN(hemilight_cache_options, progress),
    HEMILIGHT_SPAN(hemilight_cache_options, progress_user), HEMILIGHT_SPAN(hemilight_cache_options, weight),
    HEMILIGHT_SPAN(hemilight_cache_options, gradient_radius_limit), HEMILIGHT_SPAN(hemilight_cache_options, neighbour_clamp),
    HEMILIGHT_SPAN(hemilight_cache_options, shrink_disagreeing), HEMILIGHT_SPAN(hemilight_cache_options, refine_disagreement),
    HEMILIGHT_SPAN(hemilight_cache_options, second_opinion), HEMILIGHT_SPAN(hemilight_cache_options, nearby_opinion),
    HEMILIGHT_SPAN(hemilight_cache_options, sole_record_reach), HEMILIGHT_SPAN(hemilight_cache_options, invalid_backface_fraction),
    HEMILIGHT_SPAN(hemilight_cache_options, extrapolate_wall_depth), HEMILIGHT_SPAN(hemilight_cache_options, second_order),
    HEMILIGHT_SPAN(hemilight_cache_options, edge_coverage)};  // (reserved0 is padding: never read)
const span bake_options_fields[] = {
    HEMILIGHT_SPAN(hemilight_bake_options, struct_size), HEMILIGHT_SPAN(hemilight_bake_options, width),
    HEMILIGHT_SPAN(hemilight_bake_options, height), HEMILIGHT_SPAN(hemilight_bake_options, resolution),
    HEMILIGHT_SPAN(hemilight_bake_options, bounces), HEMILIGHT_SPAN(hemilight_bake_options, indirect_only),
    HEMILIGHT_SPAN(hemilight_bake_options, error_threshold), HEMILIGHT_SPAN(hemilight_bake_options, min_coverage),
    HEMILIGHT_SPAN(hemilight_bake_options, dilation), HEMILIGHT_SPAN(hemilight_bake_options, use_cache),
    HEMILIGHT_SPAN(hemilight_bake_options, thread_count), HEMILIGHT_SPAN(hemilight_bake_options, sky_radiance),
    HEMILIGHT_SPAN(hemilight_bake_options, progress), HEMILIGHT_SPAN(hemilight_bake_options, progress_user),
    HEMILIGHT_SPAN(hemilight_bake_options, environment_rgb), HEMILIGHT_SPAN(hemilight_bake_options, environment_size),
    HEMILIGHT_SPAN(hemilight_bake_options, lights), HEMILIGHT_SPAN(hemilight_bake_options, light_count),
    HEMILIGHT_SPAN(hemilight_bake_options, shadow_mask_lights), HEMILIGHT_SPAN(hemilight_bake_options, shadow_mask_rgba),
    HEMILIGHT_SPAN(hemilight_bake_options, shadow_mask_capacity), HEMILIGHT_SPAN(hemilight_bake_options, edge_coverage),
    HEMILIGHT_SPAN(hemilight_bake_options, strict), HEMILIGHT_SPAN(hemilight_bake_options, stitch_seams),
    HEMILIGHT_SPAN(hemilight_bake_options, ao_distance), HEMILIGHT_SPAN(hemilight_bake_options, ao),
    HEMILIGHT_SPAN(hemilight_bake_options, ao_capacity)};
// (reserved1 to reserved4 are padding: never read)
const span cache_stats_fields[] = {HEMILIGHT_SPAN(hemilight_cache_stats, struct_size), HEMILIGHT_SPAN(hemilight_cache_stats, hemicubes),
                                   HEMILIGHT_SPAN(hemilight_cache_stats, records), HEMILIGHT_SPAN(hemilight_cache_stats, seconds),
                                   HEMILIGHT_SPAN(hemilight_cache_stats, invalid_samples)};
const span bake_stats_fields[] = {
    HEMILIGHT_SPAN(hemilight_bake_stats, struct_size), HEMILIGHT_SPAN(hemilight_bake_stats, sampled_texels),
    HEMILIGHT_SPAN(hemilight_bake_stats, invalid_texels), HEMILIGHT_SPAN(hemilight_bake_stats, dilated_texels),
    HEMILIGHT_SPAN(hemilight_bake_stats, overlapping_texels), HEMILIGHT_SPAN(hemilight_bake_stats, hemicubes),
    HEMILIGHT_SPAN(hemilight_bake_stats, records), HEMILIGHT_SPAN(hemilight_bake_stats, seconds),
    HEMILIGHT_SPAN(hemilight_bake_stats, degenerate_triangles), HEMILIGHT_SPAN(hemilight_bake_stats, no_uv_area_triangles),
    HEMILIGHT_SPAN(hemilight_bake_stats, first_no_uv_area_mesh), HEMILIGHT_SPAN(hemilight_bake_stats, first_no_uv_area_triangle),
    HEMILIGHT_SPAN(hemilight_bake_stats, clamped_uvs), HEMILIGHT_SPAN(hemilight_bake_stats, seam_texels),
    HEMILIGHT_SPAN(hemilight_bake_stats, stitch_seconds)};
const span cubemap_irradiance_options_fields[] = {
    HEMILIGHT_SPAN(hemilight_cubemap_irradiance_options, struct_size),
    HEMILIGHT_SPAN(hemilight_cubemap_irradiance_options, method),
    HEMILIGHT_SPAN(hemilight_cubemap_irradiance_options, input_size),
    HEMILIGHT_SPAN(hemilight_cubemap_irradiance_options, thread_count)};
// The sharded bake's info structs (capi_shards.cpp), fields in order (reserved0 is padding: set to 0 by _init and _get, its value
// never used). A later version appends fields that start at or after this version's sizeof (88
// and 40 bytes on LP64).
const span shard_info_fields[] = {
    HEMILIGHT_SPAN(hemilight_bake_shard_info, struct_size),    HEMILIGHT_SPAN(hemilight_bake_shard_info, key),
    HEMILIGHT_SPAN(hemilight_bake_shard_info, pass),           HEMILIGHT_SPAN(hemilight_bake_shard_info, shard),
    HEMILIGHT_SPAN(hemilight_bake_shard_info, shard_count),    HEMILIGHT_SPAN(hemilight_bake_shard_info, reserved0),
    HEMILIGHT_SPAN(hemilight_bake_shard_info, sample_count),
    HEMILIGHT_SPAN(hemilight_bake_shard_info, channel_count),  HEMILIGHT_SPAN(hemilight_bake_shard_info, hemicubes),
    HEMILIGHT_SPAN(hemilight_bake_shard_info, records),        HEMILIGHT_SPAN(hemilight_bake_shard_info, invalid_samples),
    HEMILIGHT_SPAN(hemilight_bake_shard_info, seconds),        HEMILIGHT_SPAN(hemilight_bake_shard_info, direct_seconds)};
const span state_info_fields[] = {
    HEMILIGHT_SPAN(hemilight_bake_pass_state_info, struct_size), HEMILIGHT_SPAN(hemilight_bake_pass_state_info, key),
    HEMILIGHT_SPAN(hemilight_bake_pass_state_info, pass),        HEMILIGHT_SPAN(hemilight_bake_pass_state_info, shard_count),
    HEMILIGHT_SPAN(hemilight_bake_pass_state_info, width),       HEMILIGHT_SPAN(hemilight_bake_pass_state_info, height),
    HEMILIGHT_SPAN(hemilight_bake_pass_state_info, pass_count)};
static_assert(sizeof(void*) != 8 || sizeof(hemilight_bake_shard_info) == 88, "hemilight_bake_shard_info changed: append only");
static_assert(sizeof(void*) != 8 || sizeof(hemilight_bake_pass_state_info) == 40, "hemilight_bake_pass_state_info changed: append only");

#undef HEMILIGHT_SPAN

// The sizes of this ABI's layouts (x86-64 and every LP64 ABI). A struct that grows keeps its old
// size here and its new fields start at or after it: edge_coverage was appended to the cache
// options of 96 bytes (after the padding field reserved0, since offset 92 was the old layout's
// tail padding) and to the bake options of 144; strict to the bake options of 152 (after the
// padding field reserved1); stitch_seams to the bake options of 160 (after the padding field
// reserved2); ao_distance, ao and ao_capacity to the bake options of 168 (after the padding field
// reserved3; reserved4 aligns the pointer); the bake statistics' input counts to the statistics
// of 64, the seam counts to those of 104.
static_assert(sizeof(void*) != 8 || sizeof(hemilight_cache_options) == 104, "hemilight_cache_options changed: see above");
static_assert(sizeof(void*) != 8 || offsetof(hemilight_cache_options, edge_coverage) >= 96,
              "hemilight_cache_options: edge_coverage must start past the earlier layout's sizeof");
static_assert(sizeof(void*) != 8 || sizeof(hemilight_bake_options) == 192, "hemilight_bake_options changed: see above");
static_assert(sizeof(void*) != 8 || offsetof(hemilight_bake_options, edge_coverage) >= 144,
              "hemilight_bake_options: edge_coverage must start past the earlier layout's sizeof");
static_assert(sizeof(void*) != 8 || offsetof(hemilight_bake_options, strict) >= 152,
              "hemilight_bake_options: strict must start past the earlier layout's sizeof");
static_assert(sizeof(void*) != 8 || offsetof(hemilight_bake_options, stitch_seams) >= 160,
              "hemilight_bake_options: stitch_seams must start past the earlier layout's sizeof");
static_assert(sizeof(void*) != 8 || offsetof(hemilight_bake_options, ao_distance) >= 168,
              "hemilight_bake_options: ao_distance must start past the earlier layout's sizeof");
static_assert(sizeof(void*) != 8 || sizeof(hemilight_cache_stats) == 40, "hemilight_cache_stats changed: see above");
static_assert(sizeof(void*) != 8 || sizeof(hemilight_bake_stats) == 120, "hemilight_bake_stats changed: see above");
static_assert(sizeof(void*) != 8 || offsetof(hemilight_bake_stats, degenerate_triangles) >= 64,
              "hemilight_bake_stats: the input counts must start past the earlier layout's sizeof");
static_assert(sizeof(void*) != 8 || offsetof(hemilight_bake_stats, seam_texels) >= 104,
              "hemilight_bake_stats: the seam counts must start past the earlier layout's sizeof");
static_assert(sizeof(void*) != 8 || sizeof(hemilight_cubemap_irradiance_options) == 24,
              "hemilight_cubemap_irradiance_options changed: see above");

template <std::size_t K>
void copy_fields(const span (&fields)[K], const void* from, void* to, std::size_t size) {
  for (const span& f : fields)
    if (f.offset + f.size <= size)
      std::memcpy(static_cast<char*>(to) + f.offset, static_cast<const char*>(from) + f.offset, f.size);
}

std::string size_problem(const char* what, const char* init, std::size_t size, std::size_t known) {
  if (size < sizeof(std::size_t))
    return std::string(what) + "->struct_size is " + std::to_string(size) + ": fill the struct with " + init + " first";
  if (size > known)
    return std::string(what) + "->struct_size is " + std::to_string(size) + " but this library knows " + std::to_string(known) +
           " bytes: the program was built against a newer hemilight.h than this libhemilight_c (link it with that version)";
  return {};
}

template <class T, std::size_t K>
std::string read(const T* in, T& out, const span (&fields)[K], const char* init) {
  const std::string problem = size_problem("options", init, in->struct_size, sizeof(T));
  if (!problem.empty()) return problem;
  copy_fields(fields, in, &out, in->struct_size);
  return {};
}

}  // namespace

hemilight_cache_options default_cache_options() {
  hemilight_cache_options o;
  std::memset(&o, 0, sizeof o);
  o.struct_size = sizeof o;
  o.resolution = 64;
  o.error_threshold = 0.2f;
  o.min_radius = 0.0f;
  o.max_radius = 0.0f;
  o.use_gradients = 1;
  o.thread_count = 0;
  o.progress = nullptr;
  o.progress_user = nullptr;
  const cache_options d;
  o.weight = HEMILIGHT_CACHE_WEIGHT_WARD;
  o.gradient_radius_limit = d.expert.limit_radius_by_gradient ? 1 : 0;
  o.neighbour_clamp = d.expert.limit_radius_by_neighbours ? 1 : 0;
  o.shrink_disagreeing = d.expert.shrink_disagreeing_records ? 1 : 0;
  o.refine_disagreement = d.expert.refine_where_records_disagree ? 1 : 0;
  o.second_opinion = d.expert.lone_record_change_limit;
  o.nearby_opinion = d.expert.lone_record_neighbour_reach;
  o.sole_record_reach = d.expert.lone_record_reach;
  o.invalid_backface_fraction = d.invalid_backface_fraction;
  o.extrapolate_wall_depth = integrate_options{}.extrapolate_wall_depth ? 1 : 0;
  o.second_order = d.second_order ? 1 : 0;
  o.edge_coverage = raster_options{}.edge_coverage ? 1 : 0;
  return o;
}

hemilight_bake_options default_bake_options() {
  hemilight_bake_options o;
  std::memset(&o, 0, sizeof o);
  o.struct_size = sizeof o;
  o.width = o.height = 256;
  o.resolution = 64;
  o.bounces = 1;
  o.indirect_only = 0;
  o.error_threshold = 0.2f;
  o.min_coverage = 0.01f;
  o.dilation = 16;
  o.use_cache = 1;
  o.thread_count = 0;
  o.progress = nullptr;
  o.progress_user = nullptr;
  o.environment_rgb = nullptr;
  o.environment_size = 0;
  o.lights = nullptr;
  o.light_count = 0;
  for (int& l : o.shadow_mask_lights) l = -1;
  o.shadow_mask_rgba = nullptr;
  o.shadow_mask_capacity = 0;
  o.edge_coverage = bake_options{}.sampler.raster.edge_coverage ? 1 : 0;
  o.strict = bake_options{}.strict ? 1 : 0;
  o.stitch_seams = bake_options{}.stitch_seams ? 1 : 0;
  o.ao_distance = bake_options{}.ao_distance;
  o.ao = nullptr;
  o.ao_capacity = 0;
  return o;
}

hemilight_cubemap_irradiance_options default_cubemap_irradiance_options() {
  hemilight_cubemap_irradiance_options o;
  std::memset(&o, 0, sizeof o);
  o.struct_size = sizeof o;
  const filter_options d;
  o.method = HEMILIGHT_IRRADIANCE_FILTER;
  o.input_size = d.irradiance_input_size;
  o.thread_count = d.thread_count;
  return o;
}

std::string read_sized(const hemilight_cache_options* in, hemilight_cache_options& out) {
  return read(in, out, cache_options_fields, "hemilight_cache_options_init");
}
std::string read_sized(const hemilight_bake_options* in, hemilight_bake_options& out) {
  return read(in, out, bake_options_fields, "hemilight_bake_options_init");
}

std::string read_sized(const hemilight_cubemap_irradiance_options* in, hemilight_cubemap_irradiance_options& out) {
  return read(in, out, cubemap_irradiance_options_fields, "hemilight_cubemap_irradiance_options_init");
}

std::string check_sized(const hemilight_cache_stats* stats) {
  return size_problem("stats", "hemilight_cache_stats_init", stats->struct_size, sizeof *stats);
}
std::string check_sized(const hemilight_bake_stats* stats) {
  return size_problem("stats", "hemilight_bake_stats_init", stats->struct_size, sizeof *stats);
}

void write_sized(const hemilight_cache_stats& from, hemilight_cache_stats* out) {
  const std::size_t size = out->struct_size;
  copy_fields(cache_stats_fields, &from, out, size);
  out->struct_size = size;
}
void write_sized(const hemilight_bake_stats& from, hemilight_bake_stats* out) {
  const std::size_t size = out->struct_size;
  copy_fields(bake_stats_fields, &from, out, size);
  out->struct_size = size;
}

// The info structs: read over zeros (struct_size the caller's), checked and written like the stats.
std::string read_sized(const hemilight_bake_shard_info* in, hemilight_bake_shard_info& out) {
  out = hemilight_bake_shard_info{};
  const std::string problem = size_problem("info", "hemilight_bake_shard_info_init", in->struct_size, sizeof out);
  if (!problem.empty()) return problem;
  copy_fields(shard_info_fields, in, &out, in->struct_size);
  return {};
}
std::string read_sized(const hemilight_bake_pass_state_info* in, hemilight_bake_pass_state_info& out) {
  out = hemilight_bake_pass_state_info{};
  const std::string problem = size_problem("info", "hemilight_bake_pass_state_info_init", in->struct_size, sizeof out);
  if (!problem.empty()) return problem;
  copy_fields(state_info_fields, in, &out, in->struct_size);
  return {};
}
std::string check_sized(const hemilight_bake_shard_info* info) {
  return size_problem("info", "hemilight_bake_shard_info_init", info->struct_size, sizeof *info);
}
std::string check_sized(const hemilight_bake_pass_state_info* info) {
  return size_problem("info", "hemilight_bake_pass_state_info_init", info->struct_size, sizeof *info);
}
void write_sized(const hemilight_bake_shard_info& from, hemilight_bake_shard_info* out) {
  const std::size_t size = out->struct_size;
  copy_fields(shard_info_fields, &from, out, size);
  out->struct_size = size;
}
void write_sized(const hemilight_bake_pass_state_info& from, hemilight_bake_pass_state_info* out) {
  const std::size_t size = out->struct_size;
  copy_fields(state_info_fields, &from, out, size);
  out->struct_size = size;
}

cache_options to_cpp(const hemilight_cache_options& c) {
  cache_options o;
  o.error_threshold = c.error_threshold;
  o.min_radius = c.min_radius;
  o.max_radius = c.max_radius;
  o.use_gradients = c.use_gradients == 1;
  int weight = 0;
  std::memcpy(&weight, &c.weight, sizeof weight);  // any int a C caller stored (checked before)
  o.weight = weight == HEMILIGHT_CACHE_WEIGHT_WARD                   ? cache_weight::ward
             : weight == HEMILIGHT_CACHE_WEIGHT_TABELLION_LAMORLETTE ? cache_weight::tabellion_lamorlette
                                                                     : cache_weight::ward_continuous;
  o.expert.limit_radius_by_gradient = c.gradient_radius_limit == 1;
  o.expert.limit_radius_by_neighbours = c.neighbour_clamp == 1;
  o.expert.shrink_disagreeing_records = c.shrink_disagreeing == 1;
  o.expert.refine_where_records_disagree = c.refine_disagreement == 1;
  o.second_order = c.second_order == 1;
  // Range-checked (with the field named) by cache_irradiance.
  o.expert.lone_record_change_limit = c.second_opinion;
  o.expert.lone_record_neighbour_reach = c.nearby_opinion;
  o.expert.lone_record_reach = c.sole_record_reach;
  o.invalid_backface_fraction = c.invalid_backface_fraction;
  return o;
}

cache_run cache_run_of(const hemilight_cache_options& c) {
  cache_run run;
  run.thread_count = c.thread_count;
  if (c.progress) {
    const hemilight_progress_fn progress = c.progress;
    void* user = c.progress_user;
    run.progress = [progress, user](float f) { return progress(user, f) != 0; };
  }
  return run;
}

sampler_options sampler_options_of(const hemilight_cache_options& c) {
  sampler_options so;
  so.resolution = c.resolution;
  so.integrate.extrapolate_wall_depth = c.extrapolate_wall_depth == 1;
  so.raster.edge_coverage = c.edge_coverage == 1;
  return so;
}

bake_options to_cpp(const hemilight_bake_options& c, std::shared_ptr<const cubemap> environment, std::vector<light> lights,
                    bool output_sh_l1, bool output_hl2) {
  bake_options o;
  o.width = c.width;
  o.height = c.height;
  o.sampler.resolution = c.resolution;
  o.bounces = c.bounces;
  o.indirect_only = c.indirect_only == 1;
  o.cache.error_threshold = c.error_threshold;
  o.min_coverage = c.min_coverage;
  o.dilation = c.dilation;
  o.use_cache = c.use_cache == 1;
  o.thread_count = c.thread_count;
  o.sampler.raster.sky = std::move(environment);
  o.lights = std::move(lights);
  o.output_sh_l1 = output_sh_l1;
  o.output_hl2 = output_hl2;
  for (std::size_t k = 0; k < 4; ++k) o.shadow_mask_lights[k] = c.shadow_mask_lights[k];
  o.sampler.raster.edge_coverage = c.edge_coverage == 1;
  o.strict = c.strict == 1;
  o.stitch_seams = c.stitch_seams == 1;
  o.ao_distance = c.ao_distance;  // range-checked, naming the C field, by the bake entries
  if (c.progress) {
    const hemilight_progress_fn progress = c.progress;
    void* user = c.progress_user;
    o.progress = [progress, user](float f) { return progress(user, f) != 0; };
  }
  return o;
}

filter_options to_cpp(const hemilight_cubemap_irradiance_options& c, edge_fixup mapping) {
  filter_options o;
  o.fixup = mapping;
  o.irradiance_input_size = c.input_size;
  o.thread_count = c.thread_count;
  return o;
}

}  // namespace hemilight::capi

namespace hemilight::capi {
namespace {

// The _init_sized functions: the defaults into the first `size` bytes' fields, then struct_size.
template <class T, std::size_t K>
void init_sized(T* out, std::size_t size, const T& defaults, const span (&fields)[K]) {
  if (!out || size < sizeof(std::size_t)) return;
  copy_fields(fields, &defaults, out, std::min(size, sizeof defaults));
  out->struct_size = size;
}

template <class T>
T zeroed() {
  T t;
  std::memset(&t, 0, sizeof t);
  return t;
}

}  // namespace
}  // namespace hemilight::capi

extern "C" {

void hemilight_cache_options_init_sized(hemilight_cache_options* options, size_t struct_size) {
  hemilight::capi::init_sized(options, struct_size, hemilight::capi::default_cache_options(), hemilight::capi::cache_options_fields);
}

void hemilight_bake_options_init_sized(hemilight_bake_options* options, size_t struct_size) {
  hemilight::capi::init_sized(options, struct_size, hemilight::capi::default_bake_options(), hemilight::capi::bake_options_fields);
}

void hemilight_cache_stats_init_sized(hemilight_cache_stats* stats, size_t struct_size) {
  hemilight::capi::init_sized(stats, struct_size, hemilight::capi::zeroed<hemilight_cache_stats>(), hemilight::capi::cache_stats_fields);
}

void hemilight_bake_stats_init_sized(hemilight_bake_stats* stats, size_t struct_size) {
  hemilight::capi::init_sized(stats, struct_size, hemilight::capi::zeroed<hemilight_bake_stats>(), hemilight::capi::bake_stats_fields);
}

void hemilight_bake_shard_info_init_sized(hemilight_bake_shard_info* info, size_t struct_size) {
  hemilight::capi::init_sized(info, struct_size, hemilight_bake_shard_info{}, hemilight::capi::shard_info_fields);
}

void hemilight_bake_pass_state_info_init_sized(hemilight_bake_pass_state_info* info, size_t struct_size) {
  hemilight::capi::init_sized(info, struct_size, hemilight_bake_pass_state_info{}, hemilight::capi::state_info_fields);
}

void hemilight_cubemap_irradiance_options_init_sized(hemilight_cubemap_irradiance_options* options, size_t struct_size) {
  hemilight::capi::init_sized(options, struct_size, hemilight::capi::default_cubemap_irradiance_options(),
                              hemilight::capi::cubemap_irradiance_options_fields);
}

}  // extern "C"

// ---- hemilight_bake_scene_desc (a growable struct like the options above) ------------------------

namespace hemilight::capi {
namespace {

#define HEMILIGHT_SPAN(T, f) span { offsetof(T, f), sizeof(static_cast<T*>(nullptr)->f) }
const span bake_scene_desc_fields[] = {
    HEMILIGHT_SPAN(hemilight_bake_scene_desc, struct_size), HEMILIGHT_SPAN(hemilight_bake_scene_desc, meshes),
    HEMILIGHT_SPAN(hemilight_bake_scene_desc, mesh_count), HEMILIGHT_SPAN(hemilight_bake_scene_desc, placements),
    HEMILIGHT_SPAN(hemilight_bake_scene_desc, pages), HEMILIGHT_SPAN(hemilight_bake_scene_desc, page_count),
    HEMILIGHT_SPAN(hemilight_bake_scene_desc, occluder_radiance), HEMILIGHT_SPAN(hemilight_bake_scene_desc, mesh_opacity),
    HEMILIGHT_SPAN(hemilight_bake_scene_desc, alpha_textures), HEMILIGHT_SPAN(hemilight_bake_scene_desc, alpha_texture_count),
    HEMILIGHT_SPAN(hemilight_bake_scene_desc, ao), HEMILIGHT_SPAN(hemilight_bake_scene_desc, ao_capacity)};  // (reserved0 is padding: never read)
#undef HEMILIGHT_SPAN
// Appended to the description of 56 bytes: the opacity fields (mesh_opacity at 56, after the
// padding field reserved0 at the older layout's tail padding, on LP64), then ao and ao_capacity
// (a description of 80 bytes has no AO fields).
static_assert(sizeof(void*) != 8 || sizeof(hemilight_bake_scene_desc) == 96, "hemilight_bake_scene_desc changed: see above");
static_assert(sizeof(void*) != 8 || offsetof(hemilight_bake_scene_desc, mesh_opacity) >= 56,
              "hemilight_bake_scene_desc: mesh_opacity must start past the earlier layout's sizeof");
static_assert(sizeof(void*) != 8 || offsetof(hemilight_bake_scene_desc, ao) >= 80,
              "hemilight_bake_scene_desc: ao must start past the opacity layout's sizeof");

}  // namespace

hemilight_bake_scene_desc default_bake_scene_desc() {
  hemilight_bake_scene_desc d = zeroed<hemilight_bake_scene_desc>();
  d.struct_size = sizeof d;
  d.occluder_radiance = HEMILIGHT_OCCLUDER_EMISSION;
  d.mesh_opacity = nullptr;  // every triangle opaque
  d.alpha_textures = nullptr;
  d.alpha_texture_count = 0;
  return d;
}

std::string read_sized(const hemilight_bake_scene_desc* in, hemilight_bake_scene_desc& out) {
  const std::string problem = size_problem("scene", "hemilight_bake_scene_desc_init", in->struct_size, sizeof out);
  if (!problem.empty()) return problem;
  copy_fields(bake_scene_desc_fields, in, &out, in->struct_size);
  return {};
}

void apply_opacity(const hemilight_opacity& o, material& m) {
  const material defaults;
  m.alpha = defaults.alpha;
  m.alpha_cutoff = defaults.alpha_cutoff;
  m.alpha_texture = defaults.alpha_texture;
  m.transmittance = defaults.transmittance;
  switch (o.mode) {
    case HEMILIGHT_ALPHA_TESTED:
      m.opacity = surface_opacity::alpha_tested;
      m.alpha = o.alpha;
      m.alpha_cutoff = o.alpha_cutoff;
      m.alpha_texture = o.alpha_texture;
      break;
    case HEMILIGHT_TRANSLUCENT:
      m.opacity = surface_opacity::translucent;
      m.transmittance = glm::vec3(o.transmittance[0], o.transmittance[1], o.transmittance[2]);
      break;
    default: m.opacity = surface_opacity::opaque; break;
  }
}

}  // namespace hemilight::capi

extern "C" void hemilight_opacity_init(hemilight_opacity* opacity) {
  if (!opacity) return;
  const hemilight_opacity defaults = HEMILIGHT_OPACITY_DEFAULT;
  *opacity = defaults;
}

extern "C" void hemilight_bake_scene_desc_init_sized(hemilight_bake_scene_desc* scene, size_t struct_size) {
  hemilight::capi::init_sized(scene, struct_size, hemilight::capi::default_bake_scene_desc(),
                              hemilight::capi::bake_scene_desc_fields);
}

// ---- hemilight_unwrap_options and hemilight_unwrap_stats (growable like the options above) -------

namespace hemilight::capi {
namespace {

#define HEMILIGHT_SPAN(T, f) span { offsetof(T, f), sizeof(static_cast<T*>(nullptr)->f) }
const span unwrap_options_fields[] = {
    HEMILIGHT_SPAN(hemilight_unwrap_options, struct_size), HEMILIGHT_SPAN(hemilight_unwrap_options, texels_per_unit),
    HEMILIGHT_SPAN(hemilight_unwrap_options, page_size), HEMILIGHT_SPAN(hemilight_unwrap_options, padding),
    HEMILIGHT_SPAN(hemilight_unwrap_options, max_chart_angle), HEMILIGHT_SPAN(hemilight_unwrap_options, max_pages),
    HEMILIGHT_SPAN(hemilight_unwrap_options, thread_count)};
const span unwrap_stats_fields[] = {
    HEMILIGHT_SPAN(hemilight_unwrap_stats, struct_size), HEMILIGHT_SPAN(hemilight_unwrap_stats, charts),
    HEMILIGHT_SPAN(hemilight_unwrap_stats, planar_charts), HEMILIGHT_SPAN(hemilight_unwrap_stats, degenerate_triangles),
    HEMILIGHT_SPAN(hemilight_unwrap_stats, pages), HEMILIGHT_SPAN(hemilight_unwrap_stats, texels_per_unit),
    HEMILIGHT_SPAN(hemilight_unwrap_stats, uv_area_fraction), HEMILIGHT_SPAN(hemilight_unwrap_stats, stretch_l2),
    HEMILIGHT_SPAN(hemilight_unwrap_stats, stretch_linf), HEMILIGHT_SPAN(hemilight_unwrap_stats, seam_texels),
    HEMILIGHT_SPAN(hemilight_unwrap_stats, seconds)};
#undef HEMILIGHT_SPAN
static_assert(sizeof(void*) != 8 || sizeof(hemilight_unwrap_options) == 32, "hemilight_unwrap_options changed: see above");
static_assert(sizeof(void*) != 8 || sizeof(hemilight_unwrap_stats) == 80, "hemilight_unwrap_stats changed: see above");

}  // namespace

hemilight_unwrap_options default_unwrap_options() {
  hemilight_unwrap_options o = zeroed<hemilight_unwrap_options>();
  const unwrap_options d;
  o.struct_size = sizeof o;
  o.texels_per_unit = d.texels_per_unit;
  o.page_size = d.page_size;
  o.padding = d.padding;
  o.max_chart_angle = d.max_chart_angle;
  o.max_pages = d.max_pages;
  o.thread_count = d.thread_count;
  return o;
}

std::string read_sized(const hemilight_unwrap_options* in, hemilight_unwrap_options& out) {
  return read(in, out, unwrap_options_fields, "hemilight_unwrap_options_init");
}

unwrap_options to_cpp(const hemilight_unwrap_options& c) {
  unwrap_options o;
  o.texels_per_unit = c.texels_per_unit;
  o.page_size = c.page_size;
  o.padding = c.padding;
  o.max_chart_angle = c.max_chart_angle;
  o.max_pages = c.max_pages;
  o.thread_count = c.thread_count;
  return o;
}

std::string check_sized(const hemilight_unwrap_stats* stats) {
  return size_problem("stats", "hemilight_unwrap_stats_init", stats->struct_size, sizeof *stats);
}

void write_sized(const hemilight_unwrap_stats& from, hemilight_unwrap_stats* out) {
  const std::size_t size = out->struct_size;
  copy_fields(unwrap_stats_fields, &from, out, size);
  out->struct_size = size;
}

}  // namespace hemilight::capi

extern "C" {

void hemilight_unwrap_options_init_sized(hemilight_unwrap_options* options, size_t struct_size) {
  hemilight::capi::init_sized(options, struct_size, hemilight::capi::default_unwrap_options(), hemilight::capi::unwrap_options_fields);
}

void hemilight_unwrap_stats_init_sized(hemilight_unwrap_stats* stats, size_t struct_size) {
  hemilight::capi::init_sized(stats, struct_size, hemilight::capi::zeroed<hemilight_unwrap_stats>(), hemilight::capi::unwrap_stats_fields);
}

}  // extern "C"
