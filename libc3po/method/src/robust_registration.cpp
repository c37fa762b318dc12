#include "c3po/method/robust_registration.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace c3po {

namespace {

// Tomita-Seki MCQ: greedy colouring gives an upper bound on the clique size
// within the candidate set; branches whose bound cannot beat the best stop.
class CliqueSearch {
 public:
  CliqueSearch(const Graph& graph, std::int64_t max_branches)
      : n_(static_cast<int>(graph.size())), adjacent_(n_ * n_, 0), max_branches_(max_branches) {
    for (int v = 0; v < n_; ++v) {
      for (int u : graph[v]) {
        if (u < 0 || u >= n_) throw std::invalid_argument("MaximumClique: vertex out of range");
        if (u == v) continue;
        adjacent_[v * n_ + u] = 1;
        adjacent_[u * n_ + v] = 1;
      }
    }
  }

  MaxCliqueResult Run() {
    std::vector<int> degree(n_, 0);
    for (int v = 0; v < n_; ++v) {
      for (int u = 0; u < n_; ++u) degree[v] += adjacent_[v * n_ + u];
    }
    std::vector<int> candidates(n_);
    for (int v = 0; v < n_; ++v) candidates[v] = v;
    // Highest degree first (coloured first, expanded last).
    std::stable_sort(candidates.begin(), candidates.end(),
                     [&](int a, int b) { return degree[a] > degree[b]; });
    std::vector<int> current;
    if (n_ > 0) Expand(&current, candidates);
    MaxCliqueResult result;
    result.clique = best_;
    std::sort(result.clique.begin(), result.clique.end());
    result.exact = !exhausted_;
    result.branches = branches_;
    return result;
  }

 private:
  bool Adjacent(int a, int b) const { return adjacent_[a * n_ + b] != 0; }

  // Orders `candidates` by colour class; colours[k] = colour (1-based) of order[k].
  void ColourSort(const std::vector<int>& candidates, std::vector<int>* order,
                  std::vector<int>* colours) const {
    std::vector<std::vector<int>> classes;
    for (int v : candidates) {
      std::size_t c = 0;
      for (; c < classes.size(); ++c) {
        bool conflict = false;
        for (int u : classes[c]) {
          if (Adjacent(u, v)) { conflict = true; break; }
        }
        if (!conflict) break;
      }
      if (c == classes.size()) classes.emplace_back();
      classes[c].push_back(v);
    }
    order->clear();
    colours->clear();
    for (std::size_t c = 0; c < classes.size(); ++c) {
      for (int v : classes[c]) {
        order->push_back(v);
        colours->push_back(static_cast<int>(c) + 1);
      }
    }
  }

  void Expand(std::vector<int>* current, const std::vector<int>& candidates) {
    if (++branches_ > max_branches_) {
      exhausted_ = true;
      return;
    }
    std::vector<int> order, colours;
    ColourSort(candidates, &order, &colours);
    for (int k = static_cast<int>(order.size()) - 1; k >= 0; --k) {
      if (current->size() + colours[k] <= best_.size()) return;
      const int v = order[k];
      current->push_back(v);
      std::vector<int> next;
      for (int j = 0; j < k; ++j) {
        if (Adjacent(v, order[j])) next.push_back(order[j]);
      }
      if (next.empty()) {
        if (current->size() > best_.size()) best_ = *current;
      } else {
        Expand(current, next);
      }
      current->pop_back();
      if (exhausted_) return;
    }
  }

