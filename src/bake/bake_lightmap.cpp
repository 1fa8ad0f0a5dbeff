// The baker's passes (pipeline.hpp: steps 2-4 and the chain bake_samples) and bake_lightmap,
// bake_radiance_texture (bake.hpp).
#include "checks.hpp"
#include "dilate.hpp"
#include "pipeline.hpp"

#include "hemilight/parallel.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/rays.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace hemilight {

namespace bake_detail {

namespace {

constexpr float pi_f = 3.14159265358979323846f;

}  // namespace

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Step 2 of bake.hpp: the sampled texels, offset along their normals.
sample_points place_samples(const sparse_samples& s, const scene& sc, const bake_options& o, const bake_layout& layout,
                            bake_result& r) {
  const std::size_t texels = std::size_t(layout.width) * std::size_t(layout.height);
  const float min_offset = 2.0f * default_near_distance(sc);
  sample_points out;
  r.coverage.assign(texels, 0.0f);
  r.sampled.assign(texels, 0);
  for (std::size_t n = 0; n < s.size(); ++n) {
    const std::size_t k = s.texel[n];
    r.coverage[k] = s.coverage[n];
    if (s.coverage[n] > 0.0f) ++r.stats.covered_texels;
    if (s.sample_triangle[n] == lightmap_samples::no_triangle || !(s.coverage[n] >= o.min_coverage) || !(s.coverage[n] > 0.0f))
      continue;
    r.sampled[k] = 1;
    out.texel_of.push_back(k);
    const float offset = std::max(min_offset, o.offset_texels * s.texel_world_size[n]);
    out.positions.push_back(s.position[n] + offset * s.normal[n]);
    out.normals.push_back(s.normal[n]);
    out.owner.push_back(s.owner[n]);
    out.tangents.push_back(s.tangent[n]);
    out.bitangents.push_back(s.bitangent[n]);
    out.spacing.push_back(s.texel_world_size[n] > 0.0f && std::isfinite(s.texel_world_size[n]) ? s.texel_world_size[n] : offset);
  }
  r.stats.sampled_texels = out.texel_of.size();
  if (out.texel_of.empty())
    throw_invalid_argument(std::string(layout.who) + ": no texel is covered by a triangle (coverage >= min_coverage): nothing to bake");
  return out;
}

invalid_filler::invalid_filler(const sample_points& pts, const std::vector<std::uint8_t>& invalid, const bake_layout& layout)
    : pts_(pts), invalid_(invalid), layout_(layout), filled_(std::size_t(layout.width) * std::size_t(layout.height), 0),
      blocked_(filled_.size(), 1) {
  for (std::size_t i = 0; i < invalid.size(); ++i) {
    if (!invalid[i]) filled_[pts.texel_of[i]] = 1;
    blocked_[pts.texel_of[i]] = 0;
    any_ = any_ || invalid[i];
  }
}

void invalid_filler::operator()(std::vector<glm::vec3>& values) const {
  if (!any_) return;
  const std::size_t count = pts_.texel_of.size();
  image tmp = image::make(layout_.width, layout_.height, 3);
  for (std::size_t i = 0; i < count; ++i) std::memcpy(tmp.pixels.data() + 3 * pts_.texel_of[i], &values[i], sizeof(glm::vec3));
  std::vector<std::uint8_t> f = filled_;
  dilate_masked(tmp, f, -1, blocked_.data());
  for (std::size_t i = 0; i < count; ++i)
    if (invalid_[i]) std::memcpy(&values[i], tmp.pixels.data() + 3 * pts_.texel_of[i], sizeof(glm::vec3));
}

// Samples inside geometry get the values of the valid texels around them (invalid_filler). Used
// by both modes.
void fill_invalid_samples(const sample_points& pts, pass_values& v, const bake_layout& layout) {
  const invalid_filler fill(pts, v.invalid, layout);
  if (!fill.needed()) return;
  const std::size_t count = pts.texel_of.size();
  fill(v.e);
  for (auto& plane : v.sh)
    if (!plane.empty()) fill(plane);
  if (!v.cone.empty()) {
    // Cone coefficients term by term (neighbours on a chart share the normal and so the
    // reference tangent).
    std::vector<glm::vec3> plane(count);
    for (std::size_t t = 0; t < std::size_t(hl2_cone_terms); ++t) {
      for (std::size_t i = 0; i < count; ++i) plane[i] = v.cone[i].coefficients[t];
      fill(plane);
      for (std::size_t i = 0; i < count; ++i) v.cone[i].coefficients[t] = plane[i];
    }
  }
}

// Step 4's radiance texture for pass k > 1: emission + albedo E_{k-1} / pi of each texel's owner
// (or of the layout's per-texel images), dilated (at least 2 rings) so that hemicubes looking at
// chart borders do not see black; then the occluder blocks and the guards. With e = null (pass 1
// of a bake with emission images): the emission alone.
image pass_radiance_texture(const scene& sc, const sample_points& pts, const std::vector<glm::vec3>* e, const bake_options& o,
                            const bake_layout& layout) {
  image texture = image::make(layout.width, layout.height, 3);
  std::vector<std::uint8_t> filled(texture.pixels.size() / 3, 0);
  for (std::size_t i = 0; i < pts.texel_of.size(); ++i) {
    const std::size_t k = pts.texel_of[i];
    const material& m = sc.triangle_material(pts.owner[i]);
    const glm::vec3 emission = layout.emission.empty() ? m.emission : layout.emission[k];
    const glm::vec3 albedo = layout.albedo.empty() ? m.albedo : layout.albedo[k];
    const glm::vec3 l = e ? emission + albedo * (*e)[i] / pi_f : emission;
    std::memcpy(texture.pixels.data() + 3 * k, &l, sizeof l);
    filled[k] = 1;
  }
  dilate_masked(texture, filled, o.dilation < 0 ? -1 : std::max(o.dilation, 2), layout.blocked_mask());
  if (!layout.occluders.empty()) {
    // The occluders' coarse estimate: the mean irradiance of the samples of the previous pass.
    glm::dvec3 sum(0.0);
    if (e && layout.occluders_reflect)
      for (const glm::vec3& v : *e) sum += glm::dvec3(v);
    const glm::vec3 mean = pts.texel_of.empty() ? glm::vec3(0.0f) : glm::vec3(sum / double(pts.texel_of.size()));
    for (const occluder_block& b : layout.occluders) {
      const glm::vec3 l = b.emission + b.albedo * mean / pi_f;
      for (std::size_t k : b.texels) std::memcpy(texture.pixels.data() + 3 * k, &l, sizeof l);
    }
  }
  for (const auto& g : layout.guards)
    std::memcpy(texture.pixels.data() + 3 * g.first, texture.pixels.data() + 3 * g.second, 3 * sizeof(float));
  return texture;
}

namespace {

// The cache's cheap inside test of its seeds (cache_run::inside_test): rays in 16 fixed directions
// spread evenly over the projected solid angle of the point's hemisphere (a golden-angle spiral);
// the point is inside when 8 or more of them hit back faces (the hemicube's backface fraction,
// estimated: a point seeing at most invalid_backface_fraction = 10% of back faces has about one
// chance in 10^4 to be called inside); it stops as soon as the answer is known.
std::function<bool(int, const glm::vec3&, const glm::vec3&)> rays_inside_test(const std::shared_ptr<const scene>& sc) {
  constexpr int rays = 16, needed = 8;
  std::array<glm::vec3, rays> local;
  for (int k = 0; k < rays; ++k) {
    const float u = (float(k) + 0.5f) / float(rays), r = std::sqrt(u), phi = 2.39996323f * float(k);
    local[std::size_t(k)] = glm::vec3(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u)));
  }
  prepare_rays(*sc);
  const float t_max = 4.0f * std::max(sc->size(), 1e-6f);
  // The rays start at the hemicube's near distance, which hides nearer geometry from hemicubes.
  const float near = default_near_distance(*sc);
  return [sc, local, t_max, near](int, const glm::vec3& p, const glm::vec3& n) {
    const frame f = make_frame(n);
    int back = 0, other = 0;
    for (const glm::vec3& l : local) {
      ray_hit hit;
      const glm::vec3 d = f.to_world(l);
      if (intersect(*sc, p + near * d, d, t_max, hit) && !hit.front_face)
        ++back;
      else
        ++other;
      if (back >= needed) return true;
      if (other > rays - needed) return false;
    }
    return false;
  };
}

