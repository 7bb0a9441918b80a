/** @file CooperativeRange.h
 *  @brief An agent's two-way range (TWR) to a neighbouring agent whose position is known only as a broadcast
 *         Gaussian belief: the neighbour is an uncertain anchor (docs/math/message-passing.md G20, the range analogue
 *         of the G11–G12 TDoA node), and the neighbour's belief, which may already contain this agent's own earlier
 *         information, is fused by covariance intersection (G21) so that repeated exchanges do not make either
 *         agent over-confident. Beliefs age between broadcasts (G22).
 */
#pragma once

#include <optional>

#include "uwb/filter/Ekf.h"
#include "uwb/filter/OutlierGate.h"
#include "uwb/graph/GaussianMessage.h"

namespace uwb {

/// (G20) Predicted range h = |p_tag(x) − m_j| from this agent's tag to the neighbour's tag mean m_j (M3), with
/// a = ∂h/∂δx (non-zero in δp and δθ, through M4) and J_j = ∂h/∂m_j = −∂h/∂p_tag when non-null. nullopt when the
/// two are closer than 1 mm (no direction).
std::optional<double> cooperativeRangePrediction(const NavState& x, const Vec3& b_t_tag, const Vec3& w_p_neighbour,
                                                 ErrRow* a = nullptr, RowVec3* J_neighbour = nullptr);

/// How a neighbour's belief enters (G21).
enum class NeighbourFusion : unsigned char {
  kNaive,                   ///< as if independent of this agent's state: s = σ² + J_j Σ_j J_jᵀ (double counts)
  kCovarianceIntersection,  ///< position prior P_pp/ω and neighbour Σ_j/(1 − ω), ω minimising the position trace (G21)
};

/// (G21) The covariance-intersection weight ω ∈ (0, 1] that minimises the trace of the posterior position block
/// tr(P⁺_pp) = T/ω − u/(ω² S(ω)), S(ω) = aPaᵀ − q + q/ω + s_indep + s_dep/(1 − ω), given T = tr(P_pp),
/// u = |P_p· aᵀ|² (position rows of P aᵀ), aPa = a P aᵀ, its part through the position q = (P_p· aᵀ)ᵀ P_pp⁻¹ P_p· aᵀ
/// (q = aPa when a observes the position alone), the independent noise s_indep = σ² and the neighbour term
/// s_dep = J_j Σ_j J_jᵀ. Returns 1 when s_dep = 0 (nothing correlated: the ordinary update).
double covarianceIntersectionWeight(double T, double u, double aPa, double q, double s_indep, double s_dep);

struct CooperativeRangeOptions {
  double sigma_m = 0.1;     ///< TWR noise std [m]
  double gate_sigma = 4.0;  ///< χ² gate on √NIS (F11); ≤ 0 disables
  NeighbourFusion fusion = NeighbourFusion::kCovarianceIntersection;
  Vec3 b_t_tag = kUtilTagOffset_b;
};

struct CooperativeRangeResult {
  UpdateOutcome outcome = UpdateOutcome::kSkipped;  ///< kSkipped: non-finite range; kDegenerate: agents coincide
  double innovation_m = 0.0;  ///< z − h(x̂)
  double nis = 0.0;           ///< r²/S with the S the update used
  double omega = 1.0;         ///< covariance-intersection weight (1 for kNaive)
};

/// Full cooperative range update of `ekf` (G20, G21, gate F11, equality node G18, reset F8). `neighbour` is the
/// neighbour's tag-position belief (aged to the measurement time by the caller, G22). The covariance should be
/// propagated by the caller.
CooperativeRangeResult updateCooperativeRange(Ekf& ekf, const Moments3& neighbour, double range_m,
                                              const CooperativeRangeOptions& options);

/// The tag-position belief an agent broadcasts: m = p + R b_t (M4), Σ = C Σ_pose Cᵀ with C = [I, −R[b_t]×] and
/// Σ_pose the 6×6 covariance of (δp, δθ) (LocalizerEstimate::cov_pose).
Moments3 tagBelief(const NavState& x, const Eigen::Matrix<double, 6, 6>& cov_pose, const Vec3& b_t_tag);

/// (G22) A belief broadcast age_s ago, brought to now: m + v age, Σ + age² Σ_v + (a_max age²/2)² I, with the
/// sender's velocity mean v and covariance Σ_v and a bound a_max on the unmodelled acceleration. |age| is used
/// (a belief may be slightly newer than the measurement).
Moments3 ageBelief(const Moments3& belief, const Vec3& w_v, const Mat3& cov_v, double age_s, double a_max_mps2);

}  // namespace uwb
