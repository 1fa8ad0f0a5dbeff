/* C99: a program built against an older layout of the growable structs (capi_older_layout.h: the
 * structs without their newest fields) runs against this library: the init functions write only
 * the caller's bytes, the calls read only them (the missing fields take their defaults) and write
 * statistics only within them; a struct_size from a newer program, or none, is refused with a
 * clear message. Each struct lies in a buffer with guard bytes after it, which must survive.
 * References: closed forms (a uniform sky gives irradiance pi L at every point). */
#include "capi_older_layout.h"
#include "capi_check.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

enum { guard = 64 };
static const unsigned char guard_byte = 0xa7;

static int guard_intact(const unsigned char* after) {
  int i;
  for (i = 0; i < guard; ++i)
    if (after[i] != guard_byte) return 0;
  return 1;
}

static void test_cache(void) {
  /* The struct and its guard bytes in one buffer (aligned for the struct). */
  static union {
    hemilight_cache_options o;
    unsigned char bytes[sizeof(hemilight_cache_options) + guard];
  } ob;
  static union {
    hemilight_cache_stats s;
    unsigned char bytes[sizeof(hemilight_cache_stats) + guard];
  } sb;
  const float sky[3] = {1.0f, 0.5f, 0.25f};
  enum { n = 64 };
  float pos[3 * n], nrm[3 * n], out[3 * n];
  hemilight_scene* empty = NULL;
  int i, c;
  memset(ob.bytes, guard_byte, sizeof ob.bytes);
  memset(sb.bytes, guard_byte, sizeof sb.bytes);
  hemilight_cache_options_init(&ob.o);
  hemilight_cache_stats_init(&sb.s);
  CHECK(guard_intact(ob.bytes + sizeof(hemilight_cache_options)));
  CHECK(guard_intact(sb.bytes + sizeof(hemilight_cache_stats)));
  CHECK(ob.o.struct_size == sizeof(hemilight_cache_options) && ob.o.resolution == 64 && ob.o.error_threshold == 0.2f);
  CHECK(ob.o.use_gradients == 1 && ob.o.extrapolate_wall_depth == 0 && ob.o.sole_record_reach == 0.99f);
  ob.o.resolution = 16;
  ob.o.thread_count = 2;
  for (i = 0; i < n; ++i) {
    pos[3 * i] = (float)(i % 8), pos[3 * i + 1] = 0.0f, pos[3 * i + 2] = (float)(i / 8);
    nrm[3 * i] = 0.0f, nrm[3 * i + 1] = 1.0f, nrm[3 * i + 2] = 0.0f;
  }
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &empty) == 0);
  CHECK(hemilight_cache_irradiance(empty, pos, nrm, n, &ob.o, out, &sb.s) == 0);
  /* Uniform sky: pi L everywhere (float rounding, 1e-5). */
  for (i = 0; i < n; ++i)
    for (c = 0; c < 3; ++c) CHECK(fabs(out[3 * i + c] / (3.14159265358979 * sky[c]) - 1.0) < 1e-5);
  CHECK(sb.s.struct_size == sizeof(hemilight_cache_stats) && sb.s.hemicubes > 0 && sb.s.hemicubes <= n);
  CHECK(sb.s.records == sb.s.hemicubes && sb.s.seconds >= 0.0);
  CHECK(guard_intact(ob.bytes + sizeof(hemilight_cache_options)));
  CHECK(guard_intact(sb.bytes + sizeof(hemilight_cache_stats)));
  /* No struct_size, or one larger than the library knows: refused, named. */
  ob.o.struct_size = 0;
  CHECK(hemilight_cache_irradiance(empty, pos, nrm, n, &ob.o, out, &sb.s) == 1);
  CHECK(strstr(hemilight_last_error(), "options->struct_size is 0") != NULL);
  ob.o.struct_size = 4096;
  CHECK(hemilight_cache_irradiance(empty, pos, nrm, n, &ob.o, out, &sb.s) == 1);
  CHECK(strstr(hemilight_last_error(), "newer hemilight.h") != NULL);
  ob.o.struct_size = sizeof(hemilight_cache_options);
  sb.s.struct_size = 3;
  CHECK(hemilight_cache_irradiance(empty, pos, nrm, n, &ob.o, out, &sb.s) == 1);
  CHECK(strstr(hemilight_last_error(), "stats->struct_size is 3") != NULL);
  hemilight_scene_release(empty);
}

