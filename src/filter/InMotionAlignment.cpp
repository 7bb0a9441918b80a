/** @file InMotionAlignment.cpp
 *  @brief docs/math/filter.md F28.
 */
#include "uwb/filter/InMotionAlignment.h"

#include <Eigen/SVD>
#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "uwb/filter/QuadImuProcess.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {

double headingOf(const Quat& w_q_b) {
  const Mat3 R = w_q_b.toRotationMatrix();
  return std::atan2(R(1, 0), R(0, 0));
}

Eigen::RowVector3d headingJacobian(const Quat& w_q_b) {
  const Mat3 R = w_q_b.toRotationMatrix();
  const Vec3 c = R.col(0);
  const Mat3 dc = -R * skew(Vec3::UnitX());
  return (c(0) * dc.row(1) - c(1) * dc.row(0)) / (c(0) * c(0) + c(1) * c(1));
}

InMotionAlignment::InMotionAlignment(double window_s, double sample_period_s, double correlation_s,
                                     double drag_per_s)
    : window_s_(window_s), sample_period_s_(sample_period_s), correlation_s_(correlation_s), drag_per_s_(drag_per_s) {
  if (!(drag_per_s >= 0.0) || !std::isfinite(drag_per_s))
    throw std::invalid_argument(fmt::format("heading alignment: drag {} /s must be finite and ≥ 0", drag_per_s));
  if (!(window_s > 0.0) || !(sample_period_s > 0.0) || !(correlation_s > 0.0))
    throw std::invalid_argument(
        fmt::format("heading alignment: window {} s, sample period {} s, correlation {} s must be > 0", window_s,
                    sample_period_s, correlation_s));
  // the first increment is the window's start, one more per sample period
  if (window_s / sample_period_s + 1.0 > static_cast<double>(kCapacity))
    throw std::invalid_argument(fmt::format(
        "heading alignment window {} s holds more than {} increments of {} s (at most {} s)", window_s, kCapacity,
        sample_period_s, static_cast<double>(kCapacity - 1) * sample_period_s));
}

void InMotionAlignment::reset() { n_ = 0; }

void InMotionAlignment::add(double t_s, const Vec3& f_b, const Vec3& omega_b, double dt_s, const Vec3& w_v) {
  if (n_ == 0) {
    // (F28) a new window: body(t₀) is the frame of this sample, the velocity increments count from here
    t0_ = t_last_ = t_s;
    t_next_sample_ = t_s + sample_period_s_;
    dq_ = Quat::Identity();
    beta_.setZero();
    phi_.setZero();
    jg_.setZero();
    ja_.setZero();
    v0_ = w_v;
    displacement_.setZero();
    step_f_dt_.setZero();
    step_w_dt_.setZero();
    step_dt_ = 0.0;
    alpha_[0].setZero();
    beta_k_[0].setZero();
    jg_k_[0].setZero();
    ja_k_[0].setZero();
    n_ = 1;
    return;
  }
  if (!(dt_s > 0.0)) return;
  // (F28a) the samples are summed over a step and integrated with their means: the sums cost three additions
  step_f_dt_ += f_b * dt_s;
  step_w_dt_ += omega_b * dt_s;
  step_dt_ += dt_s;
  displacement_ += w_v * dt_s;
  t_last_ = t_s;
  const bool store = t_s + 1e-9 >= t_next_sample_ && n_ < kCapacity;
  // a complete window is solved now: its attitude (ΔR, Φ) must include every sample
  if (store || complete() || step_dt_ >= kIntegrationStep_s - 1e-9) integrateStep();
  if (store) {
    const double tau = t_s - t0_;
    // α = v − v₀ − g_w τ + k ∫ v_h dτ with g_w = (0, 0, −g) (F28a, F28a′)
    alpha_[n_] = w_v - v0_ + Vec3(0.0, 0.0, kGravity_mps2 * tau);
    alpha_[n_].head<2>() += drag_per_s_ * displacement_.head<2>();
    beta_k_[n_] = beta_;
    jg_k_[n_] = jg_;
    ja_k_[n_] = ja_;
    ++n_;
    t_next_sample_ += sample_period_s_;
  }
}

