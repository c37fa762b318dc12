#include "c3po/geometry/nearest_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "c3po/base/parallel.hpp"

namespace c3po {

void NearestGridOptions::Check() const {
  if (!(cell_over_spacing > 0 && std::isfinite(cell_over_spacing))) {
    throw std::invalid_argument("NearestGridOptions: cell_over_spacing must be > 0");
  }
  if (!(reach_cells >= 1 && reach_cells <= 8)) throw std::invalid_argument("NearestGridOptions: reach_cells must be in [1, 8]");
  if (max_cells < 1) throw std::invalid_argument("NearestGridOptions: max_cells must be >= 1");
}

namespace {

// An axis-aligned cell [lo, lo + size]^3, widened by `slack` on every side
// so that a query that rounding puts in a neighbouring cell is still inside.
struct CellBox {
  Eigen::Vector3d lo, hi;
  double MinSquared(const Eigen::Vector3d& p) const {
    return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).squaredNorm();
  }
  double MaxSquared(const Eigen::Vector3d& p) const {
    return (p - lo).cwiseAbs().cwiseMax((hi - p).cwiseAbs()).squaredNorm();
  }
};

// Mean distance of (up to 1000 of) the points to their nearest other point.
double MeanSpacing(const PointTree& tree) {
  const PointSet& points = tree.points();
  const Eigen::Index stride = std::max<Eigen::Index>(1, points.cols() / 1000);
  double total = 0.0;
  int counted = 0;
  for (Eigen::Index i = 0; i < points.cols(); i += stride) {
    const auto neighbours = tree.KNearest(points.col(i), 2);
    if (neighbours.size() < 2) continue;
    total += std::sqrt(neighbours[1].squared_distance);
    ++counted;
  }
  return counted ? total / counted : 0.0;
}

}  // namespace

NearestGrid::NearestGrid(std::shared_ptr<const PointTree> tree, const NearestGridOptions& options)
    : tree_(std::move(tree)) {
  options.Check();
  if (!tree_) throw std::invalid_argument("NearestGrid needs a tree");
  first_.assign(1, 0);
  const PointSet& points = tree_->points();
  if (points.cols() == 0 || points.cols() > std::numeric_limits<std::uint32_t>::max() || !points.allFinite()) return;
  const Eigen::Vector3d lower = points.rowwise().minCoeff(), upper = points.rowwise().maxCoeff();
  const double extent = (upper - lower).maxCoeff();
  if (!std::isfinite(extent)) return;
  // Every point enters at most (2 reach + 2)^3 cells: keep the gathered lists' size in 32 bits.
  const double per_point = std::pow(2.0 * options.reach_cells + 2.0, 3);
  if (per_point * static_cast<double>(points.cols()) > 2e9) return;
  double cell = options.cell_over_spacing * MeanSpacing(*tree_);
  if (!(cell > 0)) cell = extent > 0 ? extent / 64.0 : 1.0;
  Eigen::Array3d cells;
  for (;;) {
    const double reach = options.reach_cells * cell;
    cells = ((upper - lower).array() + 2.0 * reach) / cell + 1.0;
    if (cells.ceil().prod() <= static_cast<double>(options.max_cells)) break;
    cell *= 1.25;
  }
  cell_ = cell;
  const double reach = options.reach_cells * cell;
  origin_ = lower.array() - reach;
  dims_ = cells.ceil().cast<int>();
  const std::int64_t count = static_cast<std::int64_t>(dims_.prod());
  const double slack = 1e-6 * cell;
  auto box_of = [&](std::int64_t c) {
    const std::int64_t ix = c % dims_(0), iy = (c / dims_(0)) % dims_(1), iz = c / (std::int64_t{dims_(0)} * dims_(1));
    CellBox box;
    box.lo = origin_ + cell * Eigen::Vector3d(double(ix), double(iy), double(iz));
    box.hi = box.lo.array() + cell + slack;
    box.lo.array() -= slack;
    return box;
  };
  // Gather: every point into the cells within `reach` of it (counting pass,
  // then filling pass, in point order so every list is sorted by index).
  const double reach_squared = reach * reach;
  // Gathered a little beyond the reach, so that rounding of the gaps' sum
  // never drops a point a valid cell (u <= reach) needs.
  const double gather_squared = reach_squared * (1.0 + 1e-9);
  // The cells within `reach` of point i, by the per-axis squared gaps of the
  // point to each cell's (widened) extent: a box test without a division.
  auto for_cells_near = [&](Eigen::Index i, auto&& visit) {
    const Eigen::Vector3d p = points.col(i);
    const Eigen::Array3i from = (((p - origin_).array() - reach) / cell).floor().cast<int>().max(0);
    const Eigen::Array3i to = (((p - origin_).array() + reach) / cell).floor().cast<int>().min(dims_ - 1);
    double gaps[3][32];   // (2 reach / cell + 2) <= 18 cells per axis
    for (int a = 0; a < 3; ++a) {
      for (int k = from(a); k <= to(a); ++k) {
        const double lo = origin_(a) + cell * k - slack, hi = origin_(a) + cell * k + cell + slack;
        const double gap = std::max({lo - p(a), p(a) - hi, 0.0});
        gaps[a][k - from(a)] = gap * gap;
      }
    }
    for (int iz = from(2); iz <= to(2); ++iz) {
      const double gz = gaps[2][iz - from(2)];
      for (int iy = from(1); iy <= to(1); ++iy) {
        const double gyz = gz + gaps[1][iy - from(1)];
        if (gyz > gather_squared) continue;
        const std::int64_t row = (std::int64_t{iz} * dims_(1) + iy) * dims_(0);
        for (int ix = from(0); ix <= to(0); ++ix) {
          if (gyz + gaps[0][ix - from(0)] <= gather_squared) visit(row + ix);
        }
      }
    }
  };
  std::vector<std::uint32_t> gathered_first(static_cast<std::size_t>(count) + 1, 0);
  for (Eigen::Index i = 0; i < points.cols(); ++i) for_cells_near(i, [&](std::int64_t c) { ++gathered_first[c + 1]; });
  for (std::int64_t c = 0; c < count; ++c) gathered_first[c + 1] += gathered_first[c];
  std::vector<std::uint32_t> gathered(gathered_first.back());
  {
    std::vector<std::uint32_t> fill(gathered_first.begin(), gathered_first.end() - 1);
    for (Eigen::Index i = 0; i < points.cols(); ++i) {
      for_cells_near(i, [&](std::int64_t c) { gathered[fill[c]++] = static_cast<std::uint32_t>(i); });
    }
  }
  // Prune: keep the points that can be nearest for some query in the cell.
  first_.assign(static_cast<std::size_t>(count) + 1, 0);
  members_.reserve(gathered.size() / 4);
  for (std::int64_t c = 0; c < count; ++c) {
    const auto begin = gathered.begin() + gathered_first[c], end = gathered.begin() + gathered_first[c + 1];
    if (begin != end) {
      const CellBox box = box_of(c);
      double bound = std::numeric_limits<double>::infinity();   // u(C)^2
      for (auto it = begin; it != end; ++it) bound = std::min(bound, box.MaxSquared(points.col(*it)));
      if (bound <= reach_squared) {
        for (auto it = begin; it != end; ++it) {
          if (box.MinSquared(points.col(*it)) <= bound) members_.push_back(*it);
        }
        ++listed_cells_;
      }
    }
    first_[c + 1] = static_cast<std::uint32_t>(members_.size());
  }
  members_.shrink_to_fit();
}

