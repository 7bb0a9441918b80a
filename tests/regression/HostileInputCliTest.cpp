/** @file HostileInputCliTest.cpp
 *  @brief The CLI against a careful attacker and a careless user (docs/robustness.md, "Hostile names, outputs and
 *         runs that find nothing"): no file name reaches a shell, no output replaces a device, a FIFO, a link or
 *         one of the run's inputs, a replaced file keeps its mode, deep JSON is a located error, absurd models and
 *         runs that never find a position fail with a reason, degraded input warns, and a killed run leaves no
 *         temporary file. The CLI is started with an argument vector (fork + execv), so names are passed as bytes.
 */
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "support/CliFixture.h"

namespace uwb {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;


void writeAll(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

/// Starts `uwbtdoa args...` in folder `cwd` with an argument vector (no shell); stdout and stderr go to files.
pid_t startCli(const fs::path& cwd, const std::vector<std::string>& args, const fs::path& out, const fs::path& err) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(cwd.c_str()) != 0) ::_exit(120);
    const int o = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (o < 0 || e < 0) ::_exit(121);
    ::dup2(o, STDOUT_FILENO);
    ::dup2(e, STDERR_FILENO);
    std::vector<std::string> argv_text{test::cliPath()};
    argv_text.insert(argv_text.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : argv_text) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

/// Runs `uwbtdoa args...` to its end; exit code (−1: killed by a signal), stdout, stderr.
test::CliResult runArgs(const fs::path& cwd, const std::vector<std::string>& args) {
  const fs::path out = cwd / ".cli_out", err = cwd / ".cli_err";
  const pid_t pid = startCli(cwd, args, out, err);
  int status = 0;
  ::waitpid(pid, &status, 0);
  test::CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = test::readFileBytes(out);
  r.err = test::readFileBytes(err);
  fs::remove(out);
  fs::remove(err);
  return r;
}

/// Files in `dir` whose name contains ".tmp" (the temporary files of an output being written).
std::vector<std::string> temporaryFiles(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.find(".tmp") != std::string::npos) names.push_back(n);
  }
  return names;
}

/// A 30 s simulated flight with ground truth, its survey and a tiny bias model, shared by the tests of this file.
class HostileCli : public test::SimulatedCircleSuite<HostileCli> {
 protected:
  void SetUp() override {
    SimulatedCircleSuite::SetUp();
    if (IsSkipped()) return;
    case_ = dir_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(case_);
  }

  static const std::string& model() {
    static std::string path;
    if (path.empty()) {
      path = (dir_ / "model.json").string();
      const test::CliResult r = runArgs(dir_, {"train", flight_, "--anchors", survey_, "--kernel", "tdoa", "--inducing",
                                               "5", "--epochs", "2", "--quiet", "--out", path});
      EXPECT_EQ(r.exit_code, 0) << r.err;
    }
    return path;
  }
  /// The flight's CSV with `edit(header, rows)` applied to its lines.
  static std::string editedFlight(const std::function<void(std::vector<std::string>&)>& edit) {
    std::vector<std::string> lines;
    std::istringstream in(test::readFileBytes(flight_));
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    edit(lines);
    std::string text;
    for (const auto& l : lines) text += l + "\n";
    return text;
  }
  static int column(const std::string& header, const std::string& name) {
    std::istringstream in(header);
    int k = 0;
    for (std::string cell; std::getline(in, cell, ','); ++k)
      if (cell == name) return k;
    return -1;
  }
  static std::vector<std::string> cells(const std::string& line) {
    std::vector<std::string> out;
    std::istringstream in(line);
    for (std::string cell; std::getline(in, cell, ',');) out.push_back(cell);
    if (!line.empty() && line.back() == ',') out.emplace_back();
    return out;
  }
  static std::string joined(const std::vector<std::string>& c) {
    std::string s;
    for (std::size_t i = 0; i < c.size(); ++i) s += (i ? "," : "") + c[i];
    return s;
  }

  fs::path case_;
};

// ------------------------------------------------------------------------------------------------- 1. no shell

