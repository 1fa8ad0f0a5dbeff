/* C99 test of the C ABI's entries for many points: the reusable samplers (hemilight_sampler_create /
 * _irradiance / _release), hemilight_sample_irradiance_batch, and the light probes
 * (hemilight_sample_probes, _with_backfaces, hemilight_sh9_irradiance). References:
 * hemilight_sample_irradiance for the same point (bitwise: the entries promise the same result),
 * and closed forms (a uniform sky gives pi L and c_0 = 2 sqrt(pi) L; Lambert's formula for a quad
 * emitter; a point light's I / d^2 Y_k towards it), written here in C.
 * Prints failing checks and a closing "N passed, N failed" line. */
#include "capi_check.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const double pi = 3.14159265358979323846;

/* A closed box [-1, 1]^3 seen from inside (12 triangles, grey walls of radiance 0.2), a 0.6 x 0.6
 * emitter of radiance (4, 3, 2) just under its ceiling facing down, and a black occluder cube
 * [-0.3, 0.3] x [-0.3, 0.3] x [-1, -0.4] standing on its floor: 32 triangles, like the Cornell box. */
static hemilight_scene* make_room(void) {
  static const float box[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                  {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  /* Inward-facing quads (counter-clockwise seen from inside). */
  static const int room_quads[6][4] = {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1}, {1, 5, 6, 2}, {2, 6, 7, 3}, {3, 7, 4, 0}};
  static const int cube_quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  float pos[(8 + 4 + 8) * 3];
  uint32_t idx[32 * 3];
  float rad[32 * 3];
  int v = 0, t = 0, q, k, c;
  hemilight_scene* scene = NULL;
  const float sky[3] = {0, 0, 0};
  for (k = 0; k < 8; ++k, ++v)
    for (c = 0; c < 3; ++c) pos[3 * v + c] = box[k][c];
  for (q = 0; q < 6; ++q) {
    const int tri[2][3] = {{room_quads[q][0], room_quads[q][1], room_quads[q][2]}, {room_quads[q][0], room_quads[q][2], room_quads[q][3]}};
    for (k = 0; k < 2; ++k, ++t)
      for (c = 0; c < 3; ++c) {
        idx[3 * t + c] = (uint32_t)tri[k][c];
        rad[3 * t + c] = 0.2f;
      }
  }
  /* The emitter at z = 0.99, facing down: (x, y) corners counter-clockwise seen from below. */
  {
    const float e[4][3] = {{-0.3f, -0.3f, 0.99f}, {-0.3f, 0.3f, 0.99f}, {0.3f, 0.3f, 0.99f}, {0.3f, -0.3f, 0.99f}};
    const float L[3] = {4, 3, 2};
    const int base = v;
    for (k = 0; k < 4; ++k, ++v)
      for (c = 0; c < 3; ++c) pos[3 * v + c] = e[k][c];
    for (k = 0; k < 2; ++k, ++t)
      for (c = 0; c < 3; ++c) {
        const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
        idx[3 * t + c] = (uint32_t)(base + tri[k][c]);
        rad[3 * t + c] = L[c];
      }
  }
  /* The occluder cube, outward-facing. */
  {
    const int base = v;
    for (k = 0; k < 8; ++k, ++v) {
      pos[3 * v + 0] = box[k][0] * 0.3f;
      pos[3 * v + 1] = box[k][1] * 0.3f;
      pos[3 * v + 2] = box[k][2] < 0 ? -1.0f : -0.4f;
    }
    for (q = 0; q < 6; ++q) {
      const int tri[2][3] = {{cube_quads[q][0], cube_quads[q][1], cube_quads[q][2]}, {cube_quads[q][0], cube_quads[q][2], cube_quads[q][3]}};
      for (k = 0; k < 2; ++k, ++t)
        for (c = 0; c < 3; ++c) {
          idx[3 * t + c] = (uint32_t)(base + tri[k][c]);
          rad[3 * t + c] = 0.0f;
        }
    }
  }
  if (hemilight_scene_create(pos, (size_t)v, idx, (size_t)t, rad, sky, &scene) != HEMILIGHT_OK) {
    printf("make_room: %s\n", hemilight_last_error());
    return NULL;
  }
  return scene;
}

/* count points on the floor and walls of the room (deterministic), normals not unit length. */
static void room_points(float* pos, float* nrm, int count) {
  int i;
  unsigned s = 12345u;
  for (i = 0; i < count; ++i) {
    const int wall = i % 3;
    float u, w;
    s = s * 1664525u + 1013904223u;
    u = (float)((s >> 8) & 0xffff) / 65536.0f * 1.8f - 0.9f;
    s = s * 1664525u + 1013904223u;
    w = (float)((s >> 8) & 0xffff) / 65536.0f * 1.8f - 0.9f;
    if (wall == 0) { /* floor, outside the occluder's footprint where u, w fall in it: moved aside */
      if (fabsf(u) < 0.35f && fabsf(w) < 0.35f) u = u < 0 ? -0.5f : 0.5f;
      pos[3 * i] = u, pos[3 * i + 1] = w, pos[3 * i + 2] = -0.999f;
      nrm[3 * i] = 0, nrm[3 * i + 1] = 0, nrm[3 * i + 2] = 3.0f;
    } else if (wall == 1) { /* the wall x = -1 */
      pos[3 * i] = -0.999f, pos[3 * i + 1] = u, pos[3 * i + 2] = w;
      nrm[3 * i] = 0.5f, nrm[3 * i + 1] = 0, nrm[3 * i + 2] = 0;
    } else { /* tilted normals in the middle of the room */
      pos[3 * i] = 0.5f * u, pos[3 * i + 1] = 0.5f * w, pos[3 * i + 2] = 0.2f;
      nrm[3 * i] = u, nrm[3 * i + 1] = w, nrm[3 * i + 2] = 1.0f;
    }
  }
}

static void test_sampler_matches(void) {
  enum { count = 48 };
  float pos[3 * count], nrm[3 * count];
  hemilight_irradiance ref[count], r;
  hemilight_scene* room = make_room();
  hemilight_scene* room_for_tiny = NULL;
  hemilight_sampler* s = NULL;
  hemilight_sampler* s16 = NULL;
  int i, same = 1;
  CHECK(room != NULL);
  if (!room) return;
  room_points(pos, nrm, count);
  for (i = 0; i < count; ++i) CHECK(hemilight_sample_irradiance(room, pos + 3 * i, nrm + 3 * i, 64, &ref[i]) == HEMILIGHT_OK);
  /* The per-thread cached context of hemilight_sample_irradiance: the same again, also after a
   * call at another N and with another scene in between. */
  {
    hemilight_scene* empty = NULL;
    const float sky[3] = {1, 1, 1};
    CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &empty) == HEMILIGHT_OK);
    CHECK(hemilight_sample_irradiance(empty, pos, nrm, 16, &r) == HEMILIGHT_OK);
    hemilight_scene_release(empty);
    for (i = 0; i < count; ++i) {
      CHECK(hemilight_sample_irradiance(room, pos + 3 * i, nrm + 3 * i, 64, &r) == HEMILIGHT_OK);
      same = same && memcmp(&r, &ref[i], sizeof r) == 0;
    }
    CHECK(same);
  }
  /* A sampler: bitwise hemilight_sample_irradiance, and it keeps the scene alive. */
  CHECK(hemilight_sampler_create(room, 64, &s) == HEMILIGHT_OK);
  CHECK(hemilight_sampler_create(room, 16, &s16) == HEMILIGHT_OK);
  hemilight_scene_release(room);
  room_for_tiny = make_room();
  same = 1;
  for (i = 0; i < count; ++i) {
    CHECK(hemilight_sampler_irradiance(s, pos + 3 * i, nrm + 3 * i, &r) == HEMILIGHT_OK);
    same = same && memcmp(&r, &ref[i], sizeof r) == 0;
    CHECK(hemilight_sampler_irradiance(s16, pos + 3 * i, nrm + 3 * i, &r) == HEMILIGHT_OK);
  }
  CHECK(same);
  /* Tiny and huge normals (their squares under- or overflow float) give the unit normal's result. */
  {
    const float p[3] = {0.1f, -0.2f, -0.999f}, up[3] = {0, 0, 1}, tiny[3] = {0, 0, 3e-23f}, huge[3] = {0, 0, 1e30f};
    const float p2[3] = {-0.999f, 0.1f, 0.2f}, x_tiny[3] = {1e-22f, 0, 0}, x_unit[3] = {1, 0, 0};
    hemilight_irradiance a, b;
    CHECK(hemilight_sampler_irradiance(s, p, up, &a) == HEMILIGHT_OK);
    CHECK(hemilight_sampler_irradiance(s, p, tiny, &b) == HEMILIGHT_OK);
    CHECK(memcmp(&a, &b, sizeof a) == 0);
    CHECK(hemilight_sampler_irradiance(s, p, huge, &b) == HEMILIGHT_OK);
    CHECK(memcmp(&a, &b, sizeof a) == 0);
    CHECK(hemilight_sampler_irradiance(s, p2, x_unit, &a) == HEMILIGHT_OK);
    CHECK(hemilight_sample_irradiance(room_for_tiny, p2, x_tiny, 64, &b) == HEMILIGHT_OK);
    CHECK(memcmp(&a, &b, sizeof a) == 0);
  }
  /* Physically plausible: finite, positive (the emitter or lit walls are in view of every point). */
  for (i = 0; i < count; ++i) CHECK(isfinite(ref[i].irradiance[0]) && ref[i].irradiance[0] > 0.0f);
  hemilight_sampler_release(s);
  hemilight_sampler_release(s16);
  hemilight_sampler_release(NULL);
  hemilight_scene_release(room_for_tiny);
}

