/** @file KernelPart.cpp
 *  @brief What the part types share: names, the parameter list, the radial parts' distances and gradient, and the
 *         factory over the part types (docs/math/gp.md P1–P4, P8, P9).
 */
#include "uwb/gp/kernels/KernelPart.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "uwb/gp/kernels/Parts.h"

namespace uwb::gp {

std::string toString(PartType type) {
  switch (type) {
    case PartType::kRbf: return "rbf";
    case PartType::kMatern52: return "matern52";
    case PartType::kPeriodic: return "periodic";
    case PartType::kLedergerber: return "ledergerber";
  }
  return "unknown";
}

PartType partTypeFromString(const std::string& name) {
  if (name == "rbf" || name == "se" || name == "squared_exponential") return PartType::kRbf;
  if (name == "matern52" || name == "matern") return PartType::kMatern52;
  if (name == "periodic") return PartType::kPeriodic;
  if (name == "ledergerber" || name == "kl" || name == "k_L") return PartType::kLedergerber;
  throw std::invalid_argument("unknown kernel part type '" + name +
                              "' (expected rbf, matern52, periodic or ledergerber)");
}

void ParamList::add(const std::string& prefix, const std::string& name, double value, bool train) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    throw std::invalid_argument("kernel parameter " + prefix + name + " must be positive and finite, got " +
                                std::to_string(value));
  }
  values.push_back(value);
  names.push_back(prefix + name);
  trainable.push_back(train);
}

int ParamList::addList(const std::string& prefix, const std::string& name, const std::vector<double>& v, int nd,
                       bool train) {
  if (v.size() != 1 && static_cast<int>(v.size()) != nd) {
    throw std::invalid_argument("kernel part " + prefix + name + ": expected 1 or " + std::to_string(nd) +
                                " values, got " + std::to_string(v.size()));
  }
  if (v.size() == 1) {
    add(prefix, name, v[0], train);
  } else {
    for (std::size_t i = 0; i < v.size(); ++i) add(prefix, name + "[" + std::to_string(i) + "]", v[i], train);
  }
  return static_cast<int>(v.size());
}

MatX activeColumns(const MatX& X, const std::vector<int>& dims) {
  MatX out(X.rows(), static_cast<Eigen::Index>(dims.size()));
  for (std::size_t d = 0; d < dims.size(); ++d) out.col(static_cast<Eigen::Index>(d)) = X.col(dims[d]);
  return out;
}

// ---- radial parts (rbf, matern52): ρ² = Σ_d ((a_d − b_d)/l_d)² (P2, P3) ----

LengthscalePart::LengthscalePart(const PartSpec& spec, const std::string& prefix, ParamList& params)
    : KernelPart(spec.active_dims, static_cast<int>(params.values.size())) {
  params.add(prefix, "sigma2", spec.sigma2, true);
  n_l_ = params.addList(prefix, "l", spec.l, static_cast<int>(spec.active_dims.size()), true);
}

PartSpec LengthscalePart::lengthscaleSpec(const VecX& theta) const {
  PartSpec s;
  s.type = type();
  s.active_dims = active_dims_;
  s.sigma2 = theta[offset_];
  s.l.assign(theta.data() + offset_ + 1, theta.data() + offset_ + 1 + n_l_);
  s.T.clear();
  return s;
}

MatX LengthscalePart::scaledSquaredDistance(const MatX& A, const MatX& B, const VecX& theta) const {
  const Eigen::Index n2 = B.rows(), nd = A.cols();
  MatX As = A, Bs = B;
  for (Eigen::Index d = 0; d < nd; ++d) {
    const double l = theta[lengthscaleIndex(d)];
    As.col(d) /= l;
    Bs.col(d) /= l;
  }
  MatX K(A.rows(), n2);
  K.setZero();
  for (Eigen::Index j = 0; j < n2; ++j)
    for (Eigen::Index d = 0; d < nd; ++d) K.col(j).array() += (As.col(d).array() - Bs(j, d)).square();
  return K;
}

void LengthscalePart::divideByLengthscales(MatX& A, MatX& B, const VecX& theta) const {
  for (Eigen::Index d = 0; d < A.cols(); ++d) {
    const double l = theta[lengthscaleIndex(d)];
    A.col(d) /= l;
    B.col(d) /= l;
  }
}

