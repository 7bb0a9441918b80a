/** @file LocalizationJson.h
 *  @brief A localization run's results as JSON, written in one place: `uwbtdoa localize --json` and Python's
 *         `localize_flight` both call these (docs/io.md, "localize").
 *
 *  Values are written as they are: a quantity that was not measured is NaN, which the JSON writer prints as null
 *  and Python receives as float('nan').
 */
#pragma once

#include <nlohmann/json.hpp>

#include "uwb/eval/RunDiagnostics.h"
#include "uwb/eval/TrajectoryMetrics.h"
#include "uwb/filter/EkfParams.h"
#include "uwb/filter/Estimator.h"
#include "uwb/filter/SensorRange.h"

namespace uwb {

/// The filter run's summary and the parameters it reports (fuse_tof, the bias model's training levels): every
/// count, time, level and note `localize --json` prints at its top level.
nlohmann::json localizerSummaryJson(const LocalizerSummary& s, const EkfParams& params);
/// Position-error statistics {n, rmse_m, rmse_x_m, rmse_y_m, rmse_z_m, mean_m, p50_m, p90_m, p99_m, max_m}.
nlohmann::json positionErrorStatsJson(const PositionErrorStats& s);
/// The samples skipped outside the sensors' physical ranges (filter.md F31), per sensor: {"gyro": {"n", "limit",
/// "first_t_s", "worst"}, "acc": …, "tdoa": …}; first_t_s and worst are null when nothing was skipped or not finite.
nlohmann::json sensorRangeJson(const SensorRangeReport& report);
/// The checks after a run (eval/RunDiagnostics.h); null for a check that did not run.
nlohmann::json runDiagnosticsJson(const RunDiagnostics& d);

}  // namespace uwb