TEST_F(HostileCli, NoFileNameReachesAShell) {
  // GIVEN a flight, a plot and a report folder whose names would run `touch PWNED` in a shell
  const std::string evil = "x';touch PWNED;'";
  fs::copy_file(flight_, case_ / (evil + ".csv"));
  // WHEN localize plots it and evaluate writes a report under such names (rendering may fail without matplotlib)
  runArgs(case_, {"localize", evil + ".csv", "--anchors", survey_, "--plot", "p" + evil + ".png", "--no-diagnostics"});
  runArgs(case_, {"evaluate", "--train", flight_, "--test", evil + ".csv", "--anchors", survey_, "--kernels", "z1",
                  "--inducing", "5", "--repeats", "1", "--epochs", "1", "--out", "o" + evil});
  // THEN no command was run
  EXPECT_FALSE(fs::exists(case_ / "PWNED"));
  EXPECT_FALSE(fs::exists(dir_ / "PWNED"));
}

// --------------------------------------------------------------------------------------------- 2. output targets

TEST_F(HostileCli, AFifoOrASymlinkAsOutputIsRefusedAndKept) {
  const fs::path fifo = case_ / "out.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const test::CliResult r = runArgs(case_, {"localize", flight_, "--anchors", survey_, "--out", fifo.string()});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_THAT(r.err, HasSubstr("FIFO"));
  EXPECT_TRUE(fs::is_fifo(fifo));

  const fs::path target = case_ / "target.csv", link = case_ / "link.csv";
  writeAll(target, "keep me\n");
  fs::create_symlink(target, link);
  const test::CliResult s = runArgs(case_, {"localize", flight_, "--anchors", survey_, "--out", link.string()});
  EXPECT_EQ(s.exit_code, 3) << s.err;
  EXPECT_THAT(s.err, HasSubstr("symbolic link"));
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(test::readFileBytes(target), "keep me\n");
  if (fs::exists("/dev/null")) {
    const test::CliResult d = runArgs(case_, {"localize", flight_, "--anchors", survey_, "--out", "/dev/null"});
    EXPECT_EQ(d.exit_code, 3) << d.err;
    EXPECT_THAT(d.err, HasSubstr("character device"));
  }
}

TEST_F(HostileCli, AnOutputThatIsAnInputIsRefusedAndTheInputKept) {
  // GIVEN copies of the flight and survey (and a hard link to the flight: same file, other name)
  const fs::path flight = case_ / "f.csv", survey = case_ / "s.txt", hard = case_ / "hard.csv";
  fs::copy_file(flight_, flight);
  fs::copy_file(survey_, survey);
  fs::create_hard_link(flight, hard);
  const std::string before = test::readFileBytes(flight), survey_before = test::readFileBytes(survey);
  for (const fs::path& out : {flight, hard}) {
    const test::CliResult r = runArgs(case_, {"localize", "f.csv", "--anchors", "s.txt", "--out", out.string()});
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_THAT(r.err, HasSubstr("input file"));
  }
  const test::CliResult t = runArgs(case_, {"train", "f.csv", "--anchors", "s.txt", "--kernel", "tdoa", "--inducing",
                                            "5", "--epochs", "1", "--quiet", "--out", "s.txt"});
  EXPECT_EQ(t.exit_code, 3) << t.err;
  EXPECT_THAT(t.err, HasSubstr("input file"));
  EXPECT_EQ(test::readFileBytes(flight), before);
  EXPECT_EQ(test::readFileBytes(survey), survey_before);
}

