#pragma once
// Further `c3po bench NAME` entries (synth, pointnet, ...), each defined in its
// own cli/bench_<name>.cpp. Each setup adds a subcommand to `parent` and, from
// the subcommand's callback, stores the function to run in `*run`.
#include <CLI/CLI.hpp>
#include <functional>
#include <vector>

namespace c3po::cli {

struct BenchEntry {
  void (*setup)(CLI::App& parent, std::function<int()>* run);
};

std::vector<BenchEntry> BenchEntries();

}  // namespace c3po::cli
