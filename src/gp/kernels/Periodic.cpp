/** @file Periodic.cpp
 *  @brief The periodic part: value (P1), gradient (P7), batch column (P32), one-point chunk.
 */
#include "uwb/gp/kernels/Parts.h"

#include <nlohmann/json.hpp>

#include "ScaledExp.h"

namespace uwb::gp {

namespace {

/// (P1) One dimension of the periodic exponent sum, sin²(π Δ / T) / l², with c = π/T and il2 = 1/l².
template <class D>
auto periodicTerm(const D& delta, double c, double il2) {
  return il2 * (c * delta).sin().square();
}

struct PeriodicPrepared final : PreparedBlock {
  MatX A, B;  ///< raw active columns
};

}  // namespace

PeriodicPart::PeriodicPart(const PartSpec& spec, const std::string& prefix, ParamList& params)
    : LengthscalePart(spec, prefix, params) {
  n_T_ = params.addList(prefix, "T", spec.T, static_cast<int>(spec.active_dims.size()), spec.train_period);
}

PartSpec PeriodicPart::spec(const VecX& theta, const std::vector<bool>& trainable) const {
  PartSpec s = lengthscaleSpec(theta);
  s.T.assign(theta.data() + offset_ + 1 + n_l_, theta.data() + offset_ + 1 + n_l_ + n_T_);
  s.train_period = trainable[static_cast<std::size_t>(offset_ + 1 + n_l_)];
  return s;
}

MatX PeriodicPart::block(const MatX& A, const MatX& B, const VecX& theta) const {
  // Σ_d sin²(π Δ_d / T_d) / l_d²  (P1)
  const Eigen::Index n2 = B.rows(), nd = A.cols();
  MatX K(A.rows(), n2);
  K.setZero();
  for (Eigen::Index d = 0; d < nd; ++d) {
    const double l = theta[lengthscaleIndex(d)];
    const double T = theta[periodIndex(d)];
    const double c = kPi / T, il2 = 1.0 / (l * l);
    for (Eigen::Index j = 0; j < n2; ++j) K.col(j).array() += periodicTerm(A.col(d).array() - B(j, d), c, il2);
  }
  K = theta[offset_] * (-2.0 * K.array()).exp();
  return K;
}

std::unique_ptr<PreparedBlock> PeriodicPart::prepare(MatX A, MatX B, const VecX&) const {
  auto q = std::make_unique<PeriodicPrepared>();
  q->A = std::move(A);
  q->B = std::move(B);
  return q;
}

void PeriodicPart::column(const PreparedBlock& prepared, Eigen::Index j, const VecX& theta, double* out_data) const {
  const auto& q = static_cast<const PeriodicPrepared&>(prepared);
  const Eigen::Index n1 = q.A.rows(), nd = q.A.cols();
  Eigen::Map<Eigen::ArrayXd> out(out_data, n1);
  out.setZero();  // Σ_d sin²(π Δ_d / T_d) / l_d²  (P1)
  for (Eigen::Index d = 0; d < nd; ++d) {
    const double l = theta[lengthscaleIndex(d)];
    const double T = theta[periodIndex(d)];
    const double c = kPi / T, il2 = 1.0 / (l * l);
    out += periodicTerm(q.A.col(d).array() - q.B(j, d), c, il2);
  }
  detail::scaledExpInPlace(out.data(), n1, -2.0, theta[offset_]);
}

void PeriodicPart::multiplyChunk(const MatX& X1, Eigen::Index i0, const Eigen::Ref<const RowVecX>& x,
                                 const VecX& theta, Chunk& prod) const {
  const Eigen::Index c = prod.size(), nd = static_cast<Eigen::Index>(active_dims_.size());
  Chunk acc = Chunk::Zero(c);
  for (Eigen::Index d = 0; d < nd; ++d) {
    const int dim = active_dims_[static_cast<std::size_t>(d)];
    const double l = theta[lengthscaleIndex(d)];
    const double T = theta[periodIndex(d)];
    acc += periodicTerm(X1.col(dim).segment(i0, c).array() - x[dim], kPi / T, 1.0 / (l * l));
  }
  prod *= theta[offset_] * (-2.0 * acc).exp();
}

void PeriodicPart::accumulateGradient(const MatX& A, const MatX& B, const MatX&, const MatX& W, const VecX& theta,
                                      VecX& grad_theta, MatX* grad_X1) const {
  // P7: u = πΔ/T; ∂k/∂l = 4k sin²u / l³; ∂k/∂T = k (2/l²) sin 2u · πΔ/T²; ∂k/∂x = −k (2/l²) sin 2u · π/T
  const Eigen::Index n2 = B.rows(), nd = A.cols();
  Eigen::ArrayXd gx(A.rows()), delta(A.rows()), su(A.rows()), ws2(A.rows());
  for (Eigen::Index d = 0; d < nd; ++d) {
    const Eigen::Index li = lengthscaleIndex(d);
    const Eigen::Index ti = periodIndex(d);
    const double l = theta[li], T = theta[ti], c = kPi / T;
    double acc_l = 0.0, acc_T = 0.0;
    gx.setZero();
    for (Eigen::Index j = 0; j < n2; ++j) {
      delta = A.col(d).array() - B(j, d);
      su = (c * delta).sin();
      acc_l += (W.col(j).array() * su.square()).sum();
      ws2 = W.col(j).array() * 2.0 * su * (c * delta).cos();  // w sin 2u
      acc_T += (ws2 * delta).sum();
      gx += ws2;
    }
    grad_theta[li] += 4.0 * acc_l / (l * l * l);
    grad_theta[ti] += (2.0 / (l * l)) * c / T * acc_T;
    if (grad_X1) grad_X1->col(active_dims_[d]) -= ((2.0 / (l * l)) * c * gx).matrix();
  }
}

void PeriodicPart::specToJson(const PartSpec& s, nlohmann::json& jp) {
  jp["sigma2"] = s.sigma2;
  jp["l"] = s.l;
  jp["T"] = s.T;
  jp["train_period"] = s.train_period;
}

void PeriodicPart::specFromJson(const nlohmann::json& src, const nlohmann::json& jp, PartSpec& s) {
  s.sigma2 = src.at("sigma2").get<double>();
  s.l = src.at("l").get<std::vector<double>>();
  s.T = src.at("T").get<std::vector<double>>();
  s.train_period = jp.value("train_period", false);
}

}  // namespace uwb::gp
