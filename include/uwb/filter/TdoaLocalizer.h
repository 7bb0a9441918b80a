/** @file TdoaLocalizer.h
 *  @brief The whole estimator over a merged sensor log: IMU averaging, prediction, covariance schedule, TDoA
 *         updates through the graph node, ground phase and take-off/landing detection, start without ground
 *         truth (multilateration), re-acquisition when lost, TDoA-only mode. docs/math/filter.md F14–F18.
 *
 *  Usage:
 *  @code
 *    AnchorTable anchors;  anchors.set(id, w_p);                 // from the survey
 *    SensorLog log;  log.imu = pairImuStreams(acc, gyro);  log.tdoa = ...;
 *    TdoaLocalizer localizer(EkfParams::defaults(), anchors);    // optional 3rd argument: a BiasPredictor
 *    LocalizerResult result = localizer.run(std::move(log));
 *  @endcode
 */
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "uwb/filter/Ekf.h"
#include "uwb/filter/EkfParams.h"
#include "uwb/filter/SensorEvents.h"
#include "uwb/filter/TdoaUpdate.h"
#include "uwb/model/TdoaFeature.h"

namespace uwb {

enum class FlightPhase : unsigned char { kGround, kAcquisition, kTracking, kLanded };

/// One output sample of the estimator.
struct LocalizerEstimate {
  double t_s = 0.0;
  NavState x;
  Vec3 sigma_p_m = Vec3::Zero();  ///< 1σ of the position per world axis [m]
  FlightPhase phase = FlightPhase::kGround;
};

struct LocalizerSummary {
  std::size_t n_tdoa_total = 0;
  std::size_t n_tdoa_used = 0;         ///< applied (possibly down-weighted)
  std::size_t n_tdoa_rejected = 0;     ///< χ² gate
  std::size_t n_tdoa_downweighted = 0; ///< robust weight < 1
  std::size_t n_tdoa_ground = 0;       ///< not used: on the ground / waiting for the start
  std::size_t n_tdoa_degenerate = 0;
  std::size_t n_tdoa_unknown_anchor = 0;
  // ToF height updates (F21; only with EkfParams::fuse_tof and a ToF stream in the log)
  std::size_t n_tof_total = 0;
  std::size_t n_tof_used = 0;
  std::size_t n_tof_rejected = 0;      ///< χ² gate
  std::size_t n_tof_invalid = 0;       ///< non-finite, ≤ 0 or above tof_max_range_m (ignored)
  std::size_t n_tof_tilted = 0;        ///< cos(tilt) ≤ kTofMinCosTilt (ignored)
  std::size_t n_tof_not_airborne = 0;  ///< on the ground, landed, or before the start position is known
  std::size_t n_predictions = 0;
  std::size_t n_covariance_propagations = 0;
  std::size_t n_reacquisitions = 0;
  double takeoff_t_s = std::numeric_limits<double>::quiet_NaN();
  double landing_t_s = std::numeric_limits<double>::quiet_NaN();
  double start_t_s = 0.0;
  double end_t_s = 0.0;
  ProcessModel process_model = ProcessModel::kImu;
  MergeReport merge;
  Vec3 start_w_p_b = Vec3::Zero();     ///< position found by multilateration (or given)
  double start_rms_residual_m = 0.0;
};

struct LocalizerResult {
  std::vector<LocalizerEstimate> estimates;
  LocalizerSummary summary;
};

class TdoaLocalizer {
 public:
  /// params.validate() is called; throws std::invalid_argument when the params are bad or no anchor is given.
  TdoaLocalizer(const EkfParams& params, AnchorTable anchors, BiasPredictor bias = {});

  /// Runs over the whole log (cleaned and merged first, F17). Without IMU samples the TDoA-only model is used
  /// (params.process_model if it is not kImu, else constant velocity). output_period_s: minimum spacing of
  /// output samples (0: one per event). A clean log (sensorLogIsClean, the usual case) is read in place; otherwise
  /// a cleaned copy is made.
  LocalizerResult run(const SensorLog& log, double output_period_s = 0.01) const;

 private:
  EkfParams params_;
  AnchorTable anchors_;
  BiasPredictor bias_;
};

}  // namespace uwb
