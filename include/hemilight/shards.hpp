// hemilight/shards.hpp — a scene bake (bake_scene, bake.hpp) split into shards: jobs that run
// anywhere (other processes, other machines) with plain inputs and outputs, and the merges that
// join them. docs/distributed.md has the protocol, the figures and the Dask driver built on it.
//
// A bake of B bounces with S shards is B passes; pass k (1-based) is S jobs and one merge:
//
//   job (shard i, pass k):   bake_scene_shard(input, options, i, S, k, state_{k-1})  -> shard_{k,i}
//   merge (pass k < B):      merge_bake_pass(input, options, k, shards_k, shards_1, state_{k-1}) -> state_k
//   merge (pass k = B):      finish_sharded_bake(input, options, shards_B, shards_1, state_{B-1}) -> result
//
// Every job and merge recomputes the bake's set-up (geometry, atlas, samples) from input and
// options: nothing but the values below passes between them. Shard i holds the samples whose
// positions come i-th in a Morton order over the scene's bounds, split into S runs of equal
// count (compact regions of the scene: the irradiance cache works per shard, so regions keep
// its records shared). Pass 1's jobs also compute the lights' direct light and the ambient
// occlusion at their samples; the merges read them from pass 1's shards.
//
// Determinism: a shard's values depend on input, options, S, i and k only (not on the machine's
// thread count nor on which process runs it), so the sharded bake is bitwise the same however
// its jobs are spread. With S = 1 it is bitwise bake_scene's result; with S > 1 and the cache, each
// shard places its own records, so the result differs from bake_scene's within the cache's
// error (docs/distributed.md measures it against S); without the cache (use_cache = false) it is
// bitwise bake_scene's for every S.
#pragma once

#include "hemilight/bake.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hemilight {

/// Largest shard count a sharded bake takes.
inline constexpr int max_bake_shards = 4096;

/// A 64-bit hash of everything that decides a bake's values: the scene (positions, indices,
/// normals, lightmap UVs, materials, alpha textures and their coordinates, the sky's constant
/// and environment), the pages (sizes, albedo and emission images), the meshes, the occluders'
/// mode and every option but thread_count, progress and the rasterizer's diagnostic switches
/// (which do not change bits). Shard results and pass states carry it; the merges refuse inputs
/// whose key differs. Not a cryptographic hash: it catches mistakes, not forgery.
/// Cost: O(input size) (one read of every array and image).
std::uint64_t bake_key(const scene_bake_input& input, const bake_options& options);

/// What one job of a sharded bake computed: per sample of its shard, in the bake's sample order,
/// `channels` floats (named by channel_names).
struct bake_shard_result {
  std::uint64_t key = 0;           ///< bake_key of the bake
  int pass = 0;                    ///< 1-based
  int shard = 0, shard_count = 0;  ///< 0 <= shard < shard_count
  std::size_t sample_count = 0;    ///< the shard's samples
  /// What each sample holds, in order: "E.R", "E.G", "E.B" (irradiance of the pass, before the
  /// lights), "invalid" (1: inside geometry), then as the pass computes them "sh{c}.{R,G,B}"
  /// (c = 0..3), "cone{t}.{R,G,B}" (HL2 cone terms), "ao", and in pass 1 with lights
  /// "direct.E.{R,G,B}", "direct.sh{c}.{R,G,B}", "direct.hl2_{j}.{R,G,B}", "direct.mask{m}.{R,G,B}".
  std::vector<std::string> channel_names;
  std::vector<float> values;       ///< sample_count x channel_names.size(), sample-major
  std::size_t hemicubes = 0;       ///< rendered by this job
  std::size_t records = 0;         ///< cache records placed by this job
  std::size_t invalid_samples = 0; ///< samples found inside geometry
  double seconds = 0.0;            ///< the job's wall time (set-up included)
  double direct_seconds = 0.0;     ///< of which the lights (pass 1)
};

/// The state between two passes of a sharded bake: what pass k + 1's jobs read.
struct bake_pass_state {
  std::uint64_t key = 0;           ///< bake_key of the bake
  int pass = 0;                    ///< the pass it follows (1-based, < bounces)
  int shard_count = 0;
  /// The radiance texture pass + 1 renders (the atlas of the pages, bake.hpp's bake_scene):
  /// RGB, emission + albedo E / pi, dilated, with guards and occluder blocks.
  image radiance;
  /// Per atlas texel: 1 where a sample lies that every pass so far found outside geometry, else 0.
  std::vector<std::uint8_t> valid;
  /// Per pass so far, summed over its shards: hemicubes, records, invalid samples, seconds (the
  /// sum of the jobs' times).
  std::vector<cache_stats> passes;
};

/// Runs job `shard` (0-based) of `shard_count` of pass `pass` (1-based, in [1, options.bounces]).
/// `previous` is the state merge_bake_pass made after pass - 1 (null for pass 1, required after).
///
/// Errors (error(invalid_argument) naming the problem, the message starting with
/// "bake_scene_shard"): shard_count not in [1, max_bake_shards], shard not in [0, shard_count),
/// pass not in [1, bounces]; `previous` missing for pass > 1, given for pass 1, or not the state of
/// pass - 1 of this bake (its key, shard count or atlas size differ); everything bake_scene
/// refuses. cancelled: options.progress returned false (it sees the job's fraction).
/// Cost: the bake's set-up (coverage of every page: O(texels)), then about 1 / shard_count of
/// the pass's hemicubes (and of the lights' rays in pass 1).
bake_shard_result bake_scene_shard(const scene_bake_input& input, const bake_options& options, int shard, int shard_count,
                                   int pass, const bake_pass_state* previous);

/// Merges pass `pass` < options.bounces: its shards' values joined, the lights added, samples
/// inside geometry filled, and the radiance texture of pass + 1 made. `shards` holds the
/// shard_count results of the pass (any order), `first_pass` those of pass 1 (their lights and AO;
/// may be the same array when pass = 1), `previous` the state after pass - 1 (null for pass 1).
///
/// Errors (error(invalid_argument), "merge_bake_pass: ..."): pass not in [1, bounces); a shard
/// missing or given twice; a result of another bake (key), pass, shard count or size than this
/// bake's partition gives; `previous` as bake_scene_shard checks it.
/// Cost: O(atlas texels) plus the dilation of the radiance texture (no hemicube).
bake_pass_state merge_bake_pass(const scene_bake_input& input, const bake_options& options, int pass,
                                const bake_shard_result* shards, std::size_t shard_count, const bake_shard_result* first_pass,
                                const bake_pass_state* previous);

/// Merges the last pass (pass = options.bounces) into the bake's result: what bake_scene returns,
/// computed from the shards (its stats.passes summed over the shards). Arguments and errors as
/// merge_bake_pass ("finish_sharded_bake: ..."). Cost: as merge_bake_pass, plus the outputs'
/// seams, dilation and pages (bake_scene's steps 5 and 6).
scene_bake_result finish_sharded_bake(const scene_bake_input& input, const bake_options& options,
                                      const bake_shard_result* shards, std::size_t shard_count,
                                      const bake_shard_result* first_pass, const bake_pass_state* previous);

/// The sharded bake in one process: every job and merge above in order, with the set-up made
/// once. The same bits as running the jobs anywhere. Errors as bake_scene and bake_scene_shard
/// ("bake_scene_sharded: ..."). Cost: bake_scene's, plus the shards' lost sharing of cache records
/// near their borders (docs/distributed.md).
scene_bake_result bake_scene_sharded(const scene_bake_input& input, const bake_options& options, int shard_count);

}  // namespace hemilight
