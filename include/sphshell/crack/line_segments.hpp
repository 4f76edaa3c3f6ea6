#pragma once
// crack::LineSegments: cracks as multiple line segments between damaged stress
// points (Ming, Zhang & Wang 2015, section 2.4 and Fig. 3; docs/method.md §6).
// Everything lives in the reference configuration (total Lagrangian): the
// topology only grows, and visibility is judged on reference positions.
//
// Topology rules (the paper states only "nearest distance criterion"; the
// details are this class's choice):
//   - linking distance L = 1.5 Δ: links the edge (Δ) and diagonal (√2 Δ)
//     neighbours of a square stress-point grid but not points two spacings
//     apart, so a crack never jumps over an intact stress point;
//   - a newly damaged stress point links to the nearest crack point (ties: the
//     lower point index) of EACH crack having a point within L; every crack it
//     links to is merged into the lowest of their ids. Linking to one crack
//     point per crack keeps each crack a tree; a second point of the same crack
//     within reach gets no extra segment (no loops, no redundant triangles);
//   - with nothing in reach it starts a new crack: an isolated point, counted by
//     crack_count() only once it has a segment;
//   - a point may carry any number of segments, so cracks branch;
//   - stress points damaged in one call are processed in ascending index order,
//     each seeing the ones before it, so the result does not depend on the
//     order the caller found them in (e.g. the OpenMP thread count).
// Each pre-crack polyline becomes a crack of its own; its points are crack
// points like the damaged ones (damaged stress points link to them).

#include <sphshell/approx/neighbour_search.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/crack/nearest_crack_point.hpp>
#include <sphshell/crack/segment_intersection.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace sphshell::crack {

// A crack segment between two crack points (indices into LineSegments::points()).
struct Segment {
  int start_point;
  int end_point;
  int crack_id;
  // The fields a checkpoint stores (crack.hpp).
  template <class S, class F>
  static void for_each_field(S& self, F&& field) {
    field(self.start_point, self.end_point, self.crack_id);
  }
};

inline bool operator==(const Segment& left, const Segment& right) {
  return left.start_point == right.start_point && left.end_point == right.end_point &&
         left.crack_id == right.crack_id;
}

// Euclidean distance from point to the segment [start, end] in 3-D.
inline double distance_to_segment(const Vector3& point, const Vector3& start, const Vector3& end) {
  const Vector3 direction = end - start;
  const double length_squared = direction.squaredNorm();
  if (length_squared == 0.0) return (point - start).norm();
  const double t = std::clamp((point - start).dot(direction) / length_squared, 0.0, 1.0);
  return (point - (start + t * direction)).norm();
}

class LineSegments {
 public:
  static constexpr bool enabled = true;
  static constexpr const char* name = "line segments";

  // Linking distance in units of the spacing (see the header comment).
  static constexpr double linking_distance_in_spacings = 1.5;
  // Pre-crack pieces shorter than this fraction of the spacing count as zero-length.
  static constexpr double zero_length_in_spacings = 1e-9;
  // Cell lists are built this much wider than the radius they serve, so the
  // exact distance test after the cell search decides at the boundary.
  static constexpr double cell_margin = 1.01;
  // A point closer than this fraction of the spacing to a pre-crack lies on it.
  static constexpr double on_precrack_in_spacings = 1e-6;
  // A pre-crack point farther than this (in spacings) from the tangent plane
  // of its nearest stress point is off the surface (it would cut nothing).
  static constexpr double off_surface_in_spacings = 0.25;
  // A pre-crack whose vertices and piece midpoints all lie this close (in
  // spacings) to an earlier pre-crack repeats it.
  static constexpr double repeated_precrack_in_spacings = 1e-3;
  static double distance_to_precrack_piece(const Vector3& point, const Vector3& start, const Vector3& end) {
    return distance_to_segment(point, start, end);
  }

  LineSegments() = default;

