/** @file Ekf.h
 *  @brief Error-state Kalman filter core (Crazyflie kalman_core / PX4 shape): predict, correct, reset.
 *         docs/math/filter.md F1–F8.
 *
 *  The nominal state is integrated at every prediction; the error-state covariance is propagated with the
 *  accumulated transition Φ = F_k ⋯ F_1 only when asked (propagateCovariance, F7), e.g. before a TDoA update
 *  or at a fixed rate as Crazyflie does at 100 Hz. Φ is kept in its block structure (9 blocks of 3×3), so
 *  accumulating one step costs a few 3×3 products and folding it into P costs O(15²·3).
 */
#pragma once

#include <optional>

#include "uwb/filter/AnchorRangeBias.h"
#include "uwb/filter/EkfParams.h"
#include "uwb/filter/NavState.h"
#include "uwb/filter/QuadImuProcess.h"
#include "uwb/filter/StateIndex.h"
#include "uwb/graph/TdoaCorrection.h"

namespace uwb {

/// Accumulated error-state transition Φ in block form (F7); the identity when empty.
struct AccumulatedTransition {
  double T_s = 0.0;                      ///< accumulated time
  Vec3 pos_vel = Vec3::Zero();           ///< diagonal of Φ_pv (T_s I without rotor drag, F2a)
  Vec3 vel_vel = Vec3::Ones();           ///< diagonal of Φ_vv (I without rotor drag)
  Mat3 pos_att = Mat3::Zero();
  Mat3 pos_accbias = Mat3::Zero();
  Mat3 pos_gyrobias = Mat3::Zero();
  Mat3 vel_att = Mat3::Zero();
  Mat3 vel_accbias = Mat3::Zero();
  Mat3 vel_gyrobias = Mat3::Zero();
  Mat3 att_att = Mat3::Identity();
  Mat3 att_gyrobias = Mat3::Zero();
  Vec3 q_vel_diag = Vec3::Zero();        ///< accumulated velocity process noise (F7 Q), per world axis [m²/s²]

  /// Φ ← F Φ for one IMU step (F7).
  void accumulate(const ImuStepJacobian& J);
  /// Dense Φ (tests).
  ErrMat dense() const;
  /// Returns Φ M for a 15×15 M using the block structure.
  ErrMat leftMultiply(const ErrMat& M) const;
  /// Returns M Φᵀ for a 15×15 M using the block structure, as column operations (contiguous in Eigen's column-major
  /// storage, so each 15×3 · 3×3 block product vectorises along the 15 rows).
  ErrMat rightMultiplyTransposed(const ErrMat& M) const;
  /// M ← M Φᵀ in place (the same arithmetic as rightMultiplyTransposed, without the 15×15 copy).
  void rightMultiplyTransposedInPlace(ErrMat& M) const;
  bool empty() const { return T_s == 0.0; }
};

class Ekf {
 public:
  explicit Ekf(const EkfParams& params);

  /// Sets the state and covariance; forgets any pending transition.
  void initialize(const NavState& x0, const ErrMat& P0);

  const NavState& state() const { return x_; }
  /// Covariance at the last propagation (pending Φ not yet applied; call propagateCovariance first if needed).
  const ErrMat& covariance() const { return P_; }
  const EkfParams& params() const { return params_; }
  /// Time since the last covariance propagation [s].
  double pendingDt() const { return phi_.T_s + pending_cv_dt_s_; }

  /// IMU prediction (F2–F5): integrates the nominal state, accumulates Φ. dt_s ≤ 0 is ignored.
  void predict(const ImuReading& imu, double dt_s);
  /// TDoA-only prediction (F9), constant velocity or constant acceleration per params.process_model.
  void predictTdoaOnly(double dt_s);
  /// P ← Φ P Φᵀ + Q(T) (F7), resets Φ.
  void propagateCovariance();

