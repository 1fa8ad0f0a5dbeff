// The C ABI's options structs against the C++ options: every C field reaches its C++ field (each
// set to a value other than its default, so a missing or swapped mapping fails), the C defaults are
// the C++ defaults, and a struct_size of an older, shorter layout reads the fields it holds and
// takes the defaults for the rest (capi/capi_options.cpp, compiled into this test).
#include "capi_options.hpp"

#include <catch2/catch.hpp>

#include <cstddef>
#include <cstring>

using namespace hemilight;

namespace {

int progress_calls = 0;
int count_progress(void* user, float) {
  ++*static_cast<int*>(user);
  return 1;
}

}  // namespace

TEST_CASE("C ABI options: every cache option reaches the C++ side", "[capi]") {
  hemilight_cache_options c = capi::default_cache_options();
  c.resolution = 48;
  c.error_threshold = 0.37f;
  c.min_radius = 0.011f;
  c.max_radius = 2.5f;
  c.use_gradients = 0;
  c.thread_count = 3;
  c.progress = count_progress;
  c.progress_user = &progress_calls;
  c.weight = HEMILIGHT_CACHE_WEIGHT_TABELLION_LAMORLETTE;
  c.gradient_radius_limit = 0;
  c.neighbour_clamp = 0;
  c.shrink_disagreeing = 0;
  c.refine_disagreement = 0;
  c.second_opinion = 0.4f;
  c.nearby_opinion = 3.0f;
  c.sole_record_reach = 0.5f;
  c.invalid_backface_fraction = 0.3f;
  c.extrapolate_wall_depth = 1;
  c.second_order = 0;
  c.edge_coverage = 1;
  const cache_options o = capi::to_cpp(c);
  const cache_run run = capi::cache_run_of(c);
  const sampler_options so = capi::sampler_options_of(c);
  CHECK(so.resolution == 48);
  CHECK(so.integrate.extrapolate_wall_depth);
  CHECK(so.raster.edge_coverage);
  CHECK(o.error_threshold == 0.37f);
  CHECK(o.min_radius == 0.011f);
  CHECK(o.max_radius == 2.5f);
  CHECK(!o.use_gradients);
  CHECK(run.thread_count == 3);
  CHECK(o.weight == cache_weight::tabellion_lamorlette);
  CHECK(!o.expert.limit_radius_by_gradient);
  CHECK(!o.expert.limit_radius_by_neighbours);
  CHECK(!o.expert.shrink_disagreeing_records);
  CHECK(!o.expert.refine_where_records_disagree);
  CHECK(o.expert.lone_record_change_limit == 0.4f);
  CHECK(o.expert.lone_record_neighbour_reach == 3.0f);
  CHECK(o.expert.lone_record_reach == 0.5f);
  CHECK(o.invalid_backface_fraction == 0.3f);
  CHECK(!o.second_order);
  REQUIRE(run.progress);
  progress_calls = 0;
  CHECK(run.progress(0.5f));
  CHECK(progress_calls == 1);
  c.weight = HEMILIGHT_CACHE_WEIGHT_WARD_CONTINUOUS;
  CHECK(capi::to_cpp(c).weight == cache_weight::ward_continuous);
  c.weight = HEMILIGHT_CACHE_WEIGHT_WARD;
  CHECK(capi::to_cpp(c).weight == cache_weight::ward);
}