// One pass through the cache (bake_options::use_cache); with `ao`, the records carry the
// sampler's ambient occlusion and every sample gets its interpolation.
pass_values cached_pass(const sample_points& pts, const irradiance_sampler& sampler, const cache_options& co, cache_run run,
                        bool directional, bool ao, const std::function<bool(float)>& progress, bake_stats& stats) {
  const std::size_t count = pts.texel_of.size();
  run.directional = directional;
  run.ao = ao;
  run.fill_invalid = false;  // fill_invalid_samples dilates valid texels into them instead
  if (progress) run.progress = progress;
  cache_result cr = cache_irradiance(pts.positions.data(), pts.normals.data(), count, sampler, co, run);
  pass_values v;
  v.e = std::move(cr.irradiance);
  v.invalid.resize(count);
  for (std::size_t i = 0; i < count; ++i) v.invalid[i] = cr.valid[i] ? 0 : 1;
  if (directional) {
    for (auto& plane : v.sh) plane.resize(count);
    for (std::size_t i = 0; i < count; ++i)
      for (std::size_t c = 0; c < 4; ++c) v.sh[c][i] = cr.sh_l1[i][c];
    v.cone = std::move(cr.cone);
  }
  v.ao = std::move(cr.ao);
  stats.hemicubes += cr.stats.hemicubes;
  stats.records += cr.stats.records;
  stats.passes.push_back(cr.stats);
  return v;
}

