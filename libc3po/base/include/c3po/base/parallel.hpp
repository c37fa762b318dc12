#pragma once
// A small deterministic parallel-for over both cores. Work items are indices;
// results must be written to per-index slots so output order never depends on
// scheduling.
//
// Contract when an item throws: the first exception is rethrown by
// ParallelFor after every worker has returned; items already running finish;
// no index is claimed (so no item starts) after the failing item's exception
// has been caught, because the stop and every claim are operations on one
// atomic counter (IndexQueue). Which items ran before the stop depends on
// scheduling; that none starts after it does not.
#include <atomic>
#include <cstdint>
#include <functional>

namespace c3po {

// Number of worker threads: $C3PO_THREADS if set, else hardware concurrency.
int DefaultThreadCount();

// Hands out the indices [begin, end) once each to concurrent claimers. Stop()
// and Claim() are linearisable: once Stop() has returned, every Claim() by
// any thread returns false.
class IndexQueue {
 public:
  IndexQueue(int begin, int end);
  // The next unclaimed index in *index, or false when none is left or the
  // queue was stopped.
  bool Claim(int* index);
  // No index is handed out after this returns. Returns how many indices had
  // been claimed before the stop.
  int Stop();
  bool stopped() const { return stopped_.load(); }

 private:
  std::atomic<std::int64_t> next_;
  const std::int64_t begin_;
  const std::int64_t end_;
  std::atomic<bool> stopped_{false};
};

// Runs body(i) for i in [begin, end) on `threads` threads (0 = DefaultThreadCount()).
// Nested: a ParallelFor called from inside another's body runs its items
// inline on that thread (the outer one has taken the cores), so a parallel
// step (e.g. the rival fits of one pose) uses both cores on its own and
// none extra inside a batch.
void ParallelFor(int begin, int end, const std::function<void(int)>& body,
                 int threads = 0);

}  // namespace c3po