TEST_CASE("C ABI options: the C defaults are the C++ defaults", "[capi]") {
  const cache_options d;
  const cache_options o = capi::to_cpp(capi::default_cache_options());
  CHECK(o.error_threshold == d.error_threshold);
  CHECK(o.min_radius == d.min_radius);
  CHECK(o.max_radius == d.max_radius);
  CHECK(o.use_gradients == d.use_gradients);
  CHECK(capi::cache_run_of(capi::default_cache_options()).thread_count == cache_run{}.thread_count);
  CHECK(o.weight == d.weight);
  CHECK(o.expert.limit_radius_by_gradient == d.expert.limit_radius_by_gradient);
  CHECK(o.expert.limit_radius_by_neighbours == d.expert.limit_radius_by_neighbours);
  CHECK(o.expert.shrink_disagreeing_records == d.expert.shrink_disagreeing_records);
  CHECK(o.expert.refine_where_records_disagree == d.expert.refine_where_records_disagree);
  CHECK(o.expert.lone_record_change_limit == d.expert.lone_record_change_limit);
  CHECK(o.expert.lone_record_neighbour_reach == d.expert.lone_record_neighbour_reach);
  CHECK(o.expert.lone_record_reach == d.expert.lone_record_reach);
  CHECK(o.invalid_backface_fraction == d.invalid_backface_fraction);
  CHECK(o.second_order == d.second_order);
  CHECK(!capi::cache_run_of(capi::default_cache_options()).progress);
  CHECK(capi::sampler_options_of(capi::default_cache_options()).resolution == sampler_options{}.resolution);
  CHECK(capi::sampler_options_of(capi::default_cache_options()).raster.edge_coverage == sampler_options{}.raster.edge_coverage);
  const bake_options bd;
  const bake_options b = capi::to_cpp(capi::default_bake_options(), nullptr, {}, false, false);
  CHECK(b.sampler.resolution == bd.sampler.resolution);
  CHECK(b.bounces == bd.bounces);
  CHECK(b.indirect_only == bd.indirect_only);
  CHECK(b.cache.error_threshold == bd.cache.error_threshold);
  CHECK(b.min_coverage == bd.min_coverage);
  CHECK(b.dilation == bd.dilation);
  CHECK(b.use_cache == bd.use_cache);
  CHECK(b.thread_count == bd.thread_count);
  CHECK(b.sampler.raster.edge_coverage == bd.sampler.raster.edge_coverage);
  CHECK(b.strict == bd.strict);
  CHECK(b.stitch_seams == bd.stitch_seams);
  CHECK(b.ao_distance == bd.ao_distance);
  CHECK(capi::default_bake_options().ao == nullptr);
  CHECK(capi::default_bake_options().ao_capacity == 0);
}

TEST_CASE("C ABI options: every bake option reaches the C++ side", "[capi]") {
  hemilight_bake_options c = capi::default_bake_options();
  c.width = 300;
  c.height = 200;
  c.resolution = 32;
  c.bounces = 4;
  c.indirect_only = 1;
  c.error_threshold = 0.3f;
  c.min_coverage = 0.05f;
  c.dilation = 3;
  c.use_cache = 0;
  c.thread_count = 2;
  c.progress = count_progress;
  c.progress_user = &progress_calls;
  c.shadow_mask_lights[0] = 2;
  c.shadow_mask_lights[3] = 0;
  c.edge_coverage = 1;
  c.strict = 1;
  c.stitch_seams = 0;
  c.ao_distance = 0.75f;
  light l;
  l.position = {1, 2, 3};
  const auto env = std::make_shared<const cubemap>();
  const bake_options o = capi::to_cpp(c, env, {l}, true, false);
  CHECK(o.width == 300);
  CHECK(o.height == 200);
  CHECK(o.sampler.resolution == 32);
  CHECK(o.bounces == 4);
  CHECK(o.indirect_only);
  CHECK(o.cache.error_threshold == 0.3f);
  CHECK(o.min_coverage == 0.05f);
  CHECK(o.dilation == 3);
  CHECK(!o.use_cache);
  CHECK(o.thread_count == 2);
  CHECK(o.sampler.raster.sky == env);
  REQUIRE(o.lights.size() == 1);
  CHECK(o.lights[0].position.z == 3.0f);
  CHECK(o.output_sh_l1);
  CHECK(!o.output_hl2);
  CHECK(o.shadow_mask_lights[0] == 2);
  CHECK(o.shadow_mask_lights[1] == -1);
  CHECK(o.shadow_mask_lights[3] == 0);
  CHECK(o.sampler.raster.edge_coverage);
  CHECK(o.strict);
  CHECK(!capi::to_cpp(capi::default_bake_options(), nullptr, {}, false, false).strict);
  CHECK(!o.stitch_seams);
  CHECK(capi::to_cpp(capi::default_bake_options(), nullptr, {}, false, false).stitch_seams);
  CHECK(o.ao_distance == 0.75f);
  REQUIRE(o.progress);
  progress_calls = 0;
  CHECK(o.progress(0.25f));
  CHECK(progress_calls == 1);
  // (sky_radiance and environment_rgb / light_count are converted by the bake entry itself, which
  // the C99 tests cover: test_capi_bake.c.)
}

