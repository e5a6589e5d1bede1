#pragma once
// Work split over the processor's cores, for loops whose parts are independent.
#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace flexarm {

// Threads for `items` of work when each thread should get at least `minPerThread` of them:
// at most one per core (and at most 8), at least 1.
inline unsigned threadsFor(std::size_t items, std::size_t minPerThread) {
  const unsigned cores = std::clamp(std::thread::hardware_concurrency(), 1u, 8u);
  const std::size_t useful = minPerThread ? items / minPerThread : items;
  return static_cast<unsigned>(std::clamp<std::size_t>(useful, 1, cores));
}

// Runs work(0), ..., work(n - 1) at once, each on its own thread (the last on the calling
// one), and returns when all are done.
template <class Work>
void inParallel(unsigned n, Work work) {
  std::vector<std::thread> pool;
  for (unsigned k = 0; k + 1 < n; ++k) pool.emplace_back(work, k);
  if (n > 0) work(n - 1);
  for (auto& t : pool) t.join();
}

// Runs body(begin, end) over [0, count) cut into `threads` consecutive ranges, at once.
template <class Body>
void parallelRanges(std::size_t count, unsigned threads, Body body) {
  threads = std::max(1u, threads);
  inParallel(threads, [&](unsigned k) { body(count * k / threads, count * (k + 1) / threads); });
}

}  // namespace flexarm
