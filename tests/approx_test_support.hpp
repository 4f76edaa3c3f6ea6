#pragma once
// Point sets shared by the approximation tests.

#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>

#include <cmath>
#include <random>
#include <vector>

namespace approx_test {

using sphshell::TangentFrame;
using sphshell::Vector3;

struct PointSets {
  std::vector<Vector3> particles;
  std::vector<double> volumes;
  std::vector<Vector3> eval_positions;
  std::vector<TangentFrame> eval_frames;
};

// n × n particles with spacing `spacing` in the xy-plane, each moved by up to
// ±jitter·spacing per axis (fixed seed); evaluation points at the centres of the
// (jittered) cells, or at the particles themselves.
inline PointSets plate(int n, double spacing, double jitter, bool at_particles,
                       unsigned seed = 12345) {
  PointSets sets;
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> offset(-jitter * spacing, jitter * spacing);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double dx = jitter > 0 ? offset(random) : 0.0;
      const double dy = jitter > 0 ? offset(random) : 0.0;
      sets.particles.emplace_back(i * spacing + dx, j * spacing + dy, 0.0);
      sets.volumes.push_back(spacing * spacing);
    }
  if (at_particles) {
    sets.eval_positions = sets.particles;
  } else {
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        const auto corner = [&](int a, int b) { return sets.particles[std::size_t(b * n + a)]; };
        sets.eval_positions.push_back(
            0.25 * (corner(i, j) + corner(i + 1, j) + corner(i, j + 1) + corner(i + 1, j + 1)));
      }
  }
  sets.eval_frames.assign(sets.eval_positions.size(), sphshell::tangent_frame(Vector3::UnitZ()));
  return sets;
}

}  // namespace approx_test
