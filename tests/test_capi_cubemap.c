/* C99 test of the cube-map part of the C ABI: every entry point with good, NULL, out-of-range
 * and non-finite arguments, and that failing calls leave the outputs untouched.
 * Usage: hemilight_capi_cubemap_test <scratch directory>
 * Prints one line per check that fails and a closing "N passed, N failed" line. */
#include "hemilight.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capi_check.h"

static const double pi = 3.14159265358979323846;

static size_t cube_floats(int size) { return (size_t)6 * (size_t)size * (size_t)size * 3; }

static void test_texel_direction(void) {
  float d[3] = {7, 7, 7};
  /* +X face (0), size 1: the face centre under every mapping */
  CHECK(hemilight_cubemap_texel_direction(1, 0, 0, 0, HEMILIGHT_EDGE_FIXUP_STRETCH, d) == HEMILIGHT_OK);
  CHECK(d[0] == 1.0f && d[1] == 0.0f && d[2] == 0.0f);
  /* stretch, size 4: texel (0, 0) of +Z is the cube corner (-1, 1, 1) / sqrt(3) (u = v = -1) */
  CHECK(hemilight_cubemap_texel_direction(4, 4, 0, 0, HEMILIGHT_EDGE_FIXUP_STRETCH, d) == HEMILIGHT_OK);
  CHECK(fabs(d[0] + 1 / sqrt(3.0)) < 1e-6 && fabs(d[1] - 1 / sqrt(3.0)) < 1e-6 && fabs(d[2] - 1 / sqrt(3.0)) < 1e-6);
  /* centres, size 2, -Y face (3), texel (1, 1): (0.5, -1, -0.5) normalised */
  CHECK(hemilight_cubemap_texel_direction(2, 3, 1, 1, HEMILIGHT_EDGE_FIXUP_NONE, d) == HEMILIGHT_OK);
  CHECK(fabs(d[0] - 0.5 / sqrt(1.5)) < 1e-6 && fabs(d[1] + 1 / sqrt(1.5)) < 1e-6 && fabs(d[2] + 0.5 / sqrt(1.5)) < 1e-6);
  CHECK(hemilight_cubemap_texel_direction(8, 5, 7, 7, HEMILIGHT_EDGE_FIXUP_WARP, d) == HEMILIGHT_OK);

  d[0] = 42.0f;
  CHECK_FAILS(hemilight_cubemap_texel_direction(4, 6, 0, 0, HEMILIGHT_EDGE_FIXUP_NONE, d),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "face 6");
  CHECK_FAILS(hemilight_cubemap_texel_direction(4, -1, 0, 0, HEMILIGHT_EDGE_FIXUP_NONE, d),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "face -1");
  CHECK_FAILS(hemilight_cubemap_texel_direction(4, 0, 4, 0, HEMILIGHT_EDGE_FIXUP_NONE, d),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "texel (4, 0)");
  CHECK_FAILS(hemilight_cubemap_texel_direction(4, 0, 0, -1, HEMILIGHT_EDGE_FIXUP_NONE, d),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "texel (0, -1)");
  CHECK_FAILS(hemilight_cubemap_texel_direction(0, 0, 0, 0, HEMILIGHT_EDGE_FIXUP_NONE, d),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "size 0");
  CHECK_FAILS(hemilight_cubemap_texel_direction(6689, 0, 0, 0, HEMILIGHT_EDGE_FIXUP_NONE, d),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "size 6689");
  CHECK_FAILS(hemilight_cubemap_texel_direction(4, 0, 0, 0, (hemilight_edge_fixup)3, d),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "fixup 3");
  CHECK_FAILS(hemilight_cubemap_texel_direction(4, 0, 0, 0, HEMILIGHT_EDGE_FIXUP_NONE, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "direction is NULL");
  CHECK(d[0] == 42.0f); /* untouched on failure */
}

static void test_fixup_lookup(void) {
  const float tie[3] = {1, 1, 0}, zero[3] = {0, 0, 0}, dir[3] = {0.2f, -0.9f, 0.4f};
  float out[3] = {9, 9, 9}, in_place[3] = {0.2f, -0.9f, 0.4f};
  float bad[3] = {0, 0, 1};
  CHECK(hemilight_cubemap_fixup_lookup(tie, 4, -1.0f, out) == HEMILIGHT_OK);
  CHECK(out[0] == 1.0f && out[1] == 0.75f && out[2] == 0.0f); /* x wins the tie, y shrinks */
  CHECK(hemilight_cubemap_fixup_lookup(zero, 4, 0.0f, out) == HEMILIGHT_OK);
  CHECK(out[0] == 0.0f && out[1] == 0.0f && out[2] == 0.0f);
  CHECK(hemilight_cubemap_fixup_lookup(dir, 8, 1.0f, out) == HEMILIGHT_OK); /* scale 1 - 2/8 */
  CHECK(out[1] == -0.9f && fabs(out[0] - 0.15) < 1e-6 && fabs(out[2] - 0.3) < 1e-6);
  CHECK(hemilight_cubemap_fixup_lookup(dir, 8, 30.0f, out) == HEMILIGHT_OK); /* past the last mip */
  CHECK(out[0] == 0.0f && out[1] == -0.9f && out[2] == 0.0f);
  CHECK(hemilight_cubemap_fixup_lookup(in_place, 8, -1.0f, in_place) == HEMILIGHT_OK); /* aliasing is fine */
  CHECK(in_place[1] == -0.9f && fabs(in_place[0] - 0.175) < 1e-6);

  out[0] = 9.0f;
  CHECK_FAILS(hemilight_cubemap_fixup_lookup(NULL, 4, 0.0f, out), HEMILIGHT_ERROR_INVALID_ARGUMENT, "direction is NULL");
  CHECK_FAILS(hemilight_cubemap_fixup_lookup(dir, 4, 0.0f, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "out_direction is NULL");
  CHECK_FAILS(hemilight_cubemap_fixup_lookup(dir, 0, 0.0f, out), HEMILIGHT_ERROR_INVALID_ARGUMENT, "size 0");
  CHECK_FAILS(hemilight_cubemap_fixup_lookup(dir, 4, (float)NAN, out), HEMILIGHT_ERROR_INVALID_ARGUMENT, "lod");
  CHECK_FAILS(hemilight_cubemap_fixup_lookup(dir, 4, (float)INFINITY, out), HEMILIGHT_ERROR_INVALID_ARGUMENT, "lod");
  bad[1] = (float)NAN;
  CHECK_FAILS(hemilight_cubemap_fixup_lookup(bad, 4, 0.0f, out), HEMILIGHT_ERROR_INVALID_ARGUMENT, "NaN or infinite");
  bad[1] = (float)-INFINITY;
  CHECK_FAILS(hemilight_cubemap_fixup_lookup(bad, 4, 0.0f, out), HEMILIGHT_ERROR_INVALID_ARGUMENT, "NaN or infinite");
  CHECK(out[0] == 9.0f);
}

static void test_filters(void) {
  const int n = 8, m = 4;
  float* in = malloc(sizeof(float) * cube_floats(n));
  float* out = malloc(sizeof(float) * cube_floats(m));
  float* chain = NULL;
  size_t i, floats = 0;
  int levels = 0;
  hemilight_edge_fixup f;
  for (i = 0; i < cube_floats(n); ++i) in[i] = 1.5f;
  /* constant in, constant out: every mapping, filter and path */
  for (f = HEMILIGHT_EDGE_FIXUP_NONE; f <= HEMILIGHT_EDGE_FIXUP_WARP; f = (hemilight_edge_fixup)(f + 1)) {
    int ok = hemilight_cubemap_filter_cosine_power(in, n, 20.0f, f, m, out) == HEMILIGHT_OK;
    for (i = 0; ok && i < cube_floats(m); ++i) ok = fabs(out[i] - 1.5) < 1e-5;
    CHECK(ok);
    ok = hemilight_cubemap_filter_irradiance(in, n, f, m, 0, out) == HEMILIGHT_OK;
    for (i = 0; ok && i < cube_floats(m); ++i) ok = fabs(out[i] / (1.5 * pi) - 1) < 1e-5;
    CHECK(ok);
    ok = hemilight_cubemap_filter_irradiance(in, n, f, m, 1, out) == HEMILIGHT_OK;
    for (i = 0; ok && i < cube_floats(m); ++i) ok = fabs(out[i] / (1.5 * pi) - 1) < 1e-5;
    CHECK(ok);
  }
  CHECK(hemilight_cubemap_chain_floats(m, &floats, &levels) == HEMILIGHT_OK);
  CHECK(levels == 3 && floats == cube_floats(4) + cube_floats(2) + cube_floats(1));
  CHECK(hemilight_cubemap_chain_floats(1, NULL, &levels) == HEMILIGHT_OK && levels == 1);
  chain = malloc(sizeof(float) * floats);
  CHECK(hemilight_cubemap_filter_mip_chain(in, n, HEMILIGHT_EDGE_FIXUP_STRETCH, m, 0.0f, chain, floats) == HEMILIGHT_OK);
  CHECK(fabs(chain[0] - 1.5) < 1e-5 && fabs(chain[floats - 1] - 1.5) < 1e-5);

  /* bad arguments: status, message, and the output untouched */
  out[0] = -3.0f;
  chain[0] = -3.0f;
  CHECK_FAILS(hemilight_cubemap_filter_cosine_power(NULL, n, 20.0f, HEMILIGHT_EDGE_FIXUP_NONE, m, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "input is NULL");
  CHECK_FAILS(hemilight_cubemap_filter_cosine_power(in, n, 20.0f, HEMILIGHT_EDGE_FIXUP_NONE, m, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "output is NULL");
  CHECK_FAILS(hemilight_cubemap_filter_cosine_power(in, 0, 20.0f, HEMILIGHT_EDGE_FIXUP_NONE, m, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "input_size 0");
  CHECK_FAILS(hemilight_cubemap_filter_cosine_power(in, n, 20.0f, HEMILIGHT_EDGE_FIXUP_NONE, -2, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "output_size -2");
  CHECK_FAILS(hemilight_cubemap_filter_cosine_power(in, n, 0.0f, HEMILIGHT_EDGE_FIXUP_NONE, m, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "specular_power");
  CHECK_FAILS(hemilight_cubemap_filter_cosine_power(in, n, (float)NAN, HEMILIGHT_EDGE_FIXUP_NONE, m, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "specular_power");
  CHECK_FAILS(hemilight_cubemap_filter_cosine_power(in, n, (float)INFINITY, HEMILIGHT_EDGE_FIXUP_NONE, m, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "specular_power");
  CHECK_FAILS(hemilight_cubemap_filter_cosine_power(in, n, 20.0f, (hemilight_edge_fixup)-1, m, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "fixup -1");
  in[100] = (float)NAN;
  CHECK_FAILS(hemilight_cubemap_filter_cosine_power(in, n, 20.0f, HEMILIGHT_EDGE_FIXUP_NONE, m, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "input value 100 = nan is not finite");
  CHECK_FAILS(hemilight_cubemap_filter_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, 1, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "not finite");
  CHECK_FAILS(hemilight_cubemap_filter_mip_chain(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, 1.0f, chain, floats),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "not finite");
  in[100] = 1.5f;
  CHECK_FAILS(hemilight_cubemap_filter_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, 2, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "use_sh is 2");
  CHECK_FAILS(hemilight_cubemap_filter_irradiance(NULL, n, HEMILIGHT_EDGE_FIXUP_NONE, m, 0, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "input is NULL");
  CHECK_FAILS(hemilight_cubemap_filter_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, 0, 0, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "output_size 0");
  CHECK_FAILS(hemilight_cubemap_filter_mip_chain(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, 1.0f, chain, floats - 1),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "too small");
  CHECK_FAILS(hemilight_cubemap_filter_mip_chain(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, (float)NAN, chain, floats),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "lobe_texels");
  CHECK_FAILS(hemilight_cubemap_filter_mip_chain(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, 1.0f, NULL, floats),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "output is NULL");
  CHECK_FAILS(hemilight_cubemap_chain_floats(0, &floats, &levels), HEMILIGHT_ERROR_INVALID_ARGUMENT, "size 0");
  CHECK(out[0] == -3.0f && chain[0] == -3.0f);
  free(in);
  free(out);
  free(chain);
}

static void test_sample(void) {
  /* a 2-level chain of size 2: level 0 holds 1 on +X and 2 elsewhere, level 1 holds 5 */
  float chain[6 * 2 * 2 * 3 + 6 * 1 * 1 * 3];
  const float px[3] = {1, 0, 0}, corner[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
  float nan_dir[3] = {1, 0, 0};
  float rgb[3] = {0, 0, 0};
  size_t i;
  for (i = 0; i < 6 * 2 * 2 * 3; ++i) i < 12 ? (chain[i] = 1.0f) : (chain[i] = 2.0f);
  for (; i < sizeof chain / sizeof chain[0]; ++i) chain[i] = 5.0f;
  CHECK(hemilight_cubemap_sample(chain, 2, 2, px, 0.0f, HEMILIGHT_CUBE_SAMPLING_CLAMP_PER_FACE, 0, rgb) == HEMILIGHT_OK);
  CHECK(rgb[0] == 1.0f && rgb[2] == 1.0f);
  CHECK(hemilight_cubemap_sample(chain, 2, 2, px, 0.5f, HEMILIGHT_CUBE_SAMPLING_CLAMP_PER_FACE, 1, rgb) == HEMILIGHT_OK);
  CHECK(fabs(rgb[1] - 3.0) < 1e-6); /* trilinear: half of level 0 (1), half of level 1 (5) */
  CHECK(hemilight_cubemap_sample(chain, 2, 2, px, 9.0f, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 0, rgb) == HEMILIGHT_OK);
  CHECK(rgb[0] == 5.0f);
  /* at the corner (1, 1, 1) seamless sampling averages +X (1), +Y (2) and +Z (2) */
  CHECK(hemilight_cubemap_sample(chain, 2, 1, corner, 0.0f, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 0, rgb) == HEMILIGHT_OK);
  CHECK(fabs(rgb[0] - 5.0 / 3.0) < 1e-6);
  /* per face with the fixup: the tie goes to +X and the lookup stays inside it */
  CHECK(hemilight_cubemap_sample(chain, 2, 1, corner, -1.0f, HEMILIGHT_CUBE_SAMPLING_CLAMP_PER_FACE, 1, rgb) == HEMILIGHT_OK);
  CHECK(rgb[0] == 1.0f);

  rgb[0] = -1.0f;
  CHECK_FAILS(hemilight_cubemap_sample(NULL, 2, 1, px, 0.0f, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 0, rgb),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "chain is NULL");
  CHECK_FAILS(hemilight_cubemap_sample(chain, 2, 1, NULL, 0.0f, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 0, rgb),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "direction is NULL");
  CHECK_FAILS(hemilight_cubemap_sample(chain, 2, 1, px, 0.0f, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 0, NULL),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "rgb is NULL");
  CHECK_FAILS(hemilight_cubemap_sample(chain, 2, 3, px, 0.0f, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 0, rgb),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "level_count 3");
  CHECK_FAILS(hemilight_cubemap_sample(chain, 2, 0, px, 0.0f, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 0, rgb),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "level_count 0");
  CHECK_FAILS(hemilight_cubemap_sample(chain, 0, 1, px, 0.0f, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 0, rgb),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "size 0");
  CHECK_FAILS(hemilight_cubemap_sample(chain, 2, 1, zero, 0.0f, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 0, rgb),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "direction is zero");
  nan_dir[2] = (float)NAN;
  CHECK_FAILS(hemilight_cubemap_sample(chain, 2, 1, nan_dir, 0.0f, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 0, rgb),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "NaN or infinite");
  CHECK_FAILS(hemilight_cubemap_sample(chain, 2, 1, px, (float)NAN, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 0, rgb),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "lod");
  CHECK_FAILS(hemilight_cubemap_sample(chain, 2, 1, px, 0.0f, (hemilight_cube_sampling)7, 0, rgb),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "sampling 7");
  CHECK_FAILS(hemilight_cubemap_sample(chain, 2, 1, px, 0.0f, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 2, rgb),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "apply_fixup is 2");
  CHECK(rgb[0] == -1.0f);
}

static void test_irradiance_methods(void) {
  /* L(w) = 1 + 0.5 w_z lies in SH bands 0-1: E(n) = pi + (pi / 3) n_z exactly (the hemisphere
   * integrals of cos and of w_z cos). SH9 and SH25 reproduce it up to the texel-centre quadrature
   * over 16^2 texels, which leaves O(h^2) of L in band 4 (band 2 cancels by the cube's symmetry;
   * measured 1e-7 with SH9, 1.9e-4 with SH25: tolerance 5e-4); the filter clips texels at the horizon by their centres on the 16^2 mip
   * (O(h^2) too: tolerance 2e-3). */
  const int n = 16, m = 4;
  float* in = malloc(sizeof(float) * cube_floats(n));
  float* out = malloc(sizeof(float) * cube_floats(m));
  float* again = malloc(sizeof(float) * cube_floats(m));
  const double tolerance[3] = {2e-3, 5e-4, 5e-4};
  hemilight_cubemap_irradiance_options o;
  int face, x, y, k, method;
  float d[3];
  for (face = 0; face < 6; ++face)
    for (y = 0; y < n; ++y)
      for (x = 0; x < n; ++x) {
        hemilight_cubemap_texel_direction(n, face, x, y, HEMILIGHT_EDGE_FIXUP_NONE, d);
        for (k = 0; k < 3; ++k) in[((size_t)(face * n + y) * n + x) * 3 + k] = 1.0f + 0.5f * d[2];
      }
  hemilight_cubemap_irradiance_options_init(&o);
  CHECK(o.struct_size == sizeof o && o.method == HEMILIGHT_IRRADIANCE_FILTER && o.input_size == 16 &&
        o.thread_count == 0);
  for (method = HEMILIGHT_IRRADIANCE_FILTER; method <= HEMILIGHT_IRRADIANCE_SH25; ++method) {
    double worst = 0;
    o.method = (hemilight_irradiance_method)method;
    o.thread_count = 1;
    CHECK(hemilight_cubemap_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_WARP, m, &o, out) == HEMILIGHT_OK);
    for (face = 0; face < 6; ++face)
      for (y = 0; y < m; ++y)
        for (x = 0; x < m; ++x) {
          const float* e = out + ((size_t)(face * m + y) * m + x) * 3;
          hemilight_cubemap_texel_direction(m, face, x, y, HEMILIGHT_EDGE_FIXUP_WARP, d);
          for (k = 0; k < 3; ++k) {
            const double exact = pi + pi / 3 * d[2], err = fabs(e[k] / exact - 1);
            if (err > worst) worst = err;
          }
        }
    if (!(worst < tolerance[method])) printf("  method %d: max relative error %g\n", method, worst);
    CHECK(worst < tolerance[method]);
    o.thread_count = 2; /* bitwise the same for any thread count */
    CHECK(hemilight_cubemap_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_WARP, m, &o, again) == HEMILIGHT_OK);
    CHECK(memcmp(out, again, sizeof(float) * cube_floats(m)) == 0);
  }
  /* NULL options: the defaults (the filter), the same as the old entry's use_sh = 0 */
  CHECK(hemilight_cubemap_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, NULL, out) == HEMILIGHT_OK);
  CHECK(hemilight_cubemap_filter_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, 0, again) == HEMILIGHT_OK);
  CHECK(memcmp(out, again, sizeof(float) * cube_floats(m)) == 0);
  /* an older caller's struct (without input_size and thread_count) takes their defaults */
  hemilight_cubemap_irradiance_options_init(&o);
  o.method = HEMILIGHT_IRRADIANCE_SH9;
  o.input_size = -5; /* past the older struct_size: not read */
  o.struct_size = offsetof(hemilight_cubemap_irradiance_options, input_size);
  CHECK(hemilight_cubemap_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, &o, out) == HEMILIGHT_OK);
  CHECK(hemilight_cubemap_filter_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, 1, again) == HEMILIGHT_OK);
  CHECK(memcmp(out, again, sizeof(float) * cube_floats(m)) == 0);

  /* bad arguments: status, message, and the output untouched */
  out[0] = -3.0f;
  hemilight_cubemap_irradiance_options_init(&o);
  o.method = (hemilight_irradiance_method)7;
  CHECK_FAILS(hemilight_cubemap_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, &o, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "options->method is 7");
  hemilight_cubemap_irradiance_options_init(&o);
  o.input_size = 0;
  CHECK_FAILS(hemilight_cubemap_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, &o, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "options->input_size 0");
  o.method = HEMILIGHT_IRRADIANCE_SH25; /* input_size is ignored by the SH methods */
  CHECK(hemilight_cubemap_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, &o, again) == HEMILIGHT_OK);
  hemilight_cubemap_irradiance_options_init(&o);
  o.struct_size = 0;
  CHECK_FAILS(hemilight_cubemap_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, &o, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_cubemap_irradiance_options_init");
  o.struct_size = sizeof o + 8;
  CHECK_FAILS(hemilight_cubemap_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, &o, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "newer hemilight.h");
  CHECK_FAILS(hemilight_cubemap_irradiance(NULL, n, HEMILIGHT_EDGE_FIXUP_NONE, m, NULL, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "input is NULL");
  CHECK_FAILS(hemilight_cubemap_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, 6689, NULL, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "output_size 6689");
  CHECK_FAILS(hemilight_cubemap_irradiance(in, n, (hemilight_edge_fixup)5, m, NULL, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "fixup 5");
  in[40] = (float)INFINITY;
  CHECK_FAILS(hemilight_cubemap_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, m, NULL, out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "input value 40");
  CHECK(out[0] == -3.0f);
  hemilight_cubemap_irradiance_options_init_sized(NULL, sizeof o); /* ignored */
  free(in);
  free(out);
  free(again);
}

static void test_exr_round_trip(const char* dir) {
  /* EXR cube-map load/save of the C ABI with a filtered map; corrupt files through the loader */
  char path[1024], bad[1024];
  const int n = 4;
  float* in = malloc(sizeof(float) * cube_floats(n));
  float* back = malloc(sizeof(float) * cube_floats(n));
  float* out = malloc(sizeof(float) * cube_floats(n));
  size_t i;
  int size = 0;
  FILE* fp;
  snprintf(path, sizeof path, "%s/capi_cubemap_filtered.exr", dir);
  snprintf(bad, sizeof bad, "%s/capi_cubemap_garbage.exr", dir);
  for (i = 0; i < cube_floats(n); ++i) in[i] = (float)(i % 11);
  CHECK(hemilight_cubemap_filter_cosine_power(in, n, 8.0f, HEMILIGHT_EDGE_FIXUP_WARP, n, out) == HEMILIGHT_OK);
  CHECK(hemilight_exr_save_cubemap_rgb(path, out, n, 0) == HEMILIGHT_OK);
  CHECK(hemilight_exr_load_cubemap_rgb(path, back, cube_floats(n), &size) == HEMILIGHT_OK);
  CHECK(size == n && memcmp(out, back, sizeof(float) * cube_floats(n)) == 0);
  fp = fopen(bad, "wb");
  if (fp) {
    fputs("v/1\001this is not an EXR file", fp);
    fclose(fp);
  }
  back[0] = -5.0f;
  CHECK_FAILS(hemilight_exr_load_cubemap_rgb(bad, back, cube_floats(n), &size), HEMILIGHT_ERROR_IO, "capi_cubemap_garbage");
  CHECK(back[0] == -5.0f);
  free(in);
  free(back);
  free(out);
}

int main(int argc, char** argv) {
  const char* dir = argc > 1 ? argv[1] : ".";
  test_texel_direction();
  test_fixup_lookup();
  test_filters();
  test_irradiance_methods();
  test_sample();
  test_exr_round_trip(dir);
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
