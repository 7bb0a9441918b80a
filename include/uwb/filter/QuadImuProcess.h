/** @file QuadImuProcess.h
 *  @brief Quadrotor IMU process model as a pure function: (state, imu, dt, params) → (next, F, G)
 *         (Mueller, Hamer, D'Andrea, ICRA 2015; docs/math/filter.md F2–F6), and the TDoA-only models (F9).
 *
 *  Nominal step (F2):  f = S (a_m − b_a),  ω = ω_m − b_g,  a = w_R_b f + w_g (− k v_h, F2a),
 *      p' = p + v dt + ½ a dt²,  v' = v + a dt,  q' = q ⊗ Exp(ω dt),  b' = b.
 *  S = I for AccelModel::kFull and S = e_z e_zᵀ for kThrustOnly (Mueller et al.: the accelerometer of a
 *  flying quadrotor measures the collective thrust along body z; x/y are not integrated).
 */
#pragma once

#include "uwb/filter/EkfParams.h"
#include "uwb/filter/NavState.h"
#include "uwb/filter/StateIndex.h"

namespace uwb {

/// World-frame gravity vector (z up) [m/s²].
inline const Vec3 kWorldGravity_mps2{0.0, 0.0, -kGravity_mps2};

/// Non-trivial 3×3 blocks of F (F4); every other block is 0 or I:
///   F = [I  F_pv  ½dt·F_vθ  ½dt·F_vba  0 ;  0 F_vv F_vθ F_vba 0 ;  0 0 F_θθ 0 F_θbg ;  0 0 0 I 0 ;  0 0 0 0 I],
///   F_pv = dt I and F_vv = I without rotor drag (F2a).
struct ImuStepJacobian {
  double dt_s = 0.0;
  /// (F2a) Diagonals of F_pv and F_vv, the velocity's blocks: dt I and I without rotor drag; with drag k (thrust
  /// model) dt (1 − ½k dt) and 1 − k dt on the horizontal axes.
  Vec3 F_p_v_diag = Vec3::Zero();
  Vec3 F_v_v_diag = Vec3::Ones();
  Mat3 F_v_att = Mat3::Zero();        ///< −w_R_b [f]× dt
  Mat3 F_v_accbias = Mat3::Zero();    ///< −w_R_b S dt
  Mat3 F_att_att = Mat3::Identity();  ///< Exp(ω dt)ᵀ
  Mat3 F_att_gyrobias = Mat3::Zero(); ///< −J_r(ω dt) dt
  Mat3 G_v_acc = Mat3::Zero();        ///< w_R_b S dt (∂v'/∂ accelerometer noise)
};

/// Noise inputs of G (F5): accelerometer and gyroscope reading noise, bias increments.
enum NoiseIndex : int { kNoiseAcc = 0, kNoiseGyro = 3, kNoiseAccBias = 6, kNoiseGyroBias = 9, kNoiseDim = 12 };
using NoiseMat = Eigen::Matrix<double, kDim, kNoiseDim>;

struct ProcessStep {
  NavState next;
  ImuStepJacobian J;
  /// Dense F = ∂δx'/∂δx (F4), built from the blocks (for tests and documentation; the filter uses the blocks).
  ErrMat F() const;
  /// Dense G = ∂δx'/∂n (F5).
  NoiseMat G() const;
};

/// One step of the quadrotor IMU model (F2–F5). Pure; dt_s ≥ 0. drag_per_s: the rotor drag k of the thrust model
/// (F2a), a = R f + g_w − k v_h; ignored with AccelModel::kFull, whose x/y readings carry the drag.
ProcessStep quadImuProcess(const NavState& state, const ImuReading& imu, double dt_s, AccelModel accel_model,
                           double drag_per_s = 0.0);

/// TDoA-only step (F9): constant velocity (a = 0) or constant acceleration (a held in the b_acc_bias block,
/// world frame). Attitude and gyro bias are carried unchanged. Returns the dense F.
ErrMat tdoaOnlyProcess(NavState& state, double dt_s, ProcessModel model);
/// The nominal part of tdoaOnlyProcess only (no F).
void tdoaOnlyPredictNominal(NavState& state, double dt_s, ProcessModel model);

/// Error between two nominal states, x1 ⊟ x0 (F1): [p1−p0, v1−v0, Log(q0⁻¹q1), b_a1−b_a0, b_g1−b_g0].
ErrVec boxMinus(const NavState& x1, const NavState& x0);
/// x ⊞ δx (F8): p+δp, v+δv, q ⊗ Exp(δθ), b+δb.
NavState boxPlus(const NavState& x, const ErrVec& dx);

/// SO(3) exponential as a unit quaternion, Exp(φ); accurate for small |φ|.
Quat expQuat(const Vec3& phi);
/// SO(3) logarithm of a unit quaternion (rotation vector, |φ| ≤ π).
Vec3 logQuat(const Quat& q);
/// Right Jacobian of SO(3), J_r(φ) (F6).
Mat3 rightJacobianSo3(const Vec3& phi);

}  // namespace uwb
