// cache_irradiance (cache.hpp): the placement of records in rounds, and the final
// interpolation, as a chain of named stages (the class placement below).
#include "fit_record_hessians.hpp"
#include "pseudo_random.hpp"
#include "record_index.hpp"
#include "validation.hpp"
#include "weights.hpp"

#include "hemilight/cache.hpp"
#include "hemilight/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

namespace hemilight {

namespace {

using namespace cache_detail;

// placement::candidate_count: seed candidates per seed spacing along a surface (so about 9 per
// spacing x spacing square); 3 keeps the seeds' spacing as with every point a candidate (the
// records, hemicube counts and errors: docs/cache.md) while checking a third fewer points.
constexpr double candidates_per_spacing = 3.0;
// placement: a record whose coverage sphere holds at most max_listed_points points is listed at
// them (record_lists) while the lists hold fewer than list_entries_per_point entries per point in
// all; the others go into a tree of their own. Lists make a coverage test cheap; the budget bounds
// their memory (docs/cache.md: the time and memory of both).
constexpr std::size_t max_listed_points = 1024;
constexpr std::size_t list_entries_per_point = 8;
// render_seeds marks a seed that cache_run::inside_test called inside with this backface
// fraction (no hemicube; a sampler never returns more than 1).
constexpr float tested_inside = 2.0f;
// With cache_run::ao and cache_expert_options::refine_where_ao_disagrees, the coverage tests hold
// the AO the records predict to a x max(AO, ao_floor), as they hold E to a x max(E, 5% of the mean
// record E): AO is a fraction in [0, 1], so its floor is absolute.
constexpr float ao_floor = 0.05f;

// A seed of pick_seeds: where it is and its normal.
struct seed {
  glm::vec3 position, normal;
};

// What the placement's coverage test needs beyond the value: how many records cover the point and
// the largest first-order term |lum(prediction) - lum(E_i)| of a covering record relative to
// max(lum(E_i), floor) (floor given in).
struct coverage_detail {
  float floor = 0.0f;
  int records = 0;
  float first_order = 0.0f;
  float max_weight = 0.0f;       // largest weight of a covering record
  std::uint32_t last = 0;        // index of the last covering record (the only one when records == 1)
  float last_prediction = 0.0f;  // its luminance prediction at the point
  std::size_t visited = 0;       // records whose box the query visited (covering or not)
  float ao_lo = 0.0f, ao_hi = 0.0f;  // the covering records' smallest and largest AO (with `ao`)
};

// Interpolation at one point through the BVH; returns the weight sum (0: not covered).
// `spread` (optional) receives the range (max - min) of the luminance the covering records
// predict for the point, and `own` whether one of them sits at the point itself.
// `sh` (optional) receives the same weighted average of the records' L1 SH (zero if uncovered),
// `cone` the same of the HL2 cones, `ao` the same of their ambient occlusion, `detail` (optional)
// what coverage_detail describes.
float interpolate(const std::vector<cache_record>& records, const record_lists& lists, const record_bvh& large, std::size_t point, const glm::vec3& x,
                  const glm::vec3& n, const cache_options& o, glm::vec3& out, float* spread = nullptr,
                  bool* own = nullptr, std::array<glm::vec3, 4>* sh = nullptr, hl2_cone* cone = nullptr,
                  coverage_detail* detail = nullptr,
                  const std::function<bool(const glm::vec3&, const glm::vec3&)>* blocked = nullptr, float* ao = nullptr) {
  // 1. The covering records and their weights, then in record order: the sums below do not
  // depend on how the lists and the tree report records (the same order as interpolate_records).
  struct covering {
    std::uint32_t index;
    float w;
  };
  thread_local std::vector<covering> cover;
  cover.clear();
  std::size_t visited = 0;
  const auto consider = [&](const record_key& key) {
    ++visited;
    const float w = weight_of(key, x, n, o);
    if (!(w > 0.0f) || is_behind(key, x, n)) return;
    // Beyond the nearest geometry the record's hemicube saw, a wall may stand between it and x.
    if (blocked && glm::length(x - key.position) > records[key.index].clear_distance && (*blocked)(key.position, x)) return;
    cover.push_back({key.index, w});
  };
  lists.query(point, consider);  // the records of few points, listed at the point
  large.query(x, consider);      // the others (each record is in one of the two)
  std::sort(cover.begin(), cover.end(), [](const covering& p, const covering& q) { return p.index < q.index; });
  // 2. The weighted sums.
  glm::vec3 sum(0.0f);
  std::array<glm::vec3, 4> sh_sum{};
  hl2_cone cone_sum;
  if (cone) cone_sum.reference = make_frame(n).t;
  float wsum = 0.0f, ao_sum = 0.0f, lo = std::numeric_limits<float>::infinity(), hi = -lo;
  bool at_record = false;
  const int order = prediction_order(o);
  for (const covering& c : cover) {
    const std::uint32_t i = c.index;
    const float w = c.w;
    const cache_record& r = records[i];
    const glm::vec3 e = extrapolate(r, x, n, order, o.error_threshold);
    sum += w * e;
    wsum += w;
    if (sh)
      for (std::size_t k = 0; k < 4; ++k) sh_sum[k] += w * r.sh_l1[k];
    if (cone) {
      const hl2_cone rc = rotate_hl2_cone(r.cone, r.normal, cone_sum.reference);
      for (std::size_t k = 0; k < std::size_t(hl2_cone_terms); ++k) cone_sum.coefficients[k] += w * rc.coefficients[k];
    }
    if (ao) ao_sum += w * r.ao;
    if (ao && detail) {
      detail->ao_lo = detail->records == 0 ? r.ao : std::min(detail->ao_lo, r.ao);
      detail->ao_hi = detail->records == 0 ? r.ao : std::max(detail->ao_hi, r.ao);
    }
    const float l = luminance(e);
    lo = std::min(lo, l);
    hi = std::max(hi, l);
    if (detail) {
      const float li = luminance(r.irradiance);
      ++detail->records;
      detail->last = i;
      detail->max_weight = std::max(detail->max_weight, w);
      detail->last_prediction = l;
      detail->first_order = std::max(detail->first_order, std::fabs(l - li) / std::max({li, detail->floor, 1e-30f}));
    }
    at_record = at_record || r.position == x;
  }
  out = wsum > 0.0f ? glm::max(sum / wsum, glm::vec3(0.0f)) : glm::vec3(0.0f);
  if (sh)
    for (std::size_t k = 0; k < 4; ++k) (*sh)[k] = wsum > 0.0f ? sh_sum[k] / wsum : glm::vec3(0.0f);
  if (cone) {
    if (wsum > 0.0f)
      for (glm::vec3& c : cone_sum.coefficients) c /= wsum;
    *cone = cone_sum;
  }
  if (ao) *ao = wsum > 0.0f ? ao_sum / wsum : 0.0f;
  if (detail) detail->visited = visited;
  if (spread) *spread = wsum > 0.0f ? hi - lo : 0.0f;
  if (own) *own = at_record;
  return wsum;
}

// Median distance from a point to its nearest other point (at a distance > 0), over up to 1024
// evenly strided points, found in the point grid within spheres of radius diagonal / sqrt(count)
// (about the spacing of points on surfaces), doubled up to four times that; a point with no
// neighbour that near is left out.
float median_spacing(const glm::vec3* p, std::size_t count, float diagonal, const point_grid& grid) {
  if (count < 2 || !(diagonal > 0.0f)) return 0.0f;
  const float reach = diagonal / std::sqrt(float(count));
  std::vector<float> nn;
  const std::size_t stride = std::max<std::size_t>(1, count / 1024);
  for (std::size_t i = 0; i < count; i += stride) {
    float best = std::numeric_limits<float>::infinity();
    for (float r = reach; r <= 4.0f * reach && !(best <= r); r *= 2.0f)
      grid.for_each_in_sphere(p[i], r, [&](std::uint32_t j) {
        const float d = glm::length(p[j] - p[i]);
        if (d > 0.0f) best = std::min(best, d);
      });
    if (best <= 4.0f * reach) nn.push_back(best);
  }
  if (nn.empty()) return 0.0f;
  std::nth_element(nn.begin(), nn.begin() + std::ptrdiff_t(nn.size() / 2), nn.end());
  return nn[nn.size() / 2];
}

// One run of cache_irradiance (cache.hpp), as a chain of named stages over shared state:
//   derive_radii -> set_up -> [ coverage_pass -> pick_seeds -> render_seeds -> append_records
//                     -> limit_radii -> mark_dirty ]* -> fit_hessians -> interpolate_all
//                     -> fill_invalid
// Per point the state is: covered (a record's weight passes 1/a and the opinions agree), own
// invalid sample (inside geometry: its own hemicube saw back faces), presumed inside (within the
// exclusion ball of an invalid sample on the same side of the same surface; final, as own invalid
// is). A point is open when it is none of covered, own invalid or presumed; an open point is a
// seed candidate when its rank in the fixed pseudo-random order is below the round's
// candidate_count.
// Where the time goes and why each structure is there: docs/cache.md, "Placement".
// The structures, each kept up to date as records are added:
//   lists_      per point, the records of few points whose sphere held it, and
//   large_tree_ the other records in a tree (both: coverage and final interpolation)
//   bvh_        the records' boxes, rebuilt each round (limit_radii's neighbours)
//   record_cells_  the records' positions (nearby_records_agree)
//   models_     per record, its first-order model, compact (limit_radii, nearby_records_agree)
class placement {
 public:
  placement(const glm::vec3* positions, const glm::vec3* normals, std::size_t count, const irradiance_sampler& sampler,
            const cache_options& options, const cache_run& run)
      : p_(positions), n_(normals), count_(count), sampler_(sampler), o_(options), r_(run) {}

