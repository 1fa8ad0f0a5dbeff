// hemilight_bake's files for sharded bakes (shards.hpp): a job's result and a pass's state as an
// OpenEXR file of float channels plus a JSON manifest beside it.
//
//   PREFIX_pass{K}_shard{I}of{S}.exr   one job's values: one pixel per sample of the shard (in the
//                                      bake's sample order, rows of 1024 samples, the last row
//                                      padded with zeros), one FLOAT channel per value
//                                      (bake_shard_result::channel_names)
//   PREFIX_pass{K}_shard{I}of{S}.json  {"format": "hemilight_shard", "version": 1, "name", "pass",
//                                      "shard", "shards", "key" (16 hex digits: bake_key),
//                                      "samples", "channels", "hemicubes", "records",
//                                      "invalid_samples", "seconds", "direct_seconds", "values"
//                                      (the EXR's file name)}
//   PREFIX_pass{K}.exr                 the state after pass K (bake_pass_state): the pages' atlas,
//                                      RGB = the next pass's radiance texture, A = valid (0 or 1)
//   PREFIX_pass{K}.json                {"format": "hemilight_pass_state", "version": 1, "name",
//                                      "pass", "shards", "key", "width", "height", "passes":
//                                      [{"hemicubes", "records", "invalid_samples", "seconds"}],
//                                      "values"}
//
// Readers check the manifest against the file (format, version, the EXR's size and channels) and
// throw std::runtime_error naming the file; the caller's library call checks key, pass and shard.
#pragma once

#include "hemilight/shards.hpp"

#include <cstdint>
#include <string>

namespace shard_files {

/// A bake's key as the manifests write it: 16 hex digits.
std::string key_text(std::uint64_t key);

/// PREFIX_pass{K}_shard{I}of{S} (no extension).
std::string shard_stem(const std::string& prefix, int pass, int shard, int shards);
/// PREFIX_pass{K} (no extension).
std::string state_stem(const std::string& prefix, int pass);

/// Writes stem.exr, then stem.json (each replaced atomically: a reader never sees half a file).
/// `name` is the scene's name, recorded in the manifest. Throws std::runtime_error naming the file.
void write_shard(const std::string& stem, const std::string& name, const hemilight::bake_shard_result& r);
void write_state(const std::string& stem, const std::string& name, const hemilight::bake_pass_state& s);

/// Reads what write_shard / write_state wrote. Throws std::runtime_error naming the file when it
/// is missing, unreadable, or its manifest and EXR disagree.
hemilight::bake_shard_result read_shard(const std::string& stem);
hemilight::bake_pass_state read_state(const std::string& stem);

}  // namespace shard_files
