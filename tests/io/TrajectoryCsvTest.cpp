/** @file TrajectoryCsvTest.cpp
 *  @brief Estimated-trajectory CSV: exact round trip and malformed input.
 */
#include "uwb/io/TrajectoryCsv.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <random>

#include "IoTestHelpers.h"
#include "uwb/core/Error.h"

namespace uwb {
namespace {

using test::TempDir;

/// What arbitraryTrajectory draws: the whole filter state at exact times, or the pose at times off by draws of 0.1 µs.
enum class Arbitrary { kWholeState, kTimeAndPose };

/// 50 samples 10 ms apart whose values are standard normal draws (seed `seed`), in the order of the sample's fields.
Trajectory arbitraryTrajectory(unsigned seed, Arbitrary what) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  Trajectory traj;
  for (int i = 0; i < 50; ++i) {
    TrajectorySample s;
    s.t_s = what == Arbitrary::kTimeAndPose ? 0.01 * i + 1e-7 * n(rng) : 0.01 * i;
    s.w_p_b = Vec3(n(rng), n(rng), n(rng));
    s.w_q_b = Quat(n(rng), n(rng), n(rng), n(rng)).normalized();
    if (what == Arbitrary::kWholeState) {
      s.sigma_p_m = Vec3(n(rng), n(rng), n(rng)).cwiseAbs();
      s.w_v_b = Vec3(n(rng), n(rng), n(rng));
      s.b_acc_bias = Vec3(n(rng), n(rng), n(rng));
      s.b_gyro_bias = Vec3(n(rng), n(rng), n(rng));
    }
    traj.push_back(s);
  }
  return traj;
}

TEST(TrajectoryCsv, RoundTripIsExact) {
  // GIVEN a trajectory with arbitrary doubles (seed 3)
  const Trajectory traj = arbitraryTrajectory(3, Arbitrary::kWholeState);
  // WHEN written and read back
  const TempDir dir;
  writeTrajectoryCsv(traj, dir.file("t.csv"));
  const Trajectory back = readTrajectoryCsv(dir.file("t.csv"));
  // THEN bit-identical, the IMU biases included
  ASSERT_EQ(back.size(), traj.size());
  for (std::size_t i = 0; i < traj.size(); ++i) {
    EXPECT_TRUE(test::sameBits(back[i].t_s, traj[i].t_s));
    EXPECT_TRUE(test::sameBits(back[i].w_p_b, traj[i].w_p_b));
    EXPECT_TRUE(test::sameBits(back[i].w_q_b, traj[i].w_q_b));
    EXPECT_TRUE(test::sameBits(back[i].sigma_p_m, traj[i].sigma_p_m));
    EXPECT_TRUE(test::sameBits(back[i].w_v_b, traj[i].w_v_b));
    EXPECT_TRUE(test::sameBits(back[i].b_acc_bias, traj[i].b_acc_bias));
    EXPECT_TRUE(test::sameBits(back[i].b_gyro_bias, traj[i].b_gyro_bias));
  }
}

TEST(TrajectoryCsv, ATrajectoryWithoutImuBiasesHasNoBiasColumnsAndAPartialSetIsAnError) {
  // GIVEN three samples, one of them without biases (not estimated)
  Trajectory traj(3);
  for (std::size_t i = 0; i < traj.size(); ++i) {
    traj[i].t_s = 0.1 * static_cast<double>(i);
    traj[i].b_acc_bias = Vec3(-0.108, 0.02, 1.0 / 3.0);
    traj[i].b_gyro_bias = Vec3(1e-3, -2e-4, 1.0 / 7.0);
  }
  traj[1].b_acc_bias = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  // WHEN written, THEN the header has the 14 columns only (a column is never partly empty), and it reads as NaN biases
  const auto header = [](const std::string& path) {
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);
    return line;
  };
  TempDir dir;
  writeTrajectoryCsv(traj, dir.file("n.csv"));
  EXPECT_EQ(header(dir.file("n.csv")), "t,x,y,z,qx,qy,qz,qw,std_x,std_y,std_z,vx,vy,vz");
  const Trajectory none = readTrajectoryCsv(dir.file("n.csv"));
  ASSERT_EQ(none.size(), traj.size());
  for (const TrajectorySample& s : none) EXPECT_FALSE(s.hasImuBias());
  // with every sample's biases the six columns follow
  traj[1].b_acc_bias = traj[0].b_acc_bias;
  writeTrajectoryCsv(traj, dir.file("b.csv"));
  EXPECT_EQ(header(dir.file("b.csv")),
            "t,x,y,z,qx,qy,qz,qw,std_x,std_y,std_z,vx,vy,vz,acc_bias_x,acc_bias_y,acc_bias_z,gyro_bias_x,gyro_bias_y,"
            "gyro_bias_z");
  // a partial set of bias columns is an error naming the first one missing
  const std::string head = "t,x,y,z,qx,qy,qz,qw,std_x,std_y,std_z,vx,vy,vz,acc_bias_x,acc_bias_y,acc_bias_z";
  test::expectThrows<InputError>(
      [&] { (void)readTrajectoryCsv(dir.write("p.csv", head + "\n0,1,2,3,0,0,0,1,0.1,0.1,0.1,0,0,0,0,0,0\n")); },
      {"missing column 'gyro_bias_x'"});
}