  cache_result run() {
    const auto start = std::chrono::steady_clock::now();
    threads_ = resolve_thread_count(r_.thread_count);
    grid_of_points_.build(p_, count_);
    derive_radii();
    set_up();
    for (;;) {
      cache_round_stats round;
      round.spacing = spacing_;
      candidates_ = candidate_count();
      timed(round.coverage_seconds, [&] { coverage_pass(round); });
      const std::size_t open = open_candidates();
      round.open_points = open;
      report(1.0f - float(open_list_.size()) / float(count_));
      if (open == 0) {
        stats_.round_details.push_back(round);
        if (candidates_ == count_) break;
        spacing_ = std::max(finest_, 0.5f * spacing_);  // nothing to place among this round's candidates
        continue;
      }
      std::vector<std::size_t> seeds;
      timed(round.seed_seconds, [&] { seeds = pick_seeds(); });
      std::vector<sampler_result> samples;
      timed(round.render_seconds, [&] { samples = render_seeds(seeds, open); });
      round.seeds = seeds.size();
      timed(round.update_seconds, [&] {
        const std::size_t first_new = append_records(seeds, samples, round);
        limit_radii(first_new);
        mark_dirty(first_new);
      });
      stats_.round_details.push_back(round);
      ++stats_.rounds;
      if (spacing_ > finest_)
        spacing_ = std::max(finest_, 0.5f * spacing_);
      else if (seeds.empty())
        break;  // defensive: nothing could be placed
    }
    if (o_.second_order && o_.use_gradients) fit_hessians(records_, o_, threads_);
    cache_result result;
    const auto t_final = std::chrono::steady_clock::now();
    interpolate_all(result);
    stats_.invalid_points = count_invalid(result);
    for (std::size_t i = 0; i < count_; ++i) {
      stats_.presumed_inside_points += presumed_[i] && !own_invalid_[i] ? 1u : 0u;
      stats_.known_inside_points += r_.known_inside && r_.known_inside[i] ? 1u : 0u;
    }
    count_limits();
    if (r_.fill_invalid) fill_invalid(result);
    stats_.interpolation_seconds = seconds_since(t_final);
    for (const cache_round_stats& r : stats_.round_details) stats_.render_seconds += r.render_seconds;
    stats_.records = records_.size();
    stats_.min_radius = o_.min_radius;
    stats_.max_radius = o_.max_radius;
    stats_.seconds = seconds_since(start);
    stats_.placement_seconds = std::max(0.0, stats_.seconds - stats_.render_seconds - stats_.interpolation_seconds);
    report(1.0f);
    result.records = std::move(records_);
    result.stats = stats_;
    return result;
  }

 private:
  static double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  }
  template <class F>
  static void timed(double& seconds, F&& f) {
    const auto t = std::chrono::steady_clock::now();
    f();
    seconds += seconds_since(t);
  }

  // Coverage can drop between rounds (radii shrink), so the reported fraction is the running
  // maximum: progress never goes backwards.
  void report(float fraction) {
    reported_ = std::max(reported_, fraction);
    if (r_.progress && !r_.progress(reported_)) throw error(status::cancelled, "cache_irradiance: cancelled by the progress callback");
  }

  // Automatic radii from the points' extent and spacing (cache_options::min_radius, max_radius).
  void derive_radii() {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (std::size_t i = 0; i < count_; ++i) {
      lo = glm::min(lo, p_[i]);
      hi = glm::max(hi, p_[i]);
    }
    lo_ = lo;
    hi_ = hi;
    diagonal_ = glm::length(hi - lo);
    const float a = o_.error_threshold;
    if (o_.min_radius == 0.0f && r_.point_spacing) {
      std::vector<float> given(r_.point_spacing, r_.point_spacing + count_);
      std::nth_element(given.begin(), given.begin() + std::ptrdiff_t(count_ / 2), given.end());
      o_.min_radius = std::max(o_.min_radius_spacings, 1.0f / a) * given[count_ / 2];
    }
    if (o_.min_radius == 0.0f) {
      const float spacing = median_spacing(p_, count_, diagonal_, grid_of_points_);
      o_.min_radius = spacing > 0.0f ? spacing / a : std::max(diagonal_, 1e-3f) * 1e-3f;
    }
    if (o_.max_radius == 0.0f) o_.max_radius = 0.2f * diagonal_;
    o_.max_radius = std::max(o_.max_radius, o_.min_radius);
    spacing_ = a * o_.max_radius;
    finest_ = a * o_.min_radius;
    nearby_reach_ = o_.expert.lone_record_neighbour_reach * finest_;
    contact_backface_ = 0.1f * o_.invalid_backface_fraction;
    ao_refine_ = r_.ao && o_.expert.refine_where_ao_disagrees;
  }