void InMotionAlignment::integrateStep() {
  if (!(step_dt_ > 0.0)) return;
  const double dt = step_dt_;
  const Vec3 f = step_f_dt_ / dt, w = step_w_dt_ / dt;
  step_f_dt_.setZero();
  step_w_dt_.setZero();
  step_dt_ = 0.0;
  // (F28a, F28b) β += ΔR_mid f dt with the rotation at the step's middle, ΔR_mid ≈ ΔR (I + [ω dt/2]×), then
  // ΔR ← ΔR exp(ω dt) (the rotation over the step, as in the prediction F7); with them the first-order effect of a
  // bias change δb_g, δb_a (ΔR(δb) ≈ ΔR Exp(Φ δb_g), ω → ω − δb_g, f → f − δb_a):
  // ∂β/∂b_g += −ΔR [f_mid]× Φ dt + ΔR [f]× dt²/2, ∂β/∂b_a += −ΔR (I + [ω dt/2]×) dt,
  // Φ ← Exp(ω dt)ᵀ Φ − J_r dt with the right Jacobian of Exp to first order, J_r ≈ I − [ω dt]×/2 (|ω dt| ≪ 1)
  const Mat3 dR = dq_.toRotationMatrix();
  const Vec3 half_turn = 0.5 * dt * w;
  const Vec3 f_mid = f + half_turn.cross(f);
  const Mat3 dR_mid = dR * (Mat3::Identity() + skew(half_turn));
  jg_.noalias() -= dR * (skew(f_mid) * phi_ * dt - skew(f) * (0.5 * dt * dt));
  ja_.noalias() -= dR_mid * dt;
  beta_.noalias() += dR * f_mid * dt;
  const Quat step = expQuat(w * dt);
  phi_ = (step.conjugate().toRotationMatrix() * phi_).eval() - (Mat3::Identity() - skew(half_turn)) * dt;
  dq_ = (dq_ * step).normalized();
}

