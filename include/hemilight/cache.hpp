// hemilight/cache.hpp — irradiance caching: render hemicubes at few of the points where
// irradiance is needed, interpolate the rest with gradients (Ward 1988, Ward & Heckbert 1992).
// Placement, radii and their figures: docs/cache.md.
//
// Records: position x_i, normal n_i, irradiance E_i, gradients g_r,i and g_t,i (integrate.hpp's
// convention), validity radius R_i. Interpolation at (x, n), over the records with w_i > 1/a that
// x is not behind:
//
//     E(x, n) = sum_i w_i (E_i + (n_i x n) . g_r,i + (x - x_i) . g_t,i) / sum_i w_i,  clamped >= 0
//
// with Ward's w_i = 1 / (|x - x_i| / R_i + sqrt(1 - n . n_i)) (cache_weight lists the others) and,
// with second_order, + 1/2 (x - x_i)^T H_i (x - x_i) in each record's prediction.
//
// Determinism: the same input gives bitwise the same output for any thread count. Points inside
// geometry (their own hemicube, or a nearby invalid sample's, sees back faces) are reported invalid
// and filled from records on their side of the surface.
#pragma once

#include "hemilight/sampler.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

namespace hemilight {

/// What set a record's final radius: the last limit that lowered it (cache_record::limit,
/// cache_stats::records_by_limit). docs/cache.md, "Radii".
enum class radius_limit : std::uint8_t {
  split_sphere,  ///< the hemicube's harmonic mean distance (nothing lowered it)
  max_radius,    ///< clamped to max_radius (or the split sphere was infinite: nothing seen)
  gradient,      ///< R <= E / |g_t| (cache_expert_options::limit_radius_by_gradient)
  contact,       ///< limited to the sample's nearest hit (a record seeing back faces: a contact)
  neighbour,     ///< neighbour clamping R_i <= R_j + d (cache_expert_options::limit_radius_by_neighbours)
  disagreement,  ///< shrunk because it and a neighbour predict each other worse than a
};
inline constexpr std::size_t radius_limit_count = 6;

/// Why a point was open (not covered) when it was given a hemicube (cache_stats::hemicubes_by_reason).
enum class open_reason : std::uint8_t {
  uncovered,          ///< no record's weight passes 1/a there (or none is on its side)
  records_disagree,   ///< the covering records' predictions span more than a (refine_where_records_disagree)
  lone_change,        ///< one record covers it and its first-order term is too large (lone_record_change_limit)
  lone_reach,         ///< one record covers it, near the rim of its reach (lone_record_reach)
  nearby_disagrees,   ///< one record covers it and a record nearby predicts otherwise (lone_record_neighbour_reach)
};
inline constexpr std::size_t open_reason_count = 5;

/// One cache record (all vectors world space).
struct cache_record {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f, 0.0f, 1.0f};
  glm::vec3 irradiance{0.0f};
  std::array<glm::vec3, 3> rotation_gradient{};
  std::array<glm::vec3, 3> translation_gradient{};
  float radius = 0.0f;          ///< validity radius R_i (scene units) after all limits
  /// The last limit that lowered the radius (when it went below the record's smallest radius,
  /// the radius is that smallest radius and this says what pushed it there).
  radius_limit limit = radius_limit::split_sphere;
  float harmonic_distance = 0;  ///< the hemicube's split-sphere distance before any limit
  /// The sample's irradiance_sample::backface_fraction (at most invalid_backface_fraction, or it
  /// would not be a record). A record whose value passes a tenth of invalid_backface_fraction
  /// stands at a contact or where surfaces intersect: its radius is limited to its sample's
  /// min_distance (the nearest hit), then raised to min_radius if below it; past clear_distance
  /// only cache_run::segment_blocked keeps its reach from crossing the geometry it touches.
  float backface_fraction = 0.0f;
  /// The sample's irradiance_sample::min_distance (its hemicube's nearest hit; +inf if none): no
  /// geometry lies nearer in its visible half-space. Beyond it, with cache_run::segment_blocked,
  /// the record covers a point only if nothing blocks the segment between them.
  float clear_distance = std::numeric_limits<float>::infinity();
  /// L1 spherical harmonics of the incoming radiance, world space, the sample's
  /// irradiance_sample::sh_l1 (integrate.hpp: Y00, Y1-1 (y), Y10 (z), Y11 (x); coefficient k,
  /// channel c: sh_l1[k][c]). Zero unless cache_run::directional.
  std::array<glm::vec3, 4> sh_l1{};
  /// Irradiance on the HL2 cone (hl2_cone), the sample's cone. Zero unless cache_run::directional.
  hl2_cone cone;
  /// Ambient occlusion, the sample's sampler_result::ao (in [0, 1]). Zero unless cache_run::ao.
  float ao = 0.0f;
  /// Second-order term per channel c (world space, symmetric, acting in the record's tangent
  /// plane; units: irradiance per scene unit squared): the interpolation adds
  /// 1/2 (x - x_i)^T hessian[c] (x - x_i) to the first-order prediction when
  /// cache_options::second_order is on. Zero until fit_record_hessians fills it.
  std::array<glm::mat3, 3> hessian{};
};

