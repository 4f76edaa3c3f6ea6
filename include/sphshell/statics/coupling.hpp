#pragma once
// The coupling graph of a solver's particles and the finite-difference
// Jacobian of its forces over a colouring of that graph: the one tangent
// assembly of the static solvers (statics::TangentAssembly for the path
// following and buckling, Solver::solve_static for its Newton steps and the
// relaxation's masses), and the one product of that Jacobian with a vector
// (difference_product, the GMRES Newton steps of both).
//
// Two particles are coupled when both sit in the row of one integration
// point: the forces on one change when the other moves. A distance-2
// colouring groups particles no particle is coupled to two of, so all the
// particles of one colour are perturbed together and each force response is
// credited to the one perturbed particle in reach (Curtis, Powell & Reid,
// J. Inst. Math. Appl. 13 (1974) 117–119). Central differences cancel the even
// terms of the forces' expansion: the error is O(h²) plus rounding of
// O(ε |f| / h) (docs/method.md, "Static solutions").

#include <sphshell/core/types.hpp>
#include <sphshell/solver/integration_points.hpp>

#include <Eigen/Sparse>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace sphshell::statics {

using SparseMatrix = Eigen::SparseMatrix<double>;

// Per particle, the particles whose forces its motion changes (itself first),
// and the colours of the graph.
struct Coupling {
  std::vector<std::vector<int>> near;
  std::vector<std::vector<int>> colours;
};

namespace detail {

// Entries of a difference column below this share of the column's largest are
// rounding (the exact tangent's zeros come out near 1e-15 of it) and may be
// left out: kept, they fill the factorisation of a Newton step. A tangent
// that is differenced again (the geometric stiffness of statics/buckling.hpp,
// the difference of two tangents) keeps them: an entry dropped on one side
// and kept on the other is an error of the dropped size there.
inline constexpr double negligible_tangent_entry = 1e-12;

// The most degrees of freedom of a particle: three translations, two rotations
// of the director (drilling is none).
inline constexpr int most_dofs_per_particle = 5;

}  // namespace detail

// Per particle, the particles sharing an integration point's row with it (the
// edge-tied shear acts within a row too).
template <class Approx>
std::vector<std::vector<int>> coupling(const solver::IntegrationPoints<Approx>& points, std::size_t particles) {
  using solver::point_groups;
  std::vector<std::vector<int>> rows_of(particles);
  std::vector<std::vector<int>> row_particles(points.size());
  for (solver::PointGroup group : point_groups) {
    const approx::ShapeFunctions& shape = points.shape(group);
    for (std::size_t row = 0; row < shape.rows(); ++row)
      for (std::size_t s = shape.row_begin[row]; s < shape.row_begin[row] + shape.row_size[row]; ++s) {
        const auto point = static_cast<int>(points.point(group, row));
        rows_of[static_cast<std::size_t>(shape.neighbour[s])].push_back(point);
        row_particles[static_cast<std::size_t>(point)].push_back(shape.neighbour[s]);
      }
  }
  std::vector<std::vector<int>> coupled(particles);
  std::vector<long> mark(particles, -1);
  for (std::size_t j = 0; j < particles; ++j) {
    coupled[j].push_back(static_cast<int>(j));
    mark[j] = static_cast<long>(j);
    for (int p : rows_of[j])
      for (int i : row_particles[static_cast<std::size_t>(p)])
        if (mark[static_cast<std::size_t>(i)] != static_cast<long>(j)) {
          mark[static_cast<std::size_t>(i)] = static_cast<long>(j);
          coupled[j].push_back(i);
        }
  }
  return coupled;
}

// Greedy distance-2 colouring: no particle is coupled to two particles of one
// colour, so the forces of a colour's joint perturbation separate by particle.
inline std::vector<std::vector<int>> colour(const std::vector<std::vector<int>>& coupled) {
  const std::size_t n = coupled.size();
  std::vector<int> colour_of(n, -1);
  std::vector<long> taken;  // per colour: the particle that last forbade it
  std::vector<std::vector<int>> classes;
  for (std::size_t j = 0; j < n; ++j) {
    for (int i : coupled[j])
      for (int k : coupled[static_cast<std::size_t>(i)]) {
        const int c = colour_of[static_cast<std::size_t>(k)];
        if (c >= 0) taken[static_cast<std::size_t>(c)] = static_cast<long>(j);
      }
    std::size_t c = 0;
    while (c < taken.size() && taken[c] == static_cast<long>(j)) ++c;
    if (c == taken.size()) {
      taken.push_back(-1);
      classes.emplace_back();
    }
    colour_of[j] = static_cast<int>(c);
    classes[c].push_back(static_cast<int>(j));
  }
  return classes;
}