  int n_;
  std::vector<char> adjacent_;
  std::int64_t max_branches_;
  std::int64_t branches_ = 0;
  bool exhausted_ = false;
  std::vector<int> best_;
};

// argmax_R sum w_i a_i^T R b_i over SO(3) (weighted Procrustes without translation).
Eigen::Matrix3d WeightedRotation(const PointSet& model, const PointSet& scene,
                                 const Eigen::VectorXd& weights) {
  const Eigen::Matrix3d h = scene * weights.asDiagonal() * model.transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

}  // namespace

MaxCliqueResult MaximumClique(const Graph& graph, std::int64_t max_branches) {
  if (max_branches < 1) throw std::invalid_argument("MaximumClique: max_branches must be >= 1");
  return CliqueSearch(graph, max_branches).Run();
}

void GncTlsOptions::Check() const {
  if (!(noise_bound > 0) || !std::isfinite(noise_bound)) {
    throw std::invalid_argument("GncTlsOptions: noise_bound must be positive and finite");
  }
  if (!(mu_factor > 1) || !std::isfinite(mu_factor)) {
    throw std::invalid_argument("GncTlsOptions: mu_factor must be > 1");
  }
  if (max_iterations < 1) throw std::invalid_argument("GncTlsOptions: max_iterations must be >= 1");
  if (!(cost_tolerance >= 0)) throw std::invalid_argument("GncTlsOptions: cost_tolerance must be >= 0");
}

// GNC-TLS (Yang et al. 2020, Sec. IV / Algorithm 1 with the TLS weight update
// of Prop. 5): mu_0 = c^2 / (2 r_max^2 - c^2); w_i = 1 if r_i^2 <= mu/(mu+1) c^2,
// 0 if r_i^2 >= (mu+1)/mu c^2, else c sqrt(mu (mu+1)) / r_i - mu.
GncTlsRotationResult GncTlsRotation(const PointSet& model, const PointSet& scene,
                                    const GncTlsOptions& options) {
  options.Check();
  if (model.cols() != scene.cols()) throw std::invalid_argument("GncTlsRotation: sizes differ");
  GncTlsRotationResult result;
  const Eigen::Index m = model.cols();
  if (m < 2 || !model.allFinite() || !scene.allFinite()) return result;
  const double c2 = options.noise_bound * options.noise_bound;
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(m);
  Eigen::Matrix3d R = WeightedRotation(model, scene, weights);
  auto squared_residuals = [&](const Eigen::Matrix3d& rotation) {
    return Eigen::VectorXd((scene - rotation * model).colwise().squaredNorm().transpose());
  };
  Eigen::VectorXd r2 = squared_residuals(R);
  const double r2_max = r2.maxCoeff();
  if (r2_max > c2) {
    double mu = c2 / std::max(2 * r2_max - c2, 1e-300);
    double previous_cost = std::numeric_limits<double>::infinity();
    for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
      result.iterations = iteration + 1;
      const double low = mu / (mu + 1) * c2;
      const double high = (mu + 1) / mu * c2;
      bool binary = true;
      for (Eigen::Index i = 0; i < m; ++i) {
        if (r2(i) >= high) {
          weights(i) = 0;
        } else if (r2(i) <= low) {
          weights(i) = 1;
        } else {
          weights(i) = options.noise_bound * std::sqrt(mu * (mu + 1)) / std::sqrt(r2(i)) - mu;
          binary = false;
        }
      }
      if (weights.sum() <= 0) break;
      R = WeightedRotation(model, scene, weights);
      r2 = squared_residuals(R);
      const double cost = weights.dot(r2);
      if (binary || std::abs(cost - previous_cost) <= options.cost_tolerance * std::max(cost, 1e-300)) {
        break;
      }
      previous_cost = cost;
      mu *= options.mu_factor;
    }
  }
  result.R = R;
  for (Eigen::Index i = 0; i < m; ++i) {
    if (r2(i) <= c2) result.inliers.push_back(static_cast<int>(i));
  }
  result.ok = R.allFinite();
  return result;
}

