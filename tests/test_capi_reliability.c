/* C99 regression tests of the C ABI's reliability fixes, one per reproducer of a fuzzing run:
 * tiny and huge normals and directions (their squares under- or overflow float), points spanning
 * more than float can square, radiance near FLT_MAX and lights whose irradiance overflows (refused,
 * never +inf on OK), the EXR writers' and cube maps' size limits, bake errors in the caller's
 * terms (the mesh and the index within it), and crafted EXR files refused within 64 MiB (peak
 * resident set of a child process). References: closed forms (a uniform sky gives pi L) and the
 * same call with the unit vector. Prints failing checks and "N passed, N failed". */
#define _POSIX_C_SOURCE 200809L /* fork, pipe, getrusage */
#include "capi_check.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__unix__) || defined(__APPLE__)
#define HAVE_FORK 1
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>
#endif

static const double pi = 3.14159265358979323846;

static void test_normals_and_radiance(void) {
  /* A quad emitter (radiance 1) above the origin, off to the +x side, facing down. */
  const float pos[] = {0.2f, -0.5f, 1.0f, 0.2f, 0.5f, 1.0f, 1.2f, 0.5f, 1.0f, 1.2f, -0.5f, 1.0f};
  const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
  const float rad[] = {1, 1, 1, 1, 1, 1}, big[] = {FLT_MAX, 1, 1, 1, 1, 1};
  const float sky0[3] = {0, 0, 0}, skymax[3] = {FLT_MAX, 1, 1};
  const float p[3] = {0, 0, 0};
  const float unit[3] = {0.70710678f, 0, 0.70710678f};
  const float normals[][3] = {{7.071e-23f, 0, 7.071e-23f}, {1e-30f, 0, 1e-30f}, {1e30f, 0, 1e30f}, {3e19f, 0, 3e19f}};
  hemilight_scene *s = NULL, *bad = NULL;
  hemilight_irradiance ref, r;
  int i;
  CHECK(hemilight_scene_create(pos, 4, idx, 2, rad, sky0, &s) == HEMILIGHT_OK);
  CHECK(hemilight_sample_irradiance(s, p, unit, 64, &ref) == HEMILIGHT_OK);
  for (i = 0; i < 4; ++i) {
    CHECK(hemilight_sample_irradiance(s, p, normals[i], 64, &r) == HEMILIGHT_OK);
    /* The same direction: the same frame to float rounding of the unit vector (1e-5). */
    CHECK(fabs(r.irradiance[0] - ref.irradiance[0]) <= 1e-5 * ref.irradiance[0]);
  }
  /* Radiance above 1e30 (max_radiance) is refused where it is given. */
  bad = (hemilight_scene*)&passed;
  CHECK_FAILS(hemilight_scene_create(pos, 4, idx, 2, rad, skymax, &bad), HEMILIGHT_ERROR_INVALID_ARGUMENT, "at most 1e30");
  CHECK_FAILS(hemilight_scene_create(pos, 4, idx, 2, big, sky0, &bad), HEMILIGHT_ERROR_INVALID_ARGUMENT, "triangle_radiance[0]");
  CHECK(bad == (hemilight_scene*)&passed);
  hemilight_scene_release(s);
}

