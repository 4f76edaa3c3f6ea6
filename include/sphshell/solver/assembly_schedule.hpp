#pragma once
// The order of the internal-force assembler's interleaved pass
// (solver/internal_forces.hpp): which points integrate together, and where
// each particle's force sum can follow them.
//
// The points integrate in runs of consecutive rows of one group; the two
// groups' runs alternate in proportion to their sizes, so that the stress
// points and the particle points of one region of the model come together
// (rows of a group are numbered region by region: a structured grid's rows,
// or a mesh's element order). A particle's sum needs every point that refers
// to it; it is formed right after the run that completes them. The runs are
// cut into segments of about equal size, one task each: a particle whose
// points all lie in one segment is summed inside it ("completed by" a run).
// One whose points lie in two or more segments ("straddling") belongs to a
// band, the straddling particles of the same first and last segment; each
// segment that holds points of a band reports after the run that completes
// its share of them, and the segment that reports last sums the band there
// and then (InternalForceAssembler keeps the count). Nothing here changes a
// result: each particle's sum keeps its order (IntegrationPoints::force_entries).

#include <sphshell/solver/integration_points.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <utility>
#include <vector>

namespace sphshell::solver {

// The fixed chunks of a sum over the points (the energy books): consecutive
// rows of one group, PointChunks::rows at most, the stress points' chunks
// first. Each chunk is added in row order, then the chunks'
// sums in chunk order (InternalForceAssembler::sum_over_points): the chunks
// depend only on the groups' sizes, so the sum is the same for any thread count.
class PointChunks {
 public:
  static constexpr std::size_t rows = 64;

  template <class Approx>
  explicit PointChunks(const IntegrationPoints<Approx>& points)
      : stress_chunks_(chunks_of(points.count(PointGroup::stress_points))),
        count_(stress_chunks_ + chunks_of(points.count(PointGroup::particles))) {}

  std::size_t count() const { return count_; }
  // Chunk c's group and first row (its rows end at the next chunk's first row or the group's end).
  PointGroup group(std::size_t c) const { return c < stress_chunks_ ? PointGroup::stress_points : PointGroup::particles; }
  std::size_t first_row(std::size_t c) const { return (c < stress_chunks_ ? c : c - stress_chunks_) * rows; }
  // The chunk that holds a group's row.
  std::size_t chunk_of(PointGroup g, std::size_t row) const {
    return (g == PointGroup::stress_points ? 0 : stress_chunks_) + row / rows;
  }

 private:
  static std::size_t chunks_of(std::size_t group_rows) { return (group_rows + rows - 1) / rows; }
  std::size_t stress_chunks_, count_;
};

class AssemblySchedule {
 public:
  // Rows of one group integrated before the other group's turn, at most. One
  // row at a time (the groups strictly alternating) made the point updates
  // slower than two separate passes. Longer runs let the hardware prefetchers
  // follow each group's arrays through memory: once the model outgrows the
  // cache (a 401×401 plate), runs of 512 rows took about 0.92 of the time per
  // step of runs of 64; runs of 4096 were slower again, the particles' sums
  // waiting too long for their points (docs/performance.md).
  static constexpr std::size_t max_rows_per_run = 512;
  // Runs per segment, at least, when several threads share the pass, so that
  // the segments can be cut to about equal sizes; but never shorter than 64
  // rows, the length of the earlier thread measurements (docs/performance.md).
  static constexpr std::size_t min_runs_per_segment = 8;
  static constexpr std::size_t min_rows_per_run = 64;
  // Segments per thread when several threads share the pass. More segments
  // let a thread that is ahead take over more of a held-back thread's share,
  // but more particles straddle two of them. While the straddling particles
  // were summed after the pass, away from the cache that held their points,
  // two per thread measured best (eight: 94 % of the paper's plate straddled).
  // Summed in bands (band()), mostly right after their points on the thread
  // that integrated them, eight per thread took about 0.93 of the time of two
  // summed after the pass, four about 0.95 (docs/performance.md).
  static constexpr std::size_t segments_per_thread = 8;
  // Every run starts at a multiple of PointChunks::rows, so each chunk of a
  // sum over the points lies in one run and is summed by the thread that
  // integrated its points.
  static_assert(min_rows_per_run % PointChunks::rows == 0 && max_rows_per_run % PointChunks::rows == 0,
                "AssemblySchedule: a run's length must be a whole number of PointChunks");

