/* C99 test of the C ABI's sharded scene bakes (hemilight.h, "sharded scene bakes"):
 * hemilight_bake_scene_shard, hemilight_merge_bake_pass, hemilight_finish_sharded_bake,
 * hemilight_bake_scene_sharded, and shards and states as plain data (_get, _create).
 * References (every output of the page compared bitwise: irradiance, valid, SH L1, shadow mask,
 * AO): one shard is hemilight_bake_scene; the 3-shard bake run job by job, each job's result and
 * each state shipped through _get -> plain arrays -> _create as a program would between machines,
 * the jobs run in reverse order with another thread count and the shards merged in reverse order,
 * is hemilight_bake_scene_sharded(.., 3, ..); without the cache 3 shards are hemilight_bake_scene.
 * Refusals name the function and the argument and write nothing (handles and page buffers).
 * Prints failing checks and a closing "N passed, N failed" line. */
#include "capi_check.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SIZE 32
#define TEXELS (SIZE * SIZE)
#define SHARDS 3

/* The outputs of one bake of the page. */
typedef struct outputs {
  float irradiance[3 * TEXELS];
  uint8_t valid[TEXELS];
  float sh_l1[12 * TEXELS];
  float shadow_mask[4 * TEXELS];
  float ao[TEXELS];
} outputs;

/* A corner of a room: a floor quad (x in [0, 1], z in [-1, 0]) facing up, a back wall (z = -1)
 * facing +z and a side wall (x = 0) facing +x, each a chart of its own on one 32 x 32 page; albedo
 * 0.6, a sky of radiance 1 and a point light above the floor. */
static const float floor_positions[] = {0, 0, 0, 1, 0, 0, 1, 0, -1, 0, 0, -1};
static const float back_positions[] = {0, 0, -1, 1, 0, -1, 1, 1, -1, 0, 1, -1};
static const float side_positions[] = {0, 0, 0, 0, 0, -1, 0, 1, -1, 0, 1, 0};
static const uint32_t quad_indices[] = {0, 1, 2, 0, 2, 3};

typedef struct fixture {
  float uvs[3][8];
  hemilight_bake_mesh meshes[3];
  hemilight_bake_placement placements[3];
  hemilight_bake_page page;
  float* ao_buffers[1];
  size_t ao_capacities[1];
  hemilight_bake_scene_desc scene;
  hemilight_light light;
  hemilight_bake_options options;
} fixture;

static void make_fixture(fixture* f) {
  const float* positions[3];
  int m, c;
  memset(f, 0, sizeof *f);
  positions[0] = floor_positions;
  positions[1] = back_positions;
  positions[2] = side_positions;
  for (m = 0; m < 3; ++m) {
    /* Chart m on u in [0.02 + 0.33 m, 0.32 + 0.33 m], v in [0.02, 0.98] (corners in vertex order). */
    const float u0 = 0.02f + 0.33f * (float)m, u1 = u0 + 0.3f, v0 = 0.02f, v1 = 0.98f;
    const float uv[8] = {u0, v0, u1, v0, u1, v1, u0, v1};
    memcpy(f->uvs[m], uv, sizeof uv);
    f->meshes[m].positions = positions[m];
    f->meshes[m].lightmap_uvs = f->uvs[m];
    f->meshes[m].vertex_count = 4;
    f->meshes[m].indices = quad_indices;
    f->meshes[m].triangle_count = 2;
    for (c = 0; c < 3; ++c) f->meshes[m].material.albedo[c] = 0.6f;
    f->placements[m].uv_scale[0] = f->placements[m].uv_scale[1] = 1.0f;
  }
  f->page.width = f->page.height = SIZE;
  hemilight_bake_scene_desc_init(&f->scene);
  f->scene.meshes = f->meshes;
  f->scene.mesh_count = 3;
  f->scene.placements = f->placements;
  f->scene.pages = &f->page;
  f->scene.page_count = 1;
  f->scene.ao = f->ao_buffers;
  f->scene.ao_capacity = f->ao_capacities;

  hemilight_light_init(&f->light, HEMILIGHT_LIGHT_POINT);
  f->light.position[0] = 0.6f;
  f->light.position[1] = 0.7f;
  f->light.position[2] = -0.4f;
  f->light.color[0] = f->light.color[1] = f->light.color[2] = 0.5f;

  hemilight_bake_options_init(&f->options);
  f->options.resolution = 24;
  f->options.bounces = 2;
  f->options.thread_count = 2;
  f->options.sky_radiance[0] = f->options.sky_radiance[1] = f->options.sky_radiance[2] = 1.0f;
  f->options.lights = &f->light;
  f->options.light_count = 1;
  f->options.shadow_mask_lights[0] = 0;
  f->options.ao_distance = 0.3f;
}

