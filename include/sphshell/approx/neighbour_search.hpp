#pragma once
// Fixed-radius neighbour search over 3-D points: a cell-linked list.
//
// Flat and mildly curved sheets use a dense array of cells over the bounding
// box (at most 2 cells per point). Strongly curved shells would mostly fill such
// an array with empty cells (a thin cylinder: ~ (R/Δ)³ cells for ~ (R/Δ)²
// points), so then only the occupied cells are stored, found through a hash
// table. Either way memory is O(N), building is O(N) (count, prefix sum,
// fill — no sort) and a query visits the 27 cells around the point, each found
// in O(1) (expected, for the hash).

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <utility>
#include <vector>

namespace sphshell::approx {

class CellList {
 public:
  // `radius` is the cell width: a query of at most that radius visits the
  // 3×3×3 block of cells around the query point's cell; a wider one (a row
  // whose local support is larger than most) visits ⌈radius / width⌉ layers.
  CellList(const std::vector<Vector3>& points, double radius) {
    sphshell::detail::require_positive("neighbour search radius", radius);
    const std::size_t count = points.size();
    if (count == 0) return;
    lower_ = points[0];
    Vector3 upper = points[0];
    for (std::size_t i = 0; i < count; ++i) {
      const Vector3& p = points[i];
      if (!p.allFinite()) {
        std::ostringstream name;
        name << "coordinates of point " << i;
        sphshell::detail::invalid_parameter(name.str(), p.transpose(), "must be finite");
      }
      lower_ = lower_.cwiseMin(p);
      upper = upper.cwiseMax(p);
    }
    // Cell coordinates are packed into 21 bits per axis; a set far longer than
    // 2^20 radii along one axis gets wider cells (slower queries, still exact).
    const double extent = (upper - lower_).maxCoeff();
    cell_size_ = std::max(radius, extent / double(1 << 20));
    inverse_cell_size_ = 1.0 / cell_size_;
    radius_ = radius;
    // Regular sheets put their points on multiples of the spacing; shifting the
    // grid by an irrational fraction of a cell keeps them off the cell faces,
    // which the coincidence check relies on to stay cheap.
    lower_ -= Vector3::Constant(0.3819660112501051 * cell_size_);
    for (int axis = 0; axis < 3; ++axis)
      cells_per_axis_[axis] =
          static_cast<std::int64_t>(std::floor((upper[axis] - lower_[axis]) * inverse_cell_size_)) + 1;

    std::vector<int> cell_of_point(count);
    std::vector<int> cell_count;
    const double dense_cells = double(cells_per_axis_[0]) * double(cells_per_axis_[1]) *
                               double(cells_per_axis_[2]);
    dense_ = dense_cells <= double(dense_cells_per_point * count + 1024);
    if (dense_) {
      cell_count.assign(static_cast<std::size_t>(dense_cells), 0);
      for (std::size_t i = 0; i < count; ++i) {
        const int cell = dense_index(cell_coordinates(points[i]));
        cell_of_point[i] = cell;
        ++cell_count[static_cast<std::size_t>(cell)];
      }
    } else {
      std::size_t table_size = 16;
      while (table_size < 2 * count) table_size *= 2;
      table_keys_.assign(table_size, empty_key);
      table_cells_.assign(table_size, 0);
      cell_count.reserve(count / 4 + 1);
      for (std::size_t i = 0; i < count; ++i) {
        const std::uint64_t key = pack(cell_coordinates(points[i]));
        std::size_t slot = hash(key) & (table_size - 1);
        while (table_keys_[slot] != empty_key && table_keys_[slot] != key)
          slot = (slot + 1) & (table_size - 1);
        if (table_keys_[slot] == empty_key) {
          table_keys_[slot] = key;
          table_cells_[slot] = static_cast<int>(cell_count.size());
          cell_count.push_back(0);
        }
        const int cell = table_cells_[slot];
        cell_of_point[i] = cell;
        ++cell_count[static_cast<std::size_t>(cell)];
      }
    }
    cell_begin_.assign(cell_count.size() + 1, 0);
    for (std::size_t c = 0; c < cell_count.size(); ++c)
      cell_begin_[c + 1] = cell_begin_[c] + cell_count[c];
    // Filling in point order keeps each cell's list sorted by index, which
    // makes query results reproducible.
    std::vector<int> fill(cell_begin_.begin(), cell_begin_.end() - 1);
    point_in_cell_.resize(count);
    cell_points_.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
      const int position = fill[static_cast<std::size_t>(cell_of_point[i])]++;
      cell_points_[static_cast<std::size_t>(position)] = static_cast<int>(i);
      point_in_cell_[static_cast<std::size_t>(position)] = points[i];
    }
  }

  double radius() const { return radius_; }
  // True when the cells are a dense array over the bounding box (flat or mildly
  // curved sets), false when only occupied cells are stored in a hash table.
  bool dense() const { return dense_; }
  std::size_t size() const { return cell_points_.size(); }

