/** @file EstimateFormat.h
 *  @brief How `uwbtdoa stream` writes an estimate (docs/io.md §5): one JSON object per line or one CSV row, with the
 *         fields a ROS PoseWithCovarianceStamped needs. Numbers are written with the shortest round-trip text.
 *
 *  JSON: {"t":…,"p":[x,y,z],"q":[w,x,y,z],"v":[vx,vy,vz],"cov":[36 values, row-major],"phase":"tracking"}
 *  CSV:  t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,cov_0_0,…,cov_5_5,phase
 *  TUM:  t px py pz qx qy qz qw  (space-separated, after the comment line `# timestamp tx ty tz qx qy qz qw`; the
 *        pose only, as `localize --format tum` writes it, for evo and the SLAM trajectory tools)
 *  The covariance is that of (δp [m], δθ [rad]) (LocalizerEstimate::cov_pose), position block first.
 */
#pragma once

#include <string>

#include "uwb/filter/Estimator.h"

namespace uwb {

enum class EstimateFormat : unsigned char { kJson, kCsv, kTum };

/// The CSV header line (no newline).
std::string estimateCsvHeader();
/// The first line of a format (no newline): the CSV header, TUM's column comment, "" for JSON lines.
std::string estimateHeader(EstimateFormat format);
/// One estimate as a line (no newline).
std::string formatEstimate(const LocalizerEstimate& e, EstimateFormat format);

/// Reads back one line written by formatEstimate (for tests and consumers); throws InputError naming the line.
/// A TUM line gives the time and the pose only (velocity zero, covariance NaN, phase tracking).
LocalizerEstimate parseEstimate(const std::string& line, EstimateFormat format, std::size_t line_no = 1);

}  // namespace uwb
