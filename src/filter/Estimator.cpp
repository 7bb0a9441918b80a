/** @file Estimator.cpp
 *  @brief The online estimator's dispatcher: docs/math/filter.md F14–F23 (rest, start-up by multilateration,
 *         acquisition, gated/robust tracking, re-acquisition, floor constraint, reported covariance).
 */
#include "uwb/filter/Estimator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "uwb/filter/BiasFloor.h"
#include "uwb/filter/Multilateration.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

/// Roll and pitch from a specific-force reading at rest, yaw = 0 (F15).
Quat levelFromGravity(const Vec3& b_acc) {
  const double roll = std::atan2(b_acc.y(), b_acc.z());
  const double pitch = std::atan2(-b_acc.x(), std::sqrt(b_acc.y() * b_acc.y() + b_acc.z() * b_acc.z()));
  return Quat(Eigen::AngleAxisd(pitch, Vec3::UnitY()) * Eigen::AngleAxisd(roll, Vec3::UnitX()));
}

/// Events listed in the summary (re-acquisitions, ground periods): the first this many, reserved at construction so
/// that no event allocates
constexpr std::size_t kMaxListedEvents = 100;
/// Anchor ids below this have a slot in the per-pair offset table (F19).
constexpr int kMaxPairId = 64;

/// (F16e) The horizontal motion relaxed towards rest over Δt from (p0, v0): v = v0 e^{−Δt/τ},
/// p = p0 + v0 τ (1 − e^{−Δt/τ}); writes x and y of *p and *v, leaves z.
void relaxHorizontal(const Vec3& p0, const Vec3& v0, double dt, double tau, Vec3* p, Vec3* v) {
  const double e = std::exp(-dt / tau);
  p->head<2>() = p0.head<2>() + v0.head<2>() * (tau * (1.0 - e));
  v->head<2>() = v0.head<2>() * e;
}

}  // namespace

std::string toString(FlightPhase phase) {
  switch (phase) {
    case FlightPhase::kGround: return "ground";
    case FlightPhase::kAcquisition: return "acquisition";
    case FlightPhase::kTracking: return "tracking";
    case FlightPhase::kLanded: return "landed";
  }
  return "unknown";
}

Estimator::Estimator(const EkfParams& params, AnchorTable anchors, BiasPredictor bias)
    : params_(params),
      anchors_(std::move(anchors)),
      bias_(std::move(bias)),
      imu_mode_(params.process_model == ProcessModel::kImu),
      descent_(DescentBoundParams{params.descent_margin_m}),
      ekf_(params),
      rest_gyro_(params.rest_gyro_window_s, params.rest_gyro_min_samples),
      mode_(params.flight_mode),
      start_(anchors_, params.b_t_tag, StartUpParams::fromEkfParams(params)),
      replay_(params),
      heading_align_(params.heading_alignment_window_s, InMotionAlignment::kDefaultSamplePeriod_s,
                     InMotionAlignment::kDefaultCorrelation_s, params.rotor_drag_per_s) {
  params_.validate();
  if (anchors_.size() < 4) throw std::invalid_argument("Estimator: at least 4 anchors are needed");
  floor_anchors_ = FloorLevelAnchors(anchors_, params_.ground_z_m, params_.floor_anchor_height_m);
  if (floor_anchors_.any()) start_.setFloorLevelAnchors(floor_anchors_.mask());
  summary_.process_model = params_.process_model;
  summary_.sensor_range = SensorRangeReport(params_);  // (F31) the limits, nothing counted
  for (std::vector<double>* list : {&summary_.reacquisition_t_s, &summary_.reacquired_t_s,
                                    &summary_.ground_entered_t_s, &summary_.ground_left_t_s,
                                    &summary_.heading_alignment_t_s, &summary_.heading_alignment_change_rad})
    list->reserve(kMaxListedEvents);
  const AnchorBox box = anchorBox(anchors_);
  box_min_ = box.min;
  box_max_ = box.max;
  centroid_ = box.centroid;

  configureUpdateOptions();
  if (params_.pair_bias_tau_s > 0.0) pair_offsets_.resize(kMaxPairId * kMaxPairId);
  configureBiasCorrections();
}

void Estimator::configureUpdateOptions() {
  tdoa_model_.b_t_tag = params_.b_t_tag;
  track_opt_ = {.sigma_m = params_.tdoa_sigma_m,
                .gate_sigma = params_.gate_sigma,
                .loss = params_.robust_loss,
                .robust_k = params_.robust_k,
                .robust_iterations = params_.robust_iterations,
                .b_t_tag = params_.b_t_tag,
                .bias_pose = params_.bias_model_pose};
  acq_opt_ = track_opt_;
  acq_opt_.sigma_m = params_.acquisition_tdoa_sigma_m;
  acq_opt_.gate_sigma = 0.0;  // (F16) no gate while acquiring; the robust loss limits outliers
  if (acq_opt_.loss == RobustLoss::kNone) acq_opt_.loss = RobustLoss::kHuber;
  rest_opt_ = track_opt_;
  rest_opt_.sigma_m = params_.rest_tdoa_sigma_m;  // (F14) down-weighted at rest, still gated
  tof_opt_ = {.sigma_m = params_.tof_sigma_m,
              .offset_m = params_.tof_offset_m,
              .floor_z_m = params_.floor_z_m,
              .max_range_m = params_.tof_max_range_m};
}

void Estimator::configureBiasCorrections() {
  if (params_.antenna_bias_degree > 0) {
    // (F25) the learned antenna pattern adds to the (optional) bias model's correction
    antenna_.emplace(AntennaBiasParams{params_.antenna_bias_degree, params_.antenna_bias_sigma_m,
                                       params_.antenna_bias_memory_s, params_.b_t_tag,
                                       params_.antenna_bias_offset_sigma_m, params_.antenna_bias_offset_memory_s});
    corrections_ = [this](const TdoaFeature& feature) {
      BiasPrediction b = bias_ ? bias_(feature) : BiasPrediction{};
      // a prediction the update discards (F12) must not leave a regressor for learning
      antenna_predicted_ = std::isfinite(b.mean_m) && std::isfinite(b.variance_m2) && b.variance_m2 >= 0.0 &&
                           std::isfinite(b.noise_scale) && b.noise_scale > 0.0;
      if (!antenna_predicted_) return b;
      const BiasPrediction a = antenna_->predict(feature);
      b.mean_m += a.mean_m;
      // (F25b) its variance hᵀ P_θ h is not added to the filter's R: the inflated σ_tdoa stands for it
      return b;
    };
  }
  bias_floor_ = Mat3::Identity() * params_.output_bias_sigma_m * params_.output_bias_sigma_m;
  recent_pairs_.reserve(64);
  if (params_.output_bias_memory_s > 0.0 && params_.output_bias_sigma_m > 0.0)
    bias_level_.emplace(params_.output_bias_memory_s);
  if (bias_ && params_.output_bias_memory_s > 0.0) {
    raw_level_.emplace(params_.output_bias_memory_s);
    if (params_.bias_model_training_level_m > 0.0 && params_.bias_model_level_exponent > 0.0) {
      // (F24b) the model's mean scaled by what this flight's own level says of the model's training flights
      model_bias_ = std::move(bias_);
      bias_ = [this](const TdoaFeature& feature) {
        BiasPrediction b = model_bias_(feature);
        last_model_mean_m_ = b.mean_m;
        b.mean_m *= model_mean_scale_;
        b.variance_m2 += model_level_variance_m2_;  // (F24e) 0 unless bias_model_level_variance
        return b;
      };
      // (F24c) and what the model itself predicts on this flight, against what it predicted on its training flights
      if (params_.bias_model_training_mean_level_m > 0.0) mean_level_.emplace(params_.output_bias_memory_s);
    }
  }
}

void Estimator::initialize(double t_s, const Vec3& acc_mean_b, bool moving) {
  NavState x0;
  // (F15) at rest the specific force is gravity; in motion under the thrust model it is the thrust along body z
  // whatever the tilt (the x/y readings are unused, F3): there the attitude starts level
  const bool level_start = !imu_mode_ || (moving && params_.accel_model == AccelModel::kThrustOnly);
  x0.w_q_b = level_start ? Quat::Identity() : levelFromGravity(acc_mean_b);
  x0.w_p_b = params_.has_start_position ? params_.start_w_p_b : Vec3(centroid_.x(), centroid_.y(), params_.ground_z_m);
  ErrMat P0 = initialCovariance(params_);
  if (moving) {
    // (F15) the IMU starts in motion (e.g. in the air): the gravity direction is only approximate and the velocity
    // is unknown
    P0.block<2, 2>(kAtt, kAtt) = Eigen::Matrix2d::Identity() * params_.moving_start_att_sigma_rad *
                                 params_.moving_start_att_sigma_rad;
    P0.block<3, 3>(kVel, kVel) = Mat3::Identity() * params_.moving_start_vel_sigma_mps *
                                 params_.moving_start_vel_sigma_mps;
    P0(kAtt + 2, kAtt + 2) = params_.moving_start_yaw_sigma_rad * params_.moving_start_yaw_sigma_rad;
  }
  if (params_.has_start_position) P0.block<3, 3>(kPos, kPos) = Mat3::Identity() * 0.05 * 0.05;
  ekf_.initialize(x0, P0);
  ekf_.setAccelModel(params_.accel_model);
  t_pred_ = t_s;
  t_last_accept_ = t_s;
  initialized_ = true;
  if (params_.has_start_position) {
    ready_ = true;
    summary_.ready_t_s = t_s;
    summary_.start_w_p_b = params_.start_w_p_b;
    phase_ = FlightPhase::kAcquisition;
    t_acq_end_ = t_s + 0.5 * params_.acquisition_s;
  } else {
    startAcquisition(t_s, false);
  }
}

