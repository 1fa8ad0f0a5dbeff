/* C99 test of the C ABI's lightmap baker: hemilight_bake_options_init, hemilight_bake_lightmap,
 * with and without lights, and ambient occlusion (also through hemilight_bake_scene).
 * Reference: a uniform sky of radiance L over unoccluded up-facing quads gives E = pi L at every
 * texel (closed form). Bad input: every failure leaves the caller's buffers untouched.
 * Prints failing checks and a closing "N passed, N failed" line. */
#include "capi_check.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>


#define W 8
#define H 8
static float out[3 * W * H];
static uint8_t valid[W * H];
static float sh[12 * W * H], hl2[9 * W * H];
static float env[6 * 2 * 2 * 3];

static void fill_sentinel(void) {
  int i;
  for (i = 0; i < 3 * W * H; ++i) out[i] = -7.0f;
  memset(valid, 9, sizeof valid);
}
static int untouched(void) {
  int i;
  for (i = 0; i < 3 * W * H; ++i)
    if (out[i] != -7.0f) return 0;
  for (i = 0; i < W * H; ++i)
    if (valid[i] != 9) return 0;
  return 1;
}

static int cancel_at_once(void* user, float fraction) {
  (void)fraction;
  ++*(int*)user;
  return 0;
}

/* hemilight_bake_options.edge_coverage: a floor quad (UV [0, 0.5] x [0, 1]) under an emitter quad
 * 0.3 above it that covers part of it (UV [0.5, 1] x [0, 1]), baked with and without exact edge
 * coverage. Both must succeed with finite values; they must differ where the emitter's edges cut
 * hemicube texels (exact coverage against point sampling, up to ~18% of an edge's weight at N = 16).
 * The accuracy itself is tested through hemilight_cache_irradiance (test_capi_irradiance.c). */
