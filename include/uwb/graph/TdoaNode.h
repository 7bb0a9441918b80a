/** @file TdoaNode.h
 *  @brief The TDoA node of the paper (Fig. 2, III-A) as Gaussian message passing on the linearized model
 *         ẑ ≈ D + B12 x_k − B1 x_i + B2 x_j  (eq. 4; docs/math/message-passing.md G11–G14).
 *
 *  Edges (paper Fig. 2): 1 = x_i, 2 = x_j, 3 = −B1 x_i, 4 = B2 x_j, 5 = B12 x_k + D-shifted sum, 6 = measured z,
 *  7 = the message on B12 x_k, 8 = the message on x_k.
 *    µ3 = N(−B1 m1, B1 Σ1 B1ᵀ)                         (G11, multiplication node −B1, forward)
 *    µ4 = N( B2 m2, B2 Σ2 B2ᵀ)                         (G11, multiplication node  B2, forward)
 *    µ7 = N(m6 − m3 − m4 − D, Σ6 + Σ3 + Σ4)            (G12, addition nodes, backward)
 *    W7 = Σ7⁻¹, ξ7 = W7 m7                             (G1)
 *    ξ8 = B12ᵀ ξ7, W8 = B12ᵀ W7 B12,  B12 = B1 − B2   (G13, multiplication node B12, backward; rank one)
 *  Anchors (or other agents) are Gaussian variables with their own mean and covariance; a surveyed anchor has a
 *  small covariance, and a zero covariance is allowed.
 *
 *  UTIL convention: tdoa = |p − a_B| − |p − a_A| ⇒ x_i = anchor B, x_j = anchor A (see TdoaLinearization.h).
 */
#pragma once

#include "uwb/graph/GaussianMessage.h"
#include "uwb/model/TdoaLinearization.h"

namespace uwb {

/// A scalar Gaussian N(m, V).
struct ScalarGaussian {
  double m = 0.0;
  double V = 0.0;
};

/// All messages of the TDoA node's forward pass (paper III-A), fixed size, no heap allocation.
struct TdoaNodeMessages {
  ScalarGaussian mu3;           ///< −B1 x_i
  ScalarGaussian mu4;           ///<  B2 x_j
  ScalarGaussian mu7;           ///< message on B12 x_k: N(m7, Σ7)
  double W7 = 0.0;              ///< Σ7⁻¹ [1/m²]
  double xi7 = 0.0;             ///< W7 m7
  RowVec3 B12 = RowVec3::Zero();  ///< B1 − B2
  Information3 mu8;             ///< message on x_k: ξ8 = B12ᵀ ξ7, W8 = B12ᵀ W7 B12 (rank one)
};

/// The forward pass up to the message on B12 x_k (G11–G12): µ3, µ4, µ7 and B12; W7, ξ7 and µ8 are left at zero. The
/// message on the tag's error state (the filter's G16) needs no more. The anchor terms B Σ Bᵀ of Σ7 are skipped for
/// anchors with zero covariance (surveyed anchors), where they are 0; the anchors' Σ must be covariances (symmetric
/// positive semi-definite), so that a zero diagonal means Σ = 0. Throws std::invalid_argument if var_m2 is not
/// finite and > 0.
TdoaNodeMessages tdoaNodeForwardToTag(const TdoaLinearization& lin, const Moments3& x_i, const Moments3& x_j,
                                      double z_m, double var_m2);

/// Forward pass of the TDoA node (G11–G13): tdoaNodeForwardToTag and the message on x_k (G13). z_m = m6 is the measured TDoA, already bias-corrected by the
/// caller; var_m2 = Σ6 is its variance (possibly inflated by the caller, e.g. GP variance or robust weight).
/// x_i, x_j: beliefs of the two anchors (or agents) in the paper's order (UTIL: x_i = anchor B, x_j = anchor A).
/// Throws std::invalid_argument if var_m2 is not finite and > 0.
TdoaNodeMessages tdoaNodeForward(const TdoaLinearization& lin, const Moments3& x_i, const Moments3& x_j,
                                 double z_m, double var_m2);

/// (G14) Backward message of the TDoA node toward x_i, given beliefs of x_k and x_j:
///   −B1 x_i ~ N(z − D − B12 m_k − B2 m_j, Σ6 + B12 Σ_k B12ᵀ + B2 Σ_j B2ᵀ) =: N(m, s),
///   ξ_i = −B1ᵀ m / s,  W_i = B1ᵀ B1 / s.   For cooperative localization (an agent as "anchor").
Information3 tdoaNodeBackwardToI(const TdoaLinearization& lin, const Moments3& x_k, const Moments3& x_j, double z_m,
                                 double var_m2);

/// (G14) Backward message toward x_j, given beliefs of x_k and x_i:
///   B2 x_j ~ N(z − D − B12 m_k + B1 m_i, Σ6 + B12 Σ_k B12ᵀ + B1 Σ_i B1ᵀ) =: N(m, s),
///   ξ_j = B2ᵀ m / s,  W_j = B2ᵀ B2 / s.
Information3 tdoaNodeBackwardToJ(const TdoaLinearization& lin, const Moments3& x_k, const Moments3& x_i, double z_m,
                                 double var_m2);

/// (G13 generalized) Backward message toward x_k from the node, given x_i, x_j: identical to mu8 of the forward pass.
inline Information3 tdoaNodeBackwardToK(const TdoaLinearization& lin, const Moments3& x_i, const Moments3& x_j,
                                        double z_m, double var_m2) {
  return tdoaNodeForward(lin, x_i, x_j, z_m, var_m2).mu8;
}

}  // namespace uwb