TEST_CASE("C ABI options: an older, shorter struct_size takes the defaults for the fields it lacks", "[capi]") {
  // An older layout: everything up to extrapolate_wall_depth (no second_order).
  hemilight_cache_options older = capi::default_cache_options();
  older.second_order = 0;  // would be read if the size covered it
  older.resolution = 32;
  older.struct_size = offsetof(hemilight_cache_options, second_order);
  hemilight_cache_options full = capi::default_cache_options();
  REQUIRE(capi::read_sized(&older, full).empty());
  CHECK(full.resolution == 32);
  CHECK(full.second_order == 1);  // the default, not the 0 beyond the caller's struct
  CHECK(full.struct_size == older.struct_size);
  older.struct_size = 0;
  CHECK_THAT(capi::read_sized(&older, full), Catch::Contains("struct_size is 0: fill the struct with hemilight_cache_options_init"));
  older.struct_size = sizeof(hemilight_cache_options) + 8;
  CHECK_THAT(capi::read_sized(&older, full), Catch::Contains("built against a newer hemilight.h"));
  hemilight_bake_options bo = capi::default_bake_options();
  bo.light_count = 5;
  bo.width = 17;
  bo.struct_size = offsetof(hemilight_bake_options, lights);
  hemilight_bake_options bfull = capi::default_bake_options();
  REQUIRE(capi::read_sized(&bo, bfull).empty());
  CHECK(bfull.width == 17);
  CHECK(bfull.light_count == 0);
  CHECK(bfull.lights == nullptr);
  // The layouts before edge_coverage (cache: up to second_order, whose tail padding is not read;
  // bake: up to shadow_mask_capacity): the field takes its default, 0, whatever lies beyond.
  hemilight_cache_options before_edge;
  std::memset(&before_edge, 0x01, sizeof before_edge);  // edge_coverage and the padding would read as nonzero
  before_edge.struct_size = offsetof(hemilight_cache_options, edge_coverage);  // the older sizeof (96 on LP64)
  hemilight_cache_options edge_full = capi::default_cache_options();
  REQUIRE(capi::read_sized(&before_edge, edge_full).empty());
  CHECK(edge_full.edge_coverage == 0);
  CHECK(edge_full.reserved0 == 0);              // padding: never read
  CHECK(edge_full.second_order == 0x01010101);  // read: within the older size
  hemilight_bake_options bake_before_edge = capi::default_bake_options();
  bake_before_edge.edge_coverage = 1;
  bake_before_edge.struct_size = offsetof(hemilight_bake_options, edge_coverage);
  hemilight_bake_options bake_edge_full = capi::default_bake_options();
  REQUIRE(capi::read_sized(&bake_before_edge, bake_edge_full).empty());
  CHECK(bake_edge_full.edge_coverage == 0);
  // The layout before strict (up to edge_coverage, whose tail padding is not read): strict takes
  // its default, 0, whatever lies beyond.
  hemilight_bake_options before_strict;
  std::memset(&before_strict, 0x01, sizeof before_strict);
  before_strict.struct_size = offsetof(hemilight_bake_options, reserved1);  // the older sizeof (152 on LP64)
  hemilight_bake_options strict_full = capi::default_bake_options();
  REQUIRE(capi::read_sized(&before_strict, strict_full).empty());
  CHECK(strict_full.strict == 0);
  CHECK(strict_full.reserved1 == 0);                // padding: never read
  CHECK(strict_full.edge_coverage == 0x01010101);  // read: within the older size
  // The layout before stitch_seams (up to strict and its tail padding, now reserved2, not read):
  // stitch_seams takes its default, 1, whatever lies beyond.
  hemilight_bake_options before_stitch;
  std::memset(&before_stitch, 0x01, sizeof before_stitch);
  before_stitch.struct_size = offsetof(hemilight_bake_options, stitch_seams);  // the older sizeof (160 on LP64)
  hemilight_bake_options stitch_full = capi::default_bake_options();
  REQUIRE(capi::read_sized(&before_stitch, stitch_full).empty());
  CHECK(stitch_full.stitch_seams == 1);
  CHECK(stitch_full.reserved2 == 0);         // padding: never read
  CHECK(stitch_full.strict == 0x01010101);  // read: within the older size
  // The layout before ao_distance (up to stitch_seams and its tail padding, now reserved3, not
  // read): ao_distance takes its default, 0, and ao and ao_capacity theirs, whatever lies beyond;
  // the whole struct reads them.
  hemilight_bake_options before_ao;
  std::memset(&before_ao, 0x01, sizeof before_ao);
  before_ao.struct_size = offsetof(hemilight_bake_options, reserved3);  // the older sizeof (168 on LP64)
  hemilight_bake_options ao_full = capi::default_bake_options();
  REQUIRE(capi::read_sized(&before_ao, ao_full).empty());
  CHECK(ao_full.ao_distance == 0.0f);
  CHECK(ao_full.ao == nullptr);
  CHECK(ao_full.ao_capacity == 0);
  CHECK(ao_full.reserved3 == 0);                 // padding: never read
  CHECK(ao_full.stitch_seams == 0x01010101);    // read: within the older size
  before_ao.struct_size = sizeof before_ao;
  REQUIRE(capi::read_sized(&before_ao, ao_full).empty());
  CHECK(ao_full.ao_capacity != 0);  // read: within the whole struct
  CHECK(ao_full.reserved3 == 0);
  CHECK(ao_full.reserved4 == 0);
  // The scene description before ao (up to occluder_radiance and its tail padding, now reserved0):
  // ao and ao_capacity stay NULL.
  hemilight_bake_scene_desc desc_before_ao;
  std::memset(&desc_before_ao, 0x01, sizeof desc_before_ao);
  desc_before_ao.struct_size = offsetof(hemilight_bake_scene_desc, reserved0);  // occluder_radiance's end (52 of 56 on LP64)
  hemilight_bake_scene_desc desc_full = capi::default_bake_scene_desc();
  REQUIRE(capi::read_sized(&desc_before_ao, desc_full).empty());
  CHECK(desc_full.ao == nullptr);
  CHECK(desc_full.ao_capacity == nullptr);
  CHECK(desc_full.reserved0 == 0);
  CHECK(desc_full.occluder_radiance == 0x01010101);
  // The description with the opacity fields but not ao (80 bytes on LP64): ao stays NULL.
  desc_before_ao.struct_size = offsetof(hemilight_bake_scene_desc, ao);
  desc_full = capi::default_bake_scene_desc();
  REQUIRE(capi::read_sized(&desc_before_ao, desc_full).empty());
  CHECK(desc_full.mesh_opacity != nullptr);
  CHECK(desc_full.ao == nullptr);
  CHECK(desc_full.ao_capacity == nullptr);
  desc_before_ao.struct_size = sizeof desc_before_ao;
  REQUIRE(capi::read_sized(&desc_before_ao, desc_full).empty());
  CHECK(desc_full.ao != nullptr);
  CHECK(desc_full.reserved0 == 0);
  // Statistics: only the fields within struct_size are written.
  hemilight_cache_stats from{};
  from.struct_size = sizeof from;
  from.hemicubes = 7;
  from.records = 5;
  from.seconds = 1.5;
  from.invalid_samples = 2;
  hemilight_cache_stats to;
  std::memset(&to, 0x5a, sizeof to);
  to.struct_size = offsetof(hemilight_cache_stats, seconds);
  capi::write_sized(from, &to);
  CHECK(to.hemicubes == 7);
  CHECK(to.records == 5);
  hemilight_cache_stats untouched;
  std::memset(&untouched, 0x5a, sizeof untouched);
  CHECK(std::memcmp(&to.seconds, &untouched.seconds, sizeof to.seconds) == 0);
  CHECK(std::memcmp(&to.invalid_samples, &untouched.invalid_samples, sizeof to.invalid_samples) == 0);
  // The bake statistics of the layout before the input counts (up to seconds): the counts stay
  // untouched; with the whole struct every count arrives.
  hemilight_bake_stats bake_from{};
  bake_from.struct_size = sizeof bake_from;
  bake_from.hemicubes = 9;
  bake_from.seconds = 2.5;
  bake_from.degenerate_triangles = 11;
  bake_from.no_uv_area_triangles = 3;
  bake_from.first_no_uv_area_mesh = 1;
  bake_from.first_no_uv_area_triangle = 4;
  bake_from.clamped_uvs = 6;
  hemilight_bake_stats bake_to;
  std::memset(&bake_to, 0x5a, sizeof bake_to);
  bake_to.struct_size = offsetof(hemilight_bake_stats, degenerate_triangles);
  capi::write_sized(bake_from, &bake_to);
  CHECK(bake_to.hemicubes == 9);
  CHECK(bake_to.seconds == 2.5);
  hemilight_bake_stats bake_untouched;
  std::memset(&bake_untouched, 0x5a, sizeof bake_untouched);
  CHECK(std::memcmp(&bake_to.degenerate_triangles, &bake_untouched.degenerate_triangles,
                    sizeof bake_to - offsetof(hemilight_bake_stats, degenerate_triangles)) == 0);
  bake_to.struct_size = sizeof bake_to;
  capi::write_sized(bake_from, &bake_to);
  CHECK(bake_to.degenerate_triangles == 11);
  CHECK(bake_to.no_uv_area_triangles == 3);
  CHECK(bake_to.first_no_uv_area_mesh == 1);
  CHECK(bake_to.first_no_uv_area_triangle == 4);
  CHECK(bake_to.clamped_uvs == 6);
}

