// The process-wide LRU of per-resolution tables (table_cache.hpp) and its public controls
// (hemilight/memory.hpp).
#include "table_cache.hpp"

#include "hemilight/memory.hpp"

#include <cstdint>
#include <map>
#include <mutex>
#include <utility>
#include <vector>

namespace hemilight {

namespace detail {

namespace {

struct entry {
  std::shared_ptr<const void> strong;  // set while the cache retains the table
  std::weak_ptr<const void> weak;      // the table while anyone holds it
  std::size_t bytes = 0;
  std::uint64_t last_use = 0;                // LRU order (higher = more recent)
  std::shared_ptr<std::mutex> building;      // held by the thread building this key
};

class table_lru {
 public:
  std::shared_ptr<const void> get(table_kind kind, int n,
                                  const std::function<std::shared_ptr<const void>(std::size_t&)>& build) {
    const key k{static_cast<int>(kind), n};
    std::shared_ptr<std::mutex> building;
    {  // Step 1: a live table (retained, or held by someone) is shared.
      std::lock_guard<std::mutex> lock(mutex_);
      entry& e = entries_[k];
      if (std::shared_ptr<const void> found = find_locked(e)) return found;
      if (!e.building) e.building = std::make_shared<std::mutex>();
      building = e.building;
    }
    // Step 2: one builder per key; the others wait here and then find its table.
    std::lock_guard<std::mutex> build_lock(*building);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      entry& e = entries_[k];
      if (std::shared_ptr<const void> found = find_locked(e)) return found;
    }
    // Step 3: build outside the cache's lock (other keys go on), then retain and evict.
    std::size_t bytes = 0;
    std::shared_ptr<const void> table = build(bytes);
    std::lock_guard<std::mutex> lock(mutex_);
    ++builds_;
    entry& e = entries_[k];
    e.weak = table;
    e.bytes = bytes;
    retain_locked(e, table);
    return table;
  }

  void set_budget(std::size_t bytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    budget_ = bytes;
    evict_locked();
  }
  std::size_t budget() {
    std::lock_guard<std::mutex> lock(mutex_);
    return budget_;
  }
  std::size_t release() {
    std::vector<std::shared_ptr<const void>> dropped;  // freed after the lock is released
    std::lock_guard<std::mutex> lock(mutex_);
    const std::size_t before = retained_bytes_;
    for (auto it = entries_.begin(); it != entries_.end();) {
      if (it->second.strong) dropped.push_back(std::move(it->second.strong));
      it = forget_if_dead_locked(it);
    }
    retained_bytes_ = 0;
    retained_tables_ = 0;
    return before;
  }
  table_cache_statistics stats() {
    std::lock_guard<std::mutex> lock(mutex_);
    table_cache_statistics s;
    s.retained_bytes = retained_bytes_;
    s.retained_tables = retained_tables_;
    s.builds = builds_;
    s.evictions = evictions_;
    return s;
  }

 private:
  using key = std::pair<int, int>;
  using iterator = std::map<key, entry>::iterator;

  // The live table of e (retained or held by someone), now the most recently used; null if none.
  std::shared_ptr<const void> find_locked(entry& e) {
    if (e.strong) {
      e.last_use = ++clock_;
      return e.strong;
    }
    std::shared_ptr<const void> alive = e.weak.lock();
    if (alive) retain_locked(e, alive);  // held elsewhere: retained again, as a fresh use
    return alive;
  }

  // Retains e's table (counted against the budget) as the most recently used, then evicts.
  void retain_locked(entry& e, const std::shared_ptr<const void>& table) {
    e.last_use = ++clock_;
    if (!e.strong) {
      e.strong = table;
      retained_bytes_ += e.bytes;
      ++retained_tables_;
    }
    evict_locked();
  }

  // Drops least-recently-used tables until the retained bytes fit the budget.
  void evict_locked() {
    while (retained_bytes_ > budget_) {
      iterator oldest = entries_.end();
      for (iterator it = entries_.begin(); it != entries_.end(); ++it)
        if (it->second.strong && (oldest == entries_.end() || it->second.last_use < oldest->second.last_use)) oldest = it;
      if (oldest == entries_.end()) break;  // unreachable: retained_bytes_ > 0 implies a retained table
      retained_bytes_ -= oldest->second.bytes;
      --retained_tables_;
      ++evictions_;
      // Freed here if no one else holds it: the table's destructor frees memory only (no lock).
      oldest->second.strong.reset();
      forget_if_dead_locked(oldest);
    }
  }

  // Erases an entry whose table is neither retained, nor held, nor being built; returns the next.
  iterator forget_if_dead_locked(iterator it) {
    const entry& e = it->second;
    if (!e.strong && e.weak.expired() && (!e.building || e.building.use_count() == 1)) return entries_.erase(it);
    return std::next(it);
  }

  std::mutex mutex_;
  std::map<key, entry> entries_;
  std::size_t budget_ = default_table_budget;
  std::size_t retained_bytes_ = 0, retained_tables_ = 0, builds_ = 0, evictions_ = 0;
  std::uint64_t clock_ = 0;
};

// Never destroyed: tables may be asked for (or released) from other static destructors and from
// threads still running at exit.
table_lru& lru() {
  static table_lru* const instance = new table_lru;
  return *instance;
}

}  // namespace

std::shared_ptr<const void> cached_table_untyped(
    table_kind kind, int n, const std::function<std::shared_ptr<const void>(std::size_t& bytes)>& build) {
  return lru().get(kind, n, build);
}

}  // namespace detail

void set_table_budget(std::size_t bytes) noexcept { detail::lru().set_budget(bytes); }

std::size_t table_budget() noexcept { return detail::lru().budget(); }

std::size_t release_tables() noexcept { return detail::lru().release(); }

table_cache_statistics table_cache_stats() noexcept { return detail::lru().stats(); }

}  // namespace hemilight