  void initialize(const std::vector<Vector3>& stress_point_positions,
                  const std::vector<Vector3>& stress_point_normals, double spacing,
                  double support_radius) {
    sphshell::detail::require_positive("crack spacing", spacing);
    sphshell::detail::require_positive("crack support_radius", support_radius);
    if (stress_point_normals.size() != stress_point_positions.size())
      sphshell::detail::invalid_parameter("crack stress_point_normals.size()",
                                          stress_point_normals.size(),
                                          "must equal the number of stress point positions (" +
                                              std::to_string(stress_point_positions.size()) + ")");
    for (std::size_t i = 0; i < stress_point_normals.size(); ++i) {
      const double length = stress_point_normals[i].norm();
      if (!(length > 0.0) || !std::isfinite(length))
        sphshell::detail::invalid_parameter("length of stress point normal " + std::to_string(i),
                                            length, "must be finite and > 0");
    }
    // The cell list checks that every position is finite.
    stress_point_index_.emplace(stress_point_positions, spacing);
    stress_point_positions_ = stress_point_positions;
    stress_point_normals_ = stress_point_normals;
    spacing_ = spacing;
    support_radius_ = support_radius;
    linking_distance_ = linking_distance_in_spacings * spacing;
    crack_point_of_stress_point_.assign(stress_point_positions.size(), -1);
    damaged_count_ = 0;
    points_.clear();
    crack_of_point_.clear();
    segments_.clear();
    crack_id_count_ = 0;
    precracks_.clear();
    max_segment_length_ = 0.0;
    segment_index_.reset();
    initialized_ = true;
  }

  // Adds a pre-crack along the polyline (reference configuration) and returns
  // the stress points that lie on it (within on_precrack_in_spacings), which
  // become its crack points and must leave the integration.
  std::vector<int> add_precrack(const std::vector<Vector3>& polyline) {
    require_initialized("add_precrack");
    if (polyline.size() < 2)
      sphshell::detail::invalid_parameter("pre-crack polyline size", polyline.size(),
                                          "needs at least 2 points");
    for (std::size_t k = 0; k < polyline.size(); ++k) {
      const Vector3& point = polyline[k];
      if (!point.allFinite()) {
        std::ostringstream name;
        name << "pre-crack point " << k;
        sphshell::detail::invalid_parameter(name.str(), point.transpose(), "must be finite");
      }
      int nearest = -1;
      double nearest_distance_squared = 0.0;
      stress_point_index_->for_each_within(point, spacing_, [&](int q, double distance_squared) {
        if (nearest < 0 || distance_squared < nearest_distance_squared) nearest = q, nearest_distance_squared = distance_squared;
      });
      if (nearest < 0) {
        std::ostringstream name;
        name << "pre-crack point " << k;
        sphshell::detail::invalid_parameter(name.str(), point.transpose(),
                                            "must lie on the shell: within one spacing (" +
                                                to_string(spacing_) + " m) of a stress point");
      }
      const auto slot = static_cast<std::size_t>(nearest);
      const double off_surface =
          std::abs((point - stress_point_positions_[slot]).dot(stress_point_normals_[slot].normalized()));
      if (off_surface > off_surface_in_spacings * spacing_) {
        std::ostringstream name;
        name << "pre-crack point " << k;
        sphshell::detail::invalid_parameter(
            name.str(), point.transpose(),
            "must lie on the shell's surface: it is " + to_string(off_surface) +
                " m off the tangent plane of the nearest stress point " + std::to_string(nearest) + ", at most " +
                to_string(off_surface_in_spacings) + " spacings (" + to_string(off_surface_in_spacings * spacing_) +
                " m) allowed");
      }
      if (k > 0 && (point - polyline[k - 1]).norm() <= zero_length_in_spacings * spacing_) {
        std::ostringstream name;
        name << "length of pre-crack piece " << k - 1 << "-" << k;
        sphshell::detail::invalid_parameter(name.str(), (point - polyline[k - 1]).norm(),
                                            "a pre-crack piece must not have zero length");
      }
    }
    for (std::size_t earlier = 0; earlier < precracks_.size(); ++earlier)
      if (repeats(polyline, precracks_[earlier]))
        sphshell::detail::invalid_parameter("pre-crack", "(" + std::to_string(polyline.size()) + " points)",
                                            "repeats pre-crack " + std::to_string(earlier) +
                                                " (it lies on it): add each pre-crack once");
    precracks_.push_back(polyline);
    // Stress points on the polyline become points of the pre-crack, in order
    // along it, exactly as damage along that row would have made them: a
    // pre-crack drawn through a row of stress points is the crack that row's
    // failure forms, and later damage links to it anywhere along its length.
    struct OnLine {
      std::size_t piece;
      double along;
      int stress_point;
    };
    std::vector<OnLine> on_line;
    const double tolerance = on_precrack_in_spacings * spacing_;
    for (std::size_t k = 0; k + 1 < polyline.size(); ++k) {
      const Vector3& start = polyline[k];
      const Vector3& end = polyline[k + 1];
      const double length = (end - start).norm();
      // Queries of one spacing (the index's radius) every half spacing cover the piece.
      const int samples = static_cast<int>(std::ceil(length / (0.5 * spacing_))) + 1;
      for (int sample = 0; sample < samples; ++sample) {
        const Vector3 centre = start + (end - start) * (double(sample) / double(samples - 1));
        stress_point_index_->for_each_within(centre, spacing_, [&](int q, double) {
          const auto slot = static_cast<std::size_t>(q);
          const Vector3& position = stress_point_positions_[slot];
          if (crack_point_of_stress_point_[slot] >= 0 || distance_to_segment(position, start, end) > tolerance)
            return;
          for (const OnLine& seen : on_line)
            if (seen.stress_point == q) return;  // found already (or on a vertex shared by two pieces)
          on_line.push_back({k, (position - start).dot(end - start) / (length * length), q});
        });
      }
    }
    std::sort(on_line.begin(), on_line.end(), [](const OnLine& a, const OnLine& b) {
      return a.piece != b.piece ? a.piece < b.piece : a.along < b.along;
    });

    struct PathPoint {
      Vector3 point;
      int stress_point;
    };
    std::vector<PathPoint> path;
    std::size_t next = 0;
    for (std::size_t k = 0; k < polyline.size(); ++k) {
      path.push_back({polyline[k], -1});
      for (; next < on_line.size() && on_line[next].piece == k; ++next)
        path.push_back({stress_point_positions_[static_cast<std::size_t>(on_line[next].stress_point)],
                        on_line[next].stress_point});
    }
    const int crack_id = crack_id_count_++;
    std::vector<int> absorbed;
    int previous = -1;
    for (const PathPoint& entry : path) {
      if (entry.stress_point >= 0) absorbed.push_back(entry.stress_point);
      // A stress point on a vertex stands for that vertex.
      if (previous >= 0 && (points_[static_cast<std::size_t>(previous)] - entry.point).norm() <= tolerance) {
        if (entry.stress_point >= 0)
          crack_point_of_stress_point_[static_cast<std::size_t>(entry.stress_point)] = previous;
        continue;
      }
      const int index = static_cast<int>(points_.size());
      points_.push_back(entry.point);
      crack_of_point_.push_back(crack_id);
      if (entry.stress_point >= 0) crack_point_of_stress_point_[static_cast<std::size_t>(entry.stress_point)] = index;
      if (previous >= 0) append_segment(previous, index);
      previous = index;
    }
    rebuild_segment_index();
    std::sort(absorbed.begin(), absorbed.end());
    return absorbed;
  }