  /// Correction with a rank-one Gaussian message on δx (from the graph's TDoA node, G16), through the graph's
  /// equality node (G18), followed by the reset (F8). Returns nullopt and leaves the filter unchanged if the
  /// equality node fails (S ≤ 0 or not finite).
  std::optional<InnovationStats> correct(const ScalarLinearMessage<kDim>& message);
  /// correct() for a message whose row is zero outside the position and attitude blocks (a TDoA message,
  /// a = B12 C, G16): the equality node then reads only those 6 columns of P (equalityRankOneTwoBlocksInPlace).
  std::optional<InnovationStats> correctPositionAttitude(const ScalarLinearMessage<kDim>& message);
  /// correctPositionAttitude() given P_a = P aᵀ and a_P_a = a P aᵀ of the current P, which the caller already
  /// formed (e.g. for its χ² gate, F11), so the equality node (G18) does not form them again.
  std::optional<InnovationStats> correctPositionAttitude(const ScalarLinearMessage<kDim>& message, const ErrVec& P_a,
                                                         double a_P_a);
  /// Innovation statistics of a message without applying it (G17).
  InnovationStats innovation(const ScalarLinearMessage<kDim>& message) const;

  /// The per-anchor range-bias states (F27), or nullptr when off (EkfParams::range_bias_sigma_m = 0). With them on,
  /// every correction is the equality node (G18) on the augmented state [δx, δβ], whatever its row: a message on δx
  /// alone still moves β̂ through the cross-covariance.
  const AnchorRangeBias* rangeBias() const { return range_bias_ ? &*range_bias_ : nullptr; }
  /// β̂_B − β̂_A: the TDoA bias of pair (A, B) the states predict [m]; 0 when off.
  double rangeBiasDifference(int id_a, int id_b) const;
  /// u = J hᵀ of a message on the augmented state [δx, δβ] with joint covariance J (G18), and h u.
  struct RangeBiasGain {
    ErrVec u_x = ErrVec::Zero();
    BiasVec u_b = BiasVec::Zero();
    double h_u = 0.0;  ///< h J hᵀ: the innovation variance is h_u + the message's var (G17)
    int slot_a = -1, slot_b = -1;  ///< the pair's range-bias slots (−1: none)
  };
  /// (F27c) The gain of a TDoA message of pair (A, B) on the augmented state: its row gains −1 at δβ_A and +1 at δβ_B
  /// (the anchors get a state on first sight). message.y must already exclude β̂_B − β̂_A. Requires rangeBias().
  RangeBiasGain rangeBiasGain(const ScalarLinearMessage<kDim>& message, int id_a, int id_b);
  /// (F27c) The correction with that gain (u does not depend on the message's var, which the caller may have changed
  /// since, e.g. by a robust weight), followed by the reset (F8) of δx and β̂ += δβ. Requires rangeBias().
  std::optional<InnovationStats> correctWithRangeBias(const ScalarLinearMessage<kDim>& message,
                                                      const RangeBiasGain& gain);

  /// Zero-velocity update v = 0 with std sigma_mps per axis (F14), three scalar corrections.
  void zeroVelocityUpdate(double sigma_mps);
  /// Zero-angular-rate update at rest (F18z): a body that does not turn reads its gyro bias, b_g = ω̄ with variance
  /// var per body axis, three scalar corrections. An axis whose innovation lies beyond gate_sigma standard deviations
  /// of its predicted spread first has its bias variance raised by the innovation's square: the bias std the filter
  /// started with was too confident for this gyro. Returns the number of axes so widened.
  int zeroAngularRateUpdate(const Vec3& mean_gyro_radps, const Vec3& var_radps2, double gate_sigma);
  /// Scalar pseudo-measurement of the position along world axis `axis` (0..2): p_axis = value ± sigma.
  void positionUpdate(int axis, double value_m, double sigma_m);
  /// The one-sided constraint p_axis ≥ lower_m (message-passing.md G23): the position's belief along that axis is
  /// replaced by its moments truncated below lower_m, the other states following through their covariance with it.
  /// Returns false (state untouched) when the belief has no mass below lower_m to speak of.
  bool constrainPositionAbove(int axis, double lower_m);
  /// The one-sided constraint p_axis ≤ upper_m: the same node on −p_axis ≥ −upper_m (G23).
  bool constrainPositionBelow(int axis, double upper_m);
  /// Adds sigma² to the position (and optionally velocity) variances: used on re-acquisition.
  void inflatePosition(double sigma_m, double vel_sigma_mps);
  /// P ← factor · P (factor > 0): the prior of a covariance-intersection update, P/ω (message-passing.md G21).
  void scaleCovariance(double factor);
  /// (G21) The joint covariance inflated along the position only, P ← P + (f − 1) P_·p P_pp⁻¹ P_p· (over [δx, δβ]):
  /// the position block times f, the regression of every other state on the position kept, their conditional
  /// covariance given the position unchanged. false (nothing done) unless f > 1 and P_pp is positive definite.
  bool inflateAlongPosition(double factor);
  /// Adds sigma² to the x and y position variances and vel_sigma² to the velocity variances.
  void inflateHorizontalPosition(double sigma_m, double vel_sigma_mps);
  /// Overwrites the position; keeps other state; sets the position block of P to sigma² I, clears its correlations.
  void resetPosition(const Vec3& w_p_b, double sigma_m);

