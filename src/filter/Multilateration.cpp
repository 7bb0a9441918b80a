/** @file Multilateration.cpp
 *  @brief Robust Gauss–Newton TDoA multilateration (docs/math/filter.md F16, F16b).
 */
#include "uwb/filter/Multilateration.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

/// Huber-IRLS Gauss–Newton over N unknowns: N = 3 solves p0 (F16), N = 6 solves (p0, v0) with the body at
/// p0 + v0 (t_i − t_ref) + d_i (F16b). The one implementation of both.
/// fixed_z (N = 3 only): the body origin's height is known (on the floor), the solve is over x and y (F16c).
template <int N>
std::optional<MultilaterationResult> solve(const std::vector<MultilaterationSample>& samples, const AnchorTable& anchors,
                                           const Vec3& b_t_tag, const std::vector<Vec3>& initial_guesses,
                                           double t_ref_s, double huber_k_m, int max_iterations,
                                           std::optional<double> fixed_z = std::nullopt) {
  using MatN = Eigen::Matrix<double, N, N>;
  using VecN = Eigen::Matrix<double, N, 1>;
  constexpr std::size_t kMinUsed = N == 3 ? 4 : 8;
  if (samples.size() < kMinUsed) return std::nullopt;
  std::optional<MultilaterationResult> best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < initial_guesses.size(); ++k) {
    VecN x = VecN::Zero();
    x.template head<3>() = initial_guesses[k];
    if (fixed_z) {
      // (F16c) guesses that differ only in height are one start on the floor: solved once (same result, a third of
      // the cost with the default guesses, which share x and y)
      x(2) = *fixed_z;
      const auto same_xy = [&](const Vec3& g) { return g.x() == x(0) && g.y() == x(1); };
      if (std::any_of(initial_guesses.begin(), initial_guesses.begin() + static_cast<std::ptrdiff_t>(k), same_xy))
        continue;
    }
    MultilaterationResult res;
    double cost = 0.0;
    MatN A = MatN::Zero();
    for (int it = 0; it < max_iterations; ++it) {
      A.setZero();
      VecN g = VecN::Zero();
      cost = 0.0;
      double wr2 = 0.0, wsum = 0.0;
      std::size_t n = 0;
      for (const MultilaterationSample& s : samples) {
        const Moments3* a = anchors.find(s.z.id_a);
        const Moments3* b = anchors.find(s.z.id_b);
        if (!a || !b) continue;
        const double dt = s.z.t_s - t_ref_s;
        Vec3 w_p = x.template head<3>() + s.w_d_b;
        if constexpr (N == 6) w_p += dt * x.template tail<3>();
        TdoaJacobians J;
        const std::optional<double> h = evaluateTdoa(w_p, s.w_q_b, a->m, b->m, {b_t_tag, 1e-6}, &J);
        if (!h) continue;
        // (F16) r = z − h(p_i); Huber weight on |r|. ∂h/∂v0 = (t_i − t_ref) ∂h/∂p (F16b).
        const double r = s.z.tdoa_m - *h;
        const double ar = std::abs(r);
        const double w = ar <= huber_k_m ? 1.0 : huber_k_m / ar;
        cost += ar <= huber_k_m ? 0.5 * r * r : huber_k_m * (ar - 0.5 * huber_k_m);
        Eigen::Matrix<double, 1, N> row;
        row.template head<3>() = J.J_z_p_b;
        if constexpr (N == 6) row.template tail<3>() = dt * J.J_z_p_b;
        A.noalias() += w * row.transpose() * row;
        g.noalias() += w * row.transpose() * r;
        wr2 += w * r * r;
        wsum += w;
        ++n;
      }
      if (n < kMinUsed) break;
      if (fixed_z) {
        // (F16c) z is not an unknown: its row and column become the identity, its step zero
        A.row(2).setZero();
        A.col(2).setZero();
        A(2, 2) = 1.0;
        g(2) = 0.0;
      }
      const Eigen::LDLT<MatN> ldlt(A + 1e-9 * MatN::Identity());
      VecN step = ldlt.solve(g);
      if (!step.allFinite()) break;
      // limit the step: TDoA geometry can be strongly nonlinear far from the anchors' hull
      const double sn = step.template head<3>().norm();
      if (sn > 2.0) step.template head<3>() *= 2.0 / sn;
      if constexpr (N == 6) {
        const double vn = step.template tail<3>().norm();
        if (vn > 2.0) step.template tail<3>() *= 2.0 / vn;
      }
      x += step;
      res.iterations = it + 1;
      res.n_used = n;
      res.rms_residual_m = std::sqrt(wr2 / std::max(wsum, 1e-12));
      if (step.norm() < 1e-5) break;
    }
    if (res.n_used < kMinUsed || !x.allFinite()) continue;
    if (cost < best_cost) {
      best_cost = cost;
      res.w_p0 = x.template head<3>();
      const MatN Ainv = (A + 1e-9 * MatN::Identity()).inverse() * (res.rms_residual_m * res.rms_residual_m);
      res.covariance = Ainv.template topLeftCorner<3, 3>();
      if constexpr (N == 6) {
        res.w_v0 = x.template tail<3>();
        res.covariance_pv = Ainv;
      }
      best = res;
    }
  }
  return best;
}

}  // namespace

std::optional<MultilaterationResult> multilaterate(const std::vector<MultilaterationSample>& samples,
                                                   const AnchorTable& anchors, const Vec3& b_t_tag,
                                                   const std::vector<Vec3>& initial_guesses, double huber_k_m,
                                                   int max_iterations) {
  return solve<3>(samples, anchors, b_t_tag, initial_guesses, 0.0, huber_k_m, max_iterations);
}

std::optional<MultilaterationResult> multilaterateOnFloor(const std::vector<MultilaterationSample>& samples,
                                                          const AnchorTable& anchors, const Vec3& b_t_tag,
                                                          const std::vector<Vec3>& initial_guesses, double floor_z_m,
                                                          double huber_k_m, int max_iterations) {
  std::optional<MultilaterationResult> r =
      solve<3>(samples, anchors, b_t_tag, initial_guesses, 0.0, huber_k_m, max_iterations, floor_z_m);
  if (r) {
    r->covariance.row(2).setZero();
    r->covariance.col(2).setZero();
  }
  return r;
}

std::optional<MultilaterationResult> multilaterateMoving(const std::vector<MultilaterationSample>& samples,
                                                         const AnchorTable& anchors, const Vec3& b_t_tag,
                                                         const std::vector<Vec3>& initial_guesses, double t_ref_s,
                                                         double huber_k_m, int max_iterations) {
  if (samples.empty()) return std::nullopt;
  const auto [lo, hi] = std::minmax_element(samples.begin(), samples.end(), [](const auto& a, const auto& b) {
    return a.z.t_s < b.z.t_s;
  });
  if (hi->z.t_s - lo->z.t_s < 0.1) return std::nullopt;
  return solve<6>(samples, anchors, b_t_tag, initial_guesses, t_ref_s, huber_k_m, max_iterations);
}

}  // namespace uwb
