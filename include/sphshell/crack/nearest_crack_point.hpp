#pragma once
// The nearest crack point of each crack within the linking distance of a
// newly damaged stress point (crack::LineSegments' topology rules,
// docs/method.md §6): one point per crack, the nearest, ties to the lower
// point index.

#include <algorithm>
#include <cstddef>
#include <optional>
#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/core/types.hpp>
#include <vector>

namespace sphshell::crack {

// Nearest crack points within the linking distance. The cell list over the
// crack points is built once per call; points added during the call are
// scanned directly until there are enough of them to be worth re-indexing.
class NearestCrackPointSearch {
 public:
  // points: the crack points (the vector may grow between calls, each new
  // point announced by note_new_point); crack_of_point: each point's crack id;
  // the cell list is built cell_margin times wider than the linking distance.
  NearestCrackPointSearch(const std::vector<Vector3>& points, const std::vector<int>& crack_of_point,
                          double linking_distance, double cell_margin)
      : points_(points),
        crack_of_point_(crack_of_point),
        linking_distance_(linking_distance),
        cell_margin_(cell_margin) {
    reindex();
  }

  // One point per crack in reach: the nearest, ties to the lower point index.
  // Sorted by crack id.
  std::vector<int> nearest_point_of_each_crack(const Vector3& position) const {
    const double reach_squared = linking_distance_ * linking_distance_;
    struct Candidate {
      int crack_id;
      double distance_squared;
      int point;
    };
    std::vector<Candidate> candidates;
    auto consider = [&](int point, double distance_squared) {
      if (distance_squared <= reach_squared)
        candidates.push_back({crack_of_point_[static_cast<std::size_t>(point)], distance_squared, point});
    };
    if (indexed_points_)
      indexed_points_->for_each_within(position, indexed_points_->radius(), [&](int point, double) {
        consider(point, (points_[static_cast<std::size_t>(point)] - position).squaredNorm());
      });
    for (int point : unindexed_points_)
      consider(point, (points_[static_cast<std::size_t>(point)] - position).squaredNorm());
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
      if (x.crack_id != y.crack_id) return x.crack_id < y.crack_id;
      if (x.distance_squared != y.distance_squared) return x.distance_squared < y.distance_squared;
      return x.point < y.point;
    });
    std::vector<int> nearest;
    for (std::size_t k = 0; k < candidates.size(); ++k)
      if (k == 0 || candidates[k].crack_id != candidates[k - 1].crack_id) nearest.push_back(candidates[k].point);
    return nearest;
  }

  void note_new_point(int point) {
    unindexed_points_.push_back(point);
    if (unindexed_points_.size() >= max_unindexed_points) reindex();
  }

 private:
  static constexpr std::size_t max_unindexed_points = 64;

  void reindex() {
    unindexed_points_.clear();
    if (points_.empty()) {
      indexed_points_.reset();
      return;
    }
    // A little wider than the linking distance: the cell list excludes its
    // boundary, the linking test includes it.
    indexed_points_.emplace(points_, cell_margin_ * linking_distance_);
  }

  const std::vector<Vector3>& points_;
  const std::vector<int>& crack_of_point_;
  double linking_distance_;
  double cell_margin_;
  std::optional<approx::CellList> indexed_points_;
  std::vector<int> unindexed_points_;
};

}  // namespace sphshell::crack
