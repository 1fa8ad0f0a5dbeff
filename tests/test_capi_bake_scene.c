/* C99 test of the C ABI's scene bake: hemilight_bake_scene_desc_init, hemilight_bake_scene with
 * pages, per-mesh placements (scale and offset), an occluder-only mesh without UVs and per-page
 * material images.
 * References: a one-page scene bake is bitwise hemilight_bake_lightmap; a uniform sky of radiance
 * L over unoccluded up-facing quads gives E = pi L (closed form); a hard sun straight down gives
 * exactly its irradiance where the occluder does not cover and exactly 0 where it does (sky 0,
 * black occluder, one bounce). Bad input names the function and the mesh, page or placement with
 * the index within it, and leaves every output buffer untouched.
 * Prints failing checks and a closing "N passed, N failed" line. */
#include "capi_check.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define W 8
#define H 8
static float single[3 * 2 * W * H];
static float page_out[2][3 * W * H];
static uint8_t page_valid[2][W * H];
static float albedo[3 * W * H];

static void fill_sentinel(void) {
  int p, i;
  for (p = 0; p < 2; ++p) {
    for (i = 0; i < 3 * W * H; ++i) page_out[p][i] = -7.0f;
    memset(page_valid[p], 9, sizeof page_valid[p]);
  }
}
static int untouched(void) {
  int p, i;
  for (p = 0; p < 2; ++p) {
    for (i = 0; i < 3 * W * H; ++i)
      if (page_out[p][i] != -7.0f) return 0;
    for (i = 0; i < W * H; ++i)
      if (page_valid[p][i] != 9) return 0;
  }
  return 1;
}

