/** @file Rbf.h
 *  @brief The RBF (squared-exponential) part, k = σ² exp(−½ ρ²), ρ² = Σ_d ((x_d − x'_d)/l_d)²
 *         (docs/math/gp.md P3; gradient P8; batch path P32).
 */
#pragma once

#include "uwb/gp/kernels/KernelPart.h"

namespace uwb::gp {

class RbfPart final : public LengthscalePart {
 public:
  /// Parameters: sigma2, l (1 or one per active dim).
  RbfPart(const PartSpec& spec, const std::string& prefix, ParamList& params);
  PartType type() const override { return PartType::kRbf; }
  PartSpec spec(const VecX& theta, const std::vector<bool>& trainable) const override;
  MatX block(const MatX& A, const MatX& B, const VecX& theta) const override;
  std::unique_ptr<PreparedBlock> prepare(MatX A, MatX B, const VecX& theta) const override;
  void column(const PreparedBlock& prepared, Eigen::Index j, const VecX& theta, double* out) const override;
  void multiplyChunk(const MatX& X1, Eigen::Index i0, const Eigen::Ref<const RowVecX>& x, const VecX& theta,
                     Chunk& prod) const override;
  void accumulateGradient(const MatX& A, const MatX& B, const MatX& H, const MatX& W, const VecX& theta,
                          VecX& grad_theta, MatX* grad_X1) const override;
};

}  // namespace uwb::gp
