/** @file NavStateTest.cpp
 *  @brief worldVertical, the fast third row of R(q), against the full rotation.
 */
#include <gtest/gtest.h>

#include <random>

#include "uwb/filter/NavState.h"

namespace uwb {
namespace {

TEST(NavState, WorldVerticalIsTheFullRotationsZ) {
  // GIVEN random unit quaternions and body vectors
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    const Quat q = Quat(n(rng), n(rng), n(rng), n(rng)).normalized();
    const Vec3 v(n(rng), n(rng), 10.0 * n(rng));
    // WHEN the vertical part is taken from the third row alone THEN it equals (q v)_z
    EXPECT_NEAR(worldVertical(q, v), (q * v).z(), 1e-12) << i;
  }
  // and a level body's vertical is its z
  EXPECT_DOUBLE_EQ(worldVertical(Quat::Identity(), Vec3(1.0, 2.0, 9.81)), 9.81);
}

}  // namespace
}  // namespace uwb
