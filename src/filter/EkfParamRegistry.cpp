/** @file EkfParamRegistry.cpp
 *  @brief The EkfParams fields, each once (name, unit, range, doc, accessors), and what is built on them.
 */
#include "uwb/filter/EkfParamRegistry.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "uwb/core/Strings.h"
#include "uwb/filter/InMotionAlignment.h"

namespace uwb {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
const EkfParamRange kPositive{0.0, kInf, true, true};
const EkfParamRange kNonNegative{0.0, kInf, false, true};
const EkfParamRange kFinite{-kInf, kInf, true, true};
EkfParamRange atLeast(double lo) { return {lo, kInf, false, true}; }

/// A real parameter; `field(p)` is its field in p (of EkfParams itself, or of a Params struct nested in it).
template <class Field>
EkfParamInfo realAt(std::string name, Field field, std::string unit, EkfParamRange range, std::string doc,
                    std::string alias) {
  EkfParamInfo i;
  i.name = std::move(name), i.cli_alias = std::move(alias), i.unit = std::move(unit), i.doc = std::move(doc);
  i.kind = EkfParamKind::kReal;
  i.range = range;
  i.get = [field](const EkfParams& p) { return EkfParamValue(field(p)); };
  i.set = [field](EkfParams& p, const EkfParamValue& v) { field(p) = std::get<double>(v); };
  return i;
}

EkfParamInfo real(std::string name, double EkfParams::*field, std::string unit, EkfParamRange range, std::string doc,
                  std::string alias = "") {
  return realAt(
      std::move(name), [field](auto& p) -> auto& { return p.*field; }, std::move(unit), range, std::move(doc),
      std::move(alias));
}

/// A real field of the Params struct `group` nested in EkfParams (e.g. flight_mode).
template <class Group>
EkfParamInfo real(std::string name, Group EkfParams::*group, double Group::*field, std::string unit,
                  EkfParamRange range, std::string doc) {
  return realAt(
      std::move(name), [group, field](auto& p) -> auto& { return (p.*group).*field; }, std::move(unit), range,
      std::move(doc), "");
}

EkfParamInfo integer(std::string name, int EkfParams::*field, EkfParamRange range, std::string doc) {
  EkfParamInfo i;
  i.name = std::move(name), i.doc = std::move(doc);
  i.kind = EkfParamKind::kInteger;
  i.range = range;
  i.get = [field](const EkfParams& p) { return EkfParamValue(static_cast<double>(p.*field)); };
  i.set = [field](EkfParams& p, const EkfParamValue& v) { p.*field = static_cast<int>(std::get<double>(v)); };
  return i;
}

EkfParamInfo boolean(std::string name, bool EkfParams::*field, std::string doc, std::string negation = "") {
  EkfParamInfo i;
  i.name = std::move(name), i.doc = std::move(doc), i.cli_negation = std::move(negation);
  i.kind = EkfParamKind::kBool;
  i.get = [field](const EkfParams& p) { return EkfParamValue(p.*field); };
  i.set = [field](EkfParams& p, const EkfParamValue& v) { p.*field = std::get<bool>(v); };
  return i;
}

EkfParamInfo vec3(std::string name, Vec3 EkfParams::*field, std::string unit, std::string doc, std::string alias = "",
                  bool EkfParams::*flag_when_set = nullptr) {
  EkfParamInfo i;
  i.name = std::move(name), i.cli_alias = std::move(alias), i.unit = std::move(unit), i.doc = std::move(doc);
  i.kind = EkfParamKind::kVec3;
  i.range = kFinite;
  i.get = [field](const EkfParams& p) { return EkfParamValue(p.*field); };
  i.set = [field, flag_when_set](EkfParams& p, const EkfParamValue& v) {
    p.*field = std::get<Vec3>(v);
    if (flag_when_set != nullptr) p.*flag_when_set = true;
  };
  return i;
}

template <class E>
EkfParamInfo choice(std::string name, E EkfParams::*field, std::vector<std::string> choices,
                    E (*parse)(const std::string&), std::string (*text)(E), std::string doc, std::string alias = "") {
  EkfParamInfo i;
  i.name = std::move(name), i.cli_alias = std::move(alias), i.doc = std::move(doc);
  i.kind = EkfParamKind::kChoice;
  i.choices = std::move(choices);
  i.get = [field, text](const EkfParams& p) { return EkfParamValue(text(p.*field)); };
  i.set = [field, parse](EkfParams& p, const EkfParamValue& v) { p.*field = parse(std::get<std::string>(v)); };
  return i;
}

std::vector<EkfParamInfo> makeRegistry() {
  using P = EkfParams;
  using M = FlightModeParams;
  const char* sd = "m/s^2/sqrt(Hz)";
  return {
      // --- process noise (continuous-time spectral densities, docs/math/filter.md F5) ---
      real("acc_noise_mps2_sqrthz", &P::acc_noise_mps2_sqrthz, sd, kNonNegative,
           "Accelerometer white noise (thrust axis; all axes with the full model)", "acc-noise"),
      real("lateral_acc_noise_mps2_sqrthz", &P::lateral_acc_noise_mps2_sqrthz, sd, kNonNegative,
           "Extra white acceleration on the horizontal velocity beyond the rotor drag (thrust model, F3)",
           "lateral-acc-noise"),
      real("gyro_noise_radps_sqrthz", &P::gyro_noise_radps_sqrthz, "rad/s/sqrt(Hz)", kNonNegative,
           "Gyroscope white noise on the attitude error", "gyro-noise"),
      real("acc_bias_rw_mps3_sqrthz", &P::acc_bias_rw_mps3_sqrthz, "m/s^3/sqrt(Hz)", kNonNegative,
           "Accelerometer-bias random walk", "acc-bias-rw"),
      real("gyro_bias_rw_radps2_sqrthz", &P::gyro_bias_rw_radps2_sqrthz, "rad/s^2/sqrt(Hz)", kNonNegative,
           "Gyroscope-bias random walk", "gyro-bias-rw"),
      real("pos_noise_m_sqrts", &P::pos_noise_m_sqrts, "m/sqrt(s)", kNonNegative,
           "Direct position random walk (Crazyflie procNoisePos)"),
      real("cv_acc_noise_mps2_sqrthz", &P::cv_acc_noise_mps2_sqrthz, sd, kPositive,
           "TDoA-only constant-velocity model: white acceleration"),
      real("ca_jerk_noise_mps3_sqrthz", &P::ca_jerk_noise_mps3_sqrthz, "m/s^3/sqrt(Hz)", kPositive,
           "TDoA-only constant-acceleration model: white jerk"),
      choice("accel_model", &P::accel_model, {"thrust", "full"}, parseAccelModel, toString,
             "Accelerometer model in flight: thrust axis only (Mueller et al.) or all three axes"),
      real("rotor_drag_per_s", &P::rotor_drag_per_s, "1/s", kNonNegative,
           "Rotor drag per unit horizontal velocity, a = R f + g - k v_h, in the thrust-axis model and the heading alignment (F2a, F28a')"),
      choice("ground_accel_model", &P::ground_accel_model, {"thrust", "full"}, parseAccelModel, toString,
             "Accelerometer model before take-off"),
      choice("process_model", &P::process_model, {"imu", "cv", "ca"}, parseProcessModel, toString,
             "IMU-driven model, or TDoA only with constant velocity / constant acceleration"),
      // --- initial uncertainty ---
      real("init_pos_sigma_m", &P::init_pos_sigma_m, "m", kPositive, "Initial position std"),
      real("init_vel_sigma_mps", &P::init_vel_sigma_mps, "m/s", kPositive, "Initial velocity std"),
      real("init_att_sigma_rad", &P::init_att_sigma_rad, "rad", kPositive, "Initial roll/pitch std"),
      real("init_yaw_sigma_rad", &P::init_yaw_sigma_rad, "rad", kPositive, "Initial yaw std"),
      real("init_acc_bias_sigma_mps2", &P::init_acc_bias_sigma_mps2, "m/s^2", kPositive,
           "Initial accelerometer-bias std"),
      real("init_gyro_bias_sigma_xy_radps", &P::init_gyro_bias_sigma_xy_radps, "rad/s", kPositive,
           "Initial gyroscope-bias std of the body x and y (roll and pitch) axes (F1)"),
      real("init_gyro_bias_sigma_z_radps", &P::init_gyro_bias_sigma_z_radps, "rad/s", kPositive,
           "Initial gyroscope-bias std of the body z (yaw) axis (F1)"),
      // --- TDoA measurement ---
      vec3("b_t_tag", &P::b_t_tag, "m", "Tag (antenna) position in the body frame x,y,z", "tag-offset"),
      real("tdoa_sigma_m", &P::tdoa_sigma_m, "m", kPositive,
           "TDoA noise std used by the filter: the white part beside the range-bias states (F27); without them 0.35 "
           "(F12)",
           "tdoa-sigma"),
      real("anchor_sigma_m", &P::anchor_sigma_m, "m", kNonNegative, "Std of each surveyed anchor coordinate"),
      real("gate_sigma", &P::gate_sigma, "", kPositive, "Mahalanobis gate on the normalised innovation (sigmas)",
           "gate"),
      choice("robust_loss", &P::robust_loss, {"none", "huber", "cauchy"}, parseRobustLoss, toString,
             "Robust loss of the TDoA update (IRLS)"),
      real("robust_k", &P::robust_k, "", kPositive, "Robust-loss scale on the normalised innovation"),
      integer("robust_iterations", &P::robust_iterations, EkfParamRange{1, 20}, "IRLS iterations per TDoA update"),
      real("pair_bias_tau_s", &P::pair_bias_tau_s, "s", kNonNegative,
           "Per-pair TDoA offset learned from innovations with this time constant; 0 off (F19)"),
      real("range_bias_sigma_m", &P::range_bias_sigma_m, "m", kNonNegative,
           "Per-anchor range bias as filter states (Ornstein-Uhlenbeck, with cross-covariance): stationary std; "
           "0 off (F27)"),
      real("range_bias_tau_s", &P::range_bias_tau_s, "s", kPositive,
           "Correlation time of each anchor's range bias state (F27)"),
      real("range_bias_adapt_s", &P::range_bias_adapt_s, "s", kNonNegative,
           "Adapt the range-bias std to the flight by online EM with this time constant; 0 off (F27e)"),
      real("range_bias_min_fraction", &P::range_bias_min_fraction, "", EkfParamRange{0.0, 1.0, true, false},
           "Lower bound of the adapted range-bias std, as a fraction of range_bias_sigma_m (F27e)"),
      integer("antenna_bias_degree", &P::antenna_bias_degree, EkfParamRange{0, 4},
              "Learn the tag antenna-pattern TDoA bias in flight from the innovations: spherical harmonics of degrees "
              "2..this of the anchor's body-frame direction; 0 off, 1 invalid (F25)"),
      real("antenna_bias_sigma_m", &P::antenna_bias_sigma_m, "m", kPositive,
           "Prior std of each antenna-pattern coefficient (F25c)"),
      real("antenna_bias_memory_s", &P::antenna_bias_memory_s, "s", kNonNegative,
           "Forgetting time constant of the learned antenna pattern towards its prior; 0 none (F25c)"),
      real("antenna_bias_offset_sigma_m", &P::antenna_bias_offset_sigma_m, "m", kNonNegative,
           "Std of the filter's own position error as the antenna-pattern learner models it; 0 not modelled (F25e)"),
      real("antenna_bias_offset_memory_s", &P::antenna_bias_offset_memory_s, "s", kPositive,
           "Correlation time of that position error (F25e)"),
      real("antenna_bias_noise_scale", &P::antenna_bias_noise_scale, "", kPositive,
           "Factor on the innovation variance when learning the antenna pattern (time-correlated TDoA error, F25d)"),
      boolean("bias_guard", &P::bias_guard,
              "With a bias model: mix the corrected and the uncorrected filter by their recent TDoA predictive "
              "likelihood (F24)"),
      real("bias_guard_tau_s", &P::bias_guard_tau_s, "s", kPositive,
           "Memory of the bias guard's likelihood comparison (F24)"),
      choice("bias_model_pose", &P::bias_model_pose, {"none", "variance", "jacobian"}, parseBiasPoseUncertainty,
             toString,
             "With a bias model: the pose uncertainty of the correction, as variance ∇µᵀ P ∇µ or in the row "
             "∂(h + µ)/∂δx (gp.md P47)"),
      real("bias_model_level_exponent", &P::bias_model_level_exponent, "", kNonNegative,
           "With a bias model: its mean scaled by min(1, flight's bias level / training level)^this; 0 off (F24b)"),
      real("bias_model_training_level_m", &P::bias_model_training_level_m, "m", kNonNegative,
           "Bias level of the model's training flights (from the model file; 0 unknown: no scaling, F24b)"),
      real("bias_model_training_mean_level_m", &P::bias_model_training_mean_level_m, "m", kNonNegative,
           "Level of the model's own mean on its training flights (from the model file; 0 unknown: the model's "
           "level on this flight is not compared, F24c)"),
      boolean("bias_model_level_variance", &P::bias_model_level_variance,
              "With a bias model: corrected TDoA get the variance the flight shows beyond the model's training "
              "flights (F24e, gp.md P43c)"),
      real("max_lost_s", &P::max_lost_s, "s", kPositive,
           "All TDoA rejected this long: re-acquire (inflate P, open the gate)"),
      real("lost_velocity_tau_s", &P::lost_velocity_tau_s, "s", kNonNegative,
           "Re-acquiring in flight: the velocity relaxes towards rest with this time constant (F16e); 0 off"),
      real("descent_margin_m", &P::descent_margin_m, "m", kNonNegative,
           "Landing: the height may not rise more than this above the IMU's dead-reckoned descent (F26; 0.3 on "
           "simulated landings); 0 off"),
      real("max_rejection_rate", &P::max_rejection_rate, "", EkfParamRange{0.0, 1.0, true, false},
           "A larger fraction of the TDoA rejected in flight (0.3 s memory): re-acquire (F16d); 1 turns it off"),
      // --- scheduling ---
      real("max_predict_dt_s", &P::max_predict_dt_s, "s", kPositive, "IMU samples are averaged over at most this"),
      real("update_predict_dt_s", &P::update_predict_dt_s, "s", kNonNegative,
           "A TDoA update first predicts to its stamp when the state lags more than this"),
      real("cov_period_s", &P::cov_period_s, "s", kNonNegative,
           "Covariance propagation period (0: before every update)", "cov-period"),
      real("max_gap_s", &P::max_gap_s, "s", kPositive, "A sensor gap longer than this is reported"),
      real("max_integration_gap_s", &P::max_integration_gap_s, "s", kPositive,
           "A longer sensor-time gap is a time jump: the IMU is not integrated across it (F17)"),
      // --- ground phase and start ---
      choice("ground_phase", &P::ground_phase, {"detect", "none"}, parseGroundPhase, toString,
             "Use the IMU's evidence of the ground (rest, floor contact): zero-velocity updates, floor height, TDoA "
             "down-weighted (F14, F18)"),
      real("takeoff_climb_mps", &P::takeoff_climb_mps, "m/s", kPositive,
           "Take-off: vertical velocity from the accelerometer above this (F15)"),
      real("takeoff_leak_s", &P::takeoff_leak_s, "s", kPositive,
           "Time constant of the take-off detector's leaky vertical-velocity integrator (F15)"),
      real("takeoff_acc_bias_sigma_mps2", &P::takeoff_acc_bias_sigma_mps2, "m/s^2", kNonNegative,
           "Thrust-axis accelerometer-bias std added at take-off (F20)"),
      real("acquisition_s", &P::acquisition_s, "s", kNonNegative,
           "Robust, gate-free acquisition after a position fix (F16)"),
      real("acquisition_tdoa_sigma_m", &P::acquisition_tdoa_sigma_m, "m", kPositive,
           "TDoA std used during acquisition"),
      boolean("has_start_position", &P::has_start_position,
              "Start at start_w_p_b instead of multilateration (set by start_w_p_b)"),
      vec3("start_w_p_b", &P::start_w_p_b, "m", "Start position of the body origin x,y,z (default: multilateration)",
           "start", &P::has_start_position),
      real("ground_z_m", &P::ground_z_m, "m", kFinite, "World z of the body origin resting on the floor (F22)"),
      boolean("floor_constraint", &P::floor_constraint,
              "The body is not below the floor; on the ground its height is ground_z_m (F22)"),
      real("floor_margin_m", &P::floor_margin_m, "m", kNonNegative,
           "Tolerance below ground_z_m before the floor constraint acts (F22)"),
      real("ground_height_sigma_m", &P::ground_height_sigma_m, "m", kPositive,
           "Height std of the body on the floor (F22, F23')"),
      real("rest_tdoa_sigma_m", &P::rest_tdoa_sigma_m, "m", kPositive,
           "TDoA std on the ground and just above it (F14)"),
      real("low_flight_m", &P::low_flight_m, "m", kFinite,
           "Below this estimated height above the floor the TDoA are weighted as on the ground (F14)"),
      real("floor_anchor_height_m", &P::floor_anchor_height_m, "m", kNonNegative,
           "Anchors less than this above the floor: on the floor their range delay is solved for at the start and "
           "removed from the TDoA on the ground (F16f); 0 off"),
      real("leave_rest_pos_sigma_m", &P::leave_rest_pos_sigma_m, "m", kNonNegative,
           "Horizontal position std added when the body leaves the ground (F15)"),
      real("zupt_period_s", &P::zupt_period_s, "s", kNonNegative,
           "Period of the zero-velocity updates at rest, and of the floor, descent and divergence checks in flight "
           "(F14)"),
      real("zupt_sigma_mps", &P::zupt_sigma_mps, "m/s", kPositive, "Std of a zero-velocity update (F14)"),
      boolean("rest_gyro_updates", &P::rest_gyro_updates,
              "Zero-angular-rate updates of the gyro bias while the body rests (F18z)", "no-rest-gyro-updates"),
      real("rest_gyro_window_s", &P::rest_gyro_window_s, "s", kPositive,
           "Window of one zero-angular-rate update at rest (F18z)"),
      integer("rest_gyro_min_samples", &P::rest_gyro_min_samples, EkfParamRange{2, 1e6},
              "A window at rest with fewer gyro readings gives no zero-angular-rate update (F18z)"),
      real("rest_gyro_sigma_floor_radps", &P::rest_gyro_sigma_floor_radps, "rad/s", kPositive,
           "Std added to the window mean's own in a zero-angular-rate update (F18z)"),
      real("rest_gyro_gate_sigma", &P::rest_gyro_gate_sigma, "", kPositive,
           "A gyro-bias reading at rest beyond this many σ widens the bias variance before it is fused (F18z)"),
      real("level_window_s", &P::level_window_s, "s", kNonNegative,
           "Levelling window before the first prediction (F15)"),
      integer("level_max_samples", &P::level_max_samples, EkfParamRange{1, 1e6},
              "The levelling window ends after this many IMU samples at the latest (F15)"),
      real("level_rest_acc_std_mps2", &P::level_rest_acc_std_mps2, "m/s^2", kNonNegative,
           "Std of |f| over the levelling window below which the IMU starts at rest (F15, F18)"),
      real("start_window_s", &P::start_window_s, "s", kPositive,
           "Multilateration window of the start and of a re-acquisition (F16)"),
      integer("start_min_samples", &P::start_min_samples, EkfParamRange{1, 1e6},
              "The first solve of a start also needs this many TDoA (F16)"),
      real("start_max_window_s", &P::start_max_window_s, "s", kPositive,
           "History a start keeps while its solves fail (F16b)"),
      real("start_min_pos_sigma_m", &P::start_min_pos_sigma_m, "m", kPositive,
           "Lower bound of a fix's position std (the TDoA bias, F16)"),
      real("start_min_vel_sigma_mps", &P::start_min_vel_sigma_mps, "m/s", kPositive,
           "Lower bound of a fix's velocity std (F16b)"),
      real("start_box_margin_m", &P::start_box_margin_m, "m", kNonNegative,
           "A fix outside the anchors' box grown by this is a failed solve (F16)"),
      real("start_max_rms_residual_m", &P::start_max_rms_residual_m, "m", kPositive,
           "A re-acquisition's fix with a larger robustly weighted RMS residual is a failed solve (F16)"),
      real("floor_refute_height_m", &P::floor_refute_height_m, "m", kFinite,
           "A first start on floor contact is refuted when the solve in motion stays this high above the floor (F16j)"),
      real("floor_refute_residual_ratio", &P::floor_refute_residual_ratio, "", kPositive,
           "... with an RMS residual at most this many times the floor solve's (F16j)"),
      real("start_max_speed_mps", &P::start_max_speed_mps, "m/s", kPositive,
           "A moving start's solve faster than this is a failed solve (F16b)"),
      real("start_floor_height_sigma_m", &P::start_floor_height_sigma_m, "m", kPositive,
           "Height std of a start's fix on the floor (F16c)"),
      real("moving_start_vel_sigma_mps", &P::moving_start_vel_sigma_mps, "m/s", kPositive,
           "Velocity std when the IMU starts while moving (F15)"),
      boolean("start_replay", &P::start_replay,
              "A first start in motion runs the filter again over the start window from the fix (F16g)"),
      real("moving_start_att_sigma_rad", &P::moving_start_att_sigma_rad, "rad", kPositive,
           "Roll/pitch std when the IMU starts while moving (F15)"),
      real("moving_start_yaw_sigma_rad", &P::moving_start_yaw_sigma_rad, "rad", kPositive,
           "Yaw std when the IMU starts while moving (yaw 0 assumed, F15)"),
      // --- ground contact, landing and the flight-mode inputs (F16f-F16i, F18, F26, F29) ---
      real("contact_hold_s", &P::contact_hold_s, "s", kPositive,
           "Shaking within this long counts as floor contact (F18)"),
      real("contact_max_height_m", &P::contact_max_height_m, "m", kFinite,
           "Contact and rest enter the ground only below this estimated height above the floor (F18)"),
      real("contact_sustained_s", &P::contact_sustained_s, "s", kNonNegative,
           "Shaking this long is floor contact at any estimated height (F18)"),
      real("contact_rearm_s", &P::contact_rearm_s, "s", kNonNegative,
           "After leaving the ground, shaking counts again only after this long (F18)"),
      real("from_rest_s", &P::from_rest_s, "s", kNonNegative,
           "The ground was left from rest when the body was at rest this recently (F16f)"),
      real("low_z_period_s", &P::low_z_period_s, "s", kPositive,
           "Sample period of the ring of recent heights (60 samples) (F18)"),
      integer("contact_low_z_samples", &P::contact_low_z_samples, EkfParamRange{0, 60},
              "The contact test uses the lowest of this many recent heights (F18)"),
      real("rest_max_climb_mps", &P::rest_max_climb_mps, "m/s", kFinite,
           "Rest enters the ground from the air only while the estimate climbs slower than this (F18)"),
      real("rest_descent_mps", &P::rest_descent_mps, "m/s", kFinite,
           "A descent faster than this opens the landing window (F18, F26)"),
      real("landing_window_s", &P::landing_window_s, "s", kNonNegative,
           "Length of the landing window after a descent (F18, F16h)"),
      real("landing_low_z_lead_s", &P::landing_low_z_lead_s, "s", kNonNegative,
           "A landing's heights count from this long before its last descending sample (F18)"),
      real("landing_band_m", &P::landing_band_m, "m", kFinite,
           "A landing's TDoA are tested against the floor-level delays this near the floor (F16h)"),
      real("landing_fix_max_s", &P::landing_fix_max_s, "s", kNonNegative,
           "A landing's floor window ends without a fix after this long (F16i)"),
      real("air_shake_settle_s", &P::air_shake_settle_s, "s", kNonNegative,
           "The airborne shaking level is learned from this long after leaving the ground (F29b)"),
      real("air_shake_min_height_m", &P::air_shake_min_height_m, "m", kFinite,
           "... and this high above the floor (F29b)"),
      real("floor_check_period_s", &P::floor_check_period_s, "s", kNonNegative,
           "A floor check in contact runs at most this often (F29e)"),
      // --- the flight-mode supervisor (F29; FlightModeParams, the fields of flight_mode) ---
      real("mode_imu_max_log_odds", &P::flight_mode, &M::imu_max_log_odds, "nats", kPositive,
           "Bound of the IMU's log-odds airborne : floor from shaking and climbs, L_IMU (F29a)"),
      real("mode_imu_rest_log_odds", &P::flight_mode, &M::imu_rest_log_odds, "nats", kPositive,
           "Bound of the IMU's log-odds towards the floor while it reads rest, L_rest; at least mode_imu_max_log_odds "
           "(F29a)"),
      real("mode_imu_rate_per_s", &P::flight_mode, &M::imu_rate_per_s, "nats/s", kPositive,
           "Rate at which the IMU's log-odds move (F29a)"),
      real("mode_tdoa_max_log_odds", &P::flight_mode, &M::tdoa_max_log_odds, "nats", kPositive,
           "Bound of the TDoA's Bayes factor for the air (F29c)"),
      real("mode_tdoa_max_floor_log_odds", &P::flight_mode, &M::tdoa_max_floor_log_odds, "nats", kNonNegative,
           "Bound of the TDoA's Bayes factor for the floor; above it the floor is doubted (F29c, F29d)"),
      real("mode_tdoa_window_s", &P::flight_mode, &M::tdoa_window_s, "s", kPositive,
           "Forgetting time of the TDoA height window (F29c)"),
      real("mode_tdoa_min_effective", &P::flight_mode, &M::tdoa_min_effective, "", atLeast(2.0),
           "The TDoA window says nothing while it holds fewer (forgotten) TDoA than this (F29c)"),
      real("mode_tdoa_independent", &P::flight_mode, &M::tdoa_independent, "", atLeast(1.0),
           "Independent TDoA a window counts as at most: their errors are correlated in time (F29c)"),
      real("mode_min_vertical_gain", &P::flight_mode, &M::min_vertical_gain, "", kPositive,
           "A TDoA whose vertical sensitivity dh/dz is below this in magnitude says nothing of the height (F29c)"),
      real("mode_height_floor_sigma_m", &P::flight_mode, &M::height_floor_sigma_m, "m", kPositive,
           "Spread added to both hypotheses' mean squares of the TDoA heights (F29c)"),
      real("mode_air_min_height_m", &P::flight_mode, &M::air_min_height_m, "m", kNonNegative,
           "Lowest flight height above the floor of the TDoA's air hypothesis (F29c)"),
      real("mode_air_max_height_m", &P::flight_mode, &M::air_max_height_m, "m", kPositive,
           "Highest flight height above the floor of the TDoA's air hypothesis; above mode_air_min_height_m (F29c)"),
      real("mode_hysteresis_log_odds", &P::flight_mode, &M::hysteresis_log_odds, "nats", kNonNegative,
           "A mode is left when the summed log-odds pass -/+ this (F29)"),
      real("mode_air_shake_ratio", &P::flight_mode, &M::air_shake_ratio, "", atLeast(1.0),
           "Floor shaking: a gyro mean square above this times the flight's airborne shaking level (F29b)"),
      real("mode_air_shake_prior_ms", &P::flight_mode, &M::air_shake_prior_ms, "rad^2/s^2", kPositive,
           "Airborne shaking level (high-passed gyro mean square) before it is measured (F29b)"),
      real("mode_air_shake_tau_s", &P::flight_mode, &M::air_shake_tau_s, "s", kPositive,
           "Time constant of the learned airborne shaking level (F29b)"),
      real("mode_tof_window_s", &P::flight_mode, &M::tof_window_s, "s", kPositive,
           "Forgetting time of the downward range's height window (F29f)"),
      real("mode_tof_min_effective", &P::flight_mode, &M::tof_min_effective, "", atLeast(1.0),
           "Forgotten downward-range count below which its window says nothing (F29f)"),
      real("mode_tof_height_sigma_m", &P::flight_mode, &M::tof_height_sigma_m, "m", kPositive,
           "Spread added to both hypotheses' mean squares of the downward range's heights (F29f)"),
      // --- re-acquisition and divergence (F16, F16d) ---
      integer("lost_min_rejections", &P::lost_min_rejections, EkfParamRange{0, 1e6},
              "Lost (F16) also needs at least this many TDoA rejected in a row"),
      real("rejection_memory_s", &P::rejection_memory_s, "s", kPositive,
           "Memory of the TDoA rejection rate in flight (F16d)"),
      real("rejection_min_height_m", &P::rejection_min_height_m, "m", kFinite,
           "The rejection rate counts only TDoA this high above the floor (F16d)"),
      real("rejection_settle_s", &P::rejection_settle_s, "s", kNonNegative,
           "... and from this long after an acquisition or leaving the ground (F16d)"),
      real("rejection_min_samples", &P::rejection_min_samples, "", kNonNegative,
           "... over at least this many (forgotten) TDoA (F16d)"),
      real("healthy_rejection_rate", &P::healthy_rejection_rate, "", kNonNegative,
           "The motion is recorded while at most this fraction of the TDoA is rejected (F16d)"),
      real("healthy_period_s", &P::healthy_period_s, "s", kNonNegative, "... every this long (F16d)"),
      real("revert_lead_s", &P::revert_lead_s, "s", kNonNegative,
           "A rejection fault reverts to a recorded motion at least this old (F16d)"),
      real("revert_max_age_s", &P::revert_max_age_s, "s", kNonNegative, "... and at most this old (F16d)"),
      real("diverged_box_margin_m", &P::diverged_box_margin_m, "m", kNonNegative,
           "Diverged: the estimate left the anchors' box by this much (F16)"),
      real("diverged_speed_mps", &P::diverged_speed_mps, "m/s", kPositive, "... or moves faster than this (F16)"),
      // --- innovation consistency (F30) ---
      real("nis_clip", &P::nis_clip, "", kPositive, "Each TDoA's NIS is clipped at this (F30)"),
      real("nis_window_s", &P::nis_window_s, "s", kPositive, "The NIS is averaged over this (F30)"),
      real("nis_far", &P::nis_far, "", kNonNegative, "A NIS beyond this counts as far (2 sigma) (F30)"),
      real("nis_max_far_fraction", &P::nis_max_far_fraction, "", kNonNegative,
           "Inconsistent while a larger share of the TDoA is far (F30)"),
      real("nis_min_samples", &P::nis_min_samples, "", kNonNegative,
           "... over at least this many (forgotten) TDoA (F30)"),
      real("inconsistent_hold_s", &P::inconsistent_hold_s, "s", kNonNegative,
           "Inconsistent only after this long beyond chance (F30)"),
      real("max_widening_m", &P::max_widening_m, "m", kNonNegative,
           "The reported band widens by at most this while inconsistent (F30)"),
      real("widening_fade_s", &P::widening_fade_s, "s", kPositive,
           "The widening fades with this time constant once the TDoA agree (F30)"),
      // --- heading alignment (F28) ---
      boolean("heading_alignment", &P::heading_alignment,
              "In flight, the heading from the gyro-tracked thrust against the velocity: a measurement, or a reset where it contradicts the filter (F28)"),
      real("heading_alignment_window_s", &P::heading_alignment_window_s, "s",
           EkfParamRange{0.0, InMotionAlignment::kMaxWindow_s, true, false},
           "Window of the heading alignment (F28)"),
      real("max_aligned_heading_sigma_rad", &P::max_aligned_heading_sigma_rad, "rad", kPositive,
           "A heading fit acts only with a heading std below this (F28)"),
      real("min_heading_change_rad", &P::min_heading_change_rad, "rad", kNonNegative,
           "A heading fit resets the attitude only beyond 3 sigma and this (F28)"),
      real("min_aligned_tilt_sigma_rad", &P::min_aligned_tilt_sigma_rad, "rad", kNonNegative,
           "Floor of the attitude std written with an alignment (F28)"),
      // --- reported covariance (F23) ---
      real("output_bias_sigma_m", &P::output_bias_sigma_m, "m", kNonNegative,
           "Slow TDoA bias std mapped into the reported position covariance (F23)"),
      real("output_bias_memory_s", &P::output_bias_memory_s, "s", kNonNegative,
           "Memory of the flight's bias level measured in flight, which scales output_bias_sigma_m (F23c); 0 off"),
      real("output_bias_level_m", &P::output_bias_level_m, "m", kPositive,
           "Measured pair-bias level above which the reported pair-bias std grows with it (F23c)"),
      real("output_bias_vertical_scale", &P::output_bias_vertical_scale, "–", kPositive,
           "Factor on the vertical part of the bias term of the reported covariance in flight (F23d)"),
      real("recent_pair_window_s", &P::recent_pair_window_s, "s", kNonNegative,
           "Anchor pairs seen within this enter the reported bias term and the anchors-heard count (F23, F16k)"),
      real("bias_floor_period_s", &P::bias_floor_period_s, "s", kNonNegative,
           "The reported bias term is recomputed at most this often (F23)"),
      // --- downward ToF range (Flow deck VL53L1x, F21) ---
      boolean("fuse_tof", &P::fuse_tof, "Fuse the downward ToF range as a height update when the log has it (F21)",
              "no-tof"),
      real("tof_sigma_m", &P::tof_sigma_m, "m", kPositive, "ToF range noise std"),
      real("tof_offset_m", &P::tof_offset_m, "m", kFinite, "ToF sensor below the body origin along body z"),
      real("floor_z_m", &P::floor_z_m, "m", kFinite, "Height of the flat floor the ToF sees (world z)"),
      real("tof_max_range_m", &P::tof_max_range_m, "m", kPositive,
           "ToF readings above this, <= 0 or non-finite are ignored"),
      real("tof_gate_sigma", &P::tof_gate_sigma, "", kFinite,
           "Mahalanobis gate on the ToF innovation (sigmas); <= 0 disables"),
      // --- the sensors' physical ranges (F31) ---
      real("max_gyro_radps", &P::max_gyro_radps, "rad/s", kPositive,
           "Gyro samples with |w| above this are skipped and counted: 2x the +-2000 deg/s full scale (BMI088) (F31)"),
      real("max_acc_mps2", &P::max_acc_mps2, "m/s^2", kPositive,
           "Accelerometer samples with |f| above this are skipped and counted: 50 g, 2x the +-24 g full scale "
           "(BMI088) (F31)"),
      real("max_tdoa_excess_m", &P::max_tdoa_excess_m, "m", kNonNegative,
           "TDoA with |z| beyond the anchor-pair baseline by more than this are skipped and counted (triangle "
           "inequality) (F31)"),
  };
}

std::string number(double v) { return fmt::format("{}", v); }

/// "where: " in front of a message, nothing when `where` is empty.
std::string prefix(const std::string& where) { return where.empty() ? std::string() : where + ": "; }

std::string valueText(const EkfParamInfo& info, const EkfParamValue& v) {
  switch (info.kind) {
    case EkfParamKind::kReal: return number(std::get<double>(v));
    case EkfParamKind::kInteger: return number(std::get<double>(v));
    case EkfParamKind::kBool: return std::get<bool>(v) ? "true" : "false";
    case EkfParamKind::kVec3: {
      const Vec3& x = std::get<Vec3>(v);
      return number(x.x()) + "," + number(x.y()) + "," + number(x.z());
    }
    case EkfParamKind::kChoice: return std::get<std::string>(v);
  }
  return "?";
}

std::string kindName(const EkfParamInfo& info) {
  switch (info.kind) {
    case EkfParamKind::kReal: return "a number";
    case EkfParamKind::kInteger: return "a whole number";
    case EkfParamKind::kBool: return "true or false";
    case EkfParamKind::kVec3: return "three numbers x,y,z";
    case EkfParamKind::kChoice: {
      std::string choices;
      for (const std::string& c : info.choices) appendToList(&choices, c);
      std::string s = "one of ";
      s += choices;
      return s;
    }
  }
  return "?";
}

/// Throws unless `v` has the entry's kind and lies in its range / choices.
void check(const EkfParamInfo& info, const EkfParamValue& v, const std::string& where) {
  const auto fail = [&](const std::string& what) {
    throw std::invalid_argument(fmt::format("{}{} must be {} (got {})", prefix(where), info.name, what,
                                            std::holds_alternative<std::string>(v) ? std::get<std::string>(v)
                                            : std::holds_alternative<double>(v)     ? number(std::get<double>(v))
                                            : std::holds_alternative<bool>(v)       ? (std::get<bool>(v) ? "true" : "false")
                                                                                    : "a vector"));
  };
  switch (info.kind) {
    case EkfParamKind::kReal:
    case EkfParamKind::kInteger: {
      if (!std::holds_alternative<double>(v)) fail(kindName(info));
      const double x = std::get<double>(v);
      if (info.kind == EkfParamKind::kInteger && !(std::isfinite(x) && x == std::round(x))) fail(kindName(info));
      if (!info.range.contains(x)) fail(info.range.toString());
      return;
    }
    case EkfParamKind::kBool:
      if (!std::holds_alternative<bool>(v)) fail(kindName(info));
      return;
    case EkfParamKind::kVec3:
      if (!std::holds_alternative<Vec3>(v)) fail(kindName(info));
      if (!std::get<Vec3>(v).allFinite()) fail("finite");
      return;
    case EkfParamKind::kChoice: {
      if (!std::holds_alternative<std::string>(v)) fail(kindName(info));
      for (const std::string& c : info.choices)
        if (c == std::get<std::string>(v)) return;
      fail(kindName(info));
    }
  }
}

double parseNumber(const std::string& text, const EkfParamInfo& info, const std::string& where) {
  std::size_t used = 0;
  double x = 0.0;
  try {
    x = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size())
    throw std::invalid_argument(fmt::format("{}{} must be {} (got '{}')", prefix(where), info.name, kindName(info), text));
  return x;
}

}  // namespace

