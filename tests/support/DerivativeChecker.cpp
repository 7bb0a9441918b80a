/** @file DerivativeChecker.cpp
 *  @brief Central differences and their comparison with analytic Jacobians.
 */
#include "support/DerivativeChecker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <ostream>
#include <stdexcept>

namespace uwb::test {

namespace {

/// Central difference of g(s) at s = 0 with step `step` (g(±k·step) evaluated).
template <class G>
VecX centralDifference(const G& g, double step, int order) {
  if (order == 2) return (g(step) - g(-step)) / (2.0 * step);
  if (order == 4) return (-g(2.0 * step) + 8.0 * g(step) - 8.0 * g(-step) + g(-2.0 * step)) / (12.0 * step);
  throw std::invalid_argument("DifferenceOptions::order must be 2 or 4");
}

}  // namespace

MatX numericalJacobian(const std::function<VecX(const VecX&)>& f, const VecX& x, const DifferenceOptions& options) {
  const VecX f0 = f(x);
  MatX J(f0.size(), x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const double step = options.h * std::max(options.min_scale, std::abs(x[i]));
    const auto g = [&](double s) {
      VecX xs = x;
      xs[i] += s;
      return f(xs);
    };
    J.col(i) = centralDifference(g, step, options.order);
  }
  return J;
}

MatX numericalJacobianRotation(const std::function<VecX(const Quat&)>& f, const Quat& q,
                               const DifferenceOptions& options) {
  const VecX f0 = f(q);
  MatX J(f0.size(), 3);
  for (int i = 0; i < 3; ++i) {
    const auto g = [&](double s) { return f((q * Quat(Eigen::AngleAxisd(s, Vec3::Unit(i)))).normalized()); };
    J.col(i) = centralDifference(g, options.h, options.order);
  }
  return J;
}

JacobianCheck compareJacobians(const MatX& analytic, const MatX& numerical) {
  JacobianCheck c;
  c.analytic = analytic;
  c.numerical = numerical;
  if (analytic.rows() != numerical.rows() || analytic.cols() != numerical.cols()) {
    c.max_abs_error = c.max_scaled_error = c.relative_error = std::numeric_limits<double>::infinity();
    return c;
  }
  double max_ref = 0.0;
  for (Eigen::Index j = 0; j < analytic.cols(); ++j) {
    for (Eigen::Index i = 0; i < analytic.rows(); ++i) {
      const double diff = std::abs(analytic(i, j) - numerical(i, j));
      const double scaled = diff / std::max(1.0, std::abs(numerical(i, j)));
      max_ref = std::max(max_ref, std::abs(numerical(i, j)));
      c.max_abs_error = std::max(c.max_abs_error, diff);
      // NaN anywhere makes the check fail: it becomes the worst entry with an infinite error
      if (!(scaled <= c.max_scaled_error)) {
        c.max_scaled_error = std::isnan(scaled) ? std::numeric_limits<double>::infinity() : scaled;
        c.worst_row = i;
        c.worst_col = j;
      }
      if (std::isnan(diff)) c.max_abs_error = std::numeric_limits<double>::infinity();
    }
  }
  c.relative_error = max_ref > 0.0 ? c.max_abs_error / max_ref : c.max_abs_error;
  return c;
}

JacobianCheck checkJacobian(const std::function<VecX(const VecX&)>& f, const VecX& x, const MatX& analytic,
                            const DifferenceOptions& options) {
  return compareJacobians(analytic, numericalJacobian(f, x, options));
}

JacobianCheck checkJacobianRotation(const std::function<VecX(const Quat&)>& f, const Quat& q, const MatX& analytic,
                                    const DifferenceOptions& options) {
  return compareJacobians(analytic, numericalJacobianRotation(f, q, options));
}

JacobianCheck checkGradient(const std::function<double(const VecX&)>& f, const VecX& x, const VecX& analytic,
                            const DifferenceOptions& options) {
  const auto fv = [&](const VecX& xx) { return VecX::Constant(1, f(xx)); };
  return compareJacobians(analytic.transpose(), numericalJacobian(fv, x, options));
}

std::ostream& operator<<(std::ostream& os, const JacobianCheck& c) {
  os << "worst entry (" << c.worst_row << ", " << c.worst_col << ")";
  if (c.worst_row < c.analytic.rows() && c.worst_col < c.analytic.cols() && c.worst_row < c.numerical.rows() &&
      c.worst_col < c.numerical.cols()) {
    os << ": analytic " << c.analytic(c.worst_row, c.worst_col) << ", numerical "
       << c.numerical(c.worst_row, c.worst_col);
  }
  os << "; max |A − N| " << c.max_abs_error << ", max |A − N| / max(1, |N|) " << c.max_scaled_error
     << ", relative " << c.relative_error << "\nanalytic\n"
     << c.analytic << "\nnumerical\n"
     << c.numerical;
  return os;
}

}  // namespace uwb::test
