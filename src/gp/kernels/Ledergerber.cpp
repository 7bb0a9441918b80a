/** @file Ledergerber.cpp
 *  @brief The Ledergerber part: value (P4), gradient (P10), batch column (P32), one-point chunk.
 */
#include "uwb/gp/kernels/Parts.h"

#include <nlohmann/json.hpp>
#include <stdexcept>

#include "ScaledExp.h"

namespace uwb::gp {

namespace {

/// Row norms of a n×3 matrix; throws when one is (numerically) zero: k_L is undefined at x = 0 (P4).
VecX rowNorms(const MatX& A) {
  VecX n = A.rowwise().norm();
  if (n.size() > 0 && n.minCoeff() < 1e-12) {
    throw std::invalid_argument("ledergerber kernel: input vector of zero norm (k_L is undefined at x = 0)");
  }
  return n;
}

/// The rows of A scaled to unit length, and their norms (P4: γ = xᵀx'/(n n')).
struct UnitRows {
  VecX norm;
  MatX unit;
};
UnitRows unitRows(const MatX& A) {
  UnitRows u;
  u.norm = rowNorms(A);
  u.unit = u.norm.cwiseInverse().asDiagonal() * A;
  return u;
}

/// (P4) Exponent of the Ledergerber kernel, −(1 − γ)/θ1 − (n − n')²/θ2, with dn = n − n'.
template <class G, class N>
auto ledergerberExponent(const G& gamma, const N& dn, double t1, double t2) {
  return -(1.0 - gamma) / t1 - dn.square() / t2;
}

struct LedergerberPrepared final : PreparedBlock {
  MatX A, B;    ///< unit rows
  VecX na, nb;  ///< norms
};

}  // namespace

LedergerberPart::LedergerberPart(const PartSpec& spec, const std::string& prefix, ParamList& params)
    : KernelPart(spec.active_dims, static_cast<int>(params.values.size())) {
  if (spec.active_dims.size() != 3) throw std::invalid_argument("ledergerber kernel part needs exactly 3 active dims");
  params.add(prefix, "t0", spec.sigma2, true);
  params.add(prefix, "t1", spec.t1, true);
  params.add(prefix, "t2", spec.t2, true);
}

PartSpec LedergerberPart::spec(const VecX& theta, const std::vector<bool>&) const {
  PartSpec s;
  s.type = PartType::kLedergerber;
  s.active_dims = active_dims_;
  s.sigma2 = theta[offset_];
  s.t1 = theta[offset_ + 1];
  s.t2 = theta[offset_ + 2];
  s.l.clear();
  s.T.clear();
  return s;
}

MatX LedergerberPart::block(const MatX& A, const MatX& B, const VecX& theta) const {
  // θ0 exp(−(1 − γ)/θ1 − (n − n')²/θ2), γ = xᵀx'/(n n')  (P4)
  const double t1 = theta[offset_ + 1], t2 = theta[offset_ + 2];
  const UnitRows ua = unitRows(A), ub = unitRows(B);
  const VecX &na = ua.norm, &nb = ub.norm;
  MatX K(A.rows(), B.rows());
  K.noalias() = ua.unit * ub.unit.transpose();  // γ
  for (Eigen::Index j = 0; j < B.rows(); ++j)
    K.col(j).array() = ledergerberExponent(K.col(j).array(), na.array() - nb[j], t1, t2);
  K = theta[offset_] * K.array().exp();
  return K;
}

std::unique_ptr<PreparedBlock> LedergerberPart::prepare(MatX A, MatX B, const VecX&) const {
  auto q = std::make_unique<LedergerberPrepared>();
  UnitRows ua = unitRows(A), ub = unitRows(B);
  q->na = std::move(ua.norm), q->A = std::move(ua.unit);
  q->nb = std::move(ub.norm), q->B = std::move(ub.unit);
  return q;
}

void LedergerberPart::column(const PreparedBlock& prepared, Eigen::Index j, const VecX& theta,
                             double* out_data) const {
  const auto& q = static_cast<const LedergerberPrepared&>(prepared);
  const Eigen::Index n1 = q.A.rows();
  Eigen::Map<Eigen::ArrayXd> out(out_data, n1);
  // θ0 exp(−(1 − γ)/θ1 − (n − n')²/θ2), γ = xᵀx'/(n n')  (P4)
  const double t1 = theta[offset_ + 1], t2 = theta[offset_ + 2];
  const auto gamma =
      q.A.col(0).array() * q.B(j, 0) + q.A.col(1).array() * q.B(j, 1) + q.A.col(2).array() * q.B(j, 2);
  out = ledergerberExponent(gamma, q.na.array() - q.nb[j], t1, t2);
  detail::scaledExpInPlace(out.data(), n1, 1.0, theta[offset_]);
}

void LedergerberPart::multiplyChunk(const MatX& X1, Eigen::Index i0, const Eigen::Ref<const RowVecX>& x,
                                    const VecX& theta, Chunk& prod) const {
  const Eigen::Index c = prod.size();
  const double t1 = theta[offset_ + 1], t2 = theta[offset_ + 2];
  const int d0 = active_dims_[0], d1 = active_dims_[1], d2 = active_dims_[2];
  const double nb = std::sqrt(x[d0] * x[d0] + x[d1] * x[d1] + x[d2] * x[d2]);
  const auto a0 = X1.col(d0).segment(i0, c).array(), a1 = X1.col(d1).segment(i0, c).array(),
             a2 = X1.col(d2).segment(i0, c).array();
  const Chunk na = (a0.square() + a1.square() + a2.square()).sqrt();
  if (nb < 1e-12 || na.minCoeff() < 1e-12)
    throw std::invalid_argument("ledergerber kernel: input vector of zero norm (k_L is undefined at x = 0)");
  const Chunk gamma = (a0 * x[d0] + a1 * x[d1] + a2 * x[d2]) / (na * nb);
  prod *= theta[offset_] * ledergerberExponent(gamma, na - nb, t1, t2).exp();
}

void LedergerberPart::accumulateGradient(const MatX& A, const MatX& B, const MatX&, const MatX& W, const VecX& theta,
                                         VecX& grad_theta, MatX* grad_X1) const {
  // P10: ∂k/∂θ1 = k(1−γ)/θ1², ∂k/∂θ2 = k(n−n')²/θ2², ∂k/∂x = k[(x'/(nn') − γx/n²)/θ1 − 2(n−n')/θ2 · x/n]
  const Eigen::Index n2 = B.rows();
  const double t1 = theta[offset_ + 1], t2 = theta[offset_ + 2];
  const UnitRows ua = unitRows(A), ub = unitRows(B);
  const VecX &na = ua.norm, &nb = ub.norm;
  const MatX &Ua = ua.unit, &Ub = ub.unit;
  const MatX gamma = Ua * Ub.transpose();
  MatX dn2(A.rows(), n2);  // (n − n')
  for (Eigen::Index j = 0; j < n2; ++j) dn2.col(j) = na.array() - nb[j];
  grad_theta[offset_ + 1] += (W.array() * (1.0 - gamma.array())).sum() / (t1 * t1);
  grad_theta[offset_ + 2] += (W.array() * dn2.array().square()).sum() / (t2 * t2);
  if (grad_X1) {
    const MatX WUb = W * Ub;                                        // Σ_j w_ij x'_j/n'_j
    const VecX wg = (W.array() * gamma.array()).rowwise().sum();  // Σ_j w_ij γ_ij
    const VecX wdn = (W.array() * dn2.array()).rowwise().sum();   // Σ_j w_ij (n_i − n'_j)
    for (Eigen::Index d = 0; d < 3; ++d) {
      const VecX g = (WUb.col(d).array() / na.array() / t1 - wg.array() * A.col(d).array() / na.array().square() / t1 -
                      2.0 * wdn.array() / t2 * A.col(d).array() / na.array())
                         .matrix();
      grad_X1->col(active_dims_[d]) += g;
    }
  }
}

void LedergerberPart::specToJson(const PartSpec& s, nlohmann::json& jp) {
  jp["t0"] = s.sigma2;
  jp["t1"] = s.t1;
  jp["t2"] = s.t2;
}

void LedergerberPart::specFromJson(const nlohmann::json& src, PartSpec& s) {
  s.sigma2 = src.at("t0").get<double>();
  s.t1 = src.at("t1").get<double>();
  s.t2 = src.at("t2").get<double>();
}

}  // namespace uwb::gp
