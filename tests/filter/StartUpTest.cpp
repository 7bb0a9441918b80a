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
/// Only the pairs (k, k + 1) with k < n_pairs are heard when n_pairs < 8 (an occluded tag).
std::optional<StartFix> runStart(StartUp& start, const AnchorTable& anchors, const Vec3& w_p_b,
                                 std::optional<double> floor_z_m, bool refutable = true, int n_pairs = 8) {
  const NavState held;  // the prediction on the ground: zero velocity, the displacements vanish
  for (int k = 0; k < 2000; ++k) {
    TdoaMeasurement z;
    z.t_s = 0.0025 * k;
    z.id_a = k % n_pairs;
    z.id_b = (z.id_a + 1) % 8;
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

TEST(StartUp, GivenAReacquisitionOnTheFloorTheFloorIsTestedOnlyWhenTheCallerAsks) {
  // GIVEN a window on the floor that is not the first start (a landing's floor window, F16i) with TDoA of a body in
  // the air: the ground evidence after a flight comes with a descent and is revised by the landing logic
  const AnchorTable anchors = boxAnchors();
  StartUp start(anchors, Vec3::Zero(), StartUpParams{});
  start.begin(0.0, NavState{}, false, true);
  // WHEN the window is solved without a floor test
  const std::optional<StartFix> fix = runStart(start, anchors, Vec3(1.5, 2.5, 1.5), 0.0, false);
  // THEN the fix stays on the floor
  ASSERT_TRUE(fix);
  EXPECT_FALSE(fix->floor_refuted);
  EXPECT_EQ(fix->w_p_b.z(), 0.0);
  // WHEN the same window is a floor check of floor contact (filter.md F29e): the floor may be refuted
  StartUp check(anchors, Vec3::Zero(), StartUpParams{});
  check.begin(0.0, NavState{}, false, true);
  const std::optional<StartFix> refuted = runStart(check, anchors, Vec3(1.5, 2.5, 1.5), 0.0, true);
  // THEN the TDoA put the body in the air
  ASSERT_TRUE(refuted);
  EXPECT_TRUE(refuted->floor_refuted);
  EXPECT_NEAR(refuted->w_p_b.z(), 1.5, 0.1);
}

TEST(StartUp, GivenTdoaOfFewerAnchorsThanAFixNeedsWhenSolvedThenThereIsNoFix) {
  const AnchorTable anchors = boxAnchors();
  const Vec3 p(1.5, 2.5, 1.4);
  for (const bool moving : {false, true}) {
    SCOPED_TRACE(moving ? "in motion" : "at rest");
    // GIVEN a tag in the air that hears only the pairs (0, 1) and (1, 2): three anchors, a curve of positions
    StartUp start(anchors, Vec3::Zero(), StartUpParams{});
    start.begin(0.0, NavState{}, moving, true);
    // WHEN its window is solved for 5 s of TDoA
    // THEN no fix comes out of it (F16k: it would be a point of the curve with the covariance of a fix)
    EXPECT_FALSE(runStart(start, anchors, p, std::nullopt, false, 2));
    // AND with the pair (2, 3) heard too (four anchors) the fix is the position
    StartUp four(anchors, Vec3::Zero(), StartUpParams{});
    four.begin(0.0, NavState{}, moving, true);
    const std::optional<StartFix> fix = runStart(four, anchors, p, std::nullopt, false, 3);
    ASSERT_TRUE(fix);
    EXPECT_LT((fix->w_p0 - p).norm(), 1e-3);
  }
  // on a floor of known height three anchors are enough
  StartUp floor(anchors, Vec3::Zero(), StartUpParams{});
  floor.begin(0.0, NavState{}, false, true);
  const std::optional<StartFix> on_floor = runStart(floor, anchors, Vec3(1.5, 2.5, 0.0), 0.0, false, 2);
  ASSERT_TRUE(on_floor);
  EXPECT_LT((on_floor->w_p_b.head<2>() - Vec2(1.5, 2.5)).norm(), 1e-3);
}

}  // namespace
}  // namespace uwb
