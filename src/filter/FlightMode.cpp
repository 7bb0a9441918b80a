/** @file FlightMode.cpp
 *  @brief The flight-mode supervisor (docs/math/filter.md F29).
 */
#include "uwb/filter/FlightMode.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "uwb/filter/RestDetector.h"

namespace uwb {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// A single TDoA's height is clipped to this interval about the floor [m]: one TDoA of small vertical gain and a
/// large residual must not carry the window (F29c).
constexpr double kMinSampleHeight_m = -3.0, kMaxSampleHeight_m = 6.0;

}  // namespace

std::string toString(FlightMode mode) {
  switch (mode) {
    case FlightMode::kRest: return "rest";
    case FlightMode::kContact: return "contact";
    case FlightMode::kAirborne: return "airborne";
  }
  return "unknown";
}

void FlightModeParams::validate() const {
  if (!(imu_max_log_odds > 0.0 && imu_rest_log_odds >= imu_max_log_odds && imu_rate_per_s > 0.0 &&
        tdoa_max_log_odds > 0.0 && tdoa_max_floor_log_odds >= 0.0 && tdoa_window_s > 0.0 &&
        tdoa_min_effective >= 2.0 && tdoa_independent >= 1.0 && min_vertical_gain > 0.0 &&
        height_floor_sigma_m > 0.0 && air_min_height_m >= 0.0 && air_max_height_m > air_min_height_m &&
        hysteresis_log_odds >= 0.0 && air_shake_ratio >= 1.0 && air_shake_prior_ms > 0.0 && air_shake_tau_s > 0.0 &&
        tof_window_s > 0.0 && tof_min_effective >= 1.0 && tof_height_sigma_m > 0.0))
    throw std::invalid_argument("FlightModeParams: bounds, rates, windows and sigmas must be > 0, "
                                "imu_rest_log_odds >= imu_max_log_odds, air_max_height_m > air_min_height_m, "
                                "air_shake_ratio >= 1, tdoa_min_effective >= 2, tdoa_independent >= 1, "
                                "tof_min_effective >= 1");
}

FlightModeSupervisor::FlightModeSupervisor(const FlightModeParams& params)
    : params_(params),
      tdoa_height_m_(kNaN),
      tdoa_height_spread_m_(kNaN),
      tof_height_m_(kNaN),
      tof_height_spread_m_(kNaN),
      air_shake_ms_(params.air_shake_prior_ms) {
  params_.validate();
}

void FlightModeSupervisor::reset(FlightMode mode) {
  mode_ = mode;
  imu_log_odds_ = mode == FlightMode::kAirborne ? params_.imu_max_log_odds : -params_.imu_max_log_odds;
  overruled_ = false;
  clearTdoa();
  tof_ = HeightWindow{};
  t_tof_ = -1e300;
  n_tof_ = tof_log_odds_ = 0.0;
  tof_height_m_ = tof_height_spread_m_ = kNaN;
}

void FlightModeSupervisor::clearTdoa() {
  n_ = 0.0;
  air_ = floor_ = HeightWindow{};
  t_tdoa_ = -1e300;
  tdoa_log_odds_ = 0.0;
  tdoa_height_m_ = tdoa_height_spread_m_ = kNaN;
}

bool FlightModeSupervisor::shakingStandsOut(double shake_ms_radps2) const {
  // (F29b) floor contact shakes the frame far more than this flight shakes in the air
  return shake_ms_radps2 > params_.air_shake_ratio * air_shake_ms_;
}

void FlightModeSupervisor::learnAirShake(double shake_ms_radps2) {
  if (!(std::isfinite(shake_ms_radps2) && shake_ms_radps2 > 0.0)) return;
  air_shake_ms_ = std::max(air_shake_ms_, shake_ms_radps2);
  air_shake_learned_ = true;
  // … and the floor evidence the IMU drew from that shaking is void (rest, motors off, is not shaking)
  if (!imu_rest_) imu_log_odds_ = std::max(imu_log_odds_, 0.0);
}