  // Calls visit(index, distance_squared) for every point with
  // |point − x| < radius (strictly: a point exactly on the support boundary
  // has zero weight for every kernel and is left out). A radius above
  // radius() visits more layers of cells.
  template <class Visit>
  void for_each_within(const Vector3& x, double radius, Visit&& visit) const {
    for_each_slot_within(x, radius,
                         [&](std::size_t slot, double distance_squared) { visit(cell_points_[slot], distance_squared); });
  }

  // The points in cell order (grouped by cell, each cell's by index): the
  // slot-th point's index and coordinates. A caller that keeps its own
  // per-point data in this order reads it in the order the queries visit it.
  int point_at(std::size_t slot) const { return cell_points_[slot]; }
  const Vector3& position_at(std::size_t slot) const { return point_in_cell_[slot]; }

  // for_each_within by slot: calls visit(slot, distance_squared) for the same
  // points in the same order (point_at(slot) is the index).
  template <class Visit>
  void for_each_slot_within(const Vector3& x, double radius, Visit&& visit) const {
    if (!(radius >= 0.0) || !std::isfinite(radius))
      sphshell::detail::invalid_parameter("query radius", radius, "must be finite and >= 0");
    if (cell_points_.empty()) return;
    const double radius_squared = radius * radius;
    const Cell centre = cell_coordinates_unclamped(x);
    const std::int64_t layers =
        radius <= cell_size_ ? 1 : static_cast<std::int64_t>(std::ceil(radius * inverse_cell_size_));
    // Only the layers inside the grid are visited: cells outside the bounding
    // box are empty (skipping them spares a flat plate 18 of its 27 lookups).
    const auto first = [&](std::int64_t c) { return std::max(c - layers, std::int64_t{0}); };
    const auto last = [&](std::int64_t c, int axis) { return std::min(c + layers, cells_per_axis_[axis] - 1); };
    const std::int64_t first_z = first(centre.z), last_z = last(centre.z, 2);
    if (dense_) {
      // A column's cells (cx, cy, first_z … last_z) are consecutive in the
      // dense array and so are their points: one run of points per column,
      // in the order the cells would give them one by one; per slab (cx) when
      // the columns span the grid's height (a flat set one or a few cells high).
      if (first_z > last_z) return;
      // The points of the cells bottom … top (dense indices), in that order.
      const auto visit_run = [&](const Cell& bottom, const Cell& top) {
        const auto end = static_cast<std::size_t>(cell_begin_[static_cast<std::size_t>(dense_index(top)) + 1]);
        for (auto k = static_cast<std::size_t>(cell_begin_[static_cast<std::size_t>(dense_index(bottom))]); k < end;
             ++k) {
          const double distance_squared = (point_in_cell_[k] - x).squaredNorm();
          if (distance_squared < radius_squared) visit(k, distance_squared);
        }
      };
      const bool whole_height = first_z == 0 && last_z == cells_per_axis_[2] - 1;
      const std::int64_t first_y = first(centre.y), last_y = last(centre.y, 1);
      for (std::int64_t cx = first(centre.x); cx <= last(centre.x, 0); ++cx) {
        if (whole_height) {
          if (first_y <= last_y) visit_run({cx, first_y, first_z}, {cx, last_y, last_z});
          continue;
        }
        for (std::int64_t cy = first_y; cy <= last_y; ++cy) visit_run({cx, cy, first_z}, {cx, cy, last_z});
      }
      return;
    }
    for (std::int64_t cx = first(centre.x); cx <= last(centre.x, 0); ++cx)
      for (std::int64_t cy = first(centre.y); cy <= last(centre.y, 1); ++cy)
        for (std::int64_t cz = first_z; cz <= last_z; ++cz) {
          const Cell cell{cx, cy, cz};
          const int index = dense_ ? dense_index(cell) : find(pack(cell));
          if (index < 0) continue;
          const std::size_t end = static_cast<std::size_t>(cell_begin_[index + 1]);
          for (std::size_t k = static_cast<std::size_t>(cell_begin_[index]); k < end; ++k) {
            const double distance_squared = (point_in_cell_[k] - x).squaredNorm();
            if (distance_squared < radius_squared) visit(k, distance_squared);
          }
        }
  }

  // Throws naming the first pair of points closer than `tolerance`.
  void require_no_coincident_points(double tolerance, const std::string& set_name) const {
    for_each_coincident_pair(tolerance, [&](int i, int j) { report_coincident(i, j, set_name); });
  }

  // Every pair (i < j) of points closer than `tolerance`, sorted, each once.
  std::vector<std::pair<int, int>> coincident_pairs(double tolerance) const {
    std::vector<std::pair<int, int>> pairs;
    for_each_coincident_pair(tolerance, [&](int i, int j) { pairs.emplace_back(i, j); });
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    return pairs;
  }