int main(void) {
  /* Two unit floor quads side by side (x in [0, 1] and [1, 2]), facing up; UVs: each on half of a
   * 2W x H map (u in [0, 0.5] and [0.5, 1]). */
  static const float pos_a[] = {0, 0, 0, 1, 0, 0, 1, 0, -1, 0, 0, -1};
  static const float pos_b[] = {1, 0, 0, 2, 0, 0, 2, 0, -1, 1, 0, -1};
  static const float uv_a[] = {0, 0, 0.5f, 0, 0.5f, 1, 0, 1};
  static const float uv_b[] = {0.5f, 0, 1, 0, 1, 1, 0.5f, 1};
  /* A black square 0.5 above quad A, front facing down, reaching x = 1 exactly (occluder only). */
  static const float pos_c[] = {-0.5f, 0.5f, 0.5f, -0.5f, 0.5f, -1.5f, 1, 0.5f, -1.5f, 1, 0.5f, 0.5f};
  static const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
  hemilight_bake_mesh meshes[3];
  hemilight_bake_placement placements[3];
  hemilight_bake_page pages[2];
  hemilight_bake_scene_desc scene;
  hemilight_bake_options o;
  hemilight_bake_stats stats;
  int i, p, ok;

  memset(meshes, 0, sizeof meshes);
  meshes[0].positions = pos_a;
  meshes[0].lightmap_uvs = uv_a;
  meshes[0].vertex_count = 4;
  meshes[0].indices = idx;
  meshes[0].triangle_count = 2;
  meshes[0].material.albedo[0] = meshes[0].material.albedo[1] = meshes[0].material.albedo[2] = 0.5f;
  meshes[1] = meshes[0];
  meshes[1].positions = pos_b;
  meshes[1].lightmap_uvs = uv_b;
  meshes[2] = meshes[0];
  meshes[2].positions = pos_c;
  meshes[2].lightmap_uvs = NULL; /* an occluder needs none */
  meshes[2].indices = idx; /* (v1 - v0) x (v2 - v0) points down */
  meshes[2].material.albedo[0] = meshes[2].material.albedo[1] = meshes[2].material.albedo[2] = 0.0f;

  hemilight_bake_scene_desc_init(&scene);
  hemilight_bake_scene_desc_init(NULL); /* ignored */
  CHECK(scene.struct_size == sizeof scene && scene.meshes == NULL && scene.mesh_count == 0 && scene.placements == NULL);
  CHECK(scene.pages == NULL && scene.page_count == 0 && scene.occluder_radiance == HEMILIGHT_OCCLUDER_EMISSION);

  hemilight_bake_options_init(&o);
  o.width = 2 * W;
  o.height = H;
  o.resolution = 16;
  o.bounces = 2;
  o.sky_radiance[0] = o.sky_radiance[1] = o.sky_radiance[2] = 1.0f;

  /* 1. One page with both meshes, identity placement: bitwise hemilight_bake_lightmap. */
  CHECK(hemilight_bake_lightmap(meshes, 2, &o, single, 3 * 2 * W * H, NULL, 0, NULL) == HEMILIGHT_OK);
  memset(placements, 0, sizeof placements);
  for (i = 0; i < 3; ++i) placements[i].uv_scale[0] = placements[i].uv_scale[1] = 1.0f;
  memset(pages, 0, sizeof pages);
  {
    static float one[3 * 2 * W * H];
    hemilight_bake_page whole;
    memset(&whole, 0, sizeof whole);
    whole.width = 2 * W;
    whole.height = H;
    whole.irradiance_rgb = one;
    whole.irradiance_capacity = 3 * 2 * W * H;
    scene.meshes = meshes;
    scene.mesh_count = 2;
    scene.placements = placements;
    scene.pages = &whole;
    scene.page_count = 1;
    o.width = o.height = 1; /* ignored by scene bakes */
    CHECK(hemilight_bake_scene(&scene, &o, NULL) == HEMILIGHT_OK);
    CHECK(memcmp(one, single, sizeof one) == 0);
  }

  /* 2. Each quad on a page of its own (scale (2, 1); offsets 0 and -1), E = pi L everywhere: the
   * quads see only the sky. Float sums of exact hemicube weights: 1e-4. */
  for (p = 0; p < 2; ++p) {
    pages[p].width = W;
    pages[p].height = H;
    pages[p].irradiance_rgb = page_out[p];
    pages[p].irradiance_capacity = 3 * W * H;
    pages[p].valid = page_valid[p];
    pages[p].valid_capacity = W * H;
    placements[p].page = p;
    placements[p].uv_scale[0] = 2.0f;
    placements[p].uv_offset[0] = p == 0 ? 0.0f : -1.0f;
  }
  scene.pages = pages;
  scene.page_count = 2;
  fill_sentinel();
  hemilight_bake_stats_init(&stats);
  CHECK(hemilight_bake_scene(&scene, &o, &stats) == HEMILIGHT_OK);
  ok = 1;
  for (p = 0; p < 2; ++p)
    for (i = 0; i < 3 * W * H; ++i)
      if (fabs(page_out[p][i] - 3.14159265) > 1e-4) ok = 0;
  CHECK(ok);
  ok = 1;
  for (p = 0; p < 2; ++p)
    for (i = 0; i < W * H; ++i)
      if (page_valid[p][i] != 1) ok = 0;
  CHECK(ok);
  CHECK(stats.sampled_texels == 2 * W * H && stats.hemicubes > 0);

  /* 3. The occluder over quad A under a hard sun straight down (sky 0, one bounce): A is in its
   * shadow (0 exactly: the shadow rays and the hemicubes see only black), B is lit (2 exactly). */
  {
    hemilight_light sun;
    hemilight_light_init(&sun, HEMILIGHT_LIGHT_DIRECTIONAL);
    sun.direction[0] = 0.0f;
    sun.direction[1] = -1.0f;
    sun.direction[2] = 0.0f;
    sun.color[0] = sun.color[1] = sun.color[2] = 2.0f;
    o.lights = &sun;
    o.light_count = 1;
    o.sky_radiance[0] = o.sky_radiance[1] = o.sky_radiance[2] = 0.0f;
    o.bounces = 1;
    placements[2].page = -1;
    scene.mesh_count = 3;
    CHECK(hemilight_bake_scene(&scene, &o, NULL) == HEMILIGHT_OK);
    ok = 1;
    for (i = 0; i < 3 * W * H; ++i)
      if (page_out[0][i] != 0.0f || fabs(page_out[1][i] - 2.0f) > 1e-6) ok = 0;
    CHECK(ok);
    /* Without the occluder both are lit. */
    scene.mesh_count = 2;
    CHECK(hemilight_bake_scene(&scene, &o, NULL) == HEMILIGHT_OK);
    ok = 1;
    for (i = 0; i < 3 * W * H; ++i)
      if (fabs(page_out[0][i] - 2.0f) > 1e-6) ok = 0;
    CHECK(ok);
    o.lights = NULL;
    o.light_count = 0;
    o.sky_radiance[0] = o.sky_radiance[1] = o.sky_radiance[2] = 1.0f;
    o.bounces = 2;
    scene.mesh_count = 3;
  }

  /* 4. Per-page albedo image equal to the triangles' albedo: the same bake, bitwise. */
  {
    static float before[3 * W * H];
    for (i = 0; i < 3 * W * H; ++i) albedo[i] = 0.5f;
    CHECK(hemilight_bake_scene(&scene, &o, NULL) == HEMILIGHT_OK);
    memcpy(before, page_out[0], sizeof before);
    pages[0].albedo_rgb = albedo;
    CHECK(hemilight_bake_scene(&scene, &o, NULL) == HEMILIGHT_OK);
    CHECK(memcmp(before, page_out[0], sizeof before) == 0);
  }

  /* 5. Bad input: one clear message each, nothing written. */
  fill_sentinel();
  albedo[5] = 1.5f;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->pages[0].albedo_rgb[5] (texel 1) = 1.500000; it must be in [0, 1]");
  albedo[5] = 0.5f;
  placements[1].page = 2;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->placements[1].page = 2 is not -1 (occluder only) or a page index (page_count 2)");
  placements[1].page = 1;
  placements[1].uv_offset[0] = -0.5f;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->meshes[1].lightmap_uvs[2] (vertex 1, u) = 1.000000 maps to 1.500000 in page 1");
  placements[1].uv_offset[0] = -1.0f;
  placements[1].uv_offset[1] = 0.25f;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->meshes[1].lightmap_uvs[5] (vertex 2, v) = 1.000000 maps to 1.250000 in page 1");
  placements[1].uv_offset[1] = 0.0f;
  placements[0].uv_scale[1] = 0.0f;
  o.strict = 1;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->meshes[0]: triangle 0 (indices[0..2]) has zero area in its page's UV space");
  o.strict = 0;
  {
    /* Without strict: mesh 0's triangles occlude, get no texels, and are counted and named. */
    hemilight_bake_stats st;
    hemilight_bake_stats_init(&st);
    CHECK(hemilight_bake_scene(&scene, &o, &st) == HEMILIGHT_OK);
    CHECK(st.no_uv_area_triangles == 2 && st.first_no_uv_area_mesh == 0 && st.first_no_uv_area_triangle == 0);
    fill_sentinel(); /* the failures below must leave the buffers as they are */
  }
  placements[0].uv_scale[1] = 1.0f;
  placements[0].uv_offset[1] = NAN;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->placements[0].uv_scale or uv_offset is not finite");
  placements[0].uv_offset[1] = 0.0f;
  pages[1].irradiance_capacity = 3 * W * H - 1;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->pages[1].irradiance_capacity 191 is below 3 x width x height = 192 floats");
  pages[1].irradiance_capacity = 3 * W * H;
  pages[1].width = 0;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->pages[1]: width x height = 0 x 8 is invalid");
  pages[1].width = W;
  scene.occluder_radiance = 7;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->occluder_radiance is 7");
  scene.occluder_radiance = HEMILIGHT_OCCLUDER_EMISSION_PLUS_MEAN_BOUNCE;
  scene.page_count = 0;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->page_count is 0");
  scene.page_count = 2;
  scene.placements = NULL;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->placements is NULL");
  scene.placements = placements;
  scene.struct_size = 0;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->struct_size is 0: fill the struct with hemilight_bake_scene_desc_init first");
  scene.struct_size = sizeof scene + 8;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "newer hemilight.h");
  scene.struct_size = sizeof scene;
  CHECK_FAILS(hemilight_bake_scene(NULL, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_bake_scene: scene is NULL");
  CHECK_FAILS(hemilight_bake_scene(&scene, NULL, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_bake_scene: options is NULL");
  /* Only occluders: nothing to bake (the C++ bake's message, under the C function's name). */
  placements[0].page = placements[1].page = -1;
  CHECK_FAILS(hemilight_bake_scene(&scene, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: no texel is covered by a triangle");
  placements[0].page = 0;
  placements[1].page = 1;
  CHECK(untouched());
  /* The emission-plus-mean-bounce occluders bake (and the buffers are written again). */
  CHECK(hemilight_bake_scene(&scene, &o, NULL) == HEMILIGHT_OK);
  CHECK(!untouched());

  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
