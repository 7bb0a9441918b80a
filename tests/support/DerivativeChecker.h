/** @file DerivativeChecker.h
 *  @brief One numerical-derivative checker for every analytic Jacobian and gradient test (STYLE §10; the idea of
 *         Ceres' GradientChecker): given a function, the point and the analytic Jacobian, it differentiates the
 *         function by central differences and reports how far the two are apart, with the worst entry.
 *
 *  Usage:
 *    const test::JacobianCheck c = test::checkJacobian(f, x, J_analytic);
 *    EXPECT_LT(c.max_abs_error, 1e-8) << c;          // prints the worst entry and both matrices
 */
#pragma once

#include <functional>
#include <iosfwd>

#include "uwb/core/Types.h"

namespace uwb::test {

/// How the central differences are taken.
struct DifferenceOptions {
  double h = 1e-6;          ///< step of coordinate i: h · max(|x_i|, min_scale)
  double min_scale = 1.0;   ///< lower bound of the step scale (so that x_i = 0 still gets a step)
  int order = 2;            ///< 2: (f(x+s) − f(x−s)) / 2s; 4: (−f(x+2s) + 8f(x+s) − 8f(x−s) + f(x−2s)) / 12s
};

/// Analytic against numerical Jacobian, entry by entry.
struct JacobianCheck {
  MatX analytic;
  MatX numerical;
  double max_abs_error = 0.0;     ///< max_ij |A_ij − N_ij|
  double max_scaled_error = 0.0;  ///< max_ij |A_ij − N_ij| / max(1, |N_ij|)
  double relative_error = 0.0;    ///< max_ij |A_ij − N_ij| / max_ij |N_ij| (0 / 0 → the numerator)
  Eigen::Index worst_row = 0;     ///< entry of max_scaled_error
  Eigen::Index worst_col = 0;
};

/// Central-difference Jacobian of f: Rⁿ → Rᵐ at x.
MatX numericalJacobian(const std::function<VecX(const VecX&)>& f, const VecX& x, const DifferenceOptions& options);

/// Central-difference Jacobian of f(q ⊞ δθ) w.r.t. the rotation-vector perturbation δθ (right, body frame):
/// q ⊞ δθ = q ⊗ exp(δθ). Returns m×3.
MatX numericalJacobianRotation(const std::function<VecX(const Quat&)>& f, const Quat& q,
                               const DifferenceOptions& options = {});

/// Compares two Jacobians of the same shape (numerical second); a shape mismatch gives infinite errors.
JacobianCheck compareJacobians(const MatX& analytic, const MatX& numerical);

/// Differentiates f at x numerically and compares with `analytic` (m×n).
JacobianCheck checkJacobian(const std::function<VecX(const VecX&)>& f, const VecX& x, const MatX& analytic,
                            const DifferenceOptions& options = {});

/// The same for a rotation argument, perturbed on the right in the body frame (see numericalJacobianRotation).
JacobianCheck checkJacobianRotation(const std::function<VecX(const Quat&)>& f, const Quat& q, const MatX& analytic,
                                    const DifferenceOptions& options = {});

/// Gradient of a scalar function f: Rⁿ → R (analytic: n entries), as a 1×n Jacobian.
JacobianCheck checkGradient(const std::function<double(const VecX&)>& f, const VecX& x, const VecX& analytic,
                            const DifferenceOptions& options = {});

/// Worst entry, the three error measures, and both matrices (for gtest messages).
std::ostream& operator<<(std::ostream& os, const JacobianCheck& check);

}  // namespace uwb::test