TEST_F(HostileCli, AReplacedOutputKeepsItsPermissions) {
  const fs::path out = case_ / "traj.csv";
  writeAll(out, "old\n");
  ASSERT_EQ(::chmod(out.c_str(), 0600), 0);
  const test::CliResult r =
      runArgs(case_, {"localize", flight_, "--anchors", survey_, "--out", out.string(), "--no-diagnostics"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  struct stat st {};
  ASSERT_EQ(::stat(out.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_NE(test::readFileBytes(out), "old\n");
}

// ------------------------------------------------------------------------------------------------ 3. deep JSON

TEST_F(HostileCli, DeeplyNestedJsonIsALocatedErrorNotACrash) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  writeAll(case_ / "deep.json", deep);
  const test::CliResult c =
      runArgs(case_, {"localize", flight_, "--anchors", survey_, "--config", "deep.json", "--no-diagnostics"});
  EXPECT_EQ(c.exit_code, 2) << c.err;
  EXPECT_THAT(c.err, HasSubstr("deep.json:1:65"));
  EXPECT_THAT(c.err, HasSubstr("nested deeper than 64"));
  const test::CliResult m = runArgs(case_, {"predict-bias", flight_, "--anchors", survey_, "--model", "deep.json",
                                            "--out", "bias.csv"});
  EXPECT_EQ(m.exit_code, 2) << m.err;
  EXPECT_THAT(m.err, HasSubstr("nested deeper than 64"));
  EXPECT_FALSE(fs::exists(case_ / "bias.csv"));
  // a deep value inside an otherwise valid object, and brackets inside strings that do not count
  writeAll(case_ / "deep_key.json", "{\"tdoa_sigma_m\": " + std::string(70, '[') + std::string(70, ']') + "}");
  const test::CliResult k =
      runArgs(case_, {"localize", flight_, "--anchors", survey_, "--config", "deep_key.json", "--no-diagnostics"});
  EXPECT_EQ(k.exit_code, 2) << k.err;
  EXPECT_THAT(k.err, HasSubstr("nested deeper than 64"));
}

// ---------------------------------------------------------------------------------------- 4. threads, file size

TEST_F(HostileCli, TrainWithTwoThousandThreadsIsAClearErrorNotAHang) {
  const auto t0 = std::chrono::steady_clock::now();
  const test::CliResult r = runArgs(case_, {"train", flight_, "--anchors", survey_, "--kernel", "tdoa", "--inducing",
                                            "5", "--epochs", "1", "--threads", "2000", "--quiet", "--out", "m.json"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.err, HasSubstr("num_threads must be in [0, 256]"));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 60.0);
  EXPECT_FALSE(fs::exists(case_ / "m.json"));
}

TEST_F(HostileCli, AFileOfExactlyTwoGibibytesIsRefusedBeforeReading) {
  // GIVEN a sparse file of exactly 2^31 bytes (no disk space used)
  const fs::path big = case_ / "big.csv";
  const int fd = ::open(big.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::ftruncate(fd, off_t{1} << 31), 0);
  ::close(fd);
  const test::CliResult r = runArgs(case_, {"inspect", big.string()});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_THAT(r.err, HasSubstr("too large (2147483648 bytes"));
  EXPECT_THAT(r.err, Not(HasSubstr("bad_alloc")));
}

// --------------------------------------------------------------------------------- 6. absurd models, NaN output

TEST_F(HostileCli, ABiasModelWithAnAbsurdVariationalMeanIsRefusedOnLoad) {
  nlohmann::json j = nlohmann::json::parse(test::readFileBytes(model()));
  j["models"][0]["svgp"]["variational"]["m"][0] = 1e300;
  writeAll(case_ / "absurd.json", j.dump());
  const test::CliResult r = runArgs(case_, {"localize", flight_, "--anchors", survey_, "--bias-model", "absurd.json",
                                            "--out", "t.csv", "--no-diagnostics"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("absurd.json"));
  EXPECT_THAT(r.err, HasSubstr("models[0].svgp.variational.m[0]"));
  EXPECT_FALSE(fs::exists(case_ / "t.csv"));
  const test::CliResult p = runArgs(case_, {"predict-bias", flight_, "--anchors", survey_, "--model", "absurd.json",
                                            "--out", "b.csv"});
  EXPECT_EQ(p.exit_code, 2) << p.err;
  EXPECT_FALSE(fs::exists(case_ / "b.csv"));
}

TEST_F(HostileCli, NoCommandWritesANonFiniteEstimate) {
  // GIVEN one gyro sample of 1e308 deg/s in the middle of the flight (the filter either skips it or diverges)
  const std::string text = editedFlight([](std::vector<std::string>& lines) {
    const int tg = column(lines[0], "t_gyro"), gz = column(lines[0], "gyro_z");
    ASSERT_GE(gz, 0);
    for (std::size_t i = 1; i < lines.size(); ++i) {
      std::vector<std::string> c = cells(lines[i]);
      if (static_cast<int>(c.size()) > gz && !c[tg].empty() && std::stod(c[tg]) >= 15.0) {
        c[gz] = "1e308";
        lines[i] = joined(c);
        break;
      }
    }
  });
  writeAll(case_ / "spike.csv", text);
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"localize", "spike.csv", "--anchors", survey_, "--out", "out.csv", "--no-diagnostics"},
        std::vector<std::string>{"predict-bias", "spike.csv", "--anchors", survey_, "--model", model(), "--inputs",
                                 "estimate", "--out", "out.csv"}}) {
    SCOPED_TRACE(args[0]);
    fs::remove(case_ / "out.csv");
    const test::CliResult r = runArgs(case_, args);
    // THEN either every number written is finite, or the command fails saying so and writes nothing
    if (r.exit_code == 0) {
      const std::string out = test::readFileBytes(case_ / "out.csv");
      EXPECT_THAT(out, Not(HasSubstr("nan")));
      EXPECT_THAT(out, Not(HasSubstr("inf")));
    } else {
      EXPECT_THAT(r.err, HasSubstr("not finite"));
      EXPECT_FALSE(fs::exists(case_ / "out.csv"));
    }
  }
}

// ------------------------------------------------------------------------------ 7. runs that find no position

TEST_F(HostileCli, ARunThatNeverFindsAPositionFailsAndSaysWhy) {
  // GIVEN a flight of three TDoA rows
  const std::string three = editedFlight([](std::vector<std::string>& lines) {
    const int t = column(lines[0], "t_tdoa");
    std::vector<std::string> keep{lines[0]};
    for (std::size_t i = 1; i < lines.size() && keep.size() < 4; ++i)
      if (!cells(lines[i])[static_cast<std::size_t>(t)].empty()) keep.push_back(lines[i]);
    lines = keep;
  });
  writeAll(case_ / "three.csv", three);
  const test::CliResult r = runArgs(case_, {"localize", "three.csv", "--anchors", survey_, "--out", "t.csv"});
  EXPECT_NE(r.exit_code, 0) << r.out;
  EXPECT_THAT(r.err, HasSubstr("no position found"));
  EXPECT_THAT(r.err, HasSubstr("only 3 TDoA"));
  EXPECT_THAT(r.out, Not(HasSubstr("RMSE 3D 0.000")));
  EXPECT_FALSE(fs::exists(case_ / "t.csv"));

  // GIVEN the survey scaled by 1e9 (a unit error)
  std::string scaled;
  {
    std::istringstream in(test::readFileBytes(survey_));
    for (std::string line; std::getline(in, line);) {
      std::vector<std::string> c = cells(line);
      if (!c.empty() && c[0].rfind("an", 0) == 0 && c[0].size() > 2 && c[0].back() == 'p') {
        for (std::size_t k = 1; k < c.size(); ++k) c[k] = std::to_string(std::stod(c[k]) * 1e9);
      }
      scaled += joined(c) + "\n";
    }
  }
  writeAll(case_ / "scaled.txt", scaled);
  const test::CliResult s = runArgs(case_, {"localize", flight_, "--anchors", "scaled.txt", "--json"});
  EXPECT_NE(s.exit_code, 0) << s.out;
  EXPECT_THAT(s.err, HasSubstr("no position found against it"));
  EXPECT_THAT(s.err, HasSubstr("are the coordinates in metres"));
  EXPECT_TRUE(s.out.empty()) << s.out;
}

// -------------------------------------------------------------------------- 8. warnings that name the cause

TEST_F(HostileCli, AllTdoaStampsEqualIsAnErrorAboutTheTimeStamps) {
  const std::string text = editedFlight([](std::vector<std::string>& lines) {
    const int t = column(lines[0], "t_tdoa");
    for (std::size_t i = 1; i < lines.size(); ++i) {
      std::vector<std::string> c = cells(lines[i]);
      if (!c[static_cast<std::size_t>(t)].empty()) c[static_cast<std::size_t>(t)] = "5.0";
      lines[i] = joined(c);
    }
  });
  writeAll(case_ / "equal.csv", text);
  const test::CliResult r = runArgs(case_, {"localize", "equal.csv", "--anchors", survey_});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("t_tdoa"));
  EXPECT_THAT(r.err, HasSubstr("time stamps are equal"));
  EXPECT_THAT(r.err, Not(HasSubstr("survey")));
}

