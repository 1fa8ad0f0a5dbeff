// The C ABI of sharded scene bakes (hemilight.h, "sharded scene bakes"; C++: shards.hpp): the jobs,
// merges and the one-process bake over the scene bake's checks and outputs (capi_scene_bake.hpp),
// and the shards and states as plain numbers and arrays (_get, _create) and back.
#include "capi_internal.hpp"
#include "capi_options.hpp"
#include "capi_scene_bake.hpp"

#include "hemilight/shards.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

/// The opaque handles: one job's result and the state between two passes (immutable).
struct hemilight_bake_shard {
  hemilight::bake_shard_result result;
};
struct hemilight_bake_pass_state {
  hemilight::bake_pass_state state;
};

namespace {

using hemilight::capi::guarded;
using hemilight::capi::invalid;

// ---- arguments ---------------------------------------------------------------------------------

std::string range_text(int lo, int hi) { return "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]"; }

// The shard count of a bake, checked in the caller's terms.
hemilight_status check_shard_count(const char* fn, std::size_t count, const char* name) {
  if (count >= 1 && count <= std::size_t(hemilight::max_bake_shards)) return HEMILIGHT_OK;
  return invalid(fn, std::string(name) + " is " + std::to_string(count) + "; it must be in " + range_text(1, hemilight::max_bake_shards) +
                         " (the bake's shards)");
}

// The C shard array `name`: non-NULL, with `count` non-NULL handles.
hemilight_status check_handles(const char* fn, const char* name, const hemilight_bake_shard* const* shards, std::size_t count) {
  if (!shards) return invalid(fn, std::string(name) + " is NULL (" + std::to_string(count) + " shard handles)");
  for (std::size_t k = 0; k < count; ++k)
    if (!shards[k]) return invalid(fn, std::string(name) + "[" + std::to_string(k) + "] is NULL");
  return HEMILIGHT_OK;
}

// The C shard array `name` of `count` handles (checked) copied into `out` in order, so that the
// C++ messages' indices ("shards[2]") are the caller's.
hemilight_status gather_shards(const char* fn, const char* name, const hemilight_bake_shard* const* shards, std::size_t count,
                               std::vector<hemilight::bake_shard_result>& out) {
  if (const hemilight_status st = check_handles(fn, name, shards, count)) return st;
  out.clear();
  out.reserve(count);
  for (std::size_t k = 0; k < count; ++k) out.push_back(shards[k]->result);
  return HEMILIGHT_OK;
}

// The arguments hemilight_merge_bake_pass and hemilight_finish_sharded_bake share: the shards of
// the pass and (when `needs_first`) those of pass 1, copied; first_pass is `shards` when pass 1 is
// the pass being merged. Elements are checked before anything is copied.
struct merge_inputs {
  std::vector<hemilight::bake_shard_result> shards, first;
  const hemilight::bake_shard_result* first_pass() const { return first.empty() ? shards.data() : first.data(); }
};

hemilight_status gather_merge(const char* fn, const hemilight_bake_shard* const* shards, std::size_t count,
                              const hemilight_bake_shard* const* first_pass, bool needs_first, merge_inputs& in) {
  if (needs_first) {
    if (!first_pass)
      return invalid(fn, "first_pass is NULL: passes after the first need pass 1's " + std::to_string(count) + " shards (their lights and AO)");
    if (const hemilight_status st = check_handles(fn, "first_pass", first_pass, count)) return st;
  }
  if (const hemilight_status st = gather_shards(fn, "shards", shards, count, in.shards)) return st;
  in.first.clear();
  if (needs_first)
    if (const hemilight_status st = gather_shards(fn, "first_pass", first_pass, count, in.first)) return st;
  return HEMILIGHT_OK;
}

// "" or what is wrong with a wall time named `name`.
std::string seconds_problem(double s, const std::string& name) {
  if (std::isfinite(s) && s >= 0.0) return {};
  return name + " = " + std::to_string(s) + "; it must be finite and >= 0";
}

}  // namespace

