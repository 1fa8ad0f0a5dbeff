// hemilight/parallel.hpp — the one way hemilight uses several cores: parallel_for over an index
// range with dynamic chunking and a worker index for per-thread contexts.
//
// Determinism: which worker runs which chunk depends on scheduling, so callers that need bitwise
// reproducible results write each index's result to its own slot and combine in index order.
#pragma once

#include <cstddef>
#include <functional>

namespace hemilight {

/// Number of workers for a thread_count option: 0 means all hardware threads (at least 1),
/// negative values are treated as 0, anything else is taken as given (clamped to 256).
int resolve_thread_count(int thread_count) noexcept;

/// Calls body(worker, begin, end) on chunks [begin, end) of [0, count) of at most `grain`
/// indices, from resolve_thread_count(thread_count) workers (worker in [0, workers)); returns
/// when all are done. With one worker, or count <= grain, everything runs on the calling thread
/// as worker 0 (no thread is started). The first exception thrown by a body stops the handing
/// out of new chunks and is rethrown here after all workers have finished.
/// Cost: one std::thread start per extra worker per call; give each grain far more work than that.
void parallel_for(std::size_t count, int thread_count, std::size_t grain,
                  const std::function<void(int worker, std::size_t begin, std::size_t end)>& body);

}  // namespace hemilight
