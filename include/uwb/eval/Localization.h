/** @file Localization.h
 *  @brief Runs the localization filter on a Flight (io types → filter types), optionally with a bias predictor,
 *         and evaluates the result against the flight's ground truth. Used by `uwbtdoa localize`, the
 *         evaluation pipeline and the regression tests.
 *
 *  @code
 *    const Flight flight = readFlightCsv("0425-traj2.csv");
 *    const AnchorSurvey survey = readAnchorSurvey("anchor_0425_survey.txt");
 *    LocalizationRun run = localizeFlight(flight, survey);                       // defaults, no bias model
 *    LocalizationRun corrected = localizeFlight(flight, survey, {}, predictor);  // with a BiasPredictor
 *    double rmse = run.metrics->airborne.rmse_m;
 *  @endcode
 */
#pragma once

#include <optional>
#include <vector>

#include "uwb/eval/TrajectoryMetrics.h"
#include "uwb/filter/TdoaLocalizer.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"
#include "uwb/io/TrajectoryCsv.h"
#include "uwb/model/TdoaFeature.h"

namespace uwb {

struct LocalizationOptions {
  EkfParams params;                 ///< filter parameters (defaults tuned on the UTIL pilot flights)
  double output_period_s = 0.01;    ///< spacing of trajectory samples [s]
  bool tdoa_only = false;           ///< force the TDoA-only model even when the flight has IMU data
  TrajectoryMetricsParams metrics;  ///< used when the flight has ground truth
};

struct LocalizationRun {
  Trajectory trajectory;
  LocalizerSummary summary;
  std::optional<TrajectoryMetrics> metrics;  ///< when the flight has ground truth
  double duration_s = 0.0;                   ///< flight duration covered by the sensor data [s]
  std::size_t n_truth_glitches = 0;          ///< ground-truth samples rejected as glitches
  /// Per trajectory sample: the TDoA taken at the floor's σ so far (LocalizerEstimate::n_tdoa_used_at_rest).
  std::vector<std::size_t> n_tdoa_used_at_rest;
};

/// The flight's IMU (paired acc/gyro) and TDoA streams as the filter consumes them; with_tof also copies the
/// downward ToF range (docs/math/filter.md F21), which the filter uses only with EkfParams::fuse_tof.
SensorLog sensorLogFromFlight(const Flight& flight, MergeReport* report = nullptr, bool with_tof = false);
/// A recorded flight as the events `uwbtdoa replay` sends: the IMU, TDoA and ToF streams paired as
/// sensorLogFromFlight does, cleaned as the batch path cleans them (F17; sensorLogIsClean holds), to be walked in
/// SensorEventCursor order; `report` gets what cleaning found.
SensorLog replayLogFromFlight(const Flight& flight, MergeReport* report = nullptr);
/// Anchor beliefs from a survey; every coordinate with std anchor_sigma_m.
AnchorTable anchorTableFromSurvey(const AnchorSurvey& survey, double anchor_sigma_m = 0.0);
/// Filter output → trajectory samples (position, attitude, velocity, position std; with imu_biases the IMU biases
/// the filter estimated, otherwise NaN: the TDoA-only models have no bias states).
Trajectory toTrajectory(const std::vector<LocalizerEstimate>& estimates, bool imu_biases);

/// Localizes a flight; without IMU (or with options.tdoa_only) the TDoA-only model runs. When the flight has
/// ground truth, metrics are computed against its glitch-free pose track.
LocalizationRun localizeFlight(const Flight& flight, const AnchorSurvey& survey, const LocalizationOptions& options = {},
                               const BiasPredictor& bias = {});

}  // namespace uwb
