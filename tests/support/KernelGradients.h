/** @file KernelGradients.h
 *  @brief The analytic gradients of f = Σ_ij G_ij k(x_i, y_j) with respect to θ and X, as the kernel accumulates
 *         them (Kernel::accumulateCrossGradient), for the tests that check them against central differences.
 *         Header-only: for tests that link uwb_gp.
 */
#pragma once

#include <vector>

#include "uwb/core/Types.h"
#include "uwb/gp/Kernel.h"

namespace uwb::test {

struct CrossGradients {
  VecX theta;  ///< ∂f/∂θ, one entry per kernel parameter
  MatX x;      ///< ∂f/∂X, the shape of X
};

/// ∂f/∂θ and ∂f/∂X of f = Σ_ij G_ij k(X_i, Y_j).
inline CrossGradients crossGradients(const gp::Kernel& k, const MatX& X, const MatX& Y, const MatX& G) {
  std::vector<MatX> blocks;
  k.cross(X, Y, &blocks);
  CrossGradients g{VecX::Zero(k.numParams()), MatX::Zero(X.rows(), X.cols())};
  k.accumulateCrossGradient(X, Y, G, blocks, g.theta, &g.x);
  return g;
}

}  // namespace uwb::test