  void set_up() {
    lists_.reset(count_, threads_);
    large_records_.clear();
    listed_points_.clear();
    listed_entries_ = 0;
    list_budget_ = list_entries_per_point * count_;
    large_tree_.build(records_, o_, 1, &large_records_);
    record_cells_.reset(lo_, hi_, std::max(nearby_reach_, finest_), count_);
    for (auto* v : {&covered_, &own_invalid_, &presumed_, &open_reason_}) v->assign(count_, 0);
    // Points the caller knows to be inside geometry (cache_options::known_inside) are invalid
    // from the start, as if their own sample had been: no hemicube, no coverage test.
    if (r_.known_inside)
      for (std::size_t i = 0; i < count_; ++i) own_invalid_[i] = r_.known_inside[i] ? 1 : 0;
    dirty_.assign(count_, 1);  // the first coverage pass tests every point
    dirty_list_.resize(count_);
    std::iota(dirty_list_.begin(), dirty_list_.end(), std::uint32_t(0));
    in_open_list_.assign(count_, 0);
    open_list_.clear();
    order_ = pseudo_random_order(count_);
    rank_.resize(count_);
    for (std::size_t k = 0; k < count_; ++k) rank_[order_[k]] = static_cast<std::uint32_t>(k);
    // The coverage tests weigh records with Ward's own weight under ward_continuous too, so that
    // both place the same records (only the final interpolation differs; cache.hpp).
    coverage_options_ = o_;
    if (coverage_options_.weight == cache_weight::ward_continuous) coverage_options_.weight = cache_weight::ward;
    
    coverage_options_.second_order = false;  // the Hessians are fitted after placement
  }

  bool inside(std::size_t i) const { return own_invalid_[i] || presumed_[i]; }
  bool open(std::size_t i) const { return !covered_[i] && !inside(i); }
  float radius_of(std::size_t j) const { return lists_[j].radius; }  // compact: the record's radius

  // The seed candidates of the round: the points of rank below this count. At spacing s only
  // about candidates_per_spacing^2 points per s x s area of surface take part (the first ones in
  // the fixed pseudo-random order: a uniform sample); the coverage of the others is checked when a
  // finer spacing makes them candidates, so a point is not checked again and again while records
  // are coarse. At the finest spacing, and from spacing candidates_per_spacing x finest on, every
  // point.
  std::size_t candidate_count() const {
    if (!(spacing_ > finest_)) return count_;
    const double share = double(candidates_per_spacing) * double(finest_) / double(spacing_);
    return share >= 1.0 ? count_ : std::max<std::size_t>(1, std::size_t(double(count_) * share * share));
  }
  // How many open points are candidates (open_list_ is in rank order: a prefix).
  std::size_t open_candidates() const {
    return std::size_t(std::lower_bound(open_list_.begin(), open_list_.end(), candidates_,
                                        [&](std::uint32_t i, std::size_t k) { return rank_[i] < k; }) - open_list_.begin());
  }

  // 1. Coverage of every candidate point whose answer can have changed (parallel, read-only on
  // the records): the dirty points (all of them at first; then those in the reach of a record
  // added or shrunk since they were last checked, within expert.lone_record_neighbour_reach's reach of a new record,
  // or newly presumed inside). Every other point, open or covered, sees the same records with the
  // same radii as when it was last checked, and its opinions come from the same records, so its
  // answer stands. Dirty points that are not yet candidates stay dirty until they are (at the
  // finest spacing every point is). The dark floor of the tests
  // (floor_e_: 5% of the mean irradiance of the first round's records, a uniform sample of the
  // points) is fixed once set, so no answer depends on records far away.
  void coverage_pass(cache_round_stats& round) {
    if (!floor_set_ && !records_.empty()) {
      double mean = 0.0;
      for (const cache_record& r : records_) mean += luminance(r.irradiance);
      floor_e_ = 0.05f * float(mean / double(records_.size()));
      floor_set_ = true;
    }
    struct tally {
      std::size_t checked = 0, visited = 0, max_visited = 0;
      std::array<std::size_t, cache_stats::histogram_buckets> histogram{};
    };
    std::vector<tally> tallies(static_cast<std::size_t>(threads_));
    in_index_order(dirty_list_, dirty_);  // neighbouring points (lightmap order) one after another
    parallel_for(dirty_list_.size(), threads_, 1024, [&](int worker, std::size_t b, std::size_t e) {
      tally& t = tallies[std::size_t(worker)];
      for (std::size_t k = b; k < e; ++k) {
        const std::size_t i = dirty_list_[k];
        if (inside(i) || rank_[i] >= candidates_) continue;
        std::size_t visited = 0;
        check_point(i, visited);
        ++t.checked;
        t.visited += visited;
        t.max_visited = std::max(t.max_visited, visited);
        ++t.histogram[cache_stats::histogram_bucket(visited)];
      }
    });
    for (const tally& t : tallies) {
      round.points_checked += t.checked;
      round.records_visited += t.visited;
      round.max_records_visited = std::max(round.max_records_visited, t.max_visited);
      for (std::size_t k = 0; k < t.histogram.size(); ++k) stats_.records_visited_histogram[k] += t.histogram[k];
    }
    update_open_list();
  }

  // The open points in the fixed order (open_list_): a point's answer changes only in a coverage
  // pass that checks it, or when it becomes inside (then it is dropped here), so the checked
  // points that are open join the list and the list drops what is no longer open.
  void update_open_list() {
    std::size_t deferred = 0;
    for (std::uint32_t i : dirty_list_) {
      if (rank_[i] >= candidates_) {  // not checked: stays dirty
        dirty_list_[deferred++] = i;
        continue;
      }
      dirty_[i] = 0;
      if (open(i) && !in_open_list_[i]) {
        in_open_list_[i] = 1;
        open_list_.push_back(i);
      }
    }
    dirty_list_.resize(deferred);
    std::size_t kept = 0;
    for (std::uint32_t i : open_list_) {
      if (open(i))
        open_list_[kept++] = i;
      else
        in_open_list_[i] = 0;
    }
    open_list_.resize(kept);
    if (open_list_.size() > count_ / 16) {  // a long list: the order itself, filtered
      open_list_.clear();
      for (std::uint32_t i : order_)
        if (in_open_list_[i]) open_list_.push_back(i);
    } else {  // a short one: sorted by rank
      for (std::uint32_t& i : open_list_) i = rank_[i];
      std::sort(open_list_.begin(), open_list_.end());
      for (std::uint32_t& k : open_list_) k = order_[k];
    }
  }

