/** @file cmd_simulate.cpp
 *  @brief `uwbtdoa simulate`: writes a simulated Crazyflie flight (UTIL flight CSV) and its anchor survey.
 *
 *  uwbtdoa simulate [--trajectory zigzag|circle|circle-sine|figure8] [--duration S] [--seed N]
 *                   [--anchors-preset paper|util-const1..4|util-pilot-0425|util-pilot-0426 | --anchors-file SURVEY]
 *                   [--yaw-rate R] [--config params.json] --out FLIGHT.csv --survey-out SURVEY.txt [--json]
 *  docs/math/simulation.md describes the model and every parameter the config file can set.
 */
#include <chrono>
#include <cmath>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <variant>

#include <fmt/format.h>

#include "Command.h"
#include "uwb/core/Error.h"
#include "uwb/io/FileAccess.h"
#include "uwb/io/JsonFile.h"
#include "uwb/io/UtilCsv.h"
#include "InputGuards.h"
#include "SimConfig.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/ResidualProfile.h"

namespace {

using uwb::sim::SimParams;
using uwb::sim::TrajectoryParams;

/// Longest simulated flight [s] and most samples of one stream: a flight of hours at 1 kHz is gigabytes.
constexpr double kMaxDuration_s = 3600.0;
constexpr double kMaxStreamSamples = 2e7;

struct Options {
  std::string trajectory = "circle";
  double duration_s = 60.0;
  std::uint64_t seed = 1;
  std::uint64_t field_seed = 0;
  std::string anchors_preset = "paper";
  std::string anchors_file;
  double yaw_rate_rps = 0.5;
  std::string config;
  std::string out = "sim-flight.csv";
  std::string survey_out = "sim-survey.txt";
  bool json = false;
};

double rate(std::size_t n, double span_s) { return span_s > 0.0 && n > 1 ? static_cast<double>(n - 1) / span_s : 0.0; }

template <class S>
double spanOf(const S& stream) {
  return stream.size() > 1 ? stream.back().t_s - stream.front().t_s : 0.0;
}

void checkSimulateArgs(const Options& o) {
  uwb::checkOutputFile(o.out, "flight file", {o.config, o.anchors_file, o.survey_out});
  uwb::checkOutputFile(o.survey_out, "anchor survey", {o.config, o.anchors_file});
  if (!std::isfinite(o.duration_s) || !(o.duration_s > 0.0) || o.duration_s > kMaxDuration_s) {
    throw uwb::InputError(fmt::format("--duration must be in (0, {:g}] s, got {}", kMaxDuration_s, o.duration_s));
  }
}

/// The anchors and the trajectory from the options and the config file (which also sets `params`).
uwb::sim::Scenario buildScenario(const Options& o, const CLI::App& sub, SimParams& params) {
  uwb::sim::Scenario scenario;
  scenario.survey = !o.anchors_file.empty() ? uwb::readAnchorSurvey(o.anchors_file)
                                            : uwb::sim::anchorPreset(o.anchors_preset, uwb::app::defaultDataDir());
  scenario.trajectory.shape = uwb::sim::parseTrajectoryShape(o.trajectory);
  scenario.trajectory.duration_s = o.duration_s;
  uwb::sim::fitTrajectoryToAnchors(scenario.survey, &scenario.trajectory);
  scenario.trajectory.yaw_rate_rps = o.yaw_rate_rps;
  if (!o.config.empty()) uwb::app::applySimConfigFile(o.config, &params, &scenario.trajectory);
  params.bias.field_seed = o.field_seed;
  if (sub.count("--yaw-rate") > 0) scenario.trajectory.yaw_rate_rps = o.yaw_rate_rps;  // the flag wins
  scenario.trajectory.yaw_mode = scenario.trajectory.yaw_rate_rps == 0.0 ? uwb::sim::YawMode::kConstant
                                                                          : uwb::sim::YawMode::kConstantRate;
  return scenario;
}

/// No stream may hold more than kMaxStreamSamples samples.
void checkSampleCounts(const SimParams& params, const uwb::sim::Scenario& scenario) {
  for (const auto& [name, rate_hz] : {std::pair<const char*, double>{"imu.rate_hz", params.imu.rate_hz},
                                      {"pose.rate_hz", params.pose.rate_hz}, {"tdoa.rate_hz", params.tdoa.rate_hz}}) {
    if (!(rate_hz * scenario.trajectory.duration_s <= kMaxStreamSamples)) {
      throw uwb::InputError(fmt::format("{} = {:g} Hz over {:g} s gives more than {:g} samples; shorten the flight or "
                                        "lower the rate",
                                        name, rate_hz, scenario.trajectory.duration_s, kMaxStreamSamples));
    }
  }
}

/// What the simulated flight holds: residual profiles, outliers, the time on the ground and the RMS of each airborne
/// error part (S17: how much of the error the body-frame directions explain).
struct SimSummary {
  uwb::sim::ResidualProfile air, ground;
  std::size_t n_outliers = 0;
  double ground_fraction = 0.0;
  double rms_pattern = 0.0, rms_multipath = 0.0, rms_noise = 0.0, rms_outlier = 0.0, rms_total = 0.0;
  double pattern_share = 0.0;  ///< of the airborne error variance
  double sim_s = 0.0, total_s = 0.0;  ///< wall-clock time of the simulation, and of the whole command
};

SimSummary summarizeSimulation(const uwb::sim::SimResult& result) {
  SimSummary s;
  const uwb::Flight& f = result.flight;
  s.air = uwb::sim::residualProfile(f, result.survey, uwb::sim::Phase::kAirborne);
  s.ground = uwb::sim::residualProfile(f, result.survey, uwb::sim::Phase::kGround);
  std::size_t n_airborne_pose = 0;
  for (const auto& p : f.pose) n_airborne_pose += uwb::isAirborne(p.w_p_b.z()) ? 1 : 0;
  double sq_pattern = 0.0, sq_multipath = 0.0, sq_noise = 0.0, sq_outlier = 0.0, sq_total = 0.0;
  std::size_t n_air = 0;
  for (const auto& t : result.tdoa_truth) {
    s.n_outliers += t.error.outlier_m != 0.0 ? 1 : 0;
    if (!t.airborne) continue;
    ++n_air;
    sq_pattern += t.error.pattern_m * t.error.pattern_m;
    sq_multipath += t.error.multipath_m * t.error.multipath_m;
    sq_noise += t.error.noise_m * t.error.noise_m;
    sq_outlier += t.error.outlier_m * t.error.outlier_m;
    sq_total += t.error.total() * t.error.total();
  }
  const auto rms = [&](double sq) { return n_air > 0 ? std::sqrt(sq / static_cast<double>(n_air)) : 0.0; };
  s.rms_pattern = rms(sq_pattern), s.rms_multipath = rms(sq_multipath), s.rms_noise = rms(sq_noise);
  s.rms_outlier = rms(sq_outlier), s.rms_total = rms(sq_total);
  s.pattern_share = sq_total > 0.0 ? sq_pattern / sq_total : 0.0;
  s.ground_fraction =
      f.pose.empty() ? 0.0 : 1.0 - static_cast<double>(n_airborne_pose) / static_cast<double>(f.pose.size());
  return s;
}

nlohmann::json streamJson(std::size_t count, double span_s) {
  return {{"count", count}, {"rate_hz", rate(count, span_s)}};
}

nlohmann::json simulateJson(const Options& o, const uwb::sim::SimResult& result, double yaw_rate_rps,
                            const SimSummary& s) {
  const uwb::Flight& f = result.flight;
  nlohmann::json j;
  j["flight"] = o.out;
  j["survey"] = o.survey_out;
  j["trajectory"] = o.trajectory;
  j["seed"] = o.seed;
  j["field_seed"] = o.field_seed;
  j["duration_s"] = o.duration_s;
  j["anchors"] = result.survey.anchors.size();
  j["anchors_source"] = result.survey.source;
  j["yaw_rate_rps"] = yaw_rate_rps;
  j["streams"] = {{"tdoa", streamJson(f.tdoa.size(), spanOf(f.tdoa))},
                  {"acc", streamJson(f.acc.size(), spanOf(f.acc))},
                  {"gyro", streamJson(f.gyro.size(), spanOf(f.gyro))},
                  {"pose", streamJson(f.pose.size(), spanOf(f.pose))}};
  j["ground_fraction"] = s.ground_fraction;
  j["outliers"] = s.n_outliers;
  j["error_rms_airborne_m"] = {{"pattern", s.rms_pattern},     {"multipath", s.rms_multipath},
                               {"noise", s.rms_noise},         {"outlier", s.rms_outlier},
                               {"total", s.rms_total},         {"pattern_variance_share", s.pattern_share}};
  nlohmann::json pairs = nlohmann::json::array();
  for (const auto& [pair, ps] : s.air.pairs) {
    pairs.push_back({{"id_a", pair.first}, {"id_b", pair.second}, {"count", ps.n}, {"median_m", ps.median_m},
                     {"std_m", ps.std_m}});
  }
  nlohmann::json ac = nlohmann::json::object();
  for (const auto& [lag, value] : s.air.autocorrelation) ac[fmt::format("{:g}s", lag)] = value;
  j["residual_airborne"] = {{"count", s.air.overall.n},         {"median_m", s.air.overall.median_m},
                            {"mean_abs_dev_m", s.air.overall.mean_abs_dev_m}, {"std_m", s.air.overall.std_m},
                            {"outlier_fraction", s.air.outlier_fraction}, {"autocorrelation", ac},
                            {"pairs", pairs}};
  j["residual_ground"] = {{"count", s.ground.overall.n}, {"median_m", s.ground.overall.median_m},
                          {"mean_abs_dev_m", s.ground.overall.mean_abs_dev_m}};
  j["time_simulate_s"] = s.sim_s;
  j["time_total_s"] = s.total_s;
  return j;
}

void printSimulateText(const Options& o, const uwb::sim::SimResult& result, double yaw_rate_rps,
                       const SimSummary& s) {
  const uwb::Flight& f = result.flight;
  std::cout << fmt::format("simulated {} flight, {:.1f} s, seed {}, {} anchors ({}), yaw rate {:g} rad/s\n",
                           o.trajectory, o.duration_s, o.seed, result.survey.anchors.size(), result.survey.source,
                           yaw_rate_rps);
  std::cout << fmt::format("  tdoa {:>7} ({:.0f} Hz)   acc/gyro {:>7} ({:.0f} Hz)   pose {:>7} ({:.0f} Hz)\n",
                           f.tdoa.size(), rate(f.tdoa.size(), spanOf(f.tdoa)), f.acc.size(),
                           rate(f.acc.size(), spanOf(f.acc)), f.pose.size(), rate(f.pose.size(), spanOf(f.pose)));
  std::cout << fmt::format("  on the ground (z ≤ 0.3 m): {:.0f} % of pose samples; outliers: {}\n",
                           100.0 * s.ground_fraction, s.n_outliers);
  std::cout << fmt::format("  airborne TDoA residual: median {:+.3f} m, mean abs dev {:.3f} m, std {:.3f} m\n",
                           s.air.overall.median_m, s.air.overall.mean_abs_dev_m, s.air.overall.std_m);
  std::string pair_text;
  for (const auto& [pair, ps] : s.air.pairs)
    pair_text += fmt::format(" {}-{}:{:+.3f}", pair.first, pair.second, ps.median_m);
  std::cout << "  per-pair medians [m]:" << pair_text << '\n';
  std::string ac_text;
  for (const auto& [lag, value] : s.air.autocorrelation) ac_text += fmt::format(" {:g}s:{:.2f}", lag, value);
  std::cout << "  autocorrelation:" << ac_text << '\n';
  std::cout << fmt::format(
      "  airborne error RMS [m]: body-direction pattern {:.3f}, multipath {:.3f}, noise {:.3f}, outliers {:.3f} "
      "(pattern = {:.0f} % of the variance)\n",
      s.rms_pattern, s.rms_multipath, s.rms_noise, s.rms_outlier, 100.0 * s.pattern_share);
  std::cout << fmt::format("  ground TDoA residual: mean abs dev {:.2f} m\n", s.ground.overall.mean_abs_dev_m);
  std::cout << fmt::format("wrote {} and {} ({:.2f} s, simulation {:.2f} s)\n", o.out, o.survey_out, s.total_s,
                           s.sim_s);
}

void run(const Options& o, CLI::App& sub) {
  checkSimulateArgs(o);
  const auto t_start = std::chrono::steady_clock::now();
  SimParams params;
  const uwb::sim::Scenario scenario = buildScenario(o, sub, params);
  checkSampleCounts(params, scenario);
  const uwb::sim::SimResult result = uwb::sim::simulateFlight(scenario, params, o.seed);
  const auto t_sim = std::chrono::steady_clock::now();
  uwb::writeFlightCsv(result.flight, o.out);
  uwb::writeAnchorSurvey(result.survey, o.survey_out);
  const auto t_end = std::chrono::steady_clock::now();

  SimSummary summary = summarizeSimulation(result);
  summary.sim_s = std::chrono::duration<double>(t_sim - t_start).count();
  summary.total_s = std::chrono::duration<double>(t_end - t_start).count();
  if (o.json) {
    std::cout << uwb::app::dumpJson(simulateJson(o, result, scenario.trajectory.yaw_rate_rps, summary)) << '\n';
    return;
  }
  printSimulateText(o, result, scenario.trajectory.yaw_rate_rps, summary);
}

void setup(CLI::App& sub) {
  auto o = std::make_shared<Options>();
  sub.add_option("--trajectory", o->trajectory, "zigzag | circle | circle-sine | figure8 | hover")
      ->check(CLI::IsMember({"zigzag", "circle", "circle-sine", "figure8", "hover"}))
      ->capture_default_str();
  sub.add_option("--duration", o->duration_s, "Flight duration including ground phases [s]")->capture_default_str();
  sub.add_option("--seed", o->seed, "Random seed (same seed, same flight)")->capture_default_str();
  sub.add_option("--field-seed", o->field_seed,
                 "Seed of the drone's and anchors' antenna patterns and the room's multipath; flights with the same "
                 "field seed share them (train on one, test on another). 0: drawn from --seed")
      ->capture_default_str();
  auto* preset = sub.add_option("--anchors-preset", o->anchors_preset,
                                "paper | util-const1..4 | util-pilot-0425 | util-pilot-0426")
                     ->capture_default_str();
  auto* file = sub.add_option("--anchors-file", o->anchors_file, "Anchor survey in the UTIL format");
  preset->excludes(file);
  sub.add_option("--yaw-rate", o->yaw_rate_rps, "Yaw rate while flying [rad/s]; 0 = constant yaw")
      ->capture_default_str();
  sub.add_option("--config", o->config, "JSON file with parameter overrides (see docs/math/simulation.md)");
  sub.add_option("--out", o->out, "Flight CSV to write (UTIL layout)")->capture_default_str();
  sub.add_option("--survey-out", o->survey_out, "Anchor survey to write")->capture_default_str();
  sub.add_flag("--json", o->json, "Print one JSON object instead of text");
  sub.callback([o, &sub] { run(*o, sub); });
}

const bool kRegistered = uwb::app::registerCommand(
    {"simulate", "Simulate a Crazyflie flight (IMU, Vicon pose, TDoA2 or TDoA3) with a realistic TDoA bias", setup});

}  // namespace
