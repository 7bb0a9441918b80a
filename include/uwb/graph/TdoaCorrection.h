/** @file TdoaCorrection.h
 *  @brief The Kalman-filter correction step of paper Fig. 3 built from graph nodes: the TDoA node's message on
 *         the tag position x_k, passed backward through x_k = x̃_k + C δx (addition of a constant, then the
 *         multiplication node C), combined with the predicted state in an equality node
 *         (docs/math/message-passing.md G15–G18).
 *
 *  Fast path (header-only template on the state dimension N, e.g. N = 15): no heap allocation, no n×n inverse.
 *  The message on δx has rank one (W = aᵀ a / s), so the equality node is used in its Kalman-gain form
 *  (Table 4; G10 with a scalar Y); the Joseph-form covariance reduces, for the optimal rank-one gain, to O(N²):
 *    u = V aᵀ,  S = a u + s,  K = u / S,
 *    m⁺ = m + K (y − a m),
 *    V⁺ = (I − K a) V (I − K a)ᵀ + K s Kᵀ = V − K uᵀ − u Kᵀ + S K Kᵀ = V − w wᵀ,  w = u/√S   (G18).
 *  The last form keeps a symmetric V exactly symmetric; zero entries of a (blocks C does not touch) are skipped.
 *
 *  Recipe for the filter (UTIL convention tdoa = |p − a_B| − |p − a_A|, right attitude error q ⊗ exp(δθ)):
 *  @code
 *    const Vec3 p_tag = tagPosition(w_p_b, w_q_b, b_t_tag);                       // x̃_k
 *    auto lin = linearizeTdoa(p_tag, anchor_b.m, anchor_a.m);                      // x_i = B, x_j = A
 *    if (!lin) → degenerate;
 *    TdoaNodeMessages msg = tdoaNodeForward(*lin, anchor_b, anchor_a, z_m - bias_m, var_m2);
 *    Eigen::Matrix<double, 3, 15> C = 0;  C.block<3,3>(0, kPos) = I;
 *    C.block<3,3>(0, kAttErr) = tagPositionJacobianAttitude(w_q_b, b_t_tag);      // −R [b_t]×
 *    ScalarLinearMessage<15> on_state = tdoaMessageOnState<15>(msg, C, p_tag);     // gate on innovationOf(...)
 *    std::optional<InnovationStats> st = equalityRankOneInPlace<15>(dx, P, on_state);  // dx, P updated
 *  @endcode
 *  With dx = 0 (error state), the innovation equals z − ẑ(x̃) exactly (G16).
 */
#pragma once

#include <cmath>
#include <optional>

#include "uwb/graph/GaussianMessage.h"
#include "uwb/graph/TdoaNode.h"