VotingResult AdaptiveVoting(const std::vector<double>& values, const std::vector<double>& bounds) {
  if (values.size() != bounds.size()) throw std::invalid_argument("AdaptiveVoting: sizes differ");
  VotingResult result;
  const std::size_t n = values.size();
  if (n == 0) return result;
  struct Event {
    double at;
    int index;
    bool enter;
  };
  std::vector<Event> events;
  events.reserve(2 * n);
  double all_out = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(values[i]) || !(bounds[i] > 0)) {
      throw std::invalid_argument("AdaptiveVoting: non-finite value or non-positive bound");
    }
    events.push_back({values[i] - bounds[i], static_cast<int>(i), true});
    events.push_back({values[i] + bounds[i], static_cast<int>(i), false});
    all_out += bounds[i] * bounds[i];
  }
  std::sort(events.begin(), events.end(), [](const Event& a, const Event& b) {
    if (a.at != b.at) return a.at < b.at;
    return a.enter && !b.enter;
  });
  // In the section [events[k].at, events[k+1].at] the members S are fixed and
  // cost(t) = sum_S (x - t)^2 + sum_out b^2, minimised at mean(S) clamped.
  double sum = 0, sum_squares = 0, out = all_out;
  int count = 0;
  double best_cost = all_out, best_value = values[0];
  for (std::size_t k = 0; k + 1 < events.size(); ++k) {
    const Event& e = events[k];
    const double x = values[e.index], b2 = bounds[e.index] * bounds[e.index];
    if (e.enter) {
      sum += x; sum_squares += x * x; out -= b2; ++count;
    } else {
      sum -= x; sum_squares -= x * x; out += b2; --count;
    }
    if (count <= 0) continue;
    const double t = std::clamp(sum / count, e.at, events[k + 1].at);
    const double cost = sum_squares - 2 * t * sum + count * t * t + out;
    if (cost < best_cost) {
      best_cost = cost;
      best_value = t;
    }
  }
  result.value = best_value;
  result.cost = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d2 = (values[i] - best_value) * (values[i] - best_value);
    result.cost += std::min(d2, bounds[i] * bounds[i]);
    if (d2 <= bounds[i] * bounds[i]) result.inliers.push_back(static_cast<int>(i));
  }
  return result;
}

void RobustRegistrationOptions::Check() const {
  if (!(noise_bound > 0) || !std::isfinite(noise_bound)) {
    throw std::invalid_argument("RobustRegistrationOptions: noise_bound must be positive and finite");
  }
  if (max_correspondences < 3) {
    throw std::invalid_argument("RobustRegistrationOptions: max_correspondences must be >= 3");
  }
  if (max_clique_branches < 1) {
    throw std::invalid_argument("RobustRegistrationOptions: max_clique_branches must be >= 1");
  }
  if (max_rotation_tims < 2) {
    throw std::invalid_argument("RobustRegistrationOptions: max_rotation_tims must be >= 2");
  }
  GncTlsOptions gnc_checked = gnc;
  gnc_checked.noise_bound = 2 * noise_bound;
  gnc_checked.Check();
}

