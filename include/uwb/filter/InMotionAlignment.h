/** @file InMotionAlignment.h
 *  @brief The attitude of a moving body from the gyro-tracked specific force against the velocity the TDoA give
 *         (docs/math/filter.md F28): finds the heading that nothing else measures when a log starts in the air.
 *
 *  Over a window from t₀ the gyro carries the body frame of t₀ forward, ΔR(t) (body(t₀) ← body(t)), and the
 *  specific force is summed in that frame, β(t) = ∫ ΔR f dτ. The world velocity obeys v(t) − v(t₀) = R₀ β(t) +
 *  g_w (t − t₀), so the increments α(t) = v(t) − v(t₀) − g_w (t − t₀) are β(t) turned by the attitude R₀ at t₀:
 *  Wahba's problem, solved in closed form (SVD), without linearising about a guess. Gravity fixes the tilt; the
 *  horizontal velocity changes fix the heading. Gravity makes the sum large (≈ g per second) and a tilt drift of the
 *  gyro turns it into horizontal velocity that is not there, so the gyro and accelerometer biases over the window are
 *  solved for with it (first order, the preintegration Jacobians of Forster et al. 2017). Bounded memory, no
 *  allocation.
 */
#pragma once

#include <array>
#include <cstddef>
#include <optional>

#include "uwb/core/Angle.h"
#include "uwb/core/Types.h"

namespace uwb {

/// Heading of the body's x axis in the world's horizontal plane, atan2(R₁₀, R₀₀) (the yaw of the z-y-x angles) [rad].
double headingOf(const Quat& w_q_b);
/// ∂ headingOf(q ⊗ Exp(δθ)) / ∂δθ at δθ = 0 (body-frame attitude error, F8): with c = R e_x, ∂c/∂δθ = −R [e_x]×, and
/// ∂ atan2(c₁, c₀) = (c₀ ∂c₁ − c₁ ∂c₀) / (c₀² + c₁²). (≈ the world-z row of R for a level body.)
Eigen::RowVector3d headingJacobian(const Quat& w_q_b);

class InMotionAlignment {
 public:
  /// One window's solution.
  struct Result {
    Quat w_q_b;                     ///< attitude at the window's last sample (world ← body)
    double heading_sigma_rad = 0.0; ///< std of the heading (rotation about world z) from the fit's residuals
    double tilt_sigma_rad = 0.0;    ///< std of a rotation about a horizontal axis
    double rms_residual_mps = 0.0;  ///< per-component RMS of α_k − R₀ β_k
    double horizontal_excitation_mps = 0.0;  ///< RMS of the horizontal velocity increments |α_k,h|
    Vec3 gyro_bias_change_radps = Vec3::Zero();  ///< gyro bias beyond the one subtracted from the samples
    Vec3 acc_bias_change_mps2 = Vec3::Zero();    ///< accelerometer bias beyond the one subtracted
  };

  /// The most increments a window stores (bounded memory): window_s / sample_period_s may not exceed it.
  static constexpr std::size_t kCapacity = 256;
  /// The spacing of the stored increments the estimator uses, and the longest window it then fits [s].
  static constexpr double kDefaultSamplePeriod_s = 0.1;
  static constexpr double kMaxWindow_s = static_cast<double>(kCapacity - 1) * kDefaultSamplePeriod_s;
  /// The time over which the filter's velocity errors are taken as correlated [s].
  static constexpr double kDefaultCorrelation_s = 1.0;
  /// The IMU samples are summed over steps of this length and integrated once per step with their mean rate and
  /// specific force (F28a): the rotation over a step is small, and the sums cost little per sample [s].
  static constexpr double kIntegrationStep_s = 0.05;

  /// window_s: the window's length; sample_period_s: spacing of the stored increments; correlation_s: the time over
  /// which the velocity's errors are taken as correlated (the residuals count once per correlation_s); drag_per_s:
  /// the rotor drag k of the model a = R f + g_w − k v_h (F28a′), 0 for none. Throws std::invalid_argument for a
  /// window that does not fit kCapacity increments, a non-positive length or a negative drag.
  explicit InMotionAlignment(double window_s = 4.0, double sample_period_s = kDefaultSamplePeriod_s,
                             double correlation_s = kDefaultCorrelation_s, double drag_per_s = 0.0);

  /// Forgets the window; the next add() starts a new one.
  void reset();
  /// One IMU sample (bias-corrected specific force f_b [m/s²] and rate ω_b [rad/s], held over the dt_s before t_s)
  /// and the world velocity at t_s (which also carries the drag's integral, F28a′).
  void add(double t_s, const Vec3& f_b, const Vec3& omega_b, double dt_s, const Vec3& w_v);
  /// The window spans window_s.
  bool complete() const { return n_ > 0 && t_last_ - t0_ >= window_s_ - 1e-9; }
  /// The attitude now and its uncertainty (nothing with fewer than 5 stored increments).
  std::optional<Result> solve() const;

  /// The running sums, to the last integration step, and their first-order bias Jacobians (tested against finite
  /// differences): β = ∫ ΔR f dτ,
  /// ΔR (body(t₀) ← body(t)), Φ = ∂Log(ΔR₀ᵀ ΔR)/∂b_g (right perturbation), ∂β/∂b_g, ∂β/∂b_a, for a bias b that is
  /// subtracted from the samples (ω − b_g, f − b_a).
  const Vec3& integratedSpecificForce() const { return beta_; }
  const Quat& rotationSinceStart() const { return dq_; }
  const Mat3& rotationGyroBiasJacobian() const { return phi_; }
  const Mat3& gyroBiasJacobian() const { return jg_; }
  const Mat3& accBiasJacobian() const { return ja_; }

 private:
  /// Integrates the samples summed since the last step (F28a).
  void integrateStep();

  double window_s_, sample_period_s_, correlation_s_, drag_per_s_;
  std::size_t n_ = 0;
  double t0_ = 0.0, t_last_ = 0.0, t_next_sample_ = 0.0;
  Quat dq_ = Quat::Identity();  ///< ΔR: body(t₀) ← body(t)
  Vec3 beta_ = Vec3::Zero();    ///< ∫ ΔR f dτ
  Mat3 phi_ = Mat3::Zero();     ///< ∂ rotation vector of ΔR (right perturbation) / ∂ gyro bias
  Mat3 jg_ = Mat3::Zero(), ja_ = Mat3::Zero();  ///< ∂β / ∂ gyro bias, ∂β / ∂ accelerometer bias
  Vec3 v0_ = Vec3::Zero();
  Vec3 displacement_ = Vec3::Zero();  ///< ∫ v dτ since t₀ (the drag's integral, F28a′)
  Vec3 step_f_dt_ = Vec3::Zero(), step_w_dt_ = Vec3::Zero();  ///< Σ f dt, Σ ω dt since the last integration step
  double step_dt_ = 0.0;                                      ///< Σ dt since the last integration step
  std::array<Vec3, kCapacity> alpha_{}, beta_k_{};
  std::array<Mat3, kCapacity> jg_k_{}, ja_k_{};
};

}  // namespace uwb