// The coupling of a solver's integration points and its colouring; with
// `one_particle_per_colour` every particle is a colour of its own (for
// checking the colouring: as many force evaluations as particles).
template <class Approx>
Coupling coloured_coupling(const solver::IntegrationPoints<Approx>& points, std::size_t particles,
                           bool one_particle_per_colour = false) {
  Coupling result;
  result.near = coupling(points, particles);
  if (one_particle_per_colour) {
    for (std::size_t i = 0; i < particles; ++i) result.colours.push_back({static_cast<int>(i)});
  } else {
    result.colours = colour(result.near);
  }
  return result;
}

// A perturbation of one degree of freedom: particle, its local degree of
// freedom (0 ≤ local < first[particle + 1] − first[particle]) and the amount.
struct Perturbation {
  int particle;
  int local;
  double amount;
};

// The Jacobian ∂F/∂q of a force vector F over degrees of freedom laid out per
// particle (those of particle i are first[i] … first[i + 1] − 1), by central
// differences colour by colour. step(particle, local) is the difference step
// of a degree of freedom; forces(perturbations) sets the configuration to the
// caller's base one moved by the perturbations and returns F there. The
// caller restores its base configuration afterwards. Entries at most
// `negligible` times their column's largest are left out (0: only zeros).
template <class Step, class Forces>
SparseMatrix difference_tangent(const Coupling& coupling, const std::vector<int>& first, Step&& step,
                                Forces&& forces, double negligible = 0.0) {
  const int n = static_cast<int>(first.size()) - 1;
  std::vector<Eigen::Triplet<double>> entries, column;
  std::vector<int> owner(static_cast<std::size_t>(n), -1);
  std::vector<Perturbation> perturbations;
  for (const std::vector<int>& members : coupling.colours) {
    // Each particle's response is read where no other member reaches.
    for (int p : members)
      for (int q : coupling.near[static_cast<std::size_t>(p)]) owner[static_cast<std::size_t>(q)] = p;
    for (int local = 0; local < detail::most_dofs_per_particle; ++local) {
      Eigen::VectorXd response[2];
      for (int side = 0; side < 2; ++side) {
        perturbations.clear();
        for (int p : members)
          if (first[p] + local < first[p + 1])
            perturbations.push_back({p, local, (side == 0 ? 1.0 : -1.0) * step(p, local)});
        if (perturbations.empty()) break;
        response[side] = forces(perturbations);
      }
      if (perturbations.empty()) continue;
      for (int p : members) {
        const int dof = first[p] + local;
        if (dof >= first[p + 1]) continue;
        const double h = step(p, local);
        column.clear();
        double largest = 0.0;
        for (int q : coupling.near[static_cast<std::size_t>(p)]) {
          if (owner[static_cast<std::size_t>(q)] != p) continue;
          for (int row = first[q]; row < first[q + 1]; ++row) {
            const double value = (response[0][row] - response[1][row]) / (2.0 * h);
            largest = std::max(largest, std::abs(value));
            column.emplace_back(row, dof, value);
          }
        }
        for (const Eigen::Triplet<double>& entry : column)
          if (entry.value() != 0.0 && std::abs(entry.value()) > negligible * largest) entries.push_back(entry);
      }
    }
    for (int p : members)
      for (int q : coupling.near[static_cast<std::size_t>(p)]) owner[static_cast<std::size_t>(q)] = -1;
  }
  SparseMatrix k(first.back(), first.back());
  k.setFromTriplets(entries.begin(), entries.end());
  k.makeCompressed();
  return k;
}

// The same Jacobian applied to a vector, (∂F/∂q) v, without assembling it: one
// central difference of the forces along v (two evaluations), the product of
// the GMRES Newton steps (statics/krylov.hpp) of both static solvers.
// step(k) is the difference step of degree of freedom k; the step along v is
// h = min_k step(k) / |v_k|, so no degree of freedom moves further than its
// own step of the assembly, whose truncation and round-off these steps
// balance. forces(u) sets the configuration to the caller's base one moved by
// the update u (+h v, then −h v) and returns F there; the caller restores its
// base configuration afterwards. A zero v gives zero without an evaluation.
template <class Step, class Forces>
Eigen::VectorXd difference_product(const Eigen::VectorXd& v, Step&& step, Forces&& forces) {
  double h = std::numeric_limits<double>::infinity();
  for (Eigen::Index k = 0; k < v.size(); ++k)
    if (v[k] != 0.0) h = std::min(h, step(k) / std::abs(v[k]));
  if (!std::isfinite(h)) return Eigen::VectorXd::Zero(v.size());
  const Eigen::VectorXd forward = forces(Eigen::VectorXd(h * v));
  const Eigen::VectorXd backward = forces(Eigen::VectorXd(-h * v));
  return (forward - backward) / (2.0 * h);
}

}  // namespace sphshell::statics
