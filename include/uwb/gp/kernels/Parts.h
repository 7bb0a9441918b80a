/** @file Parts.h
 *  @brief The kernel part types (docs/math/gp.md P1–P4). Each is defined in its own file, src/gp/kernels/<Type>.cpp,
 *         with its value, analytic gradient and fast paths side by side; the overrides are those of KernelPart.h.
 */
#pragma once

#include "uwb/gp/kernels/KernelPart.h"

namespace uwb::gp {

/// The RBF (squared-exponential) part, k = σ² exp(−½ ρ²), ρ² = Σ_d ((x_d − x'_d)/l_d)² (docs/math/gp.md P3;
/// gradient P8; batch path P32).
class RbfPart final : public LengthscalePart {
 public:
  /// Parameters: sigma2, l (1 or one per active dim).
  RbfPart(const PartSpec& spec, const std::string& prefix, ParamList& params);
  PartType type() const override { return PartType::kRbf; }
  UWB_KERNEL_PART_OVERRIDES
};

/// The Matérn-5/2 part, k = σ² (1 + √5ρ + 5ρ²/3) e^{−√5ρ}, ρ² = Σ_d ((x_d − x'_d)/l_d)² (paper eq. 8;
/// docs/math/gp.md P2; gradient P9; batch path P32).
class Matern52Part final : public LengthscalePart {
 public:
  /// Parameters: sigma2, l (1 or one per active dim).
  Matern52Part(const PartSpec& spec, const std::string& prefix, ParamList& params);
  PartType type() const override { return PartType::kMatern52; }
  UWB_KERNEL_PART_OVERRIDES
};

/// The periodic part, k = σ² exp(−2 Σ_d sin²(π|x_d − x'_d|/T_d) / l_d²) (paper k_p, eq. 7; docs/math/gp.md P1;
/// gradient P7; batch path P32).
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

/// The Ledergerber part on x ∈ ℝ³, k = θ0 exp(−(1 − xᵀx'/(‖x‖‖x'‖))/θ1 − (‖x‖ − ‖x'‖)²/θ2) (paper k_L, eq. 9;
/// docs/math/gp.md P4; gradient P10; batch path P32). Undefined at x = 0: every path throws std::invalid_argument
/// for an input of (numerically) zero norm.
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
