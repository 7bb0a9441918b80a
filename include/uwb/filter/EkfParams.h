/** @file EkfParams.h
 *  @brief Every tunable number of the localization filter, with units and defaults (one source of defaults).
 *
 *  Defaults were tuned on the 16 UTIL pilot TDoA2 flights (scripts/localize_all.sh); see docs/math/filter.md.
 */
#pragma once

#include <string>

#include "uwb/core/Types.h"
#include "uwb/filter/FlightMode.h"

namespace uwb {

/// How the accelerometer enters the prediction (docs/math/filter.md F3).
enum class AccelModel {
  kFull,        ///< all three axes as specific force (standard strapdown INS)
  kThrustOnly,  ///< Mueller et al. / Crazyflie in flight: specific force = (0, 0, a_z); x/y readings unused
};

/// Process model of the filter (docs/math/filter.md F3, F9).
enum class ProcessModel {
  kImu,                   ///< IMU-driven quadrotor model (needs accelerometer and gyroscope)
  kConstantVelocity,      ///< TDoA only: white-noise acceleration
  kConstantAcceleration,  ///< TDoA only: white-noise jerk (acceleration kept in the acc-bias block)
};

/// Robust loss of the iteratively reweighted TDoA update (docs/math/filter.md F13).
enum class RobustLoss { kNone, kHuber, kCauchy };

/// How a bias model's correction µ(x̂), evaluated at the estimated pose, enters the update (docs/math/gp.md P47).
enum class BiasPoseUncertainty {
  kNone,      ///< "none": µ at the estimate, as the paper
  kVariance,  ///< "variance": the corrected measurement's variance gains ∇µᵀ P ∇µ (input uncertainty)
  kJacobian,  ///< "jacobian": the row becomes ∂(h + µ)/∂δx (the EKF of h + µ; S then carries ∇µᵀ P ∇µ too)
};

/// Whether the IMU's evidence of the ground is used (docs/math/filter.md F14, F18).
enum class GroundPhase {
  kDetectTakeoff,  ///< "detect": at rest or in floor contact (re-decided at every IMU sample) → zero-velocity updates,
                   ///< floor height, TDoA down-weighted (never dropped)
  kNone,           ///< "none": no ground evidence (every TDoA at the flight std; no zero-velocity updates)
};

struct EkfParams {
  // --- process noise (continuous-time spectral densities, docs/math/filter.md F7; evidence for the values there) ---
  double acc_noise_mps2_sqrthz = 0.05;        ///< accelerometer white noise on v (thrust axis in kThrustOnly) (F7, F20)
  double lateral_acc_noise_mps2_sqrthz = 0.5; ///< white acceleration on horizontal v beyond the drag (kThrustOnly, F3a)
  double gyro_noise_radps_sqrthz = 0.01;      ///< gyroscope white noise on δθ
  double acc_bias_rw_mps3_sqrthz = 0.003;     ///< accelerometer-bias random walk (F7)
  double gyro_bias_rw_radps2_sqrthz = 1e-4;   ///< gyroscope-bias random walk
  double pos_noise_m_sqrts = 0.0;             ///< direct position random walk (Crazyflie procNoisePos)
  double cv_acc_noise_mps2_sqrthz = 2.0;      ///< TDoA-only constant-velocity model: white acceleration
  double ca_jerk_noise_mps3_sqrthz = 8.0;     ///< TDoA-only constant-acceleration model: white jerk
  AccelModel accel_model = AccelModel::kThrustOnly;
  double rotor_drag_per_s = 0.36;             ///< rotor drag a = R f + g_w − k v_h [1/s]; 0 off (F2a, F28a′)
  AccelModel ground_accel_model = AccelModel::kFull;  ///< accelerometer model on the ground (F14–F15, F20)
  ProcessModel process_model = ProcessModel::kImu;

