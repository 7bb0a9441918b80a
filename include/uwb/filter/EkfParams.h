/** @file EkfParams.h
 *  @brief Every tunable number of the localization filter, with units and defaults (one source of defaults).
 *
 *  Defaults were tuned on the 16 UTIL pilot TDoA2 flights (scripts/localize_all.sh); see docs/math/filter.md.
 */
#pragma once

#include <string>

#include "uwb/core/Types.h"

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
  // --- process noise (continuous-time spectral densities) ---
  /// Accelerometer white noise on v (the vertical channel in kThrustOnly). In flight the thrust-model vertical
  /// acceleration minus the Vicon one is a constant −0.06…−0.09 m/s² plus 1-s means that scatter by only
  /// 0.02–0.09 m/s² (util-pilot, incl. Vicon differentiation noise), i.e. ≈ 0.05 m/s²/√Hz; 0.2 let the
  /// position-dependent TDoA bias pull the height around (z is the largest error axis). docs/math/filter.md F7.
  double acc_noise_mps2_sqrthz = 0.05;
  double lateral_acc_noise_mps2_sqrthz = 0.5; ///< white acceleration on horizontal v beyond the drag (kThrustOnly, F3a)
  double gyro_noise_radps_sqrthz = 0.01;      ///< gyroscope white noise on δθ
  /// Accelerometer-bias random walk. Chosen on the 0425 flights (0.001–0.005 within 0.1 % of each other, 0.01 and 0.03
  /// worse), checked on 0426 and the simulated scenarios (filter.md F7).
  double acc_bias_rw_mps3_sqrthz = 0.003;
  double gyro_bias_rw_radps2_sqrthz = 1e-4;   ///< gyroscope-bias random walk
  double pos_noise_m_sqrts = 0.0;             ///< direct position random walk (Crazyflie procNoisePos)
  double cv_acc_noise_mps2_sqrthz = 2.0;      ///< TDoA-only constant-velocity model: white acceleration
  double ca_jerk_noise_mps3_sqrthz = 8.0;     ///< TDoA-only constant-acceleration model: white jerk
  AccelModel accel_model = AccelModel::kThrustOnly;
  /// (F2a) Rotor drag per unit horizontal world velocity, a = R f + g_w − k v_h [1/s], in the thrust-axis model (F3;
  /// with kFull the x/y readings carry the drag themselves) and in the heading alignment's (F28a′). Measured on the
  /// util-pilot flights against Vicon: 0.33–0.39 /s on 0426, 0.36–0.45 on 0425 (filter.md F28a′); 0 leaves it out.
  double rotor_drag_per_s = 0.36;
  /// Accelerometer model on the ground (zero-velocity updates before take-off and after landing, F14–F15).
  /// kFull (default) levels the attitude from all three axes. On the 0425 logs the motors' spin-up adds
  /// −0.3…−0.5 g to acc_x while the drone still sits level (Vicon pitch within 1°), so kFull takes off with a 4–9°
  /// pitch error that decays over 10–20 s; kThrustOnly keeps the attitude within 1° but its take-off detector
  /// fires 0.3–1 s later (the spurious tilt no longer projects the x offset onto the vertical), the start window
  /// then sees the climb, and the airborne RMSE got worse (16-flight median 0.261 → 0.276 m with acc noise 0.05).
  AccelModel ground_accel_model = AccelModel::kFull;
  ProcessModel process_model = ProcessModel::kImu;

  // --- initial uncertainty ---
  double init_pos_sigma_m = 2.0;
  double init_vel_sigma_mps = 0.1;
  double init_att_sigma_rad = 0.05;
  /// Yaw is nearly unobservable from TDoA (the tag sits 9 cm above the body origin) and the thrust-only
  /// accelerometer model gives no heading; a tight start keeps the TDoA updates from dragging it through the
  /// cross-covariances. With 0.2 rad the airborne yaw error on util-pilot reached median 12–45°; with 0.02 rad and
  /// the gyro-bias prior below it is 0–4° (0425-traj1…4, 0426-traj11/12). The GP inputs depend on it.
  double init_yaw_sigma_rad = 0.02;
  /// Matters where nothing measures the bias before the flight, a log that starts in the air (on the ground the
  /// ZUPTs learn it within a second). There the TDoA alone inform it, and the filter counts them as independent while
  /// their bias is correlated over seconds (F12): a vertical TDoA bias that drifts for a second reads as a thrust-axis
  /// accelerometer bias, and the velocity follows. The prior bounds what the first seconds can put into the state
  /// (filter.md F16b′). Chosen on the 0425 flights cut to start at 10 and 20 s (0.02…0.3 tried; 0.03–0.07 alike in the
  /// medians, the smallest 3–5 s worst at 0.02–0.05), checked on the 0426 cuts (none worse) and the simulated air
  /// starts, whose true turn-on bias is 0.1 m/s² per axis (3–5 s RMSE better on 21 of 27, worse on 4).
  double init_acc_bias_sigma_mps2 = 0.05;
  /// The Crazyflie calibrates its gyro bias on the ground before take-off, so the logged rates are nearly unbiased
  /// (integrated gyro alone stays within 1–3° of the Vicon yaw over a flight); a loose prior here lets the
  /// unobservable z bias absorb TDoA residuals and the yaw drift.
  double init_gyro_bias_sigma_radps = 0.001;

  // --- TDoA measurement ---
  Vec3 b_t_tag = kUtilTagOffset_b;       ///< tag (antenna) position in the body frame [m]
  /// TDoA noise std used by the filter: the white part beside the range-bias states (F27); without them (range_bias_
  /// sigma_m = 0) it stands for the whole correlated error and 0.35 m is the better value (F12).
  double tdoa_sigma_m = 0.2;
  double anchor_sigma_m = 0.0;           ///< std of each surveyed anchor coordinate [m] (graph node anchors)
  double gate_sigma = 4.0;               ///< Mahalanobis gate on the normalised innovation (χ²₁ = gate²)
  RobustLoss robust_loss = RobustLoss::kHuber;
  double robust_k = 1.0;                 ///< loss scale on the normalised innovation
  int robust_iterations = 2;             ///< IRLS iterations per TDoA update (≥ 1)
  double pair_bias_tau_s = 0.0;          ///< >0: per-pair TDoA offset learned from innovations, time constant [s] (F19)
  /// Per-anchor range bias as Ornstein–Uhlenbeck states of the filter with their cross-covariance (F27): stationary
  /// std [m]; 0 off. The TDoA of pair (A, B) carries β_B − β_A, so tdoa_sigma_m is then the white part alone.
  /// Chosen with range_bias_tau_s and tdoa_sigma_m on 0426 and the simulated protocol, reported on 0425 and const4
  /// (docs/math/filter.md F27).
  double range_bias_sigma_m = 0.07;
  double range_bias_tau_s = 0.5;         ///< correlation time of each anchor's range bias [s] (F27)
  /// (F27e) The stationary std adapted to the flight by online EM with this time constant [s]; 0 keeps
  /// range_bias_sigma_m. The adapted std stays within [range_bias_min_fraction, 1] × range_bias_sigma_m. Chosen on
  /// simulated flights with and without bias; the real flights do not move (docs/math/filter.md F27e).
  double range_bias_adapt_s = 0.1;
  double range_bias_min_fraction = 0.2;
  /// Tag antenna-pattern bias learned in flight from the innovations (F25): spherical harmonics of degrees
  /// 2…antenna_bias_degree (2–4) of the anchor's body-frame direction; 0 off.
  int antenna_bias_degree = 0;
  double antenna_bias_sigma_m = 0.1;     ///< prior std of each antenna-pattern coefficient [m] (F25c)
  double antenna_bias_memory_s = 0.0;    ///< forgetting time constant of the antenna pattern [s]; 0: none (F25c)
  double antenna_bias_offset_sigma_m = 0.3;   ///< std of the filter's position error in the learner [m]; 0 off (F25e)
  double antenna_bias_offset_memory_s = 1.0;  ///< correlation time of that position error [s] (F25e)
  /// Factor on the innovation variance when learning the pattern (F25d): the TDoA error is correlated in time, so
  /// 400 Hz innovations carry far less than one independent sample each. Chosen on 0426 (docs/math/filter.md F25).
  double antenna_bias_noise_scale = 1000.0;
  double max_lost_s = 1.0;               ///< all TDoA rejected this long → re-acquire (inflate P, open gate)
  double lost_velocity_tau_s = 1.0;      ///< re-acquiring in flight: velocity relaxes to rest with this τ (F16e); 0 off
  /// Landing: the height may not rise more than this above the IMU's dead-reckoned descent (F26) [m]; 0 off (the
  /// default: on a real low flight the dead reckoning can drift below the estimate; docs/math/filter.md F26).
  double descent_margin_m = 0.0;
  double max_rejection_rate = 0.7;       ///< more TDoA rejected in flight (0.3 s memory) → re-acquire (F16d); 1: off
  /// With a bias model: run the uncorrected filter beside the corrected one and output their mixture, weighted by
  /// how well each predicted the recent TDoA (F24). On by default: with the range-bias states (F27) it keeps a model
  /// that does not transfer from making the flight worse (chosen on the 0426 splits for "never worse than
  /// uncorrected", reported on 0425), at the price of part of the gain of a model that does and of a second filter
  /// (docs/math/filter.md F24).
  bool bias_guard = true;
  double bias_guard_tau_s = 10.0;        ///< memory of the F24 predictive-likelihood comparison [s]
  /// With a bias model: how the pose uncertainty of µ(x̂) enters (docs/math/gp.md P47). Off by default: neither form
  /// improved the leave-one-session-out splits (P47).
  BiasPoseUncertainty bias_model_pose = BiasPoseUncertainty::kNone;
  /// (F24b) With a bias model whose training flights' bias level is known (bias_model_training_level_m > 0, set
  /// from the model file): the model's mean is scaled by min(1, ρ)^γ, ρ = the bias level of this flight's
  /// uncorrected TDoA measured in flight (F23c) / the training level, γ = bias_model_level_exponent (0 off). A
  /// model of a more biased flight than this one over-corrects it.
  double bias_model_level_exponent = 2.0;
  double bias_model_training_level_m = 0.0;
  /// (F24c) The level of the model's own mean on its training flights (the F23c statistic on µ; set from the model
  /// file, 0 unknown). When known, ρ of F24b is divided by the level of µ on this flight / this one: a model that
  /// itself predicts a smaller bias on this path than on its training flights is not scaled down for that.
  double bias_model_training_mean_level_m = 0.0;
  /// (F24e) With a bias model whose levels are known: each corrected TDoA's variance gains the variance this flight
  /// shows beyond the model's training flights and beyond what the model's mean explains (gp.md P43c), with the
  /// levels as measured so far in flight. Off by default (F24e: the worst pair of the splits +15.0 → +3.8 %, but one
  /// pair above +1 % on the splits tested on 0426 and 4 points less gain on 0425 LOO).
  bool bias_model_level_variance = false;

  // --- scheduling ---
  double max_predict_dt_s = 0.01;        ///< IMU samples are averaged over at most this interval [s]
  double update_predict_dt_s = 0.005;    ///< a TDoA update first predicts to its stamp if the state lags more [s]
  double cov_period_s = 0.02;            ///< covariance propagated with the accumulated Φ at this period [s]
  double max_gap_s = 0.2;                ///< a sensor gap longer than this is reported [s]

  // --- ground phase and start ---
  GroundPhase ground_phase = GroundPhase::kDetectTakeoff;
  /// Take-off from the ground (F15): vertical velocity from the accelerometer's leaky integral above this [m/s]
  double takeoff_climb_mps = 0.25;
  /// Added (as a std) to the thrust-axis accelerometer bias at take-off (docs/math/filter.md F20). The bias learned
  /// on the ground (zero-velocity updates) is not the one in flight: with the motors running the thrust-model
  /// residual against the Vicon acceleration is −0.06…−0.09 m/s² while the ground estimate is −0.09…+0.10 m/s²
  /// (util-pilot; a step of median −0.07 m/s²), which the bias random walk would need minutes to follow. 0 disables.
  double takeoff_acc_bias_sigma_mps2 = 0.1;
  double acquisition_s = 1.0;            ///< after take-off: robust, gate-free acquisition window [s]
  double acquisition_tdoa_sigma_m = 0.6; ///< TDoA std used during acquisition
  bool has_start_position = false;       ///< true: start at start_w_p_b instead of multilateration
  Vec3 start_w_p_b = Vec3::Zero();       ///< user-given start (body origin, world) [m]
  double ground_z_m = 0.0;               ///< floor height (world z of the body origin at rest on the floor) [m]
  /// The body cannot be below the floor: in the air, an estimate with z < ground_z_m − floor_margin_m has its height
  /// belief truncated to z ≥ ground_z_m (F22, message-passing.md G23); on the ground z = ground_z_m. Off for rooms
  /// whose floor height in the anchor frame is unknown.
  bool floor_constraint = true;
  double floor_margin_m = 0.05;          ///< tolerance below ground_z_m before the floor constraint acts [m]
  /// TDoA std while the IMU says the body is at rest (F14, F18): near the floor the TDoA bias is large and
  /// correlated, so rest TDoA keep the position without pinning it; a moving body returns to tdoa_sigma_m at once.
  double rest_tdoa_sigma_m = 1.0;
  /// Anchors less than this above the floor (anchor z − ground_z_m) are floor-level: a body on the floor sees them by a
  /// path metres longer than the direct one. The start on the floor solves one range delay per such anchor with the
  /// position, and on the ground the TDoA are corrected by the delays found (F16f) [m]; 0 off.
  double floor_anchor_height_m = 1.0;
  /// Position std added when the body leaves rest (F20): the floor-level TDoA bias the rest position absorbed is not
  /// the bias in the air.
  double leave_rest_pos_sigma_m = 0.2;
  double start_window_s = 0.6;           ///< multilateration window of the start / re-acquisition [s] (F16)
  double moving_start_vel_sigma_mps = 1.0;  ///< velocity std when the IMU starts while moving (in the air) [m/s]
  /// A first start in motion runs the filter again over the multilateration window from the fix (F16g), instead of
  /// writing the fix into the state at its end (F16b).
  bool start_replay = true;
  double moving_start_att_sigma_rad = 0.1;  ///< roll/pitch std when the IMU starts while moving [rad]
  double moving_start_yaw_sigma_rad = 0.02; ///< yaw std when the IMU starts while moving [rad] (yaw 0 assumed)
  /// (F28) In flight, the attitude is solved for from the gyro-tracked specific force against the filter's velocity
  /// over windows of heading_alignment_window_s; a heading within 3σ of the filter's is a heading measurement, one
  /// beyond it (and beyond 0.15 rad) resets the attitude. Finds the heading of a log that starts in the air (yaw 0
  /// assumed); on the real util-pilot flights, which start at the heading the convention assumes, it changes no
  /// airborne RMSE by more than 1 mm (filter.md F28).
  bool heading_alignment = true;
  double heading_alignment_window_s = 8.0;  ///< window of the heading alignment [s] (F28)
  /// Std of one pair's slowly varying TDoA bias (F23; each anchor's range bias σ_b/√2): the reported position
  /// covariance is the filter's plus this bias mapped through the anchors in view. 0 reports the filter's P alone.
  double output_bias_sigma_m = 0.2;
  /// (F23c) The flight's own bias level σ̂_b, measured in flight from the residuals that no position explains, widens
  /// the reported band: σ_b = output_bias_sigma_m · max(1, σ̂_b / output_bias_level_m). The windows' statistics are
  /// forgotten with output_bias_memory_s; 0 keeps output_bias_sigma_m fixed.
  double output_bias_memory_s = 30.0;
  double output_bias_level_m = 0.24;
  /// (F23d) The vertical part of the bias term scaled by this factor, C ← S C S with S = diag(1, 1, s), in flight (the
  /// floor's F23′ is left alone): the per-anchor count of F23 over-states the height error that the TDoA2 neighbour
  /// cycle's bias causes. 1 leaves F23 as derived; 0.8 was chosen on the 0425 flights and their cuts (filter.md F23d).
  double output_bias_vertical_scale = 0.8;

  // --- downward ToF range (Flow deck VL53L1x), docs/math/filter.md F21 ---
  /// Fuse the ToF range as a height update when the log has it, as the Crazyflie's estimator does with a Flow deck
  /// (F21; `--no-tof` turns it off).
  bool fuse_tof = true;
  double tof_sigma_m = 0.03;             ///< ToF range noise std [m] (0425: 7–10 mm spread about the Vicon height)
  double tof_offset_m = 0.037;           ///< sensor below the body origin along body z [m] (0425: ToF − z = −0.037)
  double floor_z_m = 0.0;                ///< height of the flat floor the ToF sees, world z [m]
  double tof_max_range_m = 3.5;          ///< readings above this (VL53L1x limit), ≤ 0 or non-finite are ignored [m]
  double tof_gate_sigma = 4.0;           ///< Mahalanobis gate on the ToF innovation (F11); ≤ 0 disables

  // --- the sensors' physical ranges, docs/math/filter.md F31: a sample outside is skipped, counted and reported ---
  /// ‖ω‖ above this is no reading [rad/s]: 2× the full scale of a ±2000 deg/s gyro (Crazyflie 2.x BMI088, 34.9 rad/s
  /// per axis; saturated on all three axes ‖ω‖ = 60.5 rad/s). Dev flights: at most 8.6 rad/s (F31).
  double max_gyro_radps = 70.0;
  /// ‖f‖ above this is no reading [m/s²]: 50 g, about 2× the full scale of a ±24 g accelerometer (BMI088; saturated
  /// on all three axes 41.6 g). Dev flights: at most 4.9 g (F31).
  double max_acc_mps2 = 490.0;
  /// A TDoA whose |z| exceeds its anchor pair's baseline ‖a_B − a_A‖ by more than this is no range difference [m]
  /// (triangle inequality; the margin covers noise, NLOS delay and survey error). Dev flights: 0.61 m at most, apart
  /// from gross outliers 17–50 m beyond (F31).
  double max_tdoa_excess_m = 1.0;

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