  std::vector<Segment> add_damaged_stress_points(const std::vector<int>& stress_points) {
    require_initialized("add_damaged_stress_points");
    for (int index : stress_points) require_stress_point_index(index);
    std::vector<int> ordered = stress_points;
    std::sort(ordered.begin(), ordered.end());
    ordered.erase(std::unique(ordered.begin(), ordered.end()), ordered.end());
    // Called every step, mostly with nothing new: skip building the point index then.
    ordered.erase(std::remove_if(ordered.begin(), ordered.end(),
                                 [&](int stress_point) {
                                   return crack_point_of_stress_point_[static_cast<std::size_t>(
                                              stress_point)] >= 0;
                                 }),
                  ordered.end());
    if (ordered.empty()) return {};

    std::vector<Segment> created;
    NearestCrackPointSearch search(points_, crack_of_point_, linking_distance_, cell_margin);
    for (int stress_point : ordered) {
      const auto slot = static_cast<std::size_t>(stress_point);
      const Vector3& position = stress_point_positions_[slot];
      const std::vector<int> targets = search.nearest_point_of_each_crack(position);

      const int new_point = static_cast<int>(points_.size());
      points_.push_back(position);
      crack_point_of_stress_point_[slot] = new_point;
      ++damaged_count_;
      if (targets.empty()) {
        crack_of_point_.push_back(crack_id_count_++);
      } else {
        std::vector<int> joined_cracks;
        for (int target : targets)
          joined_cracks.push_back(crack_of_point_[static_cast<std::size_t>(target)]);
        const int merged_id = *std::min_element(joined_cracks.begin(), joined_cracks.end());
        crack_of_point_.push_back(merged_id);
        relabel(joined_cracks, merged_id);
        for (int target : targets) {
          append_segment(target, new_point);
          created.push_back(segments_.back());
        }
      }
      search.note_new_point(new_point);
    }
    // Later merges in this call may have relabelled earlier segments.
    for (Segment& segment : created)
      segment.crack_id = crack_of_point_[static_cast<std::size_t>(segment.start_point)];
    if (!created.empty()) rebuild_segment_index();
    return created;
  }