/* Points the page's buffers (and its AO) at *out, filled with a sentinel. */
static void target(fixture* f, outputs* out) {
  size_t i;
  for (i = 0; i < 3 * TEXELS; ++i) out->irradiance[i] = -7.0f;
  memset(out->valid, 9, sizeof out->valid);
  for (i = 0; i < 12 * TEXELS; ++i) out->sh_l1[i] = -7.0f;
  for (i = 0; i < 4 * TEXELS; ++i) out->shadow_mask[i] = -7.0f;
  for (i = 0; i < TEXELS; ++i) out->ao[i] = -7.0f;
  f->page.irradiance_rgb = out->irradiance;
  f->page.irradiance_capacity = 3 * TEXELS;
  f->page.valid = out->valid;
  f->page.valid_capacity = TEXELS;
  f->page.sh_l1_rgb = out->sh_l1;
  f->page.sh_l1_capacity = 12 * TEXELS;
  f->page.shadow_mask_rgba = out->shadow_mask;
  f->page.shadow_mask_capacity = 4 * TEXELS;
  f->ao_buffers[0] = out->ao;
  f->ao_capacities[0] = TEXELS;
}

static int same_bits(const outputs* a, const outputs* b) {
  return memcmp(a->irradiance, b->irradiance, sizeof a->irradiance) == 0 && memcmp(a->valid, b->valid, sizeof a->valid) == 0 &&
         memcmp(a->sh_l1, b->sh_l1, sizeof a->sh_l1) == 0 && memcmp(a->shadow_mask, b->shadow_mask, sizeof a->shadow_mask) == 0 &&
         memcmp(a->ao, b->ao, sizeof a->ao) == 0;
}

/* Every value of *a is still the sentinel of target(). */
static int untouched(const outputs* a) {
  size_t i;
  for (i = 0; i < 3 * TEXELS; ++i)
    if (a->irradiance[i] != -7.0f) return 0;
  for (i = 0; i < TEXELS; ++i)
    if (a->valid[i] != 9 || a->ao[i] != -7.0f) return 0;
  return 1;
}

/* A shard through plain data: its numbers, channel names and values read, the handle released,
 * and a new handle made from the copies (what a program shipping it to another machine does). */
static hemilight_bake_shard* ship_shard(hemilight_bake_shard* shard) {
  hemilight_bake_shard_info info;
  hemilight_bake_shard* back = NULL;
  char** names;
  float* values;
  size_t c, n;
  hemilight_bake_shard_info_init(&info);
  CHECK(hemilight_bake_shard_get(shard, &info, NULL, 0) == HEMILIGHT_OK); /* the numbers only */
  n = info.sample_count * info.channel_count;
  values = (float*)malloc((n ? n : 1) * sizeof(float));
  names = (char**)malloc((info.channel_count ? info.channel_count : 1) * sizeof(char*));
  CHECK(hemilight_bake_shard_get(shard, &info, values, n) == HEMILIGHT_OK);
  for (c = 0; c < info.channel_count; ++c) {
    const char* name = hemilight_bake_shard_channel_name(shard, c);
    CHECK(name != NULL);
    names[c] = (char*)malloc(strlen(name ? name : "") + 1);
    strcpy(names[c], name ? name : "");
  }
  CHECK(hemilight_bake_shard_channel_name(shard, info.channel_count) == NULL);
  hemilight_bake_shard_release(shard);
  CHECK(hemilight_bake_shard_create(&info, (const char* const*)names, values, n, &back) == HEMILIGHT_OK);
  for (c = 0; c < info.channel_count; ++c) free(names[c]);
  free(names);
  free(values);
  return back;
}