  /// Overwrites the height (p_z) with variance var_m2; keeps the other states and clears the height's correlations
  /// with them (F29c).
  void resetHeight(double z_m, double var_m2);

  /// Overwrites position and velocity with a joint Gaussian (mean w_p_b, w_v_b; covariance Σ over (δp, δv)); keeps the
  /// other states and clears the position/velocity correlations with them (F16b).
  void resetPositionVelocity(const Vec3& w_p_b, const Vec3& w_v_b, const Eigen::Matrix<double, 6, 6>& cov);
  /// Scalar measurement of the heading (the yaw of the z-y-x angles) = heading_rad ± sigma_rad, row headingJacobian
  /// on the attitude error (F28).
  void headingUpdate(double heading_rad, double sigma_rad);
  /// Overwrites the attitude (world ← body) with covariance `cov` of the body-frame attitude error (F8); keeps the
  /// other states and clears the attitude's correlations with them (F28).
  void resetAttitude(const Quat& w_q_b, const Mat3& cov);
  /// Switches how the accelerometer enters the prediction (e.g. full on the ground, thrust-only in flight).
  void setAccelModel(AccelModel model) { params_.accel_model = model; }
  AccelModel accelModel() const { return params_.accel_model; }
  /// Adds sigma² to the thrust-axis (body z) accelerometer-bias variance (F20).
  void inflateThrustBias(double sigma_mps2);

  /// Folds an error-state estimate into the nominal state (F8): x ← x ⊞ δx. (P is kept; the first-order
  /// attitude reset Jacobian is the identity up to O(|δθ|).)
  void inject(const ErrVec& dx);

 private:
  /// (G23) sign · p_axis ≥ sign · bound_m, sign = ±1.
  bool constrainPosition(int axis, double bound_m, double sign);
  EkfParams params_;
  NavState x_;
  ErrMat P_ = ErrMat::Identity();
  AccumulatedTransition phi_;
  /// TDoA-only models (F9): the pending transition F(T) and noise Q(T) are determined by T alone.
  double pending_cv_dt_s_ = 0.0;
  std::optional<AnchorRangeBias> range_bias_;  ///< F27, with range_bias_sigma_m > 0
  void propagateTdoaOnlyCovariance();
  /// range_bias_ at its prior (F27), adapting (F27e) as params_ say; none with range_bias_sigma_m = 0.
  void resetRangeBias();
  /// u = J hᵀ and h u for the row h = [a, e_B − e_A] on [δx, δβ] (a slot < 0 has no entry; both < 0: a row on δx).
  RangeBiasGain jointGain(const ErrRow& a, int slot_a, int slot_b) const;
  /// (G18) on the augmented state with its gain, then the reset (F8) of δx and β̂ += δβ.
  std::optional<InnovationStats> correctAugmented(double y, double var, const RangeBiasGain& gain);
};

/// The initial covariance from the params' init_* sigmas (F1).
ErrMat initialCovariance(const EkfParams& params);

}  // namespace uwb
