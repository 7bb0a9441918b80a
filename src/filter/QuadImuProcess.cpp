/** @file QuadImuProcess.cpp
 *  @brief Quadrotor IMU process model (Mueller, Hamer, D'Andrea 2015) and TDoA-only models;
 *         docs/math/filter.md F2–F6, F9.
 */
#include "uwb/filter/QuadImuProcess.h"

#include <cmath>

#include "uwb/model/TdoaModel.h"  // skew

namespace uwb {

namespace {

/// Below this rotation angle [rad] the trigonometric coefficients are evaluated by their Taylor series in θ²
/// (Horner form) instead of sin/cos. The series are truncated after the θ⁸ term, whose successor is below
/// 1e-19 relative at θ = 0.1, i.e. far below double rounding (2.2e-16): the same values to rounding, at a tenth of the
/// cost of sincos. IMU steps (|ω|·Δt ≤ ~0.05) and filter resets (|δθ| ~ 1e-4) always take this branch.
constexpr double kSeriesAngle_rad = 0.1;

}  // namespace

Quat expQuat(const Vec3& phi) {
  // Exp(φ) = (cos(θ/2), sin(θ/2)/θ · φ), θ = |φ| (F8).
  const double theta2 = phi.squaredNorm();
  if (theta2 < kSeriesAngle_rad * kSeriesAngle_rad) {
    // cos(θ/2) = Σ (−1)ᵏ θ²ᵏ / (4ᵏ (2k)!),  sin(θ/2)/θ = ½ Σ (−1)ᵏ θ²ᵏ / (4ᵏ (2k+1)!),  k = 0..4
    const double t = theta2;
    const double c = 1.0 + t * (-1.0 / 8.0 + t * (1.0 / 384.0 + t * (-1.0 / 46080.0 + t * (1.0 / 10321920.0))));
    const double s =
        0.5 * (1.0 + t * (-1.0 / 24.0 + t * (1.0 / 1920.0 + t * (-1.0 / 322560.0 + t * (1.0 / 92897280.0)))));
    return Quat(c, s * phi.x(), s * phi.y(), s * phi.z());
  }
  const double angle = std::sqrt(theta2);
  const double half = 0.5 * angle;
  const double s = std::sin(half) / angle;
  return Quat(std::cos(half), s * phi.x(), s * phi.y(), s * phi.z());
}

Vec3 logQuat(const Quat& q_in) {
  Quat q = q_in;
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // shortest rotation
  const Vec3 v = q.vec();
  const double s = v.norm();
  if (s < 1e-10) return 2.0 * v / q.w();
  const double angle = 2.0 * std::atan2(s, q.w());
  return (angle / s) * v;
}

Mat3 rightJacobianSo3(const Vec3& phi) {
  // docs/math/filter.md (F6): J_r(φ) = I − (1−cos θ)/θ² [φ]× + (θ − sin θ)/θ³ [φ]×²
  const double theta2 = phi.squaredNorm();
  const Mat3 S = skew(phi);
  double a = 0.0, b = 0.0;  // (1−cos θ)/θ², (θ − sin θ)/θ³
  if (theta2 < kSeriesAngle_rad * kSeriesAngle_rad) {
    // Taylor series in θ² through θ⁸ (see kSeriesAngle_rad); also avoids the cancellation in 1 − cos θ:
    // (1−cos θ)/θ² = Σ (−1)ᵏ θ²ᵏ/(2k+2)!,  (θ − sin θ)/θ³ = Σ (−1)ᵏ θ²ᵏ/(2k+3)!
    const double t = theta2;
    a = 1.0 / 2.0 + t * (-1.0 / 24.0 + t * (1.0 / 720.0 + t * (-1.0 / 40320.0 + t * (1.0 / 3628800.0))));
    b = 1.0 / 6.0 + t * (-1.0 / 120.0 + t * (1.0 / 5040.0 + t * (-1.0 / 362880.0 + t * (1.0 / 39916800.0))));
  } else {
    const double theta = std::sqrt(theta2);
    a = (1.0 - std::cos(theta)) / theta2;
    b = (theta - std::sin(theta)) / (theta2 * theta);
  }
  return Mat3::Identity() - a * S + b * (S * S);
}

ProcessStep quadImuProcess(const NavState& x, const ImuReading& imu, double dt_s, AccelModel accel_model,
                           double drag_per_s) {
  ProcessStep out;
  const Mat3 w_R_b = x.w_q_b.toRotationMatrix();
  // (F2) specific force after bias removal; S selects the axes that are integrated (F3)
  Vec3 b_f = imu.b_acc_mps2 - x.b_acc_bias;
  Mat3 S = Mat3::Identity();
  if (accel_model == AccelModel::kThrustOnly) {
    b_f.x() = 0.0;
    b_f.y() = 0.0;
    S.diagonal() << 0.0, 0.0, 1.0;
  }
  const Vec3 b_omega = imu.b_gyro_radps - x.b_gyro_bias;
  Vec3 w_a = w_R_b * b_f + kWorldGravity_mps2;
  // (F2a) rotor drag, −k v_h: the thrust-axis model leaves the x/y readings out, and with them the drag they carry
  const double k = accel_model == AccelModel::kThrustOnly ? drag_per_s : 0.0;
  w_a.head<2>() -= k * x.w_v_b.head<2>();
  const Vec3 phi = b_omega * dt_s;
  const Quat dq = expQuat(phi);  // one Exp for the nominal step and F_θθ

  out.next.w_p_b = x.w_p_b + x.w_v_b * dt_s + 0.5 * dt_s * dt_s * w_a;
  out.next.w_v_b = x.w_v_b + dt_s * w_a;
  out.next.w_q_b = (x.w_q_b * dq).normalized();
  out.next.b_acc_bias = x.b_acc_bias;
  out.next.b_gyro_bias = x.b_gyro_bias;

  // (F4) error-state Jacobian blocks
  out.J.dt_s = dt_s;
  out.J.F_p_v_diag << dt_s * (1.0 - 0.5 * k * dt_s), dt_s * (1.0 - 0.5 * k * dt_s), dt_s;
  out.J.F_v_v_diag << 1.0 - k * dt_s, 1.0 - k * dt_s, 1.0;
  out.J.F_v_att = -(w_R_b * skew(b_f)) * dt_s;
  out.J.G_v_acc = w_R_b * S * dt_s;
  out.J.F_v_accbias = -out.J.G_v_acc;
  out.J.F_att_att = dq.toRotationMatrix().transpose();
  out.J.F_att_gyrobias = -rightJacobianSo3(phi) * dt_s;
  return out;
}

ErrMat ProcessStep::F() const {
  ErrMat F = ErrMat::Identity();
  const double dt = J.dt_s;
  F.block<3, 3>(kPos, kVel) = J.F_p_v_diag.asDiagonal();
  F.block<3, 3>(kVel, kVel) = J.F_v_v_diag.asDiagonal();
  F.block<3, 3>(kPos, kAtt) = 0.5 * dt * J.F_v_att;
  F.block<3, 3>(kPos, kAccBias) = 0.5 * dt * J.F_v_accbias;
  F.block<3, 3>(kVel, kAtt) = J.F_v_att;
  F.block<3, 3>(kVel, kAccBias) = J.F_v_accbias;
  F.block<3, 3>(kAtt, kAtt) = J.F_att_att;
  F.block<3, 3>(kAtt, kGyroBias) = J.F_att_gyrobias;
  return F;
}

NoiseMat ProcessStep::G() const {
  // (F5) reading noise n_a, n_g enters like a bias with opposite sign; bias increments enter directly.
  NoiseMat G = NoiseMat::Zero();
  const double dt = J.dt_s;
  G.block<3, 3>(kPos, kNoiseAcc) = 0.5 * dt * J.G_v_acc;
  G.block<3, 3>(kVel, kNoiseAcc) = J.G_v_acc;
  G.block<3, 3>(kAtt, kNoiseGyro) = -J.F_att_gyrobias;
  G.block<3, 3>(kAccBias, kNoiseAccBias) = Mat3::Identity();
  G.block<3, 3>(kGyroBias, kNoiseGyroBias) = Mat3::Identity();
  return G;
}

void tdoaOnlyPredictNominal(NavState& x, double dt_s, ProcessModel model) {
  // (F9) constant velocity: p' = p + v dt; constant acceleration: p' = p + v dt + ½ a dt², v' = v + a dt.
  if (model == ProcessModel::kConstantAcceleration) {
    const Vec3& w_a = x.b_acc_bias;  // world-frame acceleration in this model
    x.w_p_b += x.w_v_b * dt_s + 0.5 * dt_s * dt_s * w_a;
    x.w_v_b += w_a * dt_s;
  } else {
    x.w_p_b += x.w_v_b * dt_s;
  }
}

ErrMat tdoaOnlyProcess(NavState& x, double dt_s, ProcessModel model) {
  ErrMat F = ErrMat::Identity();
  F.block<3, 3>(kPos, kVel) = dt_s * Mat3::Identity();
  if (model == ProcessModel::kConstantAcceleration) {
    F.block<3, 3>(kPos, kAccBias) = 0.5 * dt_s * dt_s * Mat3::Identity();
    F.block<3, 3>(kVel, kAccBias) = dt_s * Mat3::Identity();
  }
  tdoaOnlyPredictNominal(x, dt_s, model);
  return F;
}

ErrVec boxMinus(const NavState& x1, const NavState& x0) {
  ErrVec d;
  d.segment<3>(kPos) = x1.w_p_b - x0.w_p_b;
  d.segment<3>(kVel) = x1.w_v_b - x0.w_v_b;
  d.segment<3>(kAtt) = logQuat(x0.w_q_b.conjugate() * x1.w_q_b);
  d.segment<3>(kAccBias) = x1.b_acc_bias - x0.b_acc_bias;
  d.segment<3>(kGyroBias) = x1.b_gyro_bias - x0.b_gyro_bias;
  return d;
}

NavState boxPlus(const NavState& x, const ErrVec& dx) {
  NavState y;
  y.w_p_b = x.w_p_b + dx.segment<3>(kPos);
  y.w_v_b = x.w_v_b + dx.segment<3>(kVel);
  y.w_q_b = (x.w_q_b * expQuat(dx.segment<3>(kAtt))).normalized();
  y.b_acc_bias = x.b_acc_bias + dx.segment<3>(kAccBias);
  y.b_gyro_bias = x.b_gyro_bias + dx.segment<3>(kGyroBias);
  return y;
}

}  // namespace uwb