/* A state through plain data, as ship_shard. */
static hemilight_bake_pass_state* ship_state(hemilight_bake_pass_state* state) {
  hemilight_bake_pass_state_info info;
  hemilight_bake_pass_state* back = NULL;
  float* rgba;
  size_t *hemicubes, *records, *invalid, p, count;
  double* seconds;
  hemilight_bake_pass_state_info_init(&info);
  CHECK(hemilight_bake_pass_state_get(state, &info, NULL, 0, NULL, NULL, NULL, NULL, 0) == HEMILIGHT_OK);
  count = 4 * (size_t)info.width * (size_t)info.height;
  rgba = (float*)malloc(count * sizeof(float));
  hemicubes = (size_t*)malloc((info.pass_count + 1) * sizeof(size_t));
  records = (size_t*)malloc((info.pass_count + 1) * sizeof(size_t));
  invalid = (size_t*)malloc((info.pass_count + 1) * sizeof(size_t));
  seconds = (double*)malloc((info.pass_count + 1) * sizeof(double));
  CHECK(hemilight_bake_pass_state_get(state, &info, rgba, count, hemicubes, records, invalid, seconds, info.pass_count) == HEMILIGHT_OK);
  for (p = 0; p < info.pass_count; ++p) CHECK(hemicubes[p] > 0 && seconds[p] >= 0.0);
  hemilight_bake_pass_state_release(state);
  CHECK(hemilight_bake_pass_state_create(&info, rgba, count, hemicubes, records, invalid, seconds, &back) == HEMILIGHT_OK);
  free(rgba);
  free(hemicubes);
  free(records);
  free(invalid);
  free(seconds);
  return back;
}

/* The sharded bake of f run job by job: each pass's jobs in reverse order with one thread (the
 * bits do not depend on it), every shard and state shipped as plain data, the shards handed to
 * the merges in reverse order. Writes the outputs and stats; returns the finish's status. */
static hemilight_status bake_job_by_job(fixture* f, int shards, hemilight_bake_stats* stats) {
  hemilight_bake_shard* first[SHARDS];
  hemilight_bake_shard* current[SHARDS];
  const hemilight_bake_shard* reversed[SHARDS];
  hemilight_bake_pass_state* state = NULL;
  hemilight_bake_options job_options = f->options;
  hemilight_status st = HEMILIGHT_OK;
  int pass, s;
  job_options.thread_count = 1;
  for (pass = 1;; ++pass) {
    for (s = shards - 1; s >= 0; --s) {
      current[s] = NULL;
      CHECK(hemilight_bake_scene_shard(&f->scene, &job_options, s, shards, pass, state, &current[s]) == HEMILIGHT_OK);
      current[s] = ship_shard(current[s]);
    }
    for (s = 0; s < shards; ++s) reversed[s] = current[shards - 1 - s];
    if (pass == 1)
      for (s = 0; s < shards; ++s) first[s] = current[s];
    if (pass == f->options.bounces) {
      st = hemilight_finish_sharded_bake(&f->scene, &f->options, reversed, (size_t)shards, (const hemilight_bake_shard* const*)first,
                                         state, stats);
      break;
    }
    {
      hemilight_bake_pass_state* next = NULL;
      CHECK(hemilight_merge_bake_pass(&f->scene, &f->options, pass, reversed, (size_t)shards, (const hemilight_bake_shard* const*)first,
                                      state, &next) == HEMILIGHT_OK);
      hemilight_bake_pass_state_release(state);
      state = ship_state(next);
    }
    if (pass > 1)
      for (s = 0; s < shards; ++s) hemilight_bake_shard_release(current[s]);
  }
  for (s = 0; s < shards; ++s) {
    if (f->options.bounces > 1) hemilight_bake_shard_release(current[s]);
    hemilight_bake_shard_release(first[s]);
  }
  hemilight_bake_pass_state_release(state);
  return st;
}

static outputs reference, result;

/* 1. One shard is hemilight_bake_scene, every output and the statistics' counts. */
static void test_one_shard(void) {
  fixture f;
  hemilight_bake_stats a, b;
  make_fixture(&f);
  hemilight_bake_stats_init(&a);
  hemilight_bake_stats_init(&b);
  target(&f, &reference);
  CHECK(hemilight_bake_scene(&f.scene, &f.options, &a) == HEMILIGHT_OK);
  target(&f, &result);
  CHECK(hemilight_bake_scene_sharded(&f.scene, &f.options, 1, &b) == HEMILIGHT_OK);
  CHECK(same_bits(&result, &reference));
  CHECK(a.sampled_texels > 500 && a.sampled_texels == b.sampled_texels);
  CHECK(a.hemicubes == b.hemicubes && a.records == b.records);
  CHECK(a.invalid_texels == b.invalid_texels && a.dilated_texels == b.dilated_texels && a.seam_texels == b.seam_texels);
  {
    /* The AO is there (open above the floor's middle, occluded in the corner). */
    size_t i, open = 0, shut = 0;
    for (i = 0; i < TEXELS; ++i) {
      if (reference.ao[i] > 0.9f) ++open;
      if (reference.ao[i] < 0.9f && reference.valid[i]) ++shut;
    }
    CHECK(open > 0 && shut > 0);
  }
}

