// make_hemicube_sampler and validate_sampler_options (sampler.hpp): a hemicube per call, rendered
// and integrated with one context per worker, plus the optional directional projections and
// ambient occlusion.
#include "../core/hash.hpp"

#include "ao.hpp"
#include "hl2_cone.hpp"
#include "sh_l1.hpp"

#include "hemilight/sampler.hpp"

#include <cmath>
#include <cstring>
#include <memory>
#include <string>

namespace hemilight {

namespace {

// The arguments make_hemicube_sampler checks up front (the contexts are made later, by each worker).
void check_sampler_arguments(const std::shared_ptr<const scene>& s, const sampler_options& o, int workers, const sampler_pass& pass) {
  if (!s) throw_invalid_argument("make_hemicube_sampler: scene is null");
  if (workers < 1) throw_invalid_argument("make_hemicube_sampler: workers is " + std::to_string(workers) + "; it must be >= 1");
  if (pass.sh_l1 && !o.integrate.rotation_gradient)
    throw_invalid_argument("make_hemicube_sampler: sh_l1 needs integrate.rotation_gradient (band 1 comes from it)");
  if (!(pass.ao_distance >= 0.0f) || !std::isfinite(pass.ao_distance))
    throw_invalid_argument("make_hemicube_sampler: ao_distance is " + std::to_string(pass.ao_distance) +
                           "; it must be finite and >= 0 (0 = no ambient occlusion)");
  validate_sampler_options(o, "make_hemicube_sampler");
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

void validate_sampler_options(const sampler_options& o, const std::string& who) {
  check_hemicube_resolution(o.resolution, who.c_str());
  validate_raster_options(o.raster, who + ": raster");
  validate_integrate_options(o.integrate, who + ": integrate");
}

irradiance_sampler make_hemicube_sampler(std::shared_ptr<const scene> s, const sampler_options& o, int workers,
                                         const sampler_pass& pass) {
  check_sampler_arguments(s, o, workers, pass);
  std::shared_ptr<const hemicube_table> table = pass.sh_l1 ? hemicube_table::get(o.resolution) : nullptr;
  std::shared_ptr<const sampler_detail::cone_weights> cone_table =
      pass.hl2_cone ? sampler_detail::make_cone_weights(o.resolution) : nullptr;
  std::shared_ptr<const sampler_detail::ao_weights> ao_table =
      pass.ao_distance > 0.0f ? sampler_detail::make_ao_weights(o.resolution) : nullptr;
  // One context per worker, made by the worker on its first call: a worker that never runs (a
  // cache of a few points on many threads) costs nothing.
  auto contexts = std::make_shared<std::vector<std::unique_ptr<sampler_context>>>(static_cast<std::size_t>(workers));
  return [contexts, s, o, pass, table, cone_table, ao_table](int worker, const glm::vec3& x, const glm::vec3& n) -> sampler_result {
    if (worker < 0 || std::size_t(worker) >= contexts->size())
      throw_invalid_argument("hemicube sampler: worker " + std::to_string(worker) + " is out of range");
    std::unique_ptr<sampler_context>& slot = (*contexts)[std::size_t(worker)];
    if (!slot)
      slot = std::make_unique<sampler_context>(
          sampler_context{hemicube_rasterizer(s, o.raster), hemicube_integrator(o.resolution, o.integrate), {}});
    sampler_context& c = *slot;
    const frame f = sample_frame(x, n, o.roll);
    c.raster.render(x, f, o.resolution, c.buffer, pass.texture);
    sampler_result out = c.integrator.integrate(c.buffer);
    if (cone_table) out.cone = sampler_detail::project_hl2_cone(c.buffer, *cone_table, f.t);
    if (pass.sh_l1) out.sh_l1 = sampler_detail::project_sh_l1(c.buffer, *table, out.irradiance, out.rotation_gradient, f.n);
    if (ao_table) out.ao = sampler_detail::unoccluded_fraction(c.buffer, *ao_table, pass.ao_distance);
    return out;
  };
}

}  // namespace hemilight
