/* Memory of one C entry at one size: the resident set before the call, its peak (VmHWM) and what
 * stays after it and after hemilight_release_tables. Backs the formulas of docs/reliability.md
 * ("Memory"); run it under /usr/bin/time -v to cross-check the peak.
 *
 *   memory_peak ENTRY N [threads] [count]
 *     ENTRY sample   hemilight_sample_irradiance, `count` points on the calling thread
 *           sweep    hemilight_sample_irradiance once at every even N' from N to `count`
 *           sampler  hemilight_sampler_create + `count` points, then the sampler released
 *           batch    hemilight_sample_irradiance_batch, `count` points on `threads` threads
 *           cache    hemilight_cache_irradiance of a count x count grid (defaults)
 *           probes   hemilight_sample_probes, `count` probes on `threads` threads
 *           filter   hemilight_cubemap_filter_cosine_power (p = 64) of an N^3 cube map to N / 2
 *           irrad    hemilight_cubemap_filter_irradiance (quadrature) of an N^3 cube map to 32
 * The scene: a unit box open at the top (10 quads, 20 triangles) under a sky of radiance 1.
 * Prints one line: entry, N, threads, count, seconds, KiB before, peak, after, after release.
 *
 *   memory_peak exr_rgb|exr_cube FILE [capacity] [repeats]
 *     hemilight_exr_load_rgb or hemilight_exr_load_cubemap_rgb of FILE into a buffer of `capacity`
 *     floats (default 48: what a crafted file's refusal costs), `repeats` times (default 1).
 *     Prints the status, the median seconds per call, and KiB before, peak and after. */
#define _POSIX_C_SOURCE 200112L
#include "hemilight.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* A field of /proc/self/status in KiB ("VmRSS:", "VmHWM:"); 0 if unavailable. */
static long status_kib(const char* field) {
  char line[256];
  long v = 0;
  FILE* f = fopen("/proc/self/status", "r");
  if (!f) return 0;
  while (fgets(line, sizeof line, f))
    if (strncmp(line, field, strlen(field)) == 0) v = atol(line + strlen(field));
  fclose(f);
  return v;
}

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void fail(const char* what) {
  fprintf(stderr, "%s: %s\n", what, hemilight_last_error());
  exit(1);
}

/* The floor and four walls of [-1, 1]^2 x [0, 2], inward facing, radiance 0.5. */
static hemilight_scene* box(void) {
  static const float p[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0, -1, -1, 2, 1, -1, 2, 1, 1, 2, -1, 1, 2};
  static const uint32_t q[5][4] = {{0, 1, 2, 3}, {0, 4, 5, 1}, {1, 5, 6, 2}, {2, 6, 7, 3}, {3, 7, 4, 0}};
  uint32_t idx[30];
  float rad[30];
  float sky[3] = {1, 1, 1};
  hemilight_scene* s = NULL;
  int i;
  for (i = 0; i < 5; ++i) {
    idx[6 * i + 0] = q[i][0], idx[6 * i + 1] = q[i][1], idx[6 * i + 2] = q[i][2];
    idx[6 * i + 3] = q[i][0], idx[6 * i + 4] = q[i][2], idx[6 * i + 5] = q[i][3];
  }
  for (i = 0; i < 30; ++i) rad[i] = 0.5f;
  if (hemilight_scene_create(p, 8, idx, 10, rad, sky, &s) != HEMILIGHT_OK) fail("hemilight_scene_create");
  return s;
}

static int compare_doubles(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return x < y ? -1 : x > y ? 1 : 0;
}

/* memory_peak exr_rgb|exr_cube FILE [capacity] [repeats] (top of this file). */
static int exr_main(const char* entry, int argc, char** argv) {
  const char* path = argc > 2 ? argv[2] : "";
  const size_t capacity = argc > 3 ? (size_t)atol(argv[3]) : 48;
  const int repeats = argc > 4 && atoi(argv[4]) > 0 ? atoi(argv[4]) : 1;
  float* buffer = (float*)malloc((capacity > 0 ? capacity : 1) * sizeof(float));
  double* seconds = (double*)malloc((size_t)repeats * sizeof(double));
  hemilight_status st = HEMILIGHT_OK;
  long before, peak;
  int i, w = 0, h = 0;
  if (!buffer || !seconds) return 1;
  before = status_kib("VmRSS:");
  for (i = 0; i < repeats; ++i) {
    const double t0 = now();
    if (strcmp(entry, "exr_rgb") == 0)
      st = hemilight_exr_load_rgb(path, buffer, capacity, &w, &h);
    else
      st = hemilight_exr_load_cubemap_rgb(path, buffer, capacity, &w);
    seconds[i] = now() - t0;
  }
  peak = status_kib("VmHWM:");
  qsort(seconds, (size_t)repeats, sizeof(double), compare_doubles);
  printf("%s capacity=%lu repeats=%d status=%d median_seconds=%.6f rss_before_kib=%ld peak_kib=%ld after_kib=%ld\n", entry,
         (unsigned long)capacity, repeats, (int)st, seconds[repeats / 2], before, peak, status_kib("VmRSS:"));
  if (st != HEMILIGHT_OK) printf("  %s\n", hemilight_last_error());
  free(seconds);
  free(buffer);
  return 0;
}