TEST_CASE("C ABI options: cube-map irradiance options reach the C++ side, defaults are the C++ defaults", "[capi]") {
  hemilight_cubemap_irradiance_options c = capi::default_cubemap_irradiance_options();
  const filter_options d;
  const filter_options o = capi::to_cpp(c, edge_fixup::none);
  CHECK(c.method == HEMILIGHT_IRRADIANCE_FILTER);
  CHECK(o.irradiance_input_size == d.irradiance_input_size);
  CHECK(capi::cache_run_of(capi::default_cache_options()).thread_count == cache_run{}.thread_count);
  c.input_size = 48;
  c.thread_count = 3;
  const filter_options m = capi::to_cpp(c, edge_fixup::warp);
  CHECK(m.irradiance_input_size == 48);
  CHECK(m.thread_count == 3);
  CHECK(m.fixup == edge_fixup::warp);
  // an older layout without input_size and thread_count: their defaults
  c.method = HEMILIGHT_IRRADIANCE_SH25;
  c.struct_size = offsetof(hemilight_cubemap_irradiance_options, input_size);
  hemilight_cubemap_irradiance_options read = capi::default_cubemap_irradiance_options();
  CHECK(capi::read_sized(&c, read).empty());
  CHECK(read.method == HEMILIGHT_IRRADIANCE_SH25);
  CHECK(read.input_size == d.irradiance_input_size);
  CHECK(read.thread_count == d.thread_count);
}

