#pragma once
// The integration points of the shell and what is fixed about them: the two
// groups (stress points and particles), their shape functions and tangent
// frames, integration weights, reference surface gradients, the stress
// points' edge-tied shear (solver/tied_shear.hpp) and the slot transpose
// (which shape-function slots refer to each particle, solver/slot_transpose.hpp).
// Built once in the reference configuration (total Lagrangian); only a crack
// changes rows, through rebuild_row.
//
// Points are numbered across both groups: the stress points first, then the
// particle points, so per-point arrays elsewhere (section states, work) use one
// index p = offset(group) + row.

#include <sphshell/approx/approx.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/cuts.hpp>
#include <sphshell/shell/kinematics.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/shell/local_spacing.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/solver/particles.hpp>
#include <sphshell/solver/point_group.hpp>
#include <sphshell/solver/slot_transpose.hpp>
#include <sphshell/solver/tied_shear.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace sphshell::solver {

template <class Approx>
class IntegrationPoints {
 public:
  // Shape functions at the stress points and, when the particles integrate
  // (a share or a shear weight > 0), at the particles.
  // The material's shear modulus (the transverse shear) and, for the
  // director hourglass (PhysicsOptions::director_hourglass), its Poisson ratio.
  IntegrationPoints(const ShellModel& model, const PhysicsOptions& physics,
                    const ParticleIntegrationOptions& particle_integration, double shear_modulus,
                    double poisson_ratio = std::numeric_limits<double>::quiet_NaN()) {
    // Each point's support follows its own local spacing (shell/local_spacing.hpp).
    const LocalSpacing spacing = local_spacing(model);
    const bool particles_integrate = particle_integration.particle_integration_share > 0.0 ||
                                     particle_integration.particle_shear_weight > 0.0;
    const auto smoothing = [&](double local) {
      return physics.support_radius_factor * local / Approx::kernel_type::support_radius_factor;
    };
    // Sized up front: grown by push_back they would keep up to twice their
    // size for the solver's life.
    smoothing_length_[0].reserve(spacing.stress_point.size());
    for (double local : spacing.stress_point) smoothing_length_[0].push_back(smoothing(local));
    if (particles_integrate) {
      smoothing_length_[1].reserve(spacing.particle.size());
      for (double local : spacing.particle) smoothing_length_[1].push_back(smoothing(local));
    }
    frames_[0].reserve(model.stress_point_normal.size());
    for (const Vector3& normal : model.stress_point_normal) frames_[0].push_back(tangent_frame(normal));
    frames_[1].reserve(model.particle_normal.size());
    for (const Vector3& normal : model.particle_normal) frames_[1].push_back(tangent_frame(normal));
    // The cut test looks for cut pieces within the largest row support (each
    // row's own support lies within it).
    cuts_ = shell::CutVisibility(model.cut_geometry(), model.cuts(), largest_support_radius());
    shape_[0] = Approx::build(model.particle_position, model.particle_area, model.stress_point_position,
                              frames_[0], smoothing_length_[0], cut_visibility(model, PointGroup::stress_points));
    if (particles_integrate)
      shape_[1] = Approx::build(model.particle_position, model.particle_area, model.particle_position,
                                frames_[1], smoothing_length_[1], cut_visibility(model, PointGroup::particles));

    // A row that fell back to the constant approximation has no gradient: the
    // support is too small for the spacing.
    for (PointGroup group : point_groups)
      for (std::size_t row = 0; row < count(group); ++row)
        if (shape(group).shepard[row])
          detail::invalid_parameter("support_radius_factor", physics.support_radius_factor,
                                    std::string("too few neighbours (fewer than 3) at ") + name_of(group) + " " +
                                        std::to_string(row) + " within its support radius " +
                                        std::to_string(support_radius(group, row)) +
                                        " m (support_radius_factor × its local spacing)");
    const std::size_t stress_points = model.stress_point_count();
    const std::size_t particle_points = particles_integrate ? model.particle_count() : 0;
    offset_ = {0, stress_points};
    keep_reference_ = !physics.nonlinear;
    tied_ = TiedShear(
        model, physics, shape_[0], frames_[0],
        [&](std::size_t row) { return support_radius(PointGroup::stress_points, row); }, shear_modulus,
        poisson_ratio, keep_reference_);
    compute_weights(model, physics, particle_integration, shear_modulus, stress_points, particle_points);
    if (keep_reference_) reference_.resize(size());
    reference_products_.resize(size());
    for (PointGroup group : point_groups)
      for (std::size_t row = 0; row < count(group); ++row)
        set_reference(point(group, row), gather(group, row, model.particle_position, model.particle_normal));
    build_slot_transpose(model.particle_count());
    for (PointGroup group : point_groups) rebuilt_[index_of(group)].assign(count(group), 0);
  }

