/** @file Ledergerber.h
 *  @brief The Ledergerber part on x ∈ ℝ³, k = θ0 exp(−(1 − xᵀx'/(‖x‖‖x'‖))/θ1 − (‖x‖ − ‖x'‖)²/θ2)
 *         (paper k_L, eq. 9; docs/math/gp.md P4; gradient P10; batch path P32). Undefined at x = 0: every path
 *         throws std::invalid_argument for an input of (numerically) zero norm.
 */
#pragma once

#include "uwb/gp/kernels/KernelPart.h"

namespace uwb::gp {

class LedergerberPart final : public KernelPart {
 public:
  /// Parameters: t0 (the outputscale), t1, t2; exactly 3 active dims.
  LedergerberPart(const PartSpec& spec, const std::string& prefix, ParamList& params);
  PartType type() const override { return PartType::kLedergerber; }
  PartSpec spec(const VecX& theta, const std::vector<bool>& trainable) const override;
  MatX block(const MatX& A, const MatX& B, const VecX& theta) const override;
  std::unique_ptr<PreparedBlock> prepare(MatX A, MatX B, const VecX& theta) const override;
  void column(const PreparedBlock& prepared, Eigen::Index j, const VecX& theta, double* out) const override;
  void multiplyChunk(const MatX& X1, Eigen::Index i0, const Eigen::Ref<const RowVecX>& x, const VecX& theta,
                     Chunk& prod) const override;
  void accumulateGradient(const MatX& A, const MatX& B, const MatX& H, const MatX& W, const VecX& theta,
                          VecX& grad_theta, MatX* grad_X1) const override;

  static void specToJson(const PartSpec& spec, nlohmann::json& jp);
  static void specFromJson(const nlohmann::json& src, PartSpec& spec);
};

}  // namespace uwb::gp