namespace {

/// Wahba's problem: the rotation R minimising Σ |a_k − R b_k|², from B = Σ a_k b_kᵀ = U S Vᵀ as
/// R = U diag(1, 1, det(U) det(V)) Vᵀ (Markley 1988).
Mat3 wahba(const Mat3& B) {
  const Eigen::JacobiSVD<Mat3> svd(B, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  D(2, 2) = (svd.matrixU().determinant() * svd.matrixV().determinant()) < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

// (F28) prior std of the bias changes over a window, and the velocity error the prior is weighed against
constexpr double kGyroBiasPrior_radps = 0.02;
// the body-z gyro bias turns the horizontal increments only, weakly against the heading it trades with (a yaw-rate
// error of 0.19 rad/s fitted the unmodelled forces of a real circle, filter.md F28b): held to 0.005 rad/s (2.3° over
// 8 s), which the filter's own gyro-bias estimate meets
constexpr double kYawGyroBiasPrior_radps = 0.005;
constexpr double kAccBiasPrior_mps2 = 0.2;
constexpr double kPriorVelocitySigma_mps = 0.1;

}  // namespace

std::optional<InMotionAlignment::Result> InMotionAlignment::solve() const {
  if (n_ < 5) return std::nullopt;
  // (F28) R₀ and the bias changes δb = (δb_g, δb_a) minimise Σ |α_k − R₀ (β_k + J_k δb)|², J_k = [∂β/∂b_g, ∂β/∂b_a],
  // with a weak prior on δb
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  using Mat36 = Eigen::Matrix<double, 3, 6>;
  const auto jac = [&](std::size_t k) {
    Mat36 J;
    J << jg_k_[k], ja_k_[k];
    return J;
  };
  Vec6 prior_info;
  const double wg = kPriorVelocitySigma_mps / kGyroBiasPrior_radps, wa = kPriorVelocitySigma_mps / kAccBiasPrior_mps2;
  const double wgz = kPriorVelocitySigma_mps / kYawGyroBiasPrior_radps;
  prior_info << wg * wg, wg * wg, wgz * wgz, wa * wa, wa * wa, wa * wa;
  // start from Wahba without bias changes, then Gauss-Newton on (δθ, δb) jointly (the tilt at t₀ and a gyro drift are
  // strongly coupled, which alternating the two would follow only slowly): Exp(δθ) x ≈ x − [x]× δθ, so
  // r_k(δθ, Δb) ≈ r_k + [R₀β̃_k]× δθ − R₀ J_k Δb
  Vec6 db = Vec6::Zero();
  Mat3 B = Mat3::Zero();
  for (std::size_t k = 1; k < n_; ++k) B.noalias() += alpha_[k] * beta_k_[k].transpose();
  Mat3 R0 = wahba(B);
  using Mat9 = Eigen::Matrix<double, 9, 9>;
  using Vec9 = Eigen::Matrix<double, 9, 1>;
  for (int it = 0; it < 6; ++it) {
    Mat9 A = Mat9::Zero();
    Vec9 g = Vec9::Zero();
    A.bottomRightCorner<6, 6>().diagonal() = prior_info;
    g.tail<6>() = -prior_info.cwiseProduct(db);
    for (std::size_t k = 1; k < n_; ++k) {
      const Mat36 J = jac(k);
      const Vec3 rb = R0 * (beta_k_[k] + J * db);
      const Vec3 r = alpha_[k] - rb;
      Eigen::Matrix<double, 3, 9> H;
      H << skew(rb), -R0 * J;
      // coefficient-wise products: at 9 × 3 × 9 Eigen would otherwise take its blocked GEMM path, slower at this size
      A.noalias() += H.transpose().lazyProduct(H);
      g.noalias() -= H.transpose() * r;
    }
    const Vec9 step = A.ldlt().solve(g);
    R0 = (expQuat(step.head<3>()).toRotationMatrix() * R0).eval();
    db += step.tail<6>();
    if (step.norm() < 1e-12) break;
  }
  // residuals and the information of (δθ about world axes, δb): ∂r/∂δθ = [R₀β̃]×, ∂r/∂δb = −R₀ J
  Mat9 F = Mat9::Zero();
  double r2 = 0.0, h2 = 0.0;
  for (std::size_t k = 1; k < n_; ++k) {
    const Mat36 J = jac(k);
    const Vec3 rb = R0 * (beta_k_[k] + J * db);
    r2 += (alpha_[k] - rb).squaredNorm();
    h2 += alpha_[k].head<2>().squaredNorm();
    Eigen::Matrix<double, 3, 9> H;
    H << skew(rb), -R0 * J;
    F.noalias() += H.transpose().lazyProduct(H);
  }
  const double m = static_cast<double>(n_ - 1);
  Result res;
  res.rms_residual_mps = std::sqrt(r2 / (3.0 * m));
  res.horizontal_excitation_mps = std::sqrt(h2 / m);
  res.gyro_bias_change_radps = db.head<3>();
  res.acc_bias_change_mps2 = db.tail<3>();
  // the attitude now: R₀ ΔR Exp(Φ δb_g)
  res.w_q_b = (Quat(R0) * dq_ * expQuat(phi_ * db.head<3>())).normalized();
  // (F28) covariance σ_r² F⁻¹ with the bias prior, the residuals counted once per correlation time (they are velocity
  // errors, correlated): a small rotation δ about world z moves R₀β̃_k by δ e_z × R₀β̃_k
  const double samples_per_independent = std::max(1.0, correlation_s_ / sample_period_s_);
  const double s2 = std::max(r2 / (3.0 * m), 1e-12) * samples_per_independent;
  Mat9 info = F / s2;
  info.bottomRightCorner<6, 6>().diagonal() += prior_info / (kPriorVelocitySigma_mps * kPriorVelocitySigma_mps);
  const Mat9 cov = info.ldlt().solve(Mat9::Identity());
  // the attitude now, R₀ ΔR Exp(Φ δb_g), moves about the world axes by δθ + R₀ ΔR Φ δb_g
  Eigen::Matrix<double, 3, 9> G = Eigen::Matrix<double, 3, 9>::Zero();
  G.leftCols<3>() = Mat3::Identity();
  G.block<3, 3>(0, 3) = R0 * dq_.toRotationMatrix() * phi_;
  const Mat3 cov_now = G * cov * G.transpose();
  res.heading_sigma_rad = std::sqrt(std::max(cov_now(2, 2), 0.0));
  res.tilt_sigma_rad = std::sqrt(std::max(std::max(cov_now(0, 0), cov_now(1, 1)), 0.0));
  return res;
}

}  // namespace uwb