  // The rows one rank of a distributed run computes (include/sphshell/mpi/):
  // rows[group] lists global rows ascending, local_of maps a global particle
  // to its local index (−1: not on this rank). Every slot of a row's capacity
  // is kept in its place with the neighbour renumbered, and so are the frames,
  // weights, reference gradients and the edge-tied shear (its corners
  // renumbered too), so a local row computes bit for bit what the global one
  // does. A neighbour or tied corner that is not local is an Error.
  IntegrationPoints subset(const std::array<std::vector<std::size_t>, 2>& rows, const std::vector<int>& local_of,
                           std::size_t local_count) const {
    auto local = [&](int global, PointGroup group, std::size_t row) {
      const int j = local_of.at(static_cast<std::size_t>(global));
      if (j < 0)
        detail::invalid_parameter(std::string("particle of ") + name_of(group) + " " + std::to_string(row), global,
                                  "is not local to the subset (its rows need it)");
      return j;
    };
    IntegrationPoints part;
    part.keep_reference_ = keep_reference_;
    for (PointGroup group : point_groups) {
      const std::size_t g = index_of(group);
      const approx::ShapeFunctions& from = shape_[g];
      approx::ShapeFunctions& to = part.shape_[g];
      to.row_begin.push_back(0);
      for (std::size_t row : rows[g]) {
        for (std::size_t s = from.row_begin[row]; s < from.row_begin[row + 1]; ++s) {
          to.neighbour.push_back(local(from.neighbour[s], group, row));
          to.value.push_back(from.value[s]);
        }
        to.row_begin.push_back(to.neighbour.size());
        to.row_size.push_back(from.row_size[row]);
        to.shepard.push_back(from.shepard[row]);
        part.smoothing_length_[g].push_back(smoothing_length_[g][row]);
        part.frames_[g].push_back(frames_[g][row]);
        part.rebuilt_[g].push_back(rebuilt_[g][row]);
      }
      part.global_row_[g] = rows[g];
    }
    part.offset_ = {0, rows[0].size()};
    for (PointGroup group : point_groups)
      for (std::size_t row : rows[index_of(group)]) {
        const std::size_t p = point(group, row);
        part.membrane_bending_weight_.push_back(membrane_bending_weight_[p]);
        part.shear_weight_.push_back(shear_weight_[p]);
        if (keep_reference_) part.reference_.push_back(reference_[p]);
        part.reference_products_.push_back(reference_products_[p]);
      }
    part.tied_ =
        tied_.subset(rows[0], [&](int global, std::size_t row) { return local(global, PointGroup::stress_points, row); });
    part.build_slot_transpose(local_count);
    return part;
  }
  // A subset's row set to a row of the whole model's points after a crack
  // rebuilt it there (rebuilds sort by global particle index, so they run on
  // the whole model's rows): every slot, the reference gradients and the flag,
  // neighbours renumbered by local_of. The capacities must agree.
  void copy_row(PointGroup group, std::size_t row, const IntegrationPoints& from, std::size_t from_row,
                const std::vector<int>& local_of) {
    const std::size_t g = index_of(group);
    approx::ShapeFunctions& to = shape_[g];
    const approx::ShapeFunctions& source = from.shape_[g];
    if (to.capacity(row) != source.capacity(from_row))
      detail::invalid_parameter(std::string("capacity of ") + name_of(group) + " row " + std::to_string(from_row),
                                to.capacity(row), "must equal the source row's " + std::to_string(source.capacity(from_row)));
    for (std::size_t k = 0; k < to.capacity(row); ++k) {
      const std::size_t s = to.row_begin[row] + k, t = source.row_begin[from_row] + k;
      to.neighbour[s] = local_of.at(static_cast<std::size_t>(source.neighbour[t]));
      if (to.neighbour[s] < 0)
        detail::invalid_parameter(std::string("particle of ") + name_of(group) + " row " + std::to_string(from_row),
                                  source.neighbour[t], "is not local to the subset (its rows need it)");
      to.value[s] = source.value[t];
    }
    to.row_size[row] = source.row_size[from_row];
    to.shepard[row] = source.shepard[from_row];
    check_tied_corners(group, row);
    if (keep_reference_) reference_[point(group, row)] = from.reference_[from.point(group, from_row)];
    reference_products_[point(group, row)] = from.reference_products_[from.point(group, from_row)];
    mark_rebuilt(group, row);
  }