void Estimator::startAcquisition(double t_s, bool reacquisition) {
  landing_fix_ = false;  // the window begun here replaces a landing's (F16i)
  floor_check_ = false;  // … and a floor check's (F29e)
  phase_ = FlightPhase::kAcquisition;
  descent_.clear();
  climb_.clear();
  if (reacquisition) {
    ++summary_.n_reacquisitions;
    if (summary_.reacquisition_t_s.size() < kMaxListedEvents) summary_.reacquisition_t_s.push_back(t_s);
  }
  // at rest the body stays where it is: position only; otherwise position and velocity (F16b)
  start_.begin(t_s, ekf_.state(), !(imu_mode_ && on_ground_), reacquisition);
  // (F16g) the first start in motion is run again from its fix; a re-acquisition's prediction is relaxed (F16e)
  if (params_.start_replay && imu_mode_ && !on_ground_ && !reacquisition && !ready_) replay_.begin(ekf_, t_s);
  else replay_.stop();
}

void Estimator::finishStart(double t_s, const StartFix& fix) {
  if (fix.floor_refuted && on_ground_) {
    // (F16j) floor contact before the first fix (a shaking burst in flight) is refuted by the TDoA: the body is in the
    // air and never was on the floor; the fix is the solve in motion of the same window
    mode_.learnAirShake(rest_.gyroHighPassMeanSquare());  // (F29b) the burst was airborne shaking
    leaveGround(t_s, false);
    summary_.takeoff_t_s = std::numeric_limits<double>::quiet_NaN();
    summary_.start_floor_refuted = true;
  }
  // (F16g) in motion, the filter runs again over the window from the fix's starting point; otherwise (on the floor,
  // a re-acquisition, or a window not recorded whole) the fix becomes the state now (F16b)
  const bool replayed =
      fix.with_velocity && replay_.recording() && replay_.referenceTime() == fix.t_ref_s &&
      replay_.replay(ekf_, fix.w_p0, fix.w_v0, std::sqrt(fix.cov(0, 0)), params_.moving_start_vel_sigma_mps,
                     params_.cov_period_s, [this](Ekf& f, const TdoaMeasurement& z) {
                       updateTdoa(f, anchors_, z, acq_opt_, bias_ ? &bias_ : nullptr);
                     });
  replay_.stop();
  if (replayed) summary_.start_replayed = true;
  else ekf_.resetPositionVelocity(fix.w_p_b, fix.w_v_b, fix.cov);
  if (!fix.anchor_delay_m.empty()) floor_anchors_.setDelays(fix.anchor_delay_m);  // (F16f) a fix on the floor
  if (ready_ && summary_.reacquired_t_s.size() < summary_.reacquisition_t_s.size())
    summary_.reacquired_t_s.push_back(t_s);
  if (!ready_) {
    // a first fix in motion (F16b: no ground evidence, the velocity solved for) is a log that began in the air or
    // carried: the body has moved, and its next rest is a landing
    if (imu_mode_ && fix.with_velocity && !on_ground_) {
      summary_.started_in_motion = true;
      moved_ = true;
    }
    summary_.ready_t_s = t_s;
    summary_.start_w_p_b = fix.w_p0;
    summary_.start_rms_residual_m = fix.rms_residual_m;
  }
  ready_ = true;
  // (F16g) a replayed start ran the acquisition from the window's start already, over the window's TDoA: it counts,
  // and what is left of it runs from here
  beginAcquisitionPhase(t_s, replayed ? fix.t_ref_s : t_s);
}

void Estimator::beginAcquisitionPhase(double t_s, double t_start_s) {
  phase_ = FlightPhase::kAcquisition;
  t_acq_end_ = t_start_s + params_.acquisition_s;  // (F16) the acquisition lasts acquisition_s from its start
  t_fix_settled_ = t_s + params_.acquisition_s;  // (F25d) the antenna learner waits this long after any fix
  t_last_accept_ = t_s;
  n_rejected_streak_ = 0;
  n_rejected_recent_ = n_gated_recent_ = 0.0;
}

void Estimator::predictTo(double t_s) {
  const double dt = t_s - t_pred_;
  if (!(dt > 0.0)) return;
  if (imu_mode_) {
    ImuReading m = last_imu_;
    if (n_imu_acc_ > 0) {
      m.b_acc_mps2 = acc_sum_ / n_imu_acc_;
      m.b_gyro_radps = gyro_sum_ / n_imu_acc_;
    }
    // (F16e) re-acquiring in flight: the IMU alone drifts metres in a second horizontally (thrust model: the
    // horizontal acceleration rests on the tilt), while a position-controlled body stays near its course. The
    // horizontal motion relaxes towards rest instead (relaxHorizontal); the vertical channel keeps the thrust-axis
    // IMU's acceleration with its velocity damped; the covariance keeps growing with the process noise.
    if (ready_ && start_.active() && !on_ground_ && params_.lost_velocity_tau_s > 0.0) {
      const Vec3 p0 = ekf_.state().w_p_b, v0 = ekf_.state().w_v_b;
      ekf_.predict(m, dt);
      const double tau = params_.lost_velocity_tau_s;
      const Vec3 p = ekf_.state().w_p_b, v = ekf_.state().w_v_b;
      Vec3 p_relaxed = p, v_relaxed = v;
      relaxHorizontal(p0, v0, dt, tau, &p_relaxed, &v_relaxed);
      // vertically a thrust-bias error b then moves the height at b τ instead of b t
      v_relaxed.z() = v.z() * std::exp(-dt / tau);
      ErrVec dx = ErrVec::Zero();
      dx.segment<3>(kPos) = p_relaxed - p;
      dx.segment<3>(kVel) = v_relaxed - v;
      ekf_.inject(dx);
    } else {
      ekf_.predict(m, dt);
      if (replay_.recording()) replay_.recordPredict(m, dt);
    }
  } else {
    ekf_.predictTdoaOnly(dt);
  }
  acc_sum_.setZero();
  gyro_sum_.setZero();
  n_imu_acc_ = 0;
  t_pred_ = t_s;
  ++summary_.n_predictions;
}

void Estimator::propagate(bool force) {
  if (ekf_.pendingDt() > 0.0 && (force || ekf_.pendingDt() >= params_.cov_period_s)) {
    ekf_.propagateCovariance();
    ++summary_.n_covariance_propagations;
  }
}

void Estimator::handleTimeJump(double t_s, double gap_s) {
  // (F17) nothing is integrated across a gap or a backward jump: the covariance grows by what a body could do in it
  ++summary_.n_time_jumps;
  replay_.stop();  // (F16g) the record holds predictions and TDoA only
  descent_.clear();
  climb_.clear();
  endLandingFix();  // (F16i) the window's stamps no longer follow
  propagate(true);
  acc_sum_.setZero();
  gyro_sum_.setZero();
  n_imu_acc_ = 0;
  t_pred_ = t_s;
  if (ready_) {
    // up to 1 m/s for the length of the gap, at most 2 m and 1 m/s
    const double g = std::abs(gap_s);
    ekf_.inflatePosition(std::min(g, 2.0), std::min(g, 1.0));
    if (std::abs(gap_s) > 1.0 && !start_.active()) startAcquisition(t_s, true);
  }
}

void Estimator::leaveGround(double t_s, bool climbing) {
  on_ground_ = false;
  if (mode_.onFloor()) mode_.reset(FlightMode::kAirborne);  // (F29) a start's TDoA refuted the floor (F16j)
  if (floor_check_) cancelStartWindow();  // (F29e) the check's window holds the body on the floor
  floor_check_ = false;
  endLandingFix();  // (F16i) the window holds the body at rest on the floor only
  replay_.stop();  // (F16g) the record holds predictions and TDoA only
  descent_.clear();  // (F26) the climb is not dead-reckoned from the floor: the detector's climb speed lags
  // (F16f) leaving rest (motors off) without a detected climb, the body still sits on the floor (rotors spun up
  // without floor shaking, or lifted by hand): its height is dead-reckoned from there for the fade of the floor-level
  // delays. Leaving floor contact (shaking with the motors running) or with a detected climb, it has already risen.
  const bool from_rest =
      (t_s - t_last_rest_ < params_.from_rest_s || left_rest_mode_) && t_s - t_last_shake_ >= params_.contact_hold_s;
  if (floor_anchors_.hasDelays() && !climbing && from_rest) climb_.start(t_s);
  t_left_ground_ = t_s;
  if (summary_.ground_left_t_s.size() < summary_.ground_entered_t_s.size()) summary_.ground_left_t_s.push_back(t_s);
  t_last_shake_ = -1e300;
  if (std::isnan(summary_.takeoff_t_s)) summary_.takeoff_t_s = t_s;
  moved_ = true;
  if (imu_mode_) {
    ekf_.setAccelModel(params_.accel_model);
    propagate(true);
    if (climbing) {
      // (F15) the climb that the detector saw becomes the vertical velocity
      ErrVec dx = ErrVec::Zero();
      dx(kVel + 2) = v_climb_ - ekf_.state().w_v_b.z();
      ekf_.inject(dx);
    }
    // (F20) the thrust-axis accelerometer bias with the motors running is not the one learned at rest, and the
    // position held on the ground absorbed the floor-level TDoA bias
    if (params_.takeoff_acc_bias_sigma_mps2 > 0.0) ekf_.inflateThrustBias(params_.takeoff_acc_bias_sigma_mps2);
    // horizontally only: the floor fixed the height (F22)
    if (ready_) ekf_.inflateHorizontalPosition(params_.leave_rest_pos_sigma_m, 0.3);
  }
  v_climb_ = 0.0;
  if (ready_ && phase_ != FlightPhase::kAcquisition) phase_ = FlightPhase::kTracking;
  // (F16b, F16g) a take-off before the first fix: the window collected so far holds the body at rest and is not the
  // constant-velocity motion the moving solve fits; the start begins again from here, in motion, with its replay
  if (imu_mode_ && !ready_ && start_.active()) startAcquisition(t_s, false);
}

