/** @file Matern52.h
 *  @brief The Matérn-5/2 part, k = σ² (1 + √5ρ + 5ρ²/3) e^{−√5ρ}, ρ² = Σ_d ((x_d − x'_d)/l_d)²
 *         (paper eq. 8; docs/math/gp.md P2; gradient P9; batch path P32).
 */
#pragma once

#include "uwb/gp/kernels/KernelPart.h"

namespace uwb::gp {

class Matern52Part final : public LengthscalePart {
 public:
  /// Parameters: sigma2, l (1 or one per active dim).
  Matern52Part(const PartSpec& spec, const std::string& prefix, ParamList& params);
  PartType type() const override { return PartType::kMatern52; }
  UWB_KERNEL_PART_OVERRIDES
};

}  // namespace uwb::gp
