#include "c3po/geometry/kdtree.hpp"

#include <cmath>
#include <limits>
#include <nanoflann.hpp>

#include "c3po/base/parallel.hpp"

namespace c3po {

// nanoflann dataset adaptor over a column-major 3xN matrix.
struct PointSetAdaptor {
  const PointSet* points;
  std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(points->cols()); }
  double kdtree_get_pt(std::size_t index, std::size_t dim) const {
    return (*points)(static_cast<Eigen::Index>(dim), static_cast<Eigen::Index>(index));
  }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox&) const { return false; }
};

using KdTree = nanoflann::KDTreeSingleIndexAdaptor<
    nanoflann::L2_Simple_Adaptor<double, PointSetAdaptor>, PointSetAdaptor, 3, Eigen::Index>;

struct PointTree::Index {
  PointSetAdaptor adaptor;
  KdTree tree;
  explicit Index(const PointSet* points)
      : adaptor{points}, tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {
    tree.buildIndex();
  }
};

PointTree::PointTree(PointSet points) : points_(std::move(points)) {
  if (points_.cols() > 0) index_ = std::make_unique<Index>(&points_);
}
PointTree::~PointTree() = default;

// The index keeps a pointer to points_; after a move, rebuild it against the new address.
PointTree::PointTree(PointTree&& other) noexcept : points_(std::move(other.points_)) {
  other.index_.reset();
  if (points_.cols() > 0) index_ = std::make_unique<Index>(&points_);
}
PointTree& PointTree::operator=(PointTree&& other) noexcept {
  if (this != &other) {
    points_ = std::move(other.points_);
    other.index_.reset();
    index_.reset();
    if (points_.cols() > 0) index_ = std::make_unique<Index>(&points_);
  }
  return *this;
}

namespace {

// nanoflann result set of one neighbour whose search starts bounded: the
// nearest point strictly closer than `bound` (squared). Same rule as
// KNNResultSet(1): a point replaces the kept one only when strictly closer,
// so among equidistant points the first visited wins, as without a bound.
class BoundedNearest {
 public:
  explicit BoundedNearest(double bound) : best_(bound) {}
  bool addPoint(double squared_distance, Eigen::Index index) {
    if (squared_distance < best_) {
      best_ = squared_distance;
      index_ = index;
    }
    return true;
  }
  double worstDist() const { return best_; }
  bool full() const { return index_ >= 0; }
  Eigen::Index index() const { return index_; }

 private:
  double best_;
  Eigen::Index index_ = -1;
};

}  // namespace

PointTree::Neighbor PointTree::Nearest(const Eigen::Vector3d& query) const {
  Neighbor neighbor;
  if (!index_) {
    neighbor.squared_distance = std::numeric_limits<double>::infinity();
    return neighbor;
  }
  nanoflann::KNNResultSet<double, Eigen::Index> result(1);
  result.init(&neighbor.index, &neighbor.squared_distance);
  index_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  // A non-finite (or overflowing) query finds nothing: report it like an empty tree.
  if (neighbor.index < 0) neighbor.squared_distance = std::numeric_limits<double>::infinity();
  return neighbor;
}

PointTree::Neighbor PointTree::Nearest(const Eigen::Vector3d& query, Eigen::Index hint) const {
  if (!index_ || hint < 0 || hint >= points_.cols()) return Nearest(query);
  const double hinted = (query - points_.col(hint)).squaredNorm();
  // The nearest point is no farther than the hint; the margin covers rounding
  // differences between this distance and nanoflann's (its test is strict).
  const double bound = hinted * (1.0 + 1e-9) + std::numeric_limits<double>::min();
  if (!std::isfinite(bound)) return Nearest(query);
  BoundedNearest result(bound);
  index_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  if (result.index() < 0) return Nearest(query);   // cannot happen for a finite query; stay exact anyway
  Neighbor neighbor;
  neighbor.index = result.index();
  neighbor.squared_distance = result.worstDist();
  return neighbor;
}

std::vector<PointTree::Neighbor> PointTree::KNearest(const Eigen::Vector3d& query, int k) const {
  std::vector<Neighbor> neighbors;
  if (!index_ || k <= 0) return neighbors;
  const std::size_t count = std::min<std::size_t>(k, points_.cols());
  std::vector<Eigen::Index> indices(count);
  std::vector<double> distances(count);
  nanoflann::KNNResultSet<double, Eigen::Index> result(count);
  result.init(indices.data(), distances.data());
  index_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  for (std::size_t i = 0; i < result.size(); ++i) neighbors.push_back({indices[i], distances[i]});
  return neighbors;
}

void PointTree::NearestBatch(const PointSet& queries, Eigen::VectorXi* indices, Eigen::VectorXd* squared_distances,
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
      const Neighbor nb = hints ? Nearest(queries.col(i), (*hints)(i)) : Nearest(queries.col(i));
      if (indices) (*indices)(i) = static_cast<int>(nb.index);
      if (squared_distances) (*squared_distances)(i) = nb.squared_distance;
    }
  };
  // Small batches run inline: thread start-up costs more than the queries.
  ParallelFor(0, chunks, run_chunk, n < 4096 ? 1 : 0);
}

}  // namespace c3po
