#pragma once
// Linear static solution of a flat plate (in the x–y plane, normals +z) built
// by ShellModel::rectangular_plate: the bending stiffness (w and the two
// director rotations per particle) is assembled by central differences of the
// solver's internal forces, then K u = f is solved directly. This is the exact
// equilibrium the dynamic relaxation of test_solver_plate converges to, in a
// fraction of its time, so locking studies can run at fine resolutions.
//
// The assembly perturbs many particles at once: a particle's motion changes the
// forces only within two support radii (the points that see it, and the
// particles those points see), so particles on a grid with a stride larger
// than four support radii over the spacing are perturbed together and each
// response is credited to the nearest perturbed particle.

#include <sphshell/core/types.hpp>
#include <sphshell/statics/coupling.hpp>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

namespace sphshell::test_support {

// Which particles are perturbed together.
enum class PerturbationGroups {
  grid_stride,      // every stride-th particle along x and y (PlateGrid::stride)
  coupling_colours  // the colours of the solver's own coupling graph (statics/coupling.hpp)
};

struct PlateGrid {
  int nx, ny;  // particles along x and y (index j * nx + i)
  // Grid steps between particles perturbed together; 0 takes it from the
  // support on a uniform grid. A graded grid, whose supports span more steps
  // where the steps are small, passes its own (max(nx, ny): one at a time)
  // or colours by the coupling graph, which follows each row's own support.
  int stride = 0;
  PerturbationGroups groups = PerturbationGroups::grid_stride;
};

// Per-particle bending dofs: w (m), then rotations (rad) about x and y.
inline constexpr int bending_dofs = 3;

template <class Solver>
Eigen::VectorXd bending_forces(const Solver& solver) {
  const std::size_t n = solver.particle_count();
  Eigen::VectorXd forces(bending_dofs * n);
  for (std::size_t i = 0; i < n; ++i) {
    forces[bending_dofs * i] = solver.internal_forces()[i].z();
    const Vector3 moment = solver.directors()[i].cross(solver.internal_director_forces()[i]);
    forces[bending_dofs * i + 1] = moment.x();
    forces[bending_dofs * i + 2] = moment.y();
  }
  return forces;
}

// The linear (options.nonlinear = false) elastic solver's bending stiffness at
// the reference configuration, step h.
template <class Solver>
Eigen::SparseMatrix<double> assemble_bending_stiffness(Solver& solver, const PlateGrid& grid, double h) {
  const std::vector<Vector3> x0 = solver.positions(), d0 = solver.directors();
  if (grid.groups == PerturbationGroups::coupling_colours) {
    // The static family's coloured central differences over the solver's own
    // rows: w, then the rotations about x and y, per particle.
    using Approx = typename Solver::approximation_type;
    const SolverOptions& options = solver.options();
    const solver::IntegrationPoints<Approx> points(solver.model(), options.physics(), options.particle_integration(),
                                                   solver.material().shear_modulus(),
                                                   solver.material().poisson_ratio());
    const std::size_t count = solver.particle_count();
    std::vector<int> first(count + 1);
    for (std::size_t i = 0; i <= count; ++i) first[i] = bending_dofs * static_cast<int>(i);
    const Eigen::SparseMatrix<double> stiffness = statics::difference_tangent(
        statics::coloured_coupling(points, count), first, [h](int, int) { return h; },
        [&](const std::vector<statics::Perturbation>& perturbations) {
          std::vector<Vector3> x = x0, d = d0;
          for (const statics::Perturbation& m : perturbations) {
            if (m.local == 0)
              x[m.particle].z() += m.amount;
            else
              d[m.particle] =
                  Eigen::AngleAxisd(m.amount, m.local == 1 ? Vector3::UnitX() : Vector3::UnitY()) * d0[m.particle];
          }
          solver.set_configuration(x, d);
          return bending_forces(solver);
        });
    solver.set_configuration(x0, d0);
    Eigen::SparseMatrix<double> transposed = stiffness.transpose();
    return 0.5 * (stiffness + transposed);
  }
  const double spacing = solver.model().maximum_spacing();
  const double reach = 2.0 * solver.options().support_radius_factor * spacing;
  const int stride = grid.stride > 0 ? grid.stride : static_cast<int>(std::ceil(2.0 * reach / spacing)) + 1;
  const int n = static_cast<int>(x0.size());
  std::vector<Eigen::Triplet<double>> entries;
  for (int cy = 0; cy < stride; ++cy)
    for (int cx = 0; cx < stride; ++cx)
      for (int component = 0; component < bending_dofs; ++component) {
        if (cx >= grid.nx || cy >= grid.ny) continue;
        Eigen::VectorXd difference = Eigen::VectorXd::Zero(bending_dofs * n);
        for (double sign : {1.0, -1.0}) {
          std::vector<Vector3> x = x0, d = d0;
          for (int j = cy; j < grid.ny; j += stride)
            for (int i = cx; i < grid.nx; i += stride) {
              const int p = j * grid.nx + i;
              if (component == 0)
                x[p].z() += sign * h;
              else
                d[p] = Eigen::AngleAxisd(sign * h, component == 1 ? Vector3::UnitX() : Vector3::UnitY()) * d0[p];
            }
          solver.set_configuration(x, d);
          difference += sign * bending_forces(solver);
        }
        difference /= 2.0 * h;
        for (int q = 0; q < n; ++q) {
          // The perturbed particle of this colour nearest to q (in grid steps);
          // only it can reach q.
          const auto nearest = [stride](int index, int start, int count) {
            const int last = (count - 1 - start) / stride;
            const int k = static_cast<int>(std::lround(static_cast<double>(index - start) / stride));
            return start + stride * std::min(std::max(k, 0), last);
          };
          const int column = bending_dofs * (nearest(q / grid.nx, cy, grid.ny) * grid.nx +
                                              nearest(q % grid.nx, cx, grid.nx)) +
                             component;
          for (int k = 0; k < bending_dofs; ++k) {
            const double value = difference[bending_dofs * q + k];
            if (value != 0.0) entries.emplace_back(bending_dofs * q + k, column, value);
          }
        }
      }
  solver.set_configuration(x0, d0);
  Eigen::SparseMatrix<double> stiffness(bending_dofs * n, bending_dofs * n);
  stiffness.setFromTriplets(entries.begin(), entries.end());
  Eigen::SparseMatrix<double> transposed = stiffness.transpose();
  return 0.5 * (stiffness + transposed);
}

// w at every particle under a uniform pressure q (force −q A_i along +z) with
// every dof of the `fixed` particles held (a clamp).
template <class Solver>
Eigen::VectorXd clamped_plate_deflection(Solver& solver, const PlateGrid& grid, const std::vector<int>& fixed,
                                         double q, double h) {
  const Eigen::SparseMatrix<double> stiffness = assemble_bending_stiffness(solver, grid, h);
  const int n = static_cast<int>(solver.particle_count());
  std::vector<int> free_index(bending_dofs * n, -1);
  std::vector<char> is_fixed(n, 0);
  for (int i : fixed) is_fixed[i] = 1;
  int free_count = 0;
  for (int i = 0; i < n; ++i)
    if (!is_fixed[i])
      for (int k = 0; k < bending_dofs; ++k) free_index[bending_dofs * i + k] = free_count++;
  std::vector<Eigen::Triplet<double>> entries;
  for (int column = 0; column < stiffness.outerSize(); ++column)
    for (Eigen::SparseMatrix<double>::InnerIterator it(stiffness, column); it; ++it)
      if (free_index[it.row()] >= 0 && free_index[it.col()] >= 0)
        entries.emplace_back(free_index[it.row()], free_index[it.col()], it.value());
  Eigen::SparseMatrix<double> reduced(free_count, free_count);
  reduced.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd load = Eigen::VectorXd::Zero(free_count);
  for (int i = 0; i < n; ++i)
    if (!is_fixed[i]) load[free_index[bending_dofs * i]] = -q * solver.model().particle_area[i];
  // The internal force is +K u, the equilibrium K u = f_ext.
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factor(reduced);
  if (factor.info() != Eigen::Success) throw std::runtime_error("static_plate: the stiffness is singular");
  const Eigen::VectorXd solution = factor.solve(load);
  Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i)
    if (!is_fixed[i]) w[i] = solution[free_index[bending_dofs * i]];
  return w;
}

}  // namespace sphshell::test_support
