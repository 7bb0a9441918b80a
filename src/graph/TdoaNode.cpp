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

TdoaNodeMessages tdoaNodeForward(const TdoaLinearization& lin, const Moments3& x_i, const Moments3& x_j,
                                 double z_m, double var_m2) {
  checkVariance(var_m2);
  TdoaNodeMessages msg;
  msg.mu3 = {-lin.B1.dot(x_i.m), lin.B1 * x_i.V * lin.B1.transpose()};  // (G11) µ3 = N(−B1 m1, B1 Σ1 B1ᵀ)
  msg.mu4 = {lin.B2.dot(x_j.m), lin.B2 * x_j.V * lin.B2.transpose()};   // (G11) µ4 = N(B2 m2, B2 Σ2 B2ᵀ)
  // (G12) µ7 = N(m6 − m3 − m4 − D, Σ6 + Σ3 + Σ4)
  msg.mu7 = {z_m - msg.mu3.m - msg.mu4.m - lin.D, var_m2 + msg.mu3.V + msg.mu4.V};
  msg.W7 = 1.0 / msg.mu7.V;  // (G1) W7 = Σ7⁻¹ (Σ7 ≥ Σ6 > 0)
  msg.xi7 = msg.W7 * msg.mu7.m;
  msg.B12 = lin.B12();
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
