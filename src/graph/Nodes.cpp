/** @file Nodes.cpp
 *  @brief Gaussian node rules of Loeliger et al. 2007, Tables 2–4 (docs/math/message-passing.md G3–G10).
 */
#include "uwb/graph/Nodes.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <stdexcept>
#include <string>

namespace uwb {
namespace {

void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string(what) + ": dimension mismatch");
}
void checkMoments(const Moments& x, const char* what) {
  require(x.V.rows() == x.m.size() && x.V.cols() == x.m.size(), what);
}
void checkInformation(const Information& x, const char* what) {
  require(x.W.rows() == x.xi.size() && x.W.cols() == x.xi.size(), what);
}
MatX symmetrize(const MatX& A) { return 0.5 * (A + A.transpose()); }

}  // namespace

Information equality(const Information& x, const Information& y) {
  checkInformation(x, "equality");
  checkInformation(y, "equality");
  require(x.xi.size() == y.xi.size(), "equality");
  return {x.xi + y.xi, x.W + y.W};  // (G3)
}

std::optional<Moments> equality(const Moments& x, const Information& y) {
  checkMoments(x, "equality");
  checkInformation(y, "equality");
  require(x.m.size() == y.xi.size(), "equality");
  const Eigen::Index n = x.m.size();
  // (G4) (V⁻¹ + W)⁻¹ = (I + V W)⁻¹ V  and  m_Z = (V⁻¹ + W)⁻¹ (V⁻¹ m + ξ) = (I + V W)⁻¹ (m + V ξ).
  const Eigen::PartialPivLU<MatX> lu(MatX::Identity(n, n) + x.V * y.W);
  if (!(std::abs(lu.determinant()) > 1e-300)) return std::nullopt;
  Moments z{lu.solve(x.m + x.V * y.xi), symmetrize(lu.solve(x.V))};
  if (!z.m.allFinite() || !z.V.allFinite()) return std::nullopt;
  return z;
}

std::optional<Moments> equality(const Moments& x, const Moments& y) {
  checkMoments(x, "equality");
  checkMoments(y, "equality");
  require(x.m.size() == y.m.size(), "equality");
  // (G5) V_Z = V_X (V_X + V_Y)⁻¹ V_Y,  m_Z = m_X + V_X (V_X + V_Y)⁻¹ (m_Y − m_X).
  const Eigen::PartialPivLU<MatX> lu(x.V + y.V);
  if (!(std::abs(lu.determinant()) > 1e-300)) return std::nullopt;
  const MatX G_VY = lu.solve(y.V);  // (V_X + V_Y)⁻¹ V_Y
  Moments z{x.m + x.V * lu.solve(y.m - x.m), symmetrize(x.V * G_VY)};
  if (!z.m.allFinite() || !z.V.allFinite()) return std::nullopt;
  return z;
}

Moments multiplyForward(const MatX& A, const Moments& x) {
  checkMoments(x, "multiplyForward");
  require(A.cols() == x.m.size(), "multiplyForward");
  return {A * x.m, symmetrize(A * x.V * A.transpose())};  // (G6)
}

Information multiplyBackward(const MatX& A, const Information& y) {
  checkInformation(y, "multiplyBackward");
  require(A.rows() == y.xi.size(), "multiplyBackward");
  return {A.transpose() * y.xi, symmetrize(A.transpose() * y.W * A)};  // (G7)
}

Moments additionForward(const Moments& x, const Moments& y) {
  checkMoments(x, "additionForward");
  checkMoments(y, "additionForward");
  require(x.m.size() == y.m.size(), "additionForward");
  return {x.m + y.m, x.V + y.V};  // (G8)
}

Moments additionBackward(const Moments& z, const Moments& y) {
  checkMoments(z, "additionBackward");
  checkMoments(y, "additionBackward");
  require(z.m.size() == y.m.size(), "additionBackward");
  return {z.m - y.m, z.V + y.V};  // (G9)
}

Information additionBackwardConstant(const Information& z, const VecX& c) {
  checkInformation(z, "additionBackwardConstant");
  require(c.size() == z.xi.size(), "additionBackwardConstant");
  return {z.xi - z.W * c, z.W};  // (G9')
}

std::optional<Moments> equalityMultiply(const Moments& x, const MatX& A, const Moments& y) {
  checkMoments(x, "equalityMultiply");
  checkMoments(y, "equalityMultiply");
  require(A.cols() == x.m.size() && A.rows() == y.m.size(), "equalityMultiply");
  // (G10) G = (V_Y + A V_X Aᵀ)⁻¹, m_Z = m_X + V_X Aᵀ G (m_Y − A m_X), V_Z = V_X − V_X Aᵀ G A V_X.
  const MatX VAt = x.V * A.transpose();
  const MatX S = y.V + A * VAt;
  const Eigen::LDLT<MatX> ldlt(S);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return std::nullopt;
  Moments z{x.m + VAt * ldlt.solve(y.m - A * x.m), symmetrize(x.V - VAt * ldlt.solve(VAt.transpose()))};
  if (!z.m.allFinite() || !z.V.allFinite()) return std::nullopt;
  return z;
}

}  // namespace uwb
