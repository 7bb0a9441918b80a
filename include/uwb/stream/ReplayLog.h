/** @file ReplayLog.h
 *  @brief A recorded flight as the events `uwbtdoa replay` sends: IMU paired as sensorLogFromFlight does (with the
 *         ToF stream), cleaned as the batch path cleans it (F17), to be walked in SensorEventCursor order.
 */
#pragma once

#include "uwb/filter/SensorEvents.h"
#include "uwb/io/Flight.h"

namespace uwb {

/// The flight's IMU, TDoA and ToF streams, cleaned (sensorLogIsClean holds); `report` gets what cleaning found.
SensorLog replayLogFromFlight(const Flight& flight, MergeReport* report = nullptr);

}  // namespace uwb
