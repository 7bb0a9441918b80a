/** @file TrajectoryCsv.h
 *  @brief Estimated trajectories: the filter's output, written as CSV for users and plots.
 *
 *  Columns: t,x,y,z,qx,qy,qz,qw,std_x,std_y,std_z,vx,vy,vz  (SI units; quaternion body→world), then, when every
 *  sample has them, the IMU biases the filter estimated: acc_bias_x,acc_bias_y,acc_bias_z [m/s²],
 *  gyro_bias_x,gyro_bias_y,gyro_bias_z [rad/s] (body frame). A file without them reads as NaN biases.
 *
 *  TUM (the trajectory format of the TUM RGB-D benchmark, read by `evo` and the SLAM evaluation tools): one pose a
 *  line, `timestamp tx ty tz qx qy qz qw`, space-separated, after one `#` comment line naming the columns. Numbers
 *  are the shortest text that reads back as the same double, so a TUM file holds the CSV's poses exactly.
 */
#pragma once

#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "uwb/core/Types.h"

namespace uwb {

/// One estimated state: body origin, attitude, velocity and position standard deviations.
struct TrajectorySample {
  double t_s = 0.0;
  Vec3 w_p_b = Vec3::Zero();      ///< body origin in the world frame [m]
  Quat w_q_b = Quat::Identity();  ///< body→world rotation
  Vec3 sigma_p_m = Vec3::Zero();  ///< 1σ of the position per world axis [m]
  Vec3 w_v_b = Vec3::Zero();      ///< velocity in the world frame [m/s]
  /// Accelerometer and gyroscope bias, body frame [m/s²], [rad/s]; NaN where not estimated (TDoA-only models).
  Vec3 b_acc_bias = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  Vec3 b_gyro_bias = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());

  bool hasImuBias() const { return b_acc_bias.allFinite() && b_gyro_bias.allFinite(); }
};

using Trajectory = std::vector<TrajectorySample>;

void writeTrajectoryCsv(const Trajectory& trajectory, const std::string& path);
Trajectory readTrajectoryCsv(const std::string& path);
/// Same as readTrajectoryCsv on text already in memory; `source` names it in messages.
Trajectory parseTrajectoryCsv(std::string_view text, const std::string& source);

/// The poses as TUM text (header comment line, then `t x y z qx qy qz qw` per sample).
std::string formatTrajectoryTum(const Trajectory& trajectory);
/// Writes formatTrajectoryTum atomically; FileError on failure.
void writeTrajectoryTum(const Trajectory& trajectory, const std::string& path);
/// Reads TUM text: `#` lines and blank lines skipped, 8 numbers a line separated by spaces or tabs. Only the pose
/// is set (σ, velocity zero; biases NaN). InputError naming line and field for anything else.
Trajectory parseTrajectoryTum(std::string_view text, const std::string& source);
Trajectory readTrajectoryTum(const std::string& path);

}  // namespace uwb
