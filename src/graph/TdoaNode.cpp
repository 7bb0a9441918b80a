/** @file TdoaNode.cpp
 *  @brief TDoA node messages of paper III-A / Fig. 2 (docs/math/message-passing.md G11–G14).
 */
#include "uwb/graph/TdoaNode.h"

#include <cmath>
#include <stdexcept>

namespace uwb {
namespace {

void checkVariance(double var_m2) {
  if (!(var_m2 > 0.0) || !std::isfinite(var_m2)) {
    throw std::invalid_argument("TDoA node: measurement variance must be finite and > 0");
  }
}

}  // namespace

TdoaNodeMessages tdoaNodeForwardToTag(const TdoaLinearization& lin, const Moments3& x_i, const Moments3& x_j,
                                      double z_m, double var_m2) {
  checkVariance(var_m2);
  TdoaNodeMessages msg;
  // (G11) µ3 = N(−B1 m1, B1 Σ1 B1ᵀ), µ4 = N(B2 m2, B2 Σ2 B2ᵀ); B Σ Bᵀ = 0 for an exact (zero-covariance) anchor
  msg.mu3.m = -lin.B1.dot(x_i.m);
  msg.mu4.m = lin.B2.dot(x_j.m);
  // (a covariance with a zero diagonal is zero: |Σ_ij| ≤ √(Σ_ii Σ_jj))
  if (!x_i.V.diagonal().isZero(0.0)) msg.mu3.V = lin.B1 * x_i.V * lin.B1.transpose();
  if (!x_j.V.diagonal().isZero(0.0)) msg.mu4.V = lin.B2 * x_j.V * lin.B2.transpose();
  // (G12) µ7 = N(m6 − m3 − m4 − D, Σ6 + Σ3 + Σ4)
  msg.mu7 = {z_m - msg.mu3.m - msg.mu4.m - lin.D, var_m2 + msg.mu3.V + msg.mu4.V};
  msg.B12 = lin.B12();
  return msg;
}

TdoaNodeMessages tdoaNodeForward(const TdoaLinearization& lin, const Moments3& x_i, const Moments3& x_j,
                                 double z_m, double var_m2) {
  TdoaNodeMessages msg = tdoaNodeForwardToTag(lin, x_i, x_j, z_m, var_m2);  // (G11, G12)
  msg.W7 = 1.0 / msg.mu7.V;  // (G1) W7 = Σ7⁻¹ (Σ7 ≥ Σ6 > 0)
  msg.xi7 = msg.W7 * msg.mu7.m;
  // (G13) ξ8 = B12ᵀ ξ7, W8 = B12ᵀ W7 B12
  msg.mu8.xi = msg.B12.transpose() * msg.xi7;
  msg.mu8.W = msg.B12.transpose() * msg.W7 * msg.B12;
  return msg;
}

Information3 tdoaNodeBackwardToI(const TdoaLinearization& lin, const Moments3& x_k, const Moments3& x_j, double z_m,
                                 double var_m2) {
  checkVariance(var_m2);
  const RowVec3 B12 = lin.B12();
  // (G14) −B1 x_i = z − D − B12 x_k − B2 x_j − ε
  const double m = z_m - lin.D - B12.dot(x_k.m) - lin.B2.dot(x_j.m);
  const double s = var_m2 + B12 * x_k.V * B12.transpose() + lin.B2 * x_j.V * lin.B2.transpose();
  // backward through the multiplication node −B1 (G7)
  return {-lin.B1.transpose() * (m / s), lin.B1.transpose() * lin.B1 / s};
}

Information3 tdoaNodeBackwardToJ(const TdoaLinearization& lin, const Moments3& x_k, const Moments3& x_i, double z_m,
                                 double var_m2) {
  checkVariance(var_m2);
  const RowVec3 B12 = lin.B12();
  // (G14) B2 x_j = z − D − B12 x_k + B1 x_i − ε
  const double m = z_m - lin.D - B12.dot(x_k.m) + lin.B1.dot(x_i.m);
  const double s = var_m2 + B12 * x_k.V * B12.transpose() + lin.B1 * x_i.V * lin.B1.transpose();
  return {lin.B2.transpose() * (m / s), lin.B2.transpose() * lin.B2 / s};  // (G7) through B2
}

}  // namespace uwb
