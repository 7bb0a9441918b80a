/** @file Estimator.h
 *  @brief The online estimator: one sensor event at a time, in time order, the current state and covariance after
 *         each (docs/math/filter.md F14–F23). The shape of the Crazyflie estimator: a short dispatcher over sensor
 *         types (addImu, addTdoa, addTof) around the error-state filter core (Ekf), with the start-up
 *         (StartUp: multilateration of position and velocity), rest detection (RestDetector) and the TDoA update
 *         through the graph's node (updateTdoa) as components of their own.
 *
 *  No look-ahead, bounded memory, nothing given out is rewritten, no allocation per event after the start-up (with or
 *  without a bias model; tests/alloc counts).
 *  No phase decision drops a measurement: at rest TDoA are down-weighted (F14), while moving they are gated on their
 *  innovation (F11); being at rest is re-decided from the IMU at every sample (F18).
 *
 *  @code
 *    Estimator est(EkfParams::defaults(), anchors);     // optional 3rd argument: a BiasPredictor
 *    est.addImu(t, imu);  est.addTdoa(z);  est.addTof(tof);   // in time order
 *    est.addNeighbourRange(t, neighbour_belief, range_m, coop);  // another agent as an uncertain anchor (G20)
 *    if (est.ready()) { LocalizerEstimate e = est.estimate(); ... }
 *  @endcode
 */
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "uwb/filter/AntennaBias.h"
#include "uwb/filter/BiasLevel.h"
#include "uwb/filter/CooperativeRange.h"
#include "uwb/filter/DescentBound.h"
#include "uwb/filter/FloorLevelAnchors.h"
#include "uwb/filter/FlightMode.h"
#include "uwb/filter/Ekf.h"
#include "uwb/filter/EkfParams.h"
#include "uwb/filter/InMotionAlignment.h"
#include "uwb/filter/RestDetector.h"
#include "uwb/filter/RestGyroWindow.h"
#include "uwb/filter/SensorRange.h"
#include "uwb/filter/SensorEvents.h"
#include "uwb/filter/StartReplay.h"
#include "uwb/filter/StartUp.h"
#include "uwb/filter/TdoaUpdate.h"
#include "uwb/filter/TofUpdate.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {

/// What the estimator currently believes about the body (reported; no measurement depends on it being right).
enum class FlightPhase : unsigned char {
  kGround,       ///< at rest before it first moved
  kAcquisition,  ///< position being found (start-up or re-acquisition) or just found
  kTracking,     ///< moving (flying, carried)
  kLanded,       ///< at rest after it moved
};
std::string toString(FlightPhase phase);

/// One output sample of the estimator.
struct LocalizerEstimate {
  double t_s = 0.0;
  NavState x;
  Vec3 sigma_p_m = Vec3::Zero();  ///< reported 1σ of the position per world axis [m] (F23)
  /// Reported covariance of (δp, δθ): position [m²] and attitude error [rad²] (F23 on the position block).
  Eigen::Matrix<double, 6, 6> cov_pose = Eigen::Matrix<double, 6, 6>::Zero();
  Vec3 sigma_v_mps = Vec3::Zero();  ///< 1σ of the velocity per world axis [m/s]
  FlightPhase phase = FlightPhase::kGround;
  std::uint32_t mode_status = 0;  ///< the flight-mode supervisor's status word (FlightModeStatus bits, F29)
  std::size_t n_tdoa_used_at_rest = 0;  ///< LocalizerSummary::n_tdoa_used_at_rest so far (a running count)
};

