// The list of `c3po bench` entries besides `corrector` (in bench.cpp).
#include "bench_registry.hpp"

namespace c3po::cli {

std::vector<BenchEntry> BenchEntries() { return {}; }

}  // namespace c3po::cli
