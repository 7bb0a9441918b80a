/** @file GaussianMessage.cpp
 *  @brief Moment ↔ information conversions (docs/math/message-passing.md G1–G2).
 */
#include "uwb/graph/GaussianMessage.h"

#include <Eigen/Cholesky>
#include <stdexcept>

namespace uwb {
namespace {

void checkSquare(const MatX& M, Eigen::Index n, const char* what) {
  if (M.rows() != n || M.cols() != n) throw std::invalid_argument(std::string(what) + ": dimension mismatch");
}

/// Inverse of a symmetric positive definite matrix via Cholesky; nullopt if not PD.
std::optional<MatX> spdInverse(const MatX& A) {
  const Eigen::LLT<MatX> llt(A);
  if (llt.info() != Eigen::Success) return std::nullopt;
  MatX inv = llt.solve(MatX::Identity(A.rows(), A.cols()));
  return MatX(0.5 * (inv + inv.transpose()));
}

}  // namespace

std::optional<Information> toInformation(const Moments& x) {
  checkSquare(x.V, x.m.size(), "toInformation");
  std::optional<MatX> W = spdInverse(x.V);  // (G1) W = V⁻¹
  if (!W) return std::nullopt;
  Information out{(*W) * x.m, std::move(*W)};  // (G1) ξ = W m
  return out;
}

std::optional<Moments> toMoments(const Information& x) {
  checkSquare(x.W, x.xi.size(), "toMoments");
  std::optional<MatX> V = spdInverse(x.W);  // (G2) V = W⁻¹
  if (!V) return std::nullopt;
  Moments out{(*V) * x.xi, std::move(*V)};  // (G2) m = V ξ
  return out;
}

std::optional<Moments> asMoments(const GaussianMessage& msg) {
  if (const auto* m = std::get_if<Moments>(&msg)) return *m;
  return toMoments(std::get<Information>(msg));
}

std::optional<Information> asInformation(const GaussianMessage& msg) {
  if (const auto* i = std::get_if<Information>(&msg)) return *i;
  return toInformation(std::get<Moments>(msg));
}

}  // namespace uwb
