// The C ABI's point samplers: hemilight_sample_irradiance (one point, a per-thread cached
// context), hemilight_sampler_* (a context the caller keeps) and hemilight_sample_irradiance_batch
// (many points on several threads). All three go through point_sampler::sample.
#include "capi_sample.hpp"

#include "hemilight/geometry.hpp"
#include "hemilight/lights.hpp"
#include "hemilight/parallel.hpp"

#include "hemilight/memory.hpp"

#if defined(__GLIBC__)
#include <malloc.h>  // malloc_trim
#endif

#include <algorithm>
#include <atomic>
#include <memory>
#include <cmath>
#include <mutex>
#include <set>
#include <string>
#include <vector>

/// The C ABI's sampler handle: the scene's parts (shared: the handle keeps them alive) and one
/// thread's context.
struct hemilight_sampler {
  hemilight_scene scene;
  int resolution = 0;
  hemilight::capi::point_sampler context;
  std::atomic<bool> busy{false};  // set while a call runs: a second thread's call is refused
};

namespace hemilight::capi {

namespace {

std::string triple(const float* v) {
  return "(" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) + ")";
}

}  // namespace

glm::vec3 unit_normal(const float* normal) {
  // In double: every finite nonzero float vector has a finite nonzero length there (squares of
  // 1e-45 and of 3.4e38 are far inside double's range), so tiny and huge normals work.
  const glm::dvec3 n(normal[0], normal[1], normal[2]);
  return glm::vec3(n / glm::length(n));
}

bool point_ok(const float* position, const float* normal) noexcept {
  if (!position || !normal || !all_finite(position, 3) || !all_finite(normal, 3)) return false;
  for (int c = 0; c < 3; ++c)
    if (std::fabs(position[c]) > max_coordinate) return false;
  return normal[0] != 0.0f || normal[1] != 0.0f || normal[2] != 0.0f;
}

hemilight_status check_point(const char* function, const std::string& where, const float* position, const float* normal) {
  if (point_ok(position, normal)) return HEMILIGHT_OK;
  if (!position) return invalid(function, where + "position is NULL");
  if (!normal) return invalid(function, where + "normal is NULL");
  if (!all_finite(position, 3)) return invalid(function, where + "position " + triple(position) + " is not finite");
  for (int c = 0; c < 3; ++c)
    if (std::fabs(position[c]) > max_coordinate)
      return invalid(function, where + "position " + triple(position) + " is beyond 1e18 (max_coordinate)");
  if (!all_finite(normal, 3)) return invalid(function, where + "normal " + triple(normal) + " is not finite");
  if (normal[0] == 0.0f && normal[1] == 0.0f && normal[2] == 0.0f)
    return invalid(function, where + "normal " + triple(normal) + " has no direction (zero length)");
  return HEMILIGHT_OK;
}

void point_sampler::prepare(const hemilight_scene& scene, int resolution) {
  raster_options ro;
  ro.sky = scene.sky;
  ro.edge_coverage = scene.edge_coverage;
  if (!raster)
    raster = std::make_unique<hemicube_rasterizer>(scene.scene, ro);
  else
    raster->bind(scene.scene, ro);
  if (!integrator || integrator->resolution() != resolution) integrator = std::make_unique<hemicube_integrator>(resolution);
}

bool point_sampler::sample(const hemilight_scene& scene, int resolution, const float* position, const float* normal,
                           hemilight_irradiance& out) {
  const glm::vec3 unit = unit_normal(normal);
  const glm::vec3 x(position[0], position[1], position[2]);
  raster->render(x, make_frame(unit), resolution, buffer);
  const irradiance_sample s = integrator->integrate(buffer);
  hemilight_irradiance r;
  for (int ch = 0; ch < 3; ++ch) {
    r.irradiance[ch] = s.irradiance[ch];
    for (int k = 0; k < 3; ++k) {
      r.rotation_gradient[ch][k] = s.rotation_gradient[std::size_t(ch)][k];
      r.translation_gradient[ch][k] = s.translation_gradient[std::size_t(ch)][k];
    }
  }
  if (scene.lights) {
    const glm::vec3 e = direct_irradiance(*scene.scene, *scene.lights, x, unit);
    for (int ch = 0; ch < 3; ++ch) r.irradiance[ch] += e[ch];
  }
  r.harmonic_mean_distance = s.harmonic_mean_distance;
  r.min_distance = s.min_distance;
  r.backface_fraction = s.backface_fraction;
  // Finite on OK: radiance is bounded (max_radiance) but a light's I / d^2 next to it is not.
  if (!all_finite(r.irradiance, 3) || !all_finite(&r.rotation_gradient[0][0], 9) || !all_finite(&r.translation_gradient[0][0], 9))
    return false;
  out = r;
  return true;
}

}  // namespace hemilight::capi

