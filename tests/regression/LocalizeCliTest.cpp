/** @file LocalizeCliTest.cpp
 *  @brief `uwbtdoa localize` on a real flight through the command line: the ToF option by flag and by config file
 *         (docs/math/filter.md F21), its counters in --json, and a config key that does not exist.
 */
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include "support/TestSupport.h"

namespace uwb {
namespace {

class LocalizeCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(test::cliPath())) GTEST_SKIP() << "uwbtdoa not built: " << test::cliPath();
    flight_ = test::pilotFlight("0425-traj3");
    UWB_REQUIRE_REAL_DATA(flight_);
    dir_ = std::filesystem::temp_directory_path() / ("uwb_localize_cli_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }
  nlohmann::json localize(const std::string& extra) {
    const test::CliResult r = test::runCli("localize " + flight_->string() + " --anchors " +
                                           test::pilotSurvey("0425").string() + " --json " + extra);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(r.out);
  }
  std::string writeConfig(const std::string& name, const std::string& text) {
    const auto p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  std::optional<std::filesystem::path> flight_;
  std::filesystem::path dir_;
};

TEST_F(LocalizeCli, TofFusionByFlagOrConfigUsesTheHeightSensorAndReportsItsCounters) {
  // GIVEN 0425-traj3, a flight with a Flow-deck ToF stream (airborne RMSE 0.169 m UWB-only, 0.095 m with ToF)
  // WHEN it is localized without ToF, with --fuse-tof, and with fuse_tof in a config file
  const nlohmann::json plain = localize("");
  const nlohmann::json flag = localize("--fuse-tof");
  const nlohmann::json config =
      localize("--config " + writeConfig("tof.json", R"({"fuse_tof": true, "tof_sigma_m": 0.05})"));
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

}  // namespace
}  // namespace uwb
