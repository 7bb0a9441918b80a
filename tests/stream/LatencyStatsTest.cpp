/** @file LatencyStatsTest.cpp
 *  @brief Nearest-rank percentiles of the latency samples.
 */
#include <gtest/gtest.h>

#include <cmath>

#include "uwb/stream/LatencyStats.h"

namespace uwb {
namespace {

TEST(LatencyStats, NearestRankPercentiles) {
  LatencyStats s;
  EXPECT_TRUE(std::isnan(s.quantile(0.5)));
  for (int k = 100; k >= 1; --k) s.add(k * 1e-6);  // 1 … 100 µs, in reverse
  EXPECT_DOUBLE_EQ(s.quantile(0.5), 50e-6);
  EXPECT_DOUBLE_EQ(s.quantile(0.99), 99e-6);
  EXPECT_DOUBLE_EQ(s.quantile(1.0), 100e-6);
  EXPECT_DOUBLE_EQ(s.quantile(0.0), 1e-6);
  EXPECT_NE(s.summary().find("p99 99.0"), std::string::npos) << s.summary();
}

}  // namespace
}  // namespace uwb
