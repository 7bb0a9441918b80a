/** @file Multilateration.cpp
 *  @brief Robust Gauss–Newton TDoA multilateration (docs/math/filter.md F16).
 */
#include "uwb/filter/Multilateration.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

#include "uwb/model/TdoaModel.h"

namespace uwb {

std::optional<MultilaterationResult> multilaterate(const std::vector<MultilaterationSample>& samples,
                                                   const AnchorTable& anchors, const Vec3& b_t_tag,
                                                   const std::vector<Vec3>& initial_guesses, double huber_k_m,
                                                   int max_iterations) {
  if (samples.size() < 4) return std::nullopt;
  std::optional<MultilaterationResult> best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (const Vec3& guess : initial_guesses) {
    Vec3 p0 = guess;
    MultilaterationResult res;
    double cost = 0.0;
    Mat3 A = Mat3::Zero();
    for (int it = 0; it < max_iterations; ++it) {
      A.setZero();
      Vec3 g = Vec3::Zero();
      cost = 0.0;
      double wr2 = 0.0, wsum = 0.0;
      std::size_t n = 0;
      for (const MultilaterationSample& s : samples) {
        const Moments3* a = anchors.find(s.z.id_a);
        const Moments3* b = anchors.find(s.z.id_b);
        if (!a || !b) continue;
        TdoaJacobians J;
        const std::optional<double> h = evaluateTdoa(p0 + s.w_d_b, s.w_q_b, a->m, b->m, {b_t_tag, 1e-6}, &J);
        if (!h) continue;
        // (F16) r = z − h(p0 + d_i); Huber weight on |r|
        const double r = s.z.tdoa_m - *h;
        const double ar = std::abs(r);
        const double w = ar <= huber_k_m ? 1.0 : huber_k_m / ar;
        cost += ar <= huber_k_m ? 0.5 * r * r : huber_k_m * (ar - 0.5 * huber_k_m);
        A.noalias() += w * J.J_z_p_b.transpose() * J.J_z_p_b;
        g.noalias() += w * J.J_z_p_b.transpose() * r;
        wr2 += w * r * r;
        wsum += w;
        ++n;
      }
      if (n < 4) break;
      const Eigen::LDLT<Mat3> ldlt(A + 1e-9 * Mat3::Identity());
      const Vec3 step = ldlt.solve(g);
      if (!step.allFinite()) break;
      // limit the step: TDoA geometry can be strongly nonlinear far from the anchors' hull
      const double sn = step.norm();
      p0 += sn > 2.0 ? (2.0 / sn) * step : step;
      res.iterations = it + 1;
      res.n_used = n;
      res.rms_residual_m = std::sqrt(wr2 / std::max(wsum, 1e-12));
      if (sn < 1e-5) break;
    }
    if (res.n_used < 4 || !p0.allFinite()) continue;
    if (cost < best_cost) {
      best_cost = cost;
      res.w_p0 = p0;
      const Mat3 Ainv = (A + 1e-9 * Mat3::Identity()).inverse();
      res.covariance = Ainv * res.rms_residual_m * res.rms_residual_m;
      best = res;
    }
  }
  return best;
}

}  // namespace uwb
