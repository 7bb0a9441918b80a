/** @file StateIndex.h
 *  @brief Named blocks of the 15-dimensional error state (docs/math/filter.md F1).
 *
 *  δx = [δp (world, m), δv (world, m/s), δθ (body-frame attitude error, rad), δb_a (m/s²), δb_g (rad/s)].
 *  Attitude error convention (shared with model/TdoaModel.h): w_q_b(true) = w_q_b ⊗ exp(δθ).
 */
#pragma once

#include <Eigen/Core>

namespace uwb {

enum StateIndex : int { kPos = 0, kVel = 3, kAtt = 6, kAccBias = 9, kGyroBias = 12, kDim = 15 };

using ErrVec = Eigen::Matrix<double, kDim, 1>;
using ErrMat = Eigen::Matrix<double, kDim, kDim>;
using ErrRow = Eigen::Matrix<double, 1, kDim>;

}  // namespace uwb