  struct Run {
    PointGroup group;
    std::size_t first_row, end_row;
  };

  // Rebuilds the schedule when the points' force entries, the particle count
  // or the segment count changed since the last call.
  template <class Approx>
  void update(const IntegrationPoints<Approx>& points, std::size_t particle_count, std::size_t segments) {
    if (points.force_entries_stamp() == stamp_ && particle_count == particle_count_ && segments == segment_count_)
      return;
    stamp_ = points.force_entries_stamp();
    particle_count_ = particle_count;
    segment_count_ = segments;
    build_runs(points);
    cut_segments(points.size());
    order_sums(points);
  }

  // Whether the schedule was built for these points' current force entries and this segment count.
  template <class Approx>
  bool is_current(const IntegrationPoints<Approx>& points, std::size_t segments) const {
    return stamp_ != 0 && points.force_entries_stamp() == stamp_ && segments == segment_count_;
  }

  std::size_t segments() const { return segment_count_; }
  std::size_t first_run(std::size_t segment) const { return segment_first_run_[segment]; }
  std::size_t end_run(std::size_t segment) const { return segment_first_run_[segment + 1]; }
  const Run& run(std::size_t r) const { return runs_[r]; }

  // A stretch of one of the schedule's index arrays (particles or bands).
  struct Indices {
    const std::uint32_t *first, *last;
    const std::uint32_t* begin() const { return first; }
    const std::uint32_t* end() const { return last; }
  };
  // The particles whose sums the run completes (within its segment), by index.
  Indices completed_by(std::size_t r) const {
    return {sum_order_.data() + run_sum_begin_[r], sum_order_.data() + run_sum_begin_[r + 1]};
  }
  // The bands of straddling particles: band b's particles by index, and how
  // many segments report for it (at least two).
  std::size_t band_count() const { return band_parts_.size(); }
  Indices band(std::size_t b) const {
    return {band_particles_.data() + band_begin_[b], band_particles_.data() + band_begin_[b + 1]};
  }
  std::uint32_t band_parts(std::size_t b) const { return band_parts_[b]; }
  // The bands for which run r's segment reports after run r.
  Indices bands_after(std::size_t r) const {
    return {run_bands_.data() + run_band_begin_[r], run_bands_.data() + run_band_begin_[r + 1]};
  }
  // Every straddling particle, by index (the bands' particles, band by band).
  const std::vector<std::uint32_t>& straddling() const { return band_particles_; }

 private:
  // Runs in the order they integrate, and each group's runs by first row.
  template <class Approx>
  void build_runs(const IntegrationPoints<Approx>& points) {
    runs_.clear();
    for (std::vector<std::size_t>& first_rows : group_run_first_row_) first_rows.clear();
    for (std::vector<std::uint32_t>& index : group_run_index_) index.clear();
    const std::size_t count[2] = {points.count(PointGroup::stress_points), points.count(PointGroup::particles)};
    // A whole number of PointChunks.
    const std::size_t rows_per_run =
        segment_count_ == 1
            ? max_rows_per_run
            : std::clamp(points.size() / (segment_count_ * min_runs_per_segment), min_rows_per_run, max_rows_per_run) /
                  PointChunks::rows * PointChunks::rows;
    std::size_t next[2] = {0, 0};
    while (next[0] < count[0] || next[1] < count[1]) {
      // The group less far through its rows goes next (next/count compared
      // without division).
      const std::size_t g = next[1] >= count[1]   ? 0
                            : next[0] >= count[0] ? 1
                            : next[0] * count[1] <= next[1] * count[0] ? 0
                                                                       : 1;
      const std::size_t end = std::min(count[g], next[g] + rows_per_run);
      group_run_first_row_[g].push_back(next[g]);
      group_run_index_[g].push_back(static_cast<std::uint32_t>(runs_.size()));
      runs_.push_back(Run{point_groups[g], next[g], end});
      next[g] = end;
    }
  }

