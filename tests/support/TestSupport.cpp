/** @file TestSupport.cpp */
#include "TestSupport.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <random>

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

CliResult simulateCircleFiles(const std::string& flight_csv, const std::string& survey_txt) {
  return runCli("simulate --trajectory circle --duration 30 --seed 3 --json --out " + flight_csv + " --survey-out " +
                survey_txt);
}

std::string readFileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::filesystem::path makeTempDir(const std::string& tag) {
  std::random_device rd;
  const auto path =
      std::filesystem::temp_directory_path() / ("uwb_" + tag + "_" + std::to_string(rd()) + std::to_string(rd()));
  std::filesystem::create_directories(path);
  return path;
}

TempDir::TempDir(const std::string& tag) : path_(makeTempDir(tag)) {}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::string TempDir::write(const std::string& name, const std::string& text) const {
  const auto p = path_ / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

double relativeError(const MatX& a, const MatX& b) {
  const double denom = b.cwiseAbs().maxCoeff();
  const double num = (a - b).cwiseAbs().maxCoeff();
  return denom > 0 ? num / denom : num;
}

}  // namespace uwb::test
