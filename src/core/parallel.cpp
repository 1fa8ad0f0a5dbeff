#include "hemilight/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace hemilight {

int resolve_thread_count(int thread_count) noexcept {
  if (thread_count <= 0) return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  return std::min(thread_count, 256);
}

void parallel_for(std::size_t count, int thread_count, std::size_t grain,
                  const std::function<void(int, std::size_t, std::size_t)>& body) {
  if (count == 0) return;
  grain = std::max<std::size_t>(1, grain);
  const std::size_t chunks = (count + grain - 1) / grain;
  const int workers = static_cast<int>(std::min<std::size_t>(chunks, static_cast<std::size_t>(resolve_thread_count(thread_count))));
  if (workers <= 1) {
    for (std::size_t b = 0; b < count; b += grain) body(0, b, std::min(count, b + grain));
    return;
  }
  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto run = [&](int worker) {
    try {
      while (!stop.load(std::memory_order_relaxed)) {
        const std::size_t chunk = next.fetch_add(1, std::memory_order_relaxed);
        if (chunk >= chunks) break;
        const std::size_t b = chunk * grain;
        body(worker, b, std::min(count, b + grain));
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      stop = true;
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(workers - 1));
  for (int w = 1; w < workers; ++w) pool.emplace_back(run, w);
  run(0);
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace hemilight
