// CPU time the hypervisor gave to other guests while a benchmark ran ("steal" in /proc/stat).
// On a shared VM the two-thread figures drop whenever the host takes time from a core: a
// benchmark that records this can be told apart from a slower build. Linux only; elsewhere
// (or without /proc/stat) the fraction is reported as -1.
#pragma once

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

namespace hemilight::bench {

/// Totals of the "cpu" line of /proc/stat (USER_HZ ticks, all CPUs): steal, and all fields.
struct cpu_ticks {
  std::uint64_t steal = 0, total = 0;
  bool valid = false;
};

inline cpu_ticks read_cpu_ticks() {
  cpu_ticks t;
  std::ifstream in("/proc/stat");
  std::string line;
  if (!in || !std::getline(in, line) || line.compare(0, 4, "cpu ") != 0) return t;
  std::istringstream fields(line.substr(4));
  std::uint64_t v = 0;
  // user nice system idle iowait irq softirq steal guest guest_nice; guest time is already
  // counted in user and nice, so the sum stops at steal.
  for (int k = 0; k < 8 && fields >> v; ++k) {
    t.total += v;
    if (k == 7) {
      t.steal = v;
      t.valid = true;
    }
  }
  return t;
}

/// Fraction of all CPU time between `a` and `b` that was stolen (0..1), or -1 if unknown.
inline double steal_fraction(const cpu_ticks& a, const cpu_ticks& b) {
  if (!a.valid || !b.valid || b.total <= a.total) return -1.0;
  return static_cast<double>(b.steal - a.steal) / static_cast<double>(b.total - a.total);
}

}  // namespace hemilight::bench
