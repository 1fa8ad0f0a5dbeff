/* C99 test of the C ABI's lightmap unwrapper: hemilight_unwrap_options_init, hemilight_unwrap_stats_init,
 * hemilight_generate_lightmap_uvs.
 * References: invariants. A unit cube exported with every triangle's own vertices welds into six
 * planar charts (one per face, 90 degrees apart); every output vertex copies its source's position;
 * every UV lies in [0, 1]; every triangle keeps its winding in UV (positive area); every face's
 * two triangles have one UV area per unit of 3D area (one density, float rounding); the same bytes
 * for one and two threads. Bad input: a clear message naming the argument, nothing written.
 * Prints failing checks and a closing "N passed, N failed" line. */
#include "capi_check.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

enum { T = 12, V = 3 * T, CAP = 3 * T };

static float positions[3 * V];
static uint32_t indices[3 * T];
static uint32_t source[CAP], source2[CAP], out_idx[3 * T], out_idx2[3 * T], page[T];
static float uvs[2 * CAP], uvs2[2 * CAP];

/* The unit cube's 12 triangles, counter-clockwise seen from outside, every one with its own vertices. */
static void make_cube(void) {
  static const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  static const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 4, 7, 3}, {1, 2, 6, 5}};
  int f, t = 0, k;
  for (f = 0; f < 6; ++f) {
    const int tri[2][3] = {{faces[f][0], faces[f][1], faces[f][2]}, {faces[f][0], faces[f][2], faces[f][3]}};
    int h;
    for (h = 0; h < 2; ++h, ++t)
      for (k = 0; k < 3; ++k) {
        const int v = 3 * t + k, c = tri[h][k];
        positions[3 * v] = (float)corner[c][0];
        positions[3 * v + 1] = (float)corner[c][1];
        positions[3 * v + 2] = (float)corner[c][2];
        indices[3 * t + k] = (uint32_t)v;
      }
  }
}

static double uv_area2(const float* uv, const uint32_t* idx, int t) {
  const float* a = uv + 2 * idx[3 * t];
  const float* b = uv + 2 * idx[3 * t + 1];
  const float* c = uv + 2 * idx[3 * t + 2];
  return ((double)b[0] - a[0]) * ((double)c[1] - a[1]) - ((double)b[1] - a[1]) * ((double)c[0] - a[0]);
}

