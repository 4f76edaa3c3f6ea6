#pragma once
// Models and integration points of the paper's cases for the MPI tests and
// tools: the square plate (§3, 51 × 51 particles), a closed tube and the
// spherical cap (Figs 6-7), each with the solver's own shape-function rows.

#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/mpi/partition.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/options.hpp>

#include <cmath>
#include <cstring>
#include <vector>
#include <memory>
#include <string>

namespace mpi_test {

using Approximation = sphshell::approx::MLS<sphshell::kernel::CubicSpline>;
using Points = sphshell::solver::IntegrationPoints<Approximation>;

inline constexpr double pi = 3.14159265358979323846;
// Steel's shear modulus, E / (2 (1 + ν)) with E = 210 GPa, ν = 0.3 (only the weights use it).
inline constexpr double steel_shear_modulus = 210e9 / 2.6;

// A model and its integration points with the library's default options
// (particle share 0.5: both groups integrate).
struct Case {
  std::string name;
  sphshell::ShellModel model;
  std::unique_ptr<Points> points;
  sphshell::mpi::DecompositionInput input() const { return sphshell::mpi::decomposition_input(model, *points); }
};

// How many components of two vector lists differ bitwise (the size mismatch
// counts every component): a distributed run must reproduce the serial one
// exactly, not within a tolerance.
inline std::size_t differing_components(const std::vector<sphshell::Vector3>& a, const std::vector<sphshell::Vector3>& b) {
  if (a.size() != b.size()) return a.size() + b.size();
  std::size_t count = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) count += std::memcmp(&a[i][c], &b[i][c], sizeof(double)) != 0 ? 1 : 0;
  return count;
}

inline Case make_case(std::string name, sphshell::ShellModel model) {
  const sphshell::SolverOptions options;
  Case c{std::move(name), std::move(model), nullptr};
  c.points = std::make_unique<Points>(c.model, options.physics(), options.particle_integration(), steel_shear_modulus);
  return c;
}

// The paper's plate: L = 0.5 m, d = 0.01 m, n × n particles.
inline Case paper_plate(int n = 51) {
  return make_case("plate " + std::to_string(n) + "x" + std::to_string(n),
                   sphshell::ShellModel::rectangular_plate(0.5, 0.5, n, n, 0.01));
}
// A closed tube (cylindrical_panel with angle 2π): the detonation tube's
// radius 0.019 m and wall 0.89 mm at the given spacing over `length`.
inline Case closed_tube(double spacing = 2.5e-3, double length = 0.914) {
  const int circumferential = static_cast<int>(std::lround(2 * pi * 0.019 / spacing));
  const int axial = static_cast<int>(std::lround(length / spacing)) + 1;
  return make_case("tube " + std::to_string(circumferential) + "x" + std::to_string(axial),
                   sphshell::ShellModel::cylindrical_panel(0.019, length, 2 * pi, circumferential, axial, 0.89e-3));
}
// The paper's spherical cap: R = 0.5657 m, half-angle 26.67°, d = 0.010414 m.
inline Case spherical_cap(int n = 25) {
  return make_case("cap " + std::to_string(n) + "x" + std::to_string(n),
                   sphshell::ShellModel::spherical_cap(0.5657, 26.67 * pi / 180.0, n, 0.010414));
}

}  // namespace mpi_test
