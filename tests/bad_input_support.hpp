#pragma once
// Shared by the bad-input tests: a small plate in each builder's form, and a
// check that an expression throws sphshell::Error whose message holds every
// expected piece.
#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/shell/spherical_cap_ogrid.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include <catch2/catch.hpp>

#include <string>
#include <vector>

namespace bad_input {

using namespace sphshell;
using ElasticSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic>;
using CrackSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic, crack::LineSegments>;
inline const material::Elastic::Parameters steel{210e9, 0.3};

// An n × n plate of side `side` for the general constructor: particles on the
// grid with their tributary areas (halved on edges, quartered at corners),
// stress points at the cell centres with the cell areas, normals +z.
struct GeneralPlate {
  std::vector<Vector3> positions, normals, stress_positions, stress_normals;
  std::vector<double> areas, stress_areas;
  double thickness = 0.01;

  explicit GeneralPlate(int n = 6, double side = 0.1) {
    const double s = side / (n - 1);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        positions.emplace_back(i * s, j * s, 0.0);
        normals.emplace_back(0.0, 0.0, 1.0);
        const double wx = (i == 0 || i == n - 1) ? 0.5 : 1.0, wy = (j == 0 || j == n - 1) ? 0.5 : 1.0;
        areas.push_back(wx * wy * s * s);
      }
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        stress_positions.emplace_back((i + 0.5) * s, (j + 0.5) * s, 0.0);
        stress_normals.emplace_back(0.0, 0.0, 1.0);
        stress_areas.push_back(s * s);
      }
  }
  ShellModel build() const {
    return ShellModel(positions, normals, areas, stress_positions, stress_normals, stress_areas, thickness);
  }
};

// An nx × ny grid's positions, normals and counter-clockwise quads for from_quads.
struct QuadPlate {
  std::vector<Vector3> positions, normals;
  std::vector<Quad> quads;
  int nx, ny;
  QuadPlate(int nx_ = 5, int ny_ = 5, double side = 0.1) : nx(nx_), ny(ny_) {
    const double s = side / (nx - 1);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        positions.emplace_back(i * s, j * s, 0.0);
        normals.emplace_back(0.0, 0.0, 1.0);
      }
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i)
        quads.push_back({j * nx + i, j * nx + i + 1, (j + 1) * nx + i + 1, (j + 1) * nx + i});
  }
  ShellModel build(double thickness = 0.01) const { return ShellModel::from_quads(positions, normals, quads, thickness); }
};

// The message of the sphshell::Error `run` throws; fails the test when it
// throws nothing or another type.
template <class Run>
std::string error_of(Run&& run) {
  try {
    run();
  } catch (const Error& error) {
    return error.what();
  } catch (const std::exception& other) {
    FAIL("threw another exception type: " << other.what());
  }
  FAIL("threw nothing");
  return {};
}

template <class Run>
void require_error(Run&& run, const std::vector<std::string>& pieces) {
  const std::string message = error_of(run);
  INFO("message: " << message);
  for (const std::string& piece : pieces) CHECK(message.find(piece) != std::string::npos);
}

}  // namespace bad_input