/// Weighting of records. The values match hemilight_cache_weight of the C ABI (0, 1, 2).
enum class cache_weight {
  ward,                  ///< w = 1 / (d / R + sqrt(1 - n.n_i)), used where w > 1/a
  /// w = 1 - k max(d / (R/2), sqrt(1 - n.n_i) / 0.12326) with k = 1 / (2a), used where w > 0.
  /// k is tied to a so that both weights reach as far in space (d < a R); 0.12326 = sqrt(1 - cos 10 deg).
  tabellion_lamorlette,
  /// Ward's weight less 1/a, w - 1/a, used where w > 1/a: the same records cover the same points
  /// as with `ward` (placement and statistics are identical), but a record's weight falls to 0 at
  /// the edge of its reach instead of jumping from 1/a to 0 there, so the interpolated irradiance
  /// is continuous where a record's reach ends. Ward's own weight (and its jump) remains inside
  /// the coverage tests.
  ward_continuous,  // last, so the earlier values stay as they were (and match the C ABI's numbering)
};

/// Smallest error_threshold the cache takes: below it every point would be its own record (and
/// the spacings a R underflow), so a hemicube per point is the right tool.
inline constexpr float min_error_threshold = 0.001f;

/// Expert settings of the cache's placement: each default is the measured best (docs/cache.md,
/// "Placement"). Change them to study the cache, not to tune a bake.
struct cache_expert_options {
  bool limit_radius_by_gradient = true;    ///< R_i <= E_i / |g_t,i| (on luminance)
  bool limit_radius_by_neighbours = true;  ///< R_i <= R_j + |x_i - x_j|
  bool shrink_disagreeing_records = true;  ///< shrink neighbours whose predictions of each other miss by more than a
  /// A point stays uncovered while its covering records' first-order predictions span more than
  /// a x max(E, 5% of the mean record E): records gather along shadow edges, down to min_radius.
  bool refine_where_records_disagree = true;
  /// With cache_run::ao, the same for ambient occlusion: a point stays uncovered while its
  /// covering records' AO spans more than a x max(AO, 0.05), or (with lone_record_neighbour_reach)
  /// while a record near a point that one record covers holds an AO differing by more than that.
  /// AO has no gradient and varies where E may not (within the AO distance of contacts and
  /// corners), so records placed for E alone carry it with large errors there (the Cornell box at
  /// 48^2, AO within 2.3 texels: 5.5% RMS and 24% at the 99th percentile without the rule, 0.9% and
  /// 5.8% with it, for 42% more hemicubes in that pass; docs/bake.md, "Ambient occlusion").
  /// Ignored without cache_run::ao.
  bool refine_where_ao_disagrees = true;
  /// A point covered by one record only (not its own point) stays uncovered while that record's
  /// first-order term there exceeds lone_record_change_limit x a x max(E_i, 5% of the mean record
  /// E). Dimensionless, finite, >= 0; 0 = off.
  float lone_record_change_limit = 0.25f;
  /// ... or while a record within lone_record_neighbour_reach x a x min_radius of it that does not
  /// cover it (similar normal, not behind) predicts a luminance differing by more than a. In
  /// [0, 16]; 0 = off.
  float lone_record_neighbour_reach = 2.0f;
  /// ... and counts as covered only where that record's Ward weight >= 1 / (lone_record_reach x a)
  /// (ignored with the Tabellion-Lamorlette weight). In (0, 1]; 1 = off.
  float lone_record_reach = 0.99f;
  /// At the finest spacing, seeds are picked as in the coarser rounds (at least the spacing apart
  /// among points of similar normal), round after round until no point is open; false: every open
  /// point becomes a seed at once.
  bool space_finest_seeds = true;
  /// Neighbour clamping between records of any normals; false: only between records whose
  /// normals are similar (n_i . n_j > 0.9), as the disagreement shrink.
  bool clamp_across_normals = true;
  /// With cache_run::inside_test given, a seed the test calls inside geometry gets no hemicube.
  bool pretest_inside = true;
};

