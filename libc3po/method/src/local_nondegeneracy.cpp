// Local non-degeneracy: generalised eigenvalues of the point-to-plane
// information of the data against that of the model (see the header).
#include "c3po/method/local_nondegeneracy.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

namespace c3po {
namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

struct TwistFrame {
  Eigen::Vector3d centre;
  double radius = 1.0;
};

TwistFrame FrameOf(const ObjectModel& object) {
  TwistFrame frame;
  frame.centre = object.sample().rowwise().mean();
  frame.radius = std::max(0.5 * object.diameter(), 1e-12);
  return frame;
}

// J(p) = ((p - c) × n / r, n): normal displacement of p under ξ = (r ω, v).
Vector6 Row(const TwistFrame& frame, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  Vector6 J;
  J << (p - frame.centre).cross(n) / frame.radius, n;
  return J;
}

}  // namespace

void LocalNonDegeneracyOptions::Check() const {
  if (!(std::isfinite(min_eigenvalue) && min_eigenvalue >= 0)) throw std::invalid_argument("nd min_eigenvalue must be >= 0");
  if (!(std::isfinite(model_floor) && model_floor > 0 && model_floor < 1)) throw std::invalid_argument("nd model_floor must be in (0, 1)");
  if (min_points < 6) throw std::invalid_argument("nd min_points must be >= 6");
}

Matrix6 ModelInformationMatrix(const ObjectModel& object) {
  const TwistFrame frame = FrameOf(object);
  Matrix6 H = Matrix6::Zero();
  const PointSet& sample = object.sample();
  int used = 0;
  for (Eigen::Index i = 0; i < sample.cols(); ++i) {
    if (object.sample_on_crease()[i]) continue;
    const Vector6 J = Row(frame, sample.col(i), object.sample_normals().col(i));
    H.noalias() += J * J.transpose();
    ++used;
  }
  return used > 0 ? Matrix6(H / static_cast<double>(used)) : H;
}

namespace {

// The point-to-plane rows J of the accepted points (at their nearest model sample, creases
// left out), recomputed on each pass instead of stored: clouds may hold millions of points.
struct AcceptedRows {
  const ObjectModel& object;
  const Eigen::VectorXi& nearest_model_point;
  const std::vector<char>& accepted;
  TwistFrame frame;

  template <typename Visit>
  void ForEach(const Visit& visit) const {
    for (Eigen::Index j = 0; j < nearest_model_point.size(); ++j) {
      if (j >= static_cast<Eigen::Index>(accepted.size()) || !accepted[j]) continue;
      const int p = nearest_model_point(j);
      if (p < 0 || p >= object.sample().cols() || object.sample_on_crease()[p]) continue;
      visit(Row(frame, object.sample().col(p), object.sample_normals().col(p)));
    }
  }
};

// W = Q_k Λ_k^{-1/2} over the motions the model sees (eigenvalue above model_floor x the largest):
// W^T H_model W = I. Zero columns when it sees none.
Eigen::MatrixXd ModelWhitening(const Matrix6& H_model, double model_floor) {
  const Eigen::SelfAdjointEigenSolver<Matrix6> model(H_model);
  const double largest = model.eigenvalues().maxCoeff();
  std::vector<int> seen;
  for (int k = 0; k < 6; ++k) {
    if (largest > 0 && model.eigenvalues()(k) > model_floor * largest) seen.push_back(k);
  }
  Eigen::MatrixXd W(6, seen.size());
  for (std::size_t i = 0; i < seen.size(); ++i) {
    W.col(i) = model.eigenvectors().col(seen[i]) / std::sqrt(model.eigenvalues()(seen[i]));
  }
  return W;
}

// λ along one generalised eigenvector ξ: with m > 0, m accepted points might be outliers placed
// to supply exactly the missing information, so the m that contribute most along ξ are dropped.
double RobustEigenvalue(const AcceptedRows& rows, int count, const Matrix6& H_model, const Vector6& xi, double plain,
                        int max_outliers) {
  if (max_outliers <= 0) return plain;
  std::vector<double> contribution;
  contribution.reserve(count);
  rows.ForEach([&](const Vector6& J) { contribution.push_back(std::pow(J.dot(xi), 2)); });
  const std::size_t drop = std::min<std::size_t>(max_outliers, contribution.size());
  std::nth_element(contribution.begin(), contribution.begin() + drop, contribution.end(), std::greater<double>());
  double kept = 0.0;
  for (std::size_t i = drop; i < contribution.size(); ++i) kept += contribution[i];
  const double model_information = xi.dot(H_model * xi);
  return model_information > 0 ? std::min(plain, kept / static_cast<double>(count) / model_information) : plain;
}

}  // namespace

LocalNonDegeneracy CheckLocalNonDegeneracy(const ObjectModel& object, const Eigen::VectorXi& nearest_model_point,
                                           const std::vector<char>& accepted, int max_outliers,
                                           const LocalNonDegeneracyOptions& options) {
  options.Check();
  LocalNonDegeneracy result;
  const AcceptedRows rows{object, nearest_model_point, accepted, FrameOf(object)};
  Matrix6 H_data = Matrix6::Zero();
  int count = 0;
  rows.ForEach([&](const Vector6& J) {
    H_data.noalias() += J * J.transpose();
    ++count;
  });
  result.observed_points = count;
  const Matrix6 H_model = ModelInformationMatrix(object);
  const Eigen::MatrixXd W = ModelWhitening(H_model, options.model_floor);
  result.model_rank = static_cast<int>(W.cols());
  if (count == 0 || W.cols() == 0) return result;
  H_data /= static_cast<double>(count);
  // Generalised eigenproblem H_data ξ = λ H_model ξ on the seen motions.
  const Eigen::MatrixXd A = W.transpose() * H_data * W;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> generalised(0.5 * (A + A.transpose()));
  for (Eigen::Index k = 0; k < generalised.eigenvalues().size(); ++k) {
    const Vector6 xi = W * generalised.eigenvectors().col(k);
    const double plain = std::max(0.0, generalised.eigenvalues()(k));
    const double value = RobustEigenvalue(rows, count, H_model, xi, plain, max_outliers);
    if (k == 0) {
      result.motion = xi.normalized();
      result.eigenvalue_all_points = plain;
      result.min_eigenvalue = value;
    } else if (k == 1) {
      result.second_eigenvalue = value;
    }
    if (value < options.min_eigenvalue) ++result.weak_motions;
  }
  result.passed = result.observed_points >= options.min_points && result.min_eigenvalue >= options.min_eigenvalue;
  return result;
}

}  // namespace c3po
