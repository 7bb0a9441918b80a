/** @file PoseTrackTest.cpp
 *  @brief Ground-truth track: interpolation, gaps, glitch rejection (synthetic and real).
 */
#include "uwb/io/PoseTrack.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "IoTestHelpers.h"
#include "uwb/io/UtilCsv.h"

namespace uwb {
namespace {

using test::circle;
using test::cornerSurvey;
using test::roll;
using test::yaw;

TEST(PoseTrack, InterpolatesPositionLinearlyAndAttitudeBySlerp) {
  // GIVEN two samples 10 ms apart, yaw 0 → 0.2 rad
  const std::vector<PoseSample> s = {{1.0, Vec3(0, 0, 1), yaw(0.0)}, {1.01, Vec3(0.1, -0.2, 1.3), yaw(0.2)}};
  const PoseTrack track(s, /*has_orientation=*/true);
  // WHEN interpolated a quarter of the way
  const auto p = track.interpolate(1.0025);
  // THEN position is linear and the attitude is the slerp (yaw 0.05 rad)
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->t_s, 1.0025, 0);
  EXPECT_TRUE(p->w_p_b.isApprox(Vec3(0.025, -0.05, 1.075), 1e-12));
  EXPECT_NEAR(p->w_q_b.angularDistance(yaw(0.05)), 0.0, 1e-9);
  // and the end points are reproduced
  EXPECT_TRUE(track.interpolate(1.0)->w_p_b.isApprox(s[0].w_p_b));
  EXPECT_TRUE(track.interpolate(1.01)->w_p_b.isApprox(s[1].w_p_b));
}

TEST(InterpolatePose, AnySampleTypeIsInterpolatedTheSameWay) {
  // GIVEN filter output samples (TrajectorySample-like: t_s, w_p_b, w_q_b) 0.1 s apart, yawing by 90°
  struct Sample {
    double t_s;
    Vec3 w_p_b;
    Quat w_q_b;
  };
  const std::vector<Sample> s = {{1.0, Vec3(0, 0, 1), yaw(0.0)}, {1.1, Vec3(1, 2, 1), yaw(std::numbers::pi / 2)}};
  // WHEN interpolating a quarter of the way, at a sample, and outside
  const auto q = interpolatePose(s, 1.025, 0.2);
  const auto at_first = interpolatePose(s, 1.0, 0.2);
  const auto at_last = interpolatePose(s, 1.1, 0.2);
  // THEN the position is linear and the attitude the slerp (yaw 22.5°), samples are returned as they are
  ASSERT_TRUE(q && at_first && at_last);
  EXPECT_LT((q->w_p_b - Vec3(0.25, 0.5, 1)).norm(), 1e-12);
  EXPECT_NEAR(q->w_q_b.angularDistance(yaw(std::numbers::pi / 8)), 0.0, 1e-12);
  EXPECT_EQ(at_first->w_p_b, s[0].w_p_b);
  EXPECT_EQ(at_last->w_p_b, s[1].w_p_b);
  EXPECT_FALSE(interpolatePose(s, 0.99, 0.2));
  EXPECT_FALSE(interpolatePose(s, 1.11, 0.2));
  EXPECT_FALSE(interpolatePose(s, 1.05, 0.05));  // the samples are 0.1 s apart: a gap for max_gap_s = 0.05
  // AND without orientation the attitude is the identity
  EXPECT_EQ(interpolatePose(s, 1.05, 0.2, false)->w_q_b.coeffs(), Quat::Identity().coeffs());
}

TEST(Airborne, IsStrictlyAboveTheThreshold) {
  // GIVEN the one airborne definition, THEN z = 0.3 m is on the ground and anything above is airborne
  EXPECT_DOUBLE_EQ(kAirborneMinZ_m, 0.3);
  EXPECT_FALSE(isAirborne(0.3));
  EXPECT_TRUE(isAirborne(std::nextafter(0.3, 1.0)));
  EXPECT_FALSE(isAirborne(-1.0));
  EXPECT_TRUE(isAirborne(0.5, 0.4));
  EXPECT_FALSE(isAirborne(0.35, 0.4));
}

TEST(PoseTrack, NoGroundTruthOutsideTheTrackOrAcrossAGap) {
  // GIVEN samples at 0, 0.01, then a 60 ms gap to 0.07
  const std::vector<PoseSample> s = {
      {0.0, Vec3::Zero(), Quat::Identity()}, {0.01, Vec3::Zero(), Quat::Identity()}, {0.07, Vec3::Zero(), Quat::Identity()}};
  const PoseTrack track(s, true);
  EXPECT_FALSE(track.interpolate(-0.001).has_value());
  EXPECT_FALSE(track.interpolate(0.0701).has_value());
  EXPECT_TRUE(track.interpolate(0.005).has_value());
  EXPECT_FALSE(track.interpolate(0.03).has_value()) << "across a gap > 50 ms";
  EXPECT_TRUE(track.interpolate(0.07).has_value());
  EXPECT_FALSE(PoseTrack().interpolate(0.0).has_value());
}

TEST(PoseTrack, PositionOnlyTrackInterpolatesIdentityAttitude) {
  const std::vector<PoseSample> s = {{0.0, Vec3(0, 0, 0), roll(0.5)}, {0.01, Vec3(1, 0, 0), roll(0.5)}};
  const PoseTrack track(s, /*has_orientation=*/false);
  const auto p = track.interpolate(0.005);
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->w_q_b.isApprox(Quat::Identity()));
  EXPECT_FALSE(track.hasOrientation());
}

