/* C99 test: every refusal that capi/hemilight.h states for an entry, made through that entry, for
 * the ones the other test_capi*.c do not cover (they cover the rest: NULL arguments, sizes,
 * resolutions, most options). Each call has one argument past a stated limit; the message must
 * name the argument and the outputs stay untouched. For the coordinate (1e18) and radiance (1e30)
 * limits the value at the limit is accepted too, against a closed form where there is one: a
 * uniform sky of radiance L gives irradiance pi L and an SH9 c_0 of 2 sqrt(pi) L (to 1e-5: the
 * float rounding of the hemicube's weight sums). Small EXR files with one property each (no R, G,
 * B; a subsampled channel; a latlong envmap attribute) are written here byte by byte, and valid
 * ones of the same writer are read back first, so that a refusal is the property's and not the
 * writer's. Prints failing checks and "N passed, N failed". */
#include "capi_check.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const double pi = 3.14159265358979323846;

/* ---- EXR ---------------------------------------------------------------------------------- */

static void put32(FILE* f, uint32_t v) {
  fputc((int)(v & 255u), f);
  fputc((int)(v >> 8 & 255u), f);
  fputc((int)(v >> 16 & 255u), f);
  fputc((int)(v >> 24 & 255u), f);
}

static void put_attribute(FILE* f, const char* name, const char* type, uint32_t size) {
  fputs(name, f);
  fputc(0, f);
  fputs(type, f);
  fputc(0, f);
  put32(f, size);
}

/* A w x h scanline OpenEXR file, uncompressed, of half channels named by the letters of `channels`
 * (in alphabetical order), the first of them sampled every `xs` pixels in x, with an envmap
 * attribute of value `envmap` (0 latlong, 1 cube; -1: none). Every pixel 0. 1 if written. */
static int write_tiny_exr(const char* path, int w, int h, const char* channels, int xs, int envmap) {
  FILE* f = fopen(path, "wb");
  const uint32_t nc = (uint32_t)strlen(channels);
  const float one = 1.0f;
  uint32_t one_bits, line_bytes = 0, i;
  long table;
  int y, k;
  if (!f) return 0;
  memcpy(&one_bits, &one, sizeof one_bits);
  fputs("\x76\x2f\x31\x01", f); /* magic */
  put32(f, 2);                  /* version 2, single-part scanline */
  put_attribute(f, "channels", "chlist", 18 * nc + 1);
  for (i = 0; i < nc; ++i) {
    fputc(channels[i], f);
    fputc(0, f);
    put32(f, 1); /* HALF */
    put32(f, 0); /* pLinear, reserved */
    put32(f, i == 0 ? (uint32_t)xs : 1u);
    put32(f, 1);
    line_bytes += 2u * (uint32_t)(w / (i == 0 ? xs : 1));
  }
  fputc(0, f);
  put_attribute(f, "compression", "compression", 1);
  fputc(0, f); /* NO_COMPRESSION */
  for (k = 0; k < 2; ++k) {
    put_attribute(f, k == 0 ? "dataWindow" : "displayWindow", "box2i", 16);
    put32(f, 0), put32(f, 0), put32(f, (uint32_t)(w - 1)), put32(f, (uint32_t)(h - 1));
  }
  put_attribute(f, "lineOrder", "lineOrder", 1);
  fputc(0, f);
  put_attribute(f, "pixelAspectRatio", "float", 4);
  put32(f, one_bits);
  put_attribute(f, "screenWindowCenter", "v2f", 8);
  put32(f, 0), put32(f, 0);
  put_attribute(f, "screenWindowWidth", "float", 4);
  put32(f, one_bits);
  if (envmap >= 0) {
    put_attribute(f, "envmap", "envmap", 1);
    fputc(envmap, f);
  }
  fputc(0, f); /* end of the header */
  table = ftell(f);
  for (y = 0; y < h; ++y) { /* offsets of the chunks: y, size, the line */
    const uint64_t at = (uint64_t)table + 8u * (uint64_t)h + (uint64_t)y * (8u + line_bytes);
    put32(f, (uint32_t)(at & 0xffffffffu));
    put32(f, (uint32_t)(at >> 32));
  }
  for (y = 0; y < h; ++y) {
    put32(f, (uint32_t)y);
    put32(f, line_bytes);
    for (i = 0; i < line_bytes; ++i) fputc(0, f);
  }
  return fclose(f) == 0;
}

