/** @file TdoaUpdate.h
 *  @brief One TDoA correction of the filter through the graph's TDoA node (paper III-A, Fig. 2–3):
 *         bias correction (paper III-B), χ² gate, robust IRLS weight, equality node, reset.
 *         docs/math/filter.md F10–F13; docs/math/message-passing.md G11–G18.
 */
#pragma once

#include <optional>
#include <vector>

#include "uwb/core/Tdoa.h"
#include "uwb/filter/Ekf.h"
#include "uwb/filter/OutlierGate.h"
#include "uwb/graph/GaussianMessage.h"
#include "uwb/graph/TdoaNode.h"
#include "uwb/model/TdoaFeature.h"

namespace uwb {

/// Anchor beliefs addressed by id (the graph node treats anchors as Gaussian variables, paper III-A).
class AnchorTable {
 public:
  /// Adds or replaces anchor `id` (≥ 0) with mean w_p [m] and isotropic std sigma_m.
  void set(int id, const Vec3& w_p, double sigma_m = 0.0);
  /// nullptr when the id is unknown.
  const Moments3* find(int id) const {
    return (id >= 0 && id < static_cast<int>(anchors_.size()) && known_[id]) ? &anchors_[id] : nullptr;
  }
  std::vector<int> ids() const;
  std::size_t size() const;

 private:
  std::vector<Moments3> anchors_;
  std::vector<unsigned char> known_;  ///< 1 where an anchor is set (bytes: find() is on the per-TDoA path)
};

/// The anchors' axis-aligned bounding box and centroid [m] (starting guesses, plausibility bounds).
struct AnchorBox {
  Vec3 min = Vec3::Zero(), max = Vec3::Zero(), centroid = Vec3::Zero();
};
/// Throws std::invalid_argument when the table is empty.
AnchorBox anchorBox(const AnchorTable& anchors);

struct TdoaUpdateOptions {
  double sigma_m = 0.35;       ///< measurement std before bias-model variance [m]
  double gate_sigma = 4.0;     ///< χ² gate on √NIS; ≤ 0 disables the gate
  RobustLoss loss = RobustLoss::kHuber;
  double robust_k = 1.5;
  int robust_iterations = 2;
  Vec3 b_t_tag = kUtilTagOffset_b;
  /// With a bias predictor: ∂µ/∂δx (position and attitude, central differences) as input variance ∇µᵀ P ∇µ on the
  /// corrected measurement, or in its row so that the update linearizes h(x) + µ(x) (docs/math/gp.md P47).
  BiasPoseUncertainty bias_pose = BiasPoseUncertainty::kNone;
};

/// ∂µ/∂δx of a bias predictor at the state x for the TDoA between anchors A and B: position (additive) and attitude
/// (q ⊗ exp(δθ), as Ekf::inject) columns, by central differences of step 1e-4 m / 1e-4 rad (docs/math/gp.md P47).
/// Zero where a perturbed prediction is not finite. Calls the predictor 12 times.
Eigen::Matrix<double, 1, 6> biasPoseJacobian(const BiasPredictor& bias, const NavState& x, int id_a, int id_b,
                                             const Vec3& w_p_anchor_a, const Vec3& w_p_anchor_b);

struct TdoaUpdateResult {
  UpdateOutcome outcome = UpdateOutcome::kSkipped;
  double innovation_m = 0.0;  ///< z_corrected − ẑ (prior)
  double nis = 0.0;           ///< r²/S with the unweighted measurement variance
  double innovation_var_m2 = 0.0;  ///< S = a P aᵀ + measurement variance (unweighted) [m²]
  double weight = 1.0;        ///< IRLS weight applied (1 = full)
  double bias_mean_m = 0.0;   ///< bias-model correction subtracted from z
};

/// The TDoA message on the error state from the graph's TDoA node (G11–G16), without applying it.
/// nullopt when an anchor is unknown or the geometry is degenerate (tag on an anchor).
std::optional<ScalarLinearMessage<kDim>> tdoaMessage(const NavState& x, const AnchorTable& anchors,
                                                     const TdoaMeasurement& z, double z_corrected_m, double var_m2,
                                                     const Vec3& b_t_tag);

/// (G16) The TDoA node's message on the error state through x_k = x̃_k + C δx for the tag Jacobian
/// C = [I 0 J_tag_att 0 0] (J_tag_att = ∂x_k/∂δθ = −R[b_t]×, M4): the same message as tdoaMessageOnState<kDim> with
/// that dense C, built from C's two non-zero blocks. The returned row is zero outside δp and δθ.
ScalarLinearMessage<kDim> tdoaMessageOnPositionAttitude(const TdoaNodeMessages& node, const Mat3& J_tag_att,
                                                        const Vec3& w_p_tag);

/// Full TDoA update of `ekf` (F10–F13). The covariance should be propagated (Ekf::propagateCovariance) by the
/// caller according to its schedule. `bias` may be null (no bias correction).
TdoaUpdateResult updateTdoa(Ekf& ekf, const AnchorTable& anchors, const TdoaMeasurement& z,
                            const TdoaUpdateOptions& options, const BiasPredictor* bias = nullptr);

}  // namespace uwb
