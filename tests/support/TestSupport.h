/** @file TestSupport.h
 *  @brief Shared test helpers: where real data lives, and central-difference derivatives (STYLE §10).
 */
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

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

/// Skips the current test with a clear message when the real data is absent.
#define UWB_REQUIRE_REAL_DATA(path_opt)                                                           \
  do {                                                                                           \
    if (!(path_opt)) GTEST_SKIP() << "real flight data not found under " << ::uwb::test::dataDir() \
                                  << " (set UWBTDOA_DATA to the shared/data folder)";            \
  } while (0)

/// Central-difference Jacobian of f: R^n → R^m at x, step h (relative to max(|x_i|, 1)).
MatX numericalJacobian(const std::function<VecX(const VecX&)>& f, const VecX& x, double h = 1e-6);

/// Central-difference Jacobian of f(q ⊞ δθ) w.r.t. the rotation-vector perturbation δθ (right, body frame):
/// q ⊞ δθ = q ⊗ exp(δθ). Returns m×3.
MatX numericalJacobianRotation(const std::function<VecX(const Quat&)>& f, const Quat& q, double h = 1e-6);

/// max_i |a_i − b_i| / max_i |b_i| (the fixture definition of relative error).
double relativeError(const MatX& a, const MatX& b);

}  // namespace uwb::test
