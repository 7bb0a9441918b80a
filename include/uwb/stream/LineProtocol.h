/** @file LineProtocol.h
 *  @brief The sensor-event line protocol of `uwbtdoa stream` and `uwbtdoa replay` (docs/io.md §5): one event per
 *         line, comma-separated, SI units, stamps in seconds.
 *
 *    imu,t,ax,ay,az,gx,gy,gz      specific force [m/s²] and angular rate [rad/s], body frame
 *    tdoa,t,id_a,id_b,tdoa_m      ‖p − a_idB‖ − ‖p − a_idA‖ [m] (the UTIL convention)
 *    tof,t,range_m                downward range [m]
 *    # ...                        comment; empty lines are skipped as well
 *
 *  Numbers are written with the shortest text that reads back to the same double, so a replayed flight reaches the
 *  filter bit for bit.
 */
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "uwb/filter/SensorEvents.h"

namespace uwb {

/// One decoded line: a sensor event, or nothing (comment, empty line).
struct StreamEvent {
  enum class Kind : unsigned char { kNone, kImu, kTdoa, kTof };
  Kind kind = Kind::kNone;
  double t_s = 0.0;
  ImuReading imu;        ///< kImu
  TdoaMeasurement tdoa;  ///< kTdoa (its t_s equals t_s)
  TofObservation tof;    ///< kTof (its t_s equals t_s)
};

/// Decodes one line (without its newline; a trailing '\r' is ignored). Throws InputError naming `source`, the
/// 1-based `line_no`, the column and the field ("type", "t", "ax", ..., "id_a", "tdoa_m", "range_m") when the line
/// is malformed: unknown type, wrong number of fields, a number that does not parse or is not finite, an id that is
/// not an integer in [0, kMaxAnchorId], id_a equal to id_b.
StreamEvent parseEventLine(std::string_view line, std::size_t line_no, const std::string& source = "<stdin>");

/// Throws InputError naming `source`, `line_no` and the field ("id_a", "id_b") when a TDoA event names an anchor
/// that `anchors` (the survey) does not hold. Other events pass.
void checkEventAnchors(const StreamEvent& ev, const AnchorTable& anchors, std::size_t line_no,
                       const std::string& source = "<stdin>");

/// The line of one event (no newline).
std::string formatImuLine(double t_s, const ImuReading& imu);
std::string formatTdoaLine(const TdoaMeasurement& z);
std::string formatTofLine(const TofObservation& z);
/// The line of event `ev` of a merged log (SensorEventCursor over `log`).
std::string formatEventLine(const SensorLog& log, const SensorEvent& ev);

/// First line `replay` writes: a comment naming the protocol and its version.
inline constexpr std::string_view kEventProtocolHeader = "# uwbtdoa-events v1";

}  // namespace uwb
