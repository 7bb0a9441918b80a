/** @file CrazyflieGuideTest.cpp
 *  @brief docs/crazyflie.md end to end: a dev flight re-encoded as the uSD-card log the shipped
 *         examples/usd/config.txt makes the firmware write, anchor positions as the Crazyflie client saves them,
 *         then the guide's commands: import, survey, localize with the figure, --format tum; and the same flight
 *         without motion capture (σ, no RMSE).
 */
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include <unistd.h>

#include "support/CliFixture.h"
#include "support/UsdDeckConfig.h"
#include "uwb/io/SurveyCheck.h"
#include "uwb/io/TrajectoryCsv.h"
#include "uwb/io/UtilCsv.h"

namespace uwb {
namespace {

namespace fs = std::filesystem;

class SlowCrazyflieGuide : public test::PilotFlightCliTest {
 protected:
  SlowCrazyflieGuide() : PilotFlightCliTest("0425-traj2") {}
  /// `uwbtdoa <command> <args>` as the guide writes it, its file names taken in the test's directory.
  test::CliResult run(const std::string& command_line) const {
    std::istringstream in(command_line);
    std::string out, word;
    in >> out;  // the subcommand
    while (in >> word) out += " " + (word.find('.') != std::string::npos || word == "log00" ? path(word) : word);
    return test::runCli(out);
  }
};

TEST_F(SlowCrazyflieGuide, TheGuidesCommandsFromTheUsdLogToTheFigure) {
  // GIVEN the dev flight 0425-traj2 as the log the shipped config.txt makes the deck write ("log00"), and the
  // anchors as the Crazyflie client saves them ("anchors.yaml")
  const test::UsdDeckConfig config = test::readShippedUsdConfig();
  const Flight original = readFlightCsv(flight_->string());
  writeUsdLog(test::usdLogThroughConfig(original, config), path("log00"));
  {
    std::ofstream(path("anchors.yaml")) << formatCfclientAnchors(readAnchorSurvey(test::pilotSurvey("0425").string()));
  }
  // WHEN the guide's commands run
  const test::CliResult imp = run("import log00 --out flight.csv --json");
  ASSERT_EQ(imp.exit_code, 0) << imp.err;
  const test::CliResult sur = run("survey anchors.yaml --flight flight.csv --out survey.txt --json");
  ASSERT_EQ(sur.exit_code, 0) << sur.err;
  const test::CliResult loc = run("localize flight.csv --anchors survey.txt --out traj.csv --plot traj.png --json");
  ASSERT_EQ(loc.exit_code, 0) << loc.err;
  const test::CliResult tum = run("localize flight.csv --anchors survey.txt --no-diagnostics --format tum --out traj.tum");
  ASSERT_EQ(tum.exit_code, 0) << tum.err;
  // THEN import found TDoA, IMU, ToF and the pose, and noted nothing left out
  const nlohmann::json ji = nlohmann::json::parse(imp.out);
  for (const char* s : {"tdoa", "acc", "gyro", "tof", "pose"}) EXPECT_TRUE(ji["streams"].contains(s)) << s;
  for (const auto& n : ji["notes"]) {  // nothing of the log left out (equal stamps may be noted)
    EXPECT_EQ(n.get<std::string>().find("ignored"), std::string::npos) << n;
    EXPECT_EQ(n.get<std::string>().find("lacks"), std::string::npos) << n;
  }
  // AND the survey has the 8 anchors and no warning on this flight
  const nlohmann::json js = nlohmann::json::parse(sur.out);
  EXPECT_EQ(js["n_anchors"], 8);
  EXPECT_EQ(js["format"], "cfclient-yaml");
  EXPECT_GT(js["n_positions_checked"].get<int>(), 1000);
  EXPECT_TRUE(js["warnings"].empty()) << js["warnings"].dump();
  // AND localize gives the flight's known accuracy, its figure and the same poses in TUM
  const nlohmann::json jl = nlohmann::json::parse(loc.out);
  EXPECT_LT(jl["rmse_airborne_m"].get<double>(), 0.35);
  EXPECT_GT(fs::file_size(path("traj.png")), 10000u);
  const Trajectory a = readTrajectoryCsv(path("traj.csv")), b = readTrajectoryTum(path("traj.tum"));
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); i += 97) EXPECT_LE((a[i].w_p_b - b[i].w_p_b).norm(), 1e-9) << i;
}

