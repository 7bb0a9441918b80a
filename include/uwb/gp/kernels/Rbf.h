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
  UWB_KERNEL_PART_OVERRIDES
};

}  // namespace uwb::gp
