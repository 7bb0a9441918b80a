/** @file TdoaLocalizer.cpp
 *  @brief The estimator's event loop: docs/math/filter.md F14–F18 (ground phase, take-off, start by
 *         multilateration, acquisition, gating/robust tracking, re-acquisition, landing, TDoA-only mode).
 */
#include "uwb/filter/TdoaLocalizer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "uwb/filter/Multilateration.h"
#include "uwb/filter/TofUpdate.h"

namespace uwb {
namespace {

/// Roll and pitch from a specific-force reading at rest, yaw = 0 (F15).
Quat levelFromGravity(const Vec3& b_acc) {
  const double roll = std::atan2(b_acc.y(), b_acc.z());
  const double pitch = std::atan2(-b_acc.x(), std::sqrt(b_acc.y() * b_acc.y() + b_acc.z() * b_acc.z()));
  return Quat(Eigen::AngleAxisd(pitch, Vec3::UnitY()) * Eigen::AngleAxisd(roll, Vec3::UnitX()));
}

/// exp(−x) for x ≥ 0, the per-IMU-sample decay factors exp(−Δt/τ) of the stillness EMA (F18) and the take-off leak
/// (F15). Below 0.1 (every IMU step: Δt/τ ≤ 0.02 at 1 kHz) a Taylor series truncated after the x⁹ term, whose
/// successor is below 3e-17, under double rounding (1.1e-16): std::exp's value to rounding at a fraction of its cost
/// (the IMU Δt jitters, so caching the factor per Δt rarely hits). Evaluated in Estrin's scheme (pairs, then powers
/// x², x⁴, x⁸) rather than Horner's: four dependent multiply-adds instead of nine, since this sits on the
/// per-sample dependency chain of the EMA.
double expNegative(double x) {
  if (!(x < 0.1)) return std::exp(-x);
  const double x2 = x * x, x4 = x2 * x2, x8 = x4 * x4;
  const double p01 = 1.0 - x, p23 = 1.0 / 2.0 - x * (1.0 / 6.0), p45 = 1.0 / 24.0 - x * (1.0 / 120.0),
               p67 = 1.0 / 720.0 - x * (1.0 / 5040.0), p89 = 1.0 / 40320.0 - x * (1.0 / 362880.0);
  return (p01 + x2 * p23) + x4 * (p45 + x2 * p67) + x8 * p89;
}

Vec3 sqrtDiag(const ErrMat& P) { return P.diagonal().segment<3>(kPos).cwiseMax(0.0).cwiseSqrt(); }

/// Constant time of the take-off detector's leaky vertical-velocity integrator [s] (F15).
constexpr double kTakeoffLeak_s = 1.0;
/// Zero-velocity updates on the ground at this period [s] and std [m/s] (F14).
constexpr double kZuptPeriod_s = 0.01;
constexpr double kZuptSigma_mps = 0.02;
/// Multilateration window after take-off / at the start [s], and the minimum number of TDoAs (F16).
constexpr double kMlatWindow_s = 0.6;
constexpr std::size_t kMlatMinSamples = 40;
constexpr double kMlatMaxWindow_s = 3.0;
/// Stillness (motors off): acc std and gyro rms thresholds, EMA time constant (F18).
constexpr double kStillAccStd_mps2 = 0.12;
constexpr double kStillGyro_radps = 0.03;
constexpr double kStillTau_s = 0.1;
/// 1/τ of the stillness EMA [1/s] (exactly 10 in double): the decay exponent Δt/τ as a product, off the division's
/// latency on the per-sample chain.
constexpr double kStillRate_per_s = 1.0 / kStillTau_s;
/// The stillness thresholds compared with the EMA statistics as squares (acc variance, gyro mean square): no sqrt.
constexpr double kStillAccVar_m2ps4 = kStillAccStd_mps2 * kStillAccStd_mps2;
constexpr double kStillGyroMs_rad2ps2 = kStillGyro_radps * kStillGyro_radps;
/// Touchdown: high-passed gyro rms above this [rad/s] (≈40 °/s; flight vibration is 3–10 °/s) (F18).
constexpr double kTouchdownGyro_radps = 0.45;
constexpr double kTouchdownGyroMs_rad2ps2 = kTouchdownGyro_radps * kTouchdownGyro_radps;
/// Landing "slow" test (F18): |v| below this [m/s], compared as a square.
constexpr double kLandingSpeed_mps = 0.25;
/// Touchdown: the height test uses the lowest estimate of this recent window [s], sampled every 10 ms (F18):
/// on ground contact the estimate can run away upwards (biased TDoA are gated, the thrust model integrates the
/// contact force) before the vibration burst is seen.
constexpr int kTouchdownHistory = 150;
constexpr double kTouchdownHistoryPeriod_s = 0.01;

}  // namespace

TdoaLocalizer::TdoaLocalizer(const EkfParams& params, AnchorTable anchors, BiasPredictor bias)
    : params_(params), anchors_(std::move(anchors)), bias_(std::move(bias)) {
  params_.validate();
  if (anchors_.size() < 4) throw std::invalid_argument("TdoaLocalizer: at least 4 anchors are needed");
}

LocalizerResult TdoaLocalizer::run(const SensorLog& input, double output_period_s) const {
  LocalizerResult result;
  LocalizerSummary& sum = result.summary;
  // (F17) streams cleaned and merged; the input is copied only when it needs cleaning, and the merged sequence is
  // walked by a cursor over the clean streams instead of being stored
  SensorLog cleaned;
  const std::optional<MergeReport> clean_report = cleanSensorLogReportIfClean(input, params_.max_gap_s);
  const bool input_clean = clean_report.has_value();
  if (!input_clean) cleaned = input;
  const SensorLog& log = input_clean ? input : cleaned;
  sum.merge = input_clean ? *clean_report : cleanSensorLog(cleaned, params_.max_gap_s);
  SensorEventCursor events(log);
  if (events.empty()) return result;

  EkfParams p = params_;
  const bool imu_mode = !log.imu.empty() && p.process_model == ProcessModel::kImu;
  if (!imu_mode) {
    if (p.process_model == ProcessModel::kImu) p.process_model = ProcessModel::kConstantVelocity;
    p.ground_phase = GroundPhase::kNone;
  }
  sum.process_model = p.process_model;
  sum.start_t_s = events.firstStamp();
  sum.end_t_s = events.lastStamp();
  const BiasPredictor* bias = bias_ ? &bias_ : nullptr;
  // emit() spaces the outputs by output_period_s (plus one forced at the end): reserve once, no regrowth
  const double n_out_max = output_period_s > 0.0 ? (sum.end_t_s - sum.start_t_s) / output_period_s + 2.0 : 0.0;
  result.estimates.reserve(output_period_s > 0.0 && n_out_max < static_cast<double>(events.size())
                               ? static_cast<std::size_t>(n_out_max)
                               : events.size() + 1);

  TdoaUpdateOptions track_opt;
  track_opt.sigma_m = p.tdoa_sigma_m;
  track_opt.gate_sigma = p.gate_sigma;
  track_opt.loss = p.robust_loss;
  track_opt.robust_k = p.robust_k;
  track_opt.robust_iterations = p.robust_iterations;
  track_opt.b_t_tag = p.b_t_tag;
  TdoaUpdateOptions acq_opt = track_opt;
  acq_opt.sigma_m = p.acquisition_tdoa_sigma_m;
  acq_opt.gate_sigma = 0.0;  // (F16) no gate while acquiring; the robust loss limits outliers
  if (acq_opt.loss == RobustLoss::kNone) acq_opt.loss = RobustLoss::kHuber;
  // (F21) optional ToF height updates
  TofUpdateOptions tof_opt;
  tof_opt.sigma_m = p.tof_sigma_m;
  tof_opt.offset_m = p.tof_offset_m;
  tof_opt.floor_z_m = p.floor_z_m;
  tof_opt.max_range_m = p.tof_max_range_m;
  double t_last_tof_accept = -1e300;

  // Anchor centroid: the starting guesses for multilateration.
  Vec3 centroid = Vec3::Zero();
  const std::vector<int> ids = anchors_.ids();
  for (int id : ids) centroid += anchors_.find(id)->m;
  centroid /= static_cast<double>(ids.size());
  Vec3 box_min = Vec3::Constant(1e300), box_max = Vec3::Constant(-1e300);
  for (int id : ids) {
    box_min = box_min.cwiseMin(anchors_.find(id)->m);
    box_max = box_max.cwiseMax(anchors_.find(id)->m);
  }

  Ekf ekf(p);
  FlightPhase phase = FlightPhase::kAcquisition;
  bool position_known = p.has_start_position;
  bool initialized = false;
  double t_pred = sum.start_t_s;
  double t_last_out = -1e300;
  double t_last_zupt = -1e300;
  double t_acq_end = -1e300;
  double t_last_accept = sum.start_t_s;
  std::size_t n_rejected_streak = 0;

  // IMU averaging (F17)
  Vec3 acc_sum = Vec3::Zero(), gyro_sum = Vec3::Zero();
  int n_imu_acc = 0;
  const ImuReading* last_imu = nullptr;  // the latest IMU sample (in `log`, not copied per sample)
  // initialisation window for levelling
  Vec3 init_acc_sum = Vec3::Zero(), init_gyro_sum = Vec3::Zero();
  int n_init = 0;
  double t_first_imu = std::numeric_limits<double>::quiet_NaN();
  // take-off detector (F15) and stillness detector (F18)
  double g_ref = kGravity_mps2;
  double v_det = 0.0;
  double t_last_imu = std::numeric_limits<double>::quiet_NaN();
  double acc_mean = kGravity_mps2, acc_var = 1.0, gyro_ms = 1.0, gyro_hp_ms = 0.0;
  Vec3 gyro_mean = Vec3::Zero();

  double z_takeoff = p.ground_z_m;
  double t_low_slow = std::numeric_limits<double>::quiet_NaN();
  // recent estimates (F18 touchdown): ring buffer of (t, p) every 10 ms while tracking
  struct RecentPosition {
    double t_s = 0.0;
    Vec3 w_p_b = Vec3::Zero();
  };
  std::vector<RecentPosition> recent(kTouchdownHistory);
  int n_recent = 0, i_recent = 0;
  double t_last_recent = -1e300;
  struct PairOffset {
    double offset_m = 0.0;
    double t_last_s = std::numeric_limits<double>::quiet_NaN();
  };
  std::vector<PairOffset> pair_offsets(p.pair_bias_tau_s > 0.0 ? 64 * 64 : 0);
  // multilateration buffer (F16)
  std::vector<MultilaterationSample> mlat;
  double t_mlat_start = std::numeric_limits<double>::quiet_NaN();
  double t_mlat_try = 0.0;
  Vec3 mlat_ref_p = Vec3::Zero();

  auto emit = [&](double t, bool force = false) {
    if (!force && t - t_last_out < output_period_s) return;
    LocalizerEstimate e;
    e.t_s = t;
    e.x = ekf.state();
    e.sigma_p_m = sqrtDiag(ekf.covariance());
    e.phase = phase;
    result.estimates.push_back(e);
    t_last_out = t;
  };

  auto predictTo = [&](double t) {
    const double dt = t - t_pred;
    if (!(dt > 0.0)) return;
    if (imu_mode) {
      ImuReading m = last_imu ? *last_imu : ImuReading{};
      if (n_imu_acc > 0) {
        m.b_acc_mps2 = acc_sum / n_imu_acc;
        m.b_gyro_radps = gyro_sum / n_imu_acc;
      }
      ekf.predict(m, dt);
    } else {
      ekf.predictTdoaOnly(dt);
    }
    acc_sum.setZero();
    gyro_sum.setZero();
    n_imu_acc = 0;
    t_pred = t;
    ++sum.n_predictions;
  };
  auto propagate = [&](bool force) {
    if (ekf.pendingDt() > 0.0 && (force || ekf.pendingDt() >= p.cov_period_s)) {
      ekf.propagateCovariance();
      ++sum.n_covariance_propagations;
    }
  };

  auto startFromPosition = [&](const Vec3& w_p_b, double sigma_m) {
    ekf.resetPosition(w_p_b, sigma_m);
    position_known = true;
  };

  auto enterGround = [&](FlightPhase ph) {
    phase = ph;
    if (imu_mode) ekf.setAccelModel(p.ground_accel_model);  // (F15)
    v_det = 0.0;
  };

  auto takeoff = [&](double t) {
    if (std::isnan(sum.takeoff_t_s)) sum.takeoff_t_s = t;
    ekf.setAccelModel(p.accel_model);
    // the climb that the detector saw becomes the vertical velocity (F15)
    ErrVec dx = ErrVec::Zero();
    dx(kVel + 2) = v_det - ekf.state().w_v_b.z();
    ekf.inject(dx);
    ekf.inflatePosition(0.0, 0.3);
    if (p.takeoff_acc_bias_sigma_mps2 > 0.0) {
      // (F20) the thrust-axis accelerometer bias in flight differs from the one learned on the ground
      ErrMat P = ekf.covariance();
      P(kAccBias + 2, kAccBias + 2) += p.takeoff_acc_bias_sigma_mps2 * p.takeoff_acc_bias_sigma_mps2;
      ekf.initialize(ekf.state(), P);
    }
    z_takeoff = ekf.state().w_p_b.z();
    t_low_slow = std::numeric_limits<double>::quiet_NaN();
    n_recent = 0;
    if (position_known) {
      phase = FlightPhase::kAcquisition;
      t_acq_end = t + 0.5 * p.acquisition_s;
    } else {
      phase = FlightPhase::kAcquisition;
      t_mlat_start = t;
      t_mlat_try = t;
      mlat_ref_p = ekf.state().w_p_b;
      mlat.clear();
    }
    t_last_accept = t;
  };

  auto finishMultilateration = [&](double t) -> bool {
    std::vector<Vec3> guesses = {Vec3(centroid.x(), centroid.y(), 0.5), Vec3(centroid.x(), centroid.y(), 1.5),
                                 Vec3(centroid.x(), centroid.y(), centroid.z())};
    const std::optional<MultilaterationResult> r = multilaterate(mlat, anchors_, p.b_t_tag, guesses);
    if (!r) return false;
    // a start outside the anchors' box (grown by 1 m) is a failed solve (ground-phase TDoA can still be off)
    if ((r->w_p0.array() < (box_min.array() - 1.0)).any() || (r->w_p0.array() > (box_max.array() + 1.0)).any())
      return false;
    const Vec3 d_now = ekf.state().w_p_b - mlat_ref_p;
    const double sigma = std::clamp(std::sqrt(r->covariance.trace()), 0.2, p.init_pos_sigma_m);
    startFromPosition(r->w_p0 + d_now, sigma);
    sum.start_w_p_b = r->w_p0;
    sum.start_rms_residual_m = r->rms_residual_m;
    // ground-phase outputs: the body sat at the take-off point
    for (LocalizerEstimate& e : result.estimates)
      if (e.phase == FlightPhase::kGround && e.t_s <= t_mlat_start) {
        e.x.w_p_b = r->w_p0;
        e.sigma_p_m = Vec3::Constant(sigma);
      }
    // the take-off height for landing detection; TDoA near the floor is poor, so not above ground_z + 0.2 m
    z_takeoff = std::min(r->w_p0.z(), p.ground_z_m + 0.2);
    t_acq_end = t + p.acquisition_s;
    mlat.clear();
    t_mlat_start = std::numeric_limits<double>::quiet_NaN();
    (void)t;
    return true;
  };

  auto initialize = [&](double t, const Vec3& acc_mean_b, const Vec3& gyro_mean_b) {
    NavState x0;
    x0.w_q_b = imu_mode ? levelFromGravity(acc_mean_b) : Quat::Identity();
    x0.w_p_b = p.has_start_position ? p.start_w_p_b : Vec3(centroid.x(), centroid.y(), p.ground_z_m);
    (void)gyro_mean_b;
    ErrMat P0 = initialCovariance(p);
    if (p.has_start_position) P0.block<3, 3>(kPos, kPos) = Mat3::Identity() * 0.05 * 0.05;
    ekf.initialize(x0, P0);
    g_ref = imu_mode ? acc_mean_b.norm() : kGravity_mps2;
    t_pred = t;
    initialized = true;
    if (imu_mode && p.ground_phase == GroundPhase::kDetectTakeoff) {
      enterGround(FlightPhase::kGround);
    } else if (p.has_start_position) {
      phase = FlightPhase::kAcquisition;
      t_acq_end = t + 0.5 * p.acquisition_s;
      if (imu_mode) ekf.setAccelModel(p.accel_model);
    } else {
      phase = FlightPhase::kAcquisition;
      t_mlat_start = t;
      t_mlat_try = t;
      mlat_ref_p = x0.w_p_b;
      if (imu_mode) ekf.setAccelModel(p.accel_model);
      if (!imu_mode) ekf.inflatePosition(0.0, 1.0);
    }
  };

  for (SensorEvent ev; events.next(ev);) {
    const double t = ev.t_s;
    if (ev.kind == SensorEvent::Kind::kImu) {
      if (!imu_mode) continue;
      const ImuReading& imu = log.imu[ev.index].imu;
      if (!initialized) {
        if (std::isnan(t_first_imu)) t_first_imu = t;
        init_acc_sum += imu.b_acc_mps2;
        init_gyro_sum += imu.b_gyro_radps;
        ++n_init;
        if (t - t_first_imu >= 0.1 || n_init >= 100) initialize(t, init_acc_sum / n_init, init_gyro_sum / n_init);
        last_imu = &imu;
        t_last_imu = t;
        continue;
      }
      const double dt_imu = std::isnan(t_last_imu) ? 0.0 : std::min(t - t_last_imu, 0.05);
      t_last_imu = t;
      last_imu = &imu;
      acc_sum += imu.b_acc_mps2;
      gyro_sum += imu.b_gyro_radps;
      ++n_imu_acc;
      // stillness statistics (F18)
      if (dt_imu > 0.0) {
        const double a = expNegative(dt_imu * kStillRate_per_s);
        const double an = imu.b_acc_mps2.norm();
        acc_mean = a * acc_mean + (1 - a) * an;
        acc_var = a * acc_var + (1 - a) * (an - acc_mean) * (an - acc_mean);
        gyro_ms = a * gyro_ms + (1 - a) * imu.b_gyro_radps.squaredNorm();
        gyro_mean = a * gyro_mean + (1 - a) * imu.b_gyro_radps;
        gyro_hp_ms = a * gyro_hp_ms + (1 - a) * (imu.b_gyro_radps - gyro_mean).squaredNorm();
      }
      const bool still = acc_var < kStillAccVar_m2ps4 && gyro_ms < kStillGyroMs_rad2ps2;
      if (phase == FlightPhase::kGround || phase == FlightPhase::kLanded) {
        // (F15) take-off detector: leaky integral of the vertical specific-force excess
        const double a_up = (ekf.state().w_q_b * imu.b_acc_mps2).z();
        if (dt_imu > 0.0) {
          v_det = expNegative(dt_imu / kTakeoffLeak_s) * v_det + dt_imu * (a_up - g_ref);
          if (still || v_det < 0.05) g_ref += (dt_imu / 2.0) * (a_up - g_ref);
        }
        // after a landing, a new take-off must climb twice as fast (touchdown bounces and spin-down are not flight)
        const double climb = phase == FlightPhase::kLanded ? 4.0 * p.takeoff_climb_mps : p.takeoff_climb_mps;
        if (v_det > climb && !still) {
          predictTo(t);
          propagate(true);
          takeoff(t);
        }
      }
      if (t - t_pred >= p.max_predict_dt_s) {
        predictTo(t);
        propagate(false);
      }
      if ((phase == FlightPhase::kGround || phase == FlightPhase::kLanded) && t - t_last_zupt >= kZuptPeriod_s) {
        predictTo(t);
        propagate(true);
        ekf.zeroVelocityUpdate(kZuptSigma_mps);  // (F14)
        t_last_zupt = t;
      }
      // landing (F18): nearly still, or low and slow for landing_hold_s
      if (phase == FlightPhase::kTracking && !std::isnan(sum.takeoff_t_s)) {
        const NavState& x = ekf.state();
        if (t - t_last_recent >= kTouchdownHistoryPeriod_s) {
          recent[i_recent] = {t, x.w_p_b};
          i_recent = (i_recent + 1) % kTouchdownHistory;
          n_recent = std::min(n_recent + 1, kTouchdownHistory);
          t_last_recent = t;
        }
        const bool low_slow = x.w_p_b.z() - z_takeoff < p.landing_height_m &&
                              x.w_v_b.squaredNorm() < kLandingSpeed_mps * kLandingSpeed_mps;
        // touchdown: the vibration burst of ground contact near the take-off height (F18); the height test uses
        // the lowest recent estimate, since on contact the estimate can already have run away upwards
        bool touchdown = false;
        int i_low = -1;
        if (gyro_hp_ms > kTouchdownGyroMs_rad2ps2) {
          for (int k = 0; k < n_recent; ++k)
            if (i_low < 0 || recent[k].w_p_b.z() < recent[i_low].w_p_b.z()) i_low = k;
          touchdown = i_low >= 0 && recent[i_low].w_p_b.z() - z_takeoff < 0.8;
        }
        if (touchdown) {
          // hold the position of the lowest recent estimate at the take-off height, and rewrite the outputs since
          // then (as the ground-phase outputs are rewritten after multilateration, F16)
          const double t_touch = recent[i_low].t_s;
          const Vec3 w_p_land(recent[i_low].w_p_b.x(), recent[i_low].w_p_b.y(), z_takeoff);
          ErrVec dx = ErrVec::Zero();
          dx.segment<3>(kPos) = w_p_land - x.w_p_b;
          dx.segment<3>(kVel) = -x.w_v_b;
          ekf.inject(dx);
          for (auto it = result.estimates.rbegin(); it != result.estimates.rend() && it->t_s >= t_touch; ++it) {
            it->x.w_p_b = w_p_land;
            it->x.w_v_b.setZero();
            it->phase = FlightPhase::kLanded;
          }
          n_recent = 0;
          sum.landing_t_s = t_touch;
          enterGround(FlightPhase::kLanded);
        } else if (still || low_slow) {
          if (std::isnan(t_low_slow)) t_low_slow = t;
          if (t - t_low_slow >= (still ? 0.3 : p.landing_hold_s)) {
            if (std::isnan(sum.landing_t_s) || sum.landing_t_s < sum.takeoff_t_s) sum.landing_t_s = t;
            enterGround(FlightPhase::kLanded);
          }
        } else {
          t_low_slow = std::numeric_limits<double>::quiet_NaN();
        }
      }
      emit(t);
      continue;
    }

    if (ev.kind == SensorEvent::Kind::kTof) {
      // ---- ToF event (F21) ----
      ++sum.n_tof_total;
      if (!p.fuse_tof) continue;
      const double range_m = log.tof[ev.index].range_m;
      if (!(std::isfinite(range_m) && range_m > 0.0 && range_m <= p.tof_max_range_m)) {
        ++sum.n_tof_invalid;
        continue;
      }
      if (!initialized || !position_known || !std::isnan(t_mlat_start) || phase == FlightPhase::kGround ||
          phase == FlightPhase::kLanded) {
        ++sum.n_tof_not_airborne;
        continue;
      }
      if (!imu_mode || t - t_pred >= p.update_predict_dt_s) predictTo(t);
      propagate(!imu_mode);
      // the gate opens when no ToF was accepted for max_lost_s (start, or a height that drifted off under TDoA)
      tof_opt.gate_sigma = t - t_last_tof_accept > p.max_lost_s ? 0.0 : p.tof_gate_sigma;
      const TofUpdateResult r = updateTof(ekf, range_m, tof_opt);
      switch (r.outcome) {
        case UpdateOutcome::kApplied:
          ++sum.n_tof_used;
          t_last_tof_accept = t;
          break;
        case UpdateOutcome::kRejectedOutlier: ++sum.n_tof_rejected; break;
        case UpdateOutcome::kDegenerate: ++sum.n_tof_tilted; break;
        default: ++sum.n_tof_invalid; break;
      }
      continue;
    }

    // ---- TDoA event ----
    const TdoaObservation& z = log.tdoa[ev.index];
    ++sum.n_tdoa_total;
    if (!initialized) {
      if (imu_mode) {
        ++sum.n_tdoa_ground;
        continue;
      }
      initialize(t, Vec3(0, 0, kGravity_mps2), Vec3::Zero());
    }
    // (F17) the nominal state is brought to the measurement time only when it lags by more than
    // update_predict_dt_s (Crazyflie-style: updates between predictions use the last predicted state)
    if (!imu_mode || t - t_pred >= p.update_predict_dt_s) predictTo(t);
    if (phase == FlightPhase::kGround || phase == FlightPhase::kLanded) {
      ++sum.n_tdoa_ground;
      emit(t);
      continue;
    }
    if (!std::isnan(t_mlat_start)) {
      // (F16) collecting the multilateration batch; the displacement comes from the prediction
      MultilaterationSample s;
      s.z = z;
      s.w_d_b = ekf.state().w_p_b - mlat_ref_p;
      s.w_q_b = ekf.state().w_q_b;
      mlat.push_back(s);
      ++sum.n_tdoa_ground;
      if (t - t_mlat_try >= kMlatWindow_s && mlat.size() >= kMlatMinSamples) {
        propagate(true);
        const bool ok = finishMultilateration(t);
        if (!ok) {
          // keep only the most recent half window and try again later (early samples are the worst)
          std::erase_if(mlat, [&](const MultilaterationSample& m) { return m.z.t_s < t - 0.5 * kMlatWindow_s; });
          t_mlat_try = t - 0.5 * kMlatWindow_s;
        }
        if (!ok && t - t_mlat_start > kMlatMaxWindow_s) {
          // give up: EKF acquisition from the centroid with a wide prior
          startFromPosition(Vec3(centroid.x(), centroid.y(), 1.0), p.init_pos_sigma_m);
          t_acq_end = t + 2.0 * p.acquisition_s;
          mlat.clear();
          t_mlat_start = std::numeric_limits<double>::quiet_NaN();
        }
        t_last_accept = t;
      }
      emit(t);
      continue;
    }
    if (phase == FlightPhase::kAcquisition && t >= t_acq_end) phase = FlightPhase::kTracking;
    propagate(!imu_mode);
    const bool acquiring = phase == FlightPhase::kAcquisition;
    // (F19) optional per-pair offset learned from the innovations while tracking
    TdoaObservation zc = z;
    PairOffset* po = nullptr;
    if (p.pair_bias_tau_s > 0.0 && z.id_a >= 0 && z.id_b >= 0 && z.id_a < 64 && z.id_b < 64) {
      po = &pair_offsets[z.id_a * 64 + z.id_b];
      zc.tdoa_m -= po->offset_m;
    }
    const TdoaUpdateResult r = updateTdoa(ekf, anchors_, zc, acquiring ? acq_opt : track_opt, bias);
    if (po && !acquiring && r.outcome == UpdateOutcome::kApplied) {
      const double dt_pair = std::isnan(po->t_last_s) ? 0.0 : std::min(t - po->t_last_s, 0.2);
      po->offset_m = std::clamp(po->offset_m + (dt_pair / p.pair_bias_tau_s) * r.weight * r.innovation_m, -0.5, 0.5);
      po->t_last_s = t;
    }
    switch (r.outcome) {
      case UpdateOutcome::kApplied:
        ++sum.n_tdoa_used;
        if (r.weight < 1.0) ++sum.n_tdoa_downweighted;
        t_last_accept = t;
        n_rejected_streak = 0;
        break;
      case UpdateOutcome::kRejectedOutlier:
        ++sum.n_tdoa_rejected;
        ++n_rejected_streak;
        break;
      case UpdateOutcome::kUnknownAnchor: ++sum.n_tdoa_unknown_anchor; break;
      default: ++sum.n_tdoa_degenerate; break;
    }
    // (F16) lost: nothing accepted for max_lost_s → re-acquire with an inflated covariance
    if (phase == FlightPhase::kTracking && t - t_last_accept > p.max_lost_s && n_rejected_streak > 20) {
      ekf.inflatePosition(0.5, 0.5);
      phase = FlightPhase::kAcquisition;
      t_acq_end = t + p.acquisition_s;
      ++sum.n_reacquisitions;
      t_last_accept = t;
    }
    emit(t);
  }
  if (initialized) emit(sum.end_t_s, true);
  return result;
}

}  // namespace uwb