// One pass with a hemicube at every sample (use_cache = false: the reference), in blocks so that
// progress and cancellation stay live.
pass_values per_texel_pass(const sample_points& pts, const irradiance_sampler& sampler, const bake_options& o,
                           bool directional, bool ao, const std::function<bool(float)>& progress, bake_stats& stats) {
  const auto tp = std::chrono::steady_clock::now();
  const std::size_t count = pts.texel_of.size();
  pass_values v;
  v.e.resize(count);
  v.invalid.assign(count, 0);
  if (directional) {
    for (auto& plane : v.sh) plane.assign(count, glm::vec3(0.0f));
    v.cone.assign(count, hl2_cone{});
  }
  if (ao) v.ao.assign(count, 0.0f);
  const std::size_t block = 2048;
  for (std::size_t b = 0; b < count; b += block) {
    if (progress && !progress(float(b) / float(count)))
      throw error(status::cancelled, "bake_lightmap: cancelled by the progress callback");
    const std::size_t end = std::min(count, b + block);
    parallel_for(end - b, o.thread_count, 16, [&](int worker, std::size_t lo, std::size_t hi) {
      for (std::size_t i = b + lo; i < b + hi; ++i) {
        const sampler_result smp = sampler(worker, pts.positions[i], pts.normals[i]);
        v.e[i] = smp.irradiance;
        v.invalid[i] = smp.backface_fraction > o.cache.invalid_backface_fraction ? 1 : 0;
        if (directional) {
          for (std::size_t c = 0; c < 4; ++c) v.sh[c][i] = smp.sh_l1[c];
          v.cone[i] = rotate_hl2_cone(smp.cone, pts.normals[i], make_frame(pts.normals[i]).t);
        }
        if (ao) v.ao[i] = smp.ao;
      }
    });
  }
  std::size_t invalid = 0;
  for (std::uint8_t f : v.invalid) invalid += f;
  cache_stats cs;
  cs.hemicubes = count;
  cs.records = count;
  cs.invalid_samples = invalid;
  cs.invalid_points = invalid;
  cs.seconds = seconds_since(tp);
  stats.hemicubes += count;
  stats.records += count;
  stats.passes.push_back(cs);
  return v;
}

// What pass `pass`'s hemicubes compute besides irradiance (the radiance texture aside):
// directional projections only where their result is used: the last pass, and the first when the
// indirect part is wanted (last minus first). The cheap SH of sampler.hpp, not the integrator's
// directional pass. Ambient occlusion in the first pass only (the geometry is the same in every
// pass, so later passes' hemicubes would see the same distances).
sampler_pass pass_outputs(const bake_options& o, bool pass_directional, bool first_pass) {
  sampler_pass pass;
  pass.sh_l1 = pass_directional && o.output_sh_l1;
  pass.hl2_cone = pass_directional && o.output_hl2;
  pass.ao_distance = first_pass ? o.ao_distance : 0.0f;
  return pass;
}

}  // namespace