bool EkfParamRange::contains(double v) const {
  if (!std::isfinite(v)) return false;
  if (lo_open ? !(v > lo) : !(v >= lo)) return false;
  if (hi_open ? !(v < hi) : !(v <= hi)) return false;
  return true;
}

std::string EkfParamRange::toString() const {
  const bool lo_inf = std::isinf(lo), hi_inf = std::isinf(hi);
  if (lo_inf && hi_inf) return "finite";
  if (hi_inf) return fmt::format("{} {}", lo_open ? ">" : "≥", number(lo));
  if (lo_inf) return fmt::format("{} {}", hi_open ? "<" : "≤", number(hi));
  return fmt::format("in {}{}, {}{}", lo_open ? "(" : "[", number(lo), number(hi), hi_open ? ")" : "]");
}

std::string EkfParamInfo::flag() const {
  std::string f = "--" + name;
  for (char& c : f)
    if (c == '_') c = '-';
  return f;
}

const std::vector<EkfParamInfo>& ekfParamRegistry() {
  static const std::vector<EkfParamInfo> registry = makeRegistry();
  return registry;
}

const EkfParamInfo& ekfParamInfo(const std::string& name) {
  for (const EkfParamInfo& i : ekfParamRegistry())
    if (i.name == name) return i;
  std::string known;
  for (const EkfParamInfo& i : ekfParamRegistry()) appendToList(&known, i.name);
  throw std::invalid_argument("unknown filter parameter '" + name + "' (known: " + known + ")");
}