TEST_CASE("C ABI options: every unwrap option reaches the C++ side, defaults are the C++ defaults, older layouts too", "[capi]") {
  const unwrap_options d;
  const unwrap_options def = capi::to_cpp(capi::default_unwrap_options());
  CHECK(def.texels_per_unit == d.texels_per_unit);
  CHECK(def.page_size == d.page_size);
  CHECK(def.padding == d.padding);
  CHECK(def.max_chart_angle == d.max_chart_angle);
  CHECK(def.max_pages == d.max_pages);
  CHECK(def.thread_count == d.thread_count);
  hemilight_unwrap_options c = capi::default_unwrap_options();
  c.texels_per_unit = 12.5f;
  c.page_size = 512;
  c.padding = 3;
  c.max_chart_angle = 45.0f;
  c.max_pages = 9;
  c.thread_count = 2;
  const unwrap_options o = capi::to_cpp(c);
  CHECK(o.texels_per_unit == 12.5f);
  CHECK(o.page_size == 512);
  CHECK(o.padding == 3);
  CHECK(o.max_chart_angle == 45.0f);
  CHECK(o.max_pages == 9);
  CHECK(o.thread_count == 2);
  // An older, shorter layout (up to max_chart_angle): the rest takes the defaults.
  c.struct_size = offsetof(hemilight_unwrap_options, max_pages);
  hemilight_unwrap_options read = capi::default_unwrap_options();
  REQUIRE(capi::read_sized(&c, read).empty());
  CHECK(read.max_chart_angle == 45.0f);
  CHECK(read.max_pages == d.max_pages);
  CHECK(read.thread_count == d.thread_count);
  c.struct_size = sizeof c + 8;
  CHECK_THAT(capi::read_sized(&c, read), Catch::Contains("built against a newer hemilight.h"));
  // Statistics: only the fields within struct_size are written.
  hemilight_unwrap_stats from{};
  from.struct_size = sizeof from;
  from.charts = 7;
  from.pages = 2;
  from.seam_texels = 3.5;
  from.seconds = 0.25;
  hemilight_unwrap_stats to;
  std::memset(&to, 0x5a, sizeof to);
  to.struct_size = offsetof(hemilight_unwrap_stats, seam_texels);
  REQUIRE(capi::check_sized(&to).empty());
  capi::write_sized(from, &to);
  CHECK(to.charts == 7);
  CHECK(to.pages == 2);
  hemilight_unwrap_stats untouched;
  std::memset(&untouched, 0x5a, sizeof untouched);
  CHECK(std::memcmp(&to.seam_texels, &untouched.seam_texels, sizeof to - offsetof(hemilight_unwrap_stats, seam_texels)) == 0);
}