/// Options of the irradiance cache (what it computes; how one call runs is cache_run). Lengths
/// are in scene units.
struct cache_options {
  /// Ward's a: larger means fewer records and more error. In [min_error_threshold, 1].
  float error_threshold = 0.2f;
  /// Smallest and largest radius, finite, >= 0, min <= max when both are given. 0 = automatic:
  /// min_radius = (median spacing of the points) / a, max_radius = 0.2 x the diagonal of the
  /// points' bounding box (raised to min_radius if smaller).
  float min_radius = 0.0f, max_radius = 0.0f;
  /// With the automatic min_radius and cache_run::point_spacing given: min_radius =
  /// max(min_radius_spacings, 1 / a) x (median of point_spacing). A record at min_radius then
  /// reaches (a R) a x min_radius_spacings point spacings, and at least one: two texels at the
  /// default a = 0.2, one at a <= 0.1. Finite, in [1, 1000].
  float min_radius_spacings = 10.0f;
  bool use_gradients = true;  ///< interpolate with g_r and g_t
  cache_weight weight = cache_weight::ward;
  /// Second-order interpolation (needs use_gradients): each record gets a Hessian fitted from its
  /// neighbours (fit_record_hessians), clamped to +-a E_i per channel. Placement is unchanged.
  /// Cost: O(records x neighbours) once, 3 quadratic forms per covering record and point.
  bool second_order = true;
  /// Samples seeing more than this projected-solid-angle fraction of back faces are inside
  /// geometry: never records, and the points near them on their side are presumed inside too.
  /// In [0, 1].
  float invalid_backface_fraction = 0.1f;
  cache_expert_options expert;  ///< placement rules (the defaults are the measured best)
};