extern "C" {

void hemilight_bake_shard_release(hemilight_bake_shard* shard) { delete shard; }

void hemilight_bake_pass_state_release(hemilight_bake_pass_state* state) { delete state; }

hemilight_status hemilight_bake_scene_shard(const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options, int32_t shard,
                                            int32_t shard_count, int32_t pass, const hemilight_bake_pass_state* previous,
                                            hemilight_bake_shard** out) {
  const char* fn = "hemilight_bake_scene_shard";
  return guarded(fn, [&] {
    if (!out) return invalid(fn, "out is NULL");
    if (shard_count < 1 || shard_count > hemilight::max_bake_shards)
      return invalid(fn, "shard_count is " + std::to_string(shard_count) + "; it must be in " + range_text(1, hemilight::max_bake_shards));
    if (shard < 0 || shard >= shard_count)
      return invalid(fn, "shard is " + std::to_string(shard) + "; it must be in [0, " + std::to_string(shard_count) + ") (shard_count " +
                             std::to_string(shard_count) + ")");
    hemilight::capi::scene_bake_call call;
    if (const hemilight_status st = hemilight::capi::prepare_scene_bake(fn, scene, options, nullptr, call)) return st;
    // The pass and previous state: the C++ job checks them (its messages, named after fn).
    auto handle = std::make_unique<hemilight_bake_shard>();
    handle->result = hemilight::bake_scene_shard(call.input, call.options, shard, shard_count, pass, previous ? &previous->state : nullptr);
    *out = handle.release();
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_merge_bake_pass(const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options, int32_t pass,
                                           const hemilight_bake_shard* const* shards, size_t shard_count,
                                           const hemilight_bake_shard* const* first_pass, const hemilight_bake_pass_state* previous,
                                           hemilight_bake_pass_state** out) {
  const char* fn = "hemilight_merge_bake_pass";
  return guarded(fn, [&] {
    if (!out) return invalid(fn, "out is NULL");
    if (const hemilight_status st = check_shard_count(fn, shard_count, "shard_count")) return st;
    if (const hemilight_status st = check_handles(fn, "shards", shards, shard_count)) return st;
    hemilight::capi::scene_bake_call call;
    if (const hemilight_status st = hemilight::capi::prepare_scene_bake(fn, scene, options, nullptr, call)) return st;
    const int last = call.options.bounces - 1;
    if (last < 1)
      return invalid(fn, "options->bounces is 1: a bake of one bounce has no merge before hemilight_finish_sharded_bake");
    if (pass < 1 || pass > last)
      return invalid(fn, "pass is " + std::to_string(pass) + "; it must be in [1, options->bounces - 1 = " + std::to_string(last) +
                             "] (the last pass, " + std::to_string(last + 1) + ", goes to hemilight_finish_sharded_bake)");
    merge_inputs in;
    if (const hemilight_status st = gather_merge(fn, shards, shard_count, first_pass, pass > 1, in)) return st;
    auto handle = std::make_unique<hemilight_bake_pass_state>();
    handle->state = hemilight::merge_bake_pass(call.input, call.options, pass, in.shards.data(), in.shards.size(), in.first_pass(),
                                               previous ? &previous->state : nullptr);
    *out = handle.release();
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_finish_sharded_bake(const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options,
                                               const hemilight_bake_shard* const* shards, size_t shard_count,
                                               const hemilight_bake_shard* const* first_pass, const hemilight_bake_pass_state* previous,
                                               hemilight_bake_stats* stats) {
  const char* fn = "hemilight_finish_sharded_bake";
  return guarded(fn, [&] {
    if (const hemilight_status st = check_shard_count(fn, shard_count, "shard_count")) return st;
    if (const hemilight_status st = check_handles(fn, "shards", shards, shard_count)) return st;
    hemilight::capi::scene_bake_call call;
    if (const hemilight_status st = hemilight::capi::prepare_scene_bake(fn, scene, options, stats, call)) return st;
    merge_inputs in;
    if (const hemilight_status st = gather_merge(fn, shards, shard_count, first_pass, call.options.bounces > 1, in)) return st;
    const hemilight::scene_bake_result r = hemilight::finish_sharded_bake(call.input, call.options, in.shards.data(), in.shards.size(),
                                                                          in.first_pass(), previous ? &previous->state : nullptr);
    return hemilight::capi::write_scene_bake(fn, call, r, stats);
  });
}

hemilight_status hemilight_bake_scene_sharded(const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options,
                                              int32_t shard_count, hemilight_bake_stats* stats) {
  const char* fn = "hemilight_bake_scene_sharded";
  return guarded(fn, [&] {
    if (shard_count < 1 || shard_count > hemilight::max_bake_shards)
      return invalid(fn, "shard_count is " + std::to_string(shard_count) + "; it must be in " + range_text(1, hemilight::max_bake_shards));
    hemilight::capi::scene_bake_call call;
    if (const hemilight_status st = hemilight::capi::prepare_scene_bake(fn, scene, options, stats, call)) return st;
    const hemilight::scene_bake_result r = hemilight::bake_scene_sharded(call.input, call.options, shard_count);
    return hemilight::capi::write_scene_bake(fn, call, r, stats);
  });
}

// ---- shards as plain data -----------------------------------------------------------------------

hemilight_status hemilight_bake_shard_get(const hemilight_bake_shard* shard, hemilight_bake_shard_info* info, float* values,
                                          size_t values_capacity) {
  const char* fn = "hemilight_bake_shard_get";
  return guarded(fn, [&] {
    if (!shard) return invalid(fn, "shard is NULL");
    if (!info) return invalid(fn, "info is NULL (use hemilight_bake_shard_info_init)");
    if (std::string p = hemilight::capi::check_sized(info); !p.empty()) return invalid(fn, p);
    const hemilight::bake_shard_result& r = shard->result;
    if (values && values_capacity < r.values.size())
      return invalid(fn, "values_capacity " + std::to_string(values_capacity) + " is below sample_count x channel_count = " +
                             std::to_string(r.sample_count) + " x " + std::to_string(r.channel_names.size()) + " = " +
                             std::to_string(r.values.size()) + " floats");
    hemilight_bake_shard_info i{};
    i.struct_size = sizeof i;
    i.key = r.key;
    i.pass = r.pass;
    i.shard = r.shard;
    i.shard_count = r.shard_count;
    i.sample_count = r.sample_count;
    i.channel_count = r.channel_names.size();
    i.hemicubes = r.hemicubes;
    i.records = r.records;
    i.invalid_samples = r.invalid_samples;
    i.seconds = r.seconds;
    i.direct_seconds = r.direct_seconds;
    if (values && !r.values.empty()) std::memcpy(values, r.values.data(), r.values.size() * sizeof(float));
    hemilight::capi::write_sized(i, info);
    return HEMILIGHT_OK;
  });
}

const char* hemilight_bake_shard_channel_name(const hemilight_bake_shard* shard, size_t channel) {
  if (!shard || channel >= shard->result.channel_names.size()) return nullptr;
  return shard->result.channel_names[channel].c_str();
}

hemilight_status hemilight_bake_shard_create(const hemilight_bake_shard_info* info, const char* const* channel_names, const float* values,
                                             size_t value_count, hemilight_bake_shard** out) {
  const char* fn = "hemilight_bake_shard_create";
  return guarded(fn, [&] {
    if (!out) return invalid(fn, "out is NULL");
    if (!info) return invalid(fn, "info is NULL (use hemilight_bake_shard_info_init)");
    hemilight_bake_shard_info i;
    if (std::string p = hemilight::capi::read_sized(info, i); !p.empty()) return invalid(fn, p);
    if (i.shard_count < 1 || i.shard_count > hemilight::max_bake_shards)
      return invalid(fn, "info->shard_count is " + std::to_string(i.shard_count) + "; it must be in " +
                             range_text(1, hemilight::max_bake_shards));
    if (i.shard < 0 || i.shard >= i.shard_count)
      return invalid(fn, "info->shard is " + std::to_string(i.shard) + "; it must be in [0, info->shard_count = " +
                             std::to_string(i.shard_count) + ")");
    if (i.pass < 1 || i.pass > hemilight::max_bounces)
      return invalid(fn, "info->pass is " + std::to_string(i.pass) + "; it must be in " + range_text(1, hemilight::max_bounces));
    if (i.channel_count > 0 && !channel_names)
      return invalid(fn, "channel_names is NULL with info->channel_count " + std::to_string(i.channel_count));
    for (std::size_t c = 0; c < i.channel_count; ++c)
      if (!channel_names[c]) return invalid(fn, "channel_names[" + std::to_string(c) + "] is NULL");
    const bool overflows = i.channel_count > 0 && i.sample_count > std::numeric_limits<std::size_t>::max() / i.channel_count;
    if (overflows || value_count != i.sample_count * i.channel_count)
      return invalid(fn, "value_count " + std::to_string(value_count) + " is not info->sample_count x info->channel_count = " +
                             std::to_string(i.sample_count) + " x " + std::to_string(i.channel_count));
    if (value_count > 0 && !values) return invalid(fn, "values is NULL with value_count " + std::to_string(value_count));
    for (std::size_t k = 0; k < value_count; ++k)
      if (!std::isfinite(values[k]))
        return invalid(fn, "values[" + std::to_string(k) + "] (sample " + std::to_string(k / i.channel_count) + ", channel " +
                               channel_names[k % i.channel_count] + ") = " + std::to_string(values[k]) + "; it must be finite");
    if (std::string p = seconds_problem(i.seconds, "info->seconds"); !p.empty()) return invalid(fn, p);
    if (std::string p = seconds_problem(i.direct_seconds, "info->direct_seconds"); !p.empty()) return invalid(fn, p);
    auto handle = std::make_unique<hemilight_bake_shard>();
    hemilight::bake_shard_result& r = handle->result;
    r.key = i.key;
    r.pass = i.pass;
    r.shard = i.shard;
    r.shard_count = i.shard_count;
    r.sample_count = i.sample_count;
    std::vector<std::string> names(i.channel_count);
    for (std::size_t c = 0; c < i.channel_count; ++c) names[c] = channel_names[c];
    r.channel_names = std::move(names);
    r.values.assign(values, values + value_count);
    r.hemicubes = i.hemicubes;
    r.records = i.records;
    r.invalid_samples = i.invalid_samples;
    r.seconds = i.seconds;
    r.direct_seconds = i.direct_seconds;
    *out = handle.release();
    return HEMILIGHT_OK;
  });
}

// ---- states as plain data -----------------------------------------------------------------------

hemilight_status hemilight_bake_pass_state_get(const hemilight_bake_pass_state* state, hemilight_bake_pass_state_info* info,
                                               float* radiance_rgba, size_t radiance_capacity, size_t* pass_hemicubes, size_t* pass_records,
                                               size_t* pass_invalid_samples, double* pass_seconds, size_t pass_capacity) {
  const char* fn = "hemilight_bake_pass_state_get";
  return guarded(fn, [&] {
    if (!state) return invalid(fn, "state is NULL");
    if (!info) return invalid(fn, "info is NULL (use hemilight_bake_pass_state_info_init)");
    if (std::string p = hemilight::capi::check_sized(info); !p.empty()) return invalid(fn, p);
    const hemilight::bake_pass_state& s = state->state;
    const std::size_t texels = std::size_t(s.radiance.width) * std::size_t(s.radiance.height);
    if (radiance_rgba && radiance_capacity < 4 * texels)
      return invalid(fn, "radiance_capacity " + std::to_string(radiance_capacity) + " is below 4 x width x height = 4 x " +
                             std::to_string(s.radiance.width) + " x " + std::to_string(s.radiance.height) + " = " +
                             std::to_string(4 * texels) + " floats");
    const std::size_t passes = s.passes.size();
    if ((pass_hemicubes || pass_records || pass_invalid_samples || pass_seconds) && pass_capacity < passes)
      return invalid(fn, "pass_capacity " + std::to_string(pass_capacity) + " is below pass_count = " + std::to_string(passes));
    hemilight_bake_pass_state_info i{};
    i.struct_size = sizeof i;
    i.key = s.key;
    i.pass = s.pass;
    i.shard_count = s.shard_count;
    i.width = s.radiance.width;
    i.height = s.radiance.height;
    i.pass_count = passes;
    if (radiance_rgba)
      for (std::size_t k = 0; k < texels; ++k) {
        for (std::size_t c = 0; c < 3; ++c) radiance_rgba[4 * k + c] = s.radiance.pixels[3 * k + c];
        radiance_rgba[4 * k + 3] = s.valid[k] ? 1.0f : 0.0f;
      }
    for (std::size_t p = 0; p < passes; ++p) {
      if (pass_hemicubes) pass_hemicubes[p] = s.passes[p].hemicubes;
      if (pass_records) pass_records[p] = s.passes[p].records;
      if (pass_invalid_samples) pass_invalid_samples[p] = s.passes[p].invalid_samples;
      if (pass_seconds) pass_seconds[p] = s.passes[p].seconds;
    }
    hemilight::capi::write_sized(i, info);
    return HEMILIGHT_OK;
  });
}

hemilight_status hemilight_bake_pass_state_create(const hemilight_bake_pass_state_info* info, const float* radiance_rgba, size_t count,
                                                  const size_t* pass_hemicubes, const size_t* pass_records,
                                                  const size_t* pass_invalid_samples, const double* pass_seconds,
                                                  hemilight_bake_pass_state** out) {
  const char* fn = "hemilight_bake_pass_state_create";
  return guarded(fn, [&] {
    if (!out) return invalid(fn, "out is NULL");
    if (!info) return invalid(fn, "info is NULL (use hemilight_bake_pass_state_info_init)");
    hemilight_bake_pass_state_info i;
    if (std::string p = hemilight::capi::read_sized(info, i); !p.empty()) return invalid(fn, p);
    if (i.pass < 1 || i.pass > hemilight::max_bounces - 1)
      return invalid(fn, "info->pass is " + std::to_string(i.pass) + "; it must be in " + range_text(1, hemilight::max_bounces - 1) +
                             " (a state follows a pass before the last)");
    if (i.shard_count < 1 || i.shard_count > hemilight::max_bake_shards)
      return invalid(fn, "info->shard_count is " + std::to_string(i.shard_count) + "; it must be in " +
                             range_text(1, hemilight::max_bake_shards));
    constexpr std::size_t max_texels = std::size_t(1) << 28;  // the largest atlas (hemilight_bake_scene: 2^28 texels)
    if (i.width < 1 || i.height < 1 || std::size_t(i.width) * std::size_t(i.height) > max_texels)
      return invalid(fn, "info->width x height = " + std::to_string(i.width) + " x " + std::to_string(i.height) +
                             " is invalid: each must be >= 1 and the atlas at most 2^28 texels");
    if (i.pass_count > std::size_t(hemilight::max_bounces))
      return invalid(fn, "info->pass_count is " + std::to_string(i.pass_count) + "; it must be at most " +
                             std::to_string(hemilight::max_bounces));
    const std::size_t texels = std::size_t(i.width) * std::size_t(i.height);
    if (!radiance_rgba) return invalid(fn, "radiance_rgba is NULL (4 x width x height floats)");
    if (count != 4 * texels)
      return invalid(fn, "count " + std::to_string(count) + " is not 4 x info->width x info->height = 4 x " + std::to_string(i.width) +
                             " x " + std::to_string(i.height) + " = " + std::to_string(4 * texels));
    for (std::size_t k = 0; k < count; ++k) {
      const float v = radiance_rgba[k];
      const std::size_t texel = k / 4, c = k % 4;
      const bool ok = c < 3 ? (std::isfinite(v) && v >= 0.0f) : (v == 0.0f || v == 1.0f);
      if (!ok)
        return invalid(fn, "radiance_rgba[" + std::to_string(k) + "] (texel " + std::to_string(texel) + ": x " +
                               std::to_string(texel % std::size_t(i.width)) + ", y " + std::to_string(texel / std::size_t(i.width)) +
                               ", " + std::string(1, "RGBA"[c]) + ") = " + std::to_string(v) +
                               (c < 3 ? "; radiance must be finite and >= 0" : "; it must be 0 or 1 (A: the texel's sample is valid)"));
    }
    for (std::size_t p = 0; pass_seconds && p < i.pass_count; ++p)
      if (std::string e = seconds_problem(pass_seconds[p], "pass_seconds[" + std::to_string(p) + "]"); !e.empty()) return invalid(fn, e);
    auto handle = std::make_unique<hemilight_bake_pass_state>();
    hemilight::bake_pass_state& s = handle->state;
    s.key = i.key;
    s.pass = i.pass;
    s.shard_count = i.shard_count;
    s.radiance = hemilight::image::make(i.width, i.height, 3);
    s.valid.resize(texels);
    for (std::size_t k = 0; k < texels; ++k) {
      for (std::size_t c = 0; c < 3; ++c) s.radiance.pixels[3 * k + c] = radiance_rgba[4 * k + c];
      s.valid[k] = radiance_rgba[4 * k + 3] != 0.0f ? 1 : 0;
    }
    s.passes.resize(i.pass_count);
    for (std::size_t p = 0; p < i.pass_count; ++p) {
      hemilight::cache_stats& st = s.passes[p];
      st.hemicubes = pass_hemicubes ? pass_hemicubes[p] : 0;
      st.records = pass_records ? pass_records[p] : 0;
      st.invalid_samples = st.invalid_points = pass_invalid_samples ? pass_invalid_samples[p] : 0;  // as the merges sum them
      st.seconds = pass_seconds ? pass_seconds[p] : 0.0;
    }
    *out = handle.release();
    return HEMILIGHT_OK;
  });
}

}  // extern "C"