static void test_bake(void) {
  static union {
    hemilight_bake_options o;
    unsigned char bytes[sizeof(hemilight_bake_options) + guard];
  } ob;
  static union {
    hemilight_bake_stats s;
    unsigned char bytes[sizeof(hemilight_bake_stats) + guard];
  } sb;
  /* A 1 x 1 floor facing up under a sky of radiance 1: every texel's irradiance is pi. */
  const float positions[] = {0, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 1};
  const float uvs[] = {0, 0, 1, 0, 1, 1, 0, 1};
  const uint32_t indices[] = {0, 3, 2, 0, 2, 1};
  hemilight_bake_mesh mesh;
  enum { W = 8 };
  float out[3 * W * W];
  int i;
  memset(&mesh, 0, sizeof mesh);
  mesh.positions = positions;
  mesh.lightmap_uvs = uvs;
  mesh.vertex_count = 4;
  mesh.indices = indices;
  mesh.triangle_count = 2;
  mesh.material.albedo[0] = mesh.material.albedo[1] = mesh.material.albedo[2] = 0.5f;
  memset(ob.bytes, guard_byte, sizeof ob.bytes);
  memset(sb.bytes, guard_byte, sizeof sb.bytes);
  hemilight_bake_options_init(&ob.o);
  hemilight_bake_stats_init(&sb.s);
  CHECK(guard_intact(ob.bytes + sizeof(hemilight_bake_options)));
  CHECK(ob.o.width == 256 && ob.o.bounces == 1 && ob.o.environment_rgb == NULL && ob.o.environment_size == 0);
  ob.o.width = ob.o.height = W;
  ob.o.resolution = 16;
  ob.o.sky_radiance[0] = ob.o.sky_radiance[1] = ob.o.sky_radiance[2] = 1.0f;
  CHECK(hemilight_bake_lightmap(&mesh, 1, &ob.o, out, sizeof out / sizeof out[0], NULL, 0, &sb.s) == 0);
  for (i = 0; i < 3 * W * W; ++i) CHECK(fabs(out[i] / 3.14159265358979 - 1.0) < 1e-5);
  CHECK(sb.s.sampled_texels == W * W && sb.s.hemicubes > 0);
  CHECK(guard_intact(ob.bytes + sizeof(hemilight_bake_options)));
  CHECK(guard_intact(sb.bytes + sizeof(hemilight_bake_stats)));
}

/* A scene description of the layout before the opacity fields, followed by guard bytes (which,
 * read as mesh_opacity, would be a wild pointer): the bake reads none of them and every triangle
 * is opaque. A floor under the sky (radiance 1) with an occluder-only card above it: pi where the
 * floor sees only the sky, less under the card. */
static void test_bake_scene(void) {
  static union {
    hemilight_bake_scene_desc d;
    unsigned char bytes[sizeof(hemilight_bake_scene_desc) + guard];
  } db;
  static const float floor_positions[] = {0, 0, 0, 1, 0, 0, 1, 0, -1, 0, 0, -1};
  static const float floor_uvs[] = {0, 0, 1, 0, 1, 1, 0, 1};
  /* 0.25 above the floor, facing down, over x in [0.5, 2.5], z in [-2.5, 1.5]: the floor's right
   * half is under it. */
  static const float card_positions[] = {0.5f, 0.25f, 1.5f, 0.5f, 0.25f, -2.5f, 2.5f, 0.25f, -2.5f, 2.5f, 0.25f, 1.5f};
  static const uint32_t indices[] = {0, 1, 2, 0, 2, 3};
  enum { W = 8 };
  static float out[3 * W * W];
  hemilight_bake_mesh meshes[2];
  hemilight_bake_placement placements[2];
  hemilight_bake_page page;
  hemilight_bake_options o;
  int x, y, ok_lit = 1, ok_shaded = 1;
  memset(meshes, 0, sizeof meshes);
  meshes[0].positions = floor_positions;
  meshes[0].lightmap_uvs = floor_uvs;
  meshes[0].vertex_count = 4;
  meshes[0].indices = indices;
  meshes[0].triangle_count = 2;
  meshes[1] = meshes[0];
  meshes[1].positions = card_positions;
  meshes[1].lightmap_uvs = NULL;
  memset(placements, 0, sizeof placements);
  placements[0].uv_scale[0] = placements[0].uv_scale[1] = 1.0f;
  placements[1] = placements[0];
  placements[1].page = -1;
  memset(&page, 0, sizeof page);
  page.width = page.height = W;
  page.irradiance_rgb = out;
  page.irradiance_capacity = 3 * W * W;
  memset(db.bytes, guard_byte, sizeof db.bytes);
  hemilight_bake_scene_desc_init(&db.d);
  CHECK(guard_intact(db.bytes + sizeof(hemilight_bake_scene_desc)));
  CHECK(db.d.struct_size == sizeof(hemilight_bake_scene_desc) && db.d.meshes == NULL && db.d.occluder_radiance == 0);
  db.d.meshes = meshes;
  db.d.mesh_count = 2;
  db.d.placements = placements;
  db.d.pages = &page;
  db.d.page_count = 1;
  hemilight_bake_options_init(&o);
  o.resolution = 16;
  o.sky_radiance[0] = o.sky_radiance[1] = o.sky_radiance[2] = 1.0f;
  CHECK(hemilight_bake_scene(&db.d, &o, NULL) == 0);
  /* Texel columns 0 and 1 (x <= 0.25) see the card only near the horizon (it hides at most 11% of
   * the sky's projected solid angle: half-plane form factors); columns 6 and 7 (x >= 0.75), under
   * it, see the sky only past its edges (at most 22%). */
  for (y = 0; y < W; ++y)
    for (x = 0; x < W; ++x) {
      const float e = out[3 * (y * W + x)];
      if (x < 2 && !(e > 0.85f * 3.14159265f && e <= 3.1416f)) ok_lit = 0;
      if (x >= 6 && !(e < 0.25f * 3.14159265f)) ok_shaded = 0;
    }
  CHECK(ok_lit);
  CHECK(ok_shaded);
  CHECK(guard_intact(db.bytes + sizeof(hemilight_bake_scene_desc)));
}

int main(void) {
  test_cache();
  test_bake();
  test_bake_scene();
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
