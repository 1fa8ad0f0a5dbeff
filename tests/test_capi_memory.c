/* C99 tests of what the C ABI keeps between calls (hemilight.h, "memory kept between calls"):
 * the table budget bounds the kept tables across many resolutions, hemilight_release_tables
 * empties the cache and frees other threads' per-thread contexts while they wait, and every
 * result after a release (rebuilt tables and contexts) is bitwise the one before it.
 * References: the same calls before any release. Prints failing checks and "N passed, N failed". */
#define _POSIX_C_SOURCE 200112L /* pthread_barrier_t */
#include "capi_check.h"

#include <pthread.h>
#include <stdio.h>
#include <string.h>

/* A small scene: an emissive quad above the origin, a dim sky. */
static hemilight_scene* make_scene(void) {
  const float pos[] = {-0.5f, -0.5f, 1.0f, 0.5f, -0.5f, 1.0f, 0.5f, 0.5f, 1.2f, -0.5f, 0.5f, 1.2f};
  const uint32_t idx[] = {0, 2, 1, 0, 3, 2};
  const float rad[] = {1.0f, 0.5f, 0.25f, 1.0f, 0.5f, 0.25f};
  const float sky[3] = {0.1f, 0.2f, 0.3f};
  hemilight_scene* s = NULL;
  CHECK(hemilight_scene_create(pos, 4, idx, 2, rad, sky, &s) == HEMILIGHT_OK);
  return s;
}

static const float point[3] = {0.1f, -0.2f, 0.0f}, normal[3] = {0.2f, 0.1f, 1.0f};

static int same(const hemilight_irradiance* a, const hemilight_irradiance* b) { return memcmp(a, b, sizeof *a) == 0; }

static void test_budget(hemilight_scene* s) {
  const size_t budget = (size_t)2 << 20; /* 2 MiB: a few tables of N <= 64 */
  size_t most = 0;
  int n;
  hemilight_irradiance r;
  CHECK(hemilight_table_budget() == (size_t)268435456);
  hemilight_set_table_budget(budget);
  CHECK(hemilight_table_budget() == budget);
  for (n = 2; n <= 128; n += 2) {
    CHECK(hemilight_sample_irradiance(s, point, normal, n, &r) == HEMILIGHT_OK);
    if (hemilight_table_bytes() > budget) printf("N = %d: %lu bytes kept\n", n, (unsigned long)hemilight_table_bytes());
    CHECK(hemilight_table_bytes() <= budget);
    if (hemilight_table_bytes() > most) most = hemilight_table_bytes();
  }
  CHECK(most > budget / 2); /* the budget was used, not bypassed */
  hemilight_set_table_budget(0);
  CHECK(hemilight_table_bytes() == 0);
  hemilight_set_table_budget((size_t)268435456);
}

/* A second thread samples, waits while the main thread releases everything, samples again. */
typedef struct waiter {
  hemilight_scene* scene;
  pthread_barrier_t* barrier;
  hemilight_irradiance before, after;
  int ok;
} waiter;

static void* wait_for_release(void* arg) {
  waiter* w = (waiter*)arg;
  w->ok = hemilight_sample_irradiance(w->scene, point, normal, 48, &w->before) == HEMILIGHT_OK;
  pthread_barrier_wait(w->barrier); /* 1: sampled; its context is kept */
  pthread_barrier_wait(w->barrier); /* 2: the main thread released */
  w->ok = w->ok && hemilight_sample_irradiance(w->scene, point, normal, 48, &w->after) == HEMILIGHT_OK;
  return NULL;
}

static void test_release(hemilight_scene* s) {
  hemilight_irradiance a, b, c, d;
  hemilight_sampler* sampler = NULL;
  pthread_barrier_t barrier;
  pthread_t thread;
  waiter w;
  CHECK(hemilight_sample_irradiance(s, point, normal, 64, &a) == HEMILIGHT_OK);
  CHECK(hemilight_sampler_create(s, 96, &sampler) == HEMILIGHT_OK);
  CHECK(hemilight_sampler_irradiance(sampler, point, normal, &c) == HEMILIGHT_OK);
  CHECK(hemilight_table_bytes() > 0);

  memset(&w, 0, sizeof w);
  w.scene = s;
  w.barrier = &barrier;
  CHECK(pthread_barrier_init(&barrier, NULL, 2) == 0);
  CHECK(pthread_create(&thread, NULL, wait_for_release, &w) == 0);
  pthread_barrier_wait(&barrier);
  hemilight_release_tables(); /* frees the waiting thread's context and ours */
  CHECK(hemilight_table_bytes() == 0);
  pthread_barrier_wait(&barrier);
  pthread_join(thread, NULL);
  pthread_barrier_destroy(&barrier);
  CHECK(w.ok);
  CHECK(same(&w.before, &w.after));

  /* Rebuilt tables and context: bitwise the same; the live sampler still works. */
  CHECK(hemilight_sample_irradiance(s, point, normal, 64, &b) == HEMILIGHT_OK);
  CHECK(same(&a, &b));
  CHECK(hemilight_sampler_irradiance(sampler, point, normal, &d) == HEMILIGHT_OK);
  CHECK(same(&c, &d));
  hemilight_sampler_release(sampler);
  /* Budget 0: nothing kept between calls, results unchanged. */
  hemilight_set_table_budget(0);
  CHECK(hemilight_sample_irradiance(s, point, normal, 64, &b) == HEMILIGHT_OK);
  CHECK(same(&a, &b));
  CHECK(hemilight_table_bytes() == 0);
  hemilight_set_table_budget((size_t)268435456);
  hemilight_release_tables();
}

int main(void) {
  hemilight_scene* s = make_scene();
  test_budget(s);
  test_release(s);
  hemilight_scene_release(s);
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
