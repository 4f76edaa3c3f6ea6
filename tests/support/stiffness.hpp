#pragma once
// Assembles the stiffness and mass matrices of a solver's discrete system around
// its current configuration by finite differences of the internal forces, for
// eigenvalue checks. Degrees of freedom per particle: three translations and two
// rotations of the director about the axes e1, e2 of its reference tangent frame.

#include <sphshell/core/frame.hpp>

#include <Eigen/Dense>

#include <vector>

namespace sphshell::test_support {

struct DiscreteSystem {
  Eigen::MatrixXd stiffness;
  Eigen::VectorXd mass;  // lumped: translational masses and rotary inertias
};

template <class Solver>
Eigen::VectorXd generalized_forces(const Solver& solver) {
  const std::size_t n = solver.particle_count();
  Eigen::VectorXd forces(5 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const TangentFrame frame = tangent_frame(solver.model().particle_normal[i]);
    forces.segment<3>(5 * i) = solver.internal_forces()[i];
    // ∂Π/∂θ_a = e_a · (d × g) for a rotation δd = δθ × d.
    const Vector3 moment = solver.directors()[i].cross(solver.internal_director_forces()[i]);
    forces[5 * i + 3] = frame.e1.dot(moment);
    forces[5 * i + 4] = frame.e2.dot(moment);
  }
  return forces;
}

// Central differences with step `h` (m for translations, rad for rotations).
// The solver must be elastic; its state is left at the reference configuration.
template <class Solver>
DiscreteSystem assemble(Solver& solver, double h) {
  const std::size_t n = solver.particle_count();
  const std::vector<Vector3> x0 = solver.positions();
  const std::vector<Vector3> d0 = solver.directors();
  DiscreteSystem system;
  system.stiffness.resize(5 * n, 5 * n);
  system.mass.resize(5 * n);
  for (std::size_t column = 0; column < 5 * n; ++column) {
    const std::size_t i = column / 5;
    const int component = static_cast<int>(column % 5);
    const TangentFrame frame = tangent_frame(solver.model().particle_normal[i]);
    Eigen::VectorXd difference = Eigen::VectorXd::Zero(5 * n);
    for (double sign : {1.0, -1.0}) {
      std::vector<Vector3> x = x0, d = d0;
      if (component < 3) {
        x[i][component] += sign * h;
      } else {
        const Vector3 axis = component == 3 ? frame.e1 : frame.e2;
        d[i] = Eigen::AngleAxisd(sign * h, axis) * d0[i];
      }
      solver.set_configuration(x, d);
      difference += sign * generalized_forces(solver);
    }
    system.stiffness.col(column) = difference / (2.0 * h);
  }
  solver.set_configuration(x0, d0);
  system.stiffness = 0.5 * (system.stiffness + system.stiffness.transpose()).eval();
  for (std::size_t i = 0; i < n; ++i) {
    const double mass = solver.masses()[i];
    system.mass.segment<3>(5 * i).setConstant(mass);
    system.mass.segment<2>(5 * i + 3).setConstant(solver.rotary_inertias()[i]);
  }
  return system;
}

}  // namespace sphshell::test_support