namespace {

const char* const overflow_message = "the irradiance overflows float (a light too intense or too close to the point?)";

// The per-thread context of hemilight_sample_irradiance, registered so that
// hemilight_release_tables can free the contexts of every thread not inside a call.
struct thread_context;

struct context_registry {
  std::mutex mutex;
  std::set<thread_context*> contexts;
};

// Never destroyed: threads may end (and unregister) after static destructors ran.
context_registry& registry() {
  static context_registry* const instance = new context_registry;
  return *instance;
}

struct thread_context {
  std::mutex in_use;  // held by the owning thread during a call, and by a release freeing it
  hemilight::capi::point_sampler sampler;
  thread_context() {
    context_registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    r.contexts.insert(this);
  }
  ~thread_context() {
    context_registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    r.contexts.erase(this);
  }
  thread_context(const thread_context&) = delete;
  thread_context& operator=(const thread_context&) = delete;
};

// Frees the contexts of every thread that is not inside hemilight_sample_irradiance (a thread
// inside a call keeps its context; it is freed by a later release).
void release_thread_contexts() noexcept {
  context_registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  for (thread_context* c : r.contexts) {
    if (!c->in_use.try_lock()) continue;
    c->sampler = hemilight::capi::point_sampler{};
    c->in_use.unlock();
  }
}

using hemilight::capi::check_point;
using hemilight::capi::check_resolution;
using hemilight::capi::guarded;
using hemilight::capi::invalid;

}  // namespace

