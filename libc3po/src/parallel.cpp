#include "c3po/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace c3po {

int DefaultThreadCount() {
  if (const char* env = std::getenv("C3PO_THREADS")) {
    const int n = std::atoi(env);
    if (n > 0) return n;
  }
  const unsigned hw = std::thread::hardware_concurrency();
  return hw > 0 ? static_cast<int>(hw) : 1;
}

void ParallelFor(int begin, int end, const std::function<void(int)>& body, int threads) {
  const int count = end - begin;
  if (count <= 0) return;
  if (threads <= 0) threads = DefaultThreadCount();
  threads = std::min(threads, count);
  if (threads == 1) {
    for (int i = begin; i < end; ++i) body(i);
    return;
  }
  // Dynamic scheduling over an atomic counter; each index writes its own slot.
  std::atomic<int> next{begin};
  std::exception_ptr first_error;
  std::mutex error_mutex;
  auto worker = [&]() {
    for (;;) {
      const int i = next.fetch_add(1);
      if (i >= end) return;
      try {
        body(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!first_error) first_error = std::current_exception();
        next.store(end);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& thread : pool) thread.join();
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace c3po
