#include "robust_options.hpp"

#include <cstdio>
#include <cstdlib>

#include "c3po/base/error.hpp"

namespace c3po::cli {

void AddRobustOptions(CLI::App& command, RobustCliOptions* options) {
  command.add_option("--max-outliers", options->max_outliers,
                     "Outlier budget m of the certificates: a count (10) or a percentage of each cloud's points "
                     "(2%); default 0 = the paper");
  command.add_option("--robust-loss", options->robust_loss,
                     "Robust kernel of the corrector's point-cloud term, truncated at eps_oc: none (default), "
                     "tls (truncated least squares, GNC) or gm (Geman-McClure)");
  command.add_option("--nd-min-eigenvalue", options->nd_min_eigenvalue,
                     "Local non-degeneracy threshold on the smallest generalised eigenvalue (data vs model "
                     "point-to-plane information); 0 = local test off");
}

void ApplyRobustOptions(const RobustCliOptions& cli, PipelineOptions* pipeline) {
  if (!cli.max_outliers.empty()) pipeline->certificate.max_outliers = ParseOutlierBudget(cli.max_outliers);
  pipeline->corrector.robust_loss = ParseRobustLoss(cli.robust_loss);
  if (!cli.nd_min_eigenvalue.empty()) {
    char* end = nullptr;
    const double value = std::strtod(cli.nd_min_eigenvalue.c_str(), &end);
    if (*end != '\0' || !(value >= 0) || !(value < 1e6)) {
      throw InputError("--nd-min-eigenvalue", "'" + cli.nd_min_eigenvalue + "' must be a number >= 0");
    }
    pipeline->certificate.local_nondegeneracy = value > 0;
    if (value > 0) pipeline->certificate.local.min_eigenvalue = value;
  }
}

std::string DescribeRobustOptions(const PipelineOptions& pipeline) {
  char text[160];
  const auto& c = pipeline.certificate;
  if (c.local_nondegeneracy) {
    std::snprintf(text, sizeof text, "m = %s, robust loss = %s, local nd >= %g", c.max_outliers.ToString().c_str(),
                  ToString(pipeline.corrector.robust_loss), c.local.min_eigenvalue);
  } else {
    std::snprintf(text, sizeof text, "m = %s, robust loss = %s, local nd off", c.max_outliers.ToString().c_str(),
                  ToString(pipeline.corrector.robust_loss));
  }
  return text;
}

}  // namespace c3po::cli
