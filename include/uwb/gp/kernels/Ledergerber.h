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
  UWB_KERNEL_PART_OVERRIDES

  static void specToJson(const PartSpec& spec, nlohmann::json& jp);
  static void specFromJson(const nlohmann::json& src, PartSpec& spec);
};

}  // namespace uwb::gp