TEST(TrajectoryCsv, EmptyTrajectoryRoundTrips) {
  TempDir dir;
  writeTrajectoryCsv({}, dir.file("e.csv"));
  EXPECT_TRUE(readTrajectoryCsv(dir.file("e.csv")).empty());
}

TEST(TrajectoryCsv, ReadsFilesSavedWithAByteOrderMarkAndCrlfLineEnds) {
  // GIVEN a trajectory as a spreadsheet program saves it: UTF-8 BOM, CRLF, blanks around cells, a blank line
  TempDir dir;
  const std::string path = dir.write("bom.csv",
                                     "\xEF\xBB\xBFt, x,y,z,qx,qy,qz,qw,std_x,std_y,std_z,vx,vy,vz\r\n"
                                     "\r\n"
                                     "0.5, 1,2,3,0,0,0,1,0.1,0.1,0.1,0,0,0\r\n"
                                     "0.6,1,2, 3.5 ,0,0,0,1,0.1,0.1,0.1,0,0,0\r\n");
  // WHEN read
  const Trajectory t = readTrajectoryCsv(path);
  // THEN both rows arrive with their values, and an error names the line counted from the file's first line
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].t_s, 0.5);
  EXPECT_EQ(t[1].w_p_b.z(), 3.5);
  const std::string bad = dir.write("bad.csv", "\xEF\xBB\xBFt,x,y,z,qx,qy,qz,qw,std_x,std_y,std_z,vx,vy,vz\r\n\r\n"
                                              "0,1,2,3,0,0,0,1,0.1,0.1,0.1,0,0,x\r\n");
  test::expectThrows<InputError>([&] { (void)readTrajectoryCsv(bad); }, {":3:14 (vz)"});
}

TEST(TrajectoryCsv, MalformedInputNamesTheLocation) {
  TempDir dir;
  const std::string header = "t,x,y,z,qx,qy,qz,qw,std_x,std_y,std_z,vx,vy,vz\n";
  const auto expectError = [&](const std::string& text, const std::string& part) {
    const std::string path = dir.write("m.csv", text);
    SCOPED_TRACE(text);
    test::expectThrows<InputError>([&] { (void)readTrajectoryCsv(path); }, {part});
  };
  expectError("", "missing header");
  expectError("t,x,y\n", "missing column 'z'");
  expectError(header + "0,1,2,3,0,0,0,1,0.1,0.1,0.1,0,0,oops\n", ":2:14 (vz)");
  expectError(header + "1,1,2,3,0,0,0,1,0.1,0.1,0.1,0,0,0\n0.5,1,2,3,0,0,0,1,0.1,0.1,0.1,0,0,0\n", "backwards");
  expectError(header + "1,1,2,3\n", "row has 4 fields");
  EXPECT_THROW((void)readTrajectoryCsv(dir.file("none.csv")), FileError);
}

TEST(TrajectoryTum, PosesReadBackExactlyAndEvoStyleFilesRead) {
  // GIVEN a trajectory with arbitrary doubles (seed 5)
  const Trajectory traj = arbitraryTrajectory(5, Arbitrary::kTimeAndPose);
  // WHEN written as TUM and read back
  TempDir dir;
  writeTrajectoryTum(traj, dir.file("t.tum"));
  const Trajectory back = readTrajectoryTum(dir.file("t.tum"));
  // THEN every time and pose is the same double; the first line names the columns
  ASSERT_EQ(back.size(), traj.size());
  for (std::size_t i = 0; i < traj.size(); ++i) {
    EXPECT_EQ(back[i].t_s, traj[i].t_s);
    EXPECT_EQ(back[i].w_p_b, traj[i].w_p_b);
    EXPECT_EQ(back[i].w_q_b.coeffs(), traj[i].w_q_b.coeffs());
  }
  const std::string text = formatTrajectoryTum(traj);
  EXPECT_EQ(text.substr(0, text.find('\n')), "# timestamp tx ty tz qx qy qz qw");
  // AND a file as other tools write it (tabs, several spaces, comments, blank lines) reads
  const Trajectory other = parseTrajectoryTum("# evo\n\n1.5\t1 2  3 0 0 0 1\n", "other.txt");
  ASSERT_EQ(other.size(), 1u);
  EXPECT_EQ(other[0].w_p_b, Vec3(1, 2, 3));
  EXPECT_EQ(other[0].w_q_b.w(), 1.0);
  // AND a bad line names the file, line and column
  EXPECT_THAT([] { (void)parseTrajectoryTum("# c\n1 2 3 4 5 6 7\n", "f.txt"); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("f.txt:2")));
  EXPECT_THAT([] { (void)parseTrajectoryTum("1 2 x 4 5 6 7 8\n", "f.txt"); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("ty")));
}

}  // namespace
}  // namespace uwb
