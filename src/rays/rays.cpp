// Ray queries through Embree 3 (rays.hpp): one process-wide RTCDevice, one RTCScene per scene built
// on its first query (std::call_once), the fallback traversal of rays_bvh.cpp when that build fails.
#include "ray_accel.hpp"

#include "../scene/scene_access.hpp"

#include "hemilight/error.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <limits>
#include <mutex>
#include <new>
#include <string>

namespace hemilight {
namespace detail {

namespace {

// The Embree scene's settings (rays.hpp, "Acceleration structure"): robust traversal and triangle
// test (watertight), and the quality that measured best for build time + memory against ray speed.
constexpr RTCBuildQuality build_quality = RTC_BUILD_QUALITY_MEDIUM;

std::atomic<std::int64_t> device_bytes{0};
std::atomic<bool> fail_builds{false};

// The last message Embree's error callback gave on this thread (errors are reported to the thread
// that made the failing call).
thread_local std::string last_embree_message;

void on_embree_error(void*, RTCError, const char* message) { last_embree_message = message ? message : ""; }

bool on_embree_memory(void*, ssize_t bytes, bool) {
  device_bytes.fetch_add(static_cast<std::int64_t>(bytes), std::memory_order_relaxed);
  return true;  // never refuse: Embree reports its own allocation failures
}

const char* embree_error_name(RTCError e) {
  switch (e) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_UNKNOWN: return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
  }
  return "unknown error";
}

status status_of(RTCError e) {
  if (e == RTC_ERROR_OUT_OF_MEMORY) return status::out_of_memory;
  if (e == RTC_ERROR_UNSUPPORTED_CPU) return status::unsupported;
  return status::internal;
}

std::string describe(const char* what, RTCError e) {
  std::string m = std::string(what) + ": Embree " + embree_error_name(e);
  if (!last_embree_message.empty()) m += " (" + last_embree_message + ")";
  return m;
}

// The process's one RTCDevice, made on first use (a function-local static: thread-safe) and
// released at exit (Embree counts the scenes' references to it, so a scene released later is fine).
struct device_holder {
  RTCDevice device = nullptr;
  status failure = status::ok;
  std::string message;

  device_holder() {
    last_embree_message.clear();
    device = rtcNewDevice(nullptr);
    if (!device) {
      const RTCError e = rtcGetDeviceError(nullptr);
      failure = status_of(e);
      message = describe("rtcNewDevice failed", e);
      return;
    }
    rtcSetDeviceErrorFunction(device, on_embree_error, nullptr);
    rtcSetDeviceMemoryMonitorFunction(device, on_embree_memory, nullptr);
    if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED) != 0) {
      // rays.hpp promises both faces; an Embree built with EMBREE_BACKFACE_CULLING cannot keep that.
      failure = status::unsupported;
      message = "this Embree was built with backface culling (EMBREE_BACKFACE_CULLING): hemilight needs both faces";
      rtcReleaseDevice(device);
      device = nullptr;
    }
  }
  ~device_holder() {
    if (device) rtcReleaseDevice(device);
  }
  device_holder(const device_holder&) = delete;
  device_holder& operator=(const device_holder&) = delete;
};

const device_holder& shared_device() {
  static const device_holder holder;
  return holder;
}

bool finite3(const glm::vec3& v) noexcept { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The checks of rays.hpp, before Embree sees the ray (it has no defined answer for NaN or Inf).
bool valid_query(const glm::vec3& origin, const glm::vec3& d, float t_max) noexcept {
  return t_max > 0.0f && finite3(origin) && finite3(d) && (d.x != 0.0f || d.y != 0.0f || d.z != 0.0f);
}

// Embree takes rays whose origin and direction components are at most FLT_LARGE = 1.844e18 in
// magnitude (its ray.valid(); a build with assertions aborts on others). Origins stay within
// max_coordinate (scene.hpp) plus offsets; a longer direction (a shadow ray to a light 1e18 away)
// is scaled to its largest component 1, and t_max by the inverse: the same segment. Returns the
// factor that turns the scaled ray's t back into the caller's (1 when nothing was scaled), or 0
// for an origin Embree cannot take (the fallback traversal answers those).
float fit_embree_range(const glm::vec3& origin, glm::vec3& d, float& t_max) noexcept {
  constexpr float large = 1.8e18f;
  if (!(std::fabs(origin.x) <= large && std::fabs(origin.y) <= large && std::fabs(origin.z) <= large)) return 0.0f;
  const float m = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
  if (m <= large) return 1.0f;
  d /= m;
  t_max *= m;  // +inf stays +inf; a huge finite t_max may become +inf (the segment then reaches on)
  return 1.0f / m;
}

// Embree accepts tnear <= t <= tfar on its float t = rcp(den) * T, a few ulps from the true t
// (an approximate reciprocal refined once). tnear = the smallest positive float gives t > 0; tfar
// = t_max (1 - 2^-20) keeps a triangle at exactly t_max (a shadow ray's end point on a light)
// out, at the price of hits in the last 1e-6 of the segment (+inf stays +inf).
constexpr float far_margin = 1.0f - 1.0f / 1048576.0f;

void set_ray(RTCRay& r, const glm::vec3& o, const glm::vec3& d, float t_max) noexcept {
  r.org_x = o.x;
  r.org_y = o.y;
  r.org_z = o.z;
  r.dir_x = d.x;
  r.dir_y = d.y;
  r.dir_z = d.z;
  r.tnear = std::numeric_limits<float>::denorm_min();
  r.tfar = std::isinf(t_max) ? t_max : t_max * far_margin;
  r.time = 0.0f;
  r.mask = 0xffffffffu;
  r.id = 0;
  r.flags = 0;
}

}  // namespace