TEST(PoseTrack, SmoothFastCircleHasNoGlitches) {
  // GIVEN a 2 m/s circle at 200 Hz with a few sparse stretches (every 8th sample kept for 1 s)
  std::vector<PoseSample> s = circle(200.0, 10.0, /*omega=*/1.4);
  std::vector<PoseSample> sparse;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i].t_s > 4.0 && s[i].t_s < 5.0 && i % 8 != 0) continue;
    sparse.push_back(s[i]);
  }
  const PoseTrack track(sparse, true);
  EXPECT_TRUE(track.glitches().empty()) << "first glitch at t=" << track.glitches().front().t_s;
  EXPECT_EQ(track.samples().size(), sparse.size());
}

TEST(PoseTrack, SingleSampleRollFlipIsRejectedAndCounted) {
  // GIVEN a circle with one sample rolled by 170° (the 0425-traj9 / 0426-traj12 glitch)
  std::vector<PoseSample> s = circle(250.0, 4.0);
  const std::size_t k = 500;
  s[k].w_q_b = s[k].w_q_b * roll(170.0 * kDegToRad);
  // WHEN the track is built
  const PoseTrack track(s, true);
  // THEN exactly that sample is rejected as an attitude glitch and interpolation skips it
  ASSERT_EQ(track.glitches().size(), 1u);
  EXPECT_EQ(track.glitches()[0].index, k);
  EXPECT_EQ(track.glitches()[0].kind, PoseGlitchKind::kAttitude);
  EXPECT_NEAR(track.glitches()[0].magnitude, 170.0 * kDegToRad, 0.01);
  EXPECT_EQ(track.countGlitches(PoseGlitchKind::kAttitude), 1u);
  EXPECT_EQ(track.samples().size(), s.size() - 1);
  const auto p = track.interpolate(s[k].t_s);
  ASSERT_TRUE(p);
  EXPECT_LT(p->w_q_b.angularDistance(s[k - 1].w_q_b), 0.01);
}

TEST(PoseTrack, RunOfFlippedAttitudesIsRejected) {
  // GIVEN six consecutive flipped samples (≈ 25 ms), as in 0425-traj9 at t ≈ 14.0 s
  std::vector<PoseSample> s = circle(250.0, 4.0);
  for (std::size_t k = 300; k < 306; ++k) s[k].w_q_b = s[k].w_q_b * roll(-171.0 * kDegToRad);
  const PoseTrack track(s, true);
  EXPECT_EQ(track.countGlitches(PoseGlitchKind::kAttitude), 6u);
  EXPECT_TRUE(track.interpolate(s[302].t_s).has_value()) << "a 28 ms hole is still interpolated";
}

TEST(PoseTrack, GlitchAtTheVeryStartIsRejected) {
  std::vector<PoseSample> s = circle(250.0, 1.0);
  s[0].w_q_b = s[0].w_q_b * roll(kPi * 0.95);
  const PoseTrack track(s, true);
  ASSERT_EQ(track.glitches().size(), 1u);
  EXPECT_EQ(track.glitches()[0].index, 0u);
}

