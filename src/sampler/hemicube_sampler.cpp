// The cache's sampler factory (cache.hpp, make_hemicube_sampler): a hemicube per call, rendered
// and integrated with one context per worker, plus the optional directional projections
// (src/directional/).
#include "../core/hash.hpp"

#include "hl2_cone.hpp"
#include "sh_l1.hpp"

#include "hemilight/cache.hpp"

#include <cmath>
#include <cstring>
#include <memory>
#include <string>

namespace hemilight {

namespace {

// The options make_hemicube_sampler checks up front (the contexts are made later, by each worker).
void check_sampler_options(const std::shared_ptr<const scene>& s, const hemicube_sampler_options& o, int workers) {
  if (!s) throw_invalid_argument("make_hemicube_sampler: scene is null");
  if (workers < 1) throw_invalid_argument("make_hemicube_sampler: workers is " + std::to_string(workers) + "; it must be >= 1");
  if (o.sh_l1 && !o.integrate.rotation_gradient)
    throw_invalid_argument("make_hemicube_sampler: sh_l1 needs integrate.rotation_gradient (band 1 comes from it)");
}

// The options of the rasterizer and the integrator, checked now, once (the contexts are made by
// each worker on its first call).
void check_context_options(const std::shared_ptr<const scene>& s, const hemicube_sampler_options& o) {
  { hemicube_rasterizer check(s, o.raster); }
  check_hemicube_resolution(o.resolution, "make_hemicube_sampler");
  if (!(o.integrate.min_wall_distance >= 0.0f) || !std::isfinite(o.integrate.min_wall_distance))  // as hemicube_integrator
    throw_invalid_argument("make_hemicube_sampler: integrate.min_wall_distance is " + std::to_string(o.integrate.min_wall_distance) +
                           "; it must be finite and >= 0 (0 = automatic)");
}

// The hemicube's frame at (x, n): make_frame(n), with `roll` turned about n by an angle hashed
// from x's bits (deterministic; it turns the texel grid's aliasing into fine noise).
frame sample_frame(const glm::vec3& x, const glm::vec3& n, bool roll) {
  frame f = make_frame(n);
  if (roll) {
    std::uint32_t bits[3];
    std::memcpy(bits, &x, sizeof bits);
    const std::uint64_t h = core_detail::mix((std::uint64_t(bits[0]) << 32 | bits[1]) ^ core_detail::mix(bits[2]));
    const float angle = float(h >> 40) * (6.2831853f / float(1u << 24));
    const glm::vec3 t = std::cos(angle) * f.t + std::sin(angle) * f.b;
    f.b = glm::cross(f.n, t);
    f.t = t;
  }
  return f;
}

// One worker's rasterizer, integrator and buffer.
struct sampler_context {
  hemicube_rasterizer raster;
  hemicube_integrator integrator;
  hemicube_buffer buffer;
};

}  // namespace

irradiance_sampler make_hemicube_sampler(std::shared_ptr<const scene> s, const hemicube_sampler_options& o, int workers) {
  check_sampler_options(s, o, workers);
  std::shared_ptr<const hemicube_table> table = o.sh_l1 ? hemicube_table::get(o.resolution) : nullptr;
  std::shared_ptr<const directional_detail::cone_weights> cone_table =
      o.hl2_cone ? directional_detail::make_cone_weights(o.resolution) : nullptr;
  // One context per worker, made by the worker on its first call: a worker that never runs (a
  // cache of a few points on many threads) costs nothing. The options are checked now, once.
  check_context_options(s, o);
  auto contexts = std::make_shared<std::vector<std::unique_ptr<sampler_context>>>(static_cast<std::size_t>(workers));
  return [contexts, s, o, table, cone_table](int worker, const glm::vec3& x, const glm::vec3& n) -> cache_sample {
    if (worker < 0 || std::size_t(worker) >= contexts->size())
      throw_invalid_argument("hemicube sampler: worker " + std::to_string(worker) + " is out of range");
    std::unique_ptr<sampler_context>& slot = (*contexts)[std::size_t(worker)];
    if (!slot)
      slot = std::make_unique<sampler_context>(
          sampler_context{hemicube_rasterizer(s, o.raster), hemicube_integrator(o.resolution, o.integrate), {}});
    sampler_context& c = *slot;
    const frame f = sample_frame(x, n, o.roll);
    c.raster.render(x, f, o.resolution, c.buffer, o.texture);
    cache_sample out = c.integrator.integrate(c.buffer);
    if (cone_table) out.cone = directional_detail::project_hl2_cone(c.buffer, *cone_table, f.t);
    if (o.sh_l1) out.sh_l1 = directional_detail::project_sh_l1(c.buffer, *table, out.irradiance, out.rotation_gradient, f.n);
    return out;
  };
}

}  // namespace hemilight
