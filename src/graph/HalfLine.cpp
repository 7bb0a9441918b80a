/** @file HalfLine.cpp
 *  @brief Moments of a Gaussian truncated below and the half-line node's message (docs/math/message-passing.md G23).
 */
#include "uwb/graph/HalfLine.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace uwb {
namespace {

struct Tail {
  double lambda;           ///< λ(a) = φ(a)/(1 − Φ(a)), the inverse Mills ratio
  double gap;              ///< λ − a > 0
  double delta;            ///< δ = λ(λ − a) ∈ (0, 1): the fraction of the variance the truncation removes
  double one_minus_delta;  ///< 1 − δ, the fraction it keeps
};

// (G23a) Below a = 3 from erfc, which keeps its relative accuracy in the tail. From a = 3 on, λ − a and 1 − δ lose
// their digits to cancellation in that form; there the Laplace continued fraction of the Mills ratio,
// (1 − Φ(a))/φ(a) = 1/(a + 1/(a + 2/(a + 3/(a + …)))), gives them without it: with U = 2/(a + 3/(a + …)) and
// T = 1/(a + U), λ = a + T, so λ − a = T, and 1 − δ = 1 − (a + T) T = T (U − T) since 1 − a T = U T. 60 levels give
// full double precision for a ≥ 3 (checked against 60-digit arithmetic).
Tail tail(double a) {
  constexpr double kSqrt2 = 1.4142135623730951;
  constexpr double kSqrt2OverPi = 0.7978845608028654;  // √(2/π)
  if (a >= 3.0) {
    double f = 0.0;
    for (int k = 60; k >= 3; --k) f = k / (a + f);
    const double U = 2.0 / (a + f);
    const double T = 1.0 / (a + U);
    const double one_minus_delta = T * (U - T);
    return {a + T, T, 1.0 - one_minus_delta, one_minus_delta};
  }
  // λ = φ(a) / (½ erfc(a/√2)) = √(2/π) e^{−a²/2} / erfc(a/√2)
  const double lambda = kSqrt2OverPi * std::exp(-0.5 * a * a) / std::erfc(a / kSqrt2);
  const double gap = lambda - a;
  const double delta = lambda * gap;
  return {lambda, gap, delta, std::max(1.0 - delta, 0.0)};
}

void check(double m, double v, double l, const char* who) {
  if (!std::isfinite(m) || !std::isfinite(l) || !std::isfinite(v) || !(v > 0.0))
    throw std::invalid_argument(std::string(who) + ": the mean and the bound must be finite and the variance > 0");
}

}  // namespace

TruncatedMoments truncatedBelow(double m, double v, double l) {
  check(m, v, l, "truncatedBelow");
  const double sd = std::sqrt(v);
  const double a = (l - m) / sd;
  if (a < -38.0) return {m, v};  // no mass below l in double precision
  const Tail t = tail(a);
  // mean = m + √v λ = l + √v (λ − a); the second form keeps its digits when the mean lies far below l
  const double mean = a > 0.0 ? l + sd * t.gap : m + sd * t.lambda;
  return {mean, v * t.one_minus_delta};
}

std::optional<ScalarObservation> halfLineMessage(double m, double v, double l) {
  check(m, v, l, "halfLineMessage");
  const double sd = std::sqrt(v);
  const double a = (l - m) / sd;
  if (a < -38.0) return std::nullopt;
  const Tail t = tail(a);
  if (!(t.delta >= 1e-9)) return std::nullopt;
  // (G23b) N(m, v) ⊙ N(y, s) has variance v s/(v + s) = v (1 − δ) ⇒ s = v (1 − δ)/δ, and mean
  // m + v/(v + s) (y − m) = m + δ (y − m) = m + √v λ ⇒ y = m + √v λ/δ = m + √v/(λ − a)
  return ScalarObservation{m + sd / t.gap, v * t.one_minus_delta / t.delta};
}

}  // namespace uwb
