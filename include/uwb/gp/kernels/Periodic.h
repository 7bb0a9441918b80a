/** @file Periodic.h
 *  @brief The periodic part, k = σ² exp(−2 Σ_d sin²(π|x_d − x'_d|/T_d) / l_d²)
 *         (paper k_p, eq. 7; docs/math/gp.md P1; gradient P7; batch path P32).
 */
#pragma once

#include "uwb/gp/kernels/KernelPart.h"

namespace uwb::gp {

class PeriodicPart final : public LengthscalePart {
 public:
  /// Parameters: sigma2, l, T (1 or one per active dim each; T trainable only with spec.train_period).
  PeriodicPart(const PartSpec& spec, const std::string& prefix, ParamList& params);
  PartType type() const override { return PartType::kPeriodic; }
  PartSpec spec(const VecX& theta, const std::vector<bool>& trainable) const override;
  MatX block(const MatX& A, const MatX& B, const VecX& theta) const override;
  std::unique_ptr<PreparedBlock> prepare(MatX A, MatX B, const VecX& theta) const override;
  void column(const PreparedBlock& prepared, Eigen::Index j, const VecX& theta, double* out) const override;
  void multiplyChunk(const MatX& X1, Eigen::Index i0, const Eigen::Ref<const RowVecX>& x, const VecX& theta,
                     Chunk& prod) const override;
  void accumulateGradient(const MatX& A, const MatX& B, const MatX& H, const MatX& W, const VecX& theta,
                          VecX& grad_theta, MatX* grad_X1) const override;

  static void specToJson(const PartSpec& spec, nlohmann::json& jp);
  static void specFromJson(const nlohmann::json& src, const nlohmann::json& jp, PartSpec& spec);

 private:
  /// θ index of the period of active dimension d.
  Eigen::Index periodIndex(Eigen::Index d) const { return offset_ + 1 + n_l_ + (n_T_ == 1 ? 0 : d); }
  int n_T_ = 1;
};

}  // namespace uwb::gp