pass_values hemicube_pass(const sample_points& pts, const std::shared_ptr<const scene>& sc, const bake_options& o, int pass,
                          const radiance_texture* texture, const std::uint8_t* known_inside,
                          const std::function<bool(float)>& progress, bake_stats& stats) {
  const bool directional = (o.output_sh_l1 || o.output_hl2) && (pass == o.bounces - 1 || (pass == 0 && o.indirect_only));
  sampler_pass request = pass_outputs(o, directional, pass == 0);
  request.texture = texture;
  const bool ao = request.ao_distance > 0.0f;
  if (pts.texel_of.empty()) {  // a shard without samples
    pass_values v;
    stats.passes.push_back(cache_stats{});
    return v;
  }
  const irradiance_sampler sampler = make_hemicube_sampler(sc, o.sampler, resolve_thread_count(o.thread_count), request);
  if (!o.use_cache) return per_texel_pass(pts, sampler, o, directional, ao, progress, stats);
  cache_run run;
  run.thread_count = o.thread_count;
  run.point_spacing = pts.spacing.data();
  run.inside_test = rays_inside_test(sc);
  // No record reaches across a wall (cache_run::segment_blocked): one any-hit ray.
  run.segment_blocked = [sc](const glm::vec3& from, const glm::vec3& to) { return occluded(*sc, from, to - from, 1.0f); };
  run.known_inside = known_inside;
  return cached_pass(pts, sampler, o.cache, run, directional, ao, progress, stats);
}

namespace {

// The bake's progress through the callback (if any): the cache's fraction can step back between
// rounds; the bake reports the running maximum.
class bake_progress {
 public:
  explicit bake_progress(const std::function<bool(float)>& callback) : callback_(callback) {}
  explicit operator bool() const { return bool(callback_); }
  // Reports min(f, 1) (or what was reported before, if more); false: the caller cancels.
  bool operator()(float f) {
    reported_ = std::max(reported_, std::min(f, 1.0f));
    return callback_(reported_);
  }
  // Reports f, throwing error(cancelled) if the callback returns false (nothing if there is none).
  void check(float f) {
    if (callback_ && !(*this)(f)) throw error(status::cancelled, "bake_lightmap: cancelled by the progress callback");
  }

 private:
  const std::function<bool(float)>& callback_;
  float reported_ = 0.0f;
};

}  // namespace

// Step 3b with its timing: the lights' values at every sample, or nothing without lights.
direct_values lights_at_samples(const sample_points& pts, const scene& sc, const light_set& lights, const bake_options& o,
                                bake_stats& stats) {
  direct_values direct;
  if (lights.empty()) return direct;
  const auto td = std::chrono::steady_clock::now();
  // The ray structure now, so that an Embree failure is an error here, not a slower fallback.
  prepare_rays(sc);
  std::function<bool()> keep_going;
  if (o.progress) keep_going = [&] { return o.progress(0.0f); };
  direct = direct_pass(pts, sc, lights, o, keep_going);
  stats.direct_seconds = seconds_since(td);
  return direct;
}

// The ambient occlusion at samples inside geometry (valid = 0 after all passes: the set the last
// pass's irradiance was filled at, since later passes take the earlier ones' invalid samples as
// known inside) from the valid texels around them in their own chart (invalid_filler).
void fill_invalid_ao(const sample_points& pts, const std::vector<std::uint8_t>& valid, const bake_layout& layout,
                     std::vector<float>& ao) {
  std::vector<std::uint8_t> invalid(valid.size());
  for (std::size_t i = 0; i < valid.size(); ++i) invalid[i] = valid[i] ? 0 : 1;
  const invalid_filler fill(pts, invalid, layout);
  if (!fill.needed()) return;
  std::vector<glm::vec3> plane(ao.size());
  for (std::size_t i = 0; i < ao.size(); ++i) plane[i] = glm::vec3(ao[i]);
  fill(plane);
  for (std::size_t i = 0; i < ao.size(); ++i) ao[i] = plane[i].x;
}

