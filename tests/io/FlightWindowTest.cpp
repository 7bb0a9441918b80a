/** @file FlightWindowTest.cpp
 *  @brief sliceFlight: every stream cut to [t0, t1] with the stamps kept, and the one check of a window that the
 *  CLI's --window and Python's Flight.window rely on.
 */
#include "uwb/io/FlightWindow.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace uwb {
namespace {

Flight tenSecondsOfEveryStream() {
  Flight f;
  for (int k = 0; k <= 10; ++k) {
    const double t = k;
    f.tdoa.push_back({t, 0, 1, 0.1 * k});
    f.acc.push_back({t, Vec3(0.0, 0.0, 9.81)});
    f.gyro.push_back({t, Vec3::Zero()});
    f.tof.push_back({t, 0.5});
    f.pose.push_back({});
    f.pose.back().t_s = t;
  }
  f.source = "ten.csv";
  return f;
}

TEST(SliceFlight, GivenAWindowThenEveryStreamKeepsTheSamplesInsideItWithTheirStamps) {
  // GIVEN one sample per second from 0 to 10 s in every stream
  const Flight f = tenSecondsOfEveryStream();
  // WHEN cut to [2.5, 6]
  const Flight w = sliceFlight(f, 2.5, 6.0);
  // THEN 3, 4, 5 and 6 s remain in each stream (the end is inside), stamps unshifted, the rest copied
  for (const std::size_t n : {w.tdoa.size(), w.acc.size(), w.gyro.size(), w.tof.size(), w.pose.size()})
    EXPECT_EQ(n, 4u);
  EXPECT_DOUBLE_EQ(w.tdoa.front().t_s, 3.0);
  EXPECT_DOUBLE_EQ(w.tdoa.back().t_s, 6.0);
  EXPECT_DOUBLE_EQ(w.tdoa.front().tdoa_m, 0.3);
  EXPECT_DOUBLE_EQ(w.pose.back().t_s, 6.0);
  EXPECT_EQ(w.source, "ten.csv");
}

TEST(SliceFlight, GivenAnEmptyReversedOrNonFiniteWindowThenItThrowsNamingBothStamps) {
  const Flight f = tenSecondsOfEveryStream();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& [t0, t1] : {std::pair{5.0, 5.0}, std::pair{6.0, 2.0}, std::pair{nan, 2.0},
                               std::pair{0.0, std::numeric_limits<double>::infinity()}}) {
    try {
      (void)sliceFlight(f, t0, t1);
      ADD_FAILURE() << "no error for " << t0 << "," << t1;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("t0 < t1"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace uwb
