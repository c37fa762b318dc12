#pragma once
// The outlier-robust options (issue 16) shared by certify, eval, selftrain and
// bench corrector: parsing only, the meaning lives in the library
// (certificate.hpp, corrector.hpp, local_nondegeneracy.hpp).
#include <CLI/CLI.hpp>
#include <string>

#include "c3po/method/pipeline.hpp"

namespace c3po::cli {

struct RobustCliOptions {
  std::string max_outliers;        // "" = the default (0 for ready-made clouds)
  std::string robust_loss = "none";
  std::string nd_min_eigenvalue;   // "" = default; 0 = local test off
};

void AddRobustOptions(CLI::App& command, RobustCliOptions* options);
// Fills the certificate budget, the local test and the corrector kernel.
void ApplyRobustOptions(const RobustCliOptions& cli, PipelineOptions* pipeline);
// "m = 2%, robust loss = tls, local nd >= 0.02" for the printed summary.
std::string DescribeRobustOptions(const PipelineOptions& pipeline);

}  // namespace c3po::cli