  // --- initial uncertainty (F1; evidence in F15, F16b′) ---
  double init_pos_sigma_m = 2.0;
  double init_vel_sigma_mps = 0.1;
  double init_att_sigma_rad = 0.05;
  double init_yaw_sigma_rad = 0.02;           ///< yaw std at the start: TDoA barely observe yaw (F15)
  double init_acc_bias_sigma_mps2 = 0.05;     ///< accelerometer-bias std at the start (F16b′)
  double init_gyro_bias_sigma_xy_radps = 0.01;  ///< roll/pitch-axis gyro-bias std at the start [rad/s] (F1)
  double init_gyro_bias_sigma_z_radps = 0.001;  ///< yaw-axis gyro-bias std at the start: calibrated on the ground (F1)

  // --- TDoA measurement ---
  Vec3 b_t_tag = kUtilTagOffset_b;       ///< tag (antenna) position in the body frame [m]
  double tdoa_sigma_m = 0.2;             ///< TDoA white-noise std beside the range-bias states [m] (F12, F27)
  double anchor_sigma_m = 0.0;           ///< std of each surveyed anchor coordinate [m] (graph node anchors)
  double gate_sigma = 4.0;               ///< Mahalanobis gate on the normalised innovation (χ²₁ = gate²)
  RobustLoss robust_loss = RobustLoss::kHuber;
  double robust_k = 1.0;                 ///< loss scale on the normalised innovation
  int robust_iterations = 2;             ///< IRLS iterations per TDoA update (≥ 1)
  double pair_bias_tau_s = 0.0;          ///< >0: per-pair TDoA offset learned from innovations, time constant [s] (F19)
  double range_bias_sigma_m = 0.07;      ///< per-anchor range-bias states: stationary std [m]; 0 off (F27)
  double range_bias_tau_s = 0.5;         ///< correlation time of each anchor's range bias [s] (F27)
  double range_bias_adapt_s = 0.1;       ///< online-EM time constant of the range-bias std [s]; 0 keeps it (F27e)
  double range_bias_min_fraction = 0.2;  ///< the adapted std stays ≥ this × range_bias_sigma_m (F27e)
  int antenna_bias_degree = 0;           ///< antenna pattern learned in flight: harmonics 2…this (2–4); 0 off (F25)
  double antenna_bias_sigma_m = 0.1;     ///< prior std of each antenna-pattern coefficient [m] (F25c)
  double antenna_bias_memory_s = 0.0;    ///< forgetting time constant of the antenna pattern [s]; 0: none (F25c)
  double antenna_bias_offset_sigma_m = 0.3;   ///< std of the filter's position error in the learner [m]; 0 off (F25e)
  double antenna_bias_offset_memory_s = 1.0;  ///< correlation time of that position error [s] (F25e)
  double antenna_bias_noise_scale = 1000.0;   ///< factor on the innovation variance when learning the pattern (F25d)
  bool bias_guard = true;                ///< with a bias model: mix corrected and uncorrected filter (F24)
  double bias_guard_tau_s = 10.0;        ///< memory of the F24 predictive-likelihood comparison [s]
  BiasPoseUncertainty bias_model_pose = BiasPoseUncertainty::kNone;  ///< pose uncertainty of µ(x̂) (gp.md P47)
  double bias_model_level_exponent = 2.0;      ///< γ of the model-mean scale min(1, ρ)^γ; 0 off (F24b)
  double bias_model_training_level_m = 0.0;    ///< bias level of the model's training flights [m]; 0 unknown (F24b)
  double bias_model_training_mean_level_m = 0.0;  ///< level of the model's mean on its training flights [m] (F24c)
  bool bias_model_level_variance = false;      ///< corrected TDoA get the flight's excess bias variance (F24e)
  double max_lost_s = 1.0;               ///< all TDoA rejected this long → re-acquire (inflate P, open gate) [s] (F16)
  double lost_velocity_tau_s = 1.0;      ///< re-acquiring in flight: velocity relaxes to rest with this τ (F16e); 0 off
  double descent_margin_m = 0.0;         ///< landing: height at most this above the IMU's descent [m]; 0 off (F26)
  double max_rejection_rate = 0.7;       ///< more TDoA rejected in flight → re-acquire (F16d); 1: off

  // --- scheduling ---
  double max_predict_dt_s = 0.01;        ///< IMU samples are averaged over at most this interval [s]
  double update_predict_dt_s = 0.005;    ///< a TDoA update first predicts to its stamp if the state lags more [s]
  double cov_period_s = 0.02;            ///< covariance propagated with the accumulated Φ at this period [s]
  double max_gap_s = 0.2;                ///< a sensor gap longer than this is reported [s]
  double max_integration_gap_s = 0.25;   ///< a longer sensor-time gap is a time jump, not integrated [s] (F17)