struct LocalizerSummary {
  std::size_t n_imu_total = 0;
  std::size_t n_tdoa_total = 0;
  std::size_t n_tdoa_used = 0;         ///< applied (possibly down-weighted)
  std::size_t n_tdoa_used_at_rest = 0; ///< of n_tdoa_used: with the rest std (F14)
  std::size_t n_tdoa_rejected = 0;     ///< χ² gate
  std::size_t n_tdoa_downweighted = 0; ///< robust weight < 1
  std::size_t n_tdoa_start = 0;        ///< went into a start-up / re-acquisition multilateration (F16)
  std::size_t n_tdoa_before_imu = 0;   ///< arrived before the IMU had levelled the attitude (first 0.1 s)
  std::size_t n_tdoa_degenerate = 0;
  std::size_t n_tdoa_unknown_anchor = 0;
  std::size_t n_tdoa_out_of_order = 0; ///< stamp older than the state by more than max_gap_s (ignored)
  // ToF height updates (F21; only with EkfParams::fuse_tof)
  std::size_t n_tof_total = 0;
  std::size_t n_tof_used = 0;
  std::size_t n_tof_rejected = 0;      ///< χ² gate
  std::size_t n_tof_invalid = 0;       ///< non-finite, ≤ 0 or above tof_max_range_m (ignored)
  std::size_t n_tof_tilted = 0;        ///< cos(tilt) ≤ kTofMinCosTilt (ignored)
  std::size_t n_tof_not_ready = 0;     ///< before the position was known
  /// Samples outside the sensors' physical ranges, skipped (F31): per sensor the count, first stamp, worst value
  SensorRangeReport sensor_range;
  // ranges to neighbouring agents (message-passing.md G20–G22; only through addNeighbourRange)
  std::size_t n_coop_total = 0;
  std::size_t n_coop_used = 0;
  std::size_t n_coop_rejected = 0;     ///< χ² gate
  std::size_t n_coop_not_ready = 0;    ///< before the position was known, or degenerate
  double coop_omega_sum = 0.0;         ///< Σ ω of the applied ones (mean = coop_omega_sum / n_coop_used)
  std::size_t n_predictions = 0;
  std::size_t n_covariance_propagations = 0;
  std::size_t n_zero_velocity_updates = 0;
  std::size_t n_rest_gyro_updates = 0;     ///< zero-angular-rate updates of the gyro bias at rest (F18z)
  std::size_t n_rest_gyro_widenings = 0;   ///< … whose bias reading widened the bias variance (F18z)
  std::size_t n_floor_updates = 0;     ///< floor constraint applied (F22)
  std::size_t n_descent_bound_updates = 0;  ///< height held down to the dead-reckoned descent while landing (F26)
  std::size_t n_rest_periods = 0;      ///< times the body came to rest
  std::size_t n_landing_fixes = 0;     ///< floor solves at the first landing of a log begun in the air (F16i)
  std::size_t n_rejection_faults = 0; ///< re-acquisitions because most TDoA were rejected (F16d)
  std::size_t n_reverted_motion = 0;  ///< of them, with the state put back to the motion before the fault (F16d)
  bool start_replayed = false;         ///< the first start in motion ran the filter again from its fix (F16g)
  bool start_floor_refuted = false;    ///< the first start's ground evidence was refuted by its TDoA (F16j)
  /// (F28) attitude resets by the heading alignment: their times (the first 100) and heading changes [rad]
  std::size_t n_heading_alignments = 0;
  std::vector<double> heading_alignment_t_s, heading_alignment_change_rad;
  /// The pair-bias level measured in flight (F23c), √(2σ̂_a²) with the prior's share, at the last window counted;
  /// NaN before the first (or with output_bias_memory_s = 0)
  double bias_level_m = std::numeric_limits<double>::quiet_NaN();
  std::size_t n_bias_level_windows = 0;  ///< windows counted for it (F23c)
  /// With a bias model: the level of the TDoA before its correction (F24b; without a model bias_level_m is that)
  double raw_bias_level_m = std::numeric_limits<double>::quiet_NaN();
  /// With a bias model whose training mean level is known: the level of the model's own mean on this flight (F24c)
  double model_mean_level_m = std::numeric_limits<double>::quiet_NaN();
  double bias_model_mean_scale = 1.0;      ///< the scale of the model's mean at the end (F24b)
  double min_bias_model_mean_scale = 1.0;  ///< its lowest during the flight (F24b)
  /// With bias_model_level_variance: the variance added to each corrected TDoA at the end (F24e) [m²]
  double bias_model_level_variance_m2 = 0.0;
  std::size_t n_reacquisitions = 0;    ///< lost or diverged → position found again by multilateration (F16)
  std::size_t n_time_jumps = 0;        ///< sensor-time gaps or backward jumps handled (F17)
  std::vector<double> reacquisition_t_s;  ///< when each re-acquisition started (first 100)
  /// when each of those ended with a fix (same order; fewer when the last one had not ended)
  std::vector<double> reacquired_t_s;
  /// The log began with the body in motion (in the air or carried): the first fix was one in motion (F16b, no ground
  /// evidence). It moved before any take-off, so a later rest is a landing and the first time it leaves rest is not
  /// where its motion began.
  bool started_in_motion = false;
  /// When the estimator entered the ground (rest or floor contact, F18) and when it left it again (first 100 each,
  /// same order; one fewer left when the log ends on the ground). Its TDoA there carry the floor-level bias (F14).
  // the flight-mode supervisor (F29) and the innovation consistency check (F30)
  double floor_doubted_s = 0.0;           ///< on the floor by the IMU while the TDoA put the tag in the air [s]
  double floor_doubted_max_height_m = 0.0;  ///< the largest TDoA height meanwhile [m]
  std::size_t n_mode_overrules = 0;       ///< mode changes the TDoA forced against the IMU
  double air_shake_rms_radps = 0.0;       ///< the airborne shaking level learned in flight (F29b) [rad/s]
  std::size_t n_inconsistent_periods = 0; ///< times the TDoA's NIS stayed beyond chance for inconsistent_s (F30)
  double inconsistent_s = 0.0;            ///< time the check failed [s] (F30)
  std::size_t n_consistency_widenings = 0;  ///< covariance widenings by the check (F30)
  std::size_t n_floor_checks = 0;         ///< floor contact examined by a solve on the floor against the air (F29e)
  std::size_t n_floor_refutations = 0;    ///< … that put the tag in the air
  std::vector<double> ground_entered_t_s;
  std::vector<double> ground_left_t_s;
  double takeoff_t_s = std::numeric_limits<double>::quiet_NaN();  ///< first time it left rest
  double landing_t_s = std::numeric_limits<double>::quiet_NaN();  ///< last time it came to rest after moving
  double ready_t_s = std::numeric_limits<double>::quiet_NaN();    ///< first position fix
  double start_t_s = 0.0;
  double end_t_s = 0.0;
  ProcessModel process_model = ProcessModel::kImu;
  Vec3 start_w_p_b = Vec3::Zero();     ///< first position found by multilateration (or given)
  double start_rms_residual_m = 0.0;
  MergeReport merge;                   ///< batch path only: what cleaning the log found (F17)
  /// With the bias guard (F24): time-mean and final weight of the corrected filter in the output (NaN without it)
  double bias_guard_mean_weight = std::numeric_limits<double>::quiet_NaN();
  double bias_guard_final_weight = std::numeric_limits<double>::quiet_NaN();
};

