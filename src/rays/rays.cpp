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

// The context of every query: Embree hands it to the see-through geometry's filter functions
// (the first member is Embree's own context, so a pointer to one is a pointer to the other).
struct filter_context {
  RTCIntersectContext base;
  const scene* s = nullptr;
  bool transmit = false;     // a transmittance query: translucent hits are multiplied in and passed
  glm::vec3 through{1.0f};   // the product so far
  static constexpr int max_seen = 16;
  // The translucent layers already multiplied in: (primitive, t, triangle). Embree may report a
  // primitive twice, and a ray through an edge two triangles of one pane share hits both.
  struct layer {
    std::uint32_t prim;
    float t;
    std::uint32_t triangle;
  };
  layer seen[max_seen];
  int seen_count = 0;

  filter_context(const scene& sc, bool transmittance) noexcept : s(&sc), transmit(transmittance) { rtcInitIntersectContext(&base); }
  bool first_time(std::uint32_t prim, float t, std::uint32_t triangle) noexcept {
    for (int k = 0; k < seen_count; ++k)
      if (seen[k].prim == prim || same_layer(*s, seen[k].triangle, seen[k].t, triangle, t)) return false;
    if (seen_count < max_seen) seen[seen_count++] = {prim, t, triangle};
    return true;
  }
};

// The filter function of the see-through geometry (1), for intersect and occluded queries: an
// alpha-tested hit stands only where the triangle is present; a translucent hit stands (a surface),
// except in a transmittance query, where it multiplies its transmittance in and is passed while
// some light still gets through.
void see_through_filter(const RTCFilterFunctionNArguments* args) {
  auto* ctx = reinterpret_cast<filter_context*>(args->context);
  const scene& s = *ctx->s;
  const std::vector<scene::triangle>& tris = s.see_through_triangles();
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const std::uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
    const std::uint32_t t = tris[prim].index;
    const material& m = s.triangle_material(t);
    if (m.opacity != surface_opacity::translucent) {
      // Embree's (u, v) are the barycentrics of v1 and v2: scene::alpha_present's (b1, b2).
      if (!s.alpha_present(t, RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i))) args->valid[i] = 0;
      continue;
    }
    if (!ctx->transmit) continue;
    if (ctx->first_time(prim, RTCRayN_tfar(args->ray, args->N, i), t)) ctx->through *= m.transmittance;
    if (ctx->through != glm::vec3(0.0f)) args->valid[i] = 0;
  }
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

// Attaches `tris` (scene::triangle entries over s's vertices) to rtc as geometry `id`, primitive
// i = tris[i]; with `filter`, the see-through filter function and the scene as its user data.
// False when Embree could not allocate its buffers (its error code says why).
bool attach_triangles(RTCDevice device, RTCScene rtc, const scene& s, const std::vector<scene::triangle>& tris, unsigned id,
                      bool filter) {
  const std::vector<glm::vec3>& positions = s.positions();
  const std::vector<std::uint32_t>& indices = s.indices();
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
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
    if (filter) {
      rtcSetGeometryIntersectFilterFunction(g, see_through_filter);
      rtcSetGeometryOccludedFilterFunction(g, see_through_filter);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(rtc, g, id);
  }
  if (g) rtcReleaseGeometry(g);
  return ib != nullptr;
}