double NearestGrid::mean_list_length() const {
  return listed_cells_ ? static_cast<double>(members_.size()) / static_cast<double>(listed_cells_) : 0.0;
}

std::int64_t NearestGrid::CellOf(const Eigen::Vector3d& query) const {
  if (cell_ <= 0 || !query.allFinite()) return -1;
  const Eigen::Array3d at = ((query - origin_).array() / cell_).floor();
  if ((at < 0).any() || (at >= dims_.cast<double>()).any()) return -1;
  const Eigen::Array3i i = at.cast<int>();
  return (std::int64_t{i(2)} * dims_(1) + i(1)) * dims_(0) + i(0);
}

PointTree::Neighbor NearestGrid::Nearest(const Eigen::Vector3d& query, Eigen::Index hint) const {
  const std::int64_t c = CellOf(query);
  if (c < 0 || first_[c] == first_[c + 1]) return hint >= 0 ? tree_->Nearest(query, hint) : tree_->Nearest(query);
  const PointSet& points = tree_->points();
  PointTree::Neighbor best;
  best.squared_distance = std::numeric_limits<double>::infinity();
  for (std::uint32_t k = first_[c]; k < first_[c + 1]; ++k) {
    const std::uint32_t i = members_[k];
    const double dx = query(0) - points(0, i), dy = query(1) - points(1, i), dz = query(2) - points(2, i);
    const double squared = dx * dx + dy * dy + dz * dz;
    if (squared < best.squared_distance) {
      best.squared_distance = squared;
      best.index = i;
    }
  }
  return best;
}

void NearestGrid::NearestBatch(const PointSet& queries, Eigen::VectorXi* indices, Eigen::VectorXd* squared_distances,
                               const Eigen::VectorXi* hints) const {
  const Eigen::Index n = queries.cols();
  if (hints && hints->size() != n) hints = nullptr;
  if (indices) indices->resize(n);
  if (squared_distances) squared_distances->resize(n);
  constexpr int kChunk = 256;
  const int chunks = static_cast<int>((n + kChunk - 1) / kChunk);
  auto run_chunk = [&](int c) {
    const Eigen::Index end = std::min<Eigen::Index>(n, (c + 1) * Eigen::Index{kChunk});
    for (Eigen::Index i = c * Eigen::Index{kChunk}; i < end; ++i) {
      const PointTree::Neighbor nb = Nearest(queries.col(i), hints ? (*hints)(i) : -1);
      if (indices) (*indices)(i) = static_cast<int>(nb.index);
      if (squared_distances) (*squared_distances)(i) = nb.squared_distance;
    }
  };
  // Small batches run inline: thread start-up costs more than the queries.
  ParallelFor(0, chunks, run_chunk, n < 4096 ? 1 : 0);
}

}  // namespace c3po