  // The row of the whole model a row stands for (itself but in a subset).
  std::size_t global_row(PointGroup group, std::size_t row) const {
    const std::vector<std::size_t>& rows = global_row_[index_of(group)];
    return rows.empty() ? row : rows[row];
  }

  // Points of a group, all points, and the global index of a group's row.
  std::size_t count(PointGroup group) const { return shape(group).rows(); }
  std::size_t size() const { return count(PointGroup::stress_points) + count(PointGroup::particles); }
  std::size_t point(PointGroup group, std::size_t row) const { return offset_[index_of(group)] + row; }
  PointGroup group_of(std::size_t p) const {
    return p < offset_[1] ? PointGroup::stress_points : PointGroup::particles;
  }
  std::size_t row_of(std::size_t p) const { return p - offset_[index_of(group_of(p))]; }

  const approx::ShapeFunctions& shape(PointGroup group) const { return shape_[index_of(group)]; }
  const TangentFrame& frame(PointGroup group, std::size_t row) const { return frames_[index_of(group)][row]; }
  // Reference positions of a group's evaluation points.
  static const std::vector<Vector3>& positions(const ShellModel& model, PointGroup group) {
    return group == PointGroup::stress_points ? model.stress_point_position : model.particle_position;
  }
  // A row's own smoothing length h_i and support radius (kernel factor × h_i),
  // and the largest support radius of all rows.
  double smoothing_length(PointGroup group, std::size_t row) const {
    return smoothing_length_[index_of(group)][row];
  }
  double support_radius(PointGroup group, std::size_t row) const {
    return smoothing_length(group, row) * Approx::kernel_type::support_radius_factor;
  }
  double largest_support_radius() const {
    double largest = 0.0;
    for (const std::vector<double>& lengths : smoothing_length_)
      for (double h : lengths) largest = std::max(largest, h);
    return largest * Approx::kernel_type::support_radius_factor;
  }
  // The model's cuts, as the rows see them.
  const shell::CutVisibility& cuts() const { return cuts_; }

  // Weights: the area share for membrane and bending; area × κs G d (softened
  // at particles) for transverse shear.
  double membrane_bending_weight(std::size_t p) const { return membrane_bending_weight_[p]; }
  double shear_weight(std::size_t p) const { return shear_weight_[p]; }
  // The edge-tied shear of a stress point's cell (solver/tied_shear.hpp).
  bool shear_tied(PointGroup group, std::size_t row) const {
    return group == PointGroup::stress_points && tied_.tied(row);
  }
  const shell::CellShearTie& shear_tying(std::size_t row) const { return tied_.tying(row); }
  const shell::CellHourglass* hourglass(std::size_t row) const { return tied_.hourglass(row); }
  const shell::CellShearEdges* shear_edges(std::size_t row) const { return tied_.edges(row); }
  bool tied_corners_visible(std::size_t row) const { return tied_.corners_visible(row); }
  // Kept for the linear analysis only (the nonlinear one needs only its
  // products below): 120 bytes a point.
  const shell::SurfaceGradients& reference(std::size_t p) const { return reference_[p]; }
  // Its dot products in the Green strains (shell::green_strains).
  const shell::ReferenceProducts& reference_products(std::size_t p) const { return reference_products_[p]; }