/// How one call of cache_irradiance runs: threads, progress, what it computes beyond irradiance
/// and which points it may skip. What a pipeline around the cache decides per call (bake_lightmap
/// sets it from its own options).
struct cache_run {
  int thread_count = 0;  ///< >= 0; 0 = all cores. Results do not depend on it.
  /// Called from the calling thread with the fraction of points covered so far, in [0, 1]; return
  /// false to cancel (error(status::cancelled), nothing written). May be empty.
  std::function<bool(float fraction)> progress;
  /// Records keep their sample's world-space L1 SH and HL2 cone (the sampler must compute them:
  /// sampler_pass), and cache_result::sh_l1 and ::cone get their weighted averages.
  bool directional = false;
  /// Records keep their sample's ambient occlusion (sampler_result::ao; the sampler must compute
  /// it: sampler_pass::ao_distance), and cache_result::ao gets its weighted average at every
  /// point, with the weights of E and no gradients. With
  /// cache_expert_options::refine_where_ao_disagrees (on by default) the coverage tests hold AO to
  /// a as they hold E, so records are added where AO varies faster than E (a different placement,
  /// and so different irradiance bits, than without AO); off, the records are placed for E alone
  /// and the irradiance is bitwise that of a run without AO. Cost: 4 bytes per record, one
  /// multiply-add per covering record and point, and the added records' hemicubes.
  bool ao = false;
  /// Give the points not interpolated (inside geometry) the average of the nearest records on
  /// their side of the surface; false leaves them at 0 for the caller to fill.
  bool fill_invalid = true;
  /// Optional, count entries (not owned, read during the call): nonzero marks a point known to be
  /// inside geometry (e.g. invalid in an earlier call over the same points and scene): no
  /// hemicube, reported invalid. nullptr = none.
  const std::uint8_t* known_inside = nullptr;
  /// Optional, count entries (not owned, read during the call): per point, the spacing of the
  /// points around it on its own surface (scene units, finite, > 0; the baker passes each texel's
  /// world size). With it the automatic min_radius is cache_options::min_radius_spacings (at least
  /// 1 / a) x their median instead of the median distance between nearest points / a, which thin parts (points close
  /// together in 3D across surfaces) pull far below the spacing on the surfaces. nullptr = none.
  const float* point_spacing = nullptr;
  /// Optional: a test cheaper than a hemicube (the baker: a few rays) of a seed before its
  /// hemicube; true = the point is surely inside geometry: no hemicube, the point is invalid (as an
  /// invalid sample's own point, presuming nothing around it). Called from the workers with the
  /// worker's index; must be deterministic and safe to call from different workers at once.
  /// Used with cache_expert_options::pretest_inside. Empty = none.
  std::function<bool(int worker, const glm::vec3& position, const glm::vec3& normal)> inside_test;
  /// Optional (the baker: an Embree any-hit ray): true when geometry blocks the segment from a
  /// record's position to a point. A record covers a point farther from it than its
  /// cache_record::clear_distance only when this says false, so no record reaches across a wall
  /// its radius spans (records are clamped up to min_radius: two texels at the defaults, more than
  /// a thin wall's thickness). Must be deterministic and thread-safe. Empty = none. Cost: one
  /// call per (record, point) pair weighed beyond the record's clear distance.
  std::function<bool(const glm::vec3& from, const glm::vec3& to)> segment_blocked;
};

/// What one placement round of cache_irradiance did (cache_stats::round_details).
struct cache_round_stats {
  float spacing = 0.0f;                  ///< the round's seed spacing (scene units)
  std::size_t points_checked = 0;        ///< points whose coverage the round's coverage pass tested
  /// Records the tested points' queries weighed (those whose coverage sphere held the point
  /// when they were added: the covering ones and those that shrank since), summed.
  std::size_t records_visited = 0;
  std::size_t max_records_visited = 0;   ///< the most records one query weighed
  std::size_t open_points = 0;           ///< seed candidates left open after the coverage pass
  std::size_t seeds = 0;                 ///< hemicubes rendered in the round
  std::size_t records_added = 0;         ///< of them valid (records)
  std::size_t invalid_samples = 0;       ///< of them inside geometry
  double coverage_seconds = 0.0, seed_seconds = 0.0, render_seconds = 0.0, update_seconds = 0.0;  ///< wall time per stage
};