class Estimator {
 public:
  /// params.validate() is called; throws std::invalid_argument when the params are bad or fewer than 4 anchors are
  /// given. With params.process_model == kImu the estimator waits for IMU samples; otherwise TDoA alone drive it.
  Estimator(const EkfParams& params, AnchorTable anchors, BiasPredictor bias = {});
  // the start-up component refers to this estimator's anchor table: not copied or moved
  Estimator(const Estimator&) = delete;
  Estimator& operator=(const Estimator&) = delete;

  void addImu(double t_s, const ImuReading& imu);
  void addTdoa(const TdoaMeasurement& z);
  void addTof(const TofObservation& tof);
  /// A two-way range at t_s to a neighbouring agent whose tag-position belief (aged to t_s, G22) is `neighbour`
  /// (G20, G21). Ignored (counted) before the position is known.
  CooperativeRangeResult addNeighbourRange(double t_s, const Moments3& neighbour, double range_m,
                                           const CooperativeRangeOptions& options);

  /// The position is known (after the first multilateration or from a given start).
  bool ready() const { return ready_; }
  /// A bias model corrects the TDoA (the third constructor argument was given).
  bool hasBiasModel() const { return static_cast<bool>(bias_); }
  /// Time of the latest event folded in [s].
  double time() const { return t_last_event_; }
  const NavState& state() const { return ekf_.state(); }
  /// The filter (its range-bias states, F27, among others).
  const Ekf& ekf() const { return ekf_; }
  /// Covariance at the last propagation (Ekf::covariance).
  const ErrMat& covariance() const { return ekf_.covariance(); }
  FlightPhase phase() const { return phase_; }
  /// The current estimate with the reported covariance (F23).
  LocalizerEstimate estimate() const;
  const LocalizerSummary& summary() const { return summary_; }
  const EkfParams& params() const { return params_; }
  /// The update of the TDoA last given to addTdoa; outcome kSkipped when it reached no update (not initialized,
  /// start-up collection, out of order). Its innovation and S are the filter's one-step prediction of it (F24).
  const TdoaUpdateResult& lastTdoaUpdate() const { return last_tdoa_; }
  /// Whether the last TDoA was taken in flight: tracking, above the floor's band, neither still nor shaking (F16d,
  /// F23c, F24).
  bool lastTdoaInFlight() const { return last_tdoa_in_flight_; }
  /// The antenna-pattern bias learned in flight (F25); nullptr when EkfParams::antenna_bias_degree is 0.
  const OnlineAntennaBias* antennaBias() const { return antenna_ ? &*antenna_ : nullptr; }