// Builds a's Embree scene from s's drawable triangles (geometry 0, primitive i = triangles()[i];
// geometry 1, primitive j = see_through_triangles()[j]). Never throws: a failure is kept in a
// (status, message) and the queries use the fallback.
void build(const scene& s, ray_accel& a) noexcept {
  if (s.drawable_triangle_count() == 0) return;  // nothing to hit: no Embree at all
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
    if (!s.see_through_triangles().empty() && rtcGetDeviceProperty(d.device, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED) == 0) {
      a.failure = status::unsupported;
      a.message = "prepare_rays: this Embree was built without filter functions, which see-through triangles need";
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
    // Geometry 0: the opaque triangles; geometry 1: the see-through ones, with the filter function.
    const bool opaque_ok = s.triangles().empty() || attach_triangles(d.device, rtc, s, s.triangles(), 0, false);
    const bool see_ok = opaque_ok && (s.see_through_triangles().empty() ||
                                      attach_triangles(d.device, rtc, s, s.see_through_triangles(), 1, true));
    if (see_ok) rtcCommitScene(rtc);
    e = rtcGetDeviceError(d.device);
    if (!see_ok || e != RTC_ERROR_NONE) {
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

namespace detail {
namespace {
// The fallback's answers: the opaque BVH, then the see-through triangles.
bool occluded_fallback(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept {
  return occluded_bvh(s, origin, direction, t_max) || see_through_occluded(s, origin, direction, t_max);
}
}  // namespace
}  // namespace detail

bool occluded(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept {
  if (!detail::valid_query(origin, direction, t_max) || s.drawable_triangle_count() == 0) return false;
  const detail::ray_accel* a = detail::built(s);
  glm::vec3 d = direction;
  float t = t_max;
  if (!a || !a->rtc || detail::fit_embree_range(origin, d, t) == 0.0f)
    return detail::occluded_fallback(s, origin, direction, t_max);
  detail::filter_context context(s, false);
  RTCRay r;
  detail::set_ray(r, origin, d, t);
  rtcOccluded1(a->rtc, &context.base, &r);
  return r.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

glm::vec3 transmittance(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max) noexcept {
  if (!detail::valid_query(origin, direction, t_max) || s.drawable_triangle_count() == 0) return glm::vec3(1.0f);
  const detail::ray_accel* a = detail::built(s);
  glm::vec3 d = direction;
  float t = t_max;
  if (!a || !a->rtc || detail::fit_embree_range(origin, d, t) == 0.0f) {
    if (detail::occluded_bvh(s, origin, direction, t_max)) return glm::vec3(0.0f);
    return detail::see_through_transmittance(s, origin, direction, t_max);
  }
  detail::filter_context context(s, true);
  RTCRay r;
  detail::set_ray(r, origin, d, t);
  rtcOccluded1(a->rtc, &context.base, &r);
  return r.tfar < 0.0f ? glm::vec3(0.0f) : context.through;
}

namespace {

// One Embree packet of up to N rays from `origin` (N = 4 or 8: RTCRay4 / RTCRay8), lanes past
// `count` and invalid rays inactive (valid mask 0, answered false without tracing).
template <std::size_t N, class Packet>
void occluded_packet(const scene& s, RTCScene rtc, RTCIntersectContext* context, const glm::vec3& origin,
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
      rtcOccluded8(valid, rtc, context, &r);
    else
      rtcOccluded4(valid, rtc, context, &r);
  }
  for (std::size_t j = 0; j < count; ++j)
    out[j] = outside[j] ? detail::occluded_fallback(s, origin, directions[j], t_max[j])
                        : valid[j] != 0 && r.tfar[j] < 0.0f;  // tfar = -inf on a hit
}

}  // namespace

void occluded_many(const scene& s, const glm::vec3& origin, const glm::vec3* directions, const float* t_max,
                   std::size_t count, bool* out) noexcept {
  if (count == 0) return;
  if (s.drawable_triangle_count() == 0 || !detail::finite3(origin)) {
    for (std::size_t i = 0; i < count; ++i) out[i] = false;
    return;
  }
  const detail::ray_accel* a = detail::built(s);
  if (!a || !a->rtc) {
    for (std::size_t i = 0; i < count; ++i)
      out[i] = detail::valid_query(origin, directions[i], t_max[i]) &&
               detail::occluded_fallback(s, origin, directions[i], t_max[i]);
    return;
  }
  detail::filter_context context(s, false);
  for (std::size_t base = 0; base < count; base += 8) {
    const std::size_t n = std::min<std::size_t>(8, count - base);
    if (n <= 4)
      occluded_packet<4, RTCRay4>(s, a->rtc, &context.base, origin, directions + base, t_max + base, n, out + base);
    else
      occluded_packet<8, RTCRay8>(s, a->rtc, &context.base, origin, directions + base, t_max + base, n, out + base);
  }
}

bool intersect(const scene& s, const glm::vec3& origin, const glm::vec3& direction, float t_max,
               ray_hit& hit) noexcept {
  if (!detail::valid_query(origin, direction, t_max) || s.drawable_triangle_count() == 0) return false;
  const detail::ray_accel* a = detail::built(s);
  glm::vec3 d = direction;
  float t = t_max;
  const float back = a && a->rtc ? detail::fit_embree_range(origin, d, t) : 0.0f;
  if (back == 0.0f) {
    const bool opaque = detail::intersect_bvh(s, origin, direction, t_max, hit);
    return detail::see_through_closest(s, origin, direction, opaque ? hit.distance : t_max, hit) || opaque;
  }
  detail::filter_context context(s, false);
  RTCRayHit rh;
  detail::set_ray(rh.ray, origin, d, t);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(a->rtc, &context.base, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  const std::uint32_t i = rh.hit.primID;
  const bool see_through = rh.hit.geomID == 1;
  hit.distance = back == 1.0f ? rh.ray.tfar : rh.ray.tfar * back;  // in units of the caller's direction
  hit.drawable = see_through ? static_cast<std::uint32_t>(s.triangles().size()) + i : i;
  hit.triangle = see_through ? s.see_through_triangles()[i].index : s.triangles()[i].index;
  // Embree's Ng is (v1 - v0) x (v2 - v0) up to scale: our front normal.
  hit.front_face = rh.hit.Ng_x * direction.x + rh.hit.Ng_y * direction.y + rh.hit.Ng_z * direction.z < 0.0f;
  return true;
}

}  // namespace hemilight
