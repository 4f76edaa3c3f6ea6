#pragma once
// The slot transpose of the integration points (solver/integration_points.hpp):
// which shape-function slots refer to each particle, so the force gather is a
// deterministic per-particle sum (no atomic additions, identical results for
// any thread count). Rows keep their capacity when cracks shrink them, so the
// slot numbering stays; only the map is rebuilt.

#include <sphshell/approx/approx.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/shell/cell_shear.hpp>
#include <sphshell/solver/point_group.hpp>
#include <sphshell/solver/tied_shear.hpp>

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sphshell::solver {

// A used slot with what a particle needs to add its force from the point's
// conjugate forces (InternalForceAssembler): the point, the slot in its
// group's shape functions (whose Φ, ∇Φ it reads there: a copy of them here
// would cost 24 bytes a slot), and which corner of the point's edge-tied cell
// the particle is, as the index row × max_cell_corners + corner of the tied
// corner forces the assembler keeps per stress point (untied_corner when it
// is none: an index past them).
struct ForceEntry {
  std::uint32_t point;
  std::uint32_t tied_corner;
  std::uint32_t slot;
};

class SlotTranspose {
 public:
  // The used slots of both groups' rows (`shape`, the points of group g
  // numbered from offset[g]) by the particle they refer to.
  void build(const std::array<approx::ShapeFunctions, 2>& shape, const std::array<std::size_t, 2>& offset,
             const TiedShear& tied, std::size_t particle_count) {
    // The entries' 32-bit indices: points (× max_cell_corners for the tied
    // corners) and each group's slots.
    constexpr std::size_t index_limit = std::size_t(UINT32_MAX);
    const std::size_t points = shape[0].rows() + shape[1].rows();
    if (points >= index_limit / shell::max_cell_corners)
      detail::invalid_parameter("integration point count", points, "must stay below 2³⁰ (32-bit force entries)");
    for (PointGroup group : point_groups)
      if (shape[index_of(group)].slots() >= index_limit)
        detail::invalid_parameter(std::string(name_of(group)) + " shape-function slot count",
                                  shape[index_of(group)].slots(), "must stay below 2³² (32-bit force entries)");
    std::vector<std::size_t> count_of(particle_count + 1, 0);
    for (const approx::ShapeFunctions& sf : shape)
      for (std::size_t row = 0; row < sf.rows(); ++row)
        for (std::size_t s = sf.row_begin[row]; s < sf.row_begin[row] + sf.row_size[row]; ++s)
          ++count_of[std::size_t(sf.neighbour[s]) + 1];
    for (std::size_t i = 1; i < count_of.size(); ++i) count_of[i] += count_of[i - 1];
    particle_slot_begin_ = count_of;
    // Exactly sized: a rebuilt transpose (a checkpoint load) must not keep a
    // larger one's capacity.
    std::vector<ForceEntry>(count_of.back()).swap(entries_);
    static std::atomic<std::uint64_t> next_stamp{1};
    stamp_ = next_stamp.fetch_add(1, std::memory_order_relaxed);
    const std::size_t untied = untied_corner(shape);
    for (PointGroup group : point_groups) {
      const approx::ShapeFunctions& sf = shape[index_of(group)];
      for (std::size_t row = 0; row < sf.rows(); ++row) {
        const bool is_tied = group == PointGroup::stress_points && tied.tied(row);
        for (std::size_t s = sf.row_begin[row]; s < sf.row_begin[row] + sf.row_size[row]; ++s) {
          const int particle = sf.neighbour[s];
          std::size_t tied_corner = untied;
          for (int k = 0; is_tied && k < tied.tying(row).corners; ++k)
            if (tied.tying(row).particle[std::size_t(k)] == particle)
              tied_corner = row * shell::max_cell_corners + std::size_t(k);
          const std::size_t k = count_of[particle]++;
          entries_[k] = ForceEntry{static_cast<std::uint32_t>(offset[index_of(group)] + row),
                                   static_cast<std::uint32_t>(tied_corner), static_cast<std::uint32_t>(s)};
        }
      }
    }
  }

  // The used slots referring to particle i are entries()[k] for k in
  // [particle_slot_begin()[i], particle_slot_begin()[i + 1]): the stress
  // points' rows first, then the particles', rows and slots ascending.
  // Contiguous per particle, so the per-particle sum streams through them;
  // the slots of one particle lie in rows near each other.
  const std::vector<std::size_t>& particle_slot_begin() const { return particle_slot_begin_; }
  const std::vector<ForceEntry>& entries() const { return entries_; }
  // Changes whenever the entries are rebuilt (a stamp unique in the process,
  // so that one kept for another transpose never matches), for what is
  // derived from them (the assembler's schedule).
  std::uint64_t stamp() const { return stamp_; }
  // The tied_corner of a slot whose particle is no tied corner: past every
  // stress point's corners.
  static std::size_t untied_corner(const std::array<approx::ShapeFunctions, 2>& shape) {
    return shape[0].rows() * shell::max_cell_corners;
  }

 private:
  std::vector<std::size_t> particle_slot_begin_;
  std::vector<ForceEntry> entries_;  // per particle, from particle_slot_begin_
  std::uint64_t stamp_ = 0;
};

}  // namespace sphshell::solver
