/* What a program built against an older minor version of hemilight.h sees of the growable structs
 * (hemilight.h, "Structs that grow"): the same structs without their newest fields (here:
 * hemilight_cache_options without second_order, hemilight_bake_options without lights and
 * light_count, the statistics without their last field, hemilight_bake_scene_desc without the
 * opacity fields), and the functions it calls. Used by test_capi_abi.c, which must not include
 * hemilight.h. */
#ifndef HEMILIGHT_CAPI_OLDER_LAYOUT_H
#define HEMILIGHT_CAPI_OLDER_LAYOUT_H

#include <stddef.h>
#include <stdint.h>

typedef int hemilight_status; /* HEMILIGHT_OK = 0, HEMILIGHT_ERROR_INVALID_ARGUMENT = 1 */
typedef struct hemilight_scene hemilight_scene;
typedef int (*hemilight_progress_fn)(void* user, float fraction);

typedef struct hemilight_cache_options {
  size_t struct_size;
  int resolution;
  float error_threshold;
  float min_radius, max_radius;
  int use_gradients;
  int thread_count;
  hemilight_progress_fn progress;
  void* progress_user;
  int weight;
  int gradient_radius_limit;
  int neighbour_clamp;
  int shrink_disagreeing;
  int refine_disagreement;
  float second_opinion;
  float nearby_opinion;
  float sole_record_reach;
  float invalid_backface_fraction;
  int extrapolate_wall_depth;
} hemilight_cache_options;

typedef struct hemilight_cache_stats {
  size_t struct_size;
  size_t hemicubes;
  size_t records;
  double seconds;
} hemilight_cache_stats;

typedef struct hemilight_bake_material {
  float emission[3];
  float albedo[3];
  int two_sided;
} hemilight_bake_material;

typedef struct hemilight_bake_mesh {
  const float* positions;
  const float* normals;
  const float* lightmap_uvs;
  size_t vertex_count;
  const uint32_t* indices;
  size_t triangle_count;
  const hemilight_bake_material* materials;
  hemilight_bake_material material;
} hemilight_bake_mesh;

typedef struct hemilight_bake_options {
  size_t struct_size;
  int width, height;
  int resolution;
  int bounces;
  int indirect_only;
  float error_threshold;
  float min_coverage;
  int dilation;
  int use_cache;
  int thread_count;
  float sky_radiance[3];
  hemilight_progress_fn progress;
  void* progress_user;
  const float* environment_rgb;
  int environment_size;
} hemilight_bake_options;

typedef struct hemilight_bake_stats {
  size_t struct_size;
  size_t sampled_texels;
  size_t invalid_texels;
  size_t dilated_texels;
  size_t overlapping_texels;
  size_t hemicubes;
  size_t records;
} hemilight_bake_stats;

typedef struct hemilight_bake_placement {
  int page;
  float uv_scale[2];
  float uv_offset[2];
} hemilight_bake_placement;

typedef struct hemilight_bake_page {
  int width, height;
  const float* albedo_rgb;
  const float* emission_rgb;
  float* irradiance_rgb;
  size_t irradiance_capacity;
  uint8_t* valid;
  size_t valid_capacity;
  float* sh_l1_rgb;
  size_t sh_l1_capacity;
  float* hl2_rgb;
  size_t hl2_capacity;
  float* shadow_mask_rgba;
  size_t shadow_mask_capacity;
} hemilight_bake_page;

/* 0.14's layout: no mesh_opacity, alpha_textures, alpha_texture_count. */
typedef struct hemilight_bake_scene_desc {
  size_t struct_size;
  const hemilight_bake_mesh* meshes;
  size_t mesh_count;
  const hemilight_bake_placement* placements;
  const hemilight_bake_page* pages;
  size_t page_count;
  int occluder_radiance;
} hemilight_bake_scene_desc;

const char* hemilight_last_error(void);
hemilight_status hemilight_scene_create(const float* positions, size_t vertex_count, const uint32_t* indices,
                                        size_t triangle_count, const float* triangle_radiance, const float sky_radiance[3],
                                        hemilight_scene** out);
void hemilight_scene_release(hemilight_scene* scene);
void hemilight_cache_options_init_sized(hemilight_cache_options* options, size_t struct_size);
void hemilight_cache_stats_init_sized(hemilight_cache_stats* stats, size_t struct_size);
hemilight_status hemilight_cache_irradiance(const hemilight_scene* scene, const float* positions, const float* normals,
                                            size_t count, const hemilight_cache_options* options, float* irradiance_rgb,
                                            hemilight_cache_stats* stats);
void hemilight_bake_options_init_sized(hemilight_bake_options* options, size_t struct_size);
void hemilight_bake_stats_init_sized(hemilight_bake_stats* stats, size_t struct_size);
hemilight_status hemilight_bake_lightmap(const hemilight_bake_mesh* meshes, size_t mesh_count,
                                         const hemilight_bake_options* options, float* irradiance_rgb,
                                         size_t irradiance_capacity, uint8_t* valid, size_t valid_capacity,
                                         hemilight_bake_stats* stats);

void hemilight_bake_scene_desc_init_sized(hemilight_bake_scene_desc* scene, size_t struct_size);
hemilight_status hemilight_bake_scene(const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options,
                                      hemilight_bake_stats* stats);

static inline void hemilight_cache_options_init(hemilight_cache_options* o) { hemilight_cache_options_init_sized(o, sizeof *o); }
static inline void hemilight_cache_stats_init(hemilight_cache_stats* s) { hemilight_cache_stats_init_sized(s, sizeof *s); }
static inline void hemilight_bake_options_init(hemilight_bake_options* o) { hemilight_bake_options_init_sized(o, sizeof *o); }
static inline void hemilight_bake_stats_init(hemilight_bake_stats* s) { hemilight_bake_stats_init_sized(s, sizeof *s); }
static inline void hemilight_bake_scene_desc_init(hemilight_bake_scene_desc* d) { hemilight_bake_scene_desc_init_sized(d, sizeof *d); }

#endif