void Estimator::enterGround(double t_s) {
  on_ground_ = true;
  t_entered_ground_ = t_s;
  replay_.stop();  // (F16g) the record holds predictions and TDoA only
  descent_.clear();
  climb_.clear();
  n_low_z_ = 0;
  // (F15) the take-off detector starts from the descent the floor is about to stop: the touchdown's deceleration
  // brings it to zero, not to a climb
  v_climb_ = std::min(ekf_.state().w_v_b.z(), 0.0);
  ++summary_.n_rest_periods;
  if (summary_.ground_entered_t_s.size() < kMaxListedEvents) summary_.ground_entered_t_s.push_back(t_s);
  if (moved_) summary_.landing_t_s = t_s;
  if (imu_mode_ && rest_.atRest()) ekf_.setAccelModel(params_.ground_accel_model);  // (F15) levelled from all axes
  if (ready_ && phase_ != FlightPhase::kAcquisition) phase_ = moved_ ? FlightPhase::kLanded : FlightPhase::kGround;
  // (F16i) a landing of a log that has not seen the floor yet (begun in the air): the floor's delays and the
  // position are solved from a window on the floor as at a start on the floor (F16f), and the solution is fused with
  // the estimate. A log begun on the floor keeps the delays of its start (F16h uses them at every landing).
  if (moved_ && ready_ && imu_mode_ && params_.floor_constraint && floor_anchors_.any() &&
      !floor_anchors_.hasDelays() && !start_.active() &&
      phase_ != FlightPhase::kAcquisition) {
    start_.begin(t_s, ekf_.state(), false, true);
    landing_fix_ = true;
    t_landing_fix_s_ = t_s;
  }
}

void Estimator::finishFloorCheck(double t_s, const StartFix& fix) {
  floor_check_ = false;
  if (!fix.floor_refuted || !on_ground_) return;
  // (F29e) the TDoA put the tag in the air, off the floor the IMU's contact held it to: the shaking is this flight's
  // airborne shaking (F29b), the mode airborne, and the solve in the air the position
  mode_.learnAirShake(rest_.gyroHighPassMeanSquare());
  leaveGround(t_s, false);
  ekf_.resetPositionVelocity(fix.w_p_b, fix.w_v_b, fix.cov);
  ++summary_.n_floor_refutations;
}

void Estimator::endLandingFix() {
  if (landing_fix_) cancelStartWindow();
  landing_fix_ = false;
}

void Estimator::cancelStartWindow() {
  start_.cancel();
  // (F16) the window's TDoA were received and held for its solve, not missing: the time without an accepted TDoA
  // that declares the position lost in flight counts from here
  t_last_accept_ = std::max(t_last_accept_, t_last_event_);
}

void Estimator::finishLandingFix(const StartFix& fix) {
  landing_fix_ = false;
  // only a solve with the delays: the plain floor solve takes metres of floor-level delay for position (F16f)
  if (fix.anchor_delay_m.empty()) return;
  floor_anchors_.setDelays(fix.anchor_delay_m);
  // the horizontal position held through the touchdown absorbed the floor-level TDoA (no delays to take them with,
  // F16h): its variance grows as for a take-off from rest (F20) before the floor's solve corrects it
  ekf_.inflateHorizontalPosition(params_.leave_rest_pos_sigma_m, 0.0);
  ekf_.positionUpdate(0, fix.w_p_b.x(), std::sqrt(fix.cov(0, 0)));
  ekf_.positionUpdate(1, fix.w_p_b.y(), std::sqrt(fix.cov(1, 1)));
  ++summary_.n_landing_fixes;
}

void Estimator::applyFloorConstraint(bool on_ground) {
  // (F22) z ≥ floor: a one-sided constraint, applied when the estimate violates it; on the ground (F14) the body
  // sits on the floor: z = floor ± params_.ground_height_sigma_m
  if (!params_.floor_constraint || !ready_) return;
  const double z = ekf_.state().w_p_b.z();
  if (on_ground && start_.active()) return;
  if (on_ground) {
    ekf_.positionUpdate(2, params_.ground_z_m, params_.ground_height_sigma_m);
    ++summary_.n_floor_updates;
    return;
  }
  if (z < params_.ground_z_m - params_.floor_margin_m) {
    // in the air: the height's belief truncated to z ≥ floor (G23); the other states follow through their covariance
    // with the height. An estimate that sank through the floor cannot keep sinking: a downward velocity is set to zero
    // (the mean only), which a velocity barely correlated with the height (a fresh fix) would otherwise keep
    propagate(true);
    if (ekf_.constrainPositionAbove(2, params_.ground_z_m)) ++summary_.n_floor_updates;
    if (ekf_.state().w_v_b.z() < 0.0) {
      ErrVec dx = ErrVec::Zero();
      dx(kVel + 2) = -ekf_.state().w_v_b.z();
      ekf_.inject(dx);
    }
  }
}

void Estimator::applyDescentBound(double t_s) {
  // (F26) landing: the estimate may not climb more than the margin above the IMU's dead-reckoned descent; the height's
  // belief truncated to z ≤ floor + bound (G23), applied only when violated (as the floor constraint, F22)
  if (!(params_.descent_margin_m > 0.0) || !ready_ || start_.active() || on_ground_) return;
  const NavState& x = ekf_.state();
  const double h = x.w_p_b.z() - params_.ground_z_m;
  const double bound = descent_.update(t_s, h, x.w_v_b.z());
  if (!(h > bound)) return;  // no bound (NaN) or within it
  propagate(true);
  if (ekf_.constrainPositionBelow(2, params_.ground_z_m + bound)) ++summary_.n_descent_bound_updates;
}

bool Estimator::diverged() const {
  const NavState& x = ekf_.state();
  if (!x.w_p_b.allFinite() || !x.w_v_b.allFinite()) return true;
  if ((x.w_p_b.array() < box_min_.array() - params_.diverged_box_margin_m).any() ||
      (x.w_p_b.array() > box_max_.array() + params_.diverged_box_margin_m).any())
    return true;
  return x.w_v_b.squaredNorm() > params_.diverged_speed_mps * params_.diverged_speed_mps;
}

void Estimator::addImu(double t_s, const ImuReading& imu) {
  ++summary_.n_imu_total;
  if (!imu_mode_) return;
  // (F31) a reading outside the sensors' range is skipped whole: the next sample integrates over the gap
  if (!checkImuRange(t_s, imu, summary_.sensor_range)) return;
  if (std::isnan(t_last_event_)) summary_.start_t_s = t_s;
  t_last_event_ = std::isnan(t_last_event_) ? t_s : std::max(t_last_event_, t_s);
  summary_.end_t_s = t_last_event_;
  if (!initialized_) {
    addLevellingSample(t_s, imu);
    return;
  }
  const double dt_imu = t_s - t_last_imu_;
  if (dt_imu > params_.max_integration_gap_s || dt_imu < -params_.max_gap_s) {
    handleTimeJump(t_s, dt_imu);
    t_last_imu_ = t_s;
    last_imu_ = imu;
    return;
  }
  if (dt_imu <= 0.0) return;  // a repeated or slightly older stamp: nothing to integrate
  t_last_imu_ = t_s;
  last_imu_ = imu;
  acc_sum_ += imu.b_acc_mps2;
  gyro_sum_ += imu.b_gyro_radps;
  ++n_imu_acc_;

  // (F18) ground evidence is re-decided at every sample: at rest (motors off), or shaking as on the floor with the
  // motors running while the estimate is near the floor; a climb seen by the accelerometer contradicts both (F15)
  rest_.update(t_s, imu, dt_imu);
  if (rest_.atRest()) t_last_rest_ = t_s;
  // (F26) the vertical motion from the accelerometer alone, for the descent bound
  if (!on_ground_ && (descent_.running() || climb_.running())) {
    const double a_up = worldVertical(ekf_.state().w_q_b, imu.b_acc_mps2) - g_ref_;
    if (descent_.running()) descent_.integrate(a_up, dt_imu);
    climb_.integrate(t_s, a_up, dt_imu);  // (F16f)
  }
  if (params_.ground_phase == GroundPhase::kDetectTakeoff) superviseGround(t_s, imu, dt_imu);

  if (t_s - t_pred_ >= params_.max_predict_dt_s) {
    predictTo(t_s);
    propagate(false);
  }
  alignHeading(t_s, imu, dt_imu);
  runPeriodicChecks(t_s);
}

