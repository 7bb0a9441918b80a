/** @file TdoaLocalizer.h
 *  @brief The batch path: a recorded sensor log cleaned and merged (F17), then fed event by event to the online
 *         Estimator, with its estimate taken at a fixed output spacing. The result equals the online loop's.
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
#include "uwb/filter/Estimator.h"
#include "uwb/filter/EkfParams.h"
#include "uwb/filter/SensorEvents.h"
#include "uwb/filter/TdoaUpdate.h"
#include "uwb/model/TdoaFeature.h"

namespace uwb {

struct LocalizerResult {
  std::vector<LocalizerEstimate> estimates;
  LocalizerSummary summary;
};

class TdoaLocalizer {
 public:
  /// params.validate() is called; throws std::invalid_argument when the params are bad or no anchor is given.
  TdoaLocalizer(const EkfParams& params, AnchorTable anchors, BiasPredictor bias = {});

  /// Runs the Estimator over the whole log (cleaned and merged first, F17). Without IMU samples the TDoA-only model
  /// is used (params.process_model if it is not kImu, else constant velocity). output_period_s: minimum spacing of
  /// output samples (0: one per event); outputs start once the position is known (Estimator::ready). A clean log
  /// (sensorLogIsClean, the usual case) is read in place; otherwise a cleaned copy is made.
  LocalizerResult run(const SensorLog& log, double output_period_s = 0.01) const;

 private:
  EkfParams params_;
  AnchorTable anchors_;
  BiasPredictor bias_;
};

}  // namespace uwb