  // --- ground phase and start ---
  GroundPhase ground_phase = GroundPhase::kDetectTakeoff;
  double takeoff_climb_mps = 0.25;       ///< take-off: leaky-integrated vertical velocity above this [m/s] (F15)
  double takeoff_leak_s = 1.0;           ///< time constant of the take-off detector's leaky integrator [s] (F15)
  double takeoff_acc_bias_sigma_mps2 = 0.1;  ///< thrust-axis accelerometer-bias std added at take-off; 0 off (F20)
  double acquisition_s = 1.0;            ///< after take-off: robust, gate-free acquisition window [s]
  double acquisition_tdoa_sigma_m = 0.6; ///< TDoA std used during acquisition
  bool has_start_position = false;       ///< true: start at start_w_p_b instead of multilateration
  Vec3 start_w_p_b = Vec3::Zero();       ///< user-given start (body origin, world) [m]
  double ground_z_m = 0.0;               ///< floor height (world z of the body origin at rest on the floor) [m]
  bool floor_constraint = true;          ///< z ≥ ground_z_m in the air, z = ground_z_m on the ground (F22, G23)
  double floor_margin_m = 0.05;          ///< tolerance below ground_z_m before the floor constraint acts [m]
  double ground_height_sigma_m = 0.1;    ///< height std of the body on the floor [m] (F22, F23′)
  double rest_tdoa_sigma_m = 1.0;        ///< TDoA std at rest or near the floor [m] (F14, F18)
  double low_flight_m = 0.25;            ///< TDoA below this height above the floor weigh as on the ground [m] (F14)
  double floor_anchor_height_m = 1.0;    ///< anchors less than this above the floor get a range delay [m]; 0 off (F16f)
  double leave_rest_pos_sigma_m = 0.2;   ///< horizontal position std added when the body leaves rest [m] (F20)
  double zupt_period_s = 0.01;           ///< period of the zero-velocity updates and of the checks in flight [s] (F14)
  double zupt_sigma_mps = 0.02;          ///< std of a zero-velocity update [m/s] (F14)
  bool rest_gyro_updates = true;         ///< zero-angular-rate updates of the gyro bias at rest (F18z)
  double rest_gyro_window_s = 0.1;       ///< window of one zero-angular-rate update [s] (F18z)
  int rest_gyro_min_samples = 5;         ///< a window with fewer gyro readings gives no update (F18z)
  double rest_gyro_sigma_floor_radps = 3e-4;  ///< std added to a window mean's own [rad/s] (F18z)
  double rest_gyro_gate_sigma = 4.0;     ///< a bias reading beyond this many σ widens the bias variance (F18z)
  double level_window_s = 0.1;           ///< levelling window before the first prediction [s] (F15)
  int level_max_samples = 100;           ///< … or this many IMU samples, whichever comes first (F15)
  double level_rest_acc_std_mps2 = 0.15; ///< |f| std below this over the levelling window: at rest [m/s²] (F15)
  double start_window_s = 0.6;           ///< multilateration window of the start / re-acquisition [s] (F16)
  int start_min_samples = 40;            ///< … and at least this many TDoA in it (F16)
  double start_max_window_s = 3.0;       ///< history kept while solves fail [s] (F16b)
  double start_min_pos_sigma_m = 0.2;    ///< lower bound of the fix's position std [m] (F16)
  double start_min_vel_sigma_mps = 0.15; ///< lower bound of the fix's velocity std [m/s] (F16b)
  double start_box_margin_m = 1.0;       ///< a fix outside the anchors' box grown by this fails [m] (F16)
  double start_max_rms_residual_m = 1.0; ///< a re-acquisition fix with a larger robust RMS residual fails [m] (F16)
  double floor_refute_height_m = 1.2;    ///< a moving solve this high above the floor refutes a floor start [m] (F16j)
  double floor_refute_residual_ratio = 1.5;  ///< … with an RMS residual ≤ this many times the floor solve's (F16j)
  double start_max_speed_mps = 5.0;      ///< a moving solve faster than this is a failed solve [m/s] (F16b)
  double start_floor_height_sigma_m = 0.1;  ///< height std of a fix on the floor [m] (F16c)
  double moving_start_vel_sigma_mps = 1.0;  ///< velocity std when the IMU starts while moving (in the air) [m/s]
  bool start_replay = true;              ///< a first start in motion reruns the filter over its window (F16g)
  double moving_start_att_sigma_rad = 0.1;  ///< roll/pitch std when the IMU starts while moving [rad]
  double moving_start_yaw_sigma_rad = 0.02; ///< yaw std when the IMU starts while moving [rad] (yaw 0 assumed)

