/** @file HalfLine.h
 *  @brief The one-sided constraint x ≥ l on a scalar variable as a factor-graph node (the indicator factor
 *         1[x ≥ l]), with its moment-matched Gaussian message (docs/math/message-passing.md G23).
 *
 *  A Gaussian belief N(m, v) times the indicator is a truncated Gaussian. Its mean and variance (the moments of the
 *  normal distribution truncated below, Johnson, Kotz & Balakrishnan 1994, ch. 13.10) define the Gaussian the belief
 *  is replaced by; the message the node sends is the scalar Gaussian pseudo-observation that turns N(m, v) into that
 *  Gaussian through the equality node (G5/G18), as expectation propagation does for a non-Gaussian factor
 *  (Minka 2001). Applied to one component of a joint Gaussian, the equality node moves the other components through
 *  their covariance with it, which gives exactly the first two moments of the joint truncated along that component
 *  ("density truncation" of constrained Kalman filtering, Simon & Simon, IET Control Theory Appl. 4(8), 2010).
 *
 *  @code
 *    const TruncatedMoments t = truncatedBelow(m, v, l);        // moments of N(m, v) restricted to x ≥ l
 *    if (auto msg = halfLineMessage(m, v, l)) ekf.positionUpdate(2, msg->y, std::sqrt(msg->var));
 *  @endcode
 */
#pragma once

#include <optional>

namespace uwb {

/// Mean and variance of a scalar Gaussian.
struct TruncatedMoments {
  double mean = 0.0;
  double var = 0.0;
};

/// (G23a) Mean and variance of N(m, v) restricted to x ≥ l (v > 0): with a = (l − m)/√v, λ = φ(a)/(1 − Φ(a)),
/// mean m + √v λ, variance v (1 − λ(λ − a)). Full precision for any a (a continued fraction from a = 3 on).
/// Throws std::invalid_argument unless m, l are finite and v is finite and > 0.
TruncatedMoments truncatedBelow(double m, double v, double l);

/// A scalar Gaussian pseudo-observation y of the variable, with variance var.
struct ScalarObservation {
  double y = 0.0;
  double var = 0.0;
};

/// (G23b) The half-line node's moment-matched message to a variable with belief N(m, v): the observation
/// (y, s) with N(m, v) ⊙ N(y, s) ∝ N(truncatedBelow(m, v, l)), i.e. s = v (1 − δ)/δ, y = m + √v/(λ − a),
/// δ = λ(λ − a). nullopt when the belief has no mass below l to speak of (δ < 1e-9: the message is flat).
std::optional<ScalarObservation> halfLineMessage(double m, double v, double l);

}  // namespace uwb