TEST_F(HostileCli, AnImuThatEndsMidFlightIsAWarningWithBothEndTimes) {
  const std::string text = editedFlight([](std::vector<std::string>& lines) {
    const std::vector<std::string> header = cells(lines[0]);
    for (std::size_t i = 1; i < lines.size(); ++i) {
      std::vector<std::string> c = cells(lines[i]);
      c.resize(header.size());
      for (const char* stream : {"acc", "gyro"}) {
        const int t = column(lines[0], std::string("t_") + stream);
        if (!c[static_cast<std::size_t>(t)].empty() && std::stod(c[static_cast<std::size_t>(t)]) > 15.0) {
          for (std::size_t k = 0; k < header.size(); ++k)
            if (header[k] == std::string("t_") + stream || header[k].rfind(std::string(stream) + "_", 0) == 0) c[k].clear();
        }
      }
      lines[i] = joined(c);
    }
  });
  writeAll(case_ / "imu_cut.csv", text);
  const test::CliResult r = runArgs(case_, {"localize", "imu_cut.csv", "--anchors", survey_, "--json", "--no-diagnostics"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("stream acc ends at t = 1"));
  EXPECT_THAT(r.err, HasSubstr("before the TDoA stream (t = 2"));
  EXPECT_THAT(r.err, HasSubstr("the rest of the flight has no IMU"));
  EXPECT_THAT(nlohmann::json::parse(r.out)["warnings"].dump(), HasSubstr("ends at t ="));
}

TEST_F(HostileCli, TwoAnchorsAtOnePlaceAreAWarningNamingBoth) {
  // GIVEN the survey with anchor 1's coordinates copied onto anchor 2
  std::string text, p1;
  std::istringstream in(test::readFileBytes(survey_));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  for (const auto& l : lines)
    if (l.rfind("an1_p", 0) == 0) p1 = l.substr(5);
  ASSERT_FALSE(p1.empty());
  for (auto& l : lines) {
    if (l.rfind("an2_p", 0) == 0) l = "an2_p" + p1;
    text += l + "\n";
  }
  writeAll(case_ / "twin.txt", text);
  const test::CliResult r = runArgs(case_, {"localize", flight_, "--anchors", "twin.txt", "--no-diagnostics"});
  EXPECT_THAT(r.err, HasSubstr("anchors 1 and 2 are 0.000 m apart"));
}

TEST_F(HostileCli, ATdoaOfAnAnchorAgainstItselfIsALocatedError) {
  std::size_t bad_line = 0;
  const std::string text = editedFlight([&](std::vector<std::string>& lines) {
    const int t = column(lines[0], "t_tdoa"), a = column(lines[0], "idA"), b = column(lines[0], "idB");
    for (std::size_t i = 1; i < lines.size(); ++i) {
      std::vector<std::string> c = cells(lines[i]);
      if (!c[static_cast<std::size_t>(t)].empty() && i > 100) {
        c[static_cast<std::size_t>(b)] = c[static_cast<std::size_t>(a)];
        lines[i] = joined(c);
        bad_line = i + 1;
        break;
      }
    }
  });
  writeAll(case_ / "self.csv", text);
  const test::CliResult r = runArgs(case_, {"localize", "self.csv", "--anchors", survey_});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("self.csv:" + std::to_string(bad_line) + ":"));
  EXPECT_THAT(r.err, HasSubstr("(idB)"));
  EXPECT_THAT(r.err, HasSubstr("same anchor"));
}

