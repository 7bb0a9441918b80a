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
  UWB_KERNEL_PART_OVERRIDES

  static void specToJson(const PartSpec& spec, nlohmann::json& jp);
  static void specFromJson(const nlohmann::json& src, const nlohmann::json& jp, PartSpec& spec);

 private:
  /// θ index of the period of active dimension d.
  Eigen::Index periodIndex(Eigen::Index d) const { return offset_ + 1 + n_l_ + (n_T_ == 1 ? 0 : d); }
  int n_T_ = 1;
};

}  // namespace uwb::gp