/// Statistics of one cache run.
struct cache_stats {
  std::size_t hemicubes = 0;        ///< hemicubes rendered (records + invalid samples)
  std::size_t records = 0;          ///< records kept
  std::size_t invalid_samples = 0;  ///< samples rejected for seeing back faces (their own point is inside geometry)
  /// Points not interpolated (cache_result::valid = 0): invalid samples' own points and points
  /// presumed inside geometry near them, filled from records on their side (or left at 0).
  std::size_t invalid_points = 0;
  std::size_t rounds = 0;           ///< placement rounds that rendered hemicubes
  double seconds = 0.0;             ///< wall time
  /// Wall time of rendering and integrating hemicubes (render), of the final interpolation and
  /// fill (interpolation), and of everything else (placement: coverage passes, seed picking,
  /// record updates, automatic radii, second-order fits): the three add up to `seconds`.
  double placement_seconds = 0.0, render_seconds = 0.0, interpolation_seconds = 0.0;
  float min_radius = 0.0f, max_radius = 0.0f;  ///< the radii used (after automatic defaults)
  std::vector<cache_round_stats> round_details;  ///< per round, including those that rendered nothing (coverage only)
  /// What limits the records' radii (docs/cache.md, "What limits the radii"): records by the last
  /// limit that lowered their radius (cache_record::limit; index: radius_limit), and of them those
  /// whose final radius is their smallest allowed radius (raised to it, or clamped down to it).
  std::array<std::size_t, radius_limit_count> records_by_limit{};
  std::array<std::size_t, radius_limit_count> records_at_min_radius_by_limit{};
  std::size_t records_at_min_radius = 0;  ///< the sum of records_at_min_radius_by_limit
  /// Of the neighbour clamps (R_i <= R_j + d) that lowered a radius, those by a record whose
  /// normal differs (n_i . n_j <= 0.9).
  std::size_t neighbour_clamps = 0, neighbour_clamps_across_normals = 0;
  /// Medians over the records of the final radius and of the split-sphere (harmonic mean) distance.
  float median_radius = 0.0f, median_harmonic_distance = 0.0f;
  /// Hemicubes by why their point was open when it became a seed (index: open_reason); sums to hemicubes.
  std::array<std::size_t, open_reason_count> hemicubes_by_reason{};
  /// Of invalid_points: the invalid samples' own points, the points presumed inside by an invalid
  /// sample nearby (no hemicube), and those cache_run::known_inside gave.
  std::size_t presumed_inside_points = 0, known_inside_points = 0;
  /// Invalid samples by how much of their hemicube saw back faces: at most half (at the rim of a
  /// solid, or where a thin part passes through), more than half (deep inside).
  std::size_t invalid_samples_partly = 0, invalid_samples_deep = 0;
  /// Seeds given to cache_run::inside_test, and of them those it called inside (no hemicube; they
  /// count in invalid_points, not in hemicubes or invalid_samples).
  std::size_t inside_tests = 0, inside_by_test = 0;
  /// Records visited per coverage query, over all rounds: bucket 0 counts queries that visited
  /// none, bucket k >= 1 those that visited [2^(k-1), 2^k) records, the last bucket everything above.
  static constexpr std::size_t histogram_buckets = 16;
  std::array<std::size_t, histogram_buckets> records_visited_histogram{};
  /// The bucket of a visit count v (see records_visited_histogram).
  static constexpr std::size_t histogram_bucket(std::size_t v) noexcept {
    std::size_t k = 0;
    while (v > 0 && k + 1 < histogram_buckets) {
      v >>= 1;
      ++k;
    }
    return k;
  }
};

/// What cache_irradiance returns.
struct cache_result {
  std::vector<glm::vec3> irradiance;  ///< per point, RGB, >= 0
  std::vector<std::uint8_t> valid;    ///< per point: 1 = interpolated from covering records, 0 = filled (inside geometry or uncovered)
  /// Per point with run.directional (else empty): the Ward-weighted average of the covering
  /// records' world-space L1 SH (filled points: of the same nearest records as their E). Not
  /// clamped: band-1 coefficients are signed.
  std::vector<std::array<glm::vec3, 4>> sh_l1;
  /// Per point with run.directional (else empty): the records' cones rotated to the
  /// reference make_frame(normal).t of the point (rotate_hl2_cone) and averaged with the weights of E.
  std::vector<hl2_cone> cone;
  /// Per point with run.ao (else empty): the average of the covering records' ambient occlusion
  /// with the weights of E (no gradients), in [0, 1]; filled points: of the same nearest records as
  /// their E; points left unfilled (fill_invalid false): 0.
  std::vector<float> ao;
  std::vector<cache_record> records;
  cache_stats stats;
};

/// Checks every field against the range its comment states and throws error(invalid_argument)
/// naming the field, the message starting with `who` ("bake_lightmap: cache: error_threshold is
/// nan; ..."). Cost: O(1).
void validate_cache_options(const cache_options& options, const std::string& who);