static void test_sampler_closed_forms(void) {
  const float sky[3] = {1.0f, 2.0f, 3.0f}, zero_sky[3] = {0, 0, 0};
  const float p[3] = {0, 0, 0}, up[3] = {0, 0, 2};
  /* A 0.8 x 0.6 emitter (radiance 1) at height 1, facing down. */
  const float pos[] = {-0.3f, -0.2f, 1.0f, -0.3f, 0.4f, 1.0f, 0.5f, 0.4f, 1.0f, 0.5f, -0.2f, 1.0f};
  const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
  const float rad[] = {1, 1, 1, 1, 1, 1};
  const double v[4][3] = {{-0.3, -0.2, 1.0}, {-0.3, 0.4, 1.0}, {0.5, 0.4, 1.0}, {0.5, -0.2, 1.0}};
  hemilight_scene *empty = NULL, *quad = NULL;
  hemilight_sampler* s = NULL;
  hemilight_irradiance r;
  double e_ref = 0.0;
  int c, i;
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &empty) == HEMILIGHT_OK);
  CHECK(hemilight_sampler_create(empty, 16, &s) == HEMILIGHT_OK);
  CHECK(hemilight_sampler_irradiance(s, p, up, &r) == HEMILIGHT_OK);
  /* Uniform sky: pi L to float rounding (1e-5 relative). */
  for (c = 0; c < 3; ++c) CHECK(fabs(r.irradiance[c] / (pi * sky[c]) - 1.0) < 1e-5);
  hemilight_sampler_release(s);
  hemilight_scene_release(empty);

  /* Lambert's formula for the quad seen from the origin (normal +z): sum over edges of
   * acos(a.b) (a x b).n / 2 with a, b the unit vectors to consecutive corners (radiance 1). */
  for (i = 0; i < 4; ++i) {
    const double* a0 = v[i];
    const double* b0 = v[(i + 1) % 4];
    const double la = sqrt(a0[0] * a0[0] + a0[1] * a0[1] + a0[2] * a0[2]);
    const double lb = sqrt(b0[0] * b0[0] + b0[1] * b0[1] + b0[2] * b0[2]);
    const double d = (a0[0] * b0[0] + a0[1] * b0[1] + a0[2] * b0[2]) / (la * lb);
    const double cz = (a0[0] * b0[1] - a0[1] * b0[0]) / (la * lb);
    const double sn = sqrt(1.0 - d * d);
    e_ref += acos(d) * cz / sn / 2.0;
  }
  e_ref = fabs(e_ref);
  CHECK(hemilight_scene_create(pos, 4, idx, 2, rad, zero_sky, &quad) == HEMILIGHT_OK);
  CHECK(hemilight_sampler_create(quad, 128, &s) == HEMILIGHT_OK);
  CHECK(hemilight_sampler_irradiance(s, p, up, &r) == HEMILIGHT_OK);
  /* N = 128: the emitter's outline cuts ~0.5% of its texels' weight; 1% tolerance. */
  CHECK(fabs(r.irradiance[0] / e_ref - 1.0) < 0.01);
  hemilight_sampler_release(s);
  hemilight_scene_release(quad);
}

