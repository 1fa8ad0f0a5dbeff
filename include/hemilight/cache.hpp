// hemilight/cache.hpp — irradiance caching: render hemicubes at few of the points where
// irradiance is needed, interpolate the rest with gradients.
//
// Records (Ward 1988, Ward & Heckbert 1992): position x_i, normal n_i, irradiance E_i, gradients
// g_r,i and g_t,i (convention of integrate.hpp), validity radius R_i. Interpolation at (x, n):
//
//     E(x, n) = sum_i w_i (E_i + (n_i x n) . g_r,i + (x - x_i) . g_t,i) / sum_i w_i,  clamped >= 0
//
// (with second_order, each record's prediction also has 1/2 (x - x_i)^T H_i (x - x_i), H_i fitted
// after placement from the gradients of the records around it: fit_record_hessians)
//
// over the records with w_i > 1/a (Ward: w_i = 1 / (|x - x_i| / R_i + sqrt(1 - n . n_i))) that pass
// the "behind" test (a record is skipped when x lies behind it: (x - x_i) . (n_i + n) / 2 < -eps).
// With cache_weight::ward_continuous each such record is weighted w_i - 1/a instead, which falls
// to 0 at the edge of its reach (the coverage tests still use w_i).
//
// Radii: R_i = the hemicube's harmonic mean distance (split sphere), clamped to [min_radius,
// max_radius] and limited by (each a switch of cache_options): the translation gradient,
// R_i <= E_i / |g_t,i| (on luminance); neighbour clamping R_i <= R_j + |x_i - x_j|; and
// shrinking of neighbours whose gradients disagree (each predicts the other's irradiance worse
// than a allows), so that a record is placed between them.
//
// Placement is deterministic: the same input gives bitwise the same output for any thread count.
// It runs in rounds. Each round finds the points no record covers, picks among them, in a fixed
// pseudo-random order, seeds at least `spacing` apart (spacing halves every round, from
// a x max_radius down to a x min_radius), renders the seeds' hemicubes in parallel, and appends
// the new records in seed order. While the spacing s is coarse only a uniform sample of the
// points, about 9 per s x s of surface (the first ones in that order), are candidates; the others
// are tested when a finer spacing makes them candidates (at the finest spacing every point is).
// At the finest spacing neighbour clamping does not shrink older records (it limits the new
// ones, by each other and by the older ones); a disagreement shrinks both. Interpolation sums the
// covering records in record order, as interpolate_records does. A point counts as covered when a record's weight passes 1/a
// and (refine_disagreement) the covering records' predictions agree within a, and
// (second_opinion) a point covered by one record only is not extrapolated far from it, nor
// (sole_record_reach) from the rim of its reach, and (nearby_opinion) records near such a point
// that do not cover it agree with that record there. Samples that see more than
// invalid_backface_fraction back faces (the point is inside geometry) never become records; the
// points within 0.9 x such a sample's min distance on the visible side of its tangent plane and
// with a similar normal are presumed inside too, unless a valid record covers them (then they get
// their own hemicube, as do points covered by a record that saw back faces: a contact). Points
// inside are filled at the end from records on their side of the surface (fill_invalid).
// docs/cache.md, "Points inside geometry, and contacts".
#pragma once

#include "hemilight/integrate.hpp"
#include "hemilight/raster.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace hemilight {

/// Order of the azimuthal Fourier series of hl2_cone.
inline constexpr int hl2_cone_order = 3;
/// Number of its coefficients: a_0, then a_m, b_m for m = 1..hl2_cone_order.
inline constexpr int hl2_cone_terms = 2 * hl2_cone_order + 1;

