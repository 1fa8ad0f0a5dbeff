/* C99 test of the C ABI: every entry point, with good, NULL and out-of-range arguments.
 * Usage: hemilight_capi_test <scratch directory>
 * Prints one line per check that fails and a closing "N passed, N failed" line. */
#include "hemilight.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capi_check.h"

static const double pi = 3.14159265358979323846;

static void test_version(void) {
  int major = -1, minor = -1, patch = -1;
  hemilight_version(&major, &minor, &patch);
  CHECK(major == HEMILIGHT_VERSION_MAJOR && minor == HEMILIGHT_VERSION_MINOR && patch == HEMILIGHT_VERSION_PATCH);
  hemilight_version(NULL, NULL, NULL); /* must not crash */
  CHECK(hemilight_last_error() != NULL);
}

static void test_hemicube(void) {
  size_t count = 0, i;
  double sum_sa = 0, sum_psa = 0;
  float dir[3], sa, psa;
  CHECK(hemilight_hemicube_texel_count(64, &count) == HEMILIGHT_OK && count == 3 * 64 * 64);
  for (i = 0; i < count; ++i) {
    if (hemilight_hemicube_texel_info(64, i, dir, &sa, &psa) != HEMILIGHT_OK) {
      CHECK(0);
      return;
    }
    sum_sa += sa;
    sum_psa += psa;
    if (dir[2] <= 0.0f || fabs(sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]) - 1.0) > 1e-6) {
      CHECK(0);
      return;
    }
  }
  CHECK(fabs(sum_sa / (2 * pi) - 1) < 1e-6);
  CHECK(fabs(sum_psa / pi - 1) < 1e-6);
  /* optional outputs may be NULL */
  CHECK(hemilight_hemicube_texel_info(2, 11, NULL, NULL, NULL) == HEMILIGHT_OK);

  count = 12345;
  CHECK_FAILS(hemilight_hemicube_texel_count(63, &count), HEMILIGHT_ERROR_INVALID_ARGUMENT, "resolution 63");
  CHECK(count == 12345); /* untouched on failure */
  CHECK_FAILS(hemilight_hemicube_texel_count(0, &count), HEMILIGHT_ERROR_INVALID_ARGUMENT, "resolution 0");
  CHECK_FAILS(hemilight_hemicube_texel_count(-4, &count), HEMILIGHT_ERROR_INVALID_ARGUMENT, "resolution -4");
  CHECK_FAILS(hemilight_hemicube_texel_count(4098, &count), HEMILIGHT_ERROR_INVALID_ARGUMENT, "resolution 4098");
  CHECK_FAILS(hemilight_hemicube_texel_count(64, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "count is NULL");
  dir[0] = 99.0f;
  CHECK_FAILS(hemilight_hemicube_texel_info(4, 48, dir, &sa, &psa), HEMILIGHT_ERROR_INVALID_ARGUMENT, "texel 48 is out of range");
  CHECK(dir[0] == 99.0f);
  CHECK_FAILS(hemilight_hemicube_texel_info(4, (size_t)-1, dir, &sa, &psa), HEMILIGHT_ERROR_INVALID_ARGUMENT, "out of range");
  CHECK_FAILS(hemilight_hemicube_texel_info(5, 0, dir, &sa, &psa), HEMILIGHT_ERROR_INVALID_ARGUMENT, "resolution 5");
}

