/** @file TdoaFeatureTest.cpp */
#include <gtest/gtest.h>

#include <cmath>

#include "uwb/model/TdoaFeature.h"

namespace uwb {

TEST(TdoaFeature, AnchorAheadHasZeroYawAndYawFollowsBodyRotation) {
  // GIVEN a drone at the origin yawed by +90° and an anchor on the world +y axis
  const Quat w_q_b(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()));
  const Vec3 anchor_a(0, 2, 0), anchor_b(-3, 0, 1);
  // WHEN we compute the feature
  const TdoaFeature f = makeTdoaFeature(1, 2, Vec3::Zero(), w_q_b, anchor_a, anchor_b);
  // THEN anchor A lies straight ahead (body +x) and anchor B (world −x) on the body's left side (body +y)
  EXPECT_NEAR(f.yaw_a_rad, 0.0, 1e-12);
  EXPECT_NEAR(f.b_p_a.x(), 2.0, 1e-12);
  EXPECT_NEAR(f.yaw_b_rad, kPi / 2, 1e-12);
  EXPECT_NEAR(f.b_p_b.z(), 1.0, 1e-12);
  EXPECT_NEAR(f.b_p_b.norm(), std::sqrt(10.0), 1e-12);
}

}  // namespace uwb
