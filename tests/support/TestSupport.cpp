/** @file TestSupport.cpp */
#include "TestSupport.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>

#include <sys/wait.h>
#include <unistd.h>

namespace uwb::test {

std::filesystem::path dataDir() {
  if (const char* env = std::getenv("UWBTDOA_DATA"); env != nullptr && *env != '\0') return env;
  return UWB_DEFAULT_DATA_DIR;
}

std::optional<std::filesystem::path> pilotFlight(const std::string& name) {
  const std::string session = name.substr(0, 4);
  const auto p = dataDir() / "real" / "util-pilot" / session / (name + ".csv");
  if (!std::filesystem::exists(p)) return std::nullopt;
  return p;
}

std::filesystem::path pilotSurvey(const std::string& session) {
  return dataDir() / "real" / "util-pilot" / "survey" / ("anchor_" + session + "_survey.txt");
}

std::string cliPath() { return UWB_CLI_PATH; }

CliResult runCli(const std::string& args) {
  CliResult r;
  const auto err_file = std::filesystem::temp_directory_path() / ("uwb_cli_err_" + std::to_string(::getpid()));
  const std::string cmd = cliPath() + " " + args + " 2>" + err_file.string();
  FILE* pipe = popen(cmd.c_str(), "r");
  if (pipe == nullptr) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), static_cast<int>(buf.size()), pipe) != nullptr) r.out += buf.data();
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(err_file);
  r.err.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  std::filesystem::remove(err_file);
  return r;
}

MatX numericalJacobian(const std::function<VecX(const VecX&)>& f, const VecX& x, double h) {
  const VecX f0 = f(x);
  MatX J(f0.size(), x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const double step = h * std::max(1.0, std::abs(x[i]));
    VecX xp = x, xm = x;
    xp[i] += step;
    xm[i] -= step;
    J.col(i) = (f(xp) - f(xm)) / (2.0 * step);
  }
  return J;
}

MatX numericalJacobianRotation(const std::function<VecX(const Quat&)>& f, const Quat& q, double h) {
  const VecX f0 = f(q);
  MatX J(f0.size(), 3);
  for (int i = 0; i < 3; ++i) {
    const Quat qp = (q * Quat(Eigen::AngleAxisd(h, Vec3::Unit(i)))).normalized();
    const Quat qm = (q * Quat(Eigen::AngleAxisd(-h, Vec3::Unit(i)))).normalized();
    J.col(i) = (f(qp) - f(qm)) / (2.0 * h);
  }
  return J;
}

double relativeError(const MatX& a, const MatX& b) {
  const double denom = b.cwiseAbs().maxCoeff();
  const double num = (a - b).cwiseAbs().maxCoeff();
  return denom > 0 ? num / denom : num;
}

}  // namespace uwb::test
