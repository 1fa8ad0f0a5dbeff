// The sharded scene bake (shards.hpp): the bake's set-up and partition (make_shard_plan), one
// job (run_shard: the pass's hemicubes and, in pass 1, the lights at the shard's samples), and
// the merges (join_pass: the shards' values joined, lights added, invalid samples filled; then
// either the next pass's radiance texture or bake_scene's outputs).
#include "checks.hpp"
#include "pipeline.hpp"

#include "hemilight/shards.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace hemilight {

namespace bake_detail {

namespace {

// A bake's set-up as every job and merge makes it, and its partition into shards.
struct shard_plan {
  scene_setup su;
  sample_points pts;
  bake_result r;  // coverage, sampled and the set-up's statistics (place_samples)
  std::uint64_t key = 0;
  int shard_count = 0;
  // The samples shard by shard: shard i's are by_shard[begin[i], begin[i + 1]), in the bake's
  // sample order (the i-th of shard_count equal runs of the Morton order, each sorted once).
  std::vector<std::uint32_t> by_shard;
  std::vector<std::size_t> begin;
  double setup_seconds = 0.0;

  struct sample_range {
    const std::uint32_t *first, *last;
    std::size_t size() const { return std::size_t(last - first); }
    std::uint32_t operator[](std::size_t k) const { return first[k]; }
  };
  sample_range samples(int i) const {
    return {by_shard.data() + begin[std::size_t(i)], by_shard.data() + begin[std::size_t(i) + 1]};
  }
};

// 21 bits of x spread to every third bit.
std::uint64_t spread_bits(std::uint64_t x) {
  x &= 0x1fffffull;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

// The samples in Morton order of their positions over the scene's bounds (21 bits per axis, in
// double: the same order on every machine).
std::vector<std::uint32_t> morton_order(const sample_points& pts, const scene& sc) {
  const glm::dvec3 lo(sc.bounds_lo()), hi(sc.bounds_hi());
  const glm::dvec3 extent = glm::max(hi - lo, glm::dvec3(1e-30));
  const std::size_t n = pts.positions.size();
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(n);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec3 q = glm::clamp((glm::dvec3(pts.positions[i]) - lo) / extent, 0.0, 1.0) * 2097151.0;
    const std::uint64_t code = spread_bits(std::uint64_t(q.x)) | spread_bits(std::uint64_t(q.y)) << 1 | spread_bits(std::uint64_t(q.z)) << 2;
    keyed[i] = {code, std::uint32_t(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

std::string key_text(std::uint64_t key) {
  char text[24];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(key));
  return text;
}

template <class Count>  // int (the jobs) or std::size_t (the merges)
void check_shard_count(const char* who, Count shard_count) {
  if (shard_count < Count(1) || shard_count > Count(max_bake_shards))
    throw_invalid_argument(std::string(who) + ": shard_count = " + std::to_string(shard_count) + " is not in [1, " +
                           std::to_string(max_bake_shards) + "]");
}

shard_plan make_shard_plan(const char* who, const scene_bake_input& input, const bake_options& o, int shard_count) {
  const auto t0 = std::chrono::steady_clock::now();
  check_shard_count(who, shard_count);
  shard_plan p;
  p.su = make_scene_setup(who, input, o);
  p.r.stats.texels = std::size_t(p.su.atlas.layout.width) * std::size_t(p.su.atlas.layout.height);
  p.r.stats.overlapping_texels = p.su.samples.overlapping_texels;
  p.r.stats.degenerate_triangles = p.su.samples.degenerate_triangles;
  p.r.stats.no_uv_area_triangles = p.su.samples.no_uv_area_triangles;
  p.r.stats.first_no_uv_area_triangle = p.su.samples.first_no_uv_area_triangle;
  p.pts = place_samples(p.su.samples, *p.su.sc, o, p.su.atlas.layout, p.r);
  p.r.stats.coverage_seconds = seconds_since(t0);
  p.su.samples = sparse_samples{};
  p.key = bake_key(input, o);
  p.shard_count = shard_count;
  p.by_shard = morton_order(p.pts, *p.su.sc);
  const std::size_t n = p.by_shard.size(), count = std::size_t(shard_count);
  for (std::size_t i = 0; i <= count; ++i) p.begin.push_back(n * i / count);
  for (std::size_t i = 0; i < count; ++i)
    std::sort(p.by_shard.begin() + std::ptrdiff_t(p.begin[i]), p.by_shard.begin() + std::ptrdiff_t(p.begin[i + 1]));
  p.setup_seconds = seconds_since(t0);
  return p;
}

// The per-sample channels of a shard's result for pass `pass` (1-based): which values it holds.
struct shard_channels {
  bool sh = false, cone = false, ao = false, direct = false, direct_sh = false, direct_hl2 = false, mask = false;
  std::vector<std::string> names;

  shard_channels(const bake_options& o, int pass) {
    const bool directional = (o.output_sh_l1 || o.output_hl2) && (pass == o.bounces || (pass == 1 && o.indirect_only));
    sh = directional && o.output_sh_l1;
    cone = directional && o.output_hl2;
    ao = pass == 1 && o.ao_distance > 0.0f;
    direct = pass == 1 && !o.lights.empty();
    direct_sh = direct && o.output_sh_l1;
    direct_hl2 = direct && o.output_hl2;
    mask = direct && std::any_of(o.shadow_mask_lights.begin(), o.shadow_mask_lights.end(), [](int l) { return l >= 0; });
    rgb("E");
    names.push_back("invalid");
    for (int c = 0; sh && c < 4; ++c) rgb("sh" + std::to_string(c));
    for (int t = 0; cone && t < hl2_cone_terms; ++t) rgb("cone" + std::to_string(t));
    if (ao) names.push_back("ao");
    if (direct) rgb("direct.E");
    for (int c = 0; direct_sh && c < 4; ++c) rgb("direct.sh" + std::to_string(c));
    for (int j = 0; direct_hl2 && j < 3; ++j) rgb("direct.hl2_" + std::to_string(j));
    for (int m = 0; mask && m < 2; ++m) rgb("direct.mask" + std::to_string(m));
  }
  std::size_t size() const { return names.size(); }

 private:
  void rgb(const std::string& base) {
    for (const char* c : {".R", ".G", ".B"}) names.push_back(base + c);
  }
};

// Writes one sample's values (pass values v at index i, the lights' d at index i) into out.
void pack_sample(const shard_channels& ch, const pass_values& v, const direct_values* d, std::size_t i, float* out) {
  const auto put = [&out](const glm::vec3& x) { out[0] = x.x, out[1] = x.y, out[2] = x.z, out += 3; };
  put(v.e[i]);
  *out++ = v.invalid[i] ? 1.0f : 0.0f;
  for (std::size_t c = 0; ch.sh && c < 4; ++c) put(v.sh[c][i]);
  for (std::size_t t = 0; ch.cone && t < std::size_t(hl2_cone_terms); ++t) put(v.cone[i].coefficients[t]);
  if (ch.ao) *out++ = v.ao[i];
  if (!ch.direct) return;
  put(d->e[i]);
  for (std::size_t c = 0; ch.direct_sh && c < 4; ++c) put(d->sh[c][i]);
  for (std::size_t j = 0; ch.direct_hl2 && j < 3; ++j) put(d->hl2[j][i]);
  for (std::size_t m = 0; ch.mask && m < 2; ++m) put(d->mask[m][i]);
}

// The inverse of pack_sample: sample `at` of v (and d, when the channels hold the lights).
void unpack_sample(const shard_channels& ch, const float* in, std::size_t at, pass_values& v, direct_values* d) {
  const auto get = [&in]() {
    const glm::vec3 x(in[0], in[1], in[2]);
    in += 3;
    return x;
  };
  v.e[at] = get();
  v.invalid[at] = *in++ != 0.0f ? 1 : 0;
  for (std::size_t c = 0; ch.sh && c < 4; ++c) v.sh[c][at] = get();
  for (std::size_t t = 0; ch.cone && t < std::size_t(hl2_cone_terms); ++t) v.cone[at].coefficients[t] = get();
  if (ch.ao) v.ao[at] = *in++;
  if (!ch.direct || !d) return;
  d->e[at] = get();
  for (std::size_t c = 0; ch.direct_sh && c < 4; ++c) d->sh[c][at] = get();
  for (std::size_t j = 0; ch.direct_hl2 && j < 3; ++j) d->hl2[j][at] = get();
  for (std::size_t m = 0; ch.mask && m < 2; ++m) d->mask[m][at] = get();
}

// The samples `idx` of pts as a sample_points of their own.
sample_points subset(const sample_points& pts, shard_plan::sample_range idx) {
  sample_points s;
  const auto take = [&idx](const auto& from, auto& to) {
    to.reserve(idx.size());
    for (const std::uint32_t* i = idx.first; i != idx.last; ++i) to.push_back(from[*i]);
  };
  take(pts.texel_of, s.texel_of);
  take(pts.positions, s.positions);
  take(pts.normals, s.normals);
  take(pts.owner, s.owner);
  take(pts.tangents, s.tangents);
  take(pts.bitangents, s.bitangents);
  take(pts.spacing, s.spacing);
  return s;
}

// Refuses a state that is not the one after pass - 1 of this bake.
void check_previous(const char* who, const shard_plan& p, int pass, const bake_pass_state* previous) {
  if (pass == 1) {
    if (previous) throw_invalid_argument(std::string(who) + ": pass 1 takes no previous state (it was given the state after pass " +
                                         std::to_string(previous->pass) + ")");
    return;
  }
  if (!previous)
    throw_invalid_argument(std::string(who) + ": pass " + std::to_string(pass) + " needs the state after pass " + std::to_string(pass - 1) +
                           " (previous is null)");
  const bake_layout& l = p.su.atlas.layout;
  if (previous->key != p.key)
    throw_invalid_argument(std::string(who) + ": the previous state was made by another bake (another scene or options: key " +
                           key_text(previous->key) + ", this bake's " + key_text(p.key) + ")");
  if (previous->pass != pass - 1)
    throw_invalid_argument(std::string(who) + ": the previous state follows pass " + std::to_string(previous->pass) + ", not pass " +
                           std::to_string(pass - 1));
  if (previous->shard_count != p.shard_count)
    throw_invalid_argument(std::string(who) + ": the previous state comes from " + std::to_string(previous->shard_count) +
                           " shards, this bake has " + std::to_string(p.shard_count));
  const std::size_t texels = std::size_t(l.width) * std::size_t(l.height);
  if (previous->radiance.width != l.width || previous->radiance.height != l.height || previous->radiance.channels != 3 ||
      previous->radiance.pixels.size() != 3 * texels || previous->valid.size() != texels)
    throw_invalid_argument(std::string(who) + ": the previous state's radiance is " + std::to_string(previous->radiance.width) + " x " +
                           std::to_string(previous->radiance.height) + " with " + std::to_string(previous->radiance.channels) +
                           " channels and " + std::to_string(previous->valid.size()) + " valid flags: this bake's atlas is " +
                           std::to_string(l.width) + " x " + std::to_string(l.height) + " RGB");
  if (previous->passes.size() != std::size_t(pass - 1))
    throw_invalid_argument(std::string(who) + ": the previous state holds the statistics of " + std::to_string(previous->passes.size()) +
                           " passes, not " + std::to_string(pass - 1));
}

// pass in [1, hi], hi = bounces for jobs, bounces - 1 for merge_bake_pass (the last pass is
// finish_sharded_bake's).
void check_pass(const char* who, int pass, int hi, int bounces) {
  if (pass < 1 || pass > hi)
    throw_invalid_argument(std::string(who) + ": pass = " + std::to_string(pass) + " is not in [1, " + std::to_string(hi) +
                           "] (the bake has " + std::to_string(bounces) + " bounce" + (bounces > 1 ? "s" : "") +
                           (hi < bounces ? "; the last pass is finish_sharded_bake's)" : ")"));
}

// Job `shard` of pass `pass`: the pass's values (and in pass 1 the lights') at the shard's samples.
// `progress` (may be empty) sees the job's fraction; false cancels.
bake_shard_result run_shard(const shard_plan& p, const bake_options& o, int shard, int pass, const bake_pass_state* previous,
                            const std::function<bool(float)>& progress, std::chrono::steady_clock::time_point t0) {
  const shard_plan::sample_range idx = p.samples(shard);
  const sample_points pts = subset(p.pts, idx);
  const bake_layout& layout = p.su.atlas.layout;
  image emission_texture;
  radiance_texture view;
  const radiance_texture* texture = nullptr;
  if (pass > 1) {
    view = radiance_texture(previous->radiance);
    texture = &view;
  } else if (layout.textured_first_pass) {
    emission_texture = pass_radiance_texture(*p.su.sc, p.pts, nullptr, o, layout);
    view = radiance_texture(emission_texture);
    texture = &view;
  }
  std::vector<std::uint8_t> inside;
  if (pass > 1) {
    inside.resize(idx.size());
    for (std::size_t i = 0; i < idx.size(); ++i) inside[i] = previous->valid[pts.texel_of[i]] ? 0 : 1;
  }
  bake_result r;
  const shard_channels ch(o, pass);
  direct_values direct;
  if (ch.direct) {
    const light_set lights(o.lights.data(), o.lights.size());
    direct = lights_at_samples(pts, *p.su.sc, lights, o, r.stats);
  }
  const pass_values v = hemicube_pass(pts, p.su.sc, o, pass - 1, texture, inside.empty() ? nullptr : inside.data(), progress, r.stats);
  bake_shard_result out;
  out.key = p.key;
  out.pass = pass;
  out.shard = shard;
  out.shard_count = p.shard_count;
  out.sample_count = idx.size();
  out.channel_names = ch.names;
  out.values.resize(idx.size() * ch.size());
  for (std::size_t i = 0; i < idx.size(); ++i) pack_sample(ch, v, ch.direct ? &direct : nullptr, i, out.values.data() + i * ch.size());
  out.hemicubes = r.stats.hemicubes;
  out.records = r.stats.records;
  out.invalid_samples = r.stats.passes.empty() ? 0 : r.stats.passes.back().invalid_samples;
  out.direct_seconds = r.stats.direct_seconds;
  out.seconds = seconds_since(t0);
  return out;
}

// Checks that `shards` are the shard_count results of pass `pass` of this bake, once each, with
// the partition's sizes and the pass's channels; returns them by shard index.
std::vector<const bake_shard_result*> check_shards(const char* who, const char* what, const shard_plan& p, const bake_options& o,
                                                   int pass, const bake_shard_result* shards, std::size_t count) {
  const std::string name = std::string(who) + ": " + what;
  if (!shards) throw_invalid_argument(name + " is null");
  if (count != std::size_t(p.shard_count))
    throw_invalid_argument(name + " holds " + std::to_string(count) + " results, the bake has " + std::to_string(p.shard_count) +
                           " shards");
  const shard_channels ch(o, pass);
  std::vector<const bake_shard_result*> by_shard(count, nullptr);
  for (std::size_t k = 0; k < count; ++k) {
    const bake_shard_result& s = shards[k];
    const std::string at = name + "[" + std::to_string(k) + "]";
    if (s.key != p.key)
      throw_invalid_argument(at + " (shard " + std::to_string(s.shard) + " of pass " + std::to_string(s.pass) +
                             ") was baked from another scene or options (key " + key_text(s.key) + ", this bake's " + key_text(p.key) + ")");
    if (s.pass != pass) throw_invalid_argument(at + " is a result of pass " + std::to_string(s.pass) + ", not pass " + std::to_string(pass));
    if (s.shard_count != p.shard_count || s.shard < 0 || s.shard >= p.shard_count)
      throw_invalid_argument(at + " is shard " + std::to_string(s.shard) + " of " + std::to_string(s.shard_count) + ", not one of " +
                             std::to_string(p.shard_count));
    if (by_shard[std::size_t(s.shard)])
      throw_invalid_argument(at + " is shard " + std::to_string(s.shard) + " again (given twice)");
    const std::size_t n = p.samples(s.shard).size();
    if (s.sample_count != n || s.channel_names != ch.names || s.values.size() != n * ch.size())
      throw_invalid_argument(at + " (shard " + std::to_string(s.shard) + ") holds " + std::to_string(s.sample_count) + " samples of " +
                             std::to_string(s.channel_names.size()) + " channels (" + std::to_string(s.values.size()) +
                             " values): this bake's shard has " + std::to_string(n) + " samples of " + std::to_string(ch.size()));
    by_shard[std::size_t(s.shard)] = &s;
  }
  return by_shard;
}

// The values of pass `pass` over all samples (the lights' into d when the shards hold them).
pass_values join_shards(const shard_plan& p, const bake_options& o, int pass, const std::vector<const bake_shard_result*>& shards,
                        direct_values* d) {
  const shard_channels ch(o, pass);
  const std::size_t n = p.pts.texel_of.size();
  pass_values v;
  v.e.resize(n);
  v.invalid.resize(n);
  if (ch.sh)
    for (auto& plane : v.sh) plane.resize(n);
  if (ch.cone) v.cone.resize(n);
  if (ch.ao) v.ao.resize(n);
  if (ch.direct && d) {
    d->e.resize(n);
    if (ch.direct_sh)
      for (auto& plane : d->sh) plane.resize(n);
    if (ch.direct_hl2)
      for (auto& plane : d->hl2) plane.resize(n);
    if (ch.mask)
      for (auto& plane : d->mask) plane.resize(n);
  }
  for (int s = 0; s < p.shard_count; ++s) {
    const shard_plan::sample_range idx = p.samples(s);
    const bake_shard_result& r = *shards[std::size_t(s)];
    for (std::size_t i = 0; i < idx.size(); ++i) unpack_sample(ch, r.values.data() + i * ch.size(), idx[i], v, d);
  }
  return v;
}

cache_stats pass_stats(const std::vector<const bake_shard_result*>& shards) {
  cache_stats st;
  for (const bake_shard_result* s : shards) {
    st.hemicubes += s->hemicubes;
    st.records += s->records;
    st.invalid_samples += s->invalid_samples;
    st.invalid_points += s->invalid_samples;
    st.seconds += s->seconds;
  }
  return st;
}

// What a merge of pass `pass` joins: the pass's values with the lights added and invalid samples
// filled, the lights (from pass 1's shards), and per sample valid in every pass so far; with
// `finishing` (the last pass) also pass 1's AO (in v.ao) and, with indirect_only, pass 1's
// values as the one-process bake kept them (first).
struct joined_pass {
  pass_values v, first;
  direct_values direct;
  bool lit = false;
  std::vector<std::uint8_t> valid;
  std::vector<cache_stats> passes;
};

joined_pass join_pass(const char* who, const shard_plan& p, const bake_options& o, int pass, const bake_shard_result* shards,
                      std::size_t count, const bake_shard_result* first_pass, const bake_pass_state* previous, bool finishing) {
  check_previous(who, p, pass, previous);
  const std::vector<const bake_shard_result*> these = check_shards(who, "shards", p, o, pass, shards, count);
  joined_pass j;
  j.lit = !o.lights.empty();
  // Pass 1's shards are read once: its values and the lights' (pass 1 itself: both at once).
  pass_values first;
  if (pass == 1) {
    j.v = join_shards(p, o, 1, these, j.lit ? &j.direct : nullptr);
  } else {
    const std::vector<const bake_shard_result*> ones = check_shards(who, "first_pass", p, o, 1, first_pass, count);
    if (j.lit || (finishing && (o.ao_distance > 0.0f || o.indirect_only))) first = join_shards(p, o, 1, ones, j.lit ? &j.direct : nullptr);
    j.v = join_shards(p, o, pass, these, nullptr);
  }
  const std::size_t n = p.pts.texel_of.size();
  j.valid.assign(n, 1);
  if (previous) {
    for (std::size_t i = 0; i < n; ++i) j.valid[i] = previous->valid[p.pts.texel_of[i]];
    j.passes = previous->passes;
  }
  j.passes.push_back(pass_stats(these));
  merge_pass(p.pts, j.lit ? &j.direct : nullptr, p.su.atlas.layout, j.v, j.valid);
  if (!finishing) return j;
  if (pass == 1) {
    if (o.indirect_only) j.first = j.v;
    return j;
  }
  // The AO of pass 1 rides along to the end; with indirect_only, pass 1's values as the
  // one-process bake kept them: lights added, its own invalid samples filled.
  j.v.ao = std::move(first.ao);
  if (o.indirect_only) {
    std::vector<std::uint8_t> unused(n, 1);
    merge_pass(p.pts, j.lit ? &j.direct : nullptr, p.su.atlas.layout, first, unused);
    j.first = std::move(first);
  }
  return j;
}

bake_pass_state merge_state(const char* who, const shard_plan& p, const bake_options& o, int pass, const bake_shard_result* shards,
                            std::size_t count, const bake_shard_result* first_pass, const bake_pass_state* previous) {
  check_pass(who, pass, o.bounces - 1, o.bounces);
  joined_pass j = join_pass(who, p, o, pass, shards, count, first_pass, previous, false);
  bake_pass_state st;
  st.key = p.key;
  st.pass = pass;
  st.shard_count = p.shard_count;
  st.radiance = pass_radiance_texture(*p.su.sc, p.pts, &j.v.e, o, p.su.atlas.layout);
  const bake_layout& l = p.su.atlas.layout;
  st.valid.assign(std::size_t(l.width) * std::size_t(l.height), 0);
  for (std::size_t i = 0; i < p.pts.texel_of.size(); ++i) st.valid[p.pts.texel_of[i]] = j.valid[i];
  st.passes = std::move(j.passes);
  return st;
}

scene_bake_result finish(const char* who, const scene_bake_input& input, shard_plan& p, const bake_options& o,
                         const bake_shard_result* shards, std::size_t count, const bake_shard_result* first_pass,
                         const bake_pass_state* previous, std::chrono::steady_clock::time_point t0) {
  joined_pass j = join_pass(who, p, o, o.bounces, shards, count, first_pass, previous, true);
  const double seam_seconds = o.stitch_seams ? scene_seams(input, p.su.geometry, *p.su.sc, p.su.atlas) : 0.0;
  bake_result all = std::move(p.r);
  std::vector<float> ao = std::move(j.v.ao);
  std::vector<std::uint8_t> filled;
  finish_samples(p.pts, j.v, o.indirect_only ? &j.first : nullptr, j.lit ? &j.direct : nullptr, ao, j.valid, o, p.su.atlas.layout, all,
                 filled);
  for (const cache_stats& cs : j.passes) {
    all.stats.hemicubes += cs.hemicubes;
    all.stats.records += cs.records;
  }
  all.stats.passes = std::move(j.passes);
  if (j.lit)
    for (std::size_t k = 0; k < count; ++k) all.stats.direct_seconds += (o.bounces == 1 ? shards : first_pass)[k].direct_seconds;
  all.stats.stitch_seconds += seam_seconds;
  all.stats.seconds = seconds_since(t0);
  return scene_pages(who, input, p.su, std::move(all), filled);
}

}  // namespace

}  // namespace bake_detail

bake_shard_result bake_scene_shard(const scene_bake_input& input, const bake_options& options, int shard, int shard_count, int pass,
                                   const bake_pass_state* previous) {
  using namespace bake_detail;
  const char* who = "bake_scene_shard";
  const auto t0 = std::chrono::steady_clock::now();
  check_shard_count(who, shard_count);
  if (shard < 0 || shard >= shard_count)
    throw_invalid_argument(std::string(who) + ": shard = " + std::to_string(shard) + " is not in [0, " + std::to_string(shard_count) + ")");
  check_options(options, who, false);
  check_pass(who, pass, options.bounces, options.bounces);
  const shard_plan p = make_shard_plan(who, input, options, shard_count);
  check_previous(who, p, pass, previous);
  float reported = 0.0f;
  std::function<bool(float)> progress;
  if (options.progress)
    progress = [&](float f) {
      reported = std::max(reported, std::min(f, 1.0f));
      return options.progress(reported);
    };
  return run_shard(p, options, shard, pass, previous, progress, t0);
}

bake_pass_state merge_bake_pass(const scene_bake_input& input, const bake_options& options, int pass, const bake_shard_result* shards,
                                std::size_t shard_count, const bake_shard_result* first_pass, const bake_pass_state* previous) {
  using namespace bake_detail;
  const char* who = "merge_bake_pass";
  check_options(options, who, false);
  check_pass(who, pass, options.bounces - 1, options.bounces);
  check_shard_count(who, shard_count);
  const shard_plan p = make_shard_plan(who, input, options, int(shard_count));
  return merge_state(who, p, options, pass, shards, shard_count, first_pass, previous);
}

scene_bake_result finish_sharded_bake(const scene_bake_input& input, const bake_options& options, const bake_shard_result* shards,
                                      std::size_t shard_count, const bake_shard_result* first_pass, const bake_pass_state* previous) {
  using namespace bake_detail;
  const char* who = "finish_sharded_bake";
  const auto t0 = std::chrono::steady_clock::now();
  check_shard_count(who, shard_count);
  shard_plan p = make_shard_plan(who, input, options, int(shard_count));
  return finish(who, input, p, options, shards, shard_count, first_pass, previous, t0);
}

scene_bake_result bake_scene_sharded(const scene_bake_input& input, const bake_options& options, int shard_count) {
  using namespace bake_detail;
  const char* who = "bake_scene_sharded";
  const auto t0 = std::chrono::steady_clock::now();
  shard_plan p = make_shard_plan(who, input, options, shard_count);
  std::vector<bake_shard_result> first, current;
  bake_pass_state state;
  float reported = 0.0f;  // the whole bake's fraction, never decreasing
  for (int pass = 1; pass <= options.bounces; ++pass) {
    current.clear();
    for (int s = 0; s < shard_count; ++s) {
      std::function<bool(float)> progress;
      if (options.progress)
        progress = [&, s, pass](float f) {
          const float whole = (float(pass - 1) + (float(s) + std::min(f, 1.0f)) / float(shard_count)) / float(options.bounces);
          reported = std::max(reported, std::min(whole, 1.0f));
          return options.progress(reported);
        };
      current.push_back(run_shard(p, options, s, pass, pass > 1 ? &state : nullptr, progress, std::chrono::steady_clock::now()));
    }
    if (pass == 1) first = current;
    if (pass == options.bounces) break;
    state = merge_state(who, p, options, pass, current.data(), current.size(), first.data(), pass > 1 ? &state : nullptr);
  }
  return finish(who, input, p, options, current.data(), current.size(), first.data(), options.bounces > 1 ? &state : nullptr, t0);
}

}  // namespace hemilight
