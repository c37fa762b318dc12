#include "c3po/base/parallel.hpp"

#include <algorithm>
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

IndexQueue::IndexQueue(int begin, int end) : next_(begin), begin_(begin), end_(std::max(begin, end)) {}

bool IndexQueue::Claim(int* index) {
  // A compare-and-swap loop (not fetch_add) so that the counter never runs
  // past end_: Stop() parks it at end_, and a claim either happened before
  // that store in the counter's modification order or sees it.
  std::int64_t current = next_.load();
  while (current < end_) {
    if (next_.compare_exchange_weak(current, current + 1)) {
      *index = static_cast<int>(current);
      return true;
    }
  }
  return false;
}

int IndexQueue::Stop() {
  stopped_.store(true);
  const std::int64_t claimed = next_.exchange(end_);
  return static_cast<int>(std::min(claimed, end_) - begin_);
}

namespace {

// True while this thread runs the items of a ParallelFor (as a worker or as
// the calling thread): a ParallelFor inside runs inline instead of starting
// threads of its own (the cores are taken; results stay in their slots).
thread_local bool running_parallel_items = false;

class RunningParallelItems {
 public:
  RunningParallelItems() : previous_(running_parallel_items) { running_parallel_items = true; }
  ~RunningParallelItems() { running_parallel_items = previous_; }
  RunningParallelItems(const RunningParallelItems&) = delete;
  RunningParallelItems& operator=(const RunningParallelItems&) = delete;

 private:
  bool previous_;
};

}  // namespace

void ParallelFor(int begin, int end, const std::function<void(int)>& body, int threads) {
  const int count = end - begin;
  if (count <= 0) return;
  if (threads <= 0) threads = DefaultThreadCount();
  threads = std::min(threads, count);
  if (threads == 1 || running_parallel_items) {
    for (int i = begin; i < end; ++i) body(i);
    return;
  }
  // Dynamic scheduling over one atomic counter; each index writes its own slot.
  IndexQueue queue(begin, end);
  std::exception_ptr first_error;
  std::mutex error_mutex;
  auto worker = [&]() {
    const RunningParallelItems running;
    int i = 0;
    while (queue.Claim(&i)) {
      try {
        body(i);
      } catch (...) {
        queue.Stop();  // first, so that no index is claimed after the catch
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!first_error) first_error = std::current_exception();
        return;
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
