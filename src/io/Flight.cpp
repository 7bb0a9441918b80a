/** @file Flight.cpp */
#include "uwb/io/Flight.h"

#include <algorithm>
#include <limits>

namespace uwb {

bool Flight::has(Stream s) const {
  switch (s) {
    case Stream::kTdoa: return !tdoa.empty();
    case Stream::kTwr: return !twr.empty();
    case Stream::kAcc: return !acc.empty();
    case Stream::kGyro: return !gyro.empty();
    case Stream::kTof: return !tof.empty();
    case Stream::kFlow: return !flow.empty();
    case Stream::kBaro: return !baro.empty();
    case Stream::kPose: return !pose.empty();
  }
  return false;
}

std::pair<double, double> Flight::timeSpan() const {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  const auto extend = [&](const auto& stream) {
    if (stream.empty()) return;
    lo = std::min(lo, stream.front().t_s);
    hi = std::max(hi, stream.back().t_s);
  };
  extend(tdoa);
  extend(twr);
  extend(acc);
  extend(gyro);
  extend(tof);
  extend(flow);
  extend(baro);
  extend(pose);
  if (lo > hi) return {0.0, 0.0};
  return {lo, hi};
}

}  // namespace uwb