namespace uwb {

/// A rank-one Gaussian message on a state δx (dimension N), kept in factored form: the scalar pseudo-observation
/// y = a δx + v, v ~ N(0, var). Its information view is ξ = aᵀ y / var, W = aᵀ a / var (G15).
template <int N>
struct ScalarLinearMessage {
  Eigen::Matrix<double, 1, N> a;
  double y = 0.0;    ///< pseudo-observation [m]
  double var = 0.0;  ///< its variance Σ7 [m²]
  /// The same message in information form (G15): ξ = aᵀ y / var, W = aᵀ a / var.
  GaussianInformation<N> information() const { return {a.transpose() * (y / var), a.transpose() * a / var}; }
};

/// Innovation statistics of a scalar correction: r = y − a m, S = a V aᵀ + var, NIS = r² / S (G17).
struct InnovationStats {
  double innovation_m = 0.0;
  double innovation_var_m2 = 0.0;
  double nis = 0.0;
};

/// Posterior of a TDoA correction plus its innovation statistics.
template <int N>
struct TdoaCorrection {
  GaussianMoments<N> posterior;
  InnovationStats stats;
};

/// (G16) TDoA node message on x_k (paper µ7 on B12 x_k, equivalently ξ8/W8) passed backward through the addition
/// of the linearization point x̃_k and the multiplication node C = ∂x_k/∂δx (3×N), i.e. x_k = x̃_k + C δx:
///   a = B12 C,  y = m7 − B12 x̃_k,  var = Σ7.
template <int N>
ScalarLinearMessage<N> tdoaMessageOnState(const TdoaNodeMessages& msg, const Eigen::Matrix<double, 3, N>& C,
                                          const Vec3& x_k_lin) {
  ScalarLinearMessage<N> out;
  out.a.noalias() = msg.B12 * C;
  out.y = msg.mu7.m - msg.B12.dot(x_k_lin);
  out.var = msg.mu7.V;
  return out;
}

/// (G17) Innovation r = y − a m, its variance S = a V aᵀ + var, and NIS = r²/S, before applying the update
/// (for gating). S > 0 unless the prior and the measurement are both exact along a.
template <int N>
InnovationStats innovationOf(const ScalarLinearMessage<N>& msg, const Eigen::Matrix<double, N, 1>& m,
                             const Eigen::Matrix<double, N, N>& V) {
  InnovationStats st;
  st.innovation_m = msg.y - msg.a.dot(m.transpose());
  st.innovation_var_m2 = (msg.a * V).dot(msg.a) + msg.var;
  st.nis = st.innovation_m * st.innovation_m / st.innovation_var_m2;
  return st;
}

namespace detail {

/// V ← V − w wᵀ column by column (the O(N²) part of G18). For a fixed N ≥ 4 each column runs in full 4-wide SIMD
/// packets (Eigen vectorises a fixed 15-row column only with 2-wide packets): its first 4⌊N/4⌋ rows, and for the
/// remaining rows one packet over the last 4 rows, computed from the column's values before the update and stored
/// after the bulk; the rows both packets cover get the same value V_ij − w_i w_j from each, so no row is downdated
/// twice (15 rows: 4 packets instead of 3 packets, a pair and a scalar). Element (i, j) is V_ij − w_i w_j either way,
/// so a symmetric V stays exactly symmetric.
template <int N>
void rankOneDowndate(Eigen::Matrix<double, N, N>& V, const Eigen::Matrix<double, N, 1>& w) {
  if constexpr (N == Eigen::Dynamic || N < 4) {
    V.noalias() -= w * w.transpose();
  } else {
    constexpr int kBulk = N / 4 * 4;
    // w in locals: V's stores cannot alias them, so w's packets stay in registers across the columns
    const Eigen::Matrix<double, kBulk, 1> w_bulk = w.template head<kBulk>();
    const Eigen::Matrix<double, 4, 1> w_last = w.template tail<4>();
#pragma GCC unroll 16
    for (int j = 0; j < N; ++j) {
      const double w_j = w(j);
      if constexpr (N > kBulk) {
        const Eigen::Matrix<double, 4, 1> last = V.col(j).template tail<4>() - w_j * w_last;
        V.col(j).template head<kBulk>() -= w_j * w_bulk;
        V.col(j).template tail<4>() = last;
      } else {
        V.col(j).template head<kBulk>() -= w_j * w_bulk;
      }
    }
  }
}

/// Tail of the (G18) equality node once u = V aᵀ and a m are known: innovation statistics, m⁺ = m + K r, V⁺ = V − w wᵀ.
template <int N>
std::optional<InnovationStats> applyRankOneGain(Eigen::Matrix<double, N, 1>& m, Eigen::Matrix<double, N, N>& V,
                                                const ScalarLinearMessage<N>& msg, const Eigen::Matrix<double, N, 1>& u,
                                                double a_m, double a_u) {
  InnovationStats st;
  st.innovation_m = msg.y - a_m;
  st.innovation_var_m2 = a_u + msg.var;
  if (!(st.innovation_var_m2 > 0.0) || !std::isfinite(st.innovation_var_m2) || !std::isfinite(st.innovation_m)) {
    return std::nullopt;
  }
  st.nis = st.innovation_m * st.innovation_m / st.innovation_var_m2;
  const double S = st.innovation_var_m2;
  m.noalias() += u * (st.innovation_m / S);  // m⁺ = m + K r, K = u / S
  // Joseph form (I − K a) V (I − K a)ᵀ + K var Kᵀ = V − K uᵀ − u Kᵀ + S K Kᵀ, which for the optimal rank-one gain
  // K = u/S equals V − u uᵀ/S = V − w wᵀ with w = u/√S. Evaluated as w wᵀ, element (i, j) and (j, i) are the same
  // floating-point product, so a symmetric V stays exactly symmetric without a mirror pass.
  const Eigen::Matrix<double, N, 1> w = u * (1.0 / std::sqrt(S));
  rankOneDowndate<N>(V, w);
  return st;
}

}  // namespace detail

/// (G18) Equality node combining the prior N(m, V) (moment form) with a rank-one message, Kalman-gain form
/// (Table 4), Joseph-equivalent covariance update, in place. V must be symmetric (it then stays exactly symmetric). Returns the innovation statistics, or nullopt (and leaves m, V
/// untouched) when S ≤ 0 or anything is not finite.
template <int N>
std::optional<InnovationStats> equalityRankOneInPlace(Eigen::Matrix<double, N, 1>& m, Eigen::Matrix<double, N, N>& V,
                                                      const ScalarLinearMessage<N>& msg) {
  // u = V aᵀ, skipping the zero entries of a.
  Eigen::Matrix<double, N, 1> u = Eigen::Matrix<double, N, 1>::Zero(V.rows());
  for (Eigen::Index c = 0; c < V.cols(); ++c) {
    if (msg.a[c] != 0.0) u.noalias() += V.col(c) * msg.a[c];
  }
  return detail::applyRankOneGain<N>(m, V, msg, u, msg.a.dot(m.transpose()), msg.a.dot(u.transpose()));
}

/// (G18) The same equality node for a message whose row a is zero outside the two 3-blocks starting at b0 and b1
/// (a TDoA message a = B12 C touches only δp and δθ, G16). Exploits that sparsity: u = V aᵀ and a m are formed from
/// those 6 columns / entries only (fixed-size 15×3 blocks, no per-column test); the O(N²) rank-one downdate is
/// unchanged. Equal to equalityRankOneInPlace up to floating-point summation order. Precondition: a is zero
/// outside [b0, b0+3) ∪ [b1, b1+3).
template <int N>
std::optional<InnovationStats> equalityRankOneTwoBlocksInPlace(Eigen::Matrix<double, N, 1>& m,
                                                               Eigen::Matrix<double, N, N>& V,
                                                               const ScalarLinearMessage<N>& msg, int b0, int b1) {
  const Vec3 a0 = msg.a.template segment<3>(b0).transpose();
  const Vec3 a1 = msg.a.template segment<3>(b1).transpose();
  Eigen::Matrix<double, N, 1> u;
  u.noalias() = V.template middleCols<3>(b0) * a0;
  u.noalias() += V.template middleCols<3>(b1) * a1;
  const double a_m = a0.dot(m.template segment<3>(b0)) + a1.dot(m.template segment<3>(b1));
  const double a_u = a0.dot(u.template segment<3>(b0)) + a1.dot(u.template segment<3>(b1));
  return detail::applyRankOneGain<N>(m, V, msg, u, a_m, a_u);
}

/// (G16–G18) The whole correction step of Fig. 3 for one TDoA, by value.
template <int N>
std::optional<TdoaCorrection<N>> correctTdoa(const GaussianMoments<N>& prior, const Eigen::Matrix<double, 3, N>& C,
                                             const Vec3& x_k_lin, const TdoaNodeMessages& msg) {
  TdoaCorrection<N> out{prior, {}};
  const ScalarLinearMessage<N> on_state = tdoaMessageOnState<N>(msg, C, x_k_lin);
  const std::optional<InnovationStats> st = equalityRankOneInPlace<N>(out.posterior.m, out.posterior.V, on_state);
  if (!st) return std::nullopt;
  out.stats = *st;
  return out;
}

/// Reference (slow, dynamic-size) route through the generic node functions, in information form: ξ8/W8 →
/// additionBackwardConstant(x̃_k) → multiplyBackward(C) → equality(moments, information). Used by tests to show
/// that the fast path is the same message passing; nullopt if the equality node fails.
std::optional<Moments> correctTdoaByMessages(const Moments& prior, const MatX& C, const Vec3& x_k_lin,
                                             const TdoaNodeMessages& msg);

}  // namespace uwb