TEST_CASE("C ABI options: the scene description's opacity fields default to all opaque, also for an older struct_size", "[capi]") {
  const hemilight_bake_scene_desc d = capi::default_bake_scene_desc();
  CHECK(d.struct_size == sizeof d);
  CHECK(d.mesh_opacity == nullptr);
  CHECK(d.alpha_textures == nullptr);
  CHECK(d.alpha_texture_count == 0);
  // hemilight_bake_scene_desc_init_sized fills the same defaults.
  hemilight_bake_scene_desc inited;
  std::memset(&inited, 0x01, sizeof inited);
  hemilight_bake_scene_desc_init_sized(&inited, sizeof inited);
  CHECK(inited.mesh_opacity == nullptr);
  CHECK(inited.alpha_textures == nullptr);
  CHECK(inited.alpha_texture_count == 0);
  CHECK(inited.occluder_radiance == HEMILIGHT_OCCLUDER_EMISSION);
  // Every field the caller's struct holds is read.
  const hemilight_mesh_opacity mesh_opacity[1] = {};
  const std::uint8_t values[1] = {255};
  const hemilight_alpha_texture texture[1] = {{values, 1, 1}};
  hemilight_bake_scene_desc full = capi::default_bake_scene_desc();
  full.mesh_opacity = mesh_opacity;
  full.alpha_textures = texture;
  full.alpha_texture_count = 1;
  hemilight_bake_scene_desc read = capi::default_bake_scene_desc();
  REQUIRE(capi::read_sized(&full, read).empty());
  CHECK(read.mesh_opacity == mesh_opacity);
  CHECK(read.alpha_textures == texture);
  CHECK(read.alpha_texture_count == 1);
  // The layout before the opacity fields (up to occluder_radiance and its tail padding: 56 bytes
  // on LP64): they take their defaults, whatever lies beyond the caller's struct.
  hemilight_bake_scene_desc older;
  std::memset(&older, 0x01, sizeof older);
  older.struct_size = offsetof(hemilight_bake_scene_desc, mesh_opacity);
  older.occluder_radiance = HEMILIGHT_OCCLUDER_EMISSION_PLUS_MEAN_BOUNCE;
  CHECK((sizeof(void*) != 8 || older.struct_size == 56));
  hemilight_bake_scene_desc older_read = capi::default_bake_scene_desc();
  REQUIRE(capi::read_sized(&older, older_read).empty());
  CHECK(older_read.occluder_radiance == HEMILIGHT_OCCLUDER_EMISSION_PLUS_MEAN_BOUNCE);  // read: within the older size
  CHECK(older_read.mesh_opacity == nullptr);
  CHECK(older_read.alpha_textures == nullptr);
  CHECK(older_read.alpha_texture_count == 0);
  // An init with the older size writes nothing past it.
  hemilight_bake_scene_desc guarded;
  std::memset(&guarded, 0x5a, sizeof guarded);
  hemilight_bake_scene_desc_init_sized(&guarded, offsetof(hemilight_bake_scene_desc, mesh_opacity));
  hemilight_bake_scene_desc untouched;
  std::memset(&untouched, 0x5a, sizeof untouched);
  CHECK(std::memcmp(&guarded.mesh_opacity, &untouched.mesh_opacity,
                    sizeof guarded - offsetof(hemilight_bake_scene_desc, mesh_opacity)) == 0);
  CHECK(guarded.occluder_radiance == HEMILIGHT_OCCLUDER_EMISSION);
}