Chunk LengthscalePart::chunkSquaredDistance(const MatX& X1, Eigen::Index i0, Eigen::Index c,
                                            const Eigen::Ref<const RowVecX>& x, const VecX& theta) const {
  Chunk acc = Chunk::Zero(c);
  const Eigen::Index nd = static_cast<Eigen::Index>(active_dims_.size());
  for (Eigen::Index d = 0; d < nd; ++d) {
    const int dim = active_dims_[static_cast<std::size_t>(d)];
    const double il = 1.0 / theta[lengthscaleIndex(d)];
    acc += ((X1.col(dim).segment(i0, c).array() - x[dim]) * il).square();
  }
  return acc;
}

void LengthscalePart::accumulateRadialGradient(const MatX& A, const MatX& B, const MatX& Wg, const VecX& theta,
                                               VecX& grad_theta, MatX* grad_X1) const {
  const Eigen::Index nd = A.cols();
  // Σ_j w_ij Δ_ij = a_i (Σ_j w_ij) − (W b)_i and Σ_ij w_ij Δ_ij² = Σ_i rs_i a_i² − 2 aᵀ(W b) + Σ_j cs_j b_j²:
  // one GEMM W·B (n1×n2 · n2×d) instead of d passes over the n1×n2 block. Inputs are centred on A's column
  // means first (Δ is unchanged) to keep the cancellation in the expanded square small.
  MatX Ac = A, Bc = B;
  for (Eigen::Index d = 0; d < nd; ++d) {
    const double centre = A.rows() > 0 ? A.col(d).mean() : 0.0;
    Ac.col(d).array() -= centre;
    Bc.col(d).array() -= centre;
  }
  const VecX rs = Wg.rowwise().sum();
  const VecX cs = Wg.colwise().sum().transpose();
  MatX WB(A.rows(), nd);
  WB.noalias() = Wg * Bc;
  for (Eigen::Index d = 0; d < nd; ++d) {
    const Eigen::Index li = lengthscaleIndex(d);
    const double l = theta[li];
    const auto a = Ac.col(d).array();
    const double acc = (rs.array() * a.square()).sum() - 2.0 * (a * WB.col(d).array()).sum() +
                       (cs.array() * Bc.col(d).array().square()).sum();
    grad_theta[li] += acc / (l * l * l);
    if (grad_X1) grad_X1->col(active_dims_[d]) -= ((a * rs.array() - WB.col(d).array()) / (l * l)).matrix();
  }
}

// ---- the part types ----

std::unique_ptr<const KernelPart> makePart(const PartSpec& spec, int index, ParamList& params) {
  if (spec.active_dims.empty())
    throw std::invalid_argument("kernel part " + std::to_string(index) + ": no active dims");
  for (int d : spec.active_dims)
    if (d < 0) throw std::invalid_argument("kernel part: negative active dim");
  const std::string prefix = "p" + std::to_string(index) + "." + toString(spec.type) + ".";
  switch (spec.type) {
    case PartType::kRbf: return std::make_unique<RbfPart>(spec, prefix, params);
    case PartType::kMatern52: return std::make_unique<Matern52Part>(spec, prefix, params);
    case PartType::kPeriodic: return std::make_unique<PeriodicPart>(spec, prefix, params);
    case PartType::kLedergerber: return std::make_unique<LedergerberPart>(spec, prefix, params);
  }
  throw std::invalid_argument("kernel part: unknown type");
}

void partSpecToJson(const PartSpec& s, nlohmann::json& jp) {
  if (s.type == PartType::kLedergerber) {
    LedergerberPart::specToJson(s, jp);
  } else if (s.type == PartType::kPeriodic) {
    PeriodicPart::specToJson(s, jp);
  } else {
    jp["sigma2"] = s.sigma2;
    jp["l"] = s.l;
  }
}

void partSpecFromJson(const nlohmann::json& src, const nlohmann::json& jp, PartSpec& s) {
  if (s.type == PartType::kLedergerber) {
    LedergerberPart::specFromJson(src, s);
  } else if (s.type == PartType::kPeriodic) {
    PeriodicPart::specFromJson(src, jp, s);
  } else {
    s.sigma2 = src.at("sigma2").get<double>();
    s.l = src.at("l").get<std::vector<double>>();
  }
}

}  // namespace uwb::gp
