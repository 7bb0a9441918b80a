/** @file Types.h
 *  @brief Fixed-size Eigen aliases and physical constants used across the library (SI units inside).
 */
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace uwb {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using RowVec3 = Eigen::RowVector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;
using RowVecX = Eigen::RowVectorXd;

/// Standard gravity used to convert accelerometer readings in g to m/s² (UTIL scripts use 9.81).
inline constexpr double kGravity_mps2 = 9.81;
inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegToRad = kPi / 180.0;

/// UTIL dataset: UWB antenna (tag) position in the Crazyflie body frame [m].
inline const Vec3 kUtilTagOffset_b{-0.01245, 0.00127, 0.0908};

}  // namespace uwb
