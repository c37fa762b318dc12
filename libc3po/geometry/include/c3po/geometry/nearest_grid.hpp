#pragma once
// Exact nearest-neighbour lookup in a fixed point set by a uniform grid of
// candidate lists, for the many queries near one shape (a model sample B̂
// queried by every scene point at every corrector iterate, every rival and
// every certificate). The k-d tree answers the rest.
//
// Each cell C of the grid keeps the set points p with
//   mindist(p, C) <= u(C),   u(C) = min_q maxdist(q, C)   (q over the list),
// where the list was first gathered as every point within R of C. For any
// query x in C the nearest point p* has |x - p*| <= maxdist(q, C) for every q,
// so mindist(p*, C) <= |x - p*| <= u(C); and when u(C) <= R, p* was gathered.
// A cell with u(C) > R (far from the points) keeps no list: its queries, and
// those outside the grid or not finite, go to the tree. So every answer is
// the exact nearest distance; among points at exactly the same distance the
// grid returns the lowest index (the tree the first it visits).
#include <cstdint>
#include <memory>
#include <vector>

#include "c3po/base/types.hpp"
#include "c3po/geometry/kdtree.hpp"

namespace c3po {

struct NearestGridOptions {
  // Cell edge as a multiple of the points' mean nearest-neighbour spacing,
  // and the gathering reach R in cells. A smaller cell keeps shorter lists
  // (faster queries) and needs more cells; R bounds how far from the points
  // the grid answers, and the build time and memory grow as R^3. The
  // defaults were chosen on `c3po bench corrector` (docs/results.md,
  // "Nearest-neighbour grid"): for 10^4 points, tens of milliseconds and
  // ~15 MB to build, ~30 points per list.
  double cell_over_spacing = 2.5;
  double reach_cells = 4.0;
  std::int64_t max_cells = std::int64_t{1} << 22;   // the cell grows until the grid fits
  void Check() const;
};

class NearestGrid {
 public:
  // `tree` must outlive the grid; its points are the grid's points.
  explicit NearestGrid(std::shared_ptr<const PointTree> tree, const NearestGridOptions& options = {});

  const PointTree& tree() const { return *tree_; }
  double cell_size() const { return cell_; }
  std::int64_t cell_count() const { return static_cast<std::int64_t>(first_.size()) - 1; }
  // Cells that answer from their list (the rest ask the tree).
  std::int64_t listed_cells() const { return listed_cells_; }
  double mean_list_length() const;

  // As PointTree::Nearest: the exact nearest point; `hint` only speeds up the
  // tree's part.
  PointTree::Neighbor Nearest(const Eigen::Vector3d& query, Eigen::Index hint = -1) const;
  // As PointTree::NearestBatch (both cores for large batches).
  void NearestBatch(const PointSet& queries, Eigen::VectorXi* indices, Eigen::VectorXd* squared_distances,
                    const Eigen::VectorXi* hints = nullptr) const;

 private:
  // The cell holding `query`, or -1 (outside the grid, not finite).
  std::int64_t CellOf(const Eigen::Vector3d& query) const;

  std::shared_ptr<const PointTree> tree_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  double cell_ = 0.0;
  Eigen::Array3i dims_ = Eigen::Array3i::Zero();
  std::vector<std::uint32_t> first_;     // CSR: cell c's list is members_[first_[c], first_[c + 1])
  std::vector<std::uint32_t> members_;
  std::int64_t listed_cells_ = 0;
};

}  // namespace c3po