TEST_CASE("C ABI options: the opacity defaults are the C++ material's", "[capi]") {
  const material m;  // the C++ defaults
  const hemilight_opacity macro = HEMILIGHT_OPACITY_DEFAULT;
  hemilight_opacity inited;
  std::memset(&inited, 0x01, sizeof inited);
  hemilight_opacity_init(&inited);
  hemilight_opacity_init(nullptr);  // ignored
  for (const hemilight_opacity& o : {macro, inited}) {
    CHECK(o.mode == HEMILIGHT_OPAQUE);
    CHECK(o.alpha == m.alpha);
    CHECK(o.alpha_cutoff == m.alpha_cutoff);
    CHECK(o.alpha_texture == m.alpha_texture);
    for (int c = 0; c < 3; ++c) CHECK(o.transmittance[c] == m.transmittance[c]);
  }
  CHECK(m.opacity == surface_opacity::opaque);
}

TEST_CASE("C ABI options: every opacity field reaches the C++ material, and only the mode's", "[capi]") {
  material m;
  m.emission = glm::vec3(2.0f);
  m.albedo = glm::vec3(0.5f);
  m.two_sided = true;
  hemilight_opacity o = HEMILIGHT_OPACITY_DEFAULT;
  o.mode = HEMILIGHT_ALPHA_TESTED;
  o.alpha = 0.75f;
  o.alpha_cutoff = 0.25f;
  o.alpha_texture = 3;
  o.transmittance[0] = 0.5f;  // not the mode's: the default
  capi::apply_opacity(o, m);
  CHECK(m.opacity == surface_opacity::alpha_tested);
  CHECK(m.alpha == 0.75f);
  CHECK(m.alpha_cutoff == 0.25f);
  CHECK(m.alpha_texture == 3);
  CHECK(m.transmittance == glm::vec3(0.0f));
  // The material's other fields are kept.
  CHECK(m.emission == glm::vec3(2.0f));
  CHECK(m.albedo == glm::vec3(0.5f));
  CHECK(m.two_sided);
  o.mode = HEMILIGHT_TRANSLUCENT;
  o.transmittance[1] = 0.25f;
  o.transmittance[2] = 1.0f;
  capi::apply_opacity(o, m);
  CHECK(m.opacity == surface_opacity::translucent);
  CHECK(m.transmittance == glm::vec3(0.5f, 0.25f, 1.0f));
  CHECK(m.alpha == material{}.alpha);  // not the mode's: the defaults again
  CHECK(m.alpha_cutoff == material{}.alpha_cutoff);
  CHECK(m.alpha_texture == -1);
  o.mode = HEMILIGHT_OPAQUE;
  capi::apply_opacity(o, m);
  CHECK(m.opacity == surface_opacity::opaque);
  CHECK(m.transmittance == glm::vec3(0.0f));
}

