// Indicator sets: parsing, validation, editing and coverage on a dataset.
#include "c3po/authoring/indicators.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <set>

#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"
#include "c3po/base/parallel.hpp"
#include "c3po/method/certificate.hpp"

namespace c3po {
namespace {

std::string SetField(std::size_t k) { return "indicator_sets[" + std::to_string(k) + "]"; }

int ParseIndex(const std::string& token, const std::string& what, const std::string& text) {
  if (token.empty()) throw InputError(what, "'" + text + "': empty keypoint index");
  char* end = nullptr;
  errno = 0;
  const long value = std::strtol(token.c_str(), &end, 10);
  if (*end != '\0' || errno == ERANGE || value < 0 || value > 1000000) {
    throw InputError(what, "'" + text + "': '" + token + "' is not a keypoint index");
  }
  return static_cast<int>(value);
}

}  // namespace

IndicatorSet ParseIndicatorSet(const std::string& text, const std::string& what) {
  IndicatorSet set;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    std::string token = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    token.erase(0, token.find_first_not_of(" \t"));
    token.erase(token.find_last_not_of(" \t") + 1);
    set.push_back(ParseIndex(token, what, text));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return set;
}

void ValidateIndicatorSets(const std::vector<IndicatorSet>& sets, int num_keypoints,
                           const std::string& where) {
  std::set<IndicatorSet> distinct;
  for (std::size_t k = 0; k < sets.size(); ++k) {
    const IndicatorSet& set = sets[k];
    if (set.empty()) throw InputError(where, SetField(k) + ": empty set");
    std::set<int> seen;
    for (int index : set) {
      if (index < 0 || index >= num_keypoints) {
        throw InputError(where, SetField(k) + ": keypoint index " + std::to_string(index) +
                                    " out of range [0, " + std::to_string(num_keypoints) + ")");
      }
      if (!seen.insert(index).second) {
        throw InputError(where, SetField(k) + ": keypoint " + std::to_string(index) + " listed twice");
      }
    }
    if (!distinct.insert(IndicatorSet(seen.begin(), seen.end())).second) {
      throw InputError(where, SetField(k) + ": the same set is already listed");
    }
  }
}

std::vector<IndicatorSet> ApplyIndicatorEdit(const std::vector<IndicatorSet>& sets,
                                             const IndicatorEdit& edit, int num_keypoints,
                                             const std::string& where) {
  std::vector<IndicatorSet> result = edit.clear ? std::vector<IndicatorSet>{} : sets;
  std::set<int> removed;
  for (int k : edit.remove) {
    if (k < 0 || k >= static_cast<int>(result.size())) {
      throw InputError(where, "--remove " + std::to_string(k) + ": no such set (" +
                                  std::to_string(result.size()) + " sets)");
    }
    removed.insert(k);
  }
  for (auto it = removed.rbegin(); it != removed.rend(); ++it) result.erase(result.begin() + *it);
  result.insert(result.end(), edit.add.begin(), edit.add.end());
  ValidateIndicatorSets(result, num_keypoints, where);
  return result;
}

std::string DescribeIndicatorSet(const ObjectSpec& spec, const IndicatorSet& set) {
  std::string text = "{";
  for (std::size_t j = 0; j < set.size(); ++j) {
    if (j) text += ", ";
    text += std::to_string(set[j]) + " " + spec.KeypointName(set[j]);
  }
  return text + "}";
}

IndicatorCoverage MeasureIndicatorCoverage(const ObjectModel& object, const Dataset& dataset,
                                           double delta_nd, const IndicatorProgress& progress) {
  const auto& sets = object.spec().indicator_sets;
  const int n = static_cast<int>(dataset.entries.size());
  for (int i = 0; i < n; ++i) {
    if (!dataset.entries[i].pose) {
      throw InputError(dataset.dir, "manifest line " + std::to_string(i + 1) +
                                        ": no ground-truth pose (\"R\", \"t\"): coverage needs them");
    }
  }
  CertificateOptions options;
  options.eps_oc = delta_nd;   // unused by CheckNonDegeneracy, must be valid
  options.delta_nd = delta_nd;
  options.local_nondegeneracy = false;   // coverage of the sets alone
  options.Check();
  std::vector<NonDegeneracy> results(n);
  std::atomic<std::size_t> done{0};
  ParallelFor(0, n, [&](int i) {
    ThrowIfInterrupted();
    const PointSet cloud = dataset.LoadCloud(i);
    results[i] = CheckNonDegeneracy(object, cloud, *dataset.entries[i].pose, options);
    const std::size_t finished = ++done;
    if (progress) progress(finished, static_cast<std::size_t>(n));
  });

  IndicatorCoverage coverage;
  coverage.views = static_cast<std::size_t>(n);
  coverage.delta_nd = delta_nd;
  coverage.set_seen.assign(sets.size(), 0);
  coverage.keypoint_seen.assign(object.num_keypoints(), 0);
  for (const NonDegeneracy& nd : results) {
    for (std::size_t s = 0; s < nd.set_worst_distance.size(); ++s) {
      coverage.set_seen[s] += nd.set_worst_distance[s] < delta_nd;
    }
    for (Eigen::Index k = 0; k < nd.keypoint_distances.size(); ++k) {
      coverage.keypoint_seen[k] += nd.keypoint_distances(k) < delta_nd;
    }
    coverage.nd_passed += nd.passed;
    coverage.view_nd.push_back(nd.passed);
  }
  return coverage;
}

}  // namespace c3po