  // Sorts `list`, the indices of the points whose flag is set, ascending: a long list by a scan of
  // the flags, a short one by sorting.
  void in_index_order(std::vector<std::uint32_t>& list, const std::vector<std::uint8_t>& flag) const {
    if (list.size() > count_ / 16) {
      list.clear();
      for (std::size_t i = 0; i < count_; ++i)
        if (flag[i]) list.push_back(static_cast<std::uint32_t>(i));
    } else {
      std::sort(list.begin(), list.end());
    }
  }

  // The coverage test of one point (coverage_pass); `visited` counts the records the query saw.
  void check_point(std::size_t i, std::size_t& visited) {
    const float a = o_.error_threshold;
    glm::vec3 value;
    float spread = 0.0f;
    bool own = false;
    coverage_detail detail;
    detail.floor = floor_e_;
    // Records whose sphere shrank past the point never cover it again (radii only shrink): out
    // of its list (the margin is coverage_weight's).
    lists_.compact(i, [&](const record_lists::key& key) {
      const glm::vec3 dx = p_[i] - key.position;
      const float reach = o_.error_threshold * key.radius;
      return glm::dot(dx, dx) <= 1.0002f * reach * reach;
    });
    float ao = 0.0f;
    const float w = interpolate(records_, lists_, large_tree_, i, p_[i], n_[i], coverage_options_, value, &spread, &own, nullptr, nullptr, &detail,
                                blocked(), r_.ao ? &ao : nullptr);
    visited = detail.visited;
    bool ok = w > 0.0f;
    open_reason why = open_reason::uncovered;
    if (ok && o_.expert.refine_where_records_disagree && !own) {
      ok = spread <= a * std::max(luminance(value), floor_e_);
      why = open_reason::records_disagree;
    }
    // The same for AO (cache_run::ao): it varies where E may not (within the AO distance of a
    // contact or a corner, under a uniform light), and it has no gradient to extrapolate with.
    if (ok && ao_refine_ && !own) {
      ok = detail.ao_hi - detail.ao_lo <= a * std::max(ao, ao_floor);
      why = open_reason::records_disagree;
    }
    // Second opinion: a point that only one record covers is not covered while that record's
    // first-order term there exceeds expert.lone_record_change_limit x a x max(E_i, floor): no other record can
    // disagree with an extrapolation that may be wrong (an edge between two rows of points, a
    // second derivative the gradient does not see).
    if (ok && o_.expert.lone_record_change_limit > 0.0f && !own && detail.records == 1) {
      ok = detail.first_order <= o_.expert.lone_record_change_limit * a;
      why = open_reason::lone_change;
    }
    // Sole record reach: a point that one record covers must lie inside expert.lone_record_reach of
    // that record's reach (Ward: weight >= 1 / (expert.lone_record_reach x a)), not on its rim.
    if (ok && o_.expert.lone_record_reach < 1.0f && !own && detail.records == 1 && coverage_options_.weight == cache_weight::ward) {
      ok = detail.max_weight >= 1.0f / (o_.expert.lone_record_reach * a);
      why = open_reason::lone_reach;
    }
    // Nearby opinion: records near a point that one record covers, which do not cover it
    // themselves, must predict the same there within a (a hard shadow edge between two rows of
    // points is invisible to the covering record's gradient, not to a record beyond it).
    if (ok && o_.expert.lone_record_neighbour_reach > 0.0f && !own && detail.records == 1) {
      ok = nearby_records_agree(i, detail, ao);
      why = open_reason::nearby_disagrees;
    }
    covered_[i] = ok ? 1 : 0;
    open_reason_[i] = static_cast<std::uint8_t>(why);
  }

  // (With ao_refine_, the nearby records' AO must agree with the covering record's `ao` as well.)
  bool nearby_records_agree(std::size_t i, const coverage_detail& detail, float ao) const {
    const glm::vec3 x = p_[i], nx = n_[i];
    const float la = std::max(detail.last_prediction, 0.0f);
    const float tolerance = o_.error_threshold * std::max(la, floor_e_);
    const float r2 = nearby_reach_ * nearby_reach_;
    return !record_cells_.any_near(x, nearby_reach_, [&](std::uint32_t k) {
      const linear_model& rb = models_[k];
      const glm::vec3 d = rb.position - x;
      if (k == detail.last || glm::dot(d, d) > r2) return false;
      if (glm::dot(rb.normal, nx) <= 0.9f || is_behind(rb, x, nx)) return false;
      const float lb = luminance(glm::max(o_.use_gradients ? rb.predict(x, nx) : rb.irradiance, glm::vec3(0.0f)));
      if (ao_refine_ && std::fabs(records_[k].ao - ao) > o_.error_threshold * std::max(ao, ao_floor)) return true;
      return std::fabs(lb - la) > tolerance;
    });
  }

  // 2. Seeds: open points in the fixed order, at least `spacing` from this round's earlier seeds
  // of a similar normal; at the finest spacing every open point is a seed. The round's seeds go
  // into a uniform grid of cells at least `spacing` wide, so a candidate looks at the seeds of
  // the cells around it only (cost O(open points), whatever the spacing).
  std::vector<std::size_t> pick_seeds() {
    std::vector<std::size_t> seeds;
    const bool finest = !(spacing_ > finest_);
    if (finest && !o_.expert.space_finest_seeds) {
      seeds.assign(open_list_.begin(), open_list_.begin() + std::ptrdiff_t(open_candidates()));
      return seeds;
    }
    seed_cells_.reset(lo_, hi_, spacing_, open_list_.size());
    const float r2 = spacing_ * spacing_;
    // The points are visited in a pseudo-random order: the positions and normals a few steps
    // ahead are prefetched.
    constexpr std::size_t ahead = 16;
    const std::size_t open_count = open_candidates();
    for (std::size_t k = 0; k < open_count; ++k) {
      if (k + ahead < open_count) {
        const std::size_t q = open_list_[k + ahead];
        __builtin_prefetch(&p_[q]);
        __builtin_prefetch(&n_[q]);
      }
      const std::size_t i = open_list_[k];
      const glm::vec3 x = p_[i], nx = n_[i];
      const bool blocked = seed_cells_.any_near(x, spacing_, [&](const seed& c) {
        const glm::vec3 d = x - c.position;
        return glm::dot(d, d) <= r2 && glm::length(d) < spacing_ && glm::dot(nx, c.normal) > 0.9f;
      });
      if (blocked) continue;
      seed_cells_.insert(x, {x, nx});
      seeds.push_back(i);
    }
    return seeds;
  }