  // --- ground contact, landing and the flight-mode inputs (F16f–F16i, F18, F26, F29) ---
  double contact_hold_s = 0.3;           ///< shaking within this long counts as floor contact [s] (F18)
  double contact_max_height_m = 0.8;     ///< contact and rest only below this height above the floor [m] (F18)
  double contact_sustained_s = 1.5;      ///< shaking this long is contact at any height [s] (F18)
  double contact_rearm_s = 0.5;          ///< after leaving the ground, shaking counts again after this long [s] (F18)
  double from_rest_s = 0.05;             ///< the ground was left from rest when at rest this recently [s] (F16f)
  double low_z_period_s = 0.05;          ///< sample period of the recent-height ring (60 samples) [s] (F18)
  int contact_low_z_samples = 30;        ///< the contact test uses the lowest of this many recent heights (F18)
  double rest_max_climb_mps = 0.3;       ///< rest enters the ground from the air only climbing slower [m/s] (F18)
  double rest_descent_mps = 0.2;         ///< a descent faster than this opens the landing window [m/s] (F18, F26)
  double landing_window_s = 3.0;         ///< length of the landing window after a descent [s] (F18, F16h)
  double landing_low_z_lead_s = 0.5;     ///< a landing's heights count from this before its last descent [s] (F18)
  double landing_band_m = 0.5;           ///< a landing's TDoA tried with floor delays this near the floor [m] (F16h)
  double landing_fix_max_s = 3.0;        ///< a landing's floor window ends without a fix after this long [s] (F16i)
  double air_shake_settle_s = 2.0;       ///< airborne shaking learned from this long after leaving ground [s] (F29b)
  double air_shake_min_height_m = 0.5;   ///< … and this high above the floor [m] (F29b)
  double floor_check_period_s = 3.0;     ///< a floor check in contact runs at most this often [s] (F29e)
  FlightModeParams flight_mode;          ///< the flight-mode supervisor's tunables, registered as mode_… (F29)

  // --- re-acquisition and divergence (F16, F16d) ---
  int lost_min_rejections = 20;          ///< lost also needs at least this many rejections in a row (F16)
  double rejection_memory_s = 0.3;       ///< memory of the TDoA rejection rate [s] (F16d)
  double rejection_min_height_m = 0.9;   ///< the rate counts only this high above the floor [m] (F16d)
  double rejection_settle_s = 2.0;       ///< … and from this long after an acquisition or take-off [s] (F16d)
  double rejection_min_samples = 20.0;   ///< … over at least this many (forgotten) TDoA (F16d)
  double healthy_rejection_rate = 0.3;   ///< the motion is recorded while at most this fraction is rejected (F16d)
  double healthy_period_s = 0.05;        ///< … every this long [s] (F16d)
  double revert_lead_s = 0.6;            ///< a fault reverts to a record at least this old [s] (F16d)
  double revert_max_age_s = 1.2;         ///< … and at most this old [s] (F16d)
  double diverged_box_margin_m = 3.0;    ///< diverged: the estimate left the anchors' box by this much [m] (F16)
  double diverged_speed_mps = 8.0;       ///< … or moves faster than this [m/s] (F16)