void FlightModeSupervisor::addImu(double t_s, double dt_s, const ImuModeEvidence& e, bool settled_in_air) {
  imu_rest_ = e.rest;
  imu_contact_ = e.shaking_near_floor;
  imu_climb_ = e.climbing;
  if (!(dt_s > 0.0)) return;
  // (F29a) the IMU's log-odds airborne : floor move at a bounded rate within ±imu_max_log_odds
  // (rest, motors off: towards its own, larger bound, reached as fast; when rest ends, back within ±imu_max_log_odds)
  const bool rest = e.rest && !e.climbing;
  const double direction = e.climbing ? 2.0 : (e.rest || e.shaking_near_floor) ? -1.0 : 1.0;
  const double floor_bound = rest ? params_.imu_rest_log_odds : params_.imu_max_log_odds;
  const double rate = params_.imu_rate_per_s * floor_bound / params_.imu_max_log_odds;
  imu_log_odds_ = std::clamp(imu_log_odds_ + direction * rate * dt_s, -floor_bound, params_.imu_max_log_odds);
  // (F29b) the airborne shaking level: an upper envelope of the high-passed gyro mean square while settled in the
  // air, rising at once, decaying with air_shake_tau_s, never below the prior
  if (settled_in_air && std::isfinite(e.shake_ms_radps2) && e.shake_ms_radps2 >= 0.0) {
    const double a = expNegative(dt_s / params_.air_shake_tau_s);
    air_shake_ms_ = std::max({params_.air_shake_prior_ms, e.shake_ms_radps2, a * air_shake_ms_});
    air_shake_learned_ = true;
  }
  (void)t_s;
}

double FlightModeSupervisor::HeightWindow::spread2() const {
  const double h = mean();
  return std::max(swhh / sw - h * h, 0.0);
}

void FlightModeSupervisor::addTdoa(double t_s, double residual_air_m, double residual_floor_m, double dh_dz,
                                   double estimate_height_m) {
  if (!(std::isfinite(residual_air_m) && std::isfinite(residual_floor_m) && std::isfinite(dh_dz) &&
        std::isfinite(estimate_height_m)))
    return;
  // (F29c) forgetting over tdoa_window_s
  const double a = t_s >= t_tdoa_ ? expNegative((t_s - t_tdoa_) / params_.tdoa_window_s) : 1.0;
  t_tdoa_ = std::max(t_tdoa_, t_s);
  n_ *= a;
  air_.scale(a);
  floor_.scale(a);
  if (std::abs(dh_dz) >= params_.min_vertical_gain) {
    // (F29c) the height this TDoA puts the tag at: the estimate's, moved along z by the residual over the gain
    const auto height = [&](double r) {
      return std::clamp(estimate_height_m + r / dh_dz, kMinSampleHeight_m, kMaxSampleHeight_m);
    };
    const double w = dh_dz * dh_dz;
    n_ += 1.0;
    air_.add(w, height(residual_air_m));
    floor_.add(w, height(residual_floor_m));
  }
  updateTdoaFactor();
}

void FlightModeSupervisor::updateTdoaFactor() {
  if (n_ < params_.tdoa_min_effective || !(air_.sw > 0.0)) {
    tdoa_log_odds_ = 0.0;
    tdoa_height_m_ = tdoa_height_spread_m_ = kNaN;
    return;
  }
  // (F29c) each hypothesis explains its window by its mean square about where it puts the body: the air about the
  // nearest height of the flight range, the floor about the floor; the TDoA errors are correlated in time, so the
  // window counts as at most tdoa_independent samples
  const double h_air = air_.mean();
  const double s2_air = air_.spread2();
  const double h_floor = floor_.mean();
  const double ms_floor = floor_.spread2() + h_floor * h_floor;
  tdoa_height_m_ = h_air;
  tdoa_height_spread_m_ = std::sqrt(s2_air);
  tdoa_log_odds_ = heightLogOdds(n_, h_air, s2_air, ms_floor, params_.height_floor_sigma_m);
}

double FlightModeSupervisor::heightLogOdds(double n, double h_air, double s2_air, double ms_floor,
                                           double sigma_m) const {
  const double d = h_air < params_.air_min_height_m   ? params_.air_min_height_m - h_air
                   : h_air > params_.air_max_height_m ? h_air - params_.air_max_height_m
                                                      : 0.0;
  const double ms_air = s2_air + d * d;
  const double s2 = sigma_m * sigma_m;
  const double n_eff = std::min(n, params_.tdoa_independent);
  return std::clamp(0.5 * n_eff * (std::log(ms_floor + s2) - std::log(ms_air + s2)), -params_.tdoa_max_floor_log_odds,
                    params_.tdoa_max_log_odds);
}

void FlightModeSupervisor::addTof(double t_s, double height_m) {
  if (!(std::isfinite(t_s) && std::isfinite(height_m))) return;
  // (F29f) forgetting over tof_window_s; the height the range measures, clipped as the TDoA's
  const double a = t_s >= t_tof_ ? expNegative((t_s - t_tof_) / params_.tof_window_s) : 1.0;
  t_tof_ = std::max(t_tof_, t_s);
  tof_.scale(a);
  n_tof_ = a * n_tof_ + 1.0;
  tof_.add(1.0, std::clamp(height_m, kMinSampleHeight_m, kMaxSampleHeight_m));
  updateTofFactor();
}