static void test_exr(const char* dir) {
  char path[1024], cube_path[1024], missing[1024];
  float rgb[4 * 3 * 3], back[4 * 3 * 3], small[3];
  float* faces;
  float* faces_back;
  int w = 0, h = 0, is_cube = -1, size = 0, k;
  snprintf(path, sizeof path, "%s/capi_image.exr", dir);
  snprintf(cube_path, sizeof cube_path, "%s/capi_cube.exr", dir);
  snprintf(missing, sizeof missing, "%s/capi_missing.exr", dir);
  for (k = 0; k < 36; ++k) rgb[k] = (float)k * 0.5f;

  CHECK(hemilight_exr_save_rgb(path, rgb, 4, 3, 0) == HEMILIGHT_OK);
  CHECK(hemilight_exr_info(path, &w, &h, &is_cube) == HEMILIGHT_OK);
  CHECK(w == 4 && h == 3 && is_cube == 0);
  CHECK(hemilight_exr_load_rgb(path, back, 36, &w, &h) == HEMILIGHT_OK);
  CHECK(memcmp(rgb, back, sizeof rgb) == 0);
  CHECK(hemilight_exr_save_rgb(path, rgb, 4, 3, 1) == HEMILIGHT_OK); /* half: these values are exact in half */
  CHECK(hemilight_exr_load_rgb(path, back, 36, NULL, NULL) == HEMILIGHT_OK);
  CHECK(memcmp(rgb, back, sizeof rgb) == 0);

  small[0] = -7.0f;
  CHECK_FAILS(hemilight_exr_load_rgb(path, small, 3, &w, &h), HEMILIGHT_ERROR_INVALID_ARGUMENT, "too small");
  CHECK(small[0] == -7.0f);
  CHECK_FAILS(hemilight_exr_load_rgb(missing, back, 36, &w, &h), HEMILIGHT_ERROR_IO, "no such file");
  CHECK_FAILS(hemilight_exr_info(missing, &w, &h, NULL), HEMILIGHT_ERROR_IO, "capi_missing.exr");
  CHECK_FAILS(hemilight_exr_info(NULL, &w, &h, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "path is NULL");
  CHECK_FAILS(hemilight_exr_load_rgb(path, NULL, 36, &w, &h), HEMILIGHT_ERROR_INVALID_ARGUMENT, "rgb is NULL");
  CHECK_FAILS(hemilight_exr_save_rgb(path, rgb, 0, 3, 0), HEMILIGHT_ERROR_INVALID_ARGUMENT, "width is 0");
  CHECK_FAILS(hemilight_exr_save_rgb(path, rgb, 4, -3, 0), HEMILIGHT_ERROR_INVALID_ARGUMENT, "height is -3");
  CHECK_FAILS(hemilight_exr_save_rgb(path, NULL, 4, 3, 0), HEMILIGHT_ERROR_INVALID_ARGUMENT, "rgb is NULL");
  CHECK_FAILS(hemilight_exr_save_rgb(NULL, rgb, 4, 3, 0), HEMILIGHT_ERROR_INVALID_ARGUMENT, "path is NULL");
  CHECK_FAILS(hemilight_exr_save_rgb(path, rgb, 1 << 20, 1 << 20, 0), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_exr_save_rgb: width x height = 1048576 x 1048576 is over the limit of 2^28 pixels");

  /* cube maps */
  faces = (float*)malloc(sizeof(float) * 6 * 8 * 8 * 3);
  faces_back = (float*)malloc(sizeof(float) * 6 * 8 * 8 * 3);
  if (!faces || !faces_back) {
    CHECK(0);
    free(faces);
    free(faces_back);
    return;
  }
  for (k = 0; k < 6 * 8 * 8 * 3; ++k) faces[k] = (float)(k % 97);
  CHECK(hemilight_exr_save_cubemap_rgb(cube_path, faces, 8, 0) == HEMILIGHT_OK);
  CHECK(hemilight_exr_info(cube_path, &w, &h, &is_cube) == HEMILIGHT_OK);
  CHECK(w == 8 && h == 48 && is_cube == 1);
  CHECK(hemilight_exr_load_cubemap_rgb(cube_path, faces_back, 6 * 8 * 8 * 3, &size) == HEMILIGHT_OK);
  CHECK(size == 8);
  CHECK(memcmp(faces, faces_back, sizeof(float) * 6 * 8 * 8 * 3) == 0);
  CHECK_FAILS(hemilight_exr_load_cubemap_rgb(path, faces_back, 6 * 8 * 8 * 3, &size), HEMILIGHT_ERROR_UNSUPPORTED,
              "must be w x 6w");
  CHECK_FAILS(hemilight_exr_load_cubemap_rgb(cube_path, faces_back, 10, &size), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "too small");
  CHECK_FAILS(hemilight_exr_load_cubemap_rgb(cube_path, NULL, 10, &size), HEMILIGHT_ERROR_INVALID_ARGUMENT, "faces is NULL");
  CHECK_FAILS(hemilight_exr_save_cubemap_rgb(cube_path, faces, 0, 0), HEMILIGHT_ERROR_INVALID_ARGUMENT, "size is 0");
  free(faces);
  free(faces_back);
}

static void test_scene(void) {
  /* A box's floor (two triangles) and one emitting triangle. */
  const float positions[] = {0, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 1, 0, 1, 0, 1, 1, 0, 0, 1, 1};
  const uint32_t indices[] = {0, 2, 1, 0, 3, 2, 4, 5, 6};
  const float radiance[] = {0, 0, 0, 0, 0, 0, 1, 2, 3};
  const uint32_t bad_indices[] = {0, 2, 1, 0, 3, 2, 4, 5, 900};
  const float bad_radiance[] = {0, 0, 0, 0, -1, 0, 1, 2, 3};
  const float sky[3] = {0.5f, 0.5f, 0.5f};
  const float bad_sky[3] = {0.5f, -1.0f, 0.5f};
  float nan_positions[sizeof positions / sizeof positions[0]];
  hemilight_scene* scene = NULL;
  hemilight_scene* untouched = (hemilight_scene*)&scene; /* any non-NULL sentinel */
  hemilight_scene* out = untouched;
  size_t k;

  CHECK(hemilight_scene_create(positions, 7, indices, 3, radiance, sky, &scene) == HEMILIGHT_OK);
  CHECK(scene != NULL);
  hemilight_scene_release(scene);
  hemilight_scene_release(NULL); /* must not crash */

  /* An empty scene is valid, with NULL arrays. */
  scene = NULL;
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &scene) == HEMILIGHT_OK);
  CHECK(scene != NULL);
  hemilight_scene_release(scene);

  /* Zero-area triangles are accepted. */
  {
    const uint32_t degenerate[] = {0, 0, 1};
    scene = NULL;
    CHECK(hemilight_scene_create(positions, 7, degenerate, 1, radiance, sky, &scene) == HEMILIGHT_OK);
    hemilight_scene_release(scene);
  }

  /* Failures name the argument and write nothing. */
  for (k = 0; k < sizeof positions / sizeof positions[0]; ++k) nan_positions[k] = positions[k];
  nan_positions[4] = (float)NAN;
  CHECK_FAILS(hemilight_scene_create(positions, 7, indices, 3, radiance, sky, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "out is NULL");
  CHECK_FAILS(hemilight_scene_create(NULL, 7, indices, 3, radiance, sky, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "positions is NULL");
  CHECK_FAILS(hemilight_scene_create(positions, 7, NULL, 3, radiance, sky, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "indices is NULL");
  CHECK_FAILS(hemilight_scene_create(positions, 7, indices, 3, NULL, sky, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "triangle_radiance is NULL");
  CHECK_FAILS(hemilight_scene_create(positions, 7, indices, 3, radiance, NULL, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "sky_radiance is NULL");
  CHECK_FAILS(hemilight_scene_create(nan_positions, 7, indices, 3, radiance, sky, &out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_scene_create: positions[4] (vertex 1) = nan");
  CHECK_FAILS(hemilight_scene_create(positions, 7, bad_indices, 3, radiance, sky, &out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "indices[8] = 900 is out of range: 7 vertices");
  CHECK_FAILS(hemilight_scene_create(positions, 7, indices, 3, bad_radiance, sky, &out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "triangle_radiance[4]");
  CHECK_FAILS(hemilight_scene_create(positions, 7, indices, 3, radiance, bad_sky, &out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "sky_radiance");
  CHECK_FAILS(hemilight_scene_create(positions, (size_t)-1, indices, 3, radiance, sky, &out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "vertex_count");
  CHECK_FAILS(hemilight_scene_create(positions, 7, indices, (size_t)-1 / 2, radiance, sky, &out),
              HEMILIGHT_ERROR_INVALID_ARGUMENT, "triangle_count");
  CHECK(out == untouched);
}

int main(int argc, char** argv) {
  const char* dir = argc > 1 ? argv[1] : ".";
  test_version();
  test_scene();
  test_hemicube();
  test_exr(dir);
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
