/** @file MultilaterationTest.cpp
 *  @brief Robust Gauss–Newton TDoA multilateration (docs/math/filter.md F16) on hand-computed geometries.
 *
 *  The tag sits at w_p_tag = (0, 0, 1) and the five anchors at whole-number distances from it:
 *    a0 = (3, 4, 1) → 5,  a1 = (−4, 3, 1) → 5,  a2 = (0, 0, 4) → 3,  a3 = (6, 0, 9) → 10,  a4 = (0, −12, 6) → 13,
 *  so the TDoA of a pair (i, j), |p − a_j| − |p − a_i| (paper eq. 2), is a difference of those integers.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "uwb/filter/Multilateration.h"

namespace uwb {
namespace {

AnchorTable handAnchors() {
  AnchorTable t;
  t.set(0, Vec3(3, 4, 1));
  t.set(1, Vec3(-4, 3, 1));
  t.set(2, Vec3(0, 0, 4));
  t.set(3, Vec3(6, 0, 9));
  t.set(4, Vec3(0, -12, 6));
  return t;
}

/// The six TDoAs of a tag at (0, 0, 1), computed by hand from the distances 5, 5, 3, 10, 13.
std::vector<MultilaterationSample> handSamples(const Vec3& w_d_b = Vec3::Zero(), const Quat& w_q_b = Quat::Identity()) {
  const struct {
    int a, b;
    double tdoa_m;
  } pairs[] = {{0, 1, 5.0 - 5.0}, {1, 2, 3.0 - 5.0}, {2, 3, 10.0 - 3.0},
               {3, 4, 13.0 - 10.0}, {4, 0, 5.0 - 13.0}, {0, 2, 3.0 - 5.0}};
  std::vector<MultilaterationSample> out;
  for (const auto& p : pairs) {
    MultilaterationSample s;
    s.z.id_a = p.a;
    s.z.id_b = p.b;
    s.z.tdoa_m = p.tdoa_m;
    s.w_d_b = w_d_b;
    s.w_q_b = w_q_b;
    out.push_back(s);
  }
  return out;
}

TEST(Multilaterate, GivenExactTdoasOfAStaticTagWhenSolvedThenFindsTheTag) {
  // GIVEN six exact TDoAs of a tag at (0, 0, 1), no lever arm, a start 1.7 m away
  // WHEN multilaterating
  const auto res = multilaterate(handSamples(), handAnchors(), Vec3::Zero(), {Vec3(1.0, -1.0, 2.0)});
  // THEN the solution is the tag, every sample is used and the residual vanishes
  ASSERT_TRUE(res);
  EXPECT_LT((res->w_p0 - Vec3(0, 0, 1)).norm(), 1e-9) << res->w_p0.transpose();
  EXPECT_EQ(res->n_used, 6u);
  EXPECT_LT(res->rms_residual_m, 1e-5);  // the residual of the iterate before the last (converged) step
  EXPECT_GE(res->iterations, 2);
}

TEST(Multilaterate, GivenKnownDisplacementsWhenSolvedThenReturnsTheReferencePosition) {
  // GIVEN the same TDoAs, each taken after the body moved by d = (1, 0, 0) since the reference instant
  // WHEN multilaterating
  const auto res = multilaterate(handSamples(Vec3(1, 0, 0)), handAnchors(), Vec3::Zero(), {Vec3(0, 0, 2)});
  // THEN p0 = (0, 0, 1) − d
  ASSERT_TRUE(res);
  EXPECT_LT((res->w_p0 - Vec3(-1, 0, 1)).norm(), 1e-9) << res->w_p0.transpose();
}

TEST(Multilaterate, GivenALeverArmWhenSolvedThenReturnsTheBodyOriginNotTheTag) {
  // GIVEN a tag 0.5 m above the body origin (b_t_tag = (0, 0, 0.5))
  const Vec3 b_t_tag(0, 0, 0.5);
  // WHEN the body is level, THEN the body origin is 0.5 m below the tag: (0, 0, 0.5)
  const auto level = multilaterate(handSamples(), handAnchors(), b_t_tag, {Vec3(0, 0, 2)});
  ASSERT_TRUE(level);
  EXPECT_LT((level->w_p0 - Vec3(0, 0, 0.5)).norm(), 1e-9) << level->w_p0.transpose();
  // WHEN the body is upside down (180° about x, so R b_t_tag = (0, 0, −0.5)), THEN it is 0.5 m above: (0, 0, 1.5)
  const Quat flipped(Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitX()));
  const auto upside_down = multilaterate(handSamples(Vec3::Zero(), flipped), handAnchors(), b_t_tag, {Vec3(0, 0, 2)});
  ASSERT_TRUE(upside_down);
  EXPECT_LT((upside_down->w_p0 - Vec3(0, 0, 1.5)).norm(), 1e-9) << upside_down->w_p0.transpose();
}

TEST(Multilaterate, GivenOneGrossOutlierWhenSolvedThenHuberKeepsTheSolutionClose) {
  // GIVEN the six TDoAs plus four more of the well-determined pairs, one of them off by 2 m
  std::vector<MultilaterationSample> s = handSamples();
  const std::vector<MultilaterationSample> again = handSamples();
  s.insert(s.end(), again.begin(), again.begin() + 4);
  s[3].z.tdoa_m += 2.0;
  // WHEN multilaterating with the default Huber threshold (0.3 m) and with plain least squares (huge threshold)
  const auto robust = multilaterate(s, handAnchors(), Vec3::Zero(), {Vec3(0, 0, 2)});
  const auto plain = multilaterate(s, handAnchors(), Vec3::Zero(), {Vec3(0, 0, 2)}, 1e6);
  // THEN the robust solution is closer to the tag than the least-squares one
  ASSERT_TRUE(robust && plain);
  EXPECT_LT((robust->w_p0 - Vec3(0, 0, 1)).norm(), (plain->w_p0 - Vec3(0, 0, 1)).norm());
}

TEST(Multilaterate, GivenTooFewUsableSamplesThenNoSolution) {
  // GIVEN three samples, or six whose anchors are missing from the table but three
  const std::vector<MultilaterationSample> all = handSamples();
  const std::vector<MultilaterationSample> three(all.begin(), all.begin() + 3);
  AnchorTable partial;
  partial.set(0, Vec3(3, 4, 1));
  partial.set(1, Vec3(-4, 3, 1));
  partial.set(2, Vec3(0, 0, 4));
  // THEN there is no solution (fewer than 4 usable samples), nor without any start
  EXPECT_FALSE(multilaterate(three, handAnchors(), Vec3::Zero(), {Vec3(0, 0, 2)}));
  EXPECT_FALSE(multilaterate(all, partial, Vec3::Zero(), {Vec3(0, 0, 2)}));  // only (0,1), (1,2), (0,2) usable
  EXPECT_FALSE(multilaterate(all, handAnchors(), Vec3::Zero(), {}));
}

TEST(Multilaterate, GivenTwoStartsWhenOneIsBadThenTheLowerCostSolutionWins) {
  // GIVEN a good start and one far outside the anchors
  const auto res = multilaterate(handSamples(), handAnchors(), Vec3::Zero(), {Vec3(50, 50, -50), Vec3(0.5, 0.5, 1.5)});
  // THEN the returned solution is the tag
  ASSERT_TRUE(res);
  EXPECT_LT((res->w_p0 - Vec3(0, 0, 1)).norm(), 1e-9);
}


/// (F16f) A room like the util-pilot arena: four anchors near the floor (z = 0.2 m) and four at 3 m, the body on the
/// floor; the floor-level anchors are seen by paths longer by `delay` (per anchor), the others directly. The pairs
/// of the LPS TDoA2 ring (k, k + 1 mod 8: floor-level and high anchors alternate), each measured `repeat` times.
struct FloorRoom {
  AnchorTable anchors;
  std::vector<unsigned char> floor_level;
  std::vector<MultilaterationSample> samples;
};
FloorRoom floorRoom(const Vec3& w_p_b, const std::vector<double>& delay, int repeat = 3) {
  FloorRoom r;
  const Vec3 corners[] = {{-3.5, -4.0, 0.0}, {-3.3, 3.8, 0.0}, {3.6, 3.7, 0.0}, {4.0, -4.2, 0.0}};
  for (int k = 0; k < 4; ++k) {
    r.anchors.set(2 * k, corners[k] + Vec3(0, 0, 0.2));                          // floor-level
    r.anchors.set(2 * k + 1, corners[(k + 1) % 4] + Vec3(0.3, -0.2, 3.0));       // high
  }
  r.floor_level.assign(8, 0);
  for (int k = 0; k < 4; ++k) r.floor_level[2 * k] = 1;
  const auto range = [&](int id) {
    const double g = r.floor_level[id] ? delay[id / 2] : 0.0;
    return (w_p_b - r.anchors.find(id)->m).norm() + g;
  };
  for (int n = 0; n < repeat; ++n)
    for (int a = 0; a < 8; ++a) {
      const int b = (a + 1) % 8;
      MultilaterationSample s;
      s.z.id_a = a;
      s.z.id_b = b;
      s.z.tdoa_m = range(b) - range(a);
      r.samples.push_back(s);
    }
  return r;
}

TEST(MultilaterateOnFloorWithDelays, GivenFloorLevelAnchorsSeenLateWhenSolvedThenFindsTheBodyAndTheDelays) {
  // GIVEN a body on the floor at (1.5, 0.2, 0) and the four floor-level anchors seen 2.8 / 3.2 / 3.9 / 2.9 m late (the
  // delays of the util-pilot 0425 floor starts)
  const Vec3 truth(1.5, 0.2, 0.0);
  const std::vector<double> delay = {2.8, 3.2, 3.9, 2.9};
  const FloorRoom room = floorRoom(truth, delay);
  const std::vector<Vec3> guesses = {Vec3(0.0, 0.0, 0.5), Vec3(0.0, 0.0, 1.5)};
  // WHEN solving on the floor without and with the delays
  const auto plain = multilaterateOnFloor(room.samples, room.anchors, Vec3::Zero(), guesses, 0.0);
  const auto with = multilaterateOnFloorWithDelays(room.samples, room.anchors, Vec3::Zero(), guesses, 0.0,
                                                   room.floor_level);
  // THEN the plain solve is pulled far off, the solve with delays finds the body and each delay (to within the
  // shrinkage of the weak N(0, (5 m)²) prior on the delays: λ/Σw ≈ 0.1 % of a delay with three samples per pair)
  ASSERT_TRUE(plain);
  ASSERT_TRUE(with);
  EXPECT_GT((plain->w_p0 - truth).norm(), 0.5) << plain->w_p0.transpose();
  EXPECT_LT((with->w_p0 - truth).norm(), 0.01) << with->w_p0.transpose();
  EXPECT_EQ(with->w_p0.z(), 0.0);
  ASSERT_EQ(with->anchor_delay_m.size(), 7u);  // up to the highest floor-level id seen
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(with->anchor_delay_m[2 * k], delay[k], 0.01) << "anchor " << 2 * k;
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isnan(with->anchor_delay_m[2 * k + 1])) << "anchor " << 2 * k + 1;
  EXPECT_EQ(with->covariance(2, 2), 0.0);
  EXPECT_GT(with->covariance(0, 0), 0.0);
}

TEST(MultilaterateOnFloorWithDelays, GivenNoDelaysWhenSolvedThenAgreesWithThePlainSolve) {
  // GIVEN exact TDoAs (no delay): the delays are free parameters that should come out zero
  const Vec3 truth(-0.7, 1.1, 0.0);
  const FloorRoom room = floorRoom(truth, {0.0, 0.0, 0.0, 0.0});
  const auto with = multilaterateOnFloorWithDelays(room.samples, room.anchors, Vec3::Zero(), {Vec3(0, 0, 1)}, 0.0,
                                                   room.floor_level);
  ASSERT_TRUE(with);
  EXPECT_LT((with->w_p0 - truth).norm(), 1e-4);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(with->anchor_delay_m[2 * k], 0.0, 1e-4);
}

TEST(MultilaterateOnFloorWithDelays, GivenDelaysOutsideTheirPlausibleRangeThenNoSolution) {
  // GIVEN TDoA whose fitted delays would be 8 m (longer than the room: not a floor path) or −3 m (a shorter path)
  for (const double g : {8.0, -3.0}) {
    const FloorRoom room = floorRoom(Vec3(1.5, 0.2, 0.0), {g, g, g, g});
    // WHEN solving with the delays
    const auto with = multilaterateOnFloorWithDelays(room.samples, room.anchors, Vec3::Zero(), {Vec3(0, 0, 1)}, 0.0,
                                                     room.floor_level);
    // THEN there is no solution (the caller falls back to the plain solve), while 6 m and −1 m are still accepted
    EXPECT_FALSE(with) << g;
  }
  for (const double g : {kMaxFloorDelay_m - 0.01, kMinFloorDelay_m + 0.01}) {
    const FloorRoom room = floorRoom(Vec3(1.5, 0.2, 0.0), {g, g, g, g});
    const auto with = multilaterateOnFloorWithDelays(room.samples, room.anchors, Vec3::Zero(), {Vec3(0, 0, 1)}, 0.0,
                                                     room.floor_level);
    ASSERT_TRUE(with) << g;
    EXPECT_NEAR(with->anchor_delay_m[0], g, 0.01);
  }
}

TEST(MultilaterateOnFloorWithDelays, GivenFewerThanThreeOtherAnchorsThenNoSolution) {
  // GIVEN only pairs among the floor-level anchors and two high ones: x and y are not determined by the others
  const FloorRoom room = floorRoom(Vec3(1, 1, 0), {3.0, 3.0, 3.0, 3.0});
  std::vector<MultilaterationSample> few;
  for (const MultilaterationSample& s : room.samples)
    if ((room.floor_level[s.z.id_a] || s.z.id_a <= 3) && (room.floor_level[s.z.id_b] || s.z.id_b <= 3))
      few.push_back(s);
  ASSERT_FALSE(few.empty());
  EXPECT_FALSE(
      multilaterateOnFloorWithDelays(few, room.anchors, Vec3::Zero(), {Vec3(0, 0, 1)}, 0.0, room.floor_level));
  // and without any floor-level anchor marked it is the plain solve
  const auto none = multilaterateOnFloorWithDelays(room.samples, room.anchors, Vec3::Zero(), {Vec3(0, 0, 1)}, 0.0,
                                                   std::vector<unsigned char>(8, 0));
  const auto plain = multilaterateOnFloor(room.samples, room.anchors, Vec3::Zero(), {Vec3(0, 0, 1)}, 0.0);
  ASSERT_TRUE(none && plain);
  EXPECT_EQ(none->w_p0, plain->w_p0);
  EXPECT_TRUE(none->anchor_delay_m.empty());
}

TEST(DistinctAnchors, GivenPairsSharingAnchorsWhenCountedThenEachAnchorCountsOnce) {
  DistinctAnchors anchors;
  EXPECT_EQ(anchors.count(), 0);
  anchors.add(0, 1);
  anchors.add(1, 2);
  anchors.add(2, 0);
  EXPECT_EQ(anchors.count(), 3);  // two TDoA2 pairs of a cycle: three anchors, not enough for a fix in the air
  EXPECT_LT(anchors.count(), minFixAnchors(false));
  EXPECT_GE(anchors.count(), minFixAnchors(true));
  anchors.add(7, 2);
  EXPECT_EQ(anchors.count(), 4);
  EXPECT_GE(anchors.count(), minFixAnchors(false));
}

TEST(DistinctAnchors, GivenMoreIdsThanItHoldsThenTheCountStopsAtItsCapacity) {
  DistinctAnchors anchors;
  for (int id = 0; id < 400; id += 2) anchors.add(id, id + 1);
  EXPECT_EQ(anchors.count(), 128);
}

}  // namespace
}  // namespace uwb
