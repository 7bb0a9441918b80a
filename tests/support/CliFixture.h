/** @file CliFixture.h
 *  @brief Fixtures of the tests that run `uwbtdoa`: a folder per test (CliTest), on a real flight
 *         (PilotFlightCliTest), or one simulated flight shared by a suite (SimulatedCircleSuite); each skips while the
 *         executable is not built. Header-only: for tests that link uwb_io.
 */
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "support/TestSupport.h"
#include "uwb/io/FlightWindow.h"
#include "uwb/io/UtilCsv.h"

namespace uwb::test {

/// Skips while `uwbtdoa` is not built and gives each test a fresh folder <tmp>/uwb_<test suite>_<random> (TempDir),
/// removed after the test. A derived SetUp calls CliTest::SetUp() first and returns when IsSkipped().
class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    UWB_REQUIRE_CLI();
    dir_ = std::make_unique<TempDir>(::testing::UnitTest::GetInstance()->current_test_info()->test_suite_name());
  }
  void TearDown() override { dir_.reset(); }

  const std::filesystem::path& dir() const { return dir_->path(); }
  /// `name` in the test's folder.
  std::string path(const std::string& name) const { return dir_->file(name); }
  /// Writes `text` to `name` in the test's folder; its path.
  std::string write(const std::string& name, const std::string& text) const { return dir_->write(name, text); }

 private:
  std::unique_ptr<TempDir> dir_;
};

/// CliTest on the util-pilot flight `flight` (pilotFlight; skips when the real data is absent): flight_, and survey_
/// the survey of its session. Given a window [t0_s, t1_s], short_ is that part of the flight (sliceFlight: as a log
/// started and ended then would hold it), written to the test's folder.
class PilotFlightCliTest : public CliTest {
 protected:
  explicit PilotFlightCliTest(std::string flight, std::optional<std::pair<double, double>> window_s = std::nullopt)
      : name_(std::move(flight)), window_s_(window_s) {}
  void SetUp() override {
    CliTest::SetUp();
    if (IsSkipped()) return;
    flight_ = pilotFlight(name_);
    UWB_REQUIRE_REAL_DATA(flight_);
    survey_ = pilotSurvey(name_.substr(0, 4)).string();
    if (!window_s_) return;
    short_ = path("short.csv");
    writeFlightCsv(sliceFlight(readFlightCsv(flight_->string()), window_s_->first, window_s_->second), short_);
  }

  std::optional<std::filesystem::path> flight_;
  std::string survey_;
  std::string short_;  ///< the window's CSV, when a window was given

 private:
  std::string name_;
  std::optional<std::pair<double, double>> window_s_;
};

/// One `uwbtdoa simulate` of the 30 s circle (simulateCircleFiles: flight_, survey_) in a folder dir_ that the tests
/// of the suite `Suite` share (<tmp>/uwb_<test suite>_<random>, removed after the suite); each test skips while
/// `uwbtdoa` is not built.
template <class Suite>
class SimulatedCircleSuite : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!std::filesystem::exists(cliPath())) return;
    dir_ = makeTempDir(::testing::UnitTest::GetInstance()->current_test_suite()->name());
    flight_ = (dir_ / "flight.csv").string();
    survey_ = (dir_ / "survey.txt").string();
    const CliResult sim = simulateCircleFiles(flight_, survey_);
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
  }
  static void TearDownTestSuite() {
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }
  void SetUp() override { UWB_REQUIRE_CLI(); }

  /// Writes `text` to `name` in the suite's folder; its path.
  static std::string write(const std::string& name, const std::string& text) {
    const std::filesystem::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }

  static inline std::filesystem::path dir_;
  static inline std::string flight_, survey_;
};

}  // namespace uwb::test
