/** @file ReplayLog.cpp
 *  @brief The events of a recorded flight for `uwbtdoa replay`.
 */
#include "uwb/stream/ReplayLog.h"

#include "uwb/eval/Localization.h"
#include "uwb/filter/EkfParams.h"

namespace uwb {

SensorLog replayLogFromFlight(const Flight& flight, MergeReport* report) {
  MergeReport pair_report;
  SensorLog log = sensorLogFromFlight(flight, &pair_report, /*with_tof=*/true);
  MergeReport clean_report = cleanSensorLog(log, EkfParams{}.max_gap_s);
  clean_report.n_imu_unpaired = pair_report.n_imu_unpaired;
  if (report) *report = clean_report;
  return log;
}

}  // namespace uwb