  // Visibility of neighbour b from evaluation point a (docs/method.md §6, item 4),
  // judged in the tangent plane of frame at a. Only crack segments within
  // reach = max(support_radius, |a − b|) of a (3-D point-to-segment distance)
  // are tested: a segment crossing the pair comes closer to a than b does, and
  // the bound keeps the far side of a curved shell, whose projection onto the
  // tangent plane at a may overlap the pair, from cutting it.
  bool visible(const Vector3& a, const Vector3& b, const TangentFrame& frame) const {
    require_initialized("visible");
    if (segments_.empty()) return true;
    const double reach = std::max(support_radius_, (a - b).norm());
    const double query_radius = reach + 0.5 * max_segment_length_;
    auto cuts = [&](const Segment& segment) {
      const Vector3& start = points_[static_cast<std::size_t>(segment.start_point)];
      const Vector3& end = points_[static_cast<std::size_t>(segment.end_point)];
      return distance_to_segment(a, start, end) <= reach &&
             pair_is_cut_in_tangent_plane(a, b, start, end, frame, a);
    };
    if (query_radius > segment_index_->radius()) {
      for (const Segment& segment : segments_)
        if (cuts(segment)) return false;
      return true;
    }
    bool cut = false;
    segment_index_->for_each_within(a, query_radius, [&](int k, double) {
      if (!cut && cuts(segments_[static_cast<std::size_t>(k)])) cut = true;
    });
    return !cut;
  }

  // Sorted indices of the evaluation points closer than support_radius to any
  // of new_segments: the only points whose support domains the new segments
  // can cut, hence the only shape functions to rebuild.
  std::vector<std::size_t> affected_points(const std::vector<Vector3>& eval_positions,
                                           const std::vector<Segment>& new_segments) const {
    require_initialized("affected_points");
    double max_half_length = 0.0;
    for (const Segment& segment : new_segments) {
      require_segment(segment);
      max_half_length = std::max(max_half_length, 0.5 * segment_length(segment));
    }
    std::vector<std::size_t> affected;
    if (new_segments.empty() || eval_positions.empty()) return affected;
    // Slightly wider than needed: the exact distance test below decides.
    const approx::CellList eval_index(eval_positions, cell_margin * (support_radius_ + max_half_length));
    std::vector<char> is_affected(eval_positions.size(), 0);
    for (const Segment& segment : new_segments) {
      const Vector3& start = points_[static_cast<std::size_t>(segment.start_point)];
      const Vector3& end = points_[static_cast<std::size_t>(segment.end_point)];
      const Vector3 midpoint = 0.5 * (start + end);
      eval_index.for_each_within(midpoint, eval_index.radius(), [&](int i, double) {
        const auto slot = static_cast<std::size_t>(i);
        if (!is_affected[slot] &&
            distance_to_segment(eval_positions[slot], start, end) < support_radius_)
          is_affected[slot] = 1;
      });
    }
    for (std::size_t i = 0; i < is_affected.size(); ++i)
      if (is_affected[i]) affected.push_back(i);
    return affected;
  }

  const std::vector<Vector3>& points() const { return points_; }
  const std::vector<Segment>& segments() const { return segments_; }
  bool is_damaged(int stress_point) const {
    require_initialized("is_damaged");
    require_stress_point_index(stress_point);
    return crack_point_of_stress_point_[static_cast<std::size_t>(stress_point)] >= 0;
  }
  // Crack point of a damaged stress point, -1 if it is intact.
  int crack_point_of_stress_point(int stress_point) const {
    require_initialized("crack_point_of_stress_point");
    require_stress_point_index(stress_point);
    return crack_point_of_stress_point_[static_cast<std::size_t>(stress_point)];
  }
  // Crack id of each crack point, isolated points included.
  const std::vector<int>& crack_of_point() const { return crack_of_point_; }
  std::size_t damaged_count() const { return damaged_count_; }
  double spacing() const { return spacing_; }
  double support_radius() const { return support_radius_; }
  double linking_distance() const { return linking_distance_; }
  const std::vector<Vector3>& stress_point_normals() const { return stress_point_normals_; }