TEST(PoseTrack, LastingAttitudeChangeIsMotionNotAGlitch) {
  // GIVEN a step of 90° in yaw that lasts (not a physical motion, but it persists for 0.5 s)
  std::vector<PoseSample> s = circle(250.0, 1.0);
  for (std::size_t k = 100; k < s.size(); ++k) s[k].w_q_b = yaw(kPi / 2);
  const PoseTrack track(s, true);
  // THEN only the samples within max_glitch_run_s of the step are rejected, then it is accepted
  EXPECT_LE(static_cast<double>(track.glitches().size()), 0.1 * 250.0 + 2);
  EXPECT_TRUE(track.interpolate(0.9).has_value());
  EXPECT_LT(track.interpolate(0.9)->w_q_b.angularDistance(yaw(kPi / 2)), 1e-9);
}

TEST(PoseTrack, PositionSpikeIsRejected) {
  // GIVEN a 0.23 m single-sample jump (0425-traj9 t ≈ 9.69 s) and a 4.6 cm one (0425-traj10)
  std::vector<PoseSample> s = circle(270.0, 3.0);
  s[200].w_p_b += Vec3(0.23, 0.0, 0.0);
  s[500].w_p_b += Vec3(0.0, -0.046, 0.0);
  const PoseTrack track(s, true);
  ASSERT_EQ(track.glitches().size(), 2u);
  EXPECT_EQ(track.glitches()[0].index, 200u);
  EXPECT_EQ(track.glitches()[0].kind, PoseGlitchKind::kPosition);
  EXPECT_NEAR(track.glitches()[0].magnitude, 0.23, 0.005);
  EXPECT_EQ(track.glitches()[1].index, 500u);
  EXPECT_EQ(track.countGlitches(PoseGlitchKind::kPosition), 2u);
}

TEST(PoseTrack, InvalidParamsAndUnsortedSamplesThrow) {
  PoseTrackParams bad;
  bad.max_gap_s = 0.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  EXPECT_THROW(PoseTrack({}, true, bad), std::invalid_argument);
  const std::vector<PoseSample> unsorted = {{1.0, Vec3::Zero(), Quat::Identity()}, {0.5, Vec3::Zero(), Quat::Identity()}};
  EXPECT_THROW(PoseTrack(unsorted, true), std::invalid_argument);
}

TEST(RealDataPoseTrack, Traj9GlitchesFromSourceMdAreFound) {
  const auto path = test::pilotFlight("0425-traj9");
  UWB_REQUIRE_REAL_DATA(path);
  const Flight f = readFlightCsv(path->string());
  const PoseTrack track(f);
  // SOURCE.md: roll ≈ ±170° near t ≈ 14.1 s and a 0.23 m position jump
  bool attitude_near_14 = false;
  double max_position_jump = 0.0;
  for (const auto& g : track.glitches()) {
    if (g.kind == PoseGlitchKind::kAttitude && std::abs(g.t_s - 14.05) < 0.1) attitude_near_14 = true;
    if (g.kind == PoseGlitchKind::kPosition) max_position_jump = std::max(max_position_jump, g.magnitude);
  }
  EXPECT_TRUE(attitude_near_14);
  EXPECT_NEAR(max_position_jump, 0.23, 0.01);
  EXPECT_LT(track.glitches().size(), 30u) << "glitches are rare";
  // no accepted sample is rolled more than 90° (the drone never flips)
  for (const auto& s : track.samples()) {
    const Vec3 b_z_w = s.w_q_b.conjugate() * Vec3::UnitZ();
    EXPECT_GT(b_z_w.z(), 0.0) << "t=" << s.t_s;
  }
}

TEST(RealDataPoseTrack, FlightsWithoutKnownGlitchesHaveFew) {
  const auto path = test::pilotFlight("0425-traj2");
  UWB_REQUIRE_REAL_DATA(path);
  const PoseTrack track(readFlightCsv(path->string()));
  EXPECT_LE(track.glitches().size(), 3u);
}

}  // namespace
}  // namespace uwb
