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

}  // namespace sphshell