  // The run of a point (a search among its group's runs: no array per point).
  template <class Approx>
  std::uint32_t run_of(const IntegrationPoints<Approx>& points, std::size_t point) const {
    const std::size_t g = index_of(points.group_of(point)), row = points.row_of(point);
    const std::vector<std::size_t>& first_rows = group_run_first_row_[g];
    const auto after = std::upper_bound(first_rows.begin(), first_rows.end(), row);
    return group_run_index_[g][std::size_t(after - first_rows.begin()) - 1];
  }

  // Segment s starts at the first run that begins at or past s/segments of
  // the points.
  void cut_segments(std::size_t point_count) {
    segment_first_run_.assign(segment_count_ + 1, runs_.size());
    segment_first_run_[0] = 0;
    std::size_t segment = 1, done = 0;
    for (std::size_t r = 0; r < runs_.size(); ++r) {
      while (segment < segment_count_ && done * segment_count_ >= segment * point_count)
        segment_first_run_[segment++] = r;
      done += runs_[r].end_row - runs_[r].first_row;
    }
    segment_of_run_.resize(runs_.size());
    for (std::size_t s = 0; s < segment_count_; ++s)
      for (std::size_t r = segment_first_run_[s]; r < segment_first_run_[s + 1]; ++r) segment_of_run_[r] = s;
  }

  // Each particle after the last run among its points, if they all lie in
  // one segment, and in a band otherwise; one that no point refers to (its sum
  // is zero) after the first run.
  // (Two passes over the entries, counting and then placing, so that the
  // build keeps no array per particle besides the order itself.)
  template <class Approx>
  void order_sums(const IntegrationPoints<Approx>& points) {
    constexpr std::uint32_t straddles = std::numeric_limits<std::uint32_t>::max();
    const std::vector<std::size_t>& begin = points.particle_slot_begin();
    const auto& entries = points.force_entries();
    // The run that completes particle i's points, or `straddles`.
    const auto completing_run = [&](std::size_t i) {
      if (begin[i] == begin[i + 1]) return std::uint32_t{0};
      std::uint32_t first = straddles, last = 0;
      for (std::size_t k = begin[i]; k < begin[i + 1]; ++k) {
        const std::uint32_t run = run_of(points, entries[k].point);
        first = std::min(first, run);
        last = std::max(last, run);
      }
      return segment_of_run_[first] == segment_of_run_[last] ? last : straddles;
    };
    run_sum_begin_.assign(runs_.size() + 1, 0);
    std::size_t straddling = 0;
    for (std::size_t i = 0; i < particle_count_; ++i) {
      const std::uint32_t run = completing_run(i);
      if (run == straddles)
        ++straddling;
      else
        ++run_sum_begin_[std::size_t(run) + 1];
    }
    for (std::size_t r = 0; r < runs_.size(); ++r) run_sum_begin_[r + 1] += run_sum_begin_[r];
    std::vector<std::uint32_t>(run_sum_begin_.back()).swap(sum_order_);
    std::vector<std::uint32_t> straddling_particles;
    straddling_particles.reserve(straddling);
    std::vector<std::size_t> next(run_sum_begin_.begin(), run_sum_begin_.end() - 1);
    for (std::size_t i = 0; i < particle_count_; ++i) {
      const std::uint32_t run = completing_run(i);
      if (run == straddles)
        straddling_particles.push_back(static_cast<std::uint32_t>(i));
      else
        sum_order_[next[run]++] = static_cast<std::uint32_t>(i);
    }
    form_bands(points, straddling_particles);
  }