void Estimator::addLevellingSample(double t_s, const ImuReading& imu) {
  // (F15) levelling window: mean specific force for the attitude, its spread tells rest from motion
  if (std::isnan(t_first_imu_)) t_first_imu_ = t_s;
  init_acc_sum_ += imu.b_acc_mps2;
  init_gyro_sum_ += imu.b_gyro_radps;
  init_acc_sq_sum_ += imu.b_acc_mps2.squaredNorm();
  init_gyro_sq_sum_ += imu.b_gyro_radps.squaredNorm();
  ++n_init_;
  last_imu_ = imu;
  t_last_imu_ = t_s;
  if (!(t_s - t_first_imu_ >= params_.level_window_s || n_init_ >= params_.level_max_samples)) return;
  const Vec3 mean = init_acc_sum_ / n_init_;
  const double var = std::max(init_acc_sq_sum_ / n_init_ - mean.squaredNorm(), 0.0);
  const bool moving = var > params_.level_rest_acc_std_mps2 * params_.level_rest_acc_std_mps2;
  rest_.reset(imu);
  // (F18) a still levelling window shows the gyro's own bias: the rest test reads against it too
  const Vec3 gyro_mean = init_gyro_sum_ / n_init_;
  if (!moving) rest_.setGyroReference(gyro_mean);
  // (F18) the window's moments start the rest statistics: a body still from the first sample is on the ground
  // before the first fix (a motors-off start), whatever its TDoA say of the height
  const double gyro_ms = init_gyro_sq_sum_ / n_init_;
  rest_.seed(t_s, var, gyro_ms, std::max(gyro_ms - gyro_mean.squaredNorm(), 0.0));
  g_ref_ = mean.norm();
  initialize(t_s, mean, moving);
}

void Estimator::superviseGround(double t_s, const ImuReading& imu, double dt_imu) {
  bool climbing = false;
  // (F29b) floor shaking: the high-passed gyro far above the shaking this flight shows in the air
  const double shake_ms = rest_.gyroHighPassMeanSquare();
  const bool shaking = mode_.shakingStandsOut(shake_ms);
  if (on_ground_) climbing = updateTakeoffDetector(imu, dt_imu, shaking);
  if (shaking && t_s - t_left_ground_ > params_.contact_rearm_s) {
    if (t_s - t_last_shake_ >= params_.contact_hold_s) t_shake_since_ = t_s;  // a new shaking episode
    t_last_shake_ = t_s;
  }
  // recent lowest height: on ground contact the estimate can run away upwards (contact force in the thrust
  // model, floor-biased TDoA) before the shaking shows
  if (ready_ && t_s - t_low_z_sample_ >= params_.low_z_period_s) {
    low_z_[i_low_z_] = ekf_.state().w_p_b.z();
    i_low_z_ = (i_low_z_ + 1) % low_z_.size();
    n_low_z_ = std::min(n_low_z_ + 1, low_z_.size());
    t_low_z_sample_ = t_s;
  }
  const bool contact = floorContact(t_s);
  const bool rest = restNearFloor(t_s);
  restGyroUpdate(t_s, imu, rest);
  // (F29) the IMU's evidence, weighed with the TDoA's by the flight-mode supervisor
  const NavState& x = ekf_.state();
  const bool settled_in_air = !on_ground_ && ready_ && phase_ == FlightPhase::kTracking &&
                              t_s - t_left_ground_ > params_.air_shake_settle_s &&
                              x.w_p_b.z() - params_.ground_z_m > params_.air_shake_min_height_m;
  mode_.addImu(t_s, dt_imu, ImuModeEvidence{rest, contact, climbing, shake_ms}, settled_in_air);
  left_rest_mode_ = mode_.mode() == FlightMode::kRest;  // (F16f) the mode the ground is left from
  mode_.decide(t_s);
  summary_.floor_doubted_s = mode_.doubtedFloorTime();
  summary_.floor_doubted_max_height_m = mode_.doubtedFloorMaxHeight();
  summary_.n_mode_overrules = static_cast<std::size_t>(mode_.tdoaOverrules());
  summary_.air_shake_rms_radps = std::sqrt(mode_.airShakeLevel());
  followFlightMode(t_s, climbing, contact, shake_ms);
}

void Estimator::restGyroUpdate(double t_s, const ImuReading& imu, bool rest) {
  // (F18z) a body at rest on the floor does not turn: each window of its gyro readings reads the gyro bias, as the
  // Crazyflie calibrates its gyro before take-off; the window's own spread says how well (learned, not assumed)
  if (!(params_.rest_gyro_updates && imu_mode_ && on_ground_ && ready_ && rest && mode_.mode() == FlightMode::kRest)) {
    rest_gyro_.clear();
    return;
  }
  const std::optional<GyroWindowStats> w = rest_gyro_.add(t_s, imu.b_gyro_radps);
  if (!w) return;
  predictTo(t_s);
  propagate(true);
  const double floor_var = params_.rest_gyro_sigma_floor_radps * params_.rest_gyro_sigma_floor_radps;
  const Vec3 var = w->mean_var_radps2.array() + floor_var;
  summary_.n_rest_gyro_widenings +=
      static_cast<std::size_t>(ekf_.zeroAngularRateUpdate(w->mean_radps, var, params_.rest_gyro_gate_sigma));
  ++summary_.n_rest_gyro_updates;
}

bool Estimator::updateTakeoffDetector(const ImuReading& imu, double dt_imu, bool shaking) {
  // (F15) take-off detector: leaky integral of the vertical specific-force excess over its level on the ground
  const double a_up = worldVertical(ekf_.state().w_q_b, imu.b_acc_mps2);
  v_climb_ = expNegative(dt_imu / params_.takeoff_leak_s) * v_climb_ + dt_imu * (a_up - g_ref_);
  if (rest_.stillNow() || v_climb_ < 0.05) g_ref_ += (dt_imu / 2.0) * (a_up - g_ref_);
  // a body that shakes is still touching the floor (touchdown bounces, spin-up): no take-off
  (void)shaking;
  return v_climb_ > params_.takeoff_climb_mps && !rest_.stillNow();
}

double Estimator::lowestRecentZ(std::size_t n) const {
  // the lowest estimate of the last n samples (and the current one)
  double z_low = ekf_.state().w_p_b.z();
  const std::size_t size = low_z_.size();
  for (std::size_t k = 0; k < std::min(n, n_low_z_); ++k)
    z_low = std::min(z_low, low_z_[(i_low_z_ + size - 1 - k) % size]);
  return z_low;
}

bool Estimator::floorContact(double t_s) const {
  // shaking near the floor, or shaking for long wherever the estimate is (flight shakes only briefly)
  // (F29b) and not entered from the air while the estimate climbs: shaking in a climb is rotors at thrust, not the
  // floor (the climb after a take-off of a drone whose gyro shakes in flight)
  const std::size_t n_low = static_cast<std::size_t>(params_.contact_low_z_samples);
  return t_s - t_last_shake_ < params_.contact_hold_s &&
         (on_ground_ || !ready_ || ekf_.state().w_v_b.z() < params_.rest_max_climb_mps) &&
         (!ready_ || t_s - t_shake_since_ >= params_.contact_sustained_s ||
          lowestRecentZ(n_low) - params_.ground_z_m < params_.contact_max_height_m);
}

bool Estimator::restNearFloor(double t_s) {
  // rest enters the ground near the floor only: an IMU logged at a low rate or filtered reads as quiet in a still
  // hover as with the motors off, and a still hover high above the floor is not on the ground (the floor height, the
  // ZUPT and the ground's TDoA weight would pull it down); the window spans the climb of the estimate after a
  // touchdown (F26). Once on the ground, rest holds it wherever the estimate is.
  // Nor does it enter while the estimate climbs or after a climb from the floor: after a take-off a steady climb or
  // hover reads as quiet as rest too, and the ZUPT would take the climb for accelerometer bias. Only a descent
  // opens the window (the touchdown: the estimate may climb after it, F26).
  const NavState& x = ekf_.state();
  if (ready_ && x.w_v_b.z() < -params_.rest_descent_mps) t_last_descent_ = t_s;
  // the heights of a landing: those since landing_low_z_lead_s before its last descending sample (the window's span)
  const auto landingLowZ = [&] {
    const double span_s = t_s - t_last_descent_ + params_.landing_low_z_lead_s;
    return lowestRecentZ(std::min(low_z_.size(), static_cast<std::size_t>(span_s / params_.low_z_period_s) + 1));
  };
  const double floor_m = params_.ground_z_m, max_height_m = params_.contact_max_height_m;
  return rest_.atRest() &&
         (on_ground_ || !ready_ ||
          (x.w_p_b.z() - floor_m < max_height_m && x.w_v_b.z() < params_.rest_max_climb_mps) ||
          (t_s - t_last_descent_ < params_.landing_window_s && landingLowZ() - floor_m < max_height_m));
}

