/** @file EstimateFormat.h
 *  @brief How `uwbtdoa stream` writes an estimate (docs/io.md §5): one JSON object per line or one CSV row, with the
 *         fields a ROS PoseWithCovarianceStamped needs. Numbers are written with the shortest round-trip text.
 *
 *  JSON: {"t":…,"p":[x,y,z],"q":[w,x,y,z],"v":[vx,vy,vz],"cov":[36 values, row-major],"phase":"tracking"}
 *  CSV:  t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,cov_0_0,…,cov_5_5,phase
 *  The covariance is that of (δp [m], δθ [rad]) (LocalizerEstimate::cov_pose), position block first.
 */
#pragma once

#include <string>

#include "uwb/filter/Estimator.h"

namespace uwb {

enum class EstimateFormat : unsigned char { kJson, kCsv };

/// The CSV header line (no newline).
std::string estimateCsvHeader();
/// One estimate as a line (no newline).
std::string formatEstimate(const LocalizerEstimate& e, EstimateFormat format);

/// Reads back one line written by formatEstimate (for tests and consumers); throws InputError naming the line.
LocalizerEstimate parseEstimate(const std::string& line, EstimateFormat format, std::size_t line_no = 1);

}  // namespace uwb