namespace {

// What the bounce passes leave: the last pass's values, the first's (with indirect_only), the
// first pass's ambient occlusion (with ao_distance; filled where the sample is inside geometry),
// and per sample whether every pass found it valid (outside geometry).
struct bounce_values {
  pass_values last, first;
  std::vector<float> ao;
  std::vector<std::uint8_t> valid;
};

// Step 3 and 4: o.bounces passes, each through the cache (or a hemicube per sample) over the
// radiance texture of the previous pass's values (pass 1: the scene's emission, or the layout's
// emission images), plus the lights, with samples inside geometry filled from their chart.
bounce_values bounce_passes(const sample_points& pts, const std::shared_ptr<const scene>& sc, const bake_options& o,
                            const bake_layout& layout, const direct_values* direct, bake_progress& report, bake_stats& stats) {
  const std::size_t count = pts.texel_of.size();
  bounce_values out;
  out.valid.assign(count, 1);
  std::vector<std::uint8_t> inside(count, 0);  // per sample: found inside geometry by an earlier pass
  pass_values& current = out.last;
  image texture;
  radiance_texture texture_view;
  for (int pass = 0; pass < o.bounces; ++pass) {
    report.check(float(pass) / float(o.bounces));
    const radiance_texture* view = nullptr;
    if (pass > 0 || layout.textured_first_pass) {
      texture = pass_radiance_texture(*sc, pts, pass > 0 ? &current.e : nullptr, o, layout);
      texture_view = radiance_texture(texture);
      view = &texture_view;
    }
    const float base = float(pass) / float(o.bounces), span = 1.0f / float(o.bounces);
    std::function<bool(float)> pass_progress;
    if (report) pass_progress = [&](float f) { return report(base + span * f); };
    // Points an earlier pass found inside geometry are inside in this one too (the geometry is
    // the same): the cache renders no hemicube for them.
    const std::uint8_t* known_inside = nullptr;
    if (pass > 0) {
      for (std::size_t i = 0; i < count; ++i) inside[i] = std::uint8_t(out.valid[i] ? 0 : 1);
      known_inside = inside.data();
    }
    current = hemicube_pass(pts, sc, o, pass, view, known_inside, pass_progress, stats);
    if (!current.ao.empty()) out.ao = std::move(current.ao);
    merge_pass(pts, direct, layout, current, out.valid);
    if (pass == 0 && o.indirect_only) out.first = current;
  }
  return out;
}

}  // namespace

void merge_pass(const sample_points& pts, const direct_values* direct, const bake_layout& layout, pass_values& v,
                std::vector<std::uint8_t>& valid) {
  if (direct) add_direct(*direct, v);
  fill_invalid_samples(pts, v, layout);
  for (std::size_t i = 0; i < valid.size(); ++i) valid[i] = std::uint8_t(valid[i] & (v.invalid[i] ? 0 : 1));
}

void finish_samples(const sample_points& pts, const pass_values& last, const pass_values* first, direct_values* direct,
                    std::vector<float>& ao, const std::vector<std::uint8_t>& valid, const bake_options& o,
                    const bake_layout& layout, bake_result& r, std::vector<std::uint8_t>& filled) {
  if (!ao.empty()) fill_invalid_ao(pts, valid, layout, ao);
  if (direct) fill_direct_outputs(pts, valid, layout, *direct);
  write_outputs(pts, last, first, direct, ao, valid, o, layout, r, filled);
}

bake_result bake_samples(sparse_samples s, const std::shared_ptr<const scene>& sc, const bake_options& o,
                         const bake_layout& layout, std::chrono::steady_clock::time_point t0, std::vector<std::uint8_t>& filled) {
  bake_result r;
  r.stats.texels = std::size_t(layout.width) * std::size_t(layout.height);
  r.stats.coverage_seconds = seconds_since(t0);
  r.stats.overlapping_texels = s.overlapping_texels;
  r.stats.degenerate_triangles = s.degenerate_triangles;
  r.stats.no_uv_area_triangles = s.no_uv_area_triangles;
  r.stats.first_no_uv_area_triangle = s.first_no_uv_area_triangle;
  const sample_points pts = place_samples(s, *sc, o, layout, r);
  s = sparse_samples{};  // what the passes need is in pts now
  const light_set lights(o.lights.data(), o.lights.size());
  direct_values direct = lights_at_samples(pts, *sc, lights, o, r.stats);
  direct_values* lit = lights.empty() ? nullptr : &direct;
  bake_progress report(o.progress);
  bounce_values v = bounce_passes(pts, sc, o, layout, lit, report, r.stats);
  report.check(1.0f);
  finish_samples(pts, v.last, o.indirect_only ? &v.first : nullptr, lit, v.ao, v.valid, o, layout, r, filled);
  r.stats.seconds = seconds_since(t0);
  return r;
}

}  // namespace bake_detail