void Estimator::followFlightMode(double t_s, bool climbing, bool contact, double shake_ms) {
  const bool ground_now = mode_.onFloor();
  // (F29e) floor contact whose TDoA the floor explains worse than the air: the mode is examined by a solve of a
  // fresh window on the floor against one in the air (F16j), at most every floor_check_period_s
  if (ground_now && on_ground_ && ready_ && !start_.active() && mode_.mode() == FlightMode::kContact &&
      mode_.tdoaLogOdds() > 0.0 && t_s - t_floor_check_ >= params_.floor_check_period_s) {
    t_floor_check_ = t_s;
    floor_check_ = true;
    landing_fix_ = false;
    start_.begin(t_s, ekf_.state(), false, true);
    ++summary_.n_floor_checks;
  }
  if (ground_now && !on_ground_) {
    predictTo(t_s);
    propagate(true);
    enterGround(t_s);
  } else if (!ground_now && on_ground_) {
    predictTo(t_s);
    const bool overruled = (mode_.status() & kTdoaOverrulesImu) != 0;
    leaveGround(t_s, climbing);
    if (overruled) {
      // (F29) the TDoA put the tag in the air against the IMU's floor evidence: the shaking seen now is this
      // flight's airborne shaking (F29b), and the position held on the floor is found again from the TDoA (F16)
      if (contact) mode_.learnAirShake(shake_ms);
      if (ready_ && !start_.active()) acquireFromHeightWindow(t_s);
      mode_.clearTdoa();
    }
  }
}

void Estimator::acquireFromHeightWindow(double t_s) {
  // (F29c) the height from the downward range's window when it has one (F29f), from the TDoA's otherwise; the
  // horizontal position as held on the floor within the floor's TDoA σ, the velocity unknown; the robust, gate-free
  // acquisition updates (F16) take it from there
  const FlightModeParams& mp = params_.flight_mode;
  const bool tof = std::isfinite(mode_.tofHeight());
  const double h_m = tof ? mode_.tofHeight() : mode_.tdoaHeight();
  const double spread_m = tof ? mode_.tofHeightSpread() : mode_.tdoaHeightSpread();
  const double sigma_m = tof ? mp.tof_height_sigma_m : mp.height_floor_sigma_m;
  // the air hypothesis that overruled the floor puts the body at the nearest height of the flight range, d from the
  // window's mean; a window whose variance exceeds that of the flight range itself (uniform: (h_max − h_min)²/12)
  // locates the height less well than the hypothesis alone (a floor whose TDoA carry metres of bias, after a rough
  // landing): the position is found again by multilateration instead
  const double range_m = mp.air_max_height_m - mp.air_min_height_m;
  const double h_air = std::clamp(h_m, mp.air_min_height_m, mp.air_max_height_m);
  const double var_m2 = spread_m * spread_m + (h_m - h_air) * (h_m - h_air) + sigma_m * sigma_m;
  if (!(std::isfinite(h_m) && std::isfinite(spread_m)) || var_m2 > range_m * range_m / 12.0) {
    startAcquisition(t_s, true);
    return;
  }
  ekf_.resetHeight(params_.ground_z_m + h_air, var_m2);
  ekf_.inflateHorizontalPosition(params_.rest_tdoa_sigma_m, params_.moving_start_vel_sigma_mps);
  climb_.clear();  // the height is the window's, not dead-reckoned from the floor (leaveGround may have started it)
  beginAcquisitionPhase(t_s, t_s);
}

void Estimator::runPeriodicChecks(double t_s) {
  if (on_ground_ && t_s - t_last_zupt_ >= params_.zupt_period_s) {
    predictTo(t_s);
    propagate(true);
    ekf_.zeroVelocityUpdate(params_.zupt_sigma_mps);  // (F14)
    ++summary_.n_zero_velocity_updates;
    t_last_zupt_ = t_s;
    applyFloorConstraint(true);
  } else if (t_s - t_last_zupt_ >= params_.zupt_period_s) {
    t_last_zupt_ = t_s;
    applyFloorConstraint(false);
    applyDescentBound(t_s);
    // (F16) divergence is checked at the same 10 ms period
    // (F16) and in flight without any TDoA accepted for max_lost_s (none received, e.g. a radio outage): the
    // prediction gets the re-acquisition's relaxed horizontal motion (F16e) until fresh TDoA fix the position
    const bool lost_in_flight = !on_ground_ && phase_ != FlightPhase::kAcquisition &&
                                t_s - t_last_accept_ > params_.max_lost_s && [&] {
                                  // (F16k) none received (an outage), or enough anchors for a fix
                                  const int heard = anchorsHeard(params_.max_lost_s);
                                  return heard == 0 || heard >= minFixAnchors(false);
                                }();
    if (ready_ && !start_.active() && (diverged() || lost_in_flight)) {
      propagate(true);
      startAcquisition(t_s, true);
    }
  }
}

void Estimator::addTof(const TofObservation& tof) {
  ++summary_.n_tof_total;
  if (!params_.fuse_tof) return;
  const double t = tof.t_s;
  if (!(std::isfinite(tof.range_m) && tof.range_m > 0.0 && tof.range_m <= params_.tof_max_range_m)) {
    ++summary_.n_tof_invalid;
    return;
  }
  // (F29f) the height it measures is evidence of the flight mode whatever the position estimate
  if (initialized_ && imu_mode_ && params_.ground_phase == GroundPhase::kDetectTakeoff) {
    const std::optional<double> h = tofMeasuredHeight(ekf_.state().w_q_b, tof.range_m, params_.tof_offset_m);
    if (h) mode_.addTof(t, *h + params_.floor_z_m - params_.ground_z_m);
  }
  if (!initialized_ || !ready_ || start_.active()) {
    ++summary_.n_tof_not_ready;
    return;
  }
  t_last_event_ = std::max(t_last_event_, t);
  summary_.end_t_s = t_last_event_;
  if (!imu_mode_ || t - t_pred_ >= params_.update_predict_dt_s) predictTo(t);
  propagate(!imu_mode_);
  // the gate opens when no ToF was accepted for max_lost_s (start, or a height that drifted off under TDoA)
  tof_opt_.gate_sigma = t - t_last_tof_accept_ > params_.max_lost_s ? 0.0 : params_.tof_gate_sigma;
  const TofUpdateResult r = updateTof(ekf_, tof.range_m, tof_opt_);
  switch (r.outcome) {
    case UpdateOutcome::kApplied:
      ++summary_.n_tof_used;
      t_last_tof_accept_ = t;
      break;
    case UpdateOutcome::kRejectedOutlier: ++summary_.n_tof_rejected; break;
    case UpdateOutcome::kDegenerate: ++summary_.n_tof_tilted; break;
    default: ++summary_.n_tof_invalid; break;
  }
}

CooperativeRangeResult Estimator::addNeighbourRange(double t_s, const Moments3& neighbour, double range_m,
                                                   const CooperativeRangeOptions& options) {
  ++summary_.n_coop_total;
  if (!initialized_ || !ready_ || start_.active() || phase_ == FlightPhase::kAcquisition) {
    ++summary_.n_coop_not_ready;
    return {};
  }
  t_last_event_ = std::max(t_last_event_, t_s);
  summary_.end_t_s = t_last_event_;
  if (!imu_mode_ || t_s - t_pred_ >= params_.update_predict_dt_s) predictTo(t_s);
  propagate(true);  // (G21) the CI weight reads the current P
  const CooperativeRangeResult r = updateCooperativeRange(ekf_, neighbour, range_m, options);
  switch (r.outcome) {
    case UpdateOutcome::kApplied:
      ++summary_.n_coop_used;
      summary_.coop_omega_sum += r.omega;
      t_last_accept_ = t_s;  // (F16k) a range to a neighbour fixes the position too: not lost
      break;
    case UpdateOutcome::kRejectedOutlier: ++summary_.n_coop_rejected; break;
    default: ++summary_.n_coop_not_ready; break;
  }
  return r;
}