  // The bands of the straddling particles, and in each segment that holds
  // points of a band the run after which it reports (the last run there
  // among the band's points).
  template <class Approx>
  void form_bands(const IntegrationPoints<Approx>& points, const std::vector<std::uint32_t>& straddling) {
    const std::vector<std::size_t>& begin = points.particle_slot_begin();
    const auto& entries = points.force_entries();
    std::map<std::pair<std::size_t, std::size_t>, std::uint32_t> band_of_range;  // (first, last segment) → band
    std::map<std::pair<std::uint32_t, std::size_t>, std::uint32_t> report_run;  // (band, segment) → run
    std::vector<std::uint32_t> band_of(straddling.size());
    for (std::size_t k = 0; k < straddling.size(); ++k) {
      const std::size_t i = straddling[k];
      std::size_t first = segment_count_, last = 0;
      for (std::size_t e = begin[i]; e < begin[i + 1]; ++e) {
        const std::size_t segment = segment_of_run_[run_of(points, entries[e].point)];
        first = std::min(first, segment);
        last = std::max(last, segment);
      }
      const auto band = band_of_range.emplace(std::make_pair(first, last), std::uint32_t(band_of_range.size()));
      band_of[k] = band.first->second;
      for (std::size_t e = begin[i]; e < begin[i + 1]; ++e) {
        const std::uint32_t run = run_of(points, entries[e].point);
        std::uint32_t& report = report_run.emplace(std::make_pair(band_of[k], segment_of_run_[run]), run).first->second;
        report = std::max(report, run);
      }
    }
    const std::size_t bands = band_of_range.size();
    band_begin_.assign(bands + 1, 0);
    for (const std::uint32_t band : band_of) ++band_begin_[band + 1];
    for (std::size_t b = 0; b < bands; ++b) band_begin_[b + 1] += band_begin_[b];
    band_particles_.resize(straddling.size());
    std::vector<std::size_t> next(band_begin_.begin(), band_begin_.end() - 1);
    for (std::size_t k = 0; k < straddling.size(); ++k) band_particles_[next[band_of[k]]++] = straddling[k];
    band_parts_.assign(bands, 0);
    run_band_begin_.assign(runs_.size() + 1, 0);
    for (const auto& [band_and_segment, run] : report_run) {
      ++band_parts_[band_and_segment.first];
      ++run_band_begin_[std::size_t(run) + 1];
    }
    for (std::size_t r = 0; r < runs_.size(); ++r) run_band_begin_[r + 1] += run_band_begin_[r];
    run_bands_.resize(report_run.size());
    std::vector<std::size_t> next_report(run_band_begin_.begin(), run_band_begin_.end() - 1);
    for (const auto& [band_and_segment, run] : report_run) run_bands_[next_report[run]++] = band_and_segment.first;
  }

  std::uint64_t stamp_ = 0;  // IntegrationPoints::force_entries_stamp() of the last build (0: none)
  std::size_t particle_count_ = 0, segment_count_ = 0;
  std::vector<Run> runs_;
  std::array<std::vector<std::size_t>, 2> group_run_first_row_;  // per group: its runs' first rows, ascending
  std::array<std::vector<std::uint32_t>, 2> group_run_index_;     // and those runs' indices in runs_
  std::vector<std::size_t> segment_first_run_;  // size segments + 1
  std::vector<std::size_t> segment_of_run_;
  std::vector<std::size_t> run_sum_begin_;  // size runs + 1: completed_by(r) is sum_order_[r's range]
  std::vector<std::uint32_t> sum_order_;
  std::vector<std::size_t> band_begin_;        // size bands + 1: band(b) is band_particles_[b's range]
  std::vector<std::uint32_t> band_particles_;  // the straddling particles, band by band
  std::vector<std::uint32_t> band_parts_;      // per band: the segments that report
  std::vector<std::size_t> run_band_begin_;    // size runs + 1: bands_after(r) is run_bands_[r's range]
  std::vector<std::uint32_t> run_bands_;
};

}  // namespace sphshell::solver