static void test_batch(void) {
  enum { count = 61 };
  static float pos[3 * count], nrm[3 * count];
  static hemilight_irradiance ref[count], out[count], untouched[count];
  const int threads[] = {1, 2, 3, 0};
  hemilight_scene* room = make_room();
  int i, t;
  CHECK(room != NULL);
  if (!room) return;
  room_points(pos, nrm, count);
  for (i = 0; i < count; ++i) CHECK(hemilight_sample_irradiance(room, pos + 3 * i, nrm + 3 * i, 32, &ref[i]) == HEMILIGHT_OK);
  for (t = 0; t < 4; ++t) {
    memset(out, 0, sizeof out);
    CHECK(hemilight_sample_irradiance_batch(room, pos, nrm, count, 32, threads[t], out) == HEMILIGHT_OK);
    CHECK(memcmp(out, ref, sizeof out) == 0);
  }
  /* count = 0 does nothing, even with NULL arrays. */
  CHECK(hemilight_sample_irradiance_batch(room, NULL, NULL, 0, 32, 1, NULL) == HEMILIGHT_OK);

  /* A bad point fails the whole call, names its index, and nothing is written. */
  memset(untouched, 0x5a, sizeof untouched);
  memcpy(out, untouched, sizeof out);
  nrm[3 * 37 + 0] = nrm[3 * 37 + 1] = nrm[3 * 37 + 2] = 0.0f;
  CHECK_FAILS(hemilight_sample_irradiance_batch(room, pos, nrm, count, 32, 2, out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "point 37: normal");
  room_points(pos, nrm, count);
  pos[3 * 59 + 1] = INFINITY;
  CHECK_FAILS(hemilight_sample_irradiance_batch(room, pos, nrm, count, 32, 2, out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "point 59: position");
  room_points(pos, nrm, count);
  CHECK_FAILS(hemilight_sample_irradiance_batch(NULL, pos, nrm, count, 32, 2, out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "scene is NULL");
  CHECK_FAILS(hemilight_sample_irradiance_batch(room, NULL, nrm, count, 32, 2, out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "positions is NULL");
  CHECK_FAILS(hemilight_sample_irradiance_batch(room, pos, NULL, count, 32, 2, out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "normals is NULL");
  CHECK_FAILS(hemilight_sample_irradiance_batch(room, pos, nrm, count, 32, 2, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "out is NULL");
  CHECK_FAILS(hemilight_sample_irradiance_batch(room, pos, nrm, count, 33, 2, out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "resolution 33");
  CHECK_FAILS(hemilight_sample_irradiance_batch(room, pos, nrm, count, 32, -1, out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "thread_count is -1");
  CHECK(memcmp(out, untouched, sizeof out) == 0);
  hemilight_scene_release(room);
}

static void test_sampler_errors(void) {
  const float sky[3] = {1, 1, 1};
  const float p[3] = {0, 0, 0}, up[3] = {0, 0, 1}, zero_n[3] = {0, 0, 0}, bad_p[3] = {NAN, 0, 0};
  hemilight_scene* empty = NULL;
  hemilight_sampler* s = NULL;
  hemilight_sampler* untouched_handle = (hemilight_sampler*)&passed;
  hemilight_irradiance r, untouched;
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &empty) == HEMILIGHT_OK);
  s = untouched_handle;
  CHECK_FAILS(hemilight_sampler_create(NULL, 16, &s), HEMILIGHT_ERROR_INVALID_ARGUMENT, "hemilight_sampler_create: scene is NULL");
  CHECK_FAILS(hemilight_sampler_create(empty, 15, &s), HEMILIGHT_ERROR_INVALID_ARGUMENT, "resolution 15");
  CHECK_FAILS(hemilight_sampler_create(empty, 8192, &s), HEMILIGHT_ERROR_INVALID_ARGUMENT, "resolution 8192");
  CHECK_FAILS(hemilight_sampler_create(empty, 16, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "out is NULL");
  CHECK(s == untouched_handle);
  CHECK(hemilight_sampler_create(empty, 16, &s) == HEMILIGHT_OK);
  memset(&untouched, 0x5a, sizeof untouched);
  r = untouched;
  CHECK_FAILS(hemilight_sampler_irradiance(NULL, p, up, &r), HEMILIGHT_ERROR_INVALID_ARGUMENT, "sampler is NULL");
  CHECK_FAILS(hemilight_sampler_irradiance(s, NULL, up, &r), HEMILIGHT_ERROR_INVALID_ARGUMENT, "position is NULL");
  CHECK_FAILS(hemilight_sampler_irradiance(s, bad_p, up, &r), HEMILIGHT_ERROR_INVALID_ARGUMENT, "position (nan");
  CHECK_FAILS(hemilight_sampler_irradiance(s, p, zero_n, &r), HEMILIGHT_ERROR_INVALID_ARGUMENT, "zero length");
  CHECK_FAILS(hemilight_sampler_irradiance(s, p, up, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "out is NULL");
  CHECK(memcmp(&r, &untouched, sizeof r) == 0);
  hemilight_sampler_release(s);
  hemilight_scene_release(empty);
}

/* Two threads on one sampler: a call that overlaps another is refused with "in use by another
 * thread", never a race; each thread's successful calls give the right answer. The threads call
 * at N = 512 (milliseconds per call) until one refusal is seen or 400 calls are made. */
struct shared_sampler {
  hemilight_sampler* sampler;
  const hemilight_irradiance* expected;
  volatile int refused, wrong, done;
};

static void* hammer(void* arg) {
  struct shared_sampler* sh = (struct shared_sampler*)arg;
  const float p[3] = {0.1f, -0.2f, -0.999f}, up[3] = {0, 0, 1};
  hemilight_irradiance r;
  int i;
  for (i = 0; i < 200 && !sh->refused; ++i) {
    const hemilight_status st = hemilight_sampler_irradiance(sh->sampler, p, up, &r);
    if (st == HEMILIGHT_OK) {
      if (memcmp(&r, sh->expected, sizeof r) != 0) sh->wrong = 1;
    } else if (st == HEMILIGHT_ERROR_INVALID_ARGUMENT && strstr(hemilight_last_error(), "in use by another thread")) {
      sh->refused = 1;
    } else {
      sh->wrong = 1;
    }
  }
  return NULL;
}

static void test_sampler_two_threads(void) {
  const float p[3] = {0.1f, -0.2f, -0.999f}, up[3] = {0, 0, 1};
  hemilight_scene* room = make_room();
  hemilight_irradiance expected;
  struct shared_sampler sh;
  pthread_t a, b;
  CHECK(room != NULL);
  if (!room) return;
  CHECK(hemilight_sample_irradiance(room, p, up, 512, &expected) == HEMILIGHT_OK);
  memset(&sh, 0, sizeof sh);
  sh.expected = &expected;
  CHECK(hemilight_sampler_create(room, 512, &sh.sampler) == HEMILIGHT_OK);
  CHECK(pthread_create(&a, NULL, hammer, &sh) == 0);
  CHECK(pthread_create(&b, NULL, hammer, &sh) == 0);
  pthread_join(a, NULL);
  pthread_join(b, NULL);
  CHECK(!sh.wrong);
  CHECK(sh.refused);
  hemilight_sampler_release(sh.sampler);
  hemilight_scene_release(room);
}

static void test_probes(void) {
  enum { count = 13 };
  const float sky[3] = {1.0f, 2.0f, 0.5f}, zero_sky[3] = {0, 0, 0};
  static float pos[3 * count], sh[27 * count], sh2[27 * count], untouched[27 * count], back[count];
  const float origin[3] = {0, 0, 0}, nrm[3] = {0.2f, -3.0f, 0.4f};
  const double y00 = 0.282094791773878, y1 = 0.488602511902920;
  hemilight_scene *empty = NULL, *dark = NULL, *lit = NULL, *room = make_room();
  hemilight_light l;
  float e[3], probe[27];
  int i, k, c, t;
  const int threads[] = {1, 2, 3, 0};
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky, &empty) == HEMILIGHT_OK);
  CHECK(hemilight_sample_probes(empty, origin, 1, 16, 1, probe) == HEMILIGHT_OK);
  /* Uniform sky: c_0 = 2 sqrt(pi) L (1e-5), the rest 0; its irradiance pi L for any normal. */
  for (c = 0; c < 3; ++c) CHECK(fabs(probe[c] / (2.0 * sqrt(pi) * sky[c]) - 1.0) < 1e-5);
  for (k = 1; k < 9; ++k)
    for (c = 0; c < 3; ++c) CHECK(fabs(probe[3 * k + c]) < 1e-5 * sky[c]);
  CHECK(hemilight_sh9_irradiance(probe, nrm, e) == HEMILIGHT_OK);
  for (c = 0; c < 3; ++c) CHECK(fabs(e[c] / (pi * sky[c]) - 1.0) < 1e-5);

  /* A hard point light of intensity (8, 4, 0) at distance 2 along +x, nothing else:
   * c_k = I / d^2 Y_k(+x): c_0 = 2 Y00, c_3 (x) = 2 Y1, the others 0 but c_8 (x^2 - y^2). */
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, zero_sky, &dark) == HEMILIGHT_OK);
  hemilight_light_init(&l, HEMILIGHT_LIGHT_POINT);
  l.position[0] = 2.0f, l.position[1] = 0.0f, l.position[2] = 0.0f;
  l.color[0] = 8.0f, l.color[1] = 4.0f, l.color[2] = 0.0f;
  CHECK(hemilight_scene_with_lights(dark, &l, 1, &lit) == HEMILIGHT_OK);
  CHECK(hemilight_sample_probes(lit, origin, 1, 8, 1, probe) == HEMILIGHT_OK);
  CHECK(fabs(probe[0] - 2.0 * y00) < 1e-5);
  CHECK(fabs(probe[3 * 3] - 2.0 * y1) < 1e-5);
  CHECK(fabs(probe[3 * 8] - 2.0 * 0.546274215296040) < 1e-5);
  CHECK(fabs(probe[3 * 2]) < 1e-6 && fabs(probe[3 * 1]) < 1e-6 && probe[2] == 0.0f);

  /* Bitwise the same on any thread count; the back-face fractions of points in the room are ~0. */
  for (i = 0; i < count; ++i) {
    pos[3 * i] = -0.8f + 0.12f * (float)i;
    pos[3 * i + 1] = 0.5f - 0.07f * (float)i;
    pos[3 * i + 2] = 0.3f;
  }
  CHECK(hemilight_sample_probes_with_backfaces(room, pos, count, 16, 1, sh, back) == HEMILIGHT_OK);
  for (i = 0; i < count; ++i) CHECK(back[i] < 1e-3f);
  for (t = 0; t < 4; ++t) {
    memset(sh2, 0, sizeof sh2);
    CHECK(hemilight_sample_probes(room, pos, count, 16, threads[t], sh2) == HEMILIGHT_OK);
    CHECK(memcmp(sh, sh2, sizeof sh) == 0);
  }
  /* A probe inside the occluder cube (closed, outward faces): it sees back faces everywhere but
   * straight down, where the cube's bottom lies on the room's floor and the floor (facing up)
   * wins the depth tie: exactly the 5/6 of the sphere outside the down hemicube's top face. */
  pos[3 * 4] = 0.0f, pos[3 * 4 + 1] = 0.0f, pos[3 * 4 + 2] = -0.7f;
  CHECK(hemilight_sample_probes_with_backfaces(room, pos, count, 16, 2, sh, back) == HEMILIGHT_OK);
  CHECK(fabs(back[4] - 5.0f / 6.0f) < 1e-5f);

  /* Errors name the point; nothing is written. */
  memset(untouched, 0x5a, sizeof untouched);
  memcpy(sh2, untouched, sizeof sh2);
  pos[3 * 9 + 2] = NAN;
  CHECK_FAILS(hemilight_sample_probes(room, pos, count, 16, 2, sh2), HEMILIGHT_ERROR_INVALID_ARGUMENT, "point 9: position");
  pos[3 * 9 + 2] = 0.3f;
  CHECK_FAILS(hemilight_sample_probes(room, pos, count, 15, 2, sh2), HEMILIGHT_ERROR_INVALID_ARGUMENT, "resolution 15");
  CHECK_FAILS(hemilight_sample_probes(room, pos, count, 16, -1, sh2), HEMILIGHT_ERROR_INVALID_ARGUMENT, "thread_count is -1");
  CHECK_FAILS(hemilight_sample_probes(NULL, pos, count, 16, 2, sh2), HEMILIGHT_ERROR_INVALID_ARGUMENT, "scene is NULL");
  CHECK_FAILS(hemilight_sample_probes(room, NULL, count, 16, 2, sh2), HEMILIGHT_ERROR_INVALID_ARGUMENT, "positions is NULL");
  CHECK_FAILS(hemilight_sample_probes(room, pos, count, 16, 2, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT, "sh9_rgb is NULL");
  CHECK_FAILS(hemilight_sample_probes_with_backfaces(room, pos, count, 16, 2, sh2, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "backface_fraction is NULL");
  CHECK(memcmp(sh2, untouched, sizeof sh2) == 0);
  CHECK(hemilight_sample_probes(room, NULL, 0, 16, 2, NULL) == HEMILIGHT_OK);
  e[0] = e[1] = e[2] = -7.0f;
  CHECK_FAILS(hemilight_sh9_irradiance(probe, origin, e), HEMILIGHT_ERROR_INVALID_ARGUMENT, "zero length");
  CHECK_FAILS(hemilight_sh9_irradiance(NULL, nrm, e), HEMILIGHT_ERROR_INVALID_ARGUMENT, "sh9_rgb is NULL");
  CHECK(e[0] == -7.0f && e[2] == -7.0f);
  hemilight_scene_release(empty);
  hemilight_scene_release(dark);
  hemilight_scene_release(lit);
  hemilight_scene_release(room);
}

int main(void) {
  test_probes();
  test_sampler_matches();
  test_sampler_closed_forms();
  test_batch();
  test_sampler_errors();
  test_sampler_two_threads();
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
