/** @file LocalizeCliTest.cpp
 *  @brief `uwbtdoa localize` on a real flight through the command line: the ToF option by flag and by config file
 *         (docs/math/filter.md F21), its counters in --json, a config key that does not exist, and --window (a
 *         part of a log, started in the air), and --format tum (the poses of the CSV, for evo).
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include "support/CliFixture.h"
#include "uwb/io/TrajectoryCsv.h"

namespace uwb {
namespace {

class LocalizeCli : public test::PilotFlightCliTest {
 protected:
  LocalizeCli() : PilotFlightCliTest("0425-traj3") {}
  nlohmann::json localize(const std::string& extra) {
    const test::CliResult r = test::runCli("localize " + flight_->string() + " --anchors " +
                                           test::pilotSurvey("0425").string() + " --json " + extra);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(r.out);
  }
  std::string writeConfig(const std::string& name, const std::string& text) { return write(name, text); }
};

TEST_F(LocalizeCli, TofFusionByFlagOrConfigUsesTheHeightSensorAndReportsItsCounters) {
  // GIVEN 0425-traj3, a flight with a Flow-deck ToF stream (airborne RMSE 0.169 m UWB-only, 0.095 m with ToF)
  // WHEN it is localized with --no-tof, with the default (ToF fused when the log has it, F21), and with the range's
  // sigma in a config file
  const nlohmann::json plain = localize("--no-tof");
  const nlohmann::json flag = localize("");
  const nlohmann::json config = localize("--config " + writeConfig("tof.json", R"({"tof_sigma_m": 0.05})"));
  // AND --no-tof overrides a config that asks for it
  const nlohmann::json overridden =
      localize("--no-tof --config " + writeConfig("tof_on.json", R"({"fuse_tof": true})"));
  EXPECT_EQ(overridden["n_tof_used"].get<int>(), 0);
  EXPECT_FALSE(overridden["fuse_tof"].get<bool>());
  // THEN without it no reading is used; with it most readings are used and the height error collapses
  EXPECT_EQ(plain["n_tof_used"].get<int>(), 0);
  for (const nlohmann::json* j : {&flag, &config}) {
    EXPECT_GT((*j)["n_tof_used"].get<int>(), 500);
    EXPECT_LT((*j)["airborne"]["rmse_z_m"].get<double>(), 0.05);
    EXPECT_LT((*j)["rmse_airborne_m"].get<double>(), 0.13);
    EXPECT_LT((*j)["rmse_airborne_m"].get<double>(), plain["rmse_airborne_m"].get<double>() - 0.04);
  }
  // AND the config's sigma took effect (a different, still good, estimate)
  EXPECT_NE(flag["rmse_airborne_m"].get<double>(), config["rmse_airborne_m"].get<double>());
}

TEST_F(LocalizeCli, AnUnknownConfigKeyIsAClearError) {
  const std::string cfg = writeConfig("typo.json", R"({"fuse_toff": true})");
  const test::CliResult r = test::runCli("localize " + flight_->string() + " --anchors " +
                                         test::pilotSurvey("0425").string() + " --json --config " + cfg);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("fuse_toff"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST_F(LocalizeCli, AWindowLocalizesThePartOfTheLogAsALogStartedInTheAir) {
  // GIVEN 0425-traj3 (take-off at about 3 s, landing at about 29.6 s)
  const nlohmann::json whole = localize("--no-diagnostics");
  // WHEN only 10 … 28.57 s of it is localized (the protocol's cut at 10 s, docs/results.md)
  const std::string traj = path("window.csv");
  const nlohmann::json cut = localize("--no-diagnostics --window 10,28.57 --out " + traj);
  // THEN the filter starts in motion from the window's first samples and holds the protocol's bound for cuts
  EXPECT_EQ(cut["window_s"], nlohmann::json({10.0, 28.57}));
  EXPECT_TRUE(whole["window_s"].is_null());
  EXPECT_TRUE(cut["started_in_motion"].get<bool>());
  EXPECT_FALSE(whole["started_in_motion"].get<bool>());
  EXPECT_LT(cut["n_tdoa"].get<int>(), whole["n_tdoa"].get<int>() * 3 / 4);
  EXPECT_LT(cut["rmse_airborne_m"].get<double>(), 0.30);  // 0.188 m measured
  EXPECT_LT(cut["duration_s"].get<double>(), 18.6);
  // AND the trajectory holds only stamps inside the window
  std::ifstream csv(traj);
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  double first = -1.0, last = -1.0;
  while (std::getline(csv, line)) {
    const double t = std::stod(line.substr(0, line.find(',')));
    if (first < 0.0) first = t;
    last = t;
  }
  EXPECT_GE(first, 10.0);
  EXPECT_LE(last, 28.57);
  EXPECT_GT(last - first, 15.0);
}

TEST_F(LocalizeCli, AWindowThatIsReversedOrHoldsNoTdoaIsAClearError) {
  for (const char* window : {"20,10", "500,600", "nan,5"}) {
    const test::CliResult r = test::runCli("localize " + flight_->string() + " --anchors " +
                                           test::pilotSurvey("0425").string() + " --json --window " + std::string(window));
    EXPECT_NE(r.exit_code, 0) << window;
    EXPECT_NE(r.err.find("--window"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << window;
  }
  // the span of the log is named where the window misses it
  const test::CliResult r = test::runCli("localize " + flight_->string() + " --anchors " +
                                         test::pilotSurvey("0425").string() + " --window 500,600");
  EXPECT_NE(r.err.find("0.000 to 31.845 s"), std::string::npos) << r.err;
}

TEST_F(LocalizeCli, TumOutputHoldsTheSamePosesAsTheCsv) {
  // GIVEN the trajectory of a real flight written as CSV and, by a second run, as TUM (`--format tum`, for evo)
  const std::string csv = path("traj.csv"), tum = path("traj.tum");
  localize("--no-diagnostics --out " + csv);
  localize("--no-diagnostics --format tum --out " + tum);
  // WHEN both are read back
  const Trajectory a = readTrajectoryCsv(csv);
  const Trajectory b = readTrajectoryTum(tum);
  // THEN the same samples: times, positions and quaternions agree to 1e-9
  ASSERT_GT(a.size(), 1000u);
  ASSERT_EQ(a.size(), b.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    worst = std::max(worst, std::abs(a[i].t_s - b[i].t_s));
    worst = std::max(worst, (a[i].w_p_b - b[i].w_p_b).cwiseAbs().maxCoeff());
    worst = std::max(worst, (a[i].w_q_b.coeffs() - b[i].w_q_b.coeffs()).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(worst, 1e-9);
  // AND every TUM line is 8 space-separated numbers after the column comment
  std::ifstream in(tum);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "# timestamp tx ty tz qx qy qz qw");
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(std::count(line.begin(), line.end(), ' '), 7) << line;
  EXPECT_EQ(line.find(','), std::string::npos) << line;
  // AND an unknown format is refused before anything runs
  const test::CliResult r = test::runCli("localize " + flight_->string() + " --anchors " +
                                         test::pilotSurvey("0425").string() + " --format kitti --out " + csv);
  EXPECT_NE(r.exit_code, 0);
}

}  // namespace
}  // namespace uwb