void Estimator::addTdoa(const TdoaMeasurement& z) {
  ++summary_.n_tdoa_total;
  last_tdoa_ = TdoaUpdateResult{};
  last_tdoa_in_flight_ = false;
  // (F31) a TDoA longer than its anchor pair's baseline (or not finite) is no range difference: skipped
  if (!checkTdoaRange(z, anchors_, summary_.sensor_range)) return;
  const double t = z.t_s;
  if (!advanceToTdoa(t)) return;
  // (F16i) a landing's floor window that finds no fix within landing_fix_max_s ends: the TDoA are used again
  if (landing_fix_ && t - t_landing_fix_s_ > params_.landing_fix_max_s) endLandingFix();
  if (start_.active()) {
    collectStartTdoa(z);
    return;
  }
  if (phase_ == FlightPhase::kAcquisition && t >= t_acq_end_)
    phase_ = on_ground_ ? (moved_ ? FlightPhase::kLanded : FlightPhase::kGround) : FlightPhase::kTracking;
  propagate(!imu_mode_);
  const bool acquiring = phase_ == FlightPhase::kAcquisition;
  // (F14) TDoA near the floor carry the large floor-level bias: down-weighted on the ground and just above it
  const bool near_floor = on_ground_ || ekf_.state().w_p_b.z() - params_.ground_z_m < params_.low_flight_m;
  const TdoaUpdateOptions& opt = acquiring ? acq_opt_ : (near_floor ? rest_opt_ : track_opt_);
  PairOffset* po = nullptr;
  const TdoaMeasurement zc = correctedTdoa(z, acquiring, &po);
  if (imu_mode_ && ready_ && params_.ground_phase == GroundPhase::kDetectTakeoff) superviseTdoa(t, z);
  if (antenna_) {
    antenna_->advance(t);
    antenna_predicted_ = false;
  }
  const BiasPredictor* predictor = antenna_ ? &corrections_ : (bias_ ? &bias_ : nullptr);
  // (F23c) the residual without the filter's range-bias states, at the prior tag position
  const bool levels = bias_level_ || raw_level_;
  const double range_bias_prior_m = levels && ekf_.rangeBias() ? ekf_.rangeBiasDifference(z.id_a, z.id_b) : 0.0;
  const Vec3 w_p_tag_prior = levels ? Vec3(ekf_.state().w_p_b + ekf_.state().w_q_b * params_.b_t_tag) : Vec3::Zero();
  const TdoaUpdateResult r = updateTdoa(ekf_, anchors_, zc, opt, predictor);
  last_tdoa_ = r;
  learnFromInnovation(t, r, acquiring, near_floor, po);
  countTdoaOutcome(t, r, acquiring, near_floor);
  // (F30) in the air only: on and near the floor the TDoA carry the floor-level bias (F14), which their σ there covers
  const bool gated = r.outcome == UpdateOutcome::kApplied || r.outcome == UpdateOutcome::kRejectedOutlier;
  if (!acquiring && !near_floor && gated) checkConsistency(t, r.nis);
  // in flight only: on and near the floor the TDoA carry the floor-level bias (F14), and a body at rest or in ground
  // contact (F18: still, or shaking on the legs) is not flying even before the ground phase is entered
  const bool flying = !acquiring && !near_floor &&
                      std::min(t - t_acq_end_, t - t_left_ground_) >= params_.rejection_settle_s &&
                      ekf_.state().w_p_b.z() - params_.ground_z_m > params_.rejection_min_height_m &&
                      !(imu_mode_ && (rest_.stillNow() || mode_.shakingStandsOut(rest_.gyroHighPassMeanSquare())));
  last_tdoa_in_flight_ = flying;
  if (flying && gated) trackRejectionRate(t, r);
  if (levels) feedBiasLevels(t, z, r, flying, range_bias_prior_m, w_p_tag_prior);
  notePairInView(t, z, r);
  superviseTracking(t, acquiring);
}

bool Estimator::advanceToTdoa(double t) {
  if (!initialized_) {
    if (imu_mode_) {
      ++summary_.n_tdoa_before_imu;
      return false;
    }
    summary_.start_t_s = t;
    t_last_event_ = t;
    initialize(t, Vec3(0, 0, kGravity_mps2), false);
  }
  if (t < t_pred_ - params_.max_gap_s) {
    if (imu_mode_) {
      ++summary_.n_tdoa_out_of_order;  // the IMU clock leads; a backward jump of the IMU re-bases the time (F17)
      return false;
    }
    handleTimeJump(t, t - t_pred_);
  }
  if (imu_mode_ && t - t_pred_ > params_.max_integration_gap_s) {
    // (F17) the IMU stream stopped (dropout or a clock jump seen first here): nothing is integrated across the gap
    handleTimeJump(t, t - t_pred_);
    t_last_imu_ = t;
  }
  if (!imu_mode_ && t - t_pred_ > params_.max_integration_gap_s * 4.0) handleTimeJump(t, t - t_pred_);
  t_last_event_ = std::max(t_last_event_, t);
  summary_.end_t_s = t_last_event_;
  // (F17) the nominal state is brought to the measurement time only when it lags by more than update_predict_dt_s
  if (!imu_mode_ || t - t_pred_ >= params_.update_predict_dt_s) predictTo(t);
  return true;
}

void Estimator::collectStartTdoa(const TdoaMeasurement& z) {
  // (F16) collecting the multilateration batch; the displacement comes from the prediction
  const double t = z.t_s;
  ++summary_.n_tdoa_start;
  propagate(!imu_mode_);
  const std::optional<double> floor_z =
      on_ground_ && params_.floor_constraint ? std::optional<double>(params_.ground_z_m) : std::nullopt;
  if (replay_.recording()) replay_.recordTdoa(z);
  // (F16j) floor contact before the first fix may be refuted by the TDoA; rest (motors off) is not
  // (F29e) and so is floor contact at a floor check
  const bool floor_refutable = floor_z && ((!ready_ && t_last_rest_ < t_entered_ground_) || floor_check_);
  if (const std::optional<StartFix> fix = start_.add(z, ekf_.state(), floor_z, floor_refutable)) {
    propagate(true);
    if (floor_check_) finishFloorCheck(t, *fix);
    else if (landing_fix_) finishLandingFix(*fix);
    else finishStart(t, *fix);
  } else if (replay_.recording() && start_.referenceTime() != replay_.referenceTime()) {
    replay_.begin(ekf_, start_.referenceTime());  // (F16b) a failed solve moved the reference to now
  }
}

TdoaMeasurement Estimator::correctedTdoa(const TdoaMeasurement& z, bool acquiring, PairOffset** po) {
  // (F19) optional per-pair offset learned from the innovations while tracking
  TdoaMeasurement zc = z;
  if (!pair_offsets_.empty() && z.id_a >= 0 && z.id_b >= 0 && z.id_a < kMaxPairId && z.id_b < kMaxPairId) {
    *po = &pair_offsets_[z.id_a * kMaxPairId + z.id_b];
    zc.tdoa_m -= (*po)->offset_m;
  }
  // (F16f) on the ground the floor-level anchors are seen with the delays the start on the floor found; after the
  // ground evidence ended without a climb, they fade with the height dead-reckoned from the floor
  if (floor_anchors_.hasDelays() && (on_ground_ || climb_.running())) {
    const double f = on_ground_ ? 1.0 : FloorLevelAnchors::remainingFraction(climb_.height());
    zc.tdoa_m -= f * floor_anchors_.pairDelay(z.id_a, z.id_b);
  } else if (floor_anchors_.hasDelays() && !acquiring && z.t_s - t_last_descent_ < params_.landing_window_s &&
             ekf_.state().w_p_b.z() - params_.ground_z_m < params_.landing_band_m) {
    // (F16h) near the floor after a descent (a landing): the delay or none, whichever the TDoA lies nearer to
    const Moments3* a = anchors_.find(z.id_a);
    const Moments3* b = anchors_.find(z.id_b);
    if (a && b && floor_anchors_.pairDelay(z.id_a, z.id_b) != 0.0) {  // a pair without floor-level anchors: no delay
      const NavState& x = ekf_.state();
      const double r = zc.tdoa_m - predictTdoa(x.w_p_b, x.w_q_b, params_.b_t_tag, a->m, b->m);
      zc.tdoa_m -= floor_anchors_.nearerPairDelay(z.id_a, z.id_b, r);
    }
  }
  return zc;
}

void Estimator::learnFromInnovation(double t, const TdoaUpdateResult& r, bool acquiring, bool near_floor,
                                    PairOffset* po) {
  if (antenna_ && antenna_predicted_ && !acquiring && !near_floor && t >= t_fix_settled_ &&
      r.outcome == UpdateOutcome::kApplied) {
    // (F25d) learned while tracking in the air only: near the floor the TDoA carry the ground bias (F14). The
    // robust weight of the update down-weights the same TDoA for the pattern.
    // The TDoA error is correlated in time (F12): the innovations carry far less than one independent sample each
    antenna_->learn(r.innovation_m, params_.antenna_bias_noise_scale * r.innovation_var_m2 / r.weight);
  }
  if (po && !acquiring && r.outcome == UpdateOutcome::kApplied) {
    // (F19) the pair's offset follows its weighted innovations
    const double dt_pair = std::isnan(po->t_last_s) ? 0.0 : std::min(t - po->t_last_s, 0.2);
    po->offset_m =
        std::clamp(po->offset_m + (dt_pair / params_.pair_bias_tau_s) * r.weight * r.innovation_m, -0.5, 0.5);
    po->t_last_s = t;
  }
}

void Estimator::countTdoaOutcome(double t, const TdoaUpdateResult& r, bool acquiring, bool near_floor) {
  switch (r.outcome) {
    case UpdateOutcome::kApplied:
      ++summary_.n_tdoa_used;
      if (near_floor && !acquiring) ++summary_.n_tdoa_used_at_rest;
      if (r.weight < 1.0) ++summary_.n_tdoa_downweighted;
      t_last_accept_ = t;
      n_rejected_streak_ = 0;
      break;
    case UpdateOutcome::kRejectedOutlier:
      ++summary_.n_tdoa_rejected;
      ++n_rejected_streak_;
      break;
    case UpdateOutcome::kUnknownAnchor: ++summary_.n_tdoa_unknown_anchor; break;
    default: ++summary_.n_tdoa_degenerate; break;
  }
}

void Estimator::trackRejectionRate(double t, const TdoaUpdateResult& r) {
  // (F16d) rejection rate in flight, exponentially forgotten over rejection_memory_s
  const double w =
      std::isnan(t_rejection_) ? 0.0 : std::exp(-std::max(t - t_rejection_, 0.0) / params_.rejection_memory_s);
  n_rejected_recent_ = w * n_rejected_recent_ + (r.outcome == UpdateOutcome::kRejectedOutlier ? 1.0 : 0.0);
  n_gated_recent_ = w * n_gated_recent_ + 1.0;
  t_rejection_ = t;
  // (F16d) the recent motion while the TDoA agree, to fall back on when a fault is found
  if (n_rejected_recent_ <= params_.healthy_rejection_rate * n_gated_recent_ &&
      t - t_healthy_sample_ >= params_.healthy_period_s) {
    healthy_[i_healthy_] = {t, ekf_.state().w_p_b, ekf_.state().w_v_b};
    i_healthy_ = (i_healthy_ + 1) % healthy_.size();
    n_healthy_ = std::min(n_healthy_ + 1, healthy_.size());
    t_healthy_sample_ = t;
  }
}