 private:
  struct PairOffset;
  /// The TDoA update's options while tracking, acquiring and at rest, and the ToF update's (F11–F14, F16, F21).
  void configureUpdateOptions();
  /// (F24b, F24c, F25) The bias model's mean scaling and the learned antenna pattern wrapped around the bias model.
  void configureBiasCorrections();
  void initialize(double t_s, const Vec3& acc_mean_b, bool moving);
  /// (F15) One IMU sample into the levelling window; initializes the filter when the window is complete.
  void addLevellingSample(double t_s, const ImuReading& imu);
  /// (F18, F29) The IMU's ground evidence of one sample (rest, contact, climb) into the flight-mode supervisor.
  void superviseGround(double t_s, const ImuReading& imu, double dt_imu);
  /// (F15) The take-off detector's leaky vertical velocity on the ground; true when it shows a climb.
  bool updateTakeoffDetector(const ImuReading& imu, double dt_imu, bool shaking);
  /// (F18) The lowest height estimate of the last n samples of the recent-height ring and the current one [m].
  double lowestRecentZ(std::size_t n) const;
  /// (F18, F29b) Floor contact: recent shaking near the floor, or sustained shaking.
  bool floorContact(double t_s) const;
  /// (F18) Rest that may enter the ground: near the floor, not climbing, or within a landing's window.
  bool restNearFloor(double t_s);
  /// (F18z) The gyro readings of a body at rest on the floor, window by window, as readings of the gyro bias.
  void restGyroUpdate(double t_s, const ImuReading& imu, bool rest);
  /// (F29, F29e) Floor checks, and entering or leaving the ground as the flight mode decided.
  void followFlightMode(double t_s, bool climbing, bool contact, double shake_ms);
  /// (F14, F16, F22, F26) The zero-velocity update on the ground; in flight the floor, descent and divergence checks.
  void runPeriodicChecks(double t_s);
  /// (F17) Initializes a TDoA-only filter, handles time jumps and predicts to t; false when the TDoA is dropped.
  bool advanceToTdoa(double t);
  /// (F16) One TDoA into the start-up's multilateration window; finishes the start, landing fix or floor check.
  void collectStartTdoa(const TdoaMeasurement& z);
  /// (F19, F16f, F16h) The TDoA with its pair offset and floor-level delays removed; *po: its pair's offset slot.
  TdoaMeasurement correctedTdoa(const TdoaMeasurement& z, bool acquiring, PairOffset** po);
  /// (F25d, F19) The antenna pattern and the pair offset learn from an applied update's innovation.
  void learnFromInnovation(double t, const TdoaUpdateResult& r, bool acquiring, bool near_floor, PairOffset* po);
  void countTdoaOutcome(double t, const TdoaUpdateResult& r, bool acquiring, bool near_floor);
  /// (F16d) The rejection rate in flight, and the recent motion recorded while the TDoA agree.
  void trackRejectionRate(double t, const TdoaUpdateResult& r);
  /// (F23c, F24b, F24c) The flight's bias levels from a TDoA's residual.
  void feedBiasLevels(double t, const TdoaMeasurement& z, const TdoaUpdateResult& r, bool flying,
                      double range_bias_prior_m, const Vec3& w_p_tag_prior);
  /// (F23) The anchor pairs in view, and the reported bias term refreshed from them.
  void notePairInView(double t, const TdoaMeasurement& z, const TdoaUpdateResult& r);
  /// (F16, F16d, F16k) Lost or rejecting in flight: re-acquire.
  void superviseTracking(double t, bool acquiring);
  void predictTo(double t_s);
  void propagate(bool force);
  void handleTimeJump(double t_s, double gap_s);
  void leaveGround(double t_s, bool climbing);
  void enterGround(double t_s);
  void startAcquisition(double t_s, bool reacquisition);
  void finishStart(double t_s, const StartFix& fix);
  void finishLandingFix(const StartFix& fix);
  void endLandingFix();
  void finishFloorCheck(double t_s, const StartFix& fix);
  /// F16d: position and velocity back to the recent motion recorded before a TDoA fault.
  void revertToHealthyMotion(double t_s);
  void superviseTdoa(double t_s, const TdoaMeasurement& z);
  void checkConsistency(double t_s, double nis);
  void applyFloorConstraint(bool on_ground);
  /// F26: the height bounded from above by the IMU's dead-reckoned descent while landing.
  void applyDescentBound(double t_s);
  /// (F28) one IMU sample into the heading alignment while tracking in flight; resets the attitude on its evidence
  void alignHeading(double t_s, const ImuReading& imu, double dt_s);
  bool diverged() const;
  /// Reported position covariance: the filter's plus the bias floor (F23).
  Mat3 reportedPositionCovariance() const;
  /// The covariance of the anchors' range biases seen through the pairs in view (F23, BiasFloor.h).
  Mat3 biasFloor() const;
  /// Distinct anchors of the TDoA received (applied or rejected) within window_s before the last event (F16k).
  int anchorsHeard(double window_s) const;
  /// The pair-bias std that biasFloor() maps: output_bias_sigma_m, scaled by the flight's measured level (F23c).
  double outputBiasSigma() const;
  /// (F24b) The scale of the bias model's mean from the flight's uncorrected level; after each window of raw_level_.
  void updateModelMeanScale();
  /// (F29c) The ranging overruled the floor: the height from its window, the acquisition's robust updates (F16).
  void acquireFromHeightWindow(double t_s);
  /// (F16) The acquisition phase from a fix or a height reset at t_s: its robust updates until t_start_s +
  /// acquisition_s, the rejection counters and the time of the last accepted TDoA restarted.
  void beginAcquisitionPhase(double t_s, double t_start_s);
  /// Drops a landing's or a floor check's window unsolved (F16i, F29e).
  void cancelStartWindow();