void setEkfParam(EkfParams& p, const EkfParamInfo& info, const EkfParamValue& value, const std::string& where) {
  check(info, value, where);
  info.set(p, value);
}

void setEkfParamFromText(EkfParams& p, const EkfParamInfo& info, const std::string& text, const std::string& where) {
  switch (info.kind) {
    case EkfParamKind::kReal:
    case EkfParamKind::kInteger: setEkfParam(p, info, parseNumber(text, info, where), where); return;
    case EkfParamKind::kBool:
      if (text == "true" || text == "1") return setEkfParam(p, info, true, where);
      if (text == "false" || text == "0") return setEkfParam(p, info, false, where);
      throw std::invalid_argument(fmt::format("{}{} must be true or false (got '{}')", prefix(where), info.name, text));
    case EkfParamKind::kVec3: {
      std::vector<double> v;
      std::stringstream ss(text);
      std::string item;
      while (std::getline(ss, item, ',')) v.push_back(parseNumber(item, info, where));
      if (v.size() != 3)
        throw std::invalid_argument(
            fmt::format("{}{} must be three numbers x,y,z (got '{}')", prefix(where), info.name, text));
      return setEkfParam(p, info, Vec3(v[0], v[1], v[2]), where);
    }
    case EkfParamKind::kChoice: setEkfParam(p, info, text, where); return;
  }
}