TEST_CASE("C ABI options: the sharded bake's info structs read over zeros and write within struct_size", "[capi]") {
  // A caller's shorter struct (up to hemicubes): read_sized takes its fields and zeros for the
  // rest; write_sized leaves the bytes past its struct_size untouched.
  hemilight_bake_shard_info in;
  std::memset(&in, 0x5a, sizeof in);
  in.struct_size = offsetof(hemilight_bake_shard_info, hemicubes);
  in.key = 0x1234;
  in.pass = 2;
  in.sample_count = 17;
  hemilight_bake_shard_info got;
  REQUIRE(capi::read_sized(&in, got).empty());
  CHECK(got.struct_size == in.struct_size);  // the caller's, as read_sized does for the options
  CHECK(got.key == 0x1234);
  CHECK(got.pass == 2);
  CHECK(got.sample_count == 17);
  CHECK(got.hemicubes == 0);
  CHECK(got.seconds == 0.0);
  hemilight_bake_shard_info from{};
  from.struct_size = sizeof from;
  from.key = 7;
  from.hemicubes = 9;
  hemilight_bake_shard_info to;
  std::memset(&to, 0x5a, sizeof to);
  to.struct_size = offsetof(hemilight_bake_shard_info, hemicubes);
  capi::write_sized(from, &to);
  CHECK(to.key == 7);
  CHECK(to.struct_size == offsetof(hemilight_bake_shard_info, hemicubes));
  hemilight_bake_shard_info untouched;
  std::memset(&untouched, 0x5a, sizeof untouched);
  CHECK(std::memcmp(&to.hemicubes, &untouched.hemicubes, sizeof to - offsetof(hemilight_bake_shard_info, hemicubes)) == 0);
  in.struct_size = sizeof in + 8;
  CHECK(capi::read_sized(&in, got).find("newer hemilight.h") != std::string::npos);
  // The state's info: the same rules.
  hemilight_bake_pass_state_info s;
  std::memset(&s, 0x5a, sizeof s);
  s.struct_size = offsetof(hemilight_bake_pass_state_info, pass_count);
  s.width = 5;
  hemilight_bake_pass_state_info sg;
  REQUIRE(capi::read_sized(&s, sg).empty());
  CHECK(sg.width == 5);
  CHECK(sg.pass_count == 0);
  s.struct_size = 0;
  CHECK(capi::check_sized(&s).find("hemilight_bake_pass_state_info_init") != std::string::npos);
}