/// The irradiance through every direction on the cone of Half-Life 2 basis vectors at a point:
/// b(phi) = n / sqrt3 + sqrt(2/3) (cos phi r + sin phi (n x r)), 54.74 degrees from the normal n,
/// phi the azimuth from the unit tangent `reference` r towards n x r. As a Fourier series
///     E(b(phi)) ~= a_0 + sum_{m=1..3} (a_m cos(m phi) + b_m sin(m phi)),   per channel,
/// coefficients = {a_0, a_1, b_1, a_2, b_2, a_3, b_3}. The three HL2 values of any tangent frame
/// are this function at three azimuths 120 degrees apart (hl2_from_cone), so a cone describes the
/// HL2 lighting of every frame about n. Exact (to quadrature) while the incoming radiance only comes
/// from within 35.26 degrees of n (then E(b(phi)) is a first-order series); otherwise the
/// harmonics above 3 of the clamped cosine are cut (docs/bake.md measures it).
struct hl2_cone {
  glm::vec3 reference{1.0f, 0.0f, 0.0f};  ///< unit tangent (world space) at phi = 0
  std::array<glm::vec3, hl2_cone_terms> coefficients{};  ///< [term][channel], see above
};

/// The same cone with its azimuth measured from `reference` (a unit tangent of `normal`, the cone's
/// normal) instead: phi' = phi - delta with delta the azimuth of `reference` in the cone's frame;
/// exact rotation of the series. When `reference` is not in the cone's tangent plane it is projected
/// onto it (used when records of neighbouring normals are averaged). Cost: one atan2 and 3 sincos.
hl2_cone rotate_hl2_cone(const hl2_cone& cone, const glm::vec3& normal, const glm::vec3& reference) noexcept;

/// E(b(phi)) of the series at azimuth phi (radians, from cone.reference towards n x reference),
/// per channel, not clamped. Cost: O(hl2_cone_order).
glm::vec3 evaluate_hl2_cone(const hl2_cone& cone, float phi) noexcept;

/// The three HL2 values (integrate.hpp's basis, hl2_basis of bake.hpp) of the tangent frame f
/// (f.n = the cone's normal; f may be left-handed, the basis follows it) from a cone, clamped at 0:
/// the series at phi_t + s (120, -120, 0) degrees, phi_t = azimuth of f.t, s = +1 for right-handed
/// frames and -1 for left-handed ones. Cost: 3 evaluations.
std::array<glm::vec3, 3> hl2_from_cone(const hl2_cone& cone, const frame& f) noexcept;

/// One cache record (all vectors world space).
struct cache_record {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f, 0.0f, 1.0f};
  glm::vec3 irradiance{0.0f};
  std::array<glm::vec3, 3> rotation_gradient{};
  std::array<glm::vec3, 3> translation_gradient{};
  float radius = 0.0f;          ///< validity radius R_i (scene units) after all limits
  float harmonic_distance = 0;  ///< the hemicube's split-sphere distance before any limit
  /// The sample's irradiance_sample::backface_fraction (at most invalid_backface_fraction, or it
  /// would not be a record). A record whose value passes a tenth of invalid_backface_fraction
  /// stands at a contact or where surfaces intersect: its radius is limited to its sample's
  /// min_distance (the nearest hit), so its reach a R never crosses the geometry it touches.
  float backface_fraction = 0.0f;
  /// L1 spherical harmonics of the incoming radiance, world space, the sample's
  /// irradiance_sample::sh_l1 (integrate.hpp: Y00, Y1-1 (y), Y10 (z), Y11 (x); coefficient k,
  /// channel c: sh_l1[k][c]). Zero unless cache_options::directional.
  std::array<glm::vec3, 4> sh_l1{};
  /// Irradiance on the HL2 cone (hl2_cone), the sample's cone. Zero unless directional.
  hl2_cone cone;
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
  /// the coverage tests. docs/cache.md gives its measured effect on the error.
  ward_continuous,  // last, so the earlier values stay as they were (and match the C ABI's numbering)
};

/// Smallest error_threshold the cache takes: below it every point would be its own record (and
/// the spacings a R underflow), so a hemicube per point is the right tool.
inline constexpr float min_error_threshold = 0.001f;

