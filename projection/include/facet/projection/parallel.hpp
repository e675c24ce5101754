#pragma once
// A static-partition parallel loop over [0, count) on the hardware threads, for the libraries'
// own loops (facet::detail: not part of the API).
#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace facet::detail {

// Loops shorter than min_parallel run on the calling thread: starting threads costs more.
// `workers` threads share the loop (0: one per hardware thread).
template <typename Body>
void parallel_for(std::size_t count, Body&& body, std::size_t min_parallel = 8,
                  std::size_t workers = 0) {
  if (workers == 0) workers = std::max<std::size_t>(1, std::thread::hardware_concurrency());
  const std::size_t threads =
      count < min_parallel ? 1 : std::max<std::size_t>(1, std::min<std::size_t>(workers, count));
  if (threads <= 1) {
    for (std::size_t k = 0; k < count; ++k) body(k, std::size_t{0});
    return;
  }
  std::vector<std::thread> pool;
  std::vector<std::exception_ptr> failures(threads);
  for (std::size_t worker = 0; worker < threads; ++worker) {
    pool.emplace_back([&, worker] {
      try {
        for (std::size_t k = worker; k < count; k += threads) body(k, worker);
      } catch (...) {
        failures[worker] = std::current_exception();
      }
    });
  }
  for (auto& thread : pool) thread.join();
  for (auto& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
}

inline std::size_t parallel_workers() {
  return std::max<std::size_t>(1, std::thread::hardware_concurrency());
}

}  // namespace facet::detail