image bake_radiance_texture(const bake_input& input, const bake_options& o, const bake_result& r) {
  if (o.indirect_only)
    throw_invalid_argument("bake_radiance_texture: the bake is indirect_only: its irradiance lacks the first bounce");
  if (r.irradiance.width != o.width || r.irradiance.height != o.height || r.sampled.size() != std::size_t(o.width) * std::size_t(o.height))
    throw_invalid_argument("bake_radiance_texture: the result's size does not match options (" + std::to_string(o.width) + " x " +
                           std::to_string(o.height) + ")");
  bake_detail::check_input("bake_radiance_texture", input);
  bake_detail::clamped_input checked;
  bake_detail::clamp_lightmap_uvs("bake_radiance_texture", input, checked);
  const bake_detail::sparse_samples s =
      bake_detail::compute_sparse_samples(checked.input, o.width, o.height, o.strict, "bake_radiance_texture");
  image texture = image::make(o.width, o.height, 3);
  std::vector<std::uint8_t> filled(texture.pixels.size() / 3, 0);
  for (std::size_t n = 0; n < s.size(); ++n) {
    const std::size_t k = s.texel[n];
    if (!r.sampled[k]) continue;
    const material m = input.scene.materials ? input.scene.materials[s.owner[n]] : material{};
    const glm::vec3 e(r.irradiance.pixels[3 * k], r.irradiance.pixels[3 * k + 1], r.irradiance.pixels[3 * k + 2]);
    const glm::vec3 l = m.emission + m.albedo * e / bake_detail::pi_f;
    std::memcpy(texture.pixels.data() + 3 * k, &l, sizeof l);
    filled[k] = 1;
  }
  dilate(texture, filled, o.dilation < 0 ? -1 : std::max(o.dilation, 2));
  return texture;
}

bake_result bake_lightmap(const bake_input& input, const bake_options& o) {
  const char* who = "bake_lightmap";
  const auto t0 = std::chrono::steady_clock::now();
  bake_detail::check_options(o);
  bake_detail::check_input(who, input);
  bake_detail::clamped_input checked;
  bake_detail::clamp_lightmap_uvs(who, input, checked);
  const std::shared_ptr<const scene> sc = scene::create(checked.input.scene);
  bake_detail::check_environment(who, o);
  bake_detail::bake_layout layout;
  layout.width = o.width;
  layout.height = o.height;
  double seam_seconds = 0.0;
  if (o.stitch_seams) {
    const auto ts = std::chrono::steady_clock::now();
    layout.seams = bake_detail::lightmap_seams(checked.input, o.width, o.height, seam_stitch_degrees, *sc);
    layout.seam_pages = {bake_detail::page_rect{0, 0, o.width, o.height}};
    seam_seconds = bake_detail::seconds_since(ts);
  }
  std::vector<std::uint8_t> filled;
  bake_result r = bake_detail::bake_samples(bake_detail::compute_sparse_samples(checked.input, o.width, o.height, o.strict, who),
                                            sc, o, layout, t0, filled);
  r.stats.clamped_uvs = checked.clamped;
  if (checked.clamped > 0) r.stats.warnings.push_back(checked.warning);
  if (r.stats.no_uv_area_triangles > 0)
    r.stats.warnings.push_back(bake_detail::no_uv_area_warning(
        who, r.stats.no_uv_area_triangles, "triangle " + std::to_string(r.stats.first_no_uv_area_triangle)));
  r.stats.stitch_seconds += seam_seconds;
  return r;
}

}  // namespace hemilight
