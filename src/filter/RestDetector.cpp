/** @file RestDetector.cpp
 *  @brief Rest detection from IMU moving statistics (docs/math/filter.md F18).
 */
#include "uwb/filter/RestDetector.h"

#include <cmath>
#include <stdexcept>

namespace uwb {

double expNegative(double x) {
  if (!(x < 0.1)) return std::exp(-x);
  const double x2 = x * x, x4 = x2 * x2, x8 = x4 * x4;
  const double p01 = 1.0 - x, p23 = 1.0 / 2.0 - x * (1.0 / 6.0), p45 = 1.0 / 24.0 - x * (1.0 / 120.0),
               p67 = 1.0 / 720.0 - x * (1.0 / 5040.0), p89 = 1.0 / 40320.0 - x * (1.0 / 362880.0);
  return (p01 + x2 * p23) + x4 * (p45 + x2 * p67) + x8 * p89;
}

RestDetector::RestDetector(const RestDetectorParams& params)
    : params_(params),
      acc_var_max_(params.acc_std_mps2 * params.acc_std_mps2),
      gyro_ms_max_(params.gyro_rms_radps * params.gyro_rms_radps),
      rate_per_s_(1.0 / params.tau_s),
      hp_rate_per_s_(1.0 / params.hp_tau_s),
      contact_ms_min_(params.contact_gyro_hp_rms_radps * params.contact_gyro_hp_rms_radps) {
  if (!(params.acc_std_mps2 > 0.0 && params.gyro_rms_radps > 0.0 && params.tau_s > 0.0 && params.min_hold_s >= 0.0 &&
        params.contact_gyro_hp_rms_radps > 0.0 && params.hp_tau_s > 0.0 && params.max_gyro_reference_radps >= 0.0))
    throw std::invalid_argument(
        "RestDetectorParams: thresholds and tau_s must be > 0, min_hold_s and max_gyro_reference_radps >= 0");
}

bool RestDetector::stillNow() const {
  return acc_var_ < acc_var_max_ && (gyro_ms_ < gyro_ms_max_ || (has_gyro_ref_ && gyro_ref_ms_ < gyro_ms_max_));
}

bool RestDetector::setGyroReference(const Vec3& b_gyro_radps) {
  if (!b_gyro_radps.allFinite() || b_gyro_radps.norm() > params_.max_gyro_reference_radps) return false;
  gyro_ref_ = b_gyro_radps;
  gyro_ref_ms_ = gyro_ms_;
  has_gyro_ref_ = true;
  return true;
}

void RestDetector::reset(const ImuReading& imu) {
  acc_mean_ = imu.b_acc_mps2.norm();
  acc_var_ = 1.0;
  gyro_ms_ = 1.0;
  gyro_ref_ms_ = 1.0;
  gyro_hp_ms_ = 0.0;
  gyro_mean_ = imu.b_gyro_radps;
  still_ = at_rest_ = false;
}

void RestDetector::seed(double t_s, double acc_var_mps2sq, double gyro_ms_radps2sq, double gyro_ref_ms_radps2sq) {
  const auto usable = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (!usable(acc_var_mps2sq) || !usable(gyro_ms_radps2sq)) return;
  acc_var_ = acc_var_mps2sq;
  gyro_ms_ = gyro_ms_radps2sq;
  if (has_gyro_ref_ && usable(gyro_ref_ms_radps2sq)) gyro_ref_ms_ = gyro_ref_ms_radps2sq;
  // the hold starts now: at rest min_hold_s later if the samples that follow stay still (F18)
  still_ = stillNow();
  t_still_since_ = t_s;
  at_rest_ = still_ && params_.min_hold_s <= 0.0;
}

void RestDetector::update(double t_s, const ImuReading& imu, double dt_s) {
  if (dt_s > 0.0) {
    // (F18) EMA of |f|, its variance and the gyro mean square, weight 1 − exp(−Δt/τ)
    if (dt_s != dt_cached_s_) {
      dt_cached_s_ = dt_s;
      a_cached_ = expNegative(dt_s * rate_per_s_);
      a_hp_cached_ = expNegative(dt_s * hp_rate_per_s_);
    }
    const double a = a_cached_;
    const double an = imu.b_acc_mps2.norm();
    acc_mean_ = a * acc_mean_ + (1 - a) * an;
    acc_var_ = a * acc_var_ + (1 - a) * (an - acc_mean_) * (an - acc_mean_);
    gyro_ms_ = a * gyro_ms_ + (1 - a) * imu.b_gyro_radps.squaredNorm();
    if (has_gyro_ref_) gyro_ref_ms_ = a * gyro_ref_ms_ + (1 - a) * (imu.b_gyro_radps - gyro_ref_).squaredNorm();
    // high-passed gyro: deviation from its own short moving mean (rotor-frame shaking, not turning)
    const double a_hp = a_hp_cached_;
    gyro_mean_ = a_hp * gyro_mean_ + (1 - a_hp) * imu.b_gyro_radps;
    gyro_hp_ms_ = a * gyro_hp_ms_ + (1 - a) * (imu.b_gyro_radps - gyro_mean_).squaredNorm();
  }
  const bool still = stillNow();
  if (still && !still_) t_still_since_ = t_s;
  still_ = still;
  at_rest_ = still && t_s - t_still_since_ >= params_.min_hold_s;
}

}  // namespace uwb
