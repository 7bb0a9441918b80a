/** @file FlightWindow.cpp
 *  @brief Cutting a flight to a time window.
 */
#include "uwb/io/FlightWindow.h"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace uwb {
namespace {

template <class T>
std::vector<T> window(const std::vector<T>& in, double t0_s, double t1_s) {
  std::vector<T> out;
  for (const T& s : in)
    if (s.t_s >= t0_s && s.t_s <= t1_s) out.push_back(s);
  return out;
}

}  // namespace

Flight sliceFlight(const Flight& flight, double t0_s, double t1_s) {
  if (!(std::isfinite(t0_s) && std::isfinite(t1_s) && t0_s < t1_s))
    throw std::invalid_argument(fmt::format("a window needs finite stamps with t0 < t1, got {},{}", t0_s, t1_s));
  Flight out;
  out.tdoa = window(flight.tdoa, t0_s, t1_s);
  out.twr = window(flight.twr, t0_s, t1_s);
  out.acc = window(flight.acc, t0_s, t1_s);
  out.gyro = window(flight.gyro, t0_s, t1_s);
  out.tof = window(flight.tof, t0_s, t1_s);
  out.flow = window(flight.flow, t0_s, t1_s);
  out.baro = window(flight.baro, t0_s, t1_s);
  out.pose = window(flight.pose, t0_s, t1_s);
  out.pose_has_orientation = flight.pose_has_orientation;
  out.columns = flight.columns;
  out.source = flight.source;
  return out;
}

}  // namespace uwb