namespace {

// Indices of the finite correspondences, the first `cap` of them.
std::vector<int> FiniteCorrespondences(const PointSet& model, const PointSet& scene, int cap) {
  std::vector<int> kept;
  for (Eigen::Index i = 0; i < model.cols(); ++i) {
    if (model.col(i).allFinite() && scene.col(i).allFinite()) kept.push_back(static_cast<int>(i));
    if (static_cast<int>(kept.size()) == cap) break;
  }
  return kept;
}

// TIM consistency graph at scale 1: kept correspondences i, j are adjacent when their distances
// in model and scene differ by at most `tolerance`.
Graph ConsistencyGraph(const PointSet& model, const PointSet& scene, const std::vector<int>& kept,
                       double tolerance) {
  const int m = static_cast<int>(kept.size());
  Graph graph(m);
  for (int i = 0; i < m; ++i) {
    for (int j = i + 1; j < m; ++j) {
      const double dm = (model.col(kept[j]) - model.col(kept[i])).norm();
      const double ds = (scene.col(kept[j]) - scene.col(kept[i])).norm();
      if (std::abs(ds - dm) <= tolerance) {
        graph[i].push_back(j);
        graph[j].push_back(i);
      }
    }
  }
  return graph;
}

// The translation-invariant measurements (TIMs) b_j - b_i and a_j - a_i of the members' pairs,
// every pair or, above `cap`, pairs strided evenly over them.
std::pair<PointSet, PointSet> StridedTims(const PointSet& model, const PointSet& scene, const std::vector<int>& members,
                                          int cap) {
  const std::int64_t c = static_cast<std::int64_t>(members.size());
  const std::int64_t pairs = c * (c - 1) / 2;
  const std::int64_t used = std::min<std::int64_t>(pairs, cap);
  PointSet tim_model(3, used), tim_scene(3, used);
  std::int64_t pair = 0, next_column = 0;
  for (std::int64_t i = 0; i < c && next_column < used; ++i) {
    for (std::int64_t j = i + 1; j < c && next_column < used; ++j, ++pair) {
      if (pair != next_column * pairs / used) continue;
      tim_model.col(next_column) = model.col(members[j]) - model.col(members[i]);
      tim_scene.col(next_column) = scene.col(members[j]) - scene.col(members[i]);
      ++next_column;
    }
  }
  if (next_column != used) {
    tim_model.conservativeResize(3, next_column);
    tim_scene.conservativeResize(3, next_column);
  }
  return {tim_model, tim_scene};
}

// Component-wise adaptive voting for t = a_i - R b_i over the members.
Eigen::Vector3d VotedTranslation(const PointSet& model, const PointSet& scene, const std::vector<int>& members,
                                 const Eigen::Matrix3d& R, double noise_bound) {
  Eigen::Vector3d t;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> values, bounds;
    for (int i : members) {
      values.push_back(scene(k, i) - (R * model.col(i))(k));
      bounds.push_back(noise_bound);
    }
    t(k) = AdaptiveVoting(values, bounds).value;
  }
  return t;
}

}  // namespace

RobustRegistrationResult RegisterRobust(const PointSet& model, const PointSet& scene,
                                        const RobustRegistrationOptions& options) {
  options.Check();
  if (model.cols() != scene.cols()) throw std::invalid_argument("RegisterRobust: sizes differ");
  RobustRegistrationResult result;
  const std::vector<int> kept = FiniteCorrespondences(model, scene, options.max_correspondences);
  result.correspondences = static_cast<int>(kept.size());
  if (result.correspondences < 3) {
    result.failure = "fewer than 3 correspondences";
    return result;
  }
  // Step 2: TIM consistency graph (scale 1) and its maximum clique.
  const MaxCliqueResult clique =
      MaximumClique(ConsistencyGraph(model, scene, kept, 2 * options.noise_bound), options.max_clique_branches);
  result.clique_size = static_cast<int>(clique.clique.size());
  result.clique_exact = clique.exact;
  if (result.clique_size < 3) {
    result.failure = "maximum clique of fewer than 3 consistent correspondences";
    return result;
  }
  std::vector<int> members;
  for (int v : clique.clique) members.push_back(kept[v]);
  // Step 3: GNC-TLS rotation on the TIMs of the clique (every pair, strided to the cap).
  const auto [tim_model, tim_scene] = StridedTims(model, scene, members, options.max_rotation_tims);
  GncTlsOptions gnc = options.gnc;
  gnc.noise_bound = 2 * options.noise_bound;
  const GncTlsRotationResult rotation = GncTlsRotation(tim_model, tim_scene, gnc);
  result.rotation_inliers = static_cast<int>(rotation.inliers.size());
  if (!rotation.ok || rotation.inliers.size() < 2) {
    result.failure = "GNC-TLS rotation found fewer than 2 consistent invariants";
    return result;
  }
  // Step 4: component-wise adaptive voting for the translation.
  result.scene_from_model.R = rotation.R;
  result.scene_from_model.t = VotedTranslation(model, scene, members, rotation.R, options.noise_bound);
  for (int i : members) {
    const Eigen::Vector3d r = scene.col(i) - result.scene_from_model * Eigen::Vector3d(model.col(i));
    if (r.cwiseAbs().maxCoeff() <= options.noise_bound) ++result.translation_inliers;
  }
  return result;
}

}  // namespace c3po