  // Ids of the cracks that have at least one segment, ascending: the
  // "compacted id order" of crack_lengths().
  std::vector<int> crack_ids() const {
    std::vector<char> has_segment(static_cast<std::size_t>(crack_id_count_), 0);
    for (const Segment& segment : segments_)
      has_segment[static_cast<std::size_t>(segment.crack_id)] = 1;
    std::vector<int> ids;
    for (int id = 0; id < crack_id_count_; ++id)
      if (has_segment[static_cast<std::size_t>(id)]) ids.push_back(id);
    return ids;
  }
  int crack_count() const { return static_cast<int>(crack_ids().size()); }
  double total_length() const {
    double length = 0.0;
    for (const Segment& segment : segments_) length += segment_length(segment);
    return length;
  }
  // Entry k is the length of crack crack_ids()[k].
  std::vector<double> crack_lengths() const {
    std::vector<double> length_of_id(static_cast<std::size_t>(crack_id_count_), 0.0);
    for (const Segment& segment : segments_)
      length_of_id[static_cast<std::size_t>(segment.crack_id)] += segment_length(segment);
    std::vector<double> lengths;
    for (int id : crack_ids()) lengths.push_back(length_of_id[static_cast<std::size_t>(id)]);
    return lengths;
  }
  bool empty() const { return segments_.empty(); }

  // Checkpoints (crack.hpp): the topology and counters; the geometry given to
  // initialize() is the model's, and the segment index is rebuilt from the
  // segments (its answers depend on them and on max_segment_length_ only).
  template <class Writer>
  void save(Writer& out) const {
    out(crack_point_of_stress_point_, static_cast<std::uint64_t>(damaged_count_), points_, crack_of_point_, segments_,
        crack_id_count_, precracks_, max_segment_length_);
  }
  template <class Reader>
  void load(Reader& in) {
    require_initialized("load");
    // Read into locals and checked before anything is stored (the checksum
    // vouches for the bytes, this for the meaning), so a failed load leaves
    // the topology as it was, every index in range.
    std::vector<int> crack_point_of_stress_point(crack_point_of_stress_point_.size());
    std::uint64_t damaged = 0;
    std::vector<Vector3> points;
    std::vector<int> crack_of_point;
    std::vector<Segment> segments;
    int crack_id_count = 0;
    std::vector<std::vector<Vector3>> precracks;
    double max_segment_length = 0.0;
    in.read_exact(crack_point_of_stress_point, "crack point of each stress point");
    in(damaged, points, crack_of_point, segments, crack_id_count, precracks, max_segment_length);
    const auto point_count = static_cast<int>(points.size());
    if (crack_of_point.size() != points.size()) in.fail("crack ids and crack points differ in number");
    if (crack_id_count < 0) in.fail("its crack count " + std::to_string(crack_id_count) + " is negative");
    for (const int point : crack_point_of_stress_point)
      if (point < -1 || point >= point_count) in.fail("a stress point names crack point " + std::to_string(point));
    for (const int id : crack_of_point)
      if (id < 0 || id >= crack_id_count) in.fail("a crack point names crack " + std::to_string(id));
    double longest = 0.0;
    for (const Segment& segment : segments) {
      if (segment.start_point < 0 || segment.start_point >= point_count || segment.end_point < 0 ||
          segment.end_point >= point_count || segment.crack_id < 0 || segment.crack_id >= crack_id_count)
        in.fail("a crack segment names a point or crack that does not exist");
      longest = std::max(longest, (points[static_cast<std::size_t>(segment.end_point)] -
                                   points[static_cast<std::size_t>(segment.start_point)])
                                      .norm());
    }
    // The segment index reaches as far as the longest segment recorded: a
    // shorter record would hide segments from it.
    if (!(max_segment_length >= longest) || !std::isfinite(max_segment_length))
      in.fail("its longest crack segment is recorded as " + std::to_string(max_segment_length) +
              " m; it must be finite and at least its segments' " + std::to_string(longest) + " m");
    crack_point_of_stress_point_ = std::move(crack_point_of_stress_point);
    damaged_count_ = static_cast<std::size_t>(damaged);
    points_ = std::move(points);
    crack_of_point_ = std::move(crack_of_point);
    segments_ = std::move(segments);
    crack_id_count_ = crack_id_count;
    precracks_ = std::move(precracks);
    max_segment_length_ = max_segment_length;
    segment_index_.reset();
    if (!segments_.empty() || !precracks_.empty()) rebuild_segment_index();
  }