void Estimator::feedBiasLevels(double t, const TdoaMeasurement& z, const TdoaUpdateResult& r, bool flying,
                               double range_bias_prior_m, const Vec3& w_p_tag_prior) {
  // (F23c) a bias level from the TDoA used in flight; elsewhere (the floor-level bias on and near the ground, an
  // acquisition's unsettled state) the open window is dropped. Returns whether a window was counted.
  const Moments3* anchor_a = anchors_.find(z.id_a);
  const Moments3* anchor_b = anchors_.find(z.id_b);
  const auto feed = [&](BiasLevel& level, double residual_m) {
    const int n_before = level.numWindows();
    if (flying && r.outcome == UpdateOutcome::kApplied && anchor_a && anchor_b)
      level.add(t, z.id_a, anchor_a->m, z.id_b, anchor_b->m, w_p_tag_prior, residual_m);
    else if (!flying)
      level.interrupt();
    return level.numWindows() != n_before;
  };
  if (bias_level_ && feed(*bias_level_, r.innovation_m + range_bias_prior_m)) {
    summary_.n_bias_level_windows = static_cast<std::size_t>(bias_level_->numWindows());
    summary_.bias_level_m = bias_level_->pairLevel(params_.output_bias_level_m);
  }
  // (F24c) the statistic on the model's own mean, over the same windows as the uncorrected level below
  if (mean_level_) feed(*mean_level_, last_model_mean_m_);
  // (F24b) the same statistic on the TDoA before the model's correction (bias_mean_m is what it subtracted)
  if (raw_level_ && feed(*raw_level_, r.innovation_m + range_bias_prior_m + r.bias_mean_m)) updateModelMeanScale();
}

void Estimator::notePairInView(double t, const TdoaMeasurement& z, const TdoaUpdateResult& r) {
  if (r.outcome == UpdateOutcome::kApplied || r.outcome == UpdateOutcome::kRejectedOutlier) {
    // anchor pairs in view, for the reported bias floor (F23)
    auto it = std::find_if(recent_pairs_.begin(), recent_pairs_.end(),
                           [&](const RecentPair& p) { return p.id_a == z.id_a && p.id_b == z.id_b; });
    if (it != recent_pairs_.end()) it->t_s = t;
    else if (recent_pairs_.size() < recent_pairs_.capacity()) recent_pairs_.push_back({z.id_a, z.id_b, t});
  }
  // (F23) the geometry term changes slowly with the position and the pairs in view: refreshed every 50 ms of TDoA
  if (!(t - t_bias_floor_s_ < params_.bias_floor_period_s && t >= t_bias_floor_s_)) {
    bias_floor_ = biasFloor();
    t_bias_floor_s_ = t;
  }
}

void Estimator::superviseTracking(double t, bool acquiring) {
  // (F16) lost: nothing accepted for max_lost_s → find the position again by multilateration from fresh TDoA
  // (F16d) most TDoA rejected in flight: the stream is faulty or the estimate is off; the few that pass the gate
  // (which widens as P grows) would drag the state away, so the position is found again from fresh TDoA at once
  const bool rejecting = params_.max_rejection_rate < 1.0 && n_gated_recent_ >= params_.rejection_min_samples &&
                         n_rejected_recent_ > params_.max_rejection_rate * n_gated_recent_;
  const bool nothing_accepted = t - t_last_accept_ > params_.max_lost_s &&
                                n_rejected_streak_ > static_cast<std::size_t>(params_.lost_min_rejections);
  // (F16k) only TDoA of at least four anchors can fix a position again: with fewer in view (an occluded tag) a
  // re-acquisition would wait for a fix that cannot come, so the filter keeps tracking and its gate takes them back
  if (!acquiring && (rejecting || nothing_accepted) &&
      anchorsHeard(params_.recent_pair_window_s) >= minFixAnchors(false)) {
    if (rejecting) {
      ++summary_.n_rejection_faults;
      revertToHealthyMotion(t);
    }
    startAcquisition(t, true);
    t_last_accept_ = t;
    n_rejected_streak_ = 0;
  }
}

void Estimator::checkConsistency(double t_s, double nis) {
  // (F30) the TDoA's normalised innovation squared, clipped and averaged over params_.nis_window_s
  const double w = t_s >= t_nis_ ? expNegative((t_s - t_nis_) / params_.nis_window_s) : 1.0;
  const double dt = t_s > t_nis_ && t_nis_ > -1e299 ? std::min(t_s - t_nis_, 0.1) : 0.0;
  t_nis_ = std::max(t_nis_, t_s);
  nis_sum_ = w * nis_sum_ + std::min(std::isfinite(nis) ? nis : params_.nis_clip, params_.nis_clip);
  nis_n_ = w * nis_n_ + 1.0;
  nis_far_ = w * nis_far_ + (std::isfinite(nis) && nis <= params_.nis_far ? 0.0 : 1.0);
  // the bulk of the TDoA disagrees: not a few pairs out of line of sight (those the gate and the robust loss take)
  const bool beyond = nis_n_ >= params_.nis_min_samples && nis_far_ > params_.nis_max_far_fraction * nis_n_;
  // (F30) the widening of the reported band fades with params_.widening_fade_s once the TDoA agree again
  consistency_var_m2_ *= t_s > t_consistency_var_ ? expNegative((t_s - t_consistency_var_) / params_.widening_fade_s) : 1.0;
  t_consistency_var_ = std::max(t_consistency_var_, t_s);
  if (!beyond) {
    t_consistent_ = t_s;
    inconsistent_ = false;
    return;
  }
  if (t_s - t_consistent_ < params_.inconsistent_hold_s) return;
  // beyond chance for params_.inconsistent_hold_s: the estimate or its covariance is wrong, whatever the cause
  if (!inconsistent_) ++summary_.n_inconsistent_periods;
  inconsistent_ = true;
  summary_.inconsistent_s += dt;
  // the reported band is widened until the TDoA's spread is explained: the excess of the mean NIS over 1 in the
  // TDoA's variance, at most params_.max_widening_m. The filter's own P is left alone: widening it lets the faulty or
  // non-line-of-sight TDoA in that made the mean large (0426-traj12: 0.262 → 0.494 m) and hides a clock offset
  // from the checks after the run.
  const double excess = std::max(nis_sum_ / nis_n_ - 1.0, 0.0);
  const double sigma = std::min(std::sqrt(excess) * track_opt_.sigma_m, params_.max_widening_m);
  if (sigma * sigma > consistency_var_m2_) {
    if (consistency_var_m2_ == 0.0 || t_s - t_last_widening_ >= params_.inconsistent_hold_s) ++summary_.n_consistency_widenings;
    consistency_var_m2_ = sigma * sigma;
    t_last_widening_ = t_s;
  }
}

void Estimator::superviseTdoa(double t_s, const TdoaMeasurement& z) {
  // (F29c) the height at which this TDoA puts the tag: its residual at the estimate over its vertical sensitivity, as
  // a TDoA in the air and as one on the floor (with the floor-level anchors' delays, F16f)
  const Moments3* a = anchors_.find(z.id_a);
  const Moments3* b = anchors_.find(z.id_b);
  if (!a || !b) return;
  const NavState& x = ekf_.state();
  TdoaJacobians J;
  const std::optional<double> h = evaluateTdoa(x.w_p_b, x.w_q_b, a->m, b->m, tdoa_model_, &J);
  if (!h) return;
  const double r_air = z.tdoa_m - *h;
  const double floor_delay = floor_anchors_.hasDelays() ? floor_anchors_.pairDelay(z.id_a, z.id_b) : 0.0;
  mode_.addTdoa(t_s, r_air, r_air - floor_delay, J.J_z_p_b(2), x.w_p_b.z() - params_.ground_z_m);
}

void Estimator::revertToHealthyMotion(double t_s) {
  // (F16d) the TDoA that passed the gate since the fault began pulled the state off (the rate needs ≈ 0.5 s to cross
  // its threshold): back to the newest motion recorded params_.revert_lead_s before, carried to now by the relaxed motion
  // of F16e, with the covariance grown meanwhile plus that motion's own uncertainty
  const PastMotion* best = nullptr;
  for (std::size_t k = 0; k < n_healthy_; ++k) {
    const PastMotion& m = healthy_[k];
    if (m.t_s <= t_s - params_.revert_lead_s && t_s - m.t_s <= params_.revert_max_age_s && (!best || m.t_s > best->t_s)) best = &m;
  }
  n_healthy_ = 0;
  if (!best || !(params_.lost_velocity_tau_s > 0.0)) return;
  // horizontally only, as F16e: the vertical channel keeps the thrust-axis IMU's and the TDoA's account
  const double tau = params_.lost_velocity_tau_s, dt = t_s - best->t_s;
  Eigen::Matrix<double, 6, 6> cov = ekf_.covariance().block<6, 6>(kPos, kPos);
  const double reach = best->w_v_b.head<2>().norm() * std::min(dt, tau);
  cov(0, 0) += reach * reach;
  cov(1, 1) += reach * reach;
  Vec3 p = ekf_.state().w_p_b, v = ekf_.state().w_v_b;
  relaxHorizontal(best->w_p_b, best->w_v_b, dt, tau, &p, &v);
  ekf_.resetPositionVelocity(p, v, cov);
  ++summary_.n_reverted_motion;
}

