// The list of `c3po bench` entries besides `corrector` (in bench.cpp).
#include "bench_registry.hpp"

namespace c3po::cli {

void SetupSynthBench(CLI::App& parent, std::function<int()>* run);
void SetupPointNetBench(CLI::App& parent, std::function<int()>* run);
void SetupMeshBench(CLI::App& parent, std::function<int()>* run);
void SetupSynthBopBench(CLI::App& parent, std::function<int()>* run);
void SetupSegmentsBench(CLI::App& parent, std::function<int()>* run);
void SetupDetectorBench(CLI::App& parent, std::function<int()>* run);

std::vector<BenchEntry> BenchEntries() {
  return {{SetupSynthBench}, {SetupSynthBopBench}, {SetupPointNetBench}, {SetupMeshBench}, {SetupSegmentsBench},
          {SetupDetectorBench}};
}

}  // namespace c3po::cli
