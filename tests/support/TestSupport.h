/** @file TestSupport.h
 *  @brief Shared test helpers: where real data lives, running the CLI, relative errors; the derivative checker is
 *         support/DerivativeChecker.h (included here).
 */
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "support/DerivativeChecker.h"
#include "uwb/core/Types.h"

namespace uwb::test {

/// Real-data root: $UWBTDOA_DATA, else ../shared/data beside the source tree.
std::filesystem::path dataDir();
/// util-pilot flight path, e.g. pilotFlight("0425-traj1"); nullopt when the data is absent.
std::optional<std::filesystem::path> pilotFlight(const std::string& name);
/// util-pilot survey for a session ("0425" or "0426").
std::filesystem::path pilotSurvey(const std::string& session);
/// Path of the `uwbtdoa` executable under test.
std::string cliPath();

/// Exit code (−1: did not exit normally) and stdout of one `uwbtdoa` run; stderr goes to `err` when asked.
struct CliResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};
/// Runs `uwbtdoa <args>` through the shell (args are not quoted).
CliResult runCli(const std::string& args);
/// `uwbtdoa simulate` of the 30 s circle (seed 3) into `flight_csv` and `survey_txt`: the shared input of the CLI
/// robustness tests.
CliResult simulateCircleFiles(const std::string& flight_csv, const std::string& survey_txt);
/// The whole file as bytes (empty when it cannot be read).
std::string readFileBytes(const std::filesystem::path& path);

/// Skips the current test with a clear message when the real data is absent.
#define UWB_REQUIRE_REAL_DATA(path_opt)                                                           \
  do {                                                                                           \
    if (!(path_opt)) GTEST_SKIP() << "real flight data not found under " << ::uwb::test::dataDir() \
                                  << " (set UWBTDOA_DATA to the shared/data folder)";            \
  } while (0)

/// max_i |a_i − b_i| / max_i |b_i| (the fixture definition of relative error).
double relativeError(const MatX& a, const MatX& b);

}  // namespace uwb::test