  EkfParams params_;
  AnchorTable anchors_;
  BiasPredictor bias_;
  std::optional<OnlineAntennaBias> antenna_;  ///< learned antenna pattern (F25), with antenna_bias_degree > 0
  BiasPredictor corrections_;  ///< bias_ plus the learned antenna pattern (F25b); empty without learning
  bool antenna_predicted_ = false;  ///< the last TDoA's correction included the antenna pattern
  bool imu_mode_;
  DescentBound descent_;  ///< dead-reckoned descent while landing (F26)
  Ekf ekf_;
  RestDetector rest_;
  RestGyroWindow rest_gyro_;  ///< (F18z) windows of rest_gyro_window_s, rest_gyro_min_samples readings at least
  FlightModeSupervisor mode_;  ///< ground or air from all the evidence (F29)
  TdoaModelParams tdoa_model_;  ///< the tag lever arm for the supervisor's TDoA heights (F29c)
  // (F30) the innovation consistency check: forgotten sums of the clipped NIS and of the count
  double nis_sum_ = 0.0, nis_n_ = 0.0, nis_far_ = 0.0, t_nis_ = -1e300, t_consistent_ = -1e300, t_last_widening_ = -1e300;
  bool inconsistent_ = false;
  double consistency_var_m2_ = 0.0, t_consistency_var_ = -1e300;  ///< the reported band's widening (F30) [m²]
  StartUp start_;
  StartReplay replay_;  ///< the first start in motion, run again from the fix (F16g)
  InMotionAlignment heading_align_;  ///< (F28) the attitude from the gyro-tracked specific force and the velocity
  FloorLevelAnchors floor_anchors_;  ///< floor-level anchors and their delays on the floor (F16f)
  ClimbFromFloor climb_;             ///< height since leaving the ground without a detected climb (F16f)
  TdoaUpdateOptions track_opt_, acq_opt_, rest_opt_;
  TofUpdateOptions tof_opt_;
  LocalizerSummary summary_;
  Vec3 box_min_ = Vec3::Zero(), box_max_ = Vec3::Zero(), centroid_ = Vec3::Zero();

