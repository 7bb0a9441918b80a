/** @file UsdImport.h
 *  @brief A Crazyflie uSD-card event log (io/UsdLog.h) as a flight in the UTIL layout, and back.
 *
 *  The UTIL dataset was recorded with these logs; its own conversion maps event types to CSV columns (docs/io.md
 *  §6 has the table). The import applies the same mapping and units, so that a user's own log becomes the flight
 *  CSV that every other command reads:
 *    estTDOA {idA, idB, distanceDiff [m]}              → tdoa (distanceDiff = |p − a_idB| − |p − a_idA|)
 *    estDistance {id, distance [m]}                    → twr
 *    estAcceleration {acc.x, acc.y, acc.z [g]}         → acc   (in memory × kGravity_mps2, as the CSV reader)
 *    estGyroscope {gyro.x, gyro.y, gyro.z [deg/s]}     → gyro  (in memory × kDegToRad)
 *    estTOF {range.zrange [mm]} or {distance [m]}      → tof [m]
 *    estFlow {motion.deltaX, motion.deltaY [counts]}   → flow
 *    estBarometer {baro.asl [m]}                       → baro
 *    estPose {locSrv.x, .y, .z [m], locSrv.qx, .qy, .qz, .qw}, or {x, y, z [m], quat (compressed uint32)} → pose;
 *    estPosition {x, y, z} or {locSrv.x, .y, .z}       → position-only pose, when no estPose carries a pose.
 *  Time: t = (timestamp − earliest timestamp of any event in the log) [s], as UTIL's conversion.
 */
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "uwb/io/Flight.h"
#include "uwb/io/UsdLog.h"

namespace uwb {

/// Which event type (and fields) filled each stream, and what was left out.
struct UsdImportReport {
  struct Source {
    Stream stream = Stream::kTdoa;
    std::string event;   ///< event-type name, e.g. "estTDOA"
    std::string fields;  ///< the fields used, e.g. "idA, idB, distanceDiff"
    std::size_t count = 0;
  };
  std::vector<Source> sources;     ///< one per imported stream, in UTIL column order
  std::vector<std::string> notes;  ///< event types ignored or lacking fields, streams missing, reader notes
  double t0_us = 0.0;              ///< the log timestamp taken as t = 0 [µs]
};

/// One way a stream can be recorded in a log: the event type and the fields the import reads from it.
struct UsdRecording {
  Stream stream = Stream::kTdoa;
  std::string event;                ///< e.g. "estTOF"
  std::vector<std::string> fields;  ///< e.g. {"range.zrange"}
};
/// Every recording the import reads, in the order it tries them (the table above; docs/io.md §6). A uSD-deck
/// config.txt that names only these event types and variables gives a log `import` reads (examples/usd/config.txt).
std::vector<UsdRecording> usdRecordings();

/// The flight held by a log. InputError ("file: byte B, event K (type.field): ...") on a value the flight CSV
/// would refuse: NaN/Inf, an anchor id that is not an integer in [0, kMaxAnchorId], a pose quaternion far from unit
/// norm; and when no event type of the table above carries data. Event types outside the table are noted.
/// writeFlightCsv of the result reads back (readFlightCsv) as the same flight, bit for bit.
Flight flightFromUsdLog(const UsdLog& log, UsdImportReport* report = nullptr);

/// readUsdLog + flightFromUsdLog; the reader's notes are added to the report's.
Flight importUsdLog(const std::string& path, const UsdReadOptions& options = {}, UsdImportReport* report = nullptr);

/// The inverse, for tests and for tools that feed firmware replays: a flight's streams as the events UTIL recorded
/// (version 2 log, µs timestamps = round(t · 10⁶), values as float32 in the file units, tof as uint16 mm, flow
/// as int16, ids as uint8). Event order: by time, ties in UTIL column order. std::invalid_argument when a value
/// does not fit (negative time, anchor id > 255, tof outside 0…65.535 m, flow outside int16).
UsdLog usdLogFromFlight(const Flight& flight);

}  // namespace uwb