static void test_exr(const char* tmp) {
  char valid[512], y_only[512], subsampled[512], latlong[512], cube[512], garbage[512], nowhere[512];
  float px[72], untouched[72];
  int w = -7, h = -7, cube_flag = -7, size = -7, i;
  FILE* f;
  snprintf(valid, sizeof valid, "%s/limits_valid.exr", tmp);
  snprintf(y_only, sizeof y_only, "%s/limits_y_only.exr", tmp);
  snprintf(subsampled, sizeof subsampled, "%s/limits_subsampled.exr", tmp);
  snprintf(latlong, sizeof latlong, "%s/limits_latlong.exr", tmp);
  snprintf(cube, sizeof cube, "%s/limits_cube.exr", tmp);
  snprintf(garbage, sizeof garbage, "%s/limits_garbage.exr", tmp);
  snprintf(nowhere, sizeof nowhere, "%s/no/such/dir/x.exr", tmp);
  CHECK(write_tiny_exr(valid, 2, 2, "BGR", 1, -1) && write_tiny_exr(y_only, 2, 2, "Y", 1, -1) &&
        write_tiny_exr(subsampled, 2, 2, "BGR", 2, -1) && write_tiny_exr(latlong, 2, 12, "BGR", 1, 0) &&
        write_tiny_exr(cube, 2, 12, "BGR", 1, 1));
  f = fopen(garbage, "wb");
  CHECK(f != NULL);
  if (f) {
    fputs("\x76\x2f\x31\x01 this is not an EXR file, only its magic number", f);
    fclose(f);
  }
  for (i = 0; i < 72; ++i) untouched[i] = px[i] = -7.0f;
  /* The writer's files are valid: a 2 x 2 image of zeros, and a 2 x 12 cube map read as one. */
  CHECK(hemilight_exr_info(valid, &w, &h, &cube_flag) == HEMILIGHT_OK && w == 2 && h == 2 && cube_flag == 0);
  CHECK(hemilight_exr_load_rgb(valid, px, 12, &w, &h) == HEMILIGHT_OK && px[0] == 0.0f && px[11] == 0.0f && px[12] == -7.0f);
  CHECK(hemilight_exr_load_cubemap_rgb(cube, px, 72, &size) == HEMILIGHT_OK && size == 2 && px[71] == 0.0f);
  memcpy(px, untouched, sizeof px);
  w = h = cube_flag = size = -7;

  /* hemilight_exr_info (and the loaders: "Errors: as hemilight_exr_info"). */
  CHECK_FAILS(hemilight_exr_info(tmp, &w, &h, &cube_flag), HEMILIGHT_ERROR_IO, "hemilight_exr_info: '");
  CHECK(strstr(hemilight_last_error(), "is a directory") != NULL);
  CHECK_FAILS(hemilight_exr_info(garbage, &w, &h, &cube_flag), HEMILIGHT_ERROR_IO, "not a readable EXR file");
  CHECK_FAILS(hemilight_exr_info(y_only, &w, &h, &cube_flag), HEMILIGHT_ERROR_UNSUPPORTED, "missing channel 'R' (file has Y)");
  CHECK_FAILS(hemilight_exr_info(subsampled, &w, &h, &cube_flag), HEMILIGHT_ERROR_UNSUPPORTED, "channel 'B' is subsampled");
  CHECK_FAILS(hemilight_exr_load_rgb(y_only, px, 72, &w, &h), HEMILIGHT_ERROR_UNSUPPORTED, "hemilight_exr_load_rgb: ");
  CHECK_FAILS(hemilight_exr_load_rgb(subsampled, px, 72, &w, &h), HEMILIGHT_ERROR_UNSUPPORTED, "is subsampled");
  CHECK_FAILS(hemilight_exr_load_rgb(tmp, px, 72, &w, &h), HEMILIGHT_ERROR_IO, "is a directory");
  CHECK_FAILS(hemilight_exr_load_rgb(NULL, px, 72, &w, &h), HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_exr_load_rgb: path is NULL");
  CHECK_FAILS(hemilight_exr_load_cubemap_rgb(NULL, px, 72, &size), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_exr_load_cubemap_rgb: path is NULL");
  CHECK_FAILS(hemilight_exr_load_cubemap_rgb(garbage, px, 72, &size), HEMILIGHT_ERROR_IO, "not a readable EXR file");
  /* A latlong map of cube-map shape: UNSUPPORTED. */
  CHECK_FAILS(hemilight_exr_load_cubemap_rgb(latlong, px, 72, &size), HEMILIGHT_ERROR_UNSUPPORTED,
              "envmap attribute is latlong, not cube");
  CHECK(w == -7 && h == -7 && cube_flag == -7 && size == -7 && memcmp(px, untouched, sizeof px) == 0);

  /* The writers: a file that cannot be written (its directory is missing). */
  CHECK_FAILS(hemilight_exr_save_rgb(nowhere, px, 2, 2, 0), HEMILIGHT_ERROR_IO, "hemilight_exr_save_rgb: '");
  CHECK(strstr(hemilight_last_error(), "cannot write") != NULL);
  CHECK_FAILS(hemilight_exr_save_cubemap_rgb(nowhere, px, 2, 1), HEMILIGHT_ERROR_IO, "cannot write");
  CHECK_FAILS(hemilight_exr_save_cubemap_rgb(NULL, px, 2, 0), HEMILIGHT_ERROR_INVALID_ARGUMENT, "path is NULL");
  CHECK_FAILS(hemilight_exr_save_cubemap_rgb(valid, NULL, 2, 0), HEMILIGHT_ERROR_INVALID_ARGUMENT, "faces is NULL");
  CHECK_FAILS(hemilight_exr_save_cubemap_rgb(valid, px, -1, 0), HEMILIGHT_ERROR_INVALID_ARGUMENT, "size is -1");
}

/* ---- scenes and lights -------------------------------------------------------------------- */

static void test_scenes(void) {
  const float sky[3] = {1, 1, 1};
  const uint32_t idx[3] = {0, 1, 2};
  const float rad[3] = {1, 1, 1};
  float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  static float faces[6 * 2 * 2 * 3];
  hemilight_scene *s = NULL, *ok = NULL, *sentinel = (hemilight_scene*)&passed, *t = sentinel;
  int i;
  /* Coordinates: 1e18 in magnitude is accepted, 2^61 = 2.3e18 is refused. */
  pos[4] = -1e18f;
  CHECK(hemilight_scene_create(pos, 3, idx, 1, rad, sky, &ok) == HEMILIGHT_OK);
  hemilight_scene_release(ok);
  pos[4] = -0x1p61f;
  CHECK_FAILS(hemilight_scene_create(pos, 3, idx, 1, rad, sky, &t), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_create: positions[4] (vertex 1) = -2305843009213693952.000000");
  CHECK(strstr(hemilight_last_error(), "at most 1e18 in magnitude") != NULL);
  CHECK(t == sentinel);
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &s) == HEMILIGHT_OK);
  /* Environment radiance: 1e30 is accepted, 2e30 refused. */
  for (i = 0; i < 72; ++i) faces[i] = 1.0f;
  faces[3] = 1e30f;
  CHECK(hemilight_scene_with_environment(s, faces, 2, &ok) == HEMILIGHT_OK);
  hemilight_scene_release(ok);
  faces[3] = 2e30f;
  CHECK_FAILS(hemilight_scene_with_environment(s, faces, 2, &t), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_environment: faces_rgb[3]");
  CHECK(strstr(hemilight_last_error(), "at most 1e30") != NULL);
  faces[3] = 1.0f;
  CHECK_FAILS(hemilight_scene_with_environment(s, faces, 2, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "out is NULL");
  CHECK(t == sentinel);
  hemilight_scene_release(s);
}

/* One light field past its limit per case: lights[1] of two, named with its field. */
static void test_lights(void) {
  struct light_case {
    hemilight_light_type type;
    int field;
    float value;
    const char *field_name, *why;
  };
  /* field: 0 position.x, 1 radius, 2 spot_inner, 3 spot_outer, 4 height, 5 tangent (all three
   * components), 6 tangent = direction, 7 width (NaN: "any field"), 8 color.g */
  static const struct light_case cases[] = {
      {HEMILIGHT_LIGHT_POINT, 0, 0x1p61f, "lights[1].position.x = ", "is beyond 1e18"}, /* 2^61 = 2.3e18 */
      {HEMILIGHT_LIGHT_SPOT, 0, -0x1p61f, "lights[1].position.x = -", "is beyond 1e18"},
      {HEMILIGHT_LIGHT_POINT, 1, -0.5f, "lights[1].radius = -0.5", "is negative"},
      {HEMILIGHT_LIGHT_DIRECTIONAL, 1, 1.75f, "lights[1].radius = 1.75", "is past pi/2"},
      {HEMILIGHT_LIGHT_SPOT, 2, -0.25f, "lights[1].spot_inner = -0.25", "is negative"},
      {HEMILIGHT_LIGHT_SPOT, 3, 1.75f, "lights[1].spot_outer = 1.75", "is past pi/2"},
      {HEMILIGHT_LIGHT_RECT, 4, 0.0f, "lights[1].height = 0", "is not positive"},
      {HEMILIGHT_LIGHT_RECT, 5, 0.0f, "lights[1].tangent", "is zero"},
      {HEMILIGHT_LIGHT_RECT, 6, 0.0f, "lights[1].tangent", "is parallel to direction"},
      {HEMILIGHT_LIGHT_POINT, 7, NAN, "lights[1].width", "nan"},
      {HEMILIGHT_LIGHT_POINT, 8, 0x1p101f, "lights[1].color.g = ", "is over 1e30"}}; /* 2^101 = 2.5e30 */
  const float sky[3] = {0, 0, 0};
  hemilight_scene *s = NULL, *ok = NULL, *sentinel = (hemilight_scene*)&passed, *t = sentinel;
  hemilight_light l[2];
  size_t i;
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &s) == HEMILIGHT_OK);
  hemilight_light_init(&l[0], HEMILIGHT_LIGHT_POINT);
  for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    const struct light_case* c = &cases[i];
    hemilight_light_init(&l[1], c->type);
    switch (c->field) {
      case 0: l[1].position[0] = c->value; break;
      case 1: l[1].radius = c->value; break;
      case 2: l[1].spot_inner = c->value; break;
      case 3: l[1].spot_outer = c->value; break;
      case 4: l[1].height = c->value; break;
      case 5: l[1].tangent[0] = l[1].tangent[1] = l[1].tangent[2] = c->value; break;
      case 6: memcpy(l[1].tangent, l[1].direction, sizeof l[1].tangent); break;
      case 7: l[1].width = c->value; break;
      default: l[1].color[1] = c->value; break;
    }
    CHECK_FAILS(hemilight_scene_with_lights(s, l, 2, &t), HEMILIGHT_ERROR_INVALID_ARGUMENT, c->field_name);
    CHECK(strncmp(hemilight_last_error(), "hemilight_scene_with_lights: ", 29) == 0 && strstr(hemilight_last_error(), c->why));
  }
  CHECK(t == sentinel);
  /* Just inside: a position of 1e18, a colour of 1e30, angles of pi/2, a spot_inner of 0. */
  hemilight_light_init(&l[1], HEMILIGHT_LIGHT_SPOT);
  l[1].position[2] = -1e18f, l[1].color[0] = 1e30f, l[1].spot_inner = 0.0f, l[1].spot_outer = 1.5707963f;
  CHECK(hemilight_scene_with_lights(s, l, 2, &ok) == HEMILIGHT_OK);
  hemilight_scene_release(ok);
  hemilight_scene_release(s);
}