void Estimator::alignHeading(double t_s, const ImuReading& imu, double dt_s) {
  // (F28) windows run while tracking in flight only: on the ground the heading is the convention's (F15), and a
  // start or re-acquisition changes the velocity the increments count from
  const bool tracking = params_.heading_alignment && imu_mode_ && ready_ && !on_ground_ &&
                        phase_ == FlightPhase::kTracking && !start_.active();
  if (!tracking) {
    heading_align_.reset();
    return;
  }
  const NavState& x = ekf_.state();
  // the thrust axis only, as the flight's accelerometer model (F3): the x/y readings carry vibration, and the drag
  // they also carry is modelled from the velocity (F28a′)
  Vec3 f = imu.b_acc_mps2 - x.b_acc_bias;
  f.head<2>().setZero();
  heading_align_.add(t_s, f, imu.b_gyro_radps - x.b_gyro_bias, dt_s, x.w_v_b);
  if (!heading_align_.complete()) return;
  const std::optional<InMotionAlignment::Result> r = heading_align_.solve();
  heading_align_.reset();
  if (!r) return;
  const double change = wrapAngle(headingOf(r->w_q_b) - headingOf(x.w_q_b));
  if (!(r->heading_sigma_rad < params_.max_aligned_heading_sigma_rad)) return;
  predictTo(t_s);
  propagate(true);
  // the filter's own heading variance: the heading's row on the body-frame attitude covariance
  const Eigen::RowVector3d row = headingJacobian(ekf_.state().w_q_b);
  const double filter_var = (row * ekf_.covariance().block<3, 3>(kAtt, kAtt) * row.transpose())(0, 0);
  const double sigma = std::sqrt(r->heading_sigma_rad * r->heading_sigma_rad + filter_var);
  if (std::abs(change) < std::max(3.0 * sigma, params_.min_heading_change_rad)) {
    // consistent with the filter: a heading measurement (F28)
    ekf_.headingUpdate(headingOf(r->w_q_b), r->heading_sigma_rad);
    return;
  }
  // the window's evidence contradicts the filter's heading: its attitude, with the fit's uncertainty
  const double tilt = std::max(r->tilt_sigma_rad, params_.min_aligned_tilt_sigma_rad);
  const double heading = std::max(r->heading_sigma_rad, params_.min_aligned_tilt_sigma_rad);
  ekf_.resetAttitude(r->w_q_b, Vec3(tilt * tilt, tilt * tilt, heading * heading).asDiagonal());
  ++summary_.n_heading_alignments;
  if (summary_.heading_alignment_t_s.size() < kMaxListedEvents) {
    summary_.heading_alignment_t_s.push_back(t_s);
    summary_.heading_alignment_change_rad.push_back(change);
  }
}

Mat3 Estimator::reportedPositionCovariance() const {
  const Mat3 P = ekf_.covariance().block<3, 3>(kPos, kPos);
  const Mat3 widened = P + consistency_var_m2_ * Mat3::Identity();  // (F30)
  if (!(params_.output_bias_sigma_m > 0.0) || !ready_) return widened;
  return widened + bias_floor_;
}

int Estimator::anchorsHeard(double window_s) const {
  DistinctAnchors anchors;
  for (const RecentPair& rp : recent_pairs_)
    if (t_last_event_ - rp.t_s <= window_s) anchors.add(rp.id_a, rp.id_b);
  return anchors.count();
}

Mat3 Estimator::biasFloor() const {
  // (F23) a slowly varying range bias per anchor of the pairs seen recently, pair std σ_b, moves the least-squares
  // position; its covariance is added to the reported one
  const NavState& x = ekf_.state();
  BiasFloorGeometry g(x.w_p_b + x.w_q_b * params_.b_t_tag);
  for (const RecentPair& rp : recent_pairs_) {
    if (t_last_event_ - rp.t_s > params_.recent_pair_window_s) continue;
    const Moments3* a = anchors_.find(rp.id_a);
    const Moments3* b = anchors_.find(rp.id_b);
    if (a && b) g.addPair(rp.id_a, a->m, rp.id_b, b->m);
  }
  // on the floor the height is known (F22) and the TDoA carry the floor-level bias, for which the filter's own TDoA σ
  // on the ground stands (F14): the bias moves the horizontal position only (F23′)
  if (on_ground_ && params_.floor_constraint) {
    const double s = std::max(params_.rest_tdoa_sigma_m, outputBiasSigma());
    Mat3 C = Mat3::Zero();
    C.topLeftCorner<2, 2>() = g.horizontalCovariance(s);
    C(2, 2) = params_.ground_height_sigma_m * params_.ground_height_sigma_m;  // the body's height on the floor, not the repeated updates'
    return C;
  }
  // (F23e) in flight with the downward range fused recently, the height is the ToF's: the TDoA bias moves the
  // horizontal position at the height the ToF holds, and the height's σ is the filter's own
  if (params_.fuse_tof && t_last_event_ - t_last_tof_accept_ <= params_.recent_pair_window_s) {
    Mat3 C = Mat3::Zero();
    C.topLeftCorner<2, 2>() = g.horizontalCovariance(outputBiasSigma());
    return C;
  }
  // (F23d) in flight, the vertical part of the bias-induced position error scaled: C ← S C S, S = diag(1, 1, s)
  Mat3 C = g.covariance(outputBiasSigma());
  const double s = params_.output_bias_vertical_scale;
  C.row(2) *= s;
  C.col(2) *= s;
  return C;
}

void Estimator::updateModelMeanScale() {
  // (F24b) ρ = the flight's uncorrected level / the model's training level, both pair levels √(2σ_a²); the estimate
  // starts from the training level (ρ = 1, the model as trained) and follows the flight's windows
  const double train = params_.bias_model_training_level_m;
  const double level = raw_level_->pairLevel(train > 0.0 ? train : params_.output_bias_level_m);
  summary_.raw_bias_level_m = level;
  if (!model_bias_) return;
  double rho = level / train;
  if (mean_level_) {
    // (F24c) ρ = (ℓ / ℓ_train) / (ℓ_µ / ℓ_µ,train): the flight's level against the model's training flights,
    // relative to what the model itself predicts here against there; ℓ_µ starts from ℓ_µ,train
    const double mean_train = params_.bias_model_training_mean_level_m;
    const double mean_level = mean_level_->pairLevel(mean_train);
    summary_.model_mean_level_m = mean_level;
    if (mean_level > 0.0) rho *= mean_train / mean_level;
  }
  model_mean_scale_ = std::pow(std::min(1.0, rho), params_.bias_model_level_exponent);
  if (params_.bias_model_level_variance) {
    // (F24e) gp.md P43c with the levels so far
    model_level_variance_m2_ =
        levelExcessVariance(level, mean_level_ ? summary_.model_mean_level_m : 0.0, train,
                            params_.bias_model_training_mean_level_m);
    summary_.bias_model_level_variance_m2 = model_level_variance_m2_;
  }
  summary_.bias_model_mean_scale = model_mean_scale_;
  summary_.min_bias_model_mean_scale = std::min(summary_.min_bias_model_mean_scale, model_mean_scale_);
}

double Estimator::outputBiasSigma() const {
  if (!bias_level_) return params_.output_bias_sigma_m;
  // (F23c) σ_b = output_bias_sigma_m max(1, σ̂_a / σ_a,ref), σ_a,ref² = output_bias_level_m² / 2: a flight whose
  // measured level exceeds the reference widens the band; a lower one does not narrow it (what no position explains
  // is seen, what a position shift absorbs is not)
  const double ref_a2 = 0.5 * params_.output_bias_level_m * params_.output_bias_level_m;
  return params_.output_bias_sigma_m * std::max(1.0, std::sqrt(bias_level_->sigmaA2(ref_a2) / ref_a2));
}

LocalizerEstimate Estimator::estimate() const {
  LocalizerEstimate e;
  e.t_s = t_last_event_;
  e.x = ekf_.state();
  e.phase = phase_;
  e.mode_status = mode_.status() | (inconsistent_ ? kInconsistent : 0u);
  e.n_tdoa_used_at_rest = summary_.n_tdoa_used_at_rest;
  const ErrMat& P = ekf_.covariance();
  e.cov_pose.block<3, 3>(0, 0) = reportedPositionCovariance();
  e.cov_pose.block<3, 3>(0, 3) = P.block<3, 3>(kPos, kAtt);
  e.cov_pose.block<3, 3>(3, 0) = P.block<3, 3>(kAtt, kPos);
  e.cov_pose.block<3, 3>(3, 3) = P.block<3, 3>(kAtt, kAtt);
  e.sigma_p_m = e.cov_pose.diagonal().head<3>().cwiseMax(0.0).cwiseSqrt();
  e.sigma_v_mps = P.diagonal().segment<3>(kVel).cwiseMax(0.0).cwiseSqrt();
  return e;
}

}  // namespace uwb
