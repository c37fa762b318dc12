#pragma once
// A small deterministic parallel-for over both cores. Work items are indices;
// results must be written to per-index slots so output order never depends on
// scheduling. The first exception thrown by any item is rethrown.
#include <functional>

namespace c3po {

// Number of worker threads: $C3PO_THREADS if set, else hardware concurrency.
int DefaultThreadCount();

void ParallelFor(int begin, int end, const std::function<void(int)>& body,
                 int threads = 0);

}  // namespace c3po