std::string ekfParamText(const EkfParams& p, const EkfParamInfo& info) { return valueText(info, info.get(p)); }

std::string ekfParamHelpSuffix(const EkfParamInfo& info) {
  std::string s;
  if (!info.unit.empty()) s += "[" + info.unit + "] ";
  s += "(default " + ekfParamText(EkfParams{}, info);
  if (info.kind == EkfParamKind::kReal || info.kind == EkfParamKind::kInteger) s += ", " + info.range.toString();
  if (info.kind == EkfParamKind::kChoice) s += "; " + kindName(info);
  return s + ")";
}

void validateEkfParamRanges(const EkfParams& p) {
  for (const EkfParamInfo& info : ekfParamRegistry()) check(info, info.get(p), "EkfParams");
}

std::string ekfParamMarkdownTable() {
  std::string out =
      "| name (config key, Python key) | CLI flag | unit | default | valid | description |\n"
      "|---|---|---|---|---|---|\n";
  for (const EkfParamInfo& i : ekfParamRegistry()) {
    std::string flags = "`" + i.flag() + "`";
    if (!i.cli_alias.empty()) flags += ", `--" + i.cli_alias + "`";
    if (!i.cli_negation.empty()) flags += ", `--" + i.cli_negation + "`";
    std::string valid;
    if (i.kind == EkfParamKind::kReal || i.kind == EkfParamKind::kInteger) valid = i.range.toString();
    if (i.kind == EkfParamKind::kChoice) valid = kindName(i);
    if (i.kind == EkfParamKind::kBool) valid = "true, false";
    if (i.kind == EkfParamKind::kVec3) valid = "finite x,y,z";
    out += fmt::format("| `{}` | {} | {} | `{}` | {} | {} |\n", i.name, flags, i.unit.empty() ? "–" : i.unit,
                       ekfParamText(EkfParams{}, i), valid, i.doc);
  }
  return out;
}

}  // namespace uwb
