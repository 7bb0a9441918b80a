/** @file EkfParams.cpp
 *  @brief Validation, presets and enum names of the filter parameters.
 */
#include "uwb/filter/EkfParams.h"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "uwb/filter/InMotionAlignment.h"

namespace uwb {
namespace {
void requirePositive(double v, const char* name) {
  if (!(std::isfinite(v) && v > 0.0)) throw std::invalid_argument(std::string("EkfParams.") + name + " must be > 0");
}
void requireNonNegative(double v, const char* name) {
  if (!(std::isfinite(v) && v >= 0.0)) throw std::invalid_argument(std::string("EkfParams.") + name + " must be >= 0");
}
}  // namespace

void EkfParams::validate() const {
  requireNonNegative(acc_noise_mps2_sqrthz, "acc_noise_mps2_sqrthz");
  requireNonNegative(lateral_acc_noise_mps2_sqrthz, "lateral_acc_noise_mps2_sqrthz");
  requireNonNegative(gyro_noise_radps_sqrthz, "gyro_noise_radps_sqrthz");
  requireNonNegative(acc_bias_rw_mps3_sqrthz, "acc_bias_rw_mps3_sqrthz");
  requireNonNegative(gyro_bias_rw_radps2_sqrthz, "gyro_bias_rw_radps2_sqrthz");
  requireNonNegative(pos_noise_m_sqrts, "pos_noise_m_sqrts");
  requirePositive(cv_acc_noise_mps2_sqrthz, "cv_acc_noise_mps2_sqrthz");
  requirePositive(ca_jerk_noise_mps3_sqrthz, "ca_jerk_noise_mps3_sqrthz");
  requirePositive(init_pos_sigma_m, "init_pos_sigma_m");
  requirePositive(init_vel_sigma_mps, "init_vel_sigma_mps");
  requirePositive(init_att_sigma_rad, "init_att_sigma_rad");
  requirePositive(init_yaw_sigma_rad, "init_yaw_sigma_rad");
  requirePositive(init_acc_bias_sigma_mps2, "init_acc_bias_sigma_mps2");
  requirePositive(init_gyro_bias_sigma_radps, "init_gyro_bias_sigma_radps");
  if (!b_t_tag.allFinite()) throw std::invalid_argument("EkfParams.b_t_tag must be finite");
  requirePositive(tdoa_sigma_m, "tdoa_sigma_m");
  requireNonNegative(anchor_sigma_m, "anchor_sigma_m");
  requirePositive(gate_sigma, "gate_sigma");
  requirePositive(robust_k, "robust_k");
  if (robust_iterations < 1 || robust_iterations > 20)
    throw std::invalid_argument("EkfParams.robust_iterations must be in [1, 20]");
  requirePositive(max_lost_s, "max_lost_s");
  requireNonNegative(lost_velocity_tau_s, "lost_velocity_tau_s");
  requireNonNegative(descent_margin_m, "descent_margin_m");
  if (!(max_rejection_rate > 0.0 && max_rejection_rate <= 1.0))
    throw std::invalid_argument("EkfParams.max_rejection_rate must be in (0, 1]");
  requireNonNegative(pair_bias_tau_s, "pair_bias_tau_s");
  requireNonNegative(range_bias_sigma_m, "range_bias_sigma_m");
  requirePositive(range_bias_tau_s, "range_bias_tau_s");
  requireNonNegative(range_bias_adapt_s, "range_bias_adapt_s");
  if (!(range_bias_min_fraction > 0.0 && range_bias_min_fraction <= 1.0))
    throw std::invalid_argument("EkfParams.range_bias_min_fraction must be in (0, 1]");
  if (antenna_bias_degree != 0 && (antenna_bias_degree < 2 || antenna_bias_degree > 4))
    throw std::invalid_argument("EkfParams.antenna_bias_degree must be 0 (off) or in [2, 4]");
  requirePositive(antenna_bias_sigma_m, "antenna_bias_sigma_m");
  requireNonNegative(antenna_bias_memory_s, "antenna_bias_memory_s");
  requireNonNegative(antenna_bias_offset_sigma_m, "antenna_bias_offset_sigma_m");
  requirePositive(antenna_bias_offset_memory_s, "antenna_bias_offset_memory_s");
  requirePositive(antenna_bias_noise_scale, "antenna_bias_noise_scale");
  requirePositive(bias_guard_tau_s, "bias_guard_tau_s");
  requirePositive(max_predict_dt_s, "max_predict_dt_s");
  requireNonNegative(cov_period_s, "cov_period_s");
  requireNonNegative(update_predict_dt_s, "update_predict_dt_s");
  requirePositive(max_gap_s, "max_gap_s");
  requirePositive(takeoff_climb_mps, "takeoff_climb_mps");
  requireNonNegative(acquisition_s, "acquisition_s");
  requireNonNegative(takeoff_acc_bias_sigma_mps2, "takeoff_acc_bias_sigma_mps2");
  requirePositive(acquisition_tdoa_sigma_m, "acquisition_tdoa_sigma_m");
  if (!start_w_p_b.allFinite()) throw std::invalid_argument("EkfParams.start_w_p_b must be finite");
  if (!std::isfinite(ground_z_m)) throw std::invalid_argument("EkfParams.ground_z_m must be finite");
  requireNonNegative(floor_margin_m, "floor_margin_m");
  requirePositive(rest_tdoa_sigma_m, "rest_tdoa_sigma_m");
  requireNonNegative(floor_anchor_height_m, "floor_anchor_height_m");
  requireNonNegative(leave_rest_pos_sigma_m, "leave_rest_pos_sigma_m");
  requirePositive(start_window_s, "start_window_s");
  requirePositive(moving_start_vel_sigma_mps, "moving_start_vel_sigma_mps");
  requirePositive(moving_start_att_sigma_rad, "moving_start_att_sigma_rad");
  requirePositive(moving_start_yaw_sigma_rad, "moving_start_yaw_sigma_rad");
  requirePositive(heading_alignment_window_s, "heading_alignment_window_s");
  requireNonNegative(rotor_drag_per_s, "rotor_drag_per_s");
  if (heading_alignment_window_s > InMotionAlignment::kMaxWindow_s)
    throw std::invalid_argument(fmt::format("EkfParams.heading_alignment_window_s must be ≤ {} s (got {})",
                                            InMotionAlignment::kMaxWindow_s, heading_alignment_window_s));
  requireNonNegative(output_bias_sigma_m, "output_bias_sigma_m");
  requireNonNegative(output_bias_memory_s, "output_bias_memory_s");
  requireNonNegative(bias_model_level_exponent, "bias_model_level_exponent");
  requireNonNegative(bias_model_training_level_m, "bias_model_training_level_m");
  requireNonNegative(bias_model_training_mean_level_m, "bias_model_training_mean_level_m");
  requirePositive(output_bias_level_m, "output_bias_level_m");
  requirePositive(output_bias_vertical_scale, "output_bias_vertical_scale");
  requirePositive(tof_sigma_m, "tof_sigma_m");
  if (!std::isfinite(tof_offset_m)) throw std::invalid_argument("EkfParams.tof_offset_m must be finite");
  if (!std::isfinite(floor_z_m)) throw std::invalid_argument("EkfParams.floor_z_m must be finite");
  requirePositive(tof_max_range_m, "tof_max_range_m");
  if (!std::isfinite(tof_gate_sigma)) throw std::invalid_argument("EkfParams.tof_gate_sigma must be finite");
  requirePositive(max_gyro_radps, "max_gyro_radps");
  requirePositive(max_acc_mps2, "max_acc_mps2");
  requireNonNegative(max_tdoa_excess_m, "max_tdoa_excess_m");
}

EkfParams EkfParams::crazyflieLike() {
  EkfParams p;
  p.accel_model = AccelModel::kThrustOnly;
  p.robust_loss = RobustLoss::kNone;
  p.robust_iterations = 1;
  p.tdoa_sigma_m = 0.15;  // Crazyflie measNoiseTdoa
  p.gate_sigma = 4.0;
  p.acc_noise_mps2_sqrthz = 0.5;
  p.lateral_acc_noise_mps2_sqrthz = 0.0;
  p.gyro_noise_radps_sqrthz = 0.01;
  p.acc_bias_rw_mps3_sqrthz = 0.0;
  p.gyro_bias_rw_radps2_sqrthz = 0.0;
  p.pos_noise_m_sqrts = 0.0;
  return p;
}

EkfParams EkfParams::tdoaOnly() {
  EkfParams p;
  p.process_model = ProcessModel::kConstantVelocity;
  p.ground_phase = GroundPhase::kNone;
  return p;
}

std::string toString(AccelModel m) { return m == AccelModel::kFull ? "full" : "thrust"; }
std::string toString(ProcessModel m) {
  switch (m) {
    case ProcessModel::kImu: return "imu";
    case ProcessModel::kConstantVelocity: return "cv";
    case ProcessModel::kConstantAcceleration: return "ca";
  }
  return "?";
}
std::string toString(RobustLoss l) {
  switch (l) {
    case RobustLoss::kNone: return "none";
    case RobustLoss::kHuber: return "huber";
    case RobustLoss::kCauchy: return "cauchy";
  }
  return "?";
}
std::string toString(GroundPhase g) { return g == GroundPhase::kNone ? "none" : "detect"; }

AccelModel parseAccelModel(const std::string& s) {
  if (s == "full") return AccelModel::kFull;
  if (s == "thrust") return AccelModel::kThrustOnly;
  throw std::invalid_argument("unknown accelerometer model '" + s + "' (full, thrust)");
}
ProcessModel parseProcessModel(const std::string& s) {
  if (s == "imu") return ProcessModel::kImu;
  if (s == "cv") return ProcessModel::kConstantVelocity;
  if (s == "ca") return ProcessModel::kConstantAcceleration;
  throw std::invalid_argument("unknown process model '" + s + "' (imu, cv, ca)");
}
RobustLoss parseRobustLoss(const std::string& s) {
  if (s == "none") return RobustLoss::kNone;
  if (s == "huber") return RobustLoss::kHuber;
  if (s == "cauchy") return RobustLoss::kCauchy;
  throw std::invalid_argument("unknown robust loss '" + s + "' (none, huber, cauchy)");
}
GroundPhase parseGroundPhase(const std::string& s) {
  if (s == "detect") return GroundPhase::kDetectTakeoff;
  if (s == "none") return GroundPhase::kNone;
  throw std::invalid_argument("unknown ground phase '" + s + "' (detect, none)");
}
std::string toString(BiasPoseUncertainty b) {
  switch (b) {
    case BiasPoseUncertainty::kVariance: return "variance";
    case BiasPoseUncertainty::kJacobian: return "jacobian";
    case BiasPoseUncertainty::kNone: break;
  }
  return "none";
}
BiasPoseUncertainty parseBiasPoseUncertainty(const std::string& s) {
  if (s == "none") return BiasPoseUncertainty::kNone;
  if (s == "variance") return BiasPoseUncertainty::kVariance;
  if (s == "jacobian") return BiasPoseUncertainty::kJacobian;
  throw std::invalid_argument("unknown bias-model pose uncertainty '" + s + "' (none, variance, jacobian)");
}

}  // namespace uwb