  // Interpolated a1, a2, n, n1, n2 of one row from particle positions x and directors d.
  shell::SurfaceGradients gather(PointGroup group, std::size_t row, const std::vector<Vector3>& x,
                                 const std::vector<Vector3>& d) const {
    const approx::ShapeFunctions& sf = shape(group);
    shell::SurfaceGradients g;
    const std::size_t end = sf.row_begin[row] + sf.row_size[row];
    for (std::size_t s = sf.row_begin[row]; s < end; ++s) {
      const int j = sf.neighbour[s];
      const approx::ShapeValue& v = sf.value[s];
      g.a1 += v.dphi_d1 * x[j];
      g.a2 += v.dphi_d2 * x[j];
      g.n += v.phi * d[j];
      g.n1 += v.dphi_d1 * d[j];
      g.n2 += v.dphi_d2 * d[j];
    }
    return g;
  }

  // The same from the packed positions and directors (solver/particles.hpp):
  // the step's hot gather. The sums are kept in locals, not in the returned
  // structure, and the arrays are read through local pointers: a store into
  // the result might alias the arrays for all the compiler knows, so it would
  // write the sums back and reload every array's address at every slot. A
  // neighbour's position and director are read as one 6-vector, so that each
  // of ∂Φ/∂X1, ∂Φ/∂X2 scales both at once (a1 with n1, a2 with n2): three
  // SSE2 pairs instead of a pair and a single for each 3-vector, 4-6 % of the
  // paper plate's step (docs/performance.md). Every component's sum is the
  // same, in the same order.
  shell::SurfaceGradients gather(PointGroup group, std::size_t row, const std::vector<PackedKinematics>& packed) const {
    const approx::ShapeFunctions& sf = shape(group);
    const int* const neighbour = sf.neighbour.data();
    const approx::ShapeValue* const value = sf.value.data();
    const PackedKinematics* const particles = packed.data();
    using Packed6 = Eigen::Matrix<double, 6, 1>;
    Packed6 d1_sum = Packed6::Zero(), d2_sum = Packed6::Zero();
    Vector3 n = Vector3::Zero();
    const std::size_t end = sf.row_begin[row] + sf.row_size[row];
    for (std::size_t s = sf.row_begin[row]; s < end; ++s) {
      const Eigen::Map<const Packed6, Eigen::Unaligned> particle(particles[std::size_t(neighbour[s])].position.data());
      const double phi = value[s].phi, dphi_d1 = value[s].dphi_d1, dphi_d2 = value[s].dphi_d2;
      d1_sum += dphi_d1 * particle;
      d2_sum += dphi_d2 * particle;
      n += phi * particle.template tail<3>();
    }
    shell::SurfaceGradients g;
    g.a1 = d1_sum.head<3>();
    g.a2 = d2_sum.head<3>();
    g.n = n;
    g.n1 = d1_sum.tail<3>();
    g.n2 = d2_sum.tail<3>();
    return g;
  }

  // Recomputes one row with a visibility predicate visible(row, particle)
  // (after a crack), and its reference gradients; the model's cuts keep
  // hiding what they hide. Throws Error when nothing stays visible.
  template <class Visible>
  void rebuild_row(const ShellModel& model, PointGroup group, std::size_t row, Visible&& visible) {
    // Flagged first: a rebuild that throws (nothing visible) leaves its row
    // changed too, and no corner of its tied cell counted as visible.
    mark_rebuilt(group, row);
    if (group == PointGroup::stress_points) tied_.hide_corners(row);
    const auto cut_visible = cut_visibility(model, group);
    const auto both = [&](std::size_t r, std::size_t j) { return cut_visible(r, j) && visible(r, j); };
    Approx::rebuild_row(shape_[index_of(group)], row, model.particle_position, model.particle_area,
                        positions(model, group)[row], frame(group, row), smoothing_length(group, row), both);
    check_tied_corners(group, row);
    set_reference(point(group, row), gather(group, row, model.particle_position, model.particle_normal));
  }