/// Options of the irradiance cache. Lengths are in scene units.
struct cache_options {
  /// Ward's a: larger means fewer records and more error. Radiance's defaults are 0.1 (rtrace),
  /// 0.2 (rpict), 0.3 (rvu). Range [min_error_threshold = 0.001, 1].
  float error_threshold = 0.2f;
  /// Smallest and largest radius. 0 = automatic: min_radius = (median spacing of the points) / a,
  /// so that a record covers at least its neighbouring points; max_radius = 0.2 x the diagonal of
  /// the points' bounding box (as Radiance's 0.2 S). After automatic values are derived,
  /// max_radius is raised to min_radius if smaller.
  float min_radius = 0.0f, max_radius = 0.0f;
  bool use_gradients = true;               ///< interpolate with g_r and g_t
  bool gradient_radius_limit = true;       ///< R_i <= E_i / |g_t,i|
  bool neighbour_clamp = true;             ///< R_i <= R_j + |x_i - x_j|
  bool shrink_disagreeing = true;          ///< shrink records whose gradients disagree
  /// A point also counts as uncovered while the records covering it disagree: their first-order
  /// predictions at the point span more than a x max(E, 5% of the mean record E) in luminance.
  /// This places records along shadow edges and other discontinuities the split-sphere radius
  /// cannot see, down to min_radius.
  bool refine_disagreement = true;
  /// Second opinion for points covered by a single record (other than the record's own point):
  /// such a point counts as uncovered while that record's first-order term there,
  /// |lum(E_i + (n_i x n).g_r,i + (x - x_i).g_t,i) - lum(E_i)|, exceeds
  /// second_opinion x a x max(lum(E_i), 5% of the mean record E). No other record can disagree
  /// with such an extrapolation, and a large first-order term is where it fails: a hard shadow
  /// edge between two rows of points, E falling to 0 at an emitter's plane (a second derivative
  /// the gradient cannot see). Mostly hits records at min_radius, which cover their grid
  /// neighbours at exactly the threshold weight. Dimensionless, >= 0; 0 = off. Default 0.25
  /// (docs/cache.md: its error against the share of points given a hemicube).
  float second_opinion = 0.25f;
  /// Opinion of nearby records for points covered by a single record (other than its own point):
  /// such a point counts as uncovered while some record within nearby_opinion x a x min_radius of
  /// it (a x min_radius: the finest seed spacing, about one point spacing) that does not cover it,
  /// with a similar normal (n . n_j > 0.9) and not behind, predicts there (E_j plus its gradient
  /// terms, clamped at 0) a luminance that differs from the covering record's prediction by more
  /// than a x max(that prediction, 5% of the mean record E). The covering record's gradient cannot
  /// see a hard shadow edge crossed between two rows of points (a floor point in a block's umbra
  /// covered by a lit record one row away); a record on the other side of the edge can.
  /// Dimensionless, in [0, 16]; 0 = off. Default 2 (records one or two rows of points away).
  float nearby_opinion = 2.0f;
  /// A point covered by a single record (other than its own point) counts as covered only inside
  /// this fraction of that record's reach: Ward weight >= 1 / (sole_record_reach x a) (ignored with
  /// the Tabellion-Lamorlette weight). At the automatic min_radius = spacing / a the grid neighbours
  /// of a record at min_radius lie exactly on its reach (weight 1/a), where float rounding decided
  /// whether that one record alone, with no second opinion, extrapolated to them. Points covered
  /// by two or more records are unaffected. Dimensionless, in (0, 1]; 1 = off. Default 0.99.
  float sole_record_reach = 0.99f;
  cache_weight weight = cache_weight::ward;
  /// Second-order interpolation (needs use_gradients): after placement, each record gets a Hessian
  /// of E over its tangent plane fitted from its neighbours (fit_record_hessians), and the
  /// interpolation adds 1/2 (x - x_i)^T H_i (x - x_i) to each record's first-order prediction.
  /// Placement and statistics are unchanged (the same records); only the final values differ.
  /// First-order predictions all miss a curved E the same way (below it where E is convex), so
  /// averaging them does not cancel that error. The term is clamped to +-a E_i per channel.
  /// docs/cache.md gives its measured effect on the error. Off when use_gradients is off.
  /// Cost: O(records x neighbours) once after placement (a few microseconds per record), and 3
  /// quadratic forms per covering record and point.
  bool second_order = true;
  float invalid_backface_fraction = 0.1f;  ///< samples seeing more back faces than this are invalid
  /// Give the points that are not interpolated (inside geometry: cache_result::valid = 0) the
  /// relaxed-weight average of the nearest records on their side of the surface. Off: they are
  /// left at 0, for callers that fill them in their own terms (the baker dilates valid texels of
  /// the same chart into them).
  bool fill_invalid = true;
  /// Optional, one entry per point (count entries; not owned, read during the call): nonzero marks
  /// a point known to be inside geometry, for instance one that an earlier cache_irradiance over
  /// the same points and scene reported invalid (cache_result::valid = 0: whether a point is
  /// inside depends on the geometry only, not on the light). Such a point gets no hemicube and no
  /// coverage test; it is reported invalid and, with fill_invalid, filled like the others. The
  /// baker passes each bounce pass the points the earlier passes found inside. nullptr = none.
  const std::uint8_t* known_inside = nullptr;
  /// Directional records: each record keeps its sample's world-space L1 SH (irradiance_sample::
  /// sh_l1; the sampler must compute it: make_hemicube_sampler with sh_l1 or
  /// integrate.directional) and its HL2 cone (cache_sample::cone, hemicube_sampler_options::hl2_cone;
  /// interpolated into cache_result::cone),
  /// and cache_result::sh_l1 gets, per point, the plain weighted average of the covering records'
  /// coefficients with the same weights as E (no gradients: SH coefficients are not extrapolated,
  /// and not rotated towards the point's normal). Off: records carry zeros and the interpolation
  /// costs nothing extra.
  bool directional = false;
  int thread_count = 0;                    ///< 0 = all cores
  /// Called from the calling thread between rounds and during rendering with the fraction of
  /// points covered so far, in [0, 1]; return false to cancel (error(status::cancelled) is thrown
  /// and nothing is written). May be empty.
  std::function<bool(float fraction)> progress;
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
  /// presumed inside geometry near them (cache.hpp, top), filled from records on their side.
  std::size_t invalid_points = 0;
  std::size_t rounds = 0;           ///< placement rounds that rendered hemicubes
  double seconds = 0.0;             ///< wall time
  /// Wall time of rendering and integrating hemicubes (render), of the final interpolation and
  /// fill (interpolation), and of everything else (placement: coverage passes, seed picking,
  /// record updates, automatic radii, second-order fits): the three add up to `seconds`.
  double placement_seconds = 0.0, render_seconds = 0.0, interpolation_seconds = 0.0;
  float min_radius = 0.0f, max_radius = 0.0f;  ///< the radii used (after automatic defaults)
  std::vector<cache_round_stats> round_details;  ///< per round, including those that rendered nothing (coverage only)
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

/// Renders and integrates one hemicube at (position, unit normal). `worker` is in
/// [0, thread count): use it to pick a per-thread rasterizer/integrator. Must be deterministic
/// in its arguments (apart from worker) and thread-safe across different workers.
/// What a sampler returns: integrate()'s sample plus, optionally, the irradiance on the HL2 cone
/// (zero when not computed). Implicitly made from an irradiance_sample, so a sampler may return one.
struct cache_sample : irradiance_sample {
  hl2_cone cone;
  cache_sample() = default;
  cache_sample(const irradiance_sample& s) : irradiance_sample(s) {}  // NOLINT: implicit on purpose
};
using irradiance_sampler = std::function<cache_sample(int worker, const glm::vec3& position, const glm::vec3& normal)>;

/// How make_hemicube_sampler renders and integrates.
struct hemicube_sampler_options {
  int resolution = 64;            ///< hemicube N (even, 2..4096)
  raster_options raster;          ///< near plane etc.
  integrate_options integrate;    ///< estimator etc. (the defaults are the cache's)
  /// Turn each hemicube about its normal by an angle hashed from the position's bits:
  /// deterministic, and it turns the texel grid's aliasing into fine noise instead of bands.
  bool roll = true;
  const radiance_texture* texture = nullptr;  ///< optional radiance texture (bounce passes); must outlive the sampler
  /// Fill irradiance_sample::sh_l1 (world-space L1 SH, integrate.hpp) cheaply, without
  /// integrate.directional: band 1 = Y1 Phi with the vector irradiance Phi = E n + g_r x n that
  /// the rotation gradient already holds (g_r = n x Phi, integrate.hpp), band 0 = Y00 sum_i L_i
  /// Omega_i over the buffer (exact texel solid angles, summed in double). The same values as the
  /// integrator's directional SH to float rounding, for one extra pass of 3 multiply-adds per
  /// texel instead of 15 double ones; irradiance_sample::hl2 stays zero. Needs
  /// integrate.rotation_gradient (make_hemicube_sampler throws error(invalid_argument) otherwise).
  bool sh_l1 = false;
  /// Fill cache_sample::cone: the irradiance on the HL2 cone of directions as a Fourier series in
  /// azimuth (hl2_cone), reference = the hemicube's (rolled) tangent. Per texel weights from the
  /// closed-form Fourier series of the clamped cosine max(0, w . b(phi)), integrated over 8 x 8
  /// sub-rectangles of each texel with exact solid angles, or exactly (the texel's vector solid
  /// angle) where the whole texel is within 35.26 degrees of the normal. Cost: one table per
  /// resolution (28 bytes per texel; built on first use and kept in the table cache, memory.hpp: ~0.1 s at N = 64) and
  /// 21 multiply-adds per texel.
  bool hl2_cone = false;
};

/// A sampler that renders `scene` with one rasterizer, integrator and buffer per worker
/// (`workers` of them: pass resolve_thread_count(options.thread_count) of the cache; each worker
/// makes its context on its first call, so workers that never run cost nothing). Throws
/// error(invalid_argument) for a null scene, an invalid resolution or invalid raster/integrate
/// options, or sh_l1 without integrate.rotation_gradient. The sampler throws error(invalid_argument) for a worker index out of range.
irradiance_sampler make_hemicube_sampler(std::shared_ptr<const scene> scene, const hemicube_sampler_options& options,
                                         int workers);

/// What cache_irradiance returns.
struct cache_result {
  std::vector<glm::vec3> irradiance;  ///< per point, RGB, >= 0
  std::vector<std::uint8_t> valid;    ///< per point: 1 = interpolated from covering records, 0 = filled (inside geometry or uncovered)
  /// Per point with options.directional (else empty): the Ward-weighted average of the covering
  /// records' world-space L1 SH (filled points: of the same nearest records as their E). Not
  /// clamped: band-1 coefficients are signed.
  std::vector<std::array<glm::vec3, 4>> sh_l1;
  /// Per point with options.directional (else empty): the records' cones rotated to the
  /// reference make_frame(normal).t of the point (rotate_hl2_cone) and averaged with the weights of E.
  std::vector<hl2_cone> cone;
  std::vector<cache_record> records;
  cache_stats stats;
};

/// Checks the options as cache_irradiance does (the ranges listed there) and throws
/// error(invalid_argument) naming the field, the message starting with `who` (e.g.
/// "bake_lightmap: error_threshold is nan; ..."). Bakes call it whatever use_cache says. Cost: O(1).
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
/// Throws error(invalid_argument) naming the first bad input: count == 0, NULL arrays, a NaN/Inf
/// position, points spanning more than max_point_extent, a normal whose length is not 1 within
/// 1e-3 (zero normals included), options out of
/// range (error_threshold not in [0.001, 1], negative or NaN radii, min_radius > max_radius when both
/// are given, second_opinion negative or not finite, nearby_opinion not in [0, 16],
/// sole_record_reach not in (0, 1], invalid_backface_fraction not in [0, 1]); error(cancelled) if progress returned
/// false. Exceptions thrown by the sampler propagate unchanged. Cost: one sampler call per
/// record and invalid sample, plus O(count x log records) for coverage and interpolation.
cache_result cache_irradiance(const glm::vec3* positions, const glm::vec3* normals, std::size_t count,
                              const irradiance_sampler& sampler, const cache_options& options);

/// Interpolates the cache at one point from `records` (the formula at the top of this header),
/// brute force over all records: for tests and tools. Returns the weight sum through
/// *weight_sum if given (0 when no record covers the point: the result is then 0).
glm::vec3 interpolate_records(const std::vector<cache_record>& records, const glm::vec3& position,
                              const glm::vec3& normal, const cache_options& options, float* weight_sum = nullptr);

/// Fits each record's `hessian` (per channel) from the records around it, as cache_irradiance
/// does with cache_options::second_order:
///  - neighbours: records j != i with |x_j - x_i| <= 2 a R_i (a = options.error_threshold) and
///    n_i . n_j > 0.95;
///  - the 2 x 2 symmetric Hessian in the record's tangent plane is the least-squares solution of
///    P (g_t,j - g_t,i) = H P (x_j - x_i) over the neighbours (P: projection on the tangent plane),
///    with a ridge of 1e-6 of the normal matrix's trace (neighbours on one line leave the direction
///    across it at 0);
///  - then it is scaled by s in [0, 1], the least-squares factor by which the quadratic term best
///    predicts the neighbours' irradiance beyond the first-order prediction, E_j - (E_i +
///    (n_i x n_j).g_r,i + (x_j - x_i).g_t,i). The values are data the fit did not use: where the
///    gradients' differences are not a smooth quadratic (a shadow edge, a ceiling line), s goes
///    to 0 and the record stays first-order.
/// Records with fewer than 2 neighbours get 0. Deterministic for any thread count
/// (options.thread_count; 0 = all cores). Throws error(invalid_argument), naming the first bad
/// record, when error_threshold is not in [0.001, 1], a record's radius is negative or not finite, its
/// position is not finite or its normal's length is not 1 within 1e-3; records are then unchanged.
/// Irradiance and gradients are not checked: NaN in them gives that record a zero Hessian.
/// Cost: O(records x neighbours).
void fit_record_hessians(std::vector<cache_record>& records, const cache_options& options);

/// Interpolates the records' L1 SH at one point with the weights of interpolate_records (plain
/// weighted average, no gradients, not clamped); zero when no record covers the point. Brute
/// force over all records: for tests and tools.
std::array<glm::vec3, 4> interpolate_records_sh_l1(const std::vector<cache_record>& records, const glm::vec3& position,
                                                   const glm::vec3& normal, const cache_options& options);

/// The weight of one record at (position, normal) under options.weight and error_threshold,
/// before the behind test: Ward's w when w > 1/a, w - 1/a for ward_continuous (where w > 1/a),
/// the Tabellion-Lamorlette w when w > 0, else 0. A record at exactly the point and normal gets
/// 1e12 (both Ward weights: 1/0 capped) or 1 (T-L).
float record_weight(const cache_record& record, const glm::vec3& position, const glm::vec3& normal,
                    const cache_options& options);

/// True when the behind test rejects the record at (position, normal).
bool record_is_behind(const cache_record& record, const glm::vec3& position, const glm::vec3& normal);

}  // namespace hemilight