static void test_light_overflow(void) {
  /* A point light of intensity 1e30 a hair above the point: I / d^2 overflows float. Refused,
   * never OK with +inf. */
  const float sky0[3] = {0, 0, 0}, p[3] = {0, 0, 0}, up[3] = {0, 0, 1};
  hemilight_scene *empty = NULL, *lit = NULL;
  hemilight_light l;
  hemilight_irradiance r, untouched;
  float sh[27], untouched_sh[27];
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky0, &empty) == HEMILIGHT_OK);
  hemilight_light_init(&l, HEMILIGHT_LIGHT_POINT);
  l.position[0] = 0, l.position[1] = 0, l.position[2] = 1e-10f;
  l.color[0] = l.color[1] = l.color[2] = 1e30f;
  CHECK(hemilight_scene_with_lights(empty, &l, 1, &lit) == HEMILIGHT_OK);
  memset(&untouched, 0x5a, sizeof untouched);
  r = untouched;
  CHECK_FAILS(hemilight_sample_irradiance(lit, p, up, 8, &r), HEMILIGHT_ERROR_INVALID_ARGUMENT, "overflows float");
  CHECK(memcmp(&r, &untouched, sizeof r) == 0);
  memset(untouched_sh, 0x5a, sizeof untouched_sh);
  memcpy(sh, untouched_sh, sizeof sh);
  CHECK_FAILS(hemilight_sample_probes(lit, p, 1, 8, 1, sh), HEMILIGHT_ERROR_INVALID_ARGUMENT, "point 0: the probe overflows");
  CHECK(memcmp(sh, untouched_sh, sizeof sh) == 0);
  l.color[0] = 2e30f;
  hemilight_scene_release(lit);
  lit = NULL;
  CHECK_FAILS(hemilight_scene_with_lights(empty, &l, 1, &lit), HEMILIGHT_ERROR_INVALID_ARGUMENT, "lights[0].color.r");
  CHECK(lit == NULL);
  hemilight_scene_release(empty);
}