  // --- innovation consistency (F30) ---
  double nis_clip = 25.0;                ///< each TDoA's NIS is clipped at this (F30)
  double nis_window_s = 1.0;             ///< the NIS is averaged over this [s] (F30)
  double nis_far = 4.0;                  ///< a NIS beyond this (2σ) counts as far (F30)
  double nis_max_far_fraction = 0.5;     ///< inconsistent while a larger share is far (F30)
  double nis_min_samples = 20.0;         ///< … over at least this many (forgotten) TDoA (F30)
  double inconsistent_hold_s = 1.0;      ///< inconsistent only after this long [s] (F30)
  double max_widening_m = 0.5;           ///< the reported band widens by at most this [m] (F30)
  double widening_fade_s = 2.0;          ///< the widening fades with this time constant [s] (F30)

  // --- heading alignment (F28) ---
  bool heading_alignment = true;         ///< in flight, solve the attitude from thrust and velocity (F28)
  double heading_alignment_window_s = 8.0;  ///< window of the heading alignment [s] (F28)
  double max_aligned_heading_sigma_rad = 0.35;  ///< a fit acts only with a heading std below this [rad] (F28)
  double min_heading_change_rad = 0.15;  ///< a fit resets the attitude only beyond 3σ and this [rad] (F28)
  double min_aligned_tilt_sigma_rad = 0.01;  ///< floor of the attitude std written with an alignment [rad] (F28)

  // --- reported covariance (F23) ---
  double output_bias_sigma_m = 0.2;      ///< pair TDoA-bias std mapped into the reported covariance [m]; 0 off (F23)
  double output_bias_memory_s = 30.0;    ///< memory of the flight's bias level measured in flight [s]; 0 off (F23c)
  double output_bias_level_m = 0.24;     ///< reference level above which the band widens [m] (F23c)
  double output_bias_vertical_scale = 0.7;  ///< factor s on the bias term's vertical part, C ← S C S (F23d)
  double recent_pair_window_s = 0.5;     ///< pairs seen within this enter the bias term [s] (F23, F16k)
  double bias_floor_period_s = 0.05;     ///< the bias term is recomputed at most this often [s] (F23)

  // --- downward ToF range (Flow deck VL53L1x), docs/math/filter.md F21 ---
  bool fuse_tof = true;                  ///< fuse the ToF range as a height update when the log has it (F21)
  double tof_sigma_m = 0.03;             ///< ToF range noise std [m] (F21)
  double tof_offset_m = 0.037;           ///< sensor below the body origin along body z [m] (F21)
  double floor_z_m = 0.0;                ///< height of the flat floor the ToF sees, world z [m]
  double tof_max_range_m = 3.5;          ///< readings above this (VL53L1x limit), ≤ 0 or non-finite are ignored [m]
  double tof_gate_sigma = 4.0;           ///< Mahalanobis gate on the ToF innovation (F11); ≤ 0 disables

  // --- the sensors' physical ranges: a sample outside is skipped, counted and reported (F31) ---
  double max_gyro_radps = 70.0;          ///< ‖ω‖ above this is no reading [rad/s] (F31)
  double max_acc_mps2 = 490.0;           ///< ‖f‖ above this is no reading [m/s²] (F31)
  double max_tdoa_excess_m = 1.0;        ///< |z| beyond the pair's baseline by more is no range difference [m] (F31)

  /// Throws std::invalid_argument naming the first field that is out of range.
  void validate() const;

  /// The defaults: tuned on the UTIL pilot flights.
  static EkfParams defaults() { return {}; }
  /// Crazyflie kalman_core-like: thrust-only accelerometer, Crazyflie-style noise levels, no robust loss.
  static EkfParams crazyflieLike();
  /// TDoA only (no IMU): constant-velocity process model, no take-off detection.
  static EkfParams tdoaOnly();
};

std::string toString(AccelModel m);
std::string toString(ProcessModel m);
std::string toString(RobustLoss l);
std::string toString(GroundPhase g);
std::string toString(BiasPoseUncertainty b);
/// Parse the names printed by toString; throws std::invalid_argument for an unknown name.
AccelModel parseAccelModel(const std::string& s);
ProcessModel parseProcessModel(const std::string& s);
RobustLoss parseRobustLoss(const std::string& s);
GroundPhase parseGroundPhase(const std::string& s);
BiasPoseUncertainty parseBiasPoseUncertainty(const std::string& s);

}  // namespace uwb
