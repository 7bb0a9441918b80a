/** @file Flight.h
 *  @brief In-memory flight in SI units: every sensor stream of the UTIL flight-CSV layout, each its own length.
 *
 *  Frames and units (converted once at the I/O boundary, see io/UtilCsv.h):
 *  - time: seconds, on the drone's clock, shared by all streams of one flight;
 *  - acc: specific force in the body frame [m/s²] (file: g); gyro: body rates [rad/s] (file: deg/s);
 *  - pose: Vicon body position in the world frame [m] and body→world quaternion w_q_b;
 *  - tdoa_m = |p_tag − a_idB| − |p_tag − a_idA| [m] (UTIL sign convention).
 */
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "uwb/core/Tdoa.h"
#include "uwb/core/Types.h"

namespace uwb {

/// One TWR range measurement to one anchor [m].
struct TwrMeasurement {
  double t_s = 0.0;
  int anchor_id = 0;
  double range_m = 0.0;
};

/// A 3-axis inertial sample in the body frame (acc: m/s², gyro: rad/s).
struct ImuSample {
  double t_s = 0.0;
  Vec3 b_value = Vec3::Zero();
};

struct ScalarSample {
  double t_s = 0.0;
  double value = 0.0;
};

/// Optical-flow sample: raw flow counts.
struct FlowSample {
  double t_s = 0.0;
  double delta_x = 0.0;
  double delta_y = 0.0;
};

/// Ground-truth pose: body origin in the world frame and body→world rotation.
struct PoseSample {
  double t_s = 0.0;
  Vec3 w_p_b = Vec3::Zero();
  Quat w_q_b = Quat::Identity();  ///< identity when the file carries position only
};

/// The streams of the UTIL layout. A stream is "present" when its columns are in the file's header.
enum class Stream { kTdoa, kTwr, kAcc, kGyro, kTof, kFlow, kBaro, kPose };

/// A whole flight. Streams that the file did not carry are empty and marked absent in `present`.
struct Flight {
  std::vector<TdoaMeasurement> tdoa;
  std::vector<TwrMeasurement> twr;
  std::vector<ImuSample> acc;   ///< specific force [m/s²], body frame
  std::vector<ImuSample> gyro;  ///< angular rate [rad/s], body frame
  std::vector<ScalarSample> tof;   ///< [m]
  std::vector<FlowSample> flow;    ///< raw counts
  std::vector<ScalarSample> baro;  ///< [m above sea level]
  std::vector<PoseSample> pose;
  bool pose_has_orientation = false;  ///< false for position-only files (util-final-extract)

  /// Header columns of the source file, in file order (the writer reproduces them).
  std::vector<std::string> columns;
  std::string source;  ///< file the flight was read from, for messages

  bool has(Stream s) const;
  bool hasImu() const { return !acc.empty() && !gyro.empty(); }
  bool hasGroundTruth() const { return !pose.empty(); }
  /// [first, last] sample time over all streams [s]; {0, 0} for an empty flight.
  std::pair<double, double> timeSpan() const;
};

}  // namespace uwb