  bool initialized_ = false;
  bool ready_ = false;
  bool on_ground_ = false;       ///< at rest or in ground contact (F18)
  double v_climb_ = 0.0;         ///< take-off detector's vertical velocity (F15) [m/s]
  double g_ref_ = kGravity_mps2; ///< vertical specific force on the ground [m/s²]
  double t_last_shake_ = -1e300, t_shake_since_ = 0.0, t_left_ground_ = -1e300;
  double t_last_rest_ = -1e300;  ///< last IMU sample at rest (F18)
  double t_entered_ground_ = -1e300;  ///< the ground phase began (F18)
  double t_fix_settled_ = -1e300;  ///< acquisition_s after the last fix: the antenna learner starts (F25d)
  double t_last_descent_ = -1e300;  ///< last IMU sample with the estimate descending (F18)
  std::array<double, 60> low_z_{};  ///< recent heights, one per 50 ms, the last 3 s (F18)
  std::size_t i_low_z_ = 0, n_low_z_ = 0;
  double t_low_z_sample_ = -1e300;
  bool landing_fix_ = false;     ///< start_ collects the floor window of a landing (F16i)
  bool floor_check_ = false;     ///< start_ collects a floor check's window (F29e)
  bool left_rest_mode_ = false;  ///< the supervisor's mode was rest before its last decision (F16f, F29)
  double t_floor_check_ = -1e300;
  double t_landing_fix_s_ = 0.0;  ///< when that window began
  bool moved_ = false;
  FlightPhase phase_ = FlightPhase::kAcquisition;
  double t_last_event_ = std::numeric_limits<double>::quiet_NaN();
  double t_pred_ = 0.0;
  double t_last_imu_ = std::numeric_limits<double>::quiet_NaN();
  double t_last_zupt_ = -1e300;
  double t_acq_end_ = -1e300;
  double t_last_accept_ = 0.0;
  double t_last_tof_accept_ = -1e300;
  std::size_t n_rejected_streak_ = 0;
  struct PastMotion {
    double t_s = 0.0;
    Vec3 w_p_b = Vec3::Zero(), w_v_b = Vec3::Zero();
  };
  std::array<PastMotion, 24> healthy_{};  ///< recent motion while the TDoA agreed (F16d)
  std::size_t i_healthy_ = 0, n_healthy_ = 0;
  double t_healthy_sample_ = -1e300;
  double n_rejected_recent_ = 0.0, n_gated_recent_ = 0.0;  ///< forgotten counts of TDoA rejected / gated in flight (F16d)
  double t_rejection_ = std::numeric_limits<double>::quiet_NaN();
  // IMU averaging between predictions (F17) and the levelling window before initialization (F15)
  Vec3 acc_sum_ = Vec3::Zero(), gyro_sum_ = Vec3::Zero();
  int n_imu_acc_ = 0;
  ImuReading last_imu_;
  Vec3 init_acc_sum_ = Vec3::Zero();
  Vec3 init_gyro_sum_ = Vec3::Zero();
  double init_acc_sq_sum_ = 0.0;
  double init_gyro_sq_sum_ = 0.0;
  int n_init_ = 0;
  double t_first_imu_ = std::numeric_limits<double>::quiet_NaN();
  // per-pair offsets (F19)
  struct PairOffset {
    double offset_m = 0.0;
    double t_last_s = std::numeric_limits<double>::quiet_NaN();
  };
  std::vector<PairOffset> pair_offsets_;
  // anchor pairs seen recently, for the reported bias floor (F23)
  struct RecentPair {
    int id_a = -1, id_b = -1;
    double t_s = -1e300;
  };
  std::vector<RecentPair> recent_pairs_;
  TdoaUpdateResult last_tdoa_;
  bool last_tdoa_in_flight_ = false;
  Mat3 bias_floor_ = Mat3::Zero();  ///< biasFloor() at t_bias_floor_s_; σ_b² I before the first TDoA (F23)
  std::optional<BiasLevel> bias_level_;  ///< the flight's bias level (F23c), with output_bias_memory_s > 0
  /// With a bias model: the level of the uncorrected TDoA (F24b), and the model as given, which bias_ scales
  std::optional<BiasLevel> raw_level_;
  /// (F24c) the level of the model's own mean µ on this flight, and µ of the last TDoA before any scaling
  std::optional<BiasLevel> mean_level_;
  double last_model_mean_m_ = 0.0;
  BiasPredictor model_bias_;
  double model_mean_scale_ = 1.0;
  double model_level_variance_m2_ = 0.0;  ///< (F24e) added to a corrected TDoA's variance
  double t_bias_floor_s_ = -1e300;
};

}  // namespace uwb