  // Checkpoints (solver/checkpoint.hpp): the rows cracks rebuilt, whole (all
  // their slots, the hidden ones too, which later rebuilds start from) with
  // their reference gradients. Every other row is as the constructor built it
  // from the model, which is deterministic. The slot transpose is rebuilt.
  // A nonlinear analysis keeps no reference gradients: a rebuilt row's are
  // gathered again from the particles' reference positions and normals
  // (numbered as the rows' neighbours are: the model's, or a subset's local
  // particles), the same sums rebuild_row formed.
  template <class Writer>
  void save(Writer& out, const std::vector<Vector3>& reference_positions,
            const std::vector<Vector3>& reference_normals) const {
    for (PointGroup group : point_groups) {
      const std::vector<unsigned char>& rebuilt = rebuilt_[index_of(group)];
      const approx::ShapeFunctions& sf = shape(group);
      std::vector<std::uint64_t> rows;
      for (std::size_t row = 0; row < rebuilt.size(); ++row)
        if (rebuilt[row]) rows.push_back(row);
      out(rows);
      for (const std::uint64_t row : rows) {
        const std::size_t begin = sf.row_begin[row], end = sf.row_begin[row + 1];
        out(static_cast<std::uint64_t>(end - begin), sf.row_size[row], sf.shepard[row]);
        for (std::size_t s = begin; s < end; ++s) out(sf.neighbour[s], sf.value[s].phi, sf.value[s].dphi_d1, sf.value[s].dphi_d2);
        const shell::SurfaceGradients g = keep_reference_ ? reference_[point(group, row)]
                                                          : gather(group, row, reference_positions,
                                                                   reference_normals);
        out(g.a1, g.a2, g.n, g.n1, g.n2);
      }
    }
  }
  // Whether a crack changed any row since construction (a solver loading a
  // checkpoint then starts again from freshly built rows).
  bool any_rebuilt() const {
    for (const std::vector<unsigned char>& rebuilt : rebuilt_)
      for (const unsigned char flag : rebuilt)
        if (flag) return true;
    return false;
  }
  // Into freshly built rows (any_rebuilt() false).
  template <class Reader>
  void load(Reader& in, std::size_t particle_count) {
    for (PointGroup group : point_groups) {
      approx::ShapeFunctions& sf = shape_[index_of(group)];
      std::vector<unsigned char>& rebuilt = rebuilt_[index_of(group)];
      rebuilt.assign(sf.rows(), 0);
      std::vector<std::uint64_t> rows;
      in(rows);
      for (const std::uint64_t row : rows) {
        if (row >= sf.rows())
          in.fail(std::string("rebuilt ") + name_of(group) + " row " + std::to_string(row) + " out of range");
        std::uint64_t capacity = 0;
        in(capacity);
        if (capacity != sf.capacity(row))
          in.fail(std::string(name_of(group)) + " row " + std::to_string(row) + " has " + std::to_string(capacity) +
                  " slots there and " + std::to_string(sf.capacity(row)) + " here");
        // Flagged before it changes: a load that fails inside the row leaves
        // it to be rebuilt by the next load. Each value is checked before it
        // is stored, so a failed load leaves no index out of range.
        rebuilt[row] = 1;
        int row_size = 0;
        unsigned char shepard = 0;
        in(row_size, shepard);
        if (row_size < 0 || static_cast<std::size_t>(row_size) > capacity)
          in.fail(std::string(name_of(group)) + " row " + std::to_string(row) + " uses more slots than it has");
        sf.row_size[row] = row_size;
        sf.shepard[row] = shepard;
        for (std::size_t s = sf.row_begin[row]; s < sf.row_begin[row + 1]; ++s) {
          int neighbour = 0;
          approx::ShapeValue value;
          in(neighbour, value.phi, value.dphi_d1, value.dphi_d2);
          if (neighbour < 0 || static_cast<std::size_t>(neighbour) >= particle_count)
            in.fail(std::string(name_of(group)) + " row " + std::to_string(row) + " names particle " +
                    std::to_string(neighbour));
          sf.neighbour[s] = neighbour;
          sf.value[s] = value;
        }
        check_tied_corners(group, row);
        shell::SurfaceGradients g;
        in(g.a1, g.a2, g.n, g.n1, g.n2);
        set_reference(point(group, row), g);
      }
    }
    build_slot_transpose(particle_count);
  }

