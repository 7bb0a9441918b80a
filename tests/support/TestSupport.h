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

/// A fresh folder <tmp>/uwb_<tag>_<random>, created.
std::filesystem::path makeTempDir(const std::string& tag);

/// A fresh folder under the system temp dir (makeTempDir), removed at destruction.
class TempDir {
 public:
  explicit TempDir(const std::string& tag = "io_test");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  /// The path of a file named `name` in the folder.
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  /// Writes `text` to a file named `name` in the folder and returns its path.
  std::string write(const std::string& name, const std::string& text) const;

 private:
  std::filesystem::path path_;
};

/// Skips the current test while the `uwbtdoa` executable is not built (from the calling function only: a fixture's
/// SetUp that calls a base SetUp using it returns when IsSkipped()).
#define UWB_REQUIRE_CLI()                                                                                 \
  do {                                                                                                  \
    if (!std::filesystem::exists(::uwb::test::cliPath()))                                               \
      GTEST_SKIP() << "uwbtdoa not built: " << ::uwb::test::cliPath();                                  \
  } while (0)

/// Skips the current test with a clear message when the real data is absent.
#define UWB_REQUIRE_REAL_DATA(path_opt)                                                           \
  do {                                                                                           \
    if (!(path_opt)) GTEST_SKIP() << "real flight data not found under " << ::uwb::test::dataDir() \
                                  << " (set UWBTDOA_DATA to the shared/data folder)";            \
  } while (0)

/// max_i |a_i − b_i| / max_i |b_i| (the fixture definition of relative error).
double relativeError(const MatX& a, const MatX& b);

}  // namespace uwb::test