/// Checks the points as cache_irradiance does and throws error(invalid_argument) for the first bad
/// one, the message starting with `who` and naming the array and index ("who: positions[3] =
/// (nan, 0, 0) is not finite or beyond 1e18", "normals[5] ... must be a unit vector"): count 0, a
/// null array, a position not finite or beyond max_coordinate, a normal whose length is not within
/// 1e-3 of 1, points spanning more than max_point_extent. Cost: O(count).
void validate_cache_points(const glm::vec3* positions, const glm::vec3* normals, std::size_t count, const std::string& who);

/// Largest extent (bounding-box diagonal, scene units) of the points cache_irradiance takes: the
/// cache squares distances between points in float.
inline constexpr double max_point_extent = 1e18;

/// Irradiance at `count` points (positions and unit normals, world space) through the cache.
/// Throws error(invalid_argument) naming the first bad input: the points as validate_cache_points
/// checks them, the options as validate_cache_options does, a negative run.thread_count;
/// error(cancelled) when run.progress returns false. Exceptions thrown by the sampler propagate
/// unchanged. Cost: one sampler call per record and invalid sample, plus O(count x log records)
/// for coverage and interpolation.
cache_result cache_irradiance(const glm::vec3* positions, const glm::vec3* normals, std::size_t count,
                              const irradiance_sampler& sampler, const cache_options& options, const cache_run& run = {});

/// Interpolates the cache at one point from `records` (the formula at the top of this header),
/// brute force over all records: for tests and tools. Returns the weight sum through
/// *weight_sum if given (0 when no record covers the point: the result is then 0).
glm::vec3 interpolate_records(const std::vector<cache_record>& records, const glm::vec3& position,
                              const glm::vec3& normal, const cache_options& options, float* weight_sum = nullptr);

/// Fits each record's `hessian` (per channel) from the records around it, as cache_irradiance
/// does with cache_options::second_order (docs/cache.md, "The second-order term"): the 2 x 2
/// symmetric Hessian in the record's tangent plane that best maps the offsets of its neighbours
/// (|x_j - x_i| <= 2 a R_i, n_i . n_j > 0.95) to their gradient differences, scaled by s in [0, 1]
/// by how well it predicts their irradiance beyond first order. Records with fewer than 2
/// neighbours get 0. Deterministic for any thread_count (>= 0; 0 = all cores).
/// Throws error(invalid_argument), naming the first bad record, when error_threshold is not in
/// [min_error_threshold, 1], a record's radius is negative or not finite, its position is not
/// finite or its normal's length is not 1 within 1e-3; records are then unchanged.
/// Irradiance and gradients are not checked: NaN in them gives that record a zero Hessian.
/// Cost: O(records x neighbours).
void fit_record_hessians(std::vector<cache_record>& records, const cache_options& options, int thread_count = 0);

/// Interpolates the records' L1 SH at one point with the weights of interpolate_records (plain
/// weighted average, no gradients, not clamped); zero when no record covers the point. Brute
/// force over all records: for tests and tools.
std::array<glm::vec3, 4> interpolate_records_sh_l1(const std::vector<cache_record>& records, const glm::vec3& position,
                                                   const glm::vec3& normal, const cache_options& options);

/// Interpolates the records' ambient occlusion (cache_record::ao) at one point with the weights of
/// interpolate_records (plain weighted average, no gradients); 0 when no record covers the point;
/// in [0, 1] for records' AO in [0, 1]. Brute force over all records: for tests and tools. Cost:
/// O(records).
float interpolate_records_ao(const std::vector<cache_record>& records, const glm::vec3& position, const glm::vec3& normal,
                             const cache_options& options);

/// The weight of one record at (position, normal) under options.weight and error_threshold,
/// before the behind test: Ward's w when w > 1/a, w - 1/a for ward_continuous (where w > 1/a),
/// the Tabellion-Lamorlette w when w > 0, else 0. A record at exactly the point and normal gets
/// 1e12 (both Ward weights: 1/0 capped) or 1 (T-L).
float record_weight(const cache_record& record, const glm::vec3& position, const glm::vec3& normal,
                    const cache_options& options);

/// True when the behind test rejects the record at (position, normal).
bool record_is_behind(const cache_record& record, const glm::vec3& position, const glm::vec3& normal);

}  // namespace hemilight