int main(void) {
  hemilight_unwrap_options o;
  hemilight_unwrap_stats st;
  size_t n = 0, n2 = 0, i;
  int t, ok = 1;
  make_cube();
  hemilight_unwrap_options_init(&o);
  hemilight_unwrap_options_init(NULL); /* ignored */
  CHECK(o.texels_per_unit == 0.0f && o.page_size == 1024 && o.padding == 2 && o.max_chart_angle == 60.0f && o.max_pages == 64 &&
        o.thread_count == 0);
  o.page_size = 64;
  o.thread_count = 1;
  hemilight_unwrap_stats_init(&st);
  CHECK(hemilight_generate_lightmap_uvs(positions, V, indices, T, &o, source, uvs, CAP, out_idx, page, &n, &st) == HEMILIGHT_OK);
  CHECK(st.charts == 6 && st.planar_charts == 6 && st.pages == 1 && st.degenerate_triangles == 0);
  CHECK(n == V); /* each input vertex in the one chart of its face */
  CHECK(fabs(st.stretch_l2 - 1.0) < 1e-5 && fabs(st.stretch_linf - 1.0) < 1e-5); /* projections; float UVs */
  for (i = 0; i < n; ++i) {
    if (source[i] >= V) ok = 0;
    if (!(uvs[2 * i] >= 0.0f && uvs[2 * i] <= 1.0f && uvs[2 * i + 1] >= 0.0f && uvs[2 * i + 1] <= 1.0f)) ok = 0;
  }
  for (t = 0; t < T; ++t) {
    int k;
    for (k = 0; k < 3; ++k)
      if (source[out_idx[3 * t + k]] != indices[3 * t + k]) ok = 0;
    /* 3D area 1/2: UV area (texels) = density^2 / 2; float UVs: 1e-4 */
    if (fabs(uv_area2(uvs, out_idx, t) * 64.0 * 64.0 / 2.0 - (double)st.texels_per_unit * st.texels_per_unit / 2.0) >
        1e-4 * (double)st.texels_per_unit * st.texels_per_unit)
      ok = 0;
    if (page[t] != 0) ok = 0;
  }
  CHECK(ok);
  /* Two threads: the same bytes. */
  o.thread_count = 2;
  CHECK(hemilight_generate_lightmap_uvs(positions, V, indices, T, &o, source2, uvs2, CAP, out_idx2, NULL, &n2, NULL) == HEMILIGHT_OK);
  CHECK(n2 == n && memcmp(source, source2, n * sizeof *source) == 0 && memcmp(uvs, uvs2, 2 * n * sizeof *uvs) == 0 &&
        memcmp(out_idx, out_idx2, sizeof out_idx) == 0);
  /* No triangles: no vertices, the arrays may be NULL. */
  n2 = 7;
  CHECK(hemilight_generate_lightmap_uvs(positions, V, NULL, 0, NULL, NULL, NULL, 0, NULL, NULL, &n2, NULL) == HEMILIGHT_OK);
  CHECK(n2 == 0);

  /* Coordinates up to 1e18 in magnitude (max_coordinate) are taken; beyond, refused by name. */
  {
    float big[9] = {1e18f, 0, 0, 0, 1e18f, 0, 0, 0, 0};
    const uint32_t tri[3] = {0, 1, 2};
    uint32_t src[3], idx3[3];
    float uv3[6];
    hemilight_unwrap_options_init(&o);
    CHECK(hemilight_generate_lightmap_uvs(big, 3, tri, 1, &o, src, uv3, 3, idx3, NULL, &n2, NULL) == HEMILIGHT_OK);
    CHECK(n2 == 3 && fabs(uv_area2(uv3, idx3, 0)) > 0.0);
    big[4] = 1.5e18f;
    CHECK_FAILS(hemilight_generate_lightmap_uvs(big, 3, tri, 1, &o, src, uv3, 3, idx3, NULL, &n2, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
                "positions[4] (vertex 1)");
    o.page_size = 64;
    o.thread_count = 2;
  }

  /* Bad input: one clear message each, nothing written. */
  memset(source2, 0x5a, sizeof source2);
  n2 = 7;
  CHECK_FAILS(hemilight_generate_lightmap_uvs(positions, V, indices, T, &o, source2, uvs2, CAP - 1, out_idx2, NULL, &n2, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_generate_lightmap_uvs: vertex_capacity 35 is below 3 x triangle_count = 36");
  CHECK_FAILS(hemilight_generate_lightmap_uvs(positions, V, indices, T, &o, source2, uvs2, CAP, out_idx2, NULL, NULL, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "vertex_count_out is NULL");
  CHECK_FAILS(hemilight_generate_lightmap_uvs(positions, V, indices, T, &o, NULL, uvs2, CAP, out_idx2, NULL, &n2, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "vertex_source, uvs or out_indices is NULL");
  positions[13] = (float)NAN;
  CHECK_FAILS(hemilight_generate_lightmap_uvs(positions, V, indices, T, &o, source2, uvs2, CAP, out_idx2, NULL, &n2, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "positions[13] (vertex 4) = nan");
  positions[13] = 0.0f;
  indices[5] = 99;
  CHECK_FAILS(hemilight_generate_lightmap_uvs(positions, V, indices, T, &o, source2, uvs2, CAP, out_idx2, NULL, &n2, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "indices[5] = 99 is out of range: 36 vertices");
  indices[5] = 5;
  o.page_size = 8;
  CHECK_FAILS(hemilight_generate_lightmap_uvs(positions, V, indices, T, &o, source2, uvs2, CAP, out_idx2, NULL, &n2, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_generate_lightmap_uvs: options: page_size 8 is not in [16, 8192]");
  o.page_size = 64;
  o.struct_size = 0;
  CHECK_FAILS(hemilight_generate_lightmap_uvs(positions, V, indices, T, &o, source2, uvs2, CAP, out_idx2, NULL, &n2, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "struct_size is 0");
  hemilight_unwrap_options_init(&o);
  o.page_size = 16;
  o.texels_per_unit = 100.0f; /* a face 100 texels wide in pages of 16 */
  CHECK_FAILS(hemilight_generate_lightmap_uvs(positions, V, indices, T, &o, source2, uvs2, CAP, out_idx2, NULL, &n2, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_generate_lightmap_uvs: triangle 3 is 141.42");
  {
    int untouched = n2 == 7;
    for (i = 0; i < CAP; ++i)
      if (source2[i] != 0x5a5a5a5au) untouched = 0;
    CHECK(untouched);
  }
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
