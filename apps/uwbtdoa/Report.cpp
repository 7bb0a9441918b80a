/** @file Report.cpp */
#include "Report.h"

#include <fmt/format.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/ranges.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "Command.h"
#include "InputGuards.h"
#include "StopSignal.h"
#include "uwb/core/Error.h"
#include "uwb/io/FileAccess.h"

extern char** environ;

namespace uwb::app {

void EvaluationCliOptions::addTo(CLI::App& sub) {
  sub.add_option("--kernels", kernels, "Kernel presets, comma-separated (z1, z2, tdoa, pair-tdoa, pair-pos, tdoa-pm, anchor-tdoa, anchor-tdoa-pm, pair-tdoa-pos)")
      ->delimiter(',')
      ->capture_default_str();
  sub.add_option("--inducing", inducing, "Numbers of inducing points, comma-separated")
      ->delimiter(',')
      ->capture_default_str();
  sub.add_option("--repeats", repeats, "Trainings per configuration (seeds 1..N)")->capture_default_str();
  sub.add_option("--epochs", epochs, "Training epochs (0: trainer default)")->capture_default_str();
  sub.add_option("--batch", batch, "Minibatch size (0: trainer default)")->capture_default_str();
  sub.add_option("--threads", threads, "Configurations run in parallel")->capture_default_str();
  sub.add_option("--inputs", inputs,
                 "GP inputs of the training data: the uncorrected filter's 'estimate' (as at run time) or the 'truth'")
      ->check(CLI::IsMember({"estimate", "truth"}))
      ->capture_default_str();
  sub.add_flag("--no-plots", no_plots, "Write the data and report but do not render PNG figures");
  sub.add_flag("--full-variance", full_variance,
               "Corrected measurements get the TDoA variance scaled by (var_f + noise)/E[eps^2] instead of R + var_f "
               "(docs/math/gp.md P45)");
  sub.add_flag("--bias-guard", bias_guard,
               fmt::format("Corrected runs mix the corrected and the uncorrected filter by their TDoA predictive "
                           "likelihood (docs/math/filter.md F24); --bias-guard=false: the corrected filter alone "
                           "(default {})",
                           bias_guard));
  sub.add_flag("--json", json, "Print one JSON object (results and paths) on stdout");
}

EvaluationParams EvaluationCliOptions::toParams() const {
  EvaluationParams p;
  p.kernels = kernels;
  p.inducing = inducing;
  p.repeats = repeats;
  p.threads = threads;
  p.dataset.inputs = biasInputSourceFromString(inputs);
  if (epochs > 0) p.train.svgp.epochs = epochs;
  if (batch > 0) p.train.svgp.batch_size = batch;
  p.train.full_variance = full_variance;
  p.localization.params.bias_guard = bias_guard;
  return p;
}

std::string runPlots(const std::vector<std::string>& args) {
  // No shell: python3 is started with an argument vector, so no byte of a file name is ever interpreted (a name
  // such as "x';touch PWNED;'.csv" stays a name). PYTHONPATH is set in the child's environment only.
  std::vector<std::string> argv_text{"/usr/bin/python3", "-m", "uwbtdoa.plots"};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_text{std::string("PYTHONPATH=") + UWB_PYTHON_DIR};
  for (char** e = environ; e != nullptr && *e != nullptr; ++e) {
    if (std::strncmp(*e, "PYTHONPATH=", 11) != 0) env_text.emplace_back(*e);
  }
  std::vector<char*> envp;
  for (std::string& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);
  const std::string shown = fmt::format("{}", fmt::join(argv_text, " "));

  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw FileError("cannot start python3 to render the figures: " + shown);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);  // dup2 clears FD_CLOEXEC on the copy
  pid_t pid = -1;
  const int spawn_err = ::posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[1]);
  if (spawn_err == 0) setChildToStopOnSignal(pid);  // Ctrl-C stops it before the temporary files are removed
  if (spawn_err != 0) {
    ::close(fds[0]);
    throw FileError(fmt::format("cannot start python3 to render the figures ({}): {}", std::strerror(spawn_err), shown));
  }
  std::string output;
  std::array<char, 4096> buffer{};
  for (;;) {
    const ssize_t n = ::read(fds[0], buffer.data(), buffer.size());
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      break;
    }
    output.append(buffer.data(), static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  setChildToStopOnSignal(0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw FileError(fmt::format("rendering the figures failed (exit status {}): {}", status, shown));
  }
  return output;
}

std::vector<std::string> renderFigures(const std::string& dir) {
  std::string output;
  try {
    output = runPlots({"report", dir});
  } catch (const FileError& e) {
    throw FileError(std::string(e.what()) + "\n(use --no-plots to skip)");
  }
  std::vector<std::string> pngs;
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty()) pngs.push_back(std::filesystem::path(line).filename().string());
  }
  return pngs;
}

void runAndReport(const std::vector<NamedFlight>& train, const std::vector<NamedFlight>& test,
                  const AnchorSurvey& survey, const EvaluationCliOptions& options) {
  checkOutputDirectory(options.out_dir, "report folder");  // before the (long) evaluation
  const EvaluationParams params = options.toParams();
  const EvaluationResult result =
      runEvaluation(train, test, survey, params, [](const std::string& line) { std::cerr << line << std::endl; });
  writeEvaluation(result, survey, options.out_dir, commandLine());
  std::vector<std::string> figures;
  if (!options.no_plots) {
    figures = renderFigures(options.out_dir);
    writeEvaluation(result, survey, options.out_dir, commandLine(), figures);  // report lists what was drawn
  }
  const std::string report = (std::filesystem::path(options.out_dir) / "REPORT.md").string();
  if (options.json) {
    const nlohmann::json j = {{"results", toJson(result.rows)},
                              {"runs", runsToJson(result.runs)},
                              {"out_dir", options.out_dir},
                              {"report", report},
                              {"figures", figures},
                              {"best_kernel", result.best_kernel},
                              {"best_inducing", result.best_inducing},
                              {"n_train_samples", result.n_train_samples},
                              {"seconds", result.seconds}};
    std::cout << dumpJson(j, 2) << std::endl;
    return;
  }
  std::cout << toMarkdown(result.rows) << '\n';
  std::cout << fmt::format("per test flight, {} M = {} (bias calibration: docs/math/gp.md P43):\n", result.best_kernel,
                           result.best_inducing)
            << perFlightMarkdown(result.runs, result.best_kernel, result.best_inducing) << '\n';
  std::cout << fmt::format("best: {} with M = {}; report: {} ({} figures); {:.0f} s\n", result.best_kernel,
                           result.best_inducing, report, figures.size(), result.seconds);
}

}  // namespace uwb::app