/* ---- points, probes, SH9 ------------------------------------------------------------------ */

/* An empty scene with a point light of 1e30 W/sr a hair (1e-10) above the origin: I / d^2
 * overflows float at the origin. */
static hemilight_scene* overflowing_light(void) {
  const float sky[3] = {0, 0, 0};
  hemilight_scene *empty = NULL, *lit = NULL;
  hemilight_light l;
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &empty) == HEMILIGHT_OK);
  hemilight_light_init(&l, HEMILIGHT_LIGHT_POINT);
  l.position[2] = 1e-10f;
  l.color[0] = l.color[1] = l.color[2] = 1e30f;
  CHECK(hemilight_scene_with_lights(empty, &l, 1, &lit) == HEMILIGHT_OK);
  hemilight_scene_release(empty);
  return lit;
}

static void test_points(void) {
  const float sky[3] = {1, 1, 1};
  /* far_p: 2^61 = 2.3e18, printed exactly ("2305843009213693952.000000"). */
  const float p[3] = {0, 0, 0}, up[3] = {0, 0, 1}, far_p[3] = {0, 0x1p61f, 0}, edge_p[3] = {0, 1e18f, 0};
  const float inf_p[3] = {0, INFINITY, 0}, nan_n[3] = {0, NAN, 1};
  float two_p[6] = {0, 0, 0, 0, 0, 0}, two_n[6] = {0, 0, 1, 0, 0, 1};
  hemilight_scene *s = NULL, *lit = overflowing_light();
  hemilight_sampler *sm = NULL, *sm_lit = NULL;
  hemilight_irradiance r, r_untouched, two[2];
  float sh[27], sh_untouched[27], e[3] = {-7, -7, -7}, coeffs[27], big_n[3] = {1, 1, 1};
  int i;
  memset(&r_untouched, 0x5a, sizeof r_untouched);
  memset(sh_untouched, 0x5a, sizeof sh_untouched);
  r = r_untouched;
  memcpy(sh, sh_untouched, sizeof sh);
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &s) == HEMILIGHT_OK);

  /* hemilight_sample_irradiance: a position at 1e18 is sampled (a uniform sky: pi L), 2^61 is not. */
  CHECK(hemilight_sample_irradiance(s, edge_p, up, 8, &r) == HEMILIGHT_OK && fabs(r.irradiance[0] / pi - 1.0) < 1e-5);
  r = r_untouched;
  CHECK_FAILS(hemilight_sample_irradiance(s, far_p, up, 8, &r), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_sample_irradiance: position (0.000000, 2305843009213693952.000000, 0.000000) is beyond 1e18");
  CHECK_FAILS(hemilight_sample_irradiance(s, inf_p, up, 8, &r), HEMILIGHT_ERROR_INVALID_ARGUMENT, "is not finite");
  CHECK_FAILS(hemilight_sample_irradiance(s, p, nan_n, 8, &r), HEMILIGHT_ERROR_INVALID_ARGUMENT, "normal (0.000000, nan");
  CHECK_FAILS(hemilight_sample_irradiance(s, NULL, up, 8, &r), HEMILIGHT_ERROR_INVALID_ARGUMENT, "position is NULL");
  CHECK_FAILS(hemilight_sample_irradiance(s, p, NULL, 8, &r), HEMILIGHT_ERROR_INVALID_ARGUMENT, "normal is NULL");
  CHECK(memcmp(&r, &r_untouched, sizeof r) == 0);

  /* hemilight_sampler_irradiance: the same points, and an overflowing result. */
  CHECK(hemilight_sampler_create(s, 8, &sm) == HEMILIGHT_OK && hemilight_sampler_create(lit, 8, &sm_lit) == HEMILIGHT_OK);
  CHECK_FAILS(hemilight_sampler_irradiance(sm, far_p, up, &r), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_sampler_irradiance: position");
  CHECK(strstr(hemilight_last_error(), "is beyond 1e18") != NULL);
  CHECK_FAILS(hemilight_sampler_irradiance(sm, p, nan_n, &r), HEMILIGHT_ERROR_INVALID_ARGUMENT, "is not finite");
  CHECK_FAILS(hemilight_sampler_irradiance(sm_lit, p, up, &r), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_sampler_irradiance: the irradiance overflows float");
  CHECK(memcmp(&r, &r_untouched, sizeof r) == 0);
  hemilight_sampler_release(sm);
  hemilight_sampler_release(sm_lit);

  /* hemilight_sample_irradiance_batch: a count over 2^31 - 1 (refused before the arrays are read),
   * a point beyond 1e18, an overflowing point, each named. */
  memset(two, 0x5a, sizeof two);
  CHECK_FAILS(hemilight_sample_irradiance_batch(s, two_p, two_n, (size_t)1 << 31, 8, 1, two), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "count 2147483648 is over the limit of 2147483647");
  two_p[4] = 0x1p61f;
  CHECK_FAILS(hemilight_sample_irradiance_batch(s, two_p, two_n, 2, 8, 1, two), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "point 1: position (0.000000, 2305843009213693952.000000, 0.000000) is beyond 1e18");
  two_p[4] = 0.0f;
  CHECK_FAILS(hemilight_sample_irradiance_batch(lit, two_p, two_n, 2, 8, 1, two), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "point 0: the irradiance overflows float");
  CHECK(memcmp(&two[0], &r_untouched, sizeof r) == 0 && memcmp(&two[1], &r_untouched, sizeof r) == 0);

  /* hemilight_sample_probes: the count, a position beyond 1e18 (1e18 itself is a probe). */
  CHECK_FAILS(hemilight_sample_probes(s, two_p, (size_t)1 << 31, 8, 1, sh), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "count 2147483648 is over the limit of 2147483647");
  CHECK_FAILS(hemilight_sample_probes(s, far_p, 1, 8, 1, sh), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_sample_probes: point 0: position (0.000000, 2305843009213693952.000000, 0.000000) is not finite or beyond 1e18");
  CHECK_FAILS(hemilight_sample_probes_with_backfaces(s, inf_p, 1, 8, 1, sh, e), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_sample_probes_with_backfaces: point 0: position (0.000000, inf");
  CHECK(memcmp(sh, sh_untouched, sizeof sh) == 0 && e[0] == -7.0f);
  CHECK(hemilight_sample_probes(s, edge_p, 1, 8, 1, sh) == HEMILIGHT_OK && fabs(sh[0] / (2.0 * sqrt(pi)) - 1.0) < 1e-5);

  /* hemilight_sh9_irradiance: NULL outputs, non-finite coefficients or normal, an overflow (a
   * band-0 coefficient of 3e38 times A_0 Y_0 = 0.886 is finite; with the band-1 terms it is not). */
  for (i = 0; i < 27; ++i) coeffs[i] = 0.0f;
  coeffs[0] = 1.0f;
  CHECK_FAILS(hemilight_sh9_irradiance(coeffs, NULL, e), HEMILIGHT_ERROR_INVALID_ARGUMENT, "normal is NULL");
  CHECK_FAILS(hemilight_sh9_irradiance(coeffs, up, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "irradiance is NULL");
  coeffs[13] = NAN;
  CHECK_FAILS(hemilight_sh9_irradiance(coeffs, up, e), HEMILIGHT_ERROR_INVALID_ARGUMENT, "sh9_rgb holds a NaN or an infinity");
  coeffs[13] = 0.0f;
  CHECK_FAILS(hemilight_sh9_irradiance(coeffs, nan_n, e), HEMILIGHT_ERROR_INVALID_ARGUMENT, "normal is not finite");
  for (i = 0; i < 27; i += 3) coeffs[i] = 3e38f;
  CHECK_FAILS(hemilight_sh9_irradiance(coeffs, big_n, e), HEMILIGHT_ERROR_INVALID_ARGUMENT, "overflows float");
  CHECK(e[0] == -7.0f);
  hemilight_scene_release(lit);
  hemilight_scene_release(s);
}

/* ---- the irradiance cache ----------------------------------------------------------------- */

static void test_cache(void) {
  const float sky[3] = {1, 1, 1};
  const float p[6] = {0, 0, 0, 0.5f, 0, 0}, n[6] = {0, 0, 1, 0, 0, 1};
  hemilight_scene *s = NULL, *lit = overflowing_light();
  hemilight_cache_options o;
  hemilight_cache_stats st;
  float out[6] = {-7, -7, -7, -7, -7, -7};
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &s) == HEMILIGHT_OK);
  hemilight_cache_options_init(&o);
  o.resolution = 8, o.thread_count = 1;
  hemilight_cache_stats_init(&st);
  CHECK_FAILS(hemilight_cache_irradiance(s, NULL, n, 2, &o, out, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "positions is NULL");
  CHECK_FAILS(hemilight_cache_irradiance(s, p, NULL, 2, &o, out, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "normals is NULL");
  CHECK_FAILS(hemilight_cache_irradiance(s, p, n, 2, &o, NULL, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "irradiance_rgb is NULL");
  st.struct_size = 3;
  CHECK_FAILS(hemilight_cache_irradiance(s, p, n, 2, &o, out, &st), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_cache_irradiance: stats->struct_size is 3");
  hemilight_cache_stats_init(&st);
  o.thread_count = -1;
  CHECK_FAILS(hemilight_cache_irradiance(s, p, n, 2, &o, out, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "options->thread_count is -1; it must be >= 0");
  o.thread_count = 1;
  o.max_radius = -1.0f;
  CHECK_FAILS(hemilight_cache_irradiance(s, p, n, 2, &o, out, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "max_radius is -1.000000; it must be finite and >= 0");
  o.max_radius = INFINITY;
  CHECK_FAILS(hemilight_cache_irradiance(s, p, n, 2, &o, out, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "max_radius is inf");
  o.min_radius = 2.0f, o.max_radius = 1.0f;
  CHECK_FAILS(hemilight_cache_irradiance(s, p, n, 2, &o, out, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "min_radius 2.000000 is larger than max_radius 1.000000");
  o.min_radius = 0.0f, o.max_radius = 0.0f;
  o.second_opinion = INFINITY;
  CHECK_FAILS(hemilight_cache_irradiance(s, p, n, 2, &o, out, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "second_opinion is inf; it must be finite and >= 0");
  o.second_opinion = 0.25f;
  /* An overflowing result (the light's I / d^2 at the first point). */
  CHECK_FAILS(hemilight_cache_irradiance(lit, p, n, 2, &o, out, &st), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_cache_irradiance: the irradiance at point 0 overflows float");
  CHECK(out[0] == -7.0f && out[5] == -7.0f && st.hemicubes == 0);
  /* Within every limit: a uniform sky gives pi L. */
  CHECK(hemilight_cache_irradiance(s, p, n, 2, &o, out, &st) == HEMILIGHT_OK && fabs(out[5] / pi - 1.0) < 1e-5);
  hemilight_scene_release(lit);
  hemilight_scene_release(s);
}

/* ---- bakes -------------------------------------------------------------------------------- */

/* A floor quad [0, q] x [0, q] (y = 0, facing +y) over the whole lightmap. */
static void floor_mesh(hemilight_bake_mesh* m, float* pos, float q) {
  static const float uv[8] = {0, 0, 0, 1, 1, 1, 1, 0};
  static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
  const float corner[12] = {0, 0, 0, 0, 0, -1, 1, 0, -1, 1, 0, 0};
  int i;
  for (i = 0; i < 12; ++i) pos[i] = q * corner[i];
  memset(m, 0, sizeof *m);
  m->positions = pos, m->lightmap_uvs = uv, m->vertex_count = 4, m->indices = idx, m->triangle_count = 2;
}

/* 51 point lights of 1e30 W/sr at x = 0.375, z = -0.125 (the centre of texel (1, 0) of a 4 x 4
 * lightmap on floor_mesh(1)) and y from -0.0120 to -0.0130: the floor faces -y and the baker places
 * that texel's sample 0.05 texel (0.0125) along the normal, so one light is within 1e-5 of it. */
static void overflow_ladder(hemilight_light* lights) {
  int k;
  for (k = 0; k < 51; ++k) {
    hemilight_light_init(&lights[k], HEMILIGHT_LIGHT_POINT);
    lights[k].position[0] = 0.375f, lights[k].position[1] = -0.0120f - 2e-5f * (float)k, lights[k].position[2] = -0.125f;
    lights[k].color[0] = lights[k].color[1] = lights[k].color[2] = 1e30f;
    lights[k].casts_shadows = 0;
  }
}

static void test_bakes(void) {
  static const float small_uv[8] = {0.1f, 0.1f, 0.1f, 0.15f, 0.15f, 0.15f, 0.15f, 0.1f};
  float pos[12], nrm[12], env[72], out[48], untouched[48];
  hemilight_bake_mesh m, huge;
  hemilight_bake_options o, o_ok;
  hemilight_bake_stats st;
  hemilight_light lights[51];
  int i;
  floor_mesh(&m, pos, 1.0f);
  hemilight_bake_options_init(&o_ok);
  o_ok.width = o_ok.height = 4, o_ok.resolution = 8, o_ok.thread_count = 1;
  o_ok.sky_radiance[0] = o_ok.sky_radiance[1] = o_ok.sky_radiance[2] = 1.0f;
  o = o_ok;
  memset(untouched, 0x5a, sizeof untouched);
  memcpy(out, untouched, sizeof out);
  hemilight_bake_stats_init(&st);

  /* Struct sizes (options, stats), then the option fields the other tests leave out. */
  o.struct_size = 0;
  CHECK_FAILS(hemilight_bake_lightmap(&m, 1, &o, out, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_lightmap: options->struct_size is 0");
  o = o_ok;
  st.struct_size = 3;
  CHECK_FAILS(hemilight_bake_lightmap(&m, 1, &o, out, 48, NULL, 0, &st), HEMILIGHT_ERROR_INVALID_ARGUMENT, "stats->struct_size is 3");
  hemilight_bake_stats_init(&st);
  o.min_coverage = 1.5f;
  CHECK_FAILS(hemilight_bake_lightmap(&m, 1, &o, out, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "options->min_coverage 1.500000 is not in [0, 1]");
  o = o_ok;
  o.thread_count = -1;
  CHECK_FAILS(hemilight_bake_lightmap(&m, 1, &o, out, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "options->thread_count -1 must be >= 0");
  o = o_ok;
  o.indirect_only = 2;
  CHECK_FAILS(hemilight_bake_lightmap(&m, 1, &o, out, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "options->indirect_only is 2; it must be 0 or 1");
  o = o_ok;
  o.sky_radiance[1] = 2e30f;
  CHECK_FAILS(hemilight_bake_lightmap(&m, 1, &o, out, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "options->sky_radiance[1]");
  o = o_ok;
  for (i = 0; i < 72; ++i) env[i] = 1.0f;
  env[7] = 2e30f;
  o.environment_rgb = env, o.environment_size = 2;
  CHECK_FAILS(hemilight_bake_lightmap(&m, 1, &o, out, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "options->environment_rgb[7]");
  CHECK(strstr(hemilight_last_error(), "at most 1e30") != NULL);
  o = o_ok;

  /* The meshes: more than 2^31 - 1 vertices (OUT_OF_MEMORY, before any array is read), NULL
   * indices, a coordinate beyond 1e18, a NaN normal, an emission above 1e30. */
  huge = m;
  huge.vertex_count = (size_t)1 << 31;
  CHECK_FAILS(hemilight_bake_lightmap(&huge, 1, &o, out, 48, NULL, 0, NULL), HEMILIGHT_ERROR_OUT_OF_MEMORY,
              "hemilight_bake_lightmap: more than 2^31 - 1 vertices or triangles");
  huge = m;
  huge.indices = NULL;
  CHECK_FAILS(hemilight_bake_lightmap(&huge, 1, &o, out, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "meshes[0].indices is NULL with triangle_count 2");
  pos[5] = -0x1p61f;
  CHECK_FAILS(hemilight_bake_lightmap(&m, 1, &o, out, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "meshes[0].positions[5] (vertex 1) = -2305843009213693952.000000");
  CHECK(strstr(hemilight_last_error(), "at most 1e18 in magnitude") != NULL);
  pos[5] = -1.0f;
  for (i = 0; i < 12; ++i) nrm[i] = i % 3 == 1 ? 1.0f : 0.0f;
  nrm[4] = NAN;
  m.normals = nrm;
  CHECK_FAILS(hemilight_bake_lightmap(&m, 1, &o, out, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "meshes[0].normals[4] (vertex 1) = nan; it must be finite");
  m.normals = NULL;
  m.material.emission[0] = 2e30f;
  CHECK_FAILS(hemilight_bake_lightmap(&m, 1, &o, out, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "meshes[0].material.emission[0]");
  m.material.emission[0] = 0.0f;

  /* No texel covered: a triangle over 5% of one texel, with min_coverage 0.5. */
  huge = m;
  huge.lightmap_uvs = small_uv;
  o.min_coverage = 0.5f;
  CHECK_FAILS(hemilight_bake_lightmap(&huge, 1, &o, out, 48, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_lightmap: no texel is covered by a triangle");
  o = o_ok;

  /* An overflowing result: point lights of 1e30 W/sr on the normal of texel (1, 0), one of them
   * within 1e-5 of its sample (I / d^2 > 1e40). */
  overflow_ladder(lights);
  o.lights = lights, o.light_count = 51;
  CHECK_FAILS(hemilight_bake_lightmap(&m, 1, &o, out, 48, NULL, 0, &st), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_lightmap: the irradiance overflows float");
  CHECK(memcmp(out, untouched, sizeof out) == 0 && st.hemicubes == 0);
  /* Within every limit: the floor under a uniform sky gets pi L. */
  CHECK(hemilight_bake_lightmap(&m, 1, &o_ok, out, 48, NULL, 0, NULL) == HEMILIGHT_OK && fabs(out[0] / pi - 1.0) < 1e-5);
}

/* hemilight_bake_scene: the description's arrays, a page's buffers and images, an atlas over 2^28
 * texels, an overflowing result. */
static void test_bake_scene(void) {
  float pos[12], out[48], untouched[48], emission[48];
  hemilight_bake_mesh m;
  hemilight_bake_options o;
  hemilight_bake_scene_desc sd;
  hemilight_bake_placement placement = {0, {1, 1}, {0, 0}};
  hemilight_bake_page page, *pages;
  hemilight_light lights[51];
  const size_t many = 32761; /* pages of 1 x 8192, 2 guard rows between: 1 x 268,443,632 > 2^28 texels */
  size_t i;
  floor_mesh(&m, pos, 1.0f);
  hemilight_bake_options_init(&o);
  o.resolution = 8, o.thread_count = 1;
  memset(untouched, 0x5a, sizeof untouched);
  memcpy(out, untouched, sizeof out);
  memset(&page, 0, sizeof page);
  page.width = page.height = 4, page.irradiance_rgb = out, page.irradiance_capacity = 48;
  hemilight_bake_scene_desc_init(&sd);
  sd.meshes = &m, sd.mesh_count = 1, sd.placements = &placement, sd.pages = &page, sd.page_count = 1;
  CHECK(hemilight_bake_scene(&sd, &o, NULL) == HEMILIGHT_OK);
  memcpy(out, untouched, sizeof out);

  sd.meshes = NULL;
  CHECK_FAILS(hemilight_bake_scene(&sd, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_bake_scene: scene->meshes is NULL");
  sd.meshes = &m, sd.pages = NULL;
  CHECK_FAILS(hemilight_bake_scene(&sd, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_bake_scene: scene->pages is NULL");
  sd.pages = &page, page.irradiance_rgb = NULL;
  CHECK_FAILS(hemilight_bake_scene(&sd, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "scene->pages[0].irradiance_rgb is NULL");
  page.irradiance_rgb = out;
  for (i = 0; i < 48; ++i) emission[i] = 0.0f;
  emission[6] = 2e30f;
  page.emission_rgb = emission;
  CHECK_FAILS(hemilight_bake_scene(&sd, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "scene->pages[0].emission_rgb[6] (texel 2)");
  CHECK(strstr(hemilight_last_error(), "at most 1e30") != NULL);
  page.emission_rgb = NULL;

  /* Pages of 1 x 8192 (one irradiance buffer for all: nothing is written on failure) whose atlas
   * passes 2^28 texels (32,760 pages would be 2^28 - 18: a bake of that size is too long for a
   * test). */
  pages = (hemilight_bake_page*)calloc(many, sizeof *pages);
  CHECK(pages != NULL);
  if (pages) {
    float* column = (float*)calloc(3 * 8192, sizeof(float));
    CHECK(column != NULL);
    for (i = 0; column && i < many; ++i) {
      pages[i].width = 1, pages[i].height = 8192;
      pages[i].irradiance_rgb = column, pages[i].irradiance_capacity = 3 * 8192;
    }
    sd.pages = pages, sd.page_count = many;
    if (column)
      CHECK_FAILS(hemilight_bake_scene(&sd, &o, NULL), HEMILIGHT_ERROR_OUT_OF_MEMORY,
                  "hemilight_bake_scene: the pages' atlas would be 1 x 268443632 texels");
    sd.pages = &page, sd.page_count = 1;
    free(column);
    free(pages);
  }

  /* An overflowing result, as in test_bakes (one page at scale 1, offset 0: the same samples). */
  overflow_ladder(lights);
  o.lights = lights, o.light_count = 51;
  CHECK_FAILS(hemilight_bake_scene(&sd, &o, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: the irradiance overflows float");
  CHECK(memcmp(out, untouched, sizeof out) == 0);
}

/* ---- cube maps ---------------------------------------------------------------------------- */

static void test_cubemaps(void) {
  static float map[72], out[72];
  const float dir[3] = {1, 0.2f, 0.1f};
  float rgb[3] = {-7, -7, -7};
  int i;
  for (i = 0; i < 72; ++i) map[i] = 1.0f;
  /* A sample that is not finite: the chain holds an infinity where the direction reads it. */
  map[0] = map[1] = map[2] = INFINITY; /* texel (0, 0) of +X */
  CHECK_FAILS(hemilight_cubemap_sample(map, 2, 1, dir, 0.0f, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 0, rgb),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_cubemap_sample: the sample is not finite");
  CHECK(rgb[0] == -7.0f);
  map[0] = map[1] = map[2] = 1.0f;
  /* A map of 1 samples to 1 (bilinear weights sum to 1, to float rounding). */
  CHECK(hemilight_cubemap_sample(map, 2, 1, dir, 0.0f, HEMILIGHT_CUBE_SAMPLING_SEAMLESS, 0, rgb) == HEMILIGHT_OK &&
        fabs(rgb[0] - 1.0) < 1e-6);
  /* Input values: 1e30 is filtered (irradiance pi 1e30 within float), 2e30 is refused. */
  map[5] = 1e30f;
  CHECK(hemilight_cubemap_filter_irradiance(map, 2, HEMILIGHT_EDGE_FIXUP_NONE, 1, 1, out) == HEMILIGHT_OK && isfinite(out[0]));
  map[5] = 2e30f;
  CHECK_FAILS(hemilight_cubemap_filter_irradiance(map, 2, HEMILIGHT_EDGE_FIXUP_NONE, 1, 1, out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "input value 5 = ");
  CHECK(strstr(hemilight_last_error(), "is not finite or beyond +-1e30") != NULL);
  CHECK_FAILS(hemilight_cubemap_filter_cosine_power(map, 2, 4.0f, HEMILIGHT_EDGE_FIXUP_NONE, 1, out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_cubemap_filter_cosine_power: input value 5");
}

int main(int argc, char** argv) {
  test_exr(argc > 1 ? argv[1] : ".");
  test_scenes();
  test_lights();
  test_points();
  test_cache();
  test_bakes();
  test_bake_scene();
  test_cubemaps();
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