  // 3. The seeds' hemicubes in parallel; results land in per-seed slots (deterministic).
  std::vector<sampler_result> render_seeds(const std::vector<std::size_t>& seeds, std::size_t open_points) {
    std::vector<sampler_result> samples(seeds.size());
    std::atomic<bool> cancel{false};
    std::atomic<std::size_t> done{0};
    const float covered_fraction = 1.0f - float(open_points) / float(count_);
    const bool pretest = r_.inside_test && o_.expert.pretest_inside;
    std::atomic<std::size_t> inside{0};
    parallel_for(seeds.size(), threads_, 1, [&](int worker, std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e && !cancel; ++k) {
        if (pretest && r_.inside_test(worker, p_[seeds[k]], n_[seeds[k]])) {
          samples[k].backface_fraction = tested_inside;  // no hemicube (append_records)
          samples[k].min_distance = 0.0f;
          ++inside;
        } else {
          samples[k] = sampler_(worker, p_[seeds[k]], n_[seeds[k]]);
        }
        const std::size_t finished = ++done;
        // Worker 0 is the calling thread: the only one that calls progress.
        if (worker == 0 && r_.progress) {
          reported_ = std::max(reported_, covered_fraction + (1.0f - covered_fraction) * float(finished) / float(seeds.size()) * 0.99f);
          if (!r_.progress(reported_)) cancel = true;
        }
      }
    });
    if (cancel) throw error(status::cancelled, "cache_irradiance: cancelled by the progress callback");
    stats_.hemicubes += seeds.size() - inside;
    if (pretest) {
      stats_.inside_tests += seeds.size();
      stats_.inside_by_test += inside;
    }
    return samples;
  }