struct ray_accel {
  RTCScene rtc = nullptr;         // null for an empty scene or a failed build
  status failure = status::ok;
  std::string message;

  ray_accel() = default;
  ray_accel(const ray_accel&) = delete;
  ray_accel& operator=(const ray_accel&) = delete;
  ~ray_accel() {
    if (rtc) rtcReleaseScene(rtc);
  }
};

namespace {

// Builds a's Embree scene from s's drawable triangles (geometry 0, primitive i = triangles()[i]).
// Never throws: a failure is kept in a (status, message) and the queries use the fallback.
void build(const scene& s, ray_accel& a) noexcept {
  if (s.triangles().empty()) return;  // nothing to hit: no Embree at all
  try {
    if (fail_builds.load()) {
      a.failure = status::out_of_memory;
      a.message = "prepare_rays: Embree out of memory (simulated by a test)";
      return;
    }
    const device_holder& d = shared_device();
    if (!d.device) {
      a.failure = d.failure;
      a.message = "prepare_rays: " + d.message;
      return;
    }
    last_embree_message.clear();
    rtcGetDeviceError(d.device);  // clear this thread's error code
    RTCScene rtc = rtcNewScene(d.device);
    RTCError e = rtcGetDeviceError(d.device);
    if (!rtc || e != RTC_ERROR_NONE) {
      if (rtc) rtcReleaseScene(rtc);
      a.failure = status_of(e);
      a.message = describe("prepare_rays: rtcNewScene failed", e);
      return;
    }
    rtcSetSceneFlags(rtc, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(rtc, build_quality);
    const std::vector<scene::triangle>& tris = s.triangles();
    const std::vector<glm::vec3>& positions = s.positions();
    const std::vector<std::uint32_t>& indices = s.indices();
    RTCGeometry g = rtcNewGeometry(d.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    float* vb = g ? static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                3 * sizeof(float), positions.size()))
                  : nullptr;
    unsigned* ib = vb ? static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                      3 * sizeof(unsigned), tris.size()))
                      : nullptr;
    if (ib) {
      for (std::size_t i = 0; i < positions.size(); ++i) {
        vb[3 * i] = positions[i].x;
        vb[3 * i + 1] = positions[i].y;
        vb[3 * i + 2] = positions[i].z;
      }
      for (std::size_t i = 0; i < tris.size(); ++i)
        for (std::size_t k = 0; k < 3; ++k) ib[3 * i + k] = indices[3 * std::size_t(tris[i].index) + k];
      rtcCommitGeometry(g);
      rtcAttachGeometryByID(rtc, g, 0);
    }
    if (g) rtcReleaseGeometry(g);
    if (ib) rtcCommitScene(rtc);
    e = rtcGetDeviceError(d.device);
    if (!ib || e != RTC_ERROR_NONE) {
      rtcReleaseScene(rtc);
      if (e == RTC_ERROR_NONE) e = RTC_ERROR_OUT_OF_MEMORY;
      a.failure = status_of(e);
      a.message = describe("prepare_rays: building the Embree scene failed", e);
      return;
    }
    a.rtc = rtc;
  } catch (...) {  // std::bad_alloc from our strings; Embree itself reports through its error code
    a.failure = status::out_of_memory;
    a.message.clear();
  }
}

// The scene's ray_accel, built into its lazy slot by the first caller (the others wait, then
// take the fast path: an acquire load). Null only for a scene not made by scene::create or when
// even the empty structure could not be allocated (the queries then use the fallback).
ray_accel* built(const scene& s) noexcept {
  lazy_slot* slot = derived_access::of(s, derived_kind::rays);
  if (!slot) return nullptr;
  if (!slot->done.load(std::memory_order_acquire))
    std::call_once(slot->once, [&] {
      try {
        auto a = std::make_shared<ray_accel>();
        build(s, *a);
        slot->value = std::move(a);
      } catch (const std::bad_alloc&) {  // value stays null: the fallback serves the queries
      }
      slot->done.store(true, std::memory_order_release);
    });
  return static_cast<ray_accel*>(slot->value.get());
}

}  // namespace

bool rays_use_embree(const scene& s) noexcept {
  const ray_accel* a = built(s);
  return a && a->rtc;
}

std::int64_t embree_device_bytes() noexcept { return device_bytes.load(std::memory_order_relaxed); }

void fail_embree_builds_for_testing(bool fail) noexcept { fail_builds.store(fail); }

}  // namespace detail

