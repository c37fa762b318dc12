#pragma once
// `c3po synth --format bop`: the options only BOP output has, declared on the
// synth subcommand (cli/synth.cpp) and run by RunSynthBop (cli/synth_bop.cpp).
#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

namespace c3po::cli {

struct SynthBopCommand {
  int obj_id = 1;
  std::string depth_scale = "auto";
  int images_per_scene = 1000;
  int distractors = 0;
  std::vector<std::string> distractor_objects;   // FILE.json[:ID]
  bool no_background = false;
  double background_gap = 0.2;
  double min_visib_fract = 0.5;
  std::string artefacts = "none";
  std::string depth_noise;      // A,B
  std::string quantisation;
  std::string holes;
  std::string hole_blobs;
  std::string flying;
  std::string bleed;
};

// Options with no meaning for --format manifest (refused there).
const std::vector<std::string>& BopOnlyOptions();
void DeclareBopOptions(CLI::App& command, SynthBopCommand& o);

// Shared synth options, already parsed from the command line.
struct SynthCommonForBop {
  std::string object;
  std::string output;
  int count = 0;
  std::string pose;
  int min_points = -1;
  std::string distance;       // "A,B" or empty
  std::string intrinsics;     // or empty (YCB-V)
  std::uint64_t seed = 0;
};
int RunSynthBop(const SynthCommonForBop& common, const SynthBopCommand& o);

}  // namespace c3po::cli