  // 4. New records in seed order with their own radius limits (split sphere, gradient limit,
  // clamp to [min_radius, max_radius]); invalid samples mark their point and, within their
  // exclusion ball, the points on the same side of the same surface (presumed_by). Returns
  // the index of the first new record.
  std::size_t append_records(const std::vector<std::size_t>& seeds, const std::vector<sampler_result>& samples,
                             cache_round_stats& round) {
    const std::size_t first_new = records_.size();
    old_radius_.resize(first_new);
    for (std::size_t j = 0; j < first_new; ++j) old_radius_[j] = radius_of(j);
    // The records, and the points each invalid sample presumes inside, in parallel; then
    // appended in seed order.
    std::vector<cache_record> made(seeds.size());
    std::vector<std::vector<std::uint32_t>> presumed(seeds.size());
    parallel_for(seeds.size(), threads_, 64, [&](int, std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k)
        if (samples[k].backface_fraction > o_.invalid_backface_fraction)
          presumed[k] = presumed_by(seeds[k], samples[k].min_distance);
        else
          made[k] = make_record(seeds[k], samples[k]);
    });
    for (std::size_t k = 0; k < seeds.size(); ++k) {
      const std::size_t i = seeds[k];
      const sampler_result& s = samples[k];
      if (s.backface_fraction == tested_inside) {  // cache_run::inside_test: no hemicube
        own_invalid_[i] = 1;
        continue;
      }
      ++stats_.hemicubes_by_reason[open_reason_[i]];
      if (s.backface_fraction > o_.invalid_backface_fraction) {
        ++stats_.invalid_samples;
        ++(s.backface_fraction > 0.5f ? stats_.invalid_samples_deep : stats_.invalid_samples_partly);
        ++round.invalid_samples;
        own_invalid_[i] = 1;
        for (std::uint32_t j : presumed[k]) presumed_[j] = 1;  // final: never tested or seeded again
        continue;
      }
      records_.push_back(made[k]);
      models_.push_back(linear_model(records_.back()));
      record_cells_.insert(records_.back().position, static_cast<std::uint32_t>(records_.size() - 1));
      lists_.add(records_.back());
      record_point_.push_back(static_cast<std::uint32_t>(i));
    }
    round.records_added = records_.size() - first_new;
    return first_new;
  }

  // cache_run::segment_blocked, or null.
  const std::function<bool(const glm::vec3&, const glm::vec3&)>* blocked() const {
    return r_.segment_blocked ? &r_.segment_blocked : nullptr;
  }

  cache_record make_record(std::size_t i, const sampler_result& s) const {
    cache_record r;
    r.position = p_[i];
    r.normal = n_[i];
    r.irradiance = s.irradiance;
    r.rotation_gradient = s.rotation_gradient;
    r.translation_gradient = s.translation_gradient;
    r.harmonic_distance = s.harmonic_mean_distance;
    r.backface_fraction = s.backface_fraction;
    r.clear_distance = s.min_distance;
    if (r_.directional) {
      r.sh_l1 = s.sh_l1;
      r.cone = s.cone;
    }
    if (r_.ao) r.ao = s.ao;
    float radius = std::isfinite(s.harmonic_mean_distance) ? s.harmonic_mean_distance : o_.max_radius;
    r.limit = std::isfinite(s.harmonic_mean_distance) ? radius_limit::split_sphere : radius_limit::max_radius;
    if (o_.expert.limit_radius_by_gradient) {
      const float gt = glm::length(0.2126f * s.translation_gradient[0] + 0.7152f * s.translation_gradient[1] +
                                   0.0722f * s.translation_gradient[2]);
      const float e = luminance(s.irradiance);
      if (gt > 0.0f && e > 0.0f && e / gt < radius) {
        radius = e / gt;
        r.limit = radius_limit::gradient;
      }
    }
    // A record that saw back faces stands at a contact (where parts meet or intersect): its
    // reach stops short of the nearest geometry its hemicube saw, so it never covers points
    // across the contact (the ball of radius min_distance around it holds no geometry).
    if (s.backface_fraction > contact_backface_ && std::isfinite(s.min_distance) && s.min_distance > 0.0f && s.min_distance < radius) {
      radius = s.min_distance;
      r.limit = radius_limit::contact;
    }
    if (radius > o_.max_radius) r.limit = radius_limit::max_radius;
    r.radius = std::clamp(radius, o_.min_radius, o_.max_radius);
    return r;
  }

  // An invalid sample at point i saw nothing nearer than min_distance in its visible half-space:
  // points within 0.9 of that distance, on the visible side of its tangent plane (not below it by
  // more than 1% of the ball) and with a similar normal (n . n_i > 0.9), lie in the same closed
  // region, so they are presumed inside without a hemicube of their own, for good: a surface
  // separating such a point from the sample would cross the ball, where the hemicube saw nothing.
  // Points on other surfaces (a wall meeting the floor, a slab's underside inside another slab)
  // are never presumed: the ball says nothing behind the sample.
  std::vector<std::uint32_t> presumed_by(std::size_t i, float min_distance) const {
    std::vector<std::uint32_t> out;
    if (!std::isfinite(min_distance) || !(min_distance > 0.0f)) return out;
    const float ball = 0.9f * min_distance;
    const glm::vec3 c = p_[i], nc = n_[i];
    grid_of_points_.for_each_in_sphere(c, ball, [&](std::uint32_t j) {
      if (presumed_[j] || glm::dot(n_[j], nc) <= 0.9f || glm::dot(p_[j] - c, nc) < -0.01f * ball) return;
      out.push_back(j);
    });
    return out;
  }

  // 5. Neighbour clamping and shrinking of disagreeing neighbours, sequential in record order
  // over pairs (new record, neighbour) (deterministic); then the records and the lists' keys take
  // the new radii.
  void limit_radii(std::size_t first_new) {
    if (!(records_.size() > first_new && (o_.expert.limit_radius_by_neighbours || o_.expert.shrink_disagreeing_records))) return;
    bvh_.build(records_, o_, threads_);
    const std::vector<std::vector<neighbour_pair>> pairs = neighbour_pairs(first_new);
    clamp_radii(first_new, pairs);
    for (std::size_t j = 0; j < records_.size(); ++j)
      if (radius_[j] != radius_of(j)) {
        records_[j].radius = radius_[j];
        lists_.set_radius(j, radius_[j]);
      }
  }

  // A neighbour j of a new record (limit_radii): its distance and whether their first-order
  // predictions of each other disagree by more than a.
  struct neighbour_pair {
    std::uint32_t j;
    bool disagree;
    bool similar;  // n_i . n_j > 0.9
    float d;
  };

  // 5a. The pairs of each new record i: the records j of every leaf of bvh_ (built over all
  // records with the radii before this stage) whose box holds x_i, in record order, with their
  // distance and whether they disagree (neither depends on the radii, so both are found first, in
  // parallel).
  std::vector<std::vector<neighbour_pair>> neighbour_pairs(std::size_t first_new) const {
    const float a = o_.error_threshold;
    const bool shrink = o_.expert.shrink_disagreeing_records;
    std::vector<std::vector<neighbour_pair>> candidates(records_.size() - first_new);
    parallel_for(candidates.size(), threads_, 64, [&](int, std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        const std::size_t i = first_new + k;
        const linear_model& mi = models_[i];
        const float ri = radius_of(i);
        // The neighbours from the tree's keys (sorted after: a record lies in one leaf, so no
        // index twice), with their distance and whether a disagreement could change anything:
        // with neighbour clamping not while R_i + d stays within the gap radius 0.4 d / a (then
        // the clamp R_j <= R_i + d is the stronger limit on R_j, and R_i is already inside the
        // gap); R_i only shrinks in the pass below, so that holds there too (1% margin for float
        // rounding). Only those pairs read the two records' models.
        std::vector<neighbour_pair>& near = candidates[k];
        bvh_.query(mi.position, [&](const record_bvh::key& key) {
          if (std::size_t(key.index) == i) return;
          const float d = glm::length(mi.position - key.position);
          const bool moot = o_.expert.limit_radius_by_neighbours && ri + d <= 0.99f * (0.4f * d / a);
          const bool similar = glm::dot(mi.normal, key.normal) > 0.9f;
          near.push_back({key.index, shrink && !moot && d > 0.0f && similar, similar, d});
        });
        std::sort(near.begin(), near.end(), [](const neighbour_pair& x, const neighbour_pair& y) { return x.j < y.j; });
        for (neighbour_pair& q : near) {
          if (!q.disagree) continue;  // (holds "to be tested" until here)
          const linear_model& mj = models_[q.j];
          // Each record's first-order prediction of the other's irradiance (luminance).
          const float ei = luminance(mi.irradiance), ej = luminance(mj.irradiance);
          const float pij = luminance(mi.predict(mj.position, mj.normal));
          const float pji = luminance(mj.predict(mi.position, mi.normal));
          const float err = std::max(std::fabs(pij - ej) / std::max(ej, 1e-20f), std::fabs(pji - ei) / std::max(ei, 1e-20f));
          q.disagree = err > a;
        }
      }
    });
    return candidates;
  }

  // 5b. The sequential pass over the pairs, in record order, on a compact copy of the radii
  // (radius_; the lists' keys hold the current ones).
  void clamp_radii(std::size_t first_new, const std::vector<std::vector<neighbour_pair>>& candidates) {
    const float a = o_.error_threshold;
    radius_.resize(records_.size());
    for (std::size_t j = 0; j < records_.size(); ++j) radius_[j] = radius_of(j);
    // At the finest spacing, neighbour clamping does not shrink older records (only the new ones,
    // by each other and by the older ones): the points those cover stay covered, instead of
    // opening again round after round. A disagreement still shrinks both.
    const bool clamp_older = spacing_ > finest_;
    for (std::size_t i = first_new; i < records_.size(); ++i) {
      float& ri = radius_[i];
      for (const neighbour_pair& q : candidates[i - first_new]) {
        float& rj = radius_[q.j];
        const float d = q.d;
        if (o_.expert.limit_radius_by_neighbours && (q.similar || o_.expert.clamp_across_normals)) {
          if (rj + d < ri) note_clamp(i, q.j);
          ri = std::max(o_.min_radius, std::min(ri, rj + d));
          if (clamp_older || q.j >= first_new) {
            if (ri + d < rj) note_clamp(q.j, std::uint32_t(i));
            rj = std::max(o_.min_radius, std::min(rj, ri + d));
          }
        }
        if (q.disagree) {
          // Shrink so that their coverage (a R each) leaves a gap between them: 0.4 d each.
          const float r_gap = std::max(o_.min_radius, 0.4f * d / a);
          if (0.4f * d / a < ri) records_[i].limit = radius_limit::disagreement;
          if (0.4f * d / a < rj) records_[q.j].limit = radius_limit::disagreement;
          ri = std::min(ri, r_gap);
          rj = std::min(rj, r_gap);
        }
      }
    }
  }

  // Record `lowered` was clamped by record `by` (clamp_radii): the limit and the counters.
  void note_clamp(std::size_t lowered, std::uint32_t by) {
    records_[lowered].limit = radius_limit::neighbour;
    ++stats_.neighbour_clamps;
    if (!(glm::dot(models_[lowered].normal, models_[by].normal) > 0.9f)) ++stats_.neighbour_clamps_across_normals;
  }

  // What limits the radii (cache_stats::records_by_limit and the rest), from the final records.
  void count_limits() {
    std::vector<float> radius, harmonic;
    radius.reserve(records_.size());
    harmonic.reserve(records_.size());
    for (const cache_record& r : records_) {
      const std::size_t k = static_cast<std::size_t>(r.limit);
      ++stats_.records_by_limit[k];
      if (r.radius <= o_.min_radius) {
        ++stats_.records_at_min_radius_by_limit[k];
        ++stats_.records_at_min_radius;
      }
      radius.push_back(r.radius);
      harmonic.push_back(r.harmonic_distance);
    }
    const auto median = [](std::vector<float>& v) {
      if (v.empty()) return 0.0f;
      std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
      return v[v.size() / 2];
    };
    stats_.median_radius = median(radius);
    stats_.median_harmonic_distance = median(harmonic);
  }

  // 6. Points whose coverage this round's records can have changed are re-checked in the next
  // coverage pass; the new records join the lists of the points their spheres hold (after the
  // limits: their final radii) or the tree of large records.
  void mark_dirty(std::size_t first_new) {
    mark_changed_points(first_new);
    const std::vector<std::uint32_t> listed = split_listed_records(first_new);
    list_records(listed);
  }

  // The reach within which record j's sphere holds a point (1e-4 wider: the weights measure
  // distance with glm::length, the grid with a squared one).
  float reach_of(std::size_t j) const { return o_.error_threshold * radius_of(j) * 1.0001f; }

  // 6a. The changed points (in a new record's sphere, or in the old sphere of a shrunk one, which
  // holds its new one, or within expert.lone_record_neighbour_reach's reach of a new record) become dirty. Each
  // worker marks its own flags and lists what it marked (merged into dirty_list_ after: which
  // points are dirty does not depend on which worker marked what), and counts each new record's
  // points (listed_points_).
  void mark_changed_points(std::size_t first_new) {
    const float a = o_.error_threshold;
    marks_.resize(std::size_t(threads_));
    for (worker_marks& m : marks_) m.flag.resize(count_, 0);
    listed_points_.resize(records_.size(), 0);
    parallel_for(records_.size(), threads_, 256, [&](int worker, std::size_t b, std::size_t e) {
      worker_marks& m = marks_[std::size_t(worker)];
      const auto mark = [&](std::uint32_t i) {
        if (!m.flag[i]) {
          m.flag[i] = 1;
          m.list.push_back(i);
        }
      };
      for (std::size_t j = b; j < e; ++j) {
        const glm::vec3 x = lists_[j].position;
        const float reach = reach_of(j), reach2 = reach * reach;
        if (j >= first_new) {
          const float marked = o_.expert.lone_record_neighbour_reach > 0.0f ? std::max(reach, nearby_reach_ * 1.0001f) : reach;
          std::uint32_t points = 0;
          grid_of_points_.for_each_in_sphere(x, marked, [&](std::uint32_t i) {
            mark(i);
            const glm::vec3 d = p_[i] - x;
            points += glm::dot(d, d) <= reach2 ? 1u : 0u;
          });
          listed_points_[j] = points;
        } else if (radius_of(j) != old_radius_[j]) {
          grid_of_points_.for_each_in_sphere(x, a * old_radius_[j] * 1.0001f, mark);  // the old sphere holds the new one
        }
      }
    });
    for (worker_marks& m : marks_) {
      for (std::uint32_t i : m.list) {
        m.flag[i] = 0;
        if (!dirty_[i]) {
          dirty_[i] = 1;
          dirty_list_.push_back(i);
        }
      }
      m.list.clear();
    }
  }

  // 6b. Which new records are listed, in record order (deterministic): those of at most
  // max_listed_points points while the lists' entries stay within the budget; the others are
  // large and kept in a tree of their own (rebuilt here, with the radii as they are now).
  // Returns the listed ones.
  std::vector<std::uint32_t> split_listed_records(std::size_t first_new) {
    std::vector<std::uint32_t> listed;
    for (std::size_t j = first_new; j < records_.size(); ++j) {
      const bool is_listed = listed_points_[j] <= max_listed_points && listed_entries_ + listed_points_[j] <= list_budget_;
      if (is_listed) {
        listed_entries_ += listed_points_[j];
        listed.push_back(static_cast<std::uint32_t>(j));
      } else {
        large_records_.push_back(static_cast<std::uint32_t>(j));
      }
    }
    large_tree_.build(records_, o_, threads_, &large_records_);
    return listed;
  }

  // 6c. The listed records join the lists of their points: their (record, point) pairs found in
  // parallel, then appended by the owner of each point (owners in parallel); in batches of at
  // most about one pair per point, so the pairs in flight take no more memory than that.
  void list_records(const std::vector<std::uint32_t>& listed) {
    for (std::size_t first = 0; first < listed.size();) {
      std::size_t last = first, pairs = 0;
      while (last < listed.size() && (last == first || pairs + listed_points_[listed[last]] <= count_)) pairs += listed_points_[listed[last++]];
      parallel_for(last - first, threads_, 64, [&](int worker, std::size_t b, std::size_t e) {
        worker_marks& m = marks_[std::size_t(worker)];
        for (std::size_t k = first + b; k < first + e; ++k) {
          const std::uint32_t j = listed[k];
          grid_of_points_.for_each_in_sphere(lists_[j].position, reach_of(j), [&](std::uint32_t i) { m.found.push_back({j, i}); });
        }
      });
      parallel_for(lists_.owners(), threads_, 1, [&](int, std::size_t b, std::size_t e) {
        for (std::size_t owner = b; owner < e; ++owner)
          for (const worker_marks& m : marks_)
            for (const auto& jp : m.found)
              if (lists_.owner(jp.second) == owner) lists_.append(jp.second, jp.first);
      });
      for (worker_marks& m : marks_) m.found.clear();
      first = last;
    }
    parallel_for(lists_.owners(), threads_, 1, [&](int, std::size_t b, std::size_t e) {
      for (std::size_t owner = b; owner < e; ++owner) lists_.lay_out(owner);
    });
    for (worker_marks& m : marks_) m.found.shrink_to_fit();  // (emptied by the last batch)
  }

  // 7. Final interpolation (parallel) of every point that is not inside geometry.
  void interpolate_all(cache_result& result) const {
    result.irradiance.assign(count_, glm::vec3(0.0f));
    result.valid.assign(count_, 0);
    if (r_.directional) {
      result.sh_l1.assign(count_, std::array<glm::vec3, 4>{});
      result.cone.assign(count_, hl2_cone{});
    }
    if (r_.ao) result.ao.assign(count_, 0.0f);
    parallel_for(count_, threads_, 4096, [&](int, std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        glm::vec3 v;
        std::array<glm::vec3, 4> sh{};
        hl2_cone cone;
        float ao = 0.0f;
        if (!inside(i) && interpolate(records_, lists_, large_tree_, i, p_[i], n_[i], o_, v, nullptr, nullptr, r_.directional ? &sh : nullptr,
                                      r_.directional ? &cone : nullptr, nullptr, blocked(), r_.ao ? &ao : nullptr) > 0.0f) {
          result.irradiance[i] = v;
          result.valid[i] = 1;
          if (r_.directional) {
            result.sh_l1[i] = sh;
            result.cone[i] = cone;
          }
          if (r_.ao) result.ao[i] = ao;
        }
      }
    });
  }

  // 8. Points inside geometry (or, defensively, left uncovered) get the relaxed-weight average
  // (1 / (d / R + sqrt(1 - n.n_i)), no threshold) of the 8 best records on the same side of
  // their surface (n . n_i > 0.5, not behind), searched in spheres that double from 4 x the finest
  // seed spacing; from the third doubling on, of any records in the sphere.
  std::size_t count_invalid(const cache_result& result) const {
    std::size_t invalid = 0;
    for (std::uint8_t v : result.valid) invalid += v ? 0u : 1u;
    return invalid;
  }

  void fill_invalid(cache_result& result) const {
    if (records_.empty() || stats_.invalid_points == 0) return;
    std::vector<std::size_t> fill;
    for (std::size_t i = 0; i < count_; ++i)
      if (!result.valid[i]) fill.push_back(i);
    std::vector<glm::vec3> where(records_.size());
    for (std::size_t j = 0; j < records_.size(); ++j) where[j] = records_[j].position;
    point_grid grid;
    grid.build(where.data(), where.size());
    parallel_for(fill.size(), threads_, 256, [&](int, std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) fill_point(fill[k], grid, result);
    });
  }

  void fill_point(std::size_t i, const point_grid& grid, cache_result& result) const {
    std::array<std::pair<float, std::uint32_t>, 8> best;
    best.fill({0.0f, 0u});
    const auto consider = [&](std::uint32_t j, bool same_side) {
      const cache_record& r = records_[j];
      if (same_side && (glm::dot(n_[i], r.normal) <= 0.5f || record_is_behind(r, p_[i], n_[i]))) return;
      const float denom = glm::length(p_[i] - r.position) / r.radius + std::sqrt(std::max(0.0f, 1.0f - glm::dot(n_[i], r.normal)));
      const float w = 1.0f / std::max(denom, 1e-12f);
      if (w > best.back().first || (w == best.back().first && j < best.back().second && w > 0.0f)) {
        best.back() = {w, j};
        // Weight, then index: a fixed order whatever order the grid visits records in.
        std::sort(best.begin(), best.end(), [](const auto& x, const auto& y) {
          return x.first > y.first || (x.first == y.first && x.second < y.second);
        });
      }
    };
    // Doubling spheres: records on the point's side first; from 4 x the first radius on, any
    // record in the sphere (a point deep inside a solid may have no record on its side nearby).
    const float first = 4.0f * std::max(finest_, 1e-30f);
    for (float radius = first; best.front().first == 0.0f; radius *= 2.0f) {
      grid.for_each_in_sphere(p_[i], radius, [&](std::uint32_t j) { consider(j, true); });
      if (best.front().first == 0.0f && radius >= 4.0f * first)
        grid.for_each_in_sphere(p_[i], radius, [&](std::uint32_t j) { consider(j, false); });
      if (radius > 2.0f * diagonal_ + o_.max_radius) break;
    }
    if (best.front().first == 0.0f)  // defensive: the spheres above end beyond every record
      for (std::uint32_t j = 0; j < records_.size(); ++j) consider(j, false);
    glm::vec3 sum(0.0f);
    std::array<glm::vec3, 4> sh{};
    hl2_cone cone;
    cone.reference = make_frame(n_[i]).t;
    float wsum = 0.0f, ao = 0.0f;
    for (const auto& bw : best)
      if (bw.first > 0.0f) {
        const cache_record& rec = records_[bw.second];
        sum += bw.first * rec.irradiance;
        ao += bw.first * rec.ao;
        if (r_.directional) {
          for (std::size_t c = 0; c < 4; ++c) sh[c] += bw.first * rec.sh_l1[c];
          const hl2_cone rc = rotate_hl2_cone(rec.cone, rec.normal, cone.reference);
          for (std::size_t c = 0; c < std::size_t(hl2_cone_terms); ++c) cone.coefficients[c] += bw.first * rc.coefficients[c];
        }
        wsum += bw.first;
      }
    result.irradiance[i] = wsum > 0.0f ? sum / wsum : glm::vec3(0.0f);
    if (r_.ao) result.ao[i] = wsum > 0.0f ? ao / wsum : 0.0f;
    if (r_.directional && wsum > 0.0f) {
      for (std::size_t c = 0; c < 4; ++c) result.sh_l1[i][c] = sh[c] / wsum;
      for (glm::vec3& c : cone.coefficients) c /= wsum;
      result.cone[i] = cone;
    }
  }

  const glm::vec3* p_;
  const glm::vec3* n_;
  std::size_t count_;
  const irradiance_sampler& sampler_;
  cache_options o_;
  const cache_run& r_;
  cache_options coverage_options_;
  int threads_ = 1;
  float diagonal_ = 0.0f, spacing_ = 0.0f, finest_ = 0.0f, nearby_reach_ = 0.0f, reported_ = 0.0f;
  float contact_backface_ = 0.0f;  // records seeing more back faces than this stand at a contact (make_record)
  bool ao_refine_ = false;         // the coverage tests hold AO too (cache_expert_options::refine_where_ao_disagrees)
  float floor_e_ = 0.0f;   // the tests' dark floor (coverage_pass), fixed once set
  bool floor_set_ = false;
  std::vector<cache_record> records_;
  record_lists lists_;     // the records of up to max_listed_points points, per point
  record_bvh large_tree_;  // the others (large_records_), rebuilt each round
  std::vector<std::uint32_t> large_records_;
  std::vector<std::uint32_t> listed_points_;  // per new record: the points in its sphere (mark_dirty)
  std::size_t listed_entries_ = 0, list_budget_ = 0;  // list entries written so far, and the most allowed
  record_bvh bvh_;  // limit_radii: the records' boxes
  std::vector<float> radius_;  // limit_radii: the radii during its sequential pass
  std::vector<linear_model> models_;  // per record: its first-order model, compact (limit_radii, nearby_records_agree)
  incremental_grid<std::uint32_t> record_cells_;  // the records' positions (nearby_records_agree)
  std::vector<std::uint32_t> record_point_;  // per record: the point it was placed at
  point_grid grid_of_points_;
  std::vector<std::uint8_t> covered_, dirty_, own_invalid_, presumed_;
  std::vector<std::uint8_t> open_reason_;  // per point: why its last coverage test left it open (open_reason)
  incremental_grid<seed> seed_cells_;  // pick_seeds: the round's seeds so far
  glm::vec3 lo_{0.0f}, hi_{0.0f};  // the points' bounding box
  std::size_t candidates_ = 0;                 // the round's candidates: points of rank below it
  std::vector<std::uint32_t> rank_;            // per point: its place in the fixed pseudo-random order
  std::vector<std::uint32_t> order_;           // the points in that order (order_[rank_[i]] = i)
  std::vector<std::uint32_t> dirty_list_;      // the points with dirty_ set: the next coverage pass's
  std::vector<std::uint32_t> open_list_;       // the open points, by rank_ (update_open_list)
  std::vector<std::uint8_t> in_open_list_;
  std::vector<float> old_radius_;
  struct worker_marks {
    std::vector<std::uint8_t> flag;
    std::vector<std::uint32_t> list;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> found;  // (new record, point in its sphere)
  };
  std::vector<worker_marks> marks_;  // mark_dirty: each worker's marks
  cache_stats stats_;
};

}  // namespace

cache_result cache_irradiance(const glm::vec3* positions, const glm::vec3* normals, std::size_t count,
                              const irradiance_sampler& sampler, const cache_options& options, const cache_run& run) {
  cache_detail::validate_cache_input(positions, normals, count, options);
  if (run.thread_count < 0)
    throw_invalid_argument("cache_irradiance: run.thread_count is " + std::to_string(run.thread_count) + "; it must be >= 0");
  if (!sampler) throw_invalid_argument("cache_irradiance: sampler is empty");
  if (run.point_spacing)
    for (std::size_t i = 0; i < count; ++i)
      if (!(run.point_spacing[i] > 0.0f) || !std::isfinite(run.point_spacing[i]))
        throw_invalid_argument("cache_irradiance: run.point_spacing[" + std::to_string(i) + "] is " +
                               std::to_string(run.point_spacing[i]) + "; it must be finite and > 0");
  return placement(positions, normals, count, sampler, options, run).run();
}

}  // namespace hemilight