void prepare_rays(const scene& s) {
  const detail::ray_accel* a = detail::built(s);
  if (a && a->failure != status::ok)
    throw error(a->failure, a->message.empty() ? std::string("prepare_rays: out of memory") : a->message);
}

bool occluded(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept {
  if (!detail::valid_query(origin, direction, t_max) || s.triangles().empty()) return false;
  const detail::ray_accel* a = detail::built(s);
  glm::vec3 d = direction;
  float t = t_max;
  if (!a || !a->rtc || detail::fit_embree_range(origin, d, t) == 0.0f) return detail::occluded_bvh(s, origin, direction, t_max);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r;
  detail::set_ray(r, origin, d, t);
  rtcOccluded1(a->rtc, &context, &r);
  return r.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

namespace {

// One Embree packet of up to N rays from `origin` (N = 4 or 8: RTCRay4 / RTCRay8), lanes past
// `count` and invalid rays inactive (valid mask 0, answered false without tracing).
template <std::size_t N, class Packet>
void occluded_packet(const scene& s, RTCScene rtc, RTCIntersectContext& context, const glm::vec3& origin,
                     const glm::vec3* directions, const float* t_max, std::size_t count, bool* out) noexcept {
  alignas(32) int valid[N];
  Packet r;
  int live = 0;
  bool outside[N] = {};  // valid queries Embree cannot take (detail::fit_embree_range): the fallback's
  for (std::size_t j = 0; j < N; ++j) {
    bool ok = j < count && detail::valid_query(origin, directions[j], t_max[j]);
    glm::vec3 d = glm::vec3(0.0f, 0.0f, 1.0f);
    float t = 1.0f;
    if (ok) {
      d = directions[j];
      t = t_max[j];
      if (detail::fit_embree_range(origin, d, t) == 0.0f) {
        outside[j] = true;
        ok = false;
        d = glm::vec3(0.0f, 0.0f, 1.0f);
        t = 1.0f;
      }
    }
    valid[j] = ok ? -1 : 0;
    live += ok ? 1 : 0;
    r.org_x[j] = origin.x;
    r.org_y[j] = origin.y;
    r.org_z[j] = origin.z;
    r.dir_x[j] = d.x;
    r.dir_y[j] = d.y;
    r.dir_z[j] = d.z;
    r.tnear[j] = std::numeric_limits<float>::denorm_min();
    r.tfar[j] = std::isinf(t) ? t : t * detail::far_margin;
    r.time[j] = 0.0f;
    r.mask[j] = 0xffffffffu;
    r.id[j] = 0;
    r.flags[j] = 0;
  }
  if (live > 0) {
    if constexpr (N == 8)
      rtcOccluded8(valid, rtc, &context, &r);
    else
      rtcOccluded4(valid, rtc, &context, &r);
  }
  for (std::size_t j = 0; j < count; ++j)
    out[j] = outside[j] ? detail::occluded_bvh(s, origin, directions[j], t_max[j])
                        : valid[j] != 0 && r.tfar[j] < 0.0f;  // tfar = -inf on a hit
}

}  // namespace

void occluded_many(const scene& s, const glm::vec3& origin, const glm::vec3* directions, const float* t_max,
                   std::size_t count, bool* out) noexcept {
  if (count == 0) return;
  if (s.triangles().empty() || !detail::finite3(origin)) {
    for (std::size_t i = 0; i < count; ++i) out[i] = false;
    return;
  }
  const detail::ray_accel* a = detail::built(s);
  if (!a || !a->rtc) {
    for (std::size_t i = 0; i < count; ++i)
      out[i] = detail::valid_query(origin, directions[i], t_max[i]) &&
               detail::occluded_bvh(s, origin, directions[i], t_max[i]);
    return;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for (std::size_t base = 0; base < count; base += 8) {
    const std::size_t n = std::min<std::size_t>(8, count - base);
    if (n <= 4)
      occluded_packet<4, RTCRay4>(s, a->rtc, context, origin, directions + base, t_max + base, n, out + base);
    else
      occluded_packet<8, RTCRay8>(s, a->rtc, context, origin, directions + base, t_max + base, n, out + base);
  }
}

bool intersect(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max,
               ray_hit& hit) noexcept {
  if (!detail::valid_query(origin, direction, t_max) || s.triangles().empty()) return false;
  const detail::ray_accel* a = detail::built(s);
  glm::vec3 d = direction;
  float t = t_max;
  const float back = a && a->rtc ? detail::fit_embree_range(origin, d, t) : 0.0f;
  if (back == 0.0f) return detail::intersect_bvh(s, origin, direction, t_max, hit);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  detail::set_ray(rh.ray, origin, d, t);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(a->rtc, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  const std::uint32_t i = rh.hit.primID;
  hit.distance = back == 1.0f ? rh.ray.tfar : rh.ray.tfar * back;  // in units of the caller's direction
  hit.drawable = i;
  hit.triangle = s.triangles()[i].index;
  // Embree's Ng is (v1 - v0) x (v2 - v0) up to scale: our front normal.
  hit.front_face = rh.hit.Ng_x * direction.x + rh.hit.Ng_y * direction.y + rh.hit.Ng_z * direction.z < 0.0f;
  return true;
}

}  // namespace hemilight
