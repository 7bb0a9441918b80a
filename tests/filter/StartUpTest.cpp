/** @file StartUpTest.cpp
 *  @brief The start-up multilateration's decisions (docs/math/filter.md F16c, F16j): a first start on the floor is
 *         kept where the body is on the floor and refuted where its TDoA put it in the air.
 *
 *  Eight anchors in a 4 m × 4 m × 3 m box, alternately near the floor (0.2 m) and high (3 m), as the LPS ring of
 *  pairs (k, k + 1) sees them; exact TDoA at 400 Hz, no lever arm.
 */
#include <gtest/gtest.h>

#include <optional>

#include "uwb/filter/StartUp.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

AnchorTable boxAnchors() {
  AnchorTable t;
  const Vec3 corners[8] = {{0, 0, 0.2}, {4, 0, 3}, {4, 4, 0.2}, {0, 4, 3}, {0, 0, 3}, {4, 0, 0.2}, {4, 4, 3}, {0, 4, 0.2}};
  for (int i = 0; i < 8; ++i) t.set(i, corners[i]);
  return t;
}

/// Feeds exact TDoA of a body at w_p_b (held still by the prediction: x_now = x_ref) until the start-up returns.
std::optional<StartFix> runStart(StartUp& start, const AnchorTable& anchors, const Vec3& w_p_b,
                                 std::optional<double> floor_z_m, bool refutable = true) {
  const NavState held;  // the prediction on the ground: zero velocity, the displacements vanish
  for (int k = 0; k < 2000; ++k) {
    TdoaObservation z;
    z.t_s = 0.0025 * k;
    z.id_a = k % 8;
    z.id_b = (k + 1) % 8;
    z.tdoa_m = predictTdoa(w_p_b, Quat::Identity(), Vec3::Zero(), anchors.find(z.id_a)->m, anchors.find(z.id_b)->m);
    if (std::optional<StartFix> fix = start.add(z, held, floor_z_m, refutable)) return fix;
  }
  return std::nullopt;
}

TEST(StartUp, GivenGroundEvidenceAndABodyOnTheFloorWhenSolvedThenTheFixIsOnTheFloor) {
  // GIVEN floor contact before the first fix and TDoA of a body on the floor
  const AnchorTable anchors = boxAnchors();
  StartUp start(anchors, Vec3::Zero(), StartUpParams{});
  start.begin(0.0, NavState{}, false);
  // WHEN the window is solved
  const std::optional<StartFix> fix = runStart(start, anchors, Vec3(1.5, 2.5, 0.0), 0.0);
  // THEN the fix is on the floor, at rest, and the floor is not refuted (the free solve agrees with it)
  ASSERT_TRUE(fix);
  EXPECT_FALSE(fix->floor_refuted);
  EXPECT_FALSE(fix->with_velocity);
  EXPECT_EQ(fix->w_p_b.z(), 0.0);
  EXPECT_LT((fix->w_p_b.head<2>() - Vec3(1.5, 2.5, 0.0).head<2>()).norm(), 1e-3);
  EXPECT_NEAR(fix->cov(2, 2), 0.1 * 0.1, 1e-15);  // F22: the floor's height
}

TEST(StartUp, GivenGroundEvidenceAndABodyInTheAirWhenSolvedThenTheFloorIsRefuted) {
  // GIVEN floor contact before the first fix (a shaking burst in flight) and TDoA of a body hovering at 1.5 m; the
  // floor-level anchors get range delays in the floor solve (F16f), which can absorb part of the height
  const AnchorTable anchors = boxAnchors();
  StartUp start(anchors, Vec3::Zero(), StartUpParams{});
  start.setFloorLevelAnchors({1, 0, 1, 0, 0, 1, 0, 1});
  start.begin(0.0, NavState{}, false);
  // WHEN the window is solved
  const std::optional<StartFix> fix = runStart(start, anchors, Vec3(1.5, 2.5, 1.5), 0.0);
  // THEN the floor is refuted: the fix is the solve in motion, at the body, without floor delays or floor variance
  ASSERT_TRUE(fix);
  EXPECT_TRUE(fix->floor_refuted);
  EXPECT_TRUE(fix->with_velocity);
  EXPECT_LT((fix->w_p_b - Vec3(1.5, 2.5, 1.5)).norm(), 1e-3) << fix->w_p_b.transpose();
  EXPECT_LT(fix->w_v_b.norm(), 1e-3);
  EXPECT_TRUE(fix->anchor_delay_m.empty());
  EXPECT_GT(fix->cov(2, 2), 0.1 * 0.1);
}

TEST(StartUp, GivenABodyJustAboveTheFloorBandWhenSolvedThenOnlyAHeightAboveTheBandRefutesTheFloor) {
  // GIVEN floor contact and a body 1.0 m up (below floor_refute_height_m: floor-biased TDoA can read that high inside
  // the room) and 1.4 m up
  const AnchorTable anchors = boxAnchors();
  for (const double h : {1.0, 1.4}) {
    SCOPED_TRACE(h);
    StartUp start(anchors, Vec3::Zero(), StartUpParams{});
    start.begin(0.0, NavState{}, false);
    // WHEN the window is solved
    const std::optional<StartFix> fix = runStart(start, anchors, Vec3(2.0, 1.0, h), 0.0);
    // THEN the floor stands below the band and is refuted above it
    ASSERT_TRUE(fix);
    EXPECT_EQ(fix->floor_refuted, h > StartUpParams{}.floor_refute_height_m);
  }
}

TEST(StartUp, GivenRestRatherThanFloorContactWhenSolvedThenTheFloorIsNotTested) {
  // GIVEN ground evidence from rest (a still IMU: motors off, F18 (i)), which the caller does not let the TDoA refute,
  // and TDoA that read the body 1.5 m up
  const AnchorTable anchors = boxAnchors();
  StartUp start(anchors, Vec3::Zero(), StartUpParams{});
  start.begin(0.0, NavState{}, false);
  // WHEN the window is solved
  const std::optional<StartFix> fix = runStart(start, anchors, Vec3(1.5, 2.5, 1.5), 0.0, false);
  // THEN the fix stays on the floor
  ASSERT_TRUE(fix);
  EXPECT_FALSE(fix->floor_refuted);
  EXPECT_EQ(fix->w_p_b.z(), 0.0);
}

TEST(StartUp, GivenAReacquisitionOnTheFloorWhenSolvedThenTheFloorIsNotTested) {
  // GIVEN a window on the floor that is not the first start (a landing's floor window, F16i) with TDoA of a body in
  // the air: the ground evidence after a flight comes with a descent and is revised by the landing logic
  const AnchorTable anchors = boxAnchors();
  StartUp start(anchors, Vec3::Zero(), StartUpParams{});
  start.begin(0.0, NavState{}, false, true);
  // WHEN the window is solved
  const std::optional<StartFix> fix = runStart(start, anchors, Vec3(1.5, 2.5, 1.5), 0.0);
  // THEN the fix stays on the floor
  ASSERT_TRUE(fix);
  EXPECT_FALSE(fix->floor_refuted);
  EXPECT_EQ(fix->w_p_b.z(), 0.0);
}

}  // namespace
}  // namespace uwb