// ------------------------------------------------------------------------- 9. evaluate: flights are paths

TEST_F(HostileCli, EvaluateKeepsTwoFlightsThatShareAFileName) {
  fs::create_directories(case_ / "a");
  fs::create_directories(case_ / "b");
  fs::copy_file(flight_, case_ / "a" / "flight.csv");
  const test::CliResult sim = runArgs(case_, {"simulate", "--trajectory", "figure8", "--duration", "30", "--seed", "8",
                                              "--anchors-file", survey_, "--out", "b/flight.csv", "--survey-out", "b/s.txt"});
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const test::CliResult r = runArgs(case_, {"evaluate", "--train", flight_, "--test", "a/flight.csv", "--test",
                                            "b/flight.csv", "--anchors", survey_, "--kernels", "z1", "--inducing", "5",
                                            "--repeats", "1", "--epochs", "1", "--no-plots", "--json", "--out", "rep"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  std::set<std::string> names;
  std::set<double> uncorrected;
  for (const auto& run : j["runs"]) {
    names.insert(run["flight"].get<std::string>());
    uncorrected.insert(run["rmse_uncorrected_m"].get<double>());
  }
  EXPECT_EQ(names, (std::set<std::string>{"a/flight", "b/flight"}));
  EXPECT_EQ(uncorrected.size(), 2u);  // each flight its own uncorrected RMSE
}

// ------------------------------------------------------------------------------- 10. temporary files

TEST_F(HostileCli, StaleTemporaryFilesOfADeadRunAreSwept) {
  // GIVEN a temporary file left beside the output by a process that no longer exists (SIGKILL, power cut)
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  const fs::path stale = case_ / (".t.csv.tmp-" + std::to_string(dead) + "-0");
  const fs::path stale_png = case_ / (".p.png.tmp-" + std::to_string(dead) + "-3.png");
  const fs::path alive = case_ / (".t.csv.tmp-" + std::to_string(::getpid()) + "-0");  // a running process's
  const fs::path other = case_ / ".t.csv.tmp-notes";                                    // not the pattern
  for (const fs::path& p : {stale, stale_png, alive, other}) writeAll(p, std::string(1000, 'x'));
  // WHEN the next run writes that output
  const test::CliResult r =
      runArgs(case_, {"localize", flight_, "--anchors", survey_, "--out", "t.csv", "--no-diagnostics"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  runArgs(case_, {"localize", flight_, "--anchors", survey_, "--plot", "p.png", "--no-diagnostics"});
  // THEN the dead run's files are gone and the others kept
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_FALSE(fs::exists(stale_png));
  EXPECT_TRUE(fs::exists(alive));
  EXPECT_TRUE(fs::exists(other));
}

TEST_F(HostileCli, SigtermWhileAPlotIsDrawnLeavesNoTemporaryFile) {
  if (std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "python3 with matplotlib not available: the plot step is too short to interrupt";
  // GIVEN localize drawing its plot (the trajectory written to a temporary file, python3 rendering)
  const pid_t pid = startCli(case_, {"localize", flight_, "--anchors", survey_, "--plot", "p.png", "--no-diagnostics"},
                             case_ / ".out", case_ / ".err");
  bool seen = false;
  for (int i = 0; i < 12000 && !seen; ++i) {  // up to a minute on a loaded machine
    for (const auto& n : temporaryFiles(case_)) seen = seen || n.find(".trajectory.csv") != std::string::npos;
    if (!seen) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(seen) << "the plot's temporary trajectory never appeared";
  // WHEN it is stopped by SIGTERM
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the interpreter it stopped
  // THEN no temporary file is left, and no plot
  EXPECT_THAT(temporaryFiles(case_), ::testing::IsEmpty());
  EXPECT_FALSE(fs::exists(case_ / "p.png"));
}

}  // namespace
}  // namespace uwb