 private:
  // Whether every vertex and piece midpoint of `polyline` lies on `earlier`.
  bool repeats(const std::vector<Vector3>& polyline, const std::vector<Vector3>& earlier) const {
    const double tolerance = repeated_precrack_in_spacings * spacing_;
    auto on_earlier = [&](const Vector3& point) {
      for (std::size_t k = 0; k + 1 < earlier.size(); ++k)
        if (distance_to_segment(point, earlier[k], earlier[k + 1]) <= tolerance) return true;
      return false;
    };
    for (std::size_t k = 0; k < polyline.size(); ++k) {
      if (!on_earlier(polyline[k])) return false;
      if (k + 1 < polyline.size() && !on_earlier(0.5 * (polyline[k] + polyline[k + 1]))) return false;
    }
    return true;
  }
  void require_initialized(const char* operation) const {
    if (!initialized_)
      throw Error(std::string("sphshell: crack::LineSegments::") + operation +
                  " called before initialize()");
  }
  void require_stress_point_index(int index) const {
    if (index < 0 || static_cast<std::size_t>(index) >= crack_point_of_stress_point_.size())
      sphshell::detail::invalid_parameter(
          "stress point index", index,
          "must lie in [0, " + std::to_string(crack_point_of_stress_point_.size()) + ")");
  }
  void require_segment(const Segment& segment) const {
    const auto point_count = static_cast<int>(points_.size());
    for (int point : {segment.start_point, segment.end_point})
      if (point < 0 || point >= point_count)
        sphshell::detail::invalid_parameter("crack segment point index", point,
                                            "must lie in [0, " + std::to_string(point_count) + ")");
  }
  static std::string to_string(double value) {
    std::ostringstream text;
    text << value;
    return text.str();
  }

  double segment_length(const Segment& segment) const {
    return (points_[static_cast<std::size_t>(segment.end_point)] -
            points_[static_cast<std::size_t>(segment.start_point)])
        .norm();
  }

  void append_segment(int start_point, int end_point) {
    segments_.push_back(
        {start_point, end_point, crack_of_point_[static_cast<std::size_t>(end_point)]});
    max_segment_length_ = std::max(max_segment_length_, segment_length(segments_.back()));
  }

  // Merges are rare (two crack tips meeting), so a full relabelling pass is
  // cheaper overall than keeping a union-find structure consistent.
  void relabel(const std::vector<int>& old_ids, int new_id) {
    auto merged = [&](int id) {
      return std::find(old_ids.begin(), old_ids.end(), id) != old_ids.end();
    };
    if (std::all_of(old_ids.begin(), old_ids.end(), [&](int id) { return id == new_id; })) return;
    for (int& id : crack_of_point_)
      if (merged(id)) id = new_id;
    for (Segment& segment : segments_)
      if (merged(segment.crack_id)) segment.crack_id = new_id;
  }

  // Midpoints indexed with a radius that finds every segment within
  // support_radius of a query point.
  void rebuild_segment_index() {
    std::vector<Vector3> midpoints;
    midpoints.reserve(segments_.size());
    for (const Segment& segment : segments_)
      midpoints.push_back(0.5 * (points_[static_cast<std::size_t>(segment.start_point)] +
                                 points_[static_cast<std::size_t>(segment.end_point)]));
    segment_index_.emplace(midpoints, cell_margin * (support_radius_ + 0.5 * max_segment_length_));
  }

  bool initialized_ = false;
  double spacing_ = 0.0;
  double support_radius_ = 0.0;
  double linking_distance_ = 0.0;
  std::vector<Vector3> stress_point_positions_;
  std::vector<Vector3> stress_point_normals_;
  std::optional<approx::CellList> stress_point_index_;
  std::vector<int> crack_point_of_stress_point_;
  std::size_t damaged_count_ = 0;

  std::vector<Vector3> points_;
  std::vector<int> crack_of_point_;
  std::vector<Segment> segments_;
  int crack_id_count_ = 0;
  std::vector<std::vector<Vector3>> precracks_;  // as added, for the repeat check
  double max_segment_length_ = 0.0;
  std::optional<approx::CellList> segment_index_;
};

}  // namespace sphshell::crack