TEST_F(SlowCrazyflieGuide, WithoutMotionCaptureTheEstimateHasItsSigmaAndNoRmse) {
  // GIVEN the flight logged without the estPose event (no motion capture)
  test::UsdDeckConfig config = test::readShippedUsdConfig();
  std::erase_if(config.events, [](const auto& e) { return e.first == "estPose"; });
  writeUsdLog(test::usdLogThroughConfig(readFlightCsv(flight_->string()), config), path("log00"));
  writeAnchorSurvey(readAnchorSurvey(test::pilotSurvey("0425").string()), path("survey.txt"));
  // WHEN imported and localized
  const test::CliResult imp = run("import log00 --out flight.csv --json");
  ASSERT_EQ(imp.exit_code, 0) << imp.err;
  const test::CliResult loc = run("localize flight.csv --anchors survey.txt --out traj.csv --plot traj.png --json");
  ASSERT_EQ(loc.exit_code, 0) << loc.err;
  // THEN import warns that there is no ground truth; localize reports no RMSE but a trajectory with its σ
  EXPECT_NE(nlohmann::json::parse(imp.out)["warnings"].dump().find("no ground truth"), std::string::npos);
  const nlohmann::json jl = nlohmann::json::parse(loc.out);
  EXPECT_TRUE(jl["rmse_m"].is_null());
  const Trajectory t = readTrajectoryCsv(path("traj.csv"));
  ASSERT_GT(t.size(), 1000u);
  const TrajectorySample& mid = t[t.size() / 2];
  EXPECT_GT(mid.sigma_p_m.minCoeff(), 0.0);
  EXPECT_LT(mid.sigma_p_m.maxCoeff(), 0.5);
  EXPECT_GT(fs::file_size(path("traj.png")), 10000u);
  // AND the survey's volume check asks for the trajectory, and takes it
  const test::CliResult note = run("survey survey.txt --flight flight.csv");
  EXPECT_NE(note.out.find("give --trajectory"), std::string::npos) << note.out;
  const test::CliResult vol = run("survey survey.txt --flight flight.csv --trajectory traj.csv --json");
  ASSERT_EQ(vol.exit_code, 0) << vol.err;
  EXPECT_EQ(nlohmann::json::parse(vol.out)["format"], "util");
  EXPECT_EQ(nlohmann::json::parse(vol.out)["n_positions_checked"].get<std::size_t>(), t.size());
}

TEST_F(SlowCrazyflieGuide, ASurveyWithAnAnchorMissingOrOnTheCeilingIsWarnedWithNumbers) {
  // GIVEN the flight, and anchor positions with anchor 7 left out and all others moved up to the ceiling
  writeFlightCsv(readFlightCsv(flight_->string()), path("flight.csv"));
  AnchorSurvey s = readAnchorSurvey(test::pilotSurvey("0425").string());
  s.anchors.pop_back();
  for (Anchor& a : s.anchors) a.w_p.z() = 2.4;
  std::ofstream(path("anchors.yaml")) << formatCfclientAnchors(s);
  // WHEN checked
  const test::CliResult r = run("survey anchors.yaml --flight flight.csv --out survey.txt --json");
  // THEN the warnings name the missing anchor with its count, the plane and the flight outside the anchors' box
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string w = nlohmann::json::parse(r.out)["warnings"].dump();
  EXPECT_NE(w.find("anchor 7 is in"), std::string::npos) << w;
  EXPECT_NE(w.find("vertical (z) is poorly observable"), std::string::npos) << w;
  EXPECT_NE(w.find("lie outside the anchors' box"), std::string::npos) << w;
  EXPECT_NE(r.err.find("warning"), std::string::npos);
}

}  // namespace
}  // namespace uwb
