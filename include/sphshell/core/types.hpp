#pragma once
// Small fixed-size Eigen types used throughout, and plane-stress Voigt notation.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sphshell {

using Vector2 = Eigen::Vector2d;
using Vector3 = Eigen::Vector3d;
using Matrix2 = Eigen::Matrix2d;
using Matrix3 = Eigen::Matrix3d;

// Plane-stress Voigt vectors: stress (σx, σy, σxy), strain (εx, εy, γxy) with
// engineering shear γxy = 2εxy.
using StressVoigt = Eigen::Vector3d;
using StrainVoigt = Eigen::Vector3d;

// Whether every component of the given vectors is finite, for the checks a
// step makes at every particle. v − v is +0 for a finite v and NaN for ±∞ and
// NaN, so one sum of the differences decides; GCC left Eigen's allFinite() out
// of line there, a call per vector (3 % of a plate step for four vectors).
template <class... Vectors>
inline bool all_finite(const Vectors&... vectors) {
  double sum = 0.0;
  (..., (sum += (vectors[0] - vectors[0]) + (vectors[1] - vectors[1]) + (vectors[2] - vectors[2])));
  return sum == 0.0;
}

}  // namespace sphshell