static void test_edge_coverage(void) {
  static const float floor_pos[] = {0, 0, 0, 1, 0, 0, 1, 0, -1, 0, 0, -1};
  static const float lamp_pos[] = {0.2f, 0.3f, -0.1f, 0.7f, 0.3f, -0.1f, 0.7f, 0.3f, -0.55f, 0.2f, 0.3f, -0.55f};
  static const float floor_uv[] = {0, 0, 0.5f, 0, 0.5f, 1, 0, 1};
  static const float lamp_uv[] = {0.5f, 0, 1, 0, 1, 1, 0.5f, 1};
  static const uint32_t up[] = {0, 1, 2, 0, 2, 3}, down[] = {0, 2, 1, 0, 3, 2};
  static float with_edges[3 * W * H];
  hemilight_bake_mesh meshes[2];
  hemilight_bake_options o;
  int i, finite = 1, differ = 0;
  memset(meshes, 0, sizeof meshes);
  meshes[0].positions = floor_pos;
  meshes[0].lightmap_uvs = floor_uv;
  meshes[0].vertex_count = 4;
  meshes[0].indices = up; /* normal +y */
  meshes[0].triangle_count = 2;
  meshes[0].material.albedo[0] = meshes[0].material.albedo[1] = meshes[0].material.albedo[2] = 0.5f;
  meshes[1] = meshes[0];
  meshes[1].positions = lamp_pos;
  meshes[1].lightmap_uvs = lamp_uv;
  meshes[1].indices = down; /* normal -y: towards the floor */
  meshes[1].material.emission[0] = meshes[1].material.emission[1] = meshes[1].material.emission[2] = 1.0f;
  hemilight_bake_options_init(&o);
  CHECK(o.edge_coverage == 0); /* off by default */
  o.width = W;
  o.height = H;
  o.resolution = 16;
  o.use_cache = 0; /* a hemicube per texel: the difference is the hemicubes' alone */
  CHECK(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, NULL, 0, NULL) == HEMILIGHT_OK);
  o.edge_coverage = 1;
  CHECK(hemilight_bake_lightmap(meshes, 2, &o, with_edges, 3 * W * H, NULL, 0, NULL) == HEMILIGHT_OK);
  for (i = 0; i < 3 * W * H; ++i) {
    if (!isfinite(with_edges[i]) || with_edges[i] < 0.0f) finite = 0;
    if (fabs(with_edges[i] - out[i]) > 1e-3 * (fabs(out[i]) + 1e-3)) differ = 1;
  }
  CHECK(finite);
  CHECK(differ);
  o.edge_coverage = -1;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_lightmap: options->edge_coverage is -1; it must be 0 or 1");
  /* The options the C++ bake also checks are checked by the C layer first, naming the C field. */
  o.edge_coverage = 0;
  o.dilation = -2;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_lightmap: options->dilation -2 must be >= -1");
  o.dilation = 16;
  o.resolution = 7;
  CHECK_FAILS(hemilight_bake_lightmap_directional(meshes, 2, &o, out, 3 * W * H, NULL, 0, sh, 12 * W * H, NULL, 0, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_lightmap_directional: options->resolution 7 is invalid: it must be even and in [2, 4096]");
}

/* Input as exports give it: a floor of 2 x 2 quads (local x, z in [0, 1], facing up) with every
 * triangle's own three vertices (duplicates at shared corners), moved by a rotation about y and a
 * translation computed in double and rounded to float; UVs u = x, v = z except u = -0.00048 at
 * x = 0 (a packer's margin). Mesh 1 adds collinear slivers along the floor's edge (midpoints exact
 * before the transform, collinear only up to its rounding), a triangle with a zero-length edge and
 * one collapsed to a point, with UVs of real area. The bake succeeds, also with strict; the
 * statistics count what was skipped and clamped; every texel sees the sky alone: pi. */
static void place(double x, double y, double z, float* out3) {
  const double c = cos(0.6), s = sin(0.6);
  out3[0] = (float)(c * x + s * z + 37.25);
  out3[1] = (float)(y + 2.5);
  out3[2] = (float)(-s * x + c * z - 11.75);
}

static void test_exported_floor(void) {
  enum { floor_tris = 8, junk_tris = 6 };
  static float pos[2][3 * 3 * floor_tris], uv[2][2 * 3 * floor_tris];
  static uint32_t indices[2][3 * floor_tris];
  hemilight_bake_mesh m[2];
  hemilight_bake_options o;
  hemilight_bake_stats st;
  int i, j, k, t = 0, clamped = 0, sky_only = 1;
  /* mesh 0: the floor */
  for (j = 0; j < 2; ++j)
    for (i = 0; i < 2; ++i) {
      const double x0 = i / 2.0, x1 = (i + 1) / 2.0, z0 = j / 2.0, z1 = (j + 1) / 2.0;
      const double corners[2][3][2] = {{{x0, z0}, {x0, z1}, {x1, z1}}, {{x0, z0}, {x1, z1}, {x1, z0}}};
      for (k = 0; k < 2; ++k, ++t) {
        int c;
        for (c = 0; c < 3; ++c) {
          const double x = corners[k][c][0], z = corners[k][c][1];
          place(x, 0.0, z, &pos[0][9 * t + 3 * c]);
          uv[0][6 * t + 2 * c] = x == 0.0 ? -0.00048f : (float)x;
          uv[0][6 * t + 2 * c + 1] = (float)z;
          if (x == 0.0) ++clamped;
          indices[0][3 * t + c] = (uint32_t)(3 * t + c);
        }
      }
    }
  /* mesh 1: four slivers along z = 0 and x = 0, a zero-length edge, a point */
  for (t = 0; t < junk_tris; ++t) {
    double p[3][3];
    int c;
    if (t < 4) {
      const double a = (t % 2) / 2.0, b = (t % 2 + 1) / 2.0;
      const double along[3] = {a, 0.5 * (a + b), b};
      for (c = 0; c < 3; ++c) {
        p[c][0] = t < 2 ? along[c] : 0.0;
        p[c][1] = 0.0;
        p[c][2] = t < 2 ? 0.0 : along[2 - c];
      }
    } else {
      for (c = 0; c < 3; ++c) {
        p[c][0] = (t == 4 && c == 2) ? 0.75 : 0.5;
        p[c][1] = 0.0;
        p[c][2] = 0.5;
      }
    }
    for (c = 0; c < 3; ++c) {
      place(p[c][0], p[c][1], p[c][2], &pos[1][9 * t + 3 * c]);
      uv[1][6 * t + 2 * c] = c == 1 ? 0.9f : 0.8f; /* real UV area: it would cover texels if baked */
      uv[1][6 * t + 2 * c + 1] = c == 2 ? 0.9f : 0.8f;
      indices[1][3 * t + c] = (uint32_t)(3 * t + c);
    }
  }
  memset(m, 0, sizeof m);
  for (k = 0; k < 2; ++k) {
    m[k].positions = pos[k];
    m[k].lightmap_uvs = uv[k];
    m[k].indices = indices[k];
    m[k].material.albedo[0] = m[k].material.albedo[1] = m[k].material.albedo[2] = 0.5f;
  }
  m[0].vertex_count = 3 * floor_tris;
  m[0].triangle_count = floor_tris;
  m[1].vertex_count = 3 * junk_tris;
  m[1].triangle_count = junk_tris;
  hemilight_bake_options_init(&o);
  o.width = o.height = W;
  o.resolution = 16;
  o.sky_radiance[0] = o.sky_radiance[1] = o.sky_radiance[2] = 1.0f;
  o.strict = 1;
  hemilight_bake_stats_init(&st);
  CHECK(hemilight_bake_lightmap(m, 2, &o, out, 3 * W * H, valid, W * H, &st) == HEMILIGHT_OK);
  CHECK(st.degenerate_triangles == junk_tris);
  CHECK(st.no_uv_area_triangles == 0 && st.first_no_uv_area_mesh == SIZE_MAX && st.first_no_uv_area_triangle == SIZE_MAX);
  CHECK(clamped == 6 && st.clamped_uvs == (size_t)clamped);
  CHECK(st.sampled_texels == W * H);
  CHECK(st.overlapping_texels == 0); /* the slivers' UV triangle lies over the floor's: baked, it would overlap */
  for (i = 0; i < 3 * W * H; ++i)
    if (fabs(out[i] - 3.14159265) > 1e-4) sky_only = 0; /* float sums of exact weights */
  CHECK(sky_only);
}

/* Seam stitching through the C ABI: a floor of two unit quads (x in [0, 1] and [1, 2]) in two
 * meshes and two charts (u in [0.05, 0.45] and [0.55, 0.95]), a black wall at x = 1.6 making the
 * sky's irradiance fall across the cut. stitch_seams (default 1) sets texels along the cut and
 * counts them; 0 leaves the bake as it was; 2 is refused. */
static void test_stitch_seams(void) {
  static const float pos_a[12] = {0, 0, 1, 1, 0, 1, 1, 0, 0, 0, 0, 0};
  static const float pos_b[12] = {1, 0, 1, 2, 0, 1, 2, 0, 0, 1, 0, 0};
  static const float pos_w[12] = {1.6f, 0, -0.5f, 1.6f, 0, 1.5f, 1.6f, 0.5f, 1.5f, 1.6f, 0.5f, -0.5f};
  static const float uv_a[8] = {0.05f, 0.05f, 0.45f, 0.05f, 0.45f, 0.95f, 0.05f, 0.95f};
  static const float uv_b[8] = {0.55f, 0.05f, 0.95f, 0.05f, 0.95f, 0.95f, 0.55f, 0.95f};
  static const float uv_w[8] = {0, 0, 0, 0, 0, 0, 0, 0}; /* no texels: it only occludes */
  static const uint32_t quad[6] = {0, 1, 2, 0, 2, 3};
  static float stitched[3 * 32 * 32], raw[3 * 32 * 32];
  static uint8_t v[32 * 32];
  hemilight_bake_mesh m[3];
  hemilight_bake_options o;
  hemilight_bake_stats st;
  int k, changed_far = 0;
  memset(m, 0, sizeof m);
  m[0].positions = pos_a;
  m[0].lightmap_uvs = uv_a;
  m[1].positions = pos_b;
  m[1].lightmap_uvs = uv_b;
  m[2].positions = pos_w;
  m[2].lightmap_uvs = uv_w;
  m[2].material.two_sided = 1;
  for (k = 0; k < 3; ++k) {
    m[k].vertex_count = 4;
    m[k].indices = quad;
    m[k].triangle_count = 2;
    if (k < 2) m[k].material.albedo[0] = m[k].material.albedo[1] = m[k].material.albedo[2] = 0.5f;
  }
  hemilight_bake_options_init(&o);
  CHECK(o.stitch_seams == 1);
  o.width = o.height = 32;
  o.resolution = 32;
  o.sky_radiance[0] = o.sky_radiance[1] = o.sky_radiance[2] = 1.0f;
  hemilight_bake_stats_init(&st);
  CHECK(hemilight_bake_lightmap(m, 3, &o, stitched, 3 * 32 * 32, v, 32 * 32, &st) == HEMILIGHT_OK);
  CHECK(st.seam_texels > 0 && st.stitch_seconds > 0.0);
  o.stitch_seams = 0;
  hemilight_bake_stats_init(&st);
  CHECK(hemilight_bake_lightmap(m, 3, &o, raw, 3 * 32 * 32, v, 32 * 32, &st) == HEMILIGHT_OK);
  CHECK(st.seam_texels == 0);
  /* Only texels near the cut move: columns 13..18 of the 32 (u 0.45 and 0.55 are 14.4 and 17.6). */
  for (k = 0; k < 32 * 32; ++k)
    if ((k % 32 < 12 || k % 32 > 19) && memcmp(&raw[3 * k], &stitched[3 * k], 3 * sizeof(float)) != 0) ++changed_far;
  CHECK(changed_far == 0);
  CHECK(memcmp(raw, stitched, sizeof raw) != 0);
  o.stitch_seams = 2;
  CHECK_FAILS(hemilight_bake_lightmap(m, 3, &o, raw, 3 * 32 * 32, v, 32 * 32, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "options->stitch_seams is 2; it must be 0 or 1");
}

/* Ambient occlusion (hemilight_bake_options.ao_distance, .ao; hemilight_bake_scene_desc.ao): a
 * floor (x, z in [-4, 4], y = 0, facing up; u in [0, 0.5]) under a ceiling (the same square at
 * y = 1, facing down; u in [0.5, 1]), a 32 x 32 map, a hemicube per texel at N = 64, D = 2.
 * Closed form: under an infinite parallel plane at height h the directions with cos(theta) < h / D
 * are open, whose cosine-weighted share of the hemisphere is (h / D)^2 (docs/bake.md). The sample
 * sits 0.05 texel sizes above the floor (the bake's offset: the texel world size is
 * sqrt(64 m^2 / 512 texels)), so h = 1 - 0.05 sqrt(0.125). Texels whose centre lies within
 * 4 - sqrt(D^2 - h^2) = 2.25 of the middle in x and z see the square wherever the infinite plane
 * is within D: exactly the closed form. Tolerance 2e-3: the N = 64 hemicubes' discretisation
 * (texels on the boundary circle counted whole by their centres; measured at most 4.6e-4).
 * Then: a one-page scene bake writes bitwise the same AO; bad input names the C field and
 * writes nothing. */
static void test_ao(void) {
  static const float floor_pos[] = {-4, 0, -4, -4, 0, 4, 4, 0, 4, 4, 0, -4};
  static const float ceiling_pos[] = {-4, 1, -4, 4, 1, -4, 4, 1, 4, -4, 1, 4};
  static const float floor_uv[] = {0, 0, 0, 1, 0.5f, 1, 0.5f, 0};
  static const float ceiling_uv[] = {0.5f, 0, 1, 0, 1, 1, 0.5f, 1};
  static const uint32_t quad[] = {0, 1, 2, 0, 2, 3};
  static float e[3 * 32 * 32], ao[32 * 32], scene_ao[32 * 32], page_e[3 * 32 * 32];
  hemilight_bake_mesh m[2];
  hemilight_bake_options o;
  hemilight_bake_placement placements[2];
  hemilight_bake_page page;
  hemilight_bake_scene_desc sd;
  float* page_ao[1];
  size_t page_ao_capacity[1];
  const double h = 1.0 - 0.05 * sqrt(64.0 / 512.0), expected = (h / 2.0) * (h / 2.0);
  double worst = 0.0;
  int i, j, compared = 0, in_range = 1, untouched_ao = 1;
  memset(m, 0, sizeof m);
  m[0].positions = floor_pos;  /* (v1 - v0) x (v2 - v0) = (0, 8, 0) x (8, 8, 8) points up (+y) */
  m[0].lightmap_uvs = floor_uv;
  m[1].positions = ceiling_pos; /* faces down (-y) */
  m[1].lightmap_uvs = ceiling_uv;
  for (i = 0; i < 2; ++i) {
    m[i].vertex_count = 4;
    m[i].indices = quad;
    m[i].triangle_count = 2;
    m[i].material.albedo[0] = m[i].material.albedo[1] = m[i].material.albedo[2] = 0.5f;
  }
  hemilight_bake_options_init(&o);
  CHECK(o.ao_distance == 0.0f && o.ao == NULL && o.ao_capacity == 0); /* off by default */
  o.width = o.height = 32;
  o.resolution = 64;
  o.use_cache = 0;
  o.sky_radiance[0] = o.sky_radiance[1] = o.sky_radiance[2] = 1.0f;
  /* Off: the buffer is not written even when given. */
  for (i = 0; i < 32 * 32; ++i) ao[i] = -7.0f;
  o.ao = ao;
  o.ao_capacity = 32 * 32;
  CHECK(hemilight_bake_lightmap(m, 2, &o, e, 3 * 32 * 32, NULL, 0, NULL) == HEMILIGHT_OK);
  for (i = 0; i < 32 * 32; ++i)
    if (ao[i] != -7.0f) untouched_ao = 0;
  CHECK(untouched_ao);
  o.ao_distance = 2.0f;
  CHECK(hemilight_bake_lightmap(m, 2, &o, e, 3 * 32 * 32, NULL, 0, NULL) == HEMILIGHT_OK);
  for (i = 0; i < 32 * 32; ++i)
    if (!(ao[i] >= 0.0f && ao[i] <= 1.0f)) in_range = 0;
  CHECK(in_range);
  for (j = 0; j < 32; ++j)    /* rows: v = z / 8 + 0.5, texel centre z = (j + 0.5) / 4 - 4 */
    for (i = 0; i < 16; ++i) { /* the floor's columns: texel centre x = (i + 0.5) / 2 - 4 */
      const double x = (i + 0.5) / 2.0 - 4.0, z = (j + 0.5) / 4.0 - 4.0;
      if (fabs(x) > 2.25 || fabs(z) > 2.25) continue;
      if (fabs(ao[j * 32 + i] - expected) > worst) worst = fabs(ao[j * 32 + i] - expected);
      ++compared;
    }
  CHECK(compared == 10 * 18);
  CHECK(worst < 2e-3);
  if (!(worst < 2e-3)) printf("  AO under the ceiling: largest |AO - (h/D)^2| = %g (expected %g)\n", worst, expected);

  /* The same meshes as a one-page scene bake (identity placements): bitwise the same AO. */
  memset(placements, 0, sizeof placements);
  for (i = 0; i < 2; ++i) placements[i].uv_scale[0] = placements[i].uv_scale[1] = 1.0f;
  memset(&page, 0, sizeof page);
  page.width = page.height = 32;
  page.irradiance_rgb = page_e;
  page.irradiance_capacity = 3 * 32 * 32;
  hemilight_bake_scene_desc_init(&sd);
  CHECK(sd.ao == NULL && sd.ao_capacity == NULL);
  sd.meshes = m;
  sd.mesh_count = 2;
  sd.placements = placements;
  sd.pages = &page;
  sd.page_count = 1;
  page_ao[0] = scene_ao;
  page_ao_capacity[0] = 32 * 32;
  sd.ao = page_ao;
  sd.ao_capacity = page_ao_capacity;
  CHECK(hemilight_bake_scene(&sd, &o, NULL) == HEMILIGHT_OK);
  CHECK(memcmp(scene_ao, ao, sizeof ao) == 0);
  CHECK(memcmp(page_e, e, sizeof e) == 0);

  /* Bad input: the C field named, nothing written. */
  for (i = 0; i < 32 * 32; ++i) ao[i] = -7.0f;
  o.ao_distance = -1.0f;
  CHECK_FAILS(hemilight_bake_lightmap(m, 2, &o, e, 3 * 32 * 32, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_lightmap: options->ao_distance is -1");
  o.ao_distance = (float)NAN;
  CHECK_FAILS(hemilight_bake_lightmap(m, 2, &o, e, 3 * 32 * 32, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "options->ao_distance is nan");
  o.ao_distance = (float)INFINITY;
  CHECK_FAILS(hemilight_bake_scene(&sd, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_bake_scene: options->ao_distance is inf");
  o.ao_distance = 2.0f;
  o.ao_capacity = 32 * 32 - 1;
  CHECK_FAILS(hemilight_bake_lightmap(m, 2, &o, e, 3 * 32 * 32, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "options->ao_capacity 1023 is below width x height = 1024");
  o.ao = NULL;
  CHECK_FAILS(hemilight_bake_lightmap(m, 2, &o, e, 3 * 32 * 32, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "options->ao is NULL");
  untouched_ao = 1;
  for (i = 0; i < 32 * 32; ++i)
    if (ao[i] != -7.0f) untouched_ao = 0;
  CHECK(untouched_ao);
  page_ao_capacity[0] = 100;
  CHECK_FAILS(hemilight_bake_scene(&sd, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "scene->ao_capacity[0] 100 is below");
  sd.ao_capacity = NULL;
  CHECK_FAILS(hemilight_bake_scene(&sd, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "scene->ao_capacity is NULL");
  sd.ao = NULL;
  CHECK_FAILS(hemilight_bake_scene(&sd, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "scene->ao is NULL");
  /* A page may leave its AO out (ao[p] NULL): the bake succeeds. */
  page_ao[0] = NULL;
  sd.ao = page_ao;
  sd.ao_capacity = page_ao_capacity;
  CHECK(hemilight_bake_scene(&sd, &o, NULL) == HEMILIGHT_OK);
}

int main(void) {
  /* Two unit floor quads side by side (x in [0, 1] and [1, 2]), facing up, each on half of the map. */
  static const float pos_a[] = {0, 0, 0, 1, 0, 0, 1, 0, -1, 0, 0, -1};
  static const float pos_b[] = {1, 0, 0, 2, 0, 0, 2, 0, -1, 1, 0, -1};
  static const float uv_a[] = {0, 0, 0.5f, 0, 0.5f, 1, 0, 1};
  static const float uv_b[] = {0.5f, 0, 1, 0, 1, 1, 0.5f, 1};
  static const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
  hemilight_bake_mesh meshes[2];
  hemilight_bake_options o;
  hemilight_bake_stats stats;
  int i, ok = 1, calls = 0;
  float bad_uv[8], bad_pos[12];
  uint32_t bad_idx[6];

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

  hemilight_bake_options_init(&o);
  hemilight_bake_options_init(NULL); /* ignored */
  CHECK(o.width == 256 && o.resolution == 64 && o.bounces == 1 && o.use_cache == 1 && o.progress == NULL);
  CHECK(o.environment_rgb == NULL && o.environment_size == 0);
  o.width = W;
  o.height = H;
  o.resolution = 16;
  o.bounces = 2;
  o.sky_radiance[0] = o.sky_radiance[1] = o.sky_radiance[2] = 1.0f;

  /* Good call: E = pi everywhere (the quads see only the sky: nothing bounces onto them). */
  fill_sentinel();
  hemilight_bake_stats_init(&stats);
  CHECK(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, &stats) == HEMILIGHT_OK);
  for (i = 0; i < 3 * W * H; ++i)
    if (fabs(out[i] - 3.14159265) > 1e-4) ok = 0; /* float sums of exact weights */
  CHECK(ok);
  for (i = 0; i < W * H; ++i)
    if (valid[i] != 1) ok = 0;
  CHECK(ok);
  CHECK(stats.sampled_texels == W * H && stats.hemicubes > 0 && stats.invalid_texels == 0 && stats.seconds >= 0.0);
  /* valid may be NULL, stats too. */
  CHECK(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, NULL, 0, NULL) == HEMILIGHT_OK);

  /* Directional maps (same scene: unoccluded up-facing quads under a uniform sky L = 1). From the
   * header's definitions: c_0 = sqrt(pi) L, (c_1, c_2, c_3) = (sqrt(3 pi)/2) L (n_y, n_z, n_x) with
   * n = +y; each HL2 vector is 54.7 degrees from n, and a plane tilted by beta under a uniform sky
   * hemisphere receives pi L (1 + cos beta) / 2 with cos beta = 1/sqrt 3. Float sums of exact
   * weights: 1e-4. */
  for (i = 0; i < 12 * W * H; ++i) sh[i] = -7.0f;
  for (i = 0; i < 9 * W * H; ++i) hl2[i] = -7.0f;
  CHECK(hemilight_bake_lightmap_directional(meshes, 2, &o, out, 3 * W * H, valid, W * H, sh, 12 * W * H, hl2, 9 * W * H, NULL) ==
        HEMILIGHT_OK);
  ok = 1;
  for (i = 0; i < 3 * W * H; ++i) {
    if (fabs(sh[i] - 1.7724539) > 1e-4 || fabs(sh[3 * W * H + i] - 1.5349901) > 1e-4) ok = 0;
    if (fabs(sh[6 * W * H + i]) > 1e-4 || fabs(sh[9 * W * H + i]) > 1e-4) ok = 0;
    if (fabs(hl2[i] - 2.4776960) > 1e-4 || fabs(hl2[3 * W * H + i] - 2.4776960) > 1e-4 || fabs(hl2[6 * W * H + i] - 2.4776960) > 1e-4)
      ok = 0;
  }
  CHECK(ok);
  /* One kind only: the other buffer is not touched. */
  for (i = 0; i < 9 * W * H; ++i) hl2[i] = -7.0f;
  CHECK(hemilight_bake_lightmap_directional(meshes, 2, &o, out, 3 * W * H, NULL, 0, sh, 12 * W * H, NULL, 0, NULL) == HEMILIGHT_OK);
  CHECK(hl2[0] == -7.0f && hl2[9 * W * H - 1] == -7.0f);

  /* Environment sky: a 2 x 2 cube map of radiance 2 except the -Y face (100, below every quad's
   * horizon). Seamless bilinear lookups above the horizon only mix texels of value 2 (the horizon
   * runs between the side faces' two texel rows), so E = 2 pi exactly, not pi (the constant sky). */
  for (i = 0; i < 6 * 2 * 2 * 3; ++i) env[i] = i / 12 == 3 ? 100.0f : 2.0f;
  o.environment_rgb = env;
  o.environment_size = 2;
  CHECK(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL) == HEMILIGHT_OK);
  ok = 1;
  for (i = 0; i < 3 * W * H; ++i)
    if (fabs(out[i] - 2 * 3.14159265) > 2e-4) ok = 0;
  CHECK(ok);
  fill_sentinel();
  o.environment_size = 0;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "environment_size 0");
  o.environment_size = 2;
  env[5] = -1.0f;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "environment_rgb[5]");
  env[5] = 2.0f;
  o.environment_rgb = NULL;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "environment_rgb is NULL");
  o.environment_size = 0;
  CHECK_FAILS(hemilight_bake_lightmap_directional(meshes, 2, &o, out, 3 * W * H, valid, W * H, sh, 12 * W * H - 1, NULL, 0, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "sh_l1_capacity");
  CHECK_FAILS(hemilight_bake_lightmap_directional(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL, 0, hl2, 9 * W * H - 1, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "hl2_capacity");
  CHECK(untouched());

  /* Lights: a hard sun travelling along (0, -1, -1)/sqrt2 with E = 2 adds E cos 45 degrees to
   * the sky's pi at every texel (the quads are unoccluded; float closed forms: 1e-4); with
   * indirect_only the sun is dropped with the first bounce (nothing bounces here: 0). */
  {
    hemilight_light sun[2];
    hemilight_light_init(&sun[0], HEMILIGHT_LIGHT_DIRECTIONAL);
    sun[0].direction[1] = sun[0].direction[2] = -1.0f;
    sun[0].color[0] = sun[0].color[1] = sun[0].color[2] = 2.0f;
    CHECK(o.lights == NULL && o.light_count == 0);
    o.lights = sun;
    o.light_count = 1;
    CHECK(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL) == HEMILIGHT_OK);
    ok = 1;
    for (i = 0; i < 3 * W * H; ++i)
      if (fabs(out[i] - (3.14159265 + 2.0 * sqrt(0.5))) > 1e-4) ok = 0;
    CHECK(ok);
    o.indirect_only = 1;
    CHECK(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL) == HEMILIGHT_OK);
    ok = 1;
    for (i = 0; i < 3 * W * H; ++i)
      if (out[i] != 0.0f) ok = 0;
    CHECK(ok);
    o.indirect_only = 0;
    /* The shadow mask: the unoccluded sun's visibility is 1 at every texel (channel R; the others
     * unused: 0); a sun travelling upwards is below every texel's horizon: 0. */
    {
      static float mask[4 * W * H];
      int all_ones = 1, all_zero = 1;
      CHECK(o.shadow_mask_lights[0] == -1 && o.shadow_mask_lights[3] == -1 && o.shadow_mask_rgba == NULL);
      o.shadow_mask_lights[0] = 0;
      o.shadow_mask_rgba = mask;
      o.shadow_mask_capacity = 4 * W * H;
      memset(mask, 0x5a, sizeof mask);
      CHECK(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL) == HEMILIGHT_OK);
      for (i = 0; i < W * H; ++i) {
        if (mask[4 * i] != 1.0f) all_ones = 0;
        if (mask[4 * i + 1] != 0.0f || mask[4 * i + 2] != 0.0f || mask[4 * i + 3] != 0.0f) all_zero = 0;
      }
      CHECK(all_ones && all_zero);
      sun[0].direction[1] = 1.0f, sun[0].direction[2] = 0.0f;
      CHECK(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL) == HEMILIGHT_OK);
      all_zero = 1;
      for (i = 0; i < 4 * W * H; ++i)
        if (mask[i] != 0.0f) all_zero = 0;
      CHECK(all_zero);
      sun[0].direction[1] = sun[0].direction[2] = -1.0f;
      o.shadow_mask_lights[2] = 1;
      CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
                  "options->shadow_mask_lights[2] = 1 is not -1 or a light index (light_count is 1)");
      o.shadow_mask_lights[2] = -1;
      o.shadow_mask_capacity = 4 * W * H - 1;
      CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
                  "options->shadow_mask_capacity");
      o.shadow_mask_rgba = NULL;
      CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
                  "shadow_mask_rgba is NULL");
      o.shadow_mask_lights[0] = -1;
      o.shadow_mask_capacity = 0;
    }
    /* A bad light fails the call naming options->lights[i] and the field; nothing written. */
    hemilight_light_init(&sun[1], HEMILIGHT_LIGHT_POINT);
    sun[1].radius = -0.5f;
    o.light_count = 2;
    fill_sentinel();
    CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
                "hemilight_bake_lightmap: options->lights[1].radius");
    o.lights = NULL;
    CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
                "options->lights is NULL");
    CHECK(untouched());
    o.light_count = 0;
  }

  /* Bad input: a clear message, nothing written. */
  fill_sentinel();
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, NULL, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "options is NULL");
  CHECK_FAILS(hemilight_bake_lightmap(NULL, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "meshes is NULL");
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 0, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "mesh_count is 0");
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, NULL, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "irradiance_rgb is NULL");
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H - 1, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "irradiance_capacity");
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H - 1, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "valid_capacity");
  o.width = 0;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "0 x 8 is invalid");
  o.width = 1000000;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "1000000 x 8 is invalid");
  o.width = W;
  o.bounces = 0;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "bounces 0");
  o.bounces = 1;
  o.resolution = 15;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "resolution 15");
  o.resolution = 16;
  o.error_threshold = 0.0f;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "error_threshold");
  o.error_threshold = 0.2f;
  o.use_cache = 2;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "use_cache is 2");
  o.use_cache = 1;
  o.sky_radiance[1] = -1.0f;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "sky_radiance");
  o.sky_radiance[1] = 1.0f;

  memcpy(bad_uv, uv_b, sizeof bad_uv);
  bad_uv[2] = 1.25f;
  meshes[1].lightmap_uvs = bad_uv;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "meshes[1].lightmap_uvs[2] (vertex 1, u) = 1.25");
  bad_uv[2] = -0.0011f; /* past the 0.001 that is clamped */
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "meshes[1].lightmap_uvs[2] (vertex 1, u) = -0.0011");
  bad_uv[2] = bad_uv[0]; /* vertex 1 = vertex 0 in UV: triangle 0 of mesh 1 (triangle 2 overall) is flat in UV */
  bad_uv[3] = bad_uv[1];
  o.strict = 1;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "meshes[1]: triangle 0 (indices[0..2]) has zero area in lightmap UV space");
  o.strict = 2;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "options->strict is 2; it must be 0 or 1");
  /* Without strict the flat triangle still occludes but gets no texels; the statistics name it. */
  o.strict = 0;
  hemilight_bake_stats_init(&stats);
  CHECK(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, &stats) == HEMILIGHT_OK);
  CHECK(stats.no_uv_area_triangles == 1 && stats.first_no_uv_area_mesh == 1 && stats.first_no_uv_area_triangle == 0);
  CHECK(stats.degenerate_triangles == 0 && stats.clamped_uvs == 0);
  fill_sentinel(); /* the failures below must leave the buffers as they are */
  meshes[1].lightmap_uvs = uv_b;
  memcpy(bad_idx, idx, sizeof bad_idx);
  bad_idx[4] = 4;
  meshes[1].indices = bad_idx;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "meshes[1].indices[4] = 4 is out of range");
  meshes[1].indices = idx;
  memcpy(bad_pos, pos_b, sizeof bad_pos);
  bad_pos[4] = (float)NAN;
  meshes[1].positions = bad_pos;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "meshes[1].positions[4] (vertex 1) = nan");
  meshes[1].positions = pos_b;
  meshes[1].lightmap_uvs = NULL;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "lightmap_uvs is NULL");
  meshes[1].lightmap_uvs = uv_b;
  meshes[0].material.albedo[0] = 2.0f;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "albedo");
  meshes[0].material.albedo[0] = 0.5f;

  o.progress = cancel_at_once;
  o.progress_user = &calls;
  CHECK_FAILS(hemilight_bake_lightmap(meshes, 2, &o, out, 3 * W * H, valid, W * H, NULL), HEMILIGHT_ERROR_CANCELLED, "cancelled");
  CHECK(calls == 1);
  CHECK(untouched());

  test_edge_coverage();
  test_exported_floor();
  test_stitch_seams();
  test_ao();
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