/* 2. Three shards job by job, shipped as plain data, are hemilight_bake_scene_sharded's bits. */
static void test_job_by_job(void) {
  fixture f;
  hemilight_bake_stats a, b;
  make_fixture(&f);
  hemilight_bake_stats_init(&a);
  hemilight_bake_stats_init(&b);
  target(&f, &reference);
  CHECK(hemilight_bake_scene_sharded(&f.scene, &f.options, SHARDS, &a) == HEMILIGHT_OK);
  target(&f, &result);
  CHECK(bake_job_by_job(&f, SHARDS, &b) == HEMILIGHT_OK);
  CHECK(same_bits(&result, &reference));
  CHECK(a.hemicubes == b.hemicubes && a.records == b.records && a.sampled_texels == b.sampled_texels);
  /* Not vacuous: with the cache, 3 shards place their own records, so the bits differ from one
   * shard's (within the cache's error). */
  target(&f, &result);
  CHECK(hemilight_bake_scene(&f.scene, &f.options, NULL) == HEMILIGHT_OK);
  CHECK(memcmp(result.irradiance, reference.irradiance, sizeof result.irradiance) != 0);
  /* With one bounce the finish takes the first pass's shards alone (first_pass may be NULL). */
  f.options.bounces = 1;
  target(&f, &reference);
  CHECK(hemilight_bake_scene_sharded(&f.scene, &f.options, SHARDS, NULL) == HEMILIGHT_OK);
  target(&f, &result);
  {
    hemilight_bake_shard* s[SHARDS];
    int i;
    for (i = 0; i < SHARDS; ++i) CHECK(hemilight_bake_scene_shard(&f.scene, &f.options, i, SHARDS, 1, NULL, &s[i]) == HEMILIGHT_OK);
    {
      hemilight_bake_pass_state* none = NULL;
      CHECK_FAILS(hemilight_merge_bake_pass(&f.scene, &f.options, 1, (const hemilight_bake_shard* const*)s, SHARDS, NULL, NULL, &none),
                  HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_merge_bake_pass: options->bounces is 1: a bake of one bounce has no merge");
      CHECK(none == NULL);
    }
    CHECK(hemilight_finish_sharded_bake(&f.scene, &f.options, (const hemilight_bake_shard* const*)s, SHARDS, NULL, NULL, NULL) ==
          HEMILIGHT_OK);
    for (i = 0; i < SHARDS; ++i) hemilight_bake_shard_release(s[i]);
  }
  CHECK(same_bits(&result, &reference));
}

/* 3. Without the cache, three shards are hemilight_bake_scene's bits. */
static void test_without_cache(void) {
  fixture f;
  make_fixture(&f);
  f.options.use_cache = 0;
  target(&f, &reference);
  CHECK(hemilight_bake_scene(&f.scene, &f.options, NULL) == HEMILIGHT_OK);
  target(&f, &result);
  CHECK(hemilight_bake_scene_sharded(&f.scene, &f.options, SHARDS, NULL) == HEMILIGHT_OK);
  CHECK(same_bits(&result, &reference));
}

/* 4. Refusals: named, nothing written (the handle out stays as it was, the page untouched). */
static void test_refusals(void) {
  const hemilight_status bad = HEMILIGHT_ERROR_INVALID_ARGUMENT;
  hemilight_bake_shard* pass1[SHARDS];
  hemilight_bake_shard* other[SHARDS];
  hemilight_bake_pass_state* state = NULL;
  hemilight_bake_shard* sentinel_shard = (hemilight_bake_shard*)&state; /* any non-NULL address: must stay */
  hemilight_bake_shard* s = sentinel_shard;
  hemilight_bake_pass_state* sentinel_state = (hemilight_bake_pass_state*)&s;
  hemilight_bake_pass_state* st = sentinel_state;
  const hemilight_bake_shard* list[SHARDS];
  hemilight_bake_options o;
  fixture f;
  int i;
  make_fixture(&f);
  f.options.bounces = 3;
  target(&f, &result);
  for (i = 0; i < SHARDS; ++i) CHECK(hemilight_bake_scene_shard(&f.scene, &f.options, i, SHARDS, 1, NULL, &pass1[i]) == HEMILIGHT_OK);
  CHECK(hemilight_merge_bake_pass(&f.scene, &f.options, 1, (const hemilight_bake_shard* const*)pass1, SHARDS, NULL, NULL, &state) ==
        HEMILIGHT_OK);

  /* The job's arguments. */
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &f.options, 3, 3, 1, NULL, &s), bad, "hemilight_bake_scene_shard: shard is 3");
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &f.options, -1, 3, 1, NULL, &s), bad, "must be in [0, 3)");
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &f.options, 0, 0, 1, NULL, &s), bad, "shard_count is 0");
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &f.options, 0, 4097, 1, NULL, &s), bad, "[1, 4096]");
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &f.options, 0, 3, 4, state, &s), bad, "hemilight_bake_scene_shard: pass = 4 is not in [1, 3]");
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &f.options, 0, 3, 0, NULL, &s), bad, "pass = 0");
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &f.options, 0, 3, 2, NULL, &s), bad, "pass 2 needs the state after pass 1");
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &f.options, 0, 3, 1, state, &s), bad, "pass 1 takes no previous state");
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &f.options, 0, 3, 3, state, &s), bad, "the previous state follows pass 1, not pass 2");
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &f.options, 0, 2, 2, state, &s), bad, "comes from 3 shards, this bake has 2");
  CHECK_FAILS(hemilight_bake_scene_shard(NULL, &f.options, 0, 3, 1, NULL, &s), bad, "hemilight_bake_scene_shard: scene is NULL");
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, NULL, 0, 3, 1, NULL, &s), bad, "hemilight_bake_scene_shard: options is NULL");
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &f.options, 0, 3, 1, NULL, NULL), bad, "hemilight_bake_scene_shard: out is NULL");
  /* A state from a bake with other options (another hemicube resolution): its key differs. */
  o = f.options;
  o.resolution = 32;
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &o, 0, 3, 2, state, &s), bad, "hemilight_bake_scene_shard: the previous state was made by another bake");
  CHECK_FAILS(hemilight_merge_bake_pass(&f.scene, &o, 1, (const hemilight_bake_shard* const*)pass1, SHARDS, NULL, NULL, &st), bad,
              "hemilight_merge_bake_pass: shards[0] (shard 0 of pass 1) was baked from another scene or options");
  CHECK(s == sentinel_shard && st == sentinel_state);
  /* A scene bake's own refusals come through under the job's name. */
  f.page.irradiance_capacity = 5;
  CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &f.options, 0, 3, 1, NULL, &s), bad,
              "hemilight_bake_scene_shard: scene->pages[0].irradiance_capacity 5 is below");
  f.page.irradiance_capacity = 3 * TEXELS;

  /* The merge's arguments. */
  list[0] = pass1[0];
  list[1] = pass1[0];
  list[2] = pass1[2];
  CHECK_FAILS(hemilight_merge_bake_pass(&f.scene, &f.options, 1, list, SHARDS, NULL, NULL, &st), bad,
              "hemilight_merge_bake_pass: shards[1] is shard 0 again");
  list[1] = pass1[1];
  list[2] = NULL;
  CHECK_FAILS(hemilight_merge_bake_pass(&f.scene, &f.options, 1, list, SHARDS, NULL, NULL, &st), bad,
              "hemilight_merge_bake_pass: shards[2] is NULL");
  CHECK_FAILS(hemilight_merge_bake_pass(&f.scene, &f.options, 1, NULL, SHARDS, NULL, NULL, &st), bad,
              "hemilight_merge_bake_pass: shards is NULL");
  CHECK_FAILS(hemilight_merge_bake_pass(&f.scene, &f.options, 1, (const hemilight_bake_shard* const*)pass1, 2, NULL, NULL, &st), bad,
              "shards[0] is shard 0 of 3, not one of 2");
  CHECK_FAILS(hemilight_merge_bake_pass(&f.scene, &f.options, 1, (const hemilight_bake_shard* const*)pass1, 0, NULL, NULL, &st), bad,
              "hemilight_merge_bake_pass: shard_count is 0");
  CHECK_FAILS(hemilight_merge_bake_pass(&f.scene, &f.options, 3, (const hemilight_bake_shard* const*)pass1, SHARDS,
                                        (const hemilight_bake_shard* const*)pass1, state, &st),
              bad, "hemilight_merge_bake_pass: pass is 3; it must be in [1, options->bounces - 1 = 2]");
  CHECK_FAILS(hemilight_merge_bake_pass(&f.scene, &f.options, 2, (const hemilight_bake_shard* const*)pass1, SHARDS, NULL, state, &st),
              bad, "hemilight_merge_bake_pass: first_pass is NULL");
  CHECK_FAILS(hemilight_merge_bake_pass(&f.scene, &f.options, 2, (const hemilight_bake_shard* const*)pass1, SHARDS,
                                        (const hemilight_bake_shard* const*)pass1, state, &st),
              bad, "shards[0] is a result of pass 1, not pass 2");
  CHECK_FAILS(hemilight_merge_bake_pass(&f.scene, &f.options, 1, (const hemilight_bake_shard* const*)pass1, SHARDS, NULL, NULL, NULL),
              bad, "hemilight_merge_bake_pass: out is NULL");
  CHECK(st == sentinel_state);

  /* The finish: the wrong pass's shards, a missing state; nothing written to the page. */
  CHECK_FAILS(hemilight_finish_sharded_bake(&f.scene, &f.options, (const hemilight_bake_shard* const*)pass1, SHARDS,
                                            (const hemilight_bake_shard* const*)pass1, NULL, NULL),
              bad, "hemilight_finish_sharded_bake: pass 3 needs the state after pass 2");
  CHECK_FAILS(hemilight_finish_sharded_bake(&f.scene, &f.options, (const hemilight_bake_shard* const*)pass1, SHARDS, NULL, state, NULL),
              bad, "hemilight_finish_sharded_bake: first_pass is NULL");
  CHECK_FAILS(hemilight_finish_sharded_bake(&f.scene, &f.options, (const hemilight_bake_shard* const*)pass1, 5000,
                                            (const hemilight_bake_shard* const*)pass1, state, NULL),
              bad, "hemilight_finish_sharded_bake: shard_count is 5000; it must be in [1, 4096]");
  CHECK(untouched(&result));

  /* The one-process bake. */
  CHECK_FAILS(hemilight_bake_scene_sharded(&f.scene, &f.options, 0, NULL), bad, "hemilight_bake_scene_sharded: shard_count is 0");
  CHECK_FAILS(hemilight_bake_scene_sharded(&f.scene, &f.options, 4097, NULL), bad, "[1, 4096]");
  CHECK_FAILS(hemilight_bake_scene_sharded(NULL, &f.options, 2, NULL), bad, "hemilight_bake_scene_sharded: scene is NULL");
  {
    hemilight_bake_stats stats;
    hemilight_bake_stats_init(&stats);
    stats.struct_size = 0;
    CHECK_FAILS(hemilight_bake_scene_sharded(&f.scene, &f.options, 2, &stats), bad, "stats->struct_size is 0");
  }
  CHECK(untouched(&result));

  /* Shards as plain data. */
  {
    hemilight_bake_shard_info info;
    float few[4];
    const char* names[64];
    float* values;
    size_t n, c;
    hemilight_bake_shard_info_init(&info);
    CHECK(info.struct_size == sizeof info && info.sample_count == 0 && info.key == 0);
    hemilight_bake_shard_info_init(NULL); /* ignored */
    info.reserved0 = 77;                  /* written 0 */
    CHECK(hemilight_bake_shard_get(pass1[1], &info, NULL, 0) == HEMILIGHT_OK);
    CHECK(info.pass == 1 && info.shard == 1 && info.shard_count == SHARDS && info.sample_count > 100 && info.hemicubes > 0);
    CHECK(info.channel_count >= 5 && info.channel_count <= 64 && info.reserved0 == 0 && info.seconds >= info.direct_seconds);
    CHECK(strcmp(hemilight_bake_shard_channel_name(pass1[1], 0), "E.R") == 0);
    CHECK(strcmp(hemilight_bake_shard_channel_name(pass1[1], 3), "invalid") == 0);
    CHECK(hemilight_bake_shard_channel_name(NULL, 0) == NULL);
    CHECK_FAILS(hemilight_bake_shard_get(pass1[1], &info, few, 4), bad, "hemilight_bake_shard_get: values_capacity 4 is below");
    CHECK_FAILS(hemilight_bake_shard_get(NULL, &info, NULL, 0), bad, "hemilight_bake_shard_get: shard is NULL");
    CHECK_FAILS(hemilight_bake_shard_get(pass1[1], NULL, NULL, 0), bad, "hemilight_bake_shard_get: info is NULL");
    info.struct_size = 0;
    CHECK_FAILS(hemilight_bake_shard_get(pass1[1], &info, NULL, 0), bad, "info->struct_size is 0");
    info.struct_size = sizeof info + 8;
    CHECK_FAILS(hemilight_bake_shard_get(pass1[1], &info, NULL, 0), bad, "newer hemilight.h");
    hemilight_bake_shard_info_init(&info);
    CHECK(hemilight_bake_shard_get(pass1[1], &info, NULL, 0) == HEMILIGHT_OK);
    n = info.sample_count * info.channel_count;
    values = (float*)malloc(n * sizeof(float));
    CHECK(hemilight_bake_shard_get(pass1[1], &info, values, n) == HEMILIGHT_OK);
    for (c = 0; c < info.channel_count; ++c) names[c] = hemilight_bake_shard_channel_name(pass1[1], c);
    CHECK_FAILS(hemilight_bake_shard_create(&info, names, values, n - 1, &s), bad,
                "hemilight_bake_shard_create: value_count");
    CHECK_FAILS(hemilight_bake_shard_create(&info, NULL, values, n, &s), bad, "hemilight_bake_shard_create: channel_names is NULL");
    names[2] = NULL;
    CHECK_FAILS(hemilight_bake_shard_create(&info, names, values, n, &s), bad, "channel_names[2] is NULL");
    names[2] = hemilight_bake_shard_channel_name(pass1[1], 2);
    values[info.channel_count + 1] = NAN;
    CHECK_FAILS(hemilight_bake_shard_create(&info, names, values, n, &s), bad, "values[");
    CHECK(strstr(hemilight_last_error(), "(sample 1, channel E.G) = nan") != NULL);
    values[info.channel_count + 1] = 0.5f;
    info.shard = 3;
    CHECK_FAILS(hemilight_bake_shard_create(&info, names, values, n, &s), bad, "info->shard is 3");
    info.shard = 1;
    info.pass = 0;
    CHECK_FAILS(hemilight_bake_shard_create(&info, names, values, n, &s), bad, "info->pass is 0");
    info.pass = 1;
    info.seconds = -1.0;
    CHECK_FAILS(hemilight_bake_shard_create(&info, names, values, n, &s), bad, "info->seconds");
    info.seconds = 0.0;
    CHECK_FAILS(hemilight_bake_shard_create(NULL, names, values, n, &s), bad, "hemilight_bake_shard_create: info is NULL");
    CHECK(s == sentinel_shard);
    /* A shard cut short passes the sizes here; the merge refuses it. */
    info.sample_count -= 1;
    info.reserved0 = 99; /* never used */
    CHECK(hemilight_bake_shard_create(&info, names, values, n - info.channel_count, &s) == HEMILIGHT_OK);
    list[0] = pass1[0];
    list[1] = s;
    list[2] = pass1[2];
    CHECK_FAILS(hemilight_merge_bake_pass(&f.scene, &f.options, 1, list, SHARDS, NULL, NULL, &st), bad,
                "hemilight_merge_bake_pass: shards[1] (shard 1) holds");
    hemilight_bake_shard_release(s);
    free(values);
  }

  /* States as plain data. */
  {
    hemilight_bake_pass_state_info info;
    float* rgba;
    size_t count, hemicubes[1];
    hemilight_bake_pass_state_info_init(&info);
    CHECK(hemilight_bake_pass_state_get(state, &info, NULL, 0, NULL, NULL, NULL, NULL, 0) == HEMILIGHT_OK);
    CHECK(info.pass == 1 && info.shard_count == SHARDS && info.width >= SIZE && info.height >= SIZE && info.pass_count == 1);
    count = 4 * (size_t)info.width * (size_t)info.height;
    rgba = (float*)malloc(count * sizeof(float));
    CHECK_FAILS(hemilight_bake_pass_state_get(state, &info, rgba, count - 1, NULL, NULL, NULL, NULL, 0), bad,
                "hemilight_bake_pass_state_get: radiance_capacity");
    CHECK_FAILS(hemilight_bake_pass_state_get(state, &info, NULL, 0, hemicubes, NULL, NULL, NULL, 0), bad,
                "pass_capacity 0 is below pass_count = 1");
    CHECK_FAILS(hemilight_bake_pass_state_get(NULL, &info, NULL, 0, NULL, NULL, NULL, NULL, 0), bad,
                "hemilight_bake_pass_state_get: state is NULL");
    CHECK(hemilight_bake_pass_state_get(state, &info, rgba, count, hemicubes, NULL, NULL, NULL, 1) == HEMILIGHT_OK);
    CHECK(hemicubes[0] > 0);
    rgba[4 * 5 + 3] = 0.5f; /* texel 5: x 5, y 0 */
    CHECK_FAILS(hemilight_bake_pass_state_create(&info, rgba, count, NULL, NULL, NULL, NULL, &st), bad,
                "hemilight_bake_pass_state_create: radiance_rgba[23] (texel 5: x 5, y 0, A) = 0.5");
    CHECK(strstr(hemilight_last_error(), "it must be 0 or 1") != NULL);
    rgba[4 * 5 + 3] = 1.0f;
    rgba[4 * 7 + 1] = -1.0f;
    CHECK_FAILS(hemilight_bake_pass_state_create(&info, rgba, count, NULL, NULL, NULL, NULL, &st), bad, "radiance_rgba[29] (texel 7");
    rgba[4 * 7 + 1] = 0.0f;
    CHECK_FAILS(hemilight_bake_pass_state_create(&info, rgba, count - 4, NULL, NULL, NULL, NULL, &st), bad,
                "hemilight_bake_pass_state_create: count");
    CHECK_FAILS(hemilight_bake_pass_state_create(&info, NULL, count, NULL, NULL, NULL, NULL, &st), bad, "radiance_rgba is NULL");
    info.shard_count = 0;
    CHECK_FAILS(hemilight_bake_pass_state_create(&info, rgba, count, NULL, NULL, NULL, NULL, &st), bad, "info->shard_count is 0");
    info.shard_count = SHARDS;
    info.struct_size = 3;
    CHECK_FAILS(hemilight_bake_pass_state_create(&info, rgba, count, NULL, NULL, NULL, NULL, &st), bad, "info->struct_size is 3");
    hemilight_bake_pass_state_info_init(&info);
    CHECK(hemilight_bake_pass_state_get(state, &info, NULL, 0, NULL, NULL, NULL, NULL, 0) == HEMILIGHT_OK);
    CHECK(st == sentinel_state);
    /* A state whose pass count disagrees passes the sizes here; the next job refuses it. */
    info.pass_count = 2;
    CHECK(hemilight_bake_pass_state_create(&info, rgba, count, NULL, NULL, NULL, NULL, &st) == HEMILIGHT_OK);
    CHECK_FAILS(hemilight_bake_scene_shard(&f.scene, &f.options, 0, 3, 2, st, &s), bad, "holds the statistics of 2 passes, not 1");
    hemilight_bake_pass_state_release(st);
    free(rgba);
  }

  /* Shards of another bake (another resolution) are refused by the merge, naming the index. */
  for (i = 0; i < SHARDS; ++i) CHECK(hemilight_bake_scene_shard(&f.scene, &o, i, SHARDS, 1, NULL, &other[i]) == HEMILIGHT_OK);
  list[0] = pass1[0];
  list[1] = pass1[1];
  list[2] = other[2];
  CHECK_FAILS(hemilight_merge_bake_pass(&f.scene, &f.options, 1, list, SHARDS, NULL, NULL, &st), bad,
              "hemilight_merge_bake_pass: shards[2] (shard 2 of pass 1) was baked from another scene or options");
  for (i = 0; i < SHARDS; ++i) {
    hemilight_bake_shard_release(pass1[i]);
    hemilight_bake_shard_release(other[i]);
  }
  hemilight_bake_pass_state_release(state);
}

/* 5. The releases take NULL. */
static void test_release_null(void) {
  hemilight_bake_shard_release(NULL);
  hemilight_bake_pass_state_release(NULL);
  CHECK(1);
}

int main(void) {
  test_one_shard();
  test_job_by_job();
  test_without_cache();
  test_refusals();
  test_release_null();
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