void FlightModeSupervisor::dropStaleTof(double t_s) {
  // (F29f) a range that stopped reporting (out of range, the deck's dropout) stops counting: after kTofStaleWindows
  // forgetting times its readings weigh less than 1 %
  if (n_tof_ > 0.0 && t_s - t_tof_ > kTofStaleWindows * params_.tof_window_s) {
    tof_ = HeightWindow{};
    n_tof_ = 0.0;
    updateTofFactor();
  }
}

void FlightModeSupervisor::updateTofFactor() {
  if (n_tof_ < params_.tof_min_effective) {
    tof_log_odds_ = 0.0;
    tof_height_m_ = tof_height_spread_m_ = kNaN;
    return;
  }
  // (F29f) one window for both hypotheses: the air about the flight range, the floor about the floor
  const double h = tof_.mean(), s2 = tof_.spread2();
  tof_height_m_ = h;
  tof_height_spread_m_ = std::sqrt(s2);
  tof_log_odds_ = heightLogOdds(n_tof_, h, s2, s2 + h * h, params_.tof_height_sigma_m);
}

bool FlightModeSupervisor::decide(double t_s) {
  const double dt = t_s > t_last_ && t_last_ > -1e299 ? std::min(t_s - t_last_, 0.1) : 0.0;
  t_last_ = std::max(t_last_, t_s);
  dropStaleTof(t_s);
  const double sum = imu_log_odds_ + tdoa_log_odds_ + tof_log_odds_;
  // on the floor: rest or contact as the IMU reads it; without either (the IMU's log-odds on their way up), as before
  const FlightMode floor_mode = imu_rest_                     ? FlightMode::kRest
                                : imu_contact_                ? FlightMode::kContact
                                : mode_ != FlightMode::kAirborne ? mode_
                                                               : FlightMode::kContact;
  const FlightMode before = mode_;
  if (mode_ == FlightMode::kAirborne) {
    if (sum < -params_.hysteresis_log_odds) mode_ = floor_mode;
  } else if (sum > params_.hysteresis_log_odds) {
    mode_ = FlightMode::kAirborne;
  } else {
    mode_ = floor_mode;
  }
  const bool airborne_now = mode_ == FlightMode::kAirborne;
  const bool changed_side = (before == FlightMode::kAirborne) != airborne_now;
  if (changed_side) {
    // the TDoA overrule the IMU when the side taken is the one the IMU's evidence of this step and its log-odds argue
    // against (not while the log-odds are only on their way after the evidence ended)
    const bool imu_says_floor = imu_rest_ || imu_contact_;
    overruled_ = airborne_now ? imu_says_floor && imu_log_odds_ < 0.0 : !imu_says_floor && imu_log_odds_ > 0.0;
    if (overruled_) ++n_tdoa_overrules_;
  } else if ((imu_log_odds_ > 0.0) == airborne_now) {
    overruled_ = false;
  }
  // (F29d) doubt is counted only while TDoA keep coming: a window that none has refreshed for a fifth of its
  // forgetting time (a landing's re-acquisition batch, a dropout) still weighs in the mode, but it is not the TDoA
  // disagreeing now
  const bool fresh = t_s - t_tdoa_ <= 0.2 * params_.tdoa_window_s;
  if (!airborne_now && fresh && tdoa_log_odds_ > params_.tdoa_max_floor_log_odds) {
    doubted_floor_s_ += dt;
    doubted_floor_max_height_m_ = std::max(doubted_floor_max_height_m_, tdoa_height_m_);
  }
  return mode_ != before;
}

std::uint32_t FlightModeSupervisor::status() const {
  std::uint32_t s = 0;
  s |= mode_ == FlightMode::kRest ? kModeRest : mode_ == FlightMode::kContact ? kModeContact : kModeAirborne;
  if (imu_rest_) s |= kImuSaysRest;
  if (imu_contact_) s |= kImuSaysContact;
  if (imu_climb_) s |= kImuSaysClimb;
  if (std::isfinite(tdoa_height_m_)) s |= kTdoaHeightValid;
  if (tdoa_log_odds_ > params_.tdoa_max_floor_log_odds) s |= kTdoaSaysAirborne;
  if (tof_log_odds_ > params_.tdoa_max_floor_log_odds) s |= kTofSaysAirborne;
  if (overruled_) s |= kTdoaOverrulesImu;
  if (air_shake_learned_) s |= kAirShakeLearned;
  return s;
}

}  // namespace uwb