extern "C" {

hemilight_status hemilight_sample_irradiance(const hemilight_scene* scene, const float position[3], const float normal[3],
                                             int resolution, hemilight_irradiance* out) {
  const char* fn = "hemilight_sample_irradiance";
  return guarded(fn, [&] {
    if (!scene) return invalid(fn, "scene is NULL");
    if (!out) return invalid(fn, "out is NULL");
    if (const hemilight_status st = check_point(fn, "", position, normal)) return st;
    if (const hemilight_status st = check_resolution(fn, resolution)) return st;
    // The context is kept per thread between calls (tables, scratch) up to cached_resolution,
    // bound to the call's scene for the call only: no thread keeps a released scene alive.
    // Above it, a context for this call alone (its tables are then a small part of the render).
    // hemilight_release_tables frees the kept contexts of threads not inside a call.
    constexpr int cached_resolution = 512;
    thread_local thread_context cached;
    hemilight::capi::point_sampler own;
    std::unique_lock<std::mutex> in_use;
    if (resolution <= cached_resolution) in_use = std::unique_lock<std::mutex>(cached.in_use);
    hemilight::capi::point_sampler& context = resolution <= cached_resolution ? cached.sampler : own;
    struct unbind_after {
      hemilight::capi::point_sampler& c;
      ~unbind_after() {
        if (c.raster) c.raster->unbind();
      }
    } guard{context};
    context.prepare(*scene, resolution);
    hemilight_irradiance r;
    if (!context.sample(*scene, resolution, position, normal, r)) return invalid(fn, overflow_message);
    *out = r;
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_sampler_create(const hemilight_scene* scene, int resolution, hemilight_sampler** out) {
  const char* fn = "hemilight_sampler_create";
  return guarded(fn, [&] {
    if (!out) return invalid(fn, "out is NULL");
    if (!scene) return invalid(fn, "scene is NULL");
    if (const hemilight_status st = check_resolution(fn, resolution)) return st;
    auto s = std::make_unique<hemilight_sampler>();
    s->scene = *scene;
    s->resolution = resolution;
    s->context.prepare(s->scene, resolution);
    *out = s.release();
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_sampler_irradiance(hemilight_sampler* sampler, const float position[3], const float normal[3],
                                              hemilight_irradiance* out) {
  const char* fn = "hemilight_sampler_irradiance";
  return guarded(fn, [&] {
    if (!sampler) return invalid(fn, "sampler is NULL");
    if (!out) return invalid(fn, "out is NULL");
    if (const hemilight_status st = check_point(fn, "", position, normal)) return st;
    if (sampler->busy.exchange(true, std::memory_order_acquire))
      return invalid(fn, "the sampler is in use by another thread (a sampler serves one thread at a time: make one per thread)");
    struct release_after {
      std::atomic<bool>& busy;
      ~release_after() { busy.store(false, std::memory_order_release); }
    } guard{sampler->busy};
    hemilight_irradiance r;
    if (!sampler->context.sample(sampler->scene, sampler->resolution, position, normal, r)) return invalid(fn, overflow_message);
    *out = r;
    return HEMILIGHT_OK;
  });
}

void hemilight_sampler_release(hemilight_sampler* sampler) { delete sampler; }

hemilight_status hemilight_sample_irradiance_batch(const hemilight_scene* scene, const float* positions, const float* normals,
                                                   size_t count, int resolution, int thread_count, hemilight_irradiance* out) {
  const char* fn = "hemilight_sample_irradiance_batch";
  return guarded(fn, [&] {
    // Step 1: the arguments and every point, before anything is rendered; every argument whatever
    // the count (the arrays may be NULL only when it is 0: then nothing is done).
    if (!scene) return invalid(fn, "scene is NULL");
    const std::string with_count = " but count is " + std::to_string(count);
    if (count > 0 && !positions) return invalid(fn, "positions is NULL" + with_count);
    if (count > 0 && !normals) return invalid(fn, "normals is NULL" + with_count);
    if (count > 0 && !out) return invalid(fn, "out is NULL" + with_count);
    if (count > hemilight::max_scene_elements)
      return invalid(fn, "count " + std::to_string(count) + " is over the limit of " + std::to_string(hemilight::max_scene_elements) +
                             " points per call");
    if (const hemilight_status st = check_resolution(fn, resolution)) return st;
    if (thread_count < 0) return invalid(fn, "thread_count is " + std::to_string(thread_count) + "; it must be >= 0 (0 = all cores)");
    for (std::size_t i = 0; i < count; ++i)
      if (!hemilight::capi::point_ok(positions + 3 * i, normals + 3 * i))  // the message only for the bad one
        return check_point(fn, "point " + std::to_string(i) + ": ", positions + 3 * i, normals + 3 * i);
    if (count == 0) return HEMILIGHT_OK;
    // Step 2: the points on the workers, one context each, into a buffer of our own (each
    // point's result depends on that point alone: the same for any thread count).
    // Contexts are made by the workers on their first chunk: only workers that run allocate (at
    // most min(thread_count, chunks of 16 points), as parallel_for starts no more).
    constexpr std::size_t grain = 16;
    const std::size_t workers =
        std::min(static_cast<std::size_t>(hemilight::resolve_thread_count(thread_count)), (count + grain - 1) / grain);
    std::vector<hemilight::capi::point_sampler> contexts(workers);
    std::vector<hemilight_irradiance> results(count);
    std::atomic<std::size_t> first_bad{count};  // the lowest index whose result overflowed
    hemilight::parallel_for(count, static_cast<int>(workers), grain, [&](int worker, std::size_t b, std::size_t e) {
      hemilight::capi::point_sampler& c = contexts[std::size_t(worker)];
      if (!c.raster) c.prepare(*scene, resolution);
      for (std::size_t i = b; i < e; ++i)
        if (!c.sample(*scene, resolution, positions + 3 * i, normals + 3 * i, results[i])) {
          std::size_t seen = first_bad.load();
          while (i < seen && !first_bad.compare_exchange_weak(seen, i)) {
          }
        }
    });
    if (first_bad.load() < count) return invalid(fn, "point " + std::to_string(first_bad.load()) + ": " + overflow_message);
    // Step 3: the results out, only now that all succeeded.
    std::copy(results.begin(), results.end(), out);
    return HEMILIGHT_OK;
  });
}

void hemilight_set_table_budget(size_t bytes) { hemilight::set_table_budget(bytes); }

size_t hemilight_table_budget(void) { return hemilight::table_budget(); }

size_t hemilight_table_bytes(void) { return hemilight::table_cache_stats().retained_bytes; }

void hemilight_release_tables(void) {
  release_thread_contexts();  // first: the contexts hold references to tables
  hemilight::release_tables();
#if defined(__GLIBC__)
  // Tables and scratch of a few MB each sit below glibc's mmap threshold: freed, they stay in
  // the heap's free lists. Hand them back to the system.
  malloc_trim(0);
#endif
}

}  // extern "C"
