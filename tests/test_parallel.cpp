// Tests of parallel.hpp: every index visited exactly once, worker indices in range, exceptions
// propagate, one worker runs inline.
#include "hemilight/parallel.hpp"

#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

using namespace hemilight;

TEST_CASE("parallel_for visits every index once from valid workers", "[parallel]") {
  for (int threads : {0, 1, 2, 3, 8}) {
    for (std::size_t count : {std::size_t(0), std::size_t(1), std::size_t(7), std::size_t(1000)}) {
      std::vector<std::atomic<int>> hits(count);
      std::atomic<int> bad_worker{0};
      const int workers = resolve_thread_count(threads);
      parallel_for(count, threads, 3, [&](int w, std::size_t b, std::size_t e) {
        if (w < 0 || w >= workers) ++bad_worker;
        for (std::size_t i = b; i < e; ++i) ++hits[i];
      });
      CHECK(bad_worker == 0);
      for (std::size_t i = 0; i < count; ++i) REQUIRE(hits[i] == 1);
    }
  }
}

TEST_CASE("parallel_for with one worker runs on the calling thread", "[parallel]") {
  const std::thread::id me = std::this_thread::get_id();
  bool same = true;
  parallel_for(100, 1, 10, [&](int, std::size_t, std::size_t) { same = same && std::this_thread::get_id() == me; });
  CHECK(same);
  CHECK(resolve_thread_count(0) >= 1);
  CHECK(resolve_thread_count(-5) >= 1);
  CHECK(resolve_thread_count(100000) == 256);
}

TEST_CASE("parallel_for rethrows the first exception after all workers stop", "[parallel]") {
  // Two workers: the exception comes out of parallel_for, and only after every body has
  // returned (no worker still running). How many chunks the other worker finishes meanwhile
  // depends on scheduling, so it is not asserted.
  std::atomic<int> calls{0}, active{0}, after_return{0};
  CHECK_THROWS_AS(parallel_for(1000, 2, 1,
                               [&](int, std::size_t b, std::size_t) {
                                 ++active;
                                 ++calls;
                                 if (b == 5) {
                                   --active;
                                   throw std::runtime_error("boom");
                                 }
                                 --active;
                               }),
                  std::runtime_error);
  CHECK(active == 0);
  after_return = calls.load();
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  CHECK(calls == after_return);  // no worker went on after the return
  // One worker: chunks run in order on the calling thread, so the throw at chunk 5 stops it
  // after exactly 6 calls.
  int serial = 0;
  CHECK_THROWS_AS(parallel_for(1000, 1, 1,
                               [&](int, std::size_t b, std::size_t) {
                                 ++serial;
                                 if (b == 5) throw std::runtime_error("boom");
                               }),
                  std::runtime_error);
  CHECK(serial == 6);
}