static void test_cubemap_directions(void) {
  /* A 2 x 2 map whose face f holds the value f + 1: the face a direction picks is visible. */
  float map[6 * 2 * 2 * 3];
  float rgb[3], ref[3];
  int i, smp, fix;
  const float dirs[][3] = {{1e-45f, 0, 0}, {1e-45f, 1e-45f, 1e-45f}, {FLT_MAX, FLT_MAX, FLT_MAX}, {-0.0f, -0.0f, 1e-40f},
                           {0, -3e38f, 1e37f}};
  const float units[][3] = {{1, 0, 0}, {1, 1, 1}, {1, 1, 1}, {0, 0, 1}, {0, -1, 1.0f / 30.0f}};
  for (i = 0; i < 72; ++i) map[i] = (float)(i / 12 + 1);
  for (i = 0; i < 5; ++i)
    for (smp = 0; smp <= 1; ++smp)
      for (fix = 0; fix <= 1; ++fix) {
        rgb[0] = rgb[1] = rgb[2] = -7;
        CHECK(hemilight_cubemap_sample(map, 2, 1, dirs[i], 0.0f, (hemilight_cube_sampling)smp, fix, rgb) == HEMILIGHT_OK);
        CHECK(hemilight_cubemap_sample(map, 2, 1, units[i], 0.0f, (hemilight_cube_sampling)smp, fix, ref) == HEMILIGHT_OK);
        CHECK(isfinite(rgb[0]) && fabs(rgb[0] - ref[0]) < 1e-5f);
      }
  CHECK(hemilight_cubemap_fixup_lookup(dirs[0], 64, 0.0f, rgb) == HEMILIGHT_OK);
  /* Filter input near FLT_MAX (found by fuzz_cubemap: sums overflowed to +inf on OK): refused. */
  {
    float out[72];
    map[5] = 3e38f;
    CHECK_FAILS(hemilight_cubemap_filter_irradiance(map, 2, HEMILIGHT_EDGE_FIXUP_NONE, 2, 0, out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
                "input value 5");
    map[5] = 1.0f;
  }
  CHECK(isfinite(rgb[0]) && isfinite(rgb[1]) && isfinite(rgb[2]) && rgb[0] > 0.0f);
}

static void test_cache_extent(void) {
  const float sky[3] = {1, 1, 1};
  const float nrm[6] = {0, 0, 1, 0, 0, 1};
  /* Coordinates beyond 1e18 (max_coordinate) are refused as such; within it, points spanning more
   * than 1e18 (max_point_extent) too. */
  const float half_extents[] = {1.1e19f, 2e38f, 9e17f};
  const char* why[] = {"beyond 1e18", "beyond 1e18", "the points span"};
  float pos[6], out[6];
  hemilight_scene* s = NULL;
  hemilight_cache_options o;
  int k;
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &s) == HEMILIGHT_OK);
  hemilight_cache_options_init(&o);
  o.resolution = 8;
  o.thread_count = 1;
  for (k = 0; k < 3; ++k) {
    pos[0] = -half_extents[k], pos[1] = 0, pos[2] = 0, pos[3] = half_extents[k], pos[4] = 0, pos[5] = 0;
    out[0] = out[3] = -7.0f;
    CHECK_FAILS(hemilight_cache_irradiance(s, pos, nrm, 2, &o, out, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, why[k]);
    CHECK(out[0] == -7.0f && out[3] == -7.0f);
  }
  /* 1e17 apart works: a uniform sky gives pi L at both. */
  pos[0] = -5e16f, pos[3] = 5e16f;
  /* A denormal error threshold (found by fuzz_cache: the spacings a R underflowed to 0 and the
   * placement never ended) is refused: [0.001, 1]. */
  o.error_threshold = 9.4e-40f;
  CHECK_FAILS(hemilight_cache_irradiance(s, pos, nrm, 2, &o, out, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "[0.001, 1]");
  o.error_threshold = 0.2f;
  CHECK(hemilight_cache_irradiance(s, pos, nrm, 2, &o, out, NULL) == HEMILIGHT_OK);
  CHECK(fabs(out[0] / pi - 1.0) < 1e-5 && fabs(out[3] / pi - 1.0) < 1e-5);
  hemilight_scene_release(s);
}

static void test_sizes_and_messages(const char* tmp) {
  static float px[18];
  char path[512];
  FILE* f;
  hemilight_scene *s = NULL, *e = NULL;
  const float sky[3] = {1, 1, 1};
  snprintf(path, sizeof path, "%s/reliability_over_limit.exr", tmp);
  remove(path);
  CHECK_FAILS(hemilight_exr_save_rgb(path, px, 16385, 16384, 0), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_exr_save_rgb: width x height = 16385 x 16384 is over the limit");
  CHECK_FAILS(hemilight_exr_save_cubemap_rgb(path, px, 6689, 0), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_exr_save_cubemap_rgb: size 6689 is over the limit of 6688");
  f = fopen(path, "rb");
  CHECK(f == NULL);
  if (f) fclose(f);
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &s) == HEMILIGHT_OK);
  CHECK_FAILS(hemilight_scene_with_environment(s, px, 6689, &e), HEMILIGHT_ERROR_INVALID_ARGUMENT, "out of range: 1..6688");
  CHECK(e == NULL);
  hemilight_scene_release(s);
}

static void test_bake_messages(void) {
  /* Two floor quads; the second (meshes[1]) gets the bad values. */
  static const float pa[] = {0, 0, 0, 0, 0, -1, 1, 0, -1, 1, 0, 0}, pb[] = {1, 0, 0, 1, 0, -1, 2, 0, -1, 2, 0, 0};
  static const float ua[] = {0, 0, 0, 1, .5f, 1, .5f, 0}, ub[] = {.5f, 0, .5f, 1, 1, 1, 1, 0};
  static const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
  hemilight_bake_material mats[2];
  hemilight_bake_mesh m[2];
  hemilight_bake_options o;
  float out[3 * 64], untouched[3 * 64], bad_uv[8];
  memset(m, 0, sizeof m);
  memset(mats, 0, sizeof mats);
  m[0].positions = pa, m[0].lightmap_uvs = ua, m[0].vertex_count = 4, m[0].indices = idx, m[0].triangle_count = 2;
  m[1] = m[0];
  m[1].positions = pb, m[1].lightmap_uvs = ub, m[1].materials = mats;
  hemilight_bake_options_init(&o);
  o.width = o.height = 8, o.resolution = 8;
  memset(untouched, 0x5a, sizeof untouched);
  memcpy(out, untouched, sizeof out);
  CHECK(hemilight_bake_lightmap(m, 2, &o, out, 192, NULL, 0, NULL) == HEMILIGHT_OK);
  memcpy(out, untouched, sizeof out);
  mats[1].emission[2] = -1.0f;
  CHECK_FAILS(hemilight_bake_lightmap(m, 2, &o, out, 192, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_lightmap: meshes[1].materials[1].emission[2] = -1");
  mats[1].emission[2] = 0.0f;
  mats[0].two_sided = 7;
  CHECK_FAILS(hemilight_bake_lightmap(m, 2, &o, out, 192, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "meshes[1].materials[0].two_sided = 7");
  mats[0].two_sided = 0;
  memcpy(bad_uv, ub, sizeof bad_uv);
  bad_uv[3] = NAN;
  m[1].lightmap_uvs = bad_uv;
  CHECK_FAILS(hemilight_bake_lightmap(m, 2, &o, out, 192, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "meshes[1].lightmap_uvs[3] (vertex 1, v)");
  m[1].lightmap_uvs = ub;
  o.error_threshold = NAN;
  o.use_cache = 0;
  CHECK_FAILS(hemilight_bake_lightmap(m, 2, &o, out, 192, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "options->error_threshold is nan");
  CHECK(memcmp(out, untouched, sizeof out) == 0);
}

/* The rule for arrays and counts (hemilight.h, "Conventions"), for every entry that takes an array
 * with a count: a count of 0 never skips the check of another argument; an array may be NULL only
 * when its count is 0; count 0 with valid arguments succeeds and writes nothing (or makes an empty
 * set), except in the entries whose Errors refuse it (the cache, the bakes). Found by fuzzing: the
 * batch and the probes with count 0 accepted N = 3 and thread_count = -1. */
static void test_count_zero(void) {
  static const float pa[] = {0, 0, 0, 0, 0, -1, 1, 0, -1, 1, 0, 0}, ua[] = {0, 0, 0, 1, 1, 1, 1, 0};
  static const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
  const float sky[3] = {1, 1, 1}, nan_sky[3] = {NAN, 1, 1}, nan_pos[3] = {NAN, 0, 0};
  const float p[3] = {0, 0, 1}, up[3] = {0, 0, 1};
  hemilight_scene *s = NULL, *lit = NULL, *sentinel = (hemilight_scene*)&passed, *t = sentinel;
  hemilight_irradiance r[1], r_untouched[1];
  float sh[27], sh_untouched[27], bf[1] = {-7.0f}, e[3] = {-7.0f, -7.0f, -7.0f};
  hemilight_cache_options co;
  hemilight_bake_mesh m[2];
  hemilight_bake_options o;
  hemilight_bake_scene_desc sd;
  hemilight_bake_page page;
  hemilight_bake_placement placement = {0, {1, 1}, {0, 0}};
  float one[3 * 16], two[3 * 16], untouched[3 * 16];

  /* hemilight_scene_create: no vertices, no triangles (the arrays NULL) is the empty scene; the
   * other arguments are checked all the same, and triangle_count 0 does not skip the vertices. */
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &s) == HEMILIGHT_OK);
  CHECK_FAILS(hemilight_scene_create(NULL, 0, NULL, 0, NULL, NULL, &t), HEMILIGHT_ERROR_INVALID_ARGUMENT, "sky_radiance is NULL");
  CHECK_FAILS(hemilight_scene_create(NULL, 0, NULL, 0, NULL, nan_sky, &t), HEMILIGHT_ERROR_INVALID_ARGUMENT, "sky_radiance (nan");
  CHECK_FAILS(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "out is NULL");
  CHECK_FAILS(hemilight_scene_create(nan_pos, 1, NULL, 0, NULL, sky, &t), HEMILIGHT_ERROR_INVALID_ARGUMENT, "positions[0] (vertex 0)");
  CHECK_FAILS(hemilight_scene_create(NULL, 1, NULL, 0, NULL, sky, &t), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "positions is NULL but vertex_count is 1");
  CHECK(t == sentinel);

  /* hemilight_scene_with_lights: count 0 (lights NULL) is a scene without lights. */
  CHECK(hemilight_scene_with_lights(s, NULL, 0, &lit) == HEMILIGHT_OK);
  hemilight_scene_release(lit);
  CHECK_FAILS(hemilight_scene_with_lights(NULL, NULL, 0, &t), HEMILIGHT_ERROR_INVALID_ARGUMENT, "scene is NULL");
  CHECK_FAILS(hemilight_scene_with_lights(s, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "out is NULL");
  CHECK_FAILS(hemilight_scene_with_lights(s, NULL, 1, &t), HEMILIGHT_ERROR_INVALID_ARGUMENT, "lights is NULL but the count is 1");
  CHECK(t == sentinel);

  /* hemilight_sample_irradiance_batch: count 0 writes nothing; every other argument is checked. */
  memset(r_untouched, 0x5a, sizeof r_untouched);
  memcpy(r, r_untouched, sizeof r);
  CHECK(hemilight_sample_irradiance_batch(s, NULL, NULL, 0, 16, 0, NULL) == HEMILIGHT_OK);
  CHECK(hemilight_sample_irradiance_batch(s, p, up, 0, 16, 1, r) == HEMILIGHT_OK);
  CHECK_FAILS(hemilight_sample_irradiance_batch(NULL, p, up, 0, 16, 1, r), HEMILIGHT_ERROR_INVALID_ARGUMENT, "scene is NULL");
  CHECK_FAILS(hemilight_sample_irradiance_batch(s, p, up, 0, 3, 1, r), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_sample_irradiance_batch: resolution 3 is invalid");
  CHECK_FAILS(hemilight_sample_irradiance_batch(s, p, up, 0, 16, -1, r), HEMILIGHT_ERROR_INVALID_ARGUMENT, "thread_count is -1");
  CHECK_FAILS(hemilight_sample_irradiance_batch(s, NULL, up, 1, 16, 1, r), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "positions is NULL but count is 1");
  CHECK_FAILS(hemilight_sample_irradiance_batch(s, p, NULL, 1, 16, 1, r), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "normals is NULL but count is 1");
  CHECK_FAILS(hemilight_sample_irradiance_batch(s, p, up, 1, 16, 1, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "out is NULL but count is 1");
  CHECK(memcmp(r, r_untouched, sizeof r) == 0);

  /* hemilight_sample_probes and _with_backfaces: the same. */
  memset(sh_untouched, 0x5a, sizeof sh_untouched);
  memcpy(sh, sh_untouched, sizeof sh);
  CHECK(hemilight_sample_probes(s, NULL, 0, 16, 0, NULL) == HEMILIGHT_OK);
  CHECK(hemilight_sample_probes(s, p, 0, 16, 1, sh) == HEMILIGHT_OK);
  CHECK(hemilight_sample_probes_with_backfaces(s, NULL, 0, 16, 0, NULL, NULL) == HEMILIGHT_OK);
  CHECK_FAILS(hemilight_sample_probes(NULL, p, 0, 16, 1, sh), HEMILIGHT_ERROR_INVALID_ARGUMENT, "scene is NULL");
  CHECK_FAILS(hemilight_sample_probes(s, p, 0, 3, 1, sh), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_sample_probes: resolution 3 is invalid");
  CHECK_FAILS(hemilight_sample_probes(s, p, 0, 16, -1, sh), HEMILIGHT_ERROR_INVALID_ARGUMENT, "thread_count is -1");
  CHECK_FAILS(hemilight_sample_probes_with_backfaces(NULL, NULL, 0, 16, 0, NULL, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_sample_probes_with_backfaces: scene is NULL");
  CHECK_FAILS(hemilight_sample_probes_with_backfaces(s, NULL, 0, 3, 0, NULL, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "resolution 3 is invalid");
  CHECK_FAILS(hemilight_sample_probes_with_backfaces(s, NULL, 0, 16, -1, NULL, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "thread_count is -1");
  CHECK_FAILS(hemilight_sample_probes(s, NULL, 1, 16, 1, sh), HEMILIGHT_ERROR_INVALID_ARGUMENT, "positions is NULL but count is 1");
  CHECK_FAILS(hemilight_sample_probes(s, p, 1, 16, 1, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "sh9_rgb is NULL but count is 1");
  CHECK_FAILS(hemilight_sample_probes_with_backfaces(s, p, 1, 16, 1, sh, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "backface_fraction is NULL but count is 1");
  CHECK(memcmp(sh, sh_untouched, sizeof sh) == 0 && bf[0] == -7.0f);

  /* hemilight_cache_irradiance needs points: count 0 is refused (its Errors), with valid arguments
   * as with a NULL scene. */
  hemilight_cache_options_init(&co);
  CHECK_FAILS(hemilight_cache_irradiance(s, p, up, 0, &co, e, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "count is 0");
  CHECK_FAILS(hemilight_cache_irradiance(NULL, p, up, 0, &co, e, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "scene is NULL");
  CHECK(e[0] == -7.0f);

  /* The bakes: mesh_count 0 and page_count 0 are refused (their Errors); a mesh without vertices or
   * triangles may have NULL arrays and adds nothing (bitwise the same bake without it), but its
   * material is checked; options->light_count 0 takes NULL lights, 1 does not. */
  memset(m, 0, sizeof m);
  m[0].positions = pa, m[0].lightmap_uvs = ua, m[0].vertex_count = 4, m[0].indices = idx, m[0].triangle_count = 2;
  hemilight_bake_options_init(&o);
  o.width = o.height = 4, o.resolution = 8;
  o.sky_radiance[0] = o.sky_radiance[1] = o.sky_radiance[2] = 1.0f;
  memset(untouched, 0x5a, sizeof untouched);
  memcpy(two, untouched, sizeof two);
  CHECK(hemilight_bake_lightmap(m, 1, &o, one, 48, NULL, 0, NULL) == HEMILIGHT_OK);
  CHECK(hemilight_bake_lightmap(m, 2, &o, two, 48, NULL, 0, NULL) == HEMILIGHT_OK);
  CHECK(memcmp(one, two, sizeof one) == 0 && fabs(one[0] / pi - 1.0) < 1e-5);
  memcpy(two, untouched, sizeof two);
  m[1].material.albedo[0] = 2.0f;
  CHECK_FAILS(hemilight_bake_lightmap(m, 2, &o, two, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "meshes[1].material.albedo[0] = 2");
  m[1].material.albedo[0] = 0.0f;
  o.light_count = 1;
  CHECK_FAILS(hemilight_bake_lightmap(m, 1, &o, two, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "options->lights is NULL but the count is 1");
  o.light_count = 0;
  CHECK_FAILS(hemilight_bake_lightmap(m, 0, &o, two, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "mesh_count is 0");
  CHECK_FAILS(hemilight_bake_lightmap_directional(m, 0, &o, two, 48, NULL, 0, NULL, 0, NULL, 0, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_bake_lightmap_directional: mesh_count is 0");
  memset(&page, 0, sizeof page);
  page.width = page.height = 4, page.irradiance_rgb = two, page.irradiance_capacity = 48;
  hemilight_bake_scene_desc_init(&sd);
  sd.meshes = m, sd.mesh_count = 0, sd.placements = &placement, sd.pages = &page, sd.page_count = 1;
  CHECK_FAILS(hemilight_bake_scene(&sd, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "scene->mesh_count is 0");
  sd.mesh_count = 1, sd.page_count = 0;
  CHECK_FAILS(hemilight_bake_scene(&sd, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "scene->page_count is 0");
  CHECK(memcmp(two, untouched, sizeof two) == 0);
  hemilight_scene_release(s);
}

/* Crafted EXR files (tests/data/): headers claiming 16384^2 pixels in an 8.5 KB file, and an
 * attribute whose size field claims 1.6 GB in a 599-byte file. They fail (IO) from the header
 * alone, before any pixel is allocated, with the C function's name; nothing is written. */
static void test_crafted_exr(const char* data) {
  const char* files[] = {"exr_header_16384x16384_incomplete.exr", "exr_header_16384x16385_incomplete.exr",
                         "exr_opaque_attr_1.6GB_alloc.exr"};
  /* (16384 x 16385 is over the 2^28-pixel limit: OUT_OF_MEMORY, as the header documents.) */
  const char* why[] = {"truncated", "exceeds the limit of 2^28 pixels", "claims 1634231040 bytes"};
  const hemilight_status code[] = {HEMILIGHT_ERROR_IO, HEMILIGHT_ERROR_OUT_OF_MEMORY, HEMILIGHT_ERROR_IO};
  char path[1024];
  int i, w = -7, h = -7, cube = -7;
  float px[3] = {-7, -7, -7};
  for (i = 0; i < 3; ++i) {
    snprintf(path, sizeof path, "%s/%s", data, files[i]);
    CHECK_FAILS(hemilight_exr_info(path, &w, &h, &cube), code[i], why[i]);
    CHECK(strncmp(hemilight_last_error(), "hemilight_exr_info: ", 20) == 0);
    CHECK_FAILS(hemilight_exr_load_rgb(path, px, 3, &w, &h), code[i], "hemilight_exr_load_rgb: ");
    CHECK_FAILS(hemilight_exr_load_cubemap_rgb(path, px, 3, &w), code[i], "hemilight_exr_load_cubemap_rgb: ");
  }
  CHECK(w == -7 && h == -7 && cube == -7 && px[0] == -7.0f);
}

#if HAVE_FORK
/* What a child process reports of one EXR load: the call's status and message, whether the
 * 48-float buffer stayed untouched, and the child's peak resident set (getrusage). */
struct load_report {
  int status, untouched;
  long peak_kib;
  char message[400];
};

/* Runs entry 0 (hemilight_exr_info), 1 (hemilight_exr_load_rgb) or 2 (hemilight_exr_load_cubemap_rgb)
 * on `path` in a child process, with a buffer of 48 floats. Returns 0 and fills *r, or -1 if the
 * child could not run. */
static int load_in_child(const char* path, int entry, struct load_report* r) {
  int fd[2], child_status = 0;
  pid_t pid;
  ssize_t got;
  if (pipe(fd) != 0) return -1;
  fflush(stdout);
  pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    struct load_report c;
    struct rusage u;
    float px[48];
    int i, w = -7, h = -7, cube = -7;
    close(fd[0]);
    memset(&c, 0, sizeof c);
    for (i = 0; i < 48; ++i) px[i] = -7.0f;
    c.status = entry == 0   ? (int)hemilight_exr_info(path, &w, &h, &cube)
               : entry == 1 ? (int)hemilight_exr_load_rgb(path, px, 48, &w, &h)
                            : (int)hemilight_exr_load_cubemap_rgb(path, px, 48, &w);
    getrusage(RUSAGE_SELF, &u);
#if defined(__APPLE__)
    c.peak_kib = (long)(u.ru_maxrss / 1024); /* bytes there */
#else
    c.peak_kib = (long)u.ru_maxrss; /* KiB on Linux */
#endif
    c.untouched = 1;
    for (i = 0; i < 48; ++i) c.untouched = c.untouched && px[i] == -7.0f;
    if (c.status != HEMILIGHT_OK) c.untouched = c.untouched && w == -7 && h == -7 && cube == -7;
    strncpy(c.message, hemilight_last_error(), sizeof c.message - 1);
    got = write(fd[1], &c, sizeof c);
    _exit(got == (ssize_t)sizeof c ? 0 : 1);
  }
  close(fd[1]);
  got = read(fd[0], r, sizeof *r);
  close(fd[0]);
  if (waitpid(pid, &child_status, 0) != pid || got != (ssize_t)sizeof *r) return -1;
  return WIFEXITED(child_status) && WEXITSTATUS(child_status) == 0 ? 0 : -1;
}

/* Every entry that reads EXR refuses each crafted file with a peak resident set under 64 MiB
 * (measured in a child process: getrusage's ru_maxrss, the whole process: at most 6 MiB in a
 * Release build, 25 MiB under ASan, whose shadow memory counts too). A loader that decodes before
 * comparing the header's size with the capacity fails here: exr_load_capacity_checked_after_decode.exr
 * (377 bytes, RLE, a 16,514,819 x 2 data window that hemilight_exr_info accepts) then costs 480 MiB
 * in both loaders, and exr_cube_768_constant.exr (a valid 768 x 4608 cube map of 0.25, written by
 * hemilight_exr_save_cubemap_rgb with half_float = 1) 89 MiB in the cube-map loader. */
static void test_crafted_exr_peak(const char* data) {
  struct case_ {
    const char* file;
    int entry;
    hemilight_status status;
    const char* why;
  };
  static const struct case_ cases[] = {
      {"exr_load_capacity_checked_after_decode.exr", 0, HEMILIGHT_OK, ""},
      {"exr_load_capacity_checked_after_decode.exr", 1, HEMILIGHT_ERROR_INVALID_ARGUMENT,
       "hemilight_exr_load_rgb: capacity 48 floats is too small"},
      {"exr_load_capacity_checked_after_decode.exr", 2, HEMILIGHT_ERROR_UNSUPPORTED, "a cube map must be w x 6w pixels"},
      {"exr_cube_768_constant.exr", 1, HEMILIGHT_ERROR_INVALID_ARGUMENT, "capacity 48 floats is too small"},
      {"exr_cube_768_constant.exr", 2, HEMILIGHT_ERROR_INVALID_ARGUMENT,
       "hemilight_exr_load_cubemap_rgb: capacity 48 floats is too small"},
      {"exr_header_16384x16384_incomplete.exr", 0, HEMILIGHT_ERROR_IO, "truncated"},
      {"exr_header_16384x16384_incomplete.exr", 1, HEMILIGHT_ERROR_IO, "truncated"},
      {"exr_header_16384x16384_incomplete.exr", 2, HEMILIGHT_ERROR_IO, "truncated"},
      {"exr_header_16384x16385_incomplete.exr", 0, HEMILIGHT_ERROR_OUT_OF_MEMORY, "2^28 pixels"},
      {"exr_header_16384x16385_incomplete.exr", 1, HEMILIGHT_ERROR_OUT_OF_MEMORY, "2^28 pixels"},
      {"exr_header_16384x16385_incomplete.exr", 2, HEMILIGHT_ERROR_OUT_OF_MEMORY, "2^28 pixels"},
      {"exr_opaque_attr_1.6GB_alloc.exr", 0, HEMILIGHT_ERROR_IO, "claims 1634231040 bytes"},
      {"exr_opaque_attr_1.6GB_alloc.exr", 1, HEMILIGHT_ERROR_IO, "claims 1634231040 bytes"},
      {"exr_opaque_attr_1.6GB_alloc.exr", 2, HEMILIGHT_ERROR_IO, "claims 1634231040 bytes"}};
  const long limit_kib = 64 * 1024;
  long largest_kib = 0;
  char path[1024];
  size_t i;
  for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    struct load_report r;
    snprintf(path, sizeof path, "%s/%s", data, cases[i].file);
    CHECK(load_in_child(path, cases[i].entry, &r) == 0);
    if (r.peak_kib > largest_kib) largest_kib = r.peak_kib;
    CHECK(r.status == (int)cases[i].status);
    CHECK(strstr(r.message, cases[i].why) != NULL);
    CHECK(r.untouched);
    CHECK(r.peak_kib > 0 && r.peak_kib < limit_kib);
    if (r.status != (int)cases[i].status || !strstr(r.message, cases[i].why) || !(r.peak_kib > 0 && r.peak_kib < limit_kib))
      printf("  %s, entry %d: status %d, peak %ld KiB, message: %s\n", cases[i].file, cases[i].entry, r.status, r.peak_kib,
             r.message);
  }
  printf("crafted EXR files: the largest peak of a child process was %ld KiB (limit %ld)\n", largest_kib, limit_kib);
}
#endif

int main(int argc, char** argv) {
  test_normals_and_radiance();
  test_light_overflow();
  test_cubemap_directions();
  test_cache_extent();
  test_sizes_and_messages(argc > 1 ? argv[1] : ".");
  test_bake_messages();
  test_count_zero();
  if (argc > 2) test_crafted_exr(argv[2]);
#if HAVE_FORK
  if (argc > 2) test_crafted_exr_peak(argv[2]);
#endif
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