  // Slots: every (row, neighbour) entry of both groups, and their transpose
  // by particle (solver/slot_transpose.hpp), which a crack's rebuilt rows
  // need built again.
  std::size_t slot_count() const { return shape_[0].neighbour.size() + shape_[1].neighbour.size(); }
  using ForceEntry = solver::ForceEntry;
  const std::vector<std::size_t>& particle_slot_begin() const { return slots_.particle_slot_begin(); }
  const std::vector<ForceEntry>& force_entries() const { return slots_.entries(); }
  std::uint64_t force_entries_stamp() const { return slots_.stamp(); }
  std::size_t untied_corner() const { return SlotTranspose::untied_corner(shape_); }
  void build_slot_transpose(std::size_t particle_count) { slots_.build(shape_, offset_, tied_, particle_count); }

 private:
  IntegrationPoints() = default;  // subset() fills it

  void check_tied_corners(PointGroup group, std::size_t row) {
    if (group == PointGroup::stress_points) tied_.check_corners(shape_[0], row);
  }

  void set_reference(std::size_t p, const shell::SurfaceGradients& g) {
    if (keep_reference_) reference_[p] = g;
    reference_products_[p] = shell::reference_products(g);
  }

  // The cuts' visibility predicate of a group's rows (shell/cuts.hpp): a
  // particle evaluation point stands where its particle does in the cut test.
  auto cut_visibility(const ShellModel& model, PointGroup group) const {
    return [this, &model, group](std::size_t row, std::size_t j) {
      if (cuts_.empty()) return true;
      const Vector3& x = group == PointGroup::particles ? cuts_.side_point(row) : model.stress_point_position[row];
      return cuts_.visible(x, cuts_.side_point(j), frame(group, row));
    };
  }

  // Rows are rebuilt in parallel: each sets its own flag, in an array sized
  // by the constructor (never resized here).
  void mark_rebuilt(PointGroup group, std::size_t row) { rebuilt_[index_of(group)][row] = 1; }

  void compute_weights(const ShellModel& model, const PhysicsOptions& physics,
                       const ParticleIntegrationOptions& particle_integration, double shear_modulus,
                       std::size_t stress_points, std::size_t particle_points) {
    const double share = particle_integration.particle_integration_share;
    membrane_bending_weight_.resize(stress_points + particle_points);
    shear_weight_.resize(stress_points + particle_points);
    for (std::size_t p = 0; p < stress_points; ++p) {
      const double d = model.stress_point_thickness(p);
      membrane_bending_weight_[p] = (1.0 - share) * model.stress_point_area[p];
      // A tied point's shear is the cell's (shear_tying); none from the shape functions.
      shear_weight_[p] = shear_tied(PointGroup::stress_points, p)
                             ? 0.0
                             : model.stress_point_area[p] * physics.shear_correction * shear_modulus * d;
    }
    // The particles' shear term is softened by d² / (d² + s Δ²) with the local
    // spacing Δ = √A (docs/method.md, "Quadrature and the particle share").
    for (std::size_t i = 0; i < particle_points; ++i) {
      const double d = model.particle_thickness(i);
      const double shear_stiffness = physics.shear_correction * shear_modulus * d;
      const double local_spacing = std::sqrt(model.particle_area[i]);
      const double softening =
          d * d / (d * d + particle_integration.particle_shear_softening * local_spacing * local_spacing);
      membrane_bending_weight_[stress_points + i] = share * model.particle_area[i];
      shear_weight_[stress_points + i] =
          particle_integration.particle_shear_weight * model.particle_area[i] * shear_stiffness * softening;
    }
  }

  std::array<std::vector<double>, 2> smoothing_length_;  // h_i per row of each group
  shell::CutVisibility cuts_;  // the model's cuts
  TiedShear tied_;  // the stress points' edge-tied shear
  std::array<approx::ShapeFunctions, 2> shape_;
  std::array<std::vector<TangentFrame>, 2> frames_;  // evaluation frames, kept for rebuilds
  std::array<std::size_t, 2> offset_{};
  std::vector<double> membrane_bending_weight_, shear_weight_;
  bool keep_reference_ = true;  // a linear analysis: its reference gradients and tied edges are kept
  std::vector<shell::SurfaceGradients> reference_;  // per point when keep_reference_, else empty
  std::vector<shell::ReferenceProducts> reference_products_;
  SlotTranspose slots_;
  std::array<std::vector<unsigned char>, 2> rebuilt_;  // per row: changed by a crack since construction
  std::array<std::vector<std::size_t>, 2> global_row_;  // a subset's global rows (empty: the whole model)
};

}  // namespace sphshell::solver