  // Calls visit(i, j), i < j, for each pair of points closer than `tolerance`
  // (a pair near a cell face may come twice). Each point is compared with its
  // own cell; the neighbouring cells are searched only for points within
  // `tolerance` of a cell face, so this is nearly free.
  template <class Visit>
  void for_each_coincident_pair(double tolerance, Visit&& visit) const {
    const double tolerance_squared = tolerance * tolerance;
    for (std::size_t c = 0; c + 1 < cell_begin_.size(); ++c) {
      const auto begin = static_cast<std::size_t>(cell_begin_[c]);
      const auto end = static_cast<std::size_t>(cell_begin_[c + 1]);
      for (std::size_t a = begin; a < end; ++a) {
        const Vector3& p = point_in_cell_[a];
        for (std::size_t b = a + 1; b < end; ++b)
          if ((point_in_cell_[b] - p).squaredNorm() <= tolerance_squared)
            visit(std::min(cell_points_[a], cell_points_[b]), std::max(cell_points_[a], cell_points_[b]));
        if (near_cell_face(p, tolerance)) {
          const int i = cell_points_[a];
          for_each_within(p, std::max(tolerance, 0.0) + 1e-300, [&](int j, double distance_squared) {
            if (j != i && distance_squared <= tolerance_squared) visit(std::min(i, j), std::max(i, j));
          });
        }
      }
    }
  }

 private:
  struct Cell {
    std::int64_t x, y, z;
  };

  static constexpr std::uint64_t empty_key = ~std::uint64_t{0};
  // A dense array of cells is used when it costs at most this many cells per
  // point: it needs no hashing and its cells are stored in spatial order, so
  // consecutive queries hit the cache.
  static constexpr std::size_t dense_cells_per_point = 2;
  static constexpr std::int64_t axis_cells = std::int64_t{1} << 21;

  Cell cell_coordinates_unclamped(const Vector3& p) const {
    const Vector3 scaled = (p - lower_) * inverse_cell_size_;
    // Far-away query points are mapped just outside the grid (their layers are
    // clipped to it).
    auto to_cell = [](double s) {
      if (!(s > -2.0)) return std::int64_t{-2};
      if (!(s < double(axis_cells + 1))) return axis_cells + 1;
      return static_cast<std::int64_t>(std::floor(s));
    };
    return {to_cell(scaled.x()), to_cell(scaled.y()), to_cell(scaled.z())};
  }
  Cell cell_coordinates(const Vector3& p) const {
    Cell c = cell_coordinates_unclamped(p);
    c.x = std::clamp<std::int64_t>(c.x, 0, axis_cells - 1);
    c.y = std::clamp<std::int64_t>(c.y, 0, axis_cells - 1);
    c.z = std::clamp<std::int64_t>(c.z, 0, axis_cells - 1);
    return c;
  }
  int dense_index(const Cell& c) const {
    return static_cast<int>((c.x * cells_per_axis_[1] + c.y) * cells_per_axis_[2] + c.z);
  }
  static std::uint64_t pack(const Cell& c) {
    return (std::uint64_t(c.x) << 42) | (std::uint64_t(c.y) << 21) | std::uint64_t(c.z);
  }
  // splitmix64 finalizer: packed keys of neighbouring cells differ in few bits.
  static std::uint64_t hash(std::uint64_t key) {
    key ^= key >> 30;
    key *= 0xbf58476d1ce4e5b9ULL;
    key ^= key >> 27;
    key *= 0x94d049bb133111ebULL;
    return key ^ (key >> 31);
  }
  int find(std::uint64_t key) const {
    const std::size_t mask = table_keys_.size() - 1;
    std::size_t slot = hash(key) & mask;
    while (true) {
      const std::uint64_t stored = table_keys_[slot];
      if (stored == key) return table_cells_[slot];
      if (stored == empty_key) return -1;
      slot = (slot + 1) & mask;
    }
  }
  bool near_cell_face(const Vector3& p, double tolerance) const {
    const Vector3 scaled = (p - lower_) * inverse_cell_size_;
    const double relative = tolerance * inverse_cell_size_;
    for (int axis = 0; axis < 3; ++axis) {
      const double fraction = scaled[axis] - std::floor(scaled[axis]);
      if (fraction <= relative || fraction >= 1.0 - relative) return true;
    }
    return false;
  }
  [[noreturn]] static void report_coincident(int i, int j, const std::string& set_name) {
    std::ostringstream message;
    message << "sphshell: coincident " << set_name << " " << i << " and " << j
            << " (points of one set must be distinct)";
    throw Error(message.str());
  }

  Vector3 lower_ = Vector3::Zero();
  double cell_size_ = 1.0;
  double inverse_cell_size_ = 1.0;
  double radius_ = 0.0;
  std::int64_t cells_per_axis_[3] = {0, 0, 0};
  bool dense_ = false;
  std::vector<std::uint64_t> table_keys_;
  std::vector<int> table_cells_;
  std::vector<int> cell_begin_;
  std::vector<int> cell_points_;       // point indices grouped by cell
  std::vector<Vector3> point_in_cell_;  // their coordinates, in the same order, for locality
};

}  // namespace sphshell::approx