int main(int argc, char** argv) {
  const char* entry = argc > 1 ? argv[1] : "sample";
  if (strcmp(entry, "exr_rgb") == 0 || strcmp(entry, "exr_cube") == 0) return exr_main(entry, argc, argv);
  const int n = argc > 2 ? atoi(argv[2]) : 64;
  const int threads = argc > 3 ? atoi(argv[3]) : 1;
  const size_t count = argc > 4 ? (size_t)atol(argv[4]) : 1;
  hemilight_scene* s = box();
  float* pos = (float*)calloc(3 * (count * count + 1), sizeof(float));
  float* nor = (float*)calloc(3 * (count * count + 1), sizeof(float));
  float* out = NULL;
  long before, peak, after, released;
  double t0, t1;
  size_t i;
  if (!pos || !nor) return 1;
  for (i = 0; i < count * count + 1; ++i) { /* a grid on the floor, just above it */
    pos[3 * i + 0] = -0.9f + 1.8f * (float)(i % (count + 1)) / (float)(count + 1);
    pos[3 * i + 1] = -0.9f + 1.8f * (float)(i / (count + 1) % (count + 1)) / (float)(count + 1);
    pos[3 * i + 2] = 0.01f;
    nor[3 * i + 2] = 1.0f;
  }
  before = status_kib("VmRSS:");
  t0 = now();
  if (strcmp(entry, "sample") == 0) {
    hemilight_irradiance r;
    for (i = 0; i < count; ++i)
      if (hemilight_sample_irradiance(s, pos + 3 * i, nor + 3 * i, n, &r) != HEMILIGHT_OK) fail(entry);
  } else if (strcmp(entry, "sweep") == 0) {
    hemilight_irradiance r;
    int m;
    for (m = n; m <= (int)count; m += 2)
      if (hemilight_sample_irradiance(s, pos, nor, m, &r) != HEMILIGHT_OK) fail(entry);
  } else if (strcmp(entry, "sampler") == 0) {
    hemilight_irradiance r;
    hemilight_sampler* sm = NULL;
    if (hemilight_sampler_create(s, n, &sm) != HEMILIGHT_OK) fail(entry);
    for (i = 0; i < count; ++i)
      if (hemilight_sampler_irradiance(sm, pos + 3 * i, nor + 3 * i, &r) != HEMILIGHT_OK) fail(entry);
    hemilight_sampler_release(sm);
  } else if (strcmp(entry, "batch") == 0) {
    hemilight_irradiance* r = (hemilight_irradiance*)malloc(count * sizeof *r);
    if (hemilight_sample_irradiance_batch(s, pos, nor, count, n, threads, r) != HEMILIGHT_OK) fail(entry);
    free(r);
  } else if (strcmp(entry, "cache") == 0) {
    hemilight_cache_options o;
    hemilight_cache_options_init(&o);
    o.resolution = n;
    o.thread_count = threads;
    out = (float*)malloc(3 * count * count * sizeof(float));
    hemilight_cache_stats st;
    hemilight_cache_stats_init(&st);
    if (hemilight_cache_irradiance(s, pos, nor, count * count, &o, out, &st) != HEMILIGHT_OK) fail(entry);
    fprintf(stderr, "records=%lu hemicubes=%lu\n", (unsigned long)st.records, (unsigned long)st.hemicubes);
  } else if (strcmp(entry, "probes") == 0) {
    out = (float*)malloc(27 * count * sizeof(float));
    for (i = 0; i < count; ++i) pos[3 * i + 2] = 1.0f;
    if (hemilight_sample_probes(s, pos, count, n, threads, out) != HEMILIGHT_OK) fail(entry);
  } else if (strcmp(entry, "filter") == 0 || strcmp(entry, "irrad") == 0) {
    const size_t in_floats = 18 * (size_t)n * (size_t)n;
    const int out_size = strcmp(entry, "filter") == 0 ? n / 2 : 32;
    float* in = (float*)malloc(in_floats * sizeof(float));
    out = (float*)malloc(18 * (size_t)out_size * (size_t)out_size * sizeof(float));
    for (i = 0; i < in_floats; ++i) in[i] = (float)(i % 101) / 101.0f;
    before = status_kib("VmRSS:");
    t0 = now();
    if (strcmp(entry, "filter") == 0) {
      if (hemilight_cubemap_filter_cosine_power(in, n, 64.0f, HEMILIGHT_EDGE_FIXUP_NONE, out_size, out) != HEMILIGHT_OK) fail(entry);
    } else if (hemilight_cubemap_filter_irradiance(in, n, HEMILIGHT_EDGE_FIXUP_NONE, out_size, 0, out) != HEMILIGHT_OK) {
      fail(entry);
    }
    free(in);
  } else {
    fprintf(stderr, "unknown entry %s\n", entry);
    return 2;
  }
  t1 = now();
  peak = status_kib("VmHWM:");
  after = status_kib("VmRSS:");
  hemilight_release_tables();
  released = status_kib("VmRSS:");
  printf("%s N=%d threads=%d count=%lu seconds=%.2f rss_before_kib=%ld peak_kib=%ld after_kib=%ld after_release_kib=%ld\n",
         entry, n, threads, (unsigned long)count, t1 - t0, before, peak, after, released);
  free(out);
  free(pos);
  free(nor);
  hemilight_scene_release(s);
  return 0;
}
