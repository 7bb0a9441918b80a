/** @file Evaluation.cpp
 *  @brief The paper's evaluation pipeline (III-D, IV, Fig. 5–7): train, localize without/with correction, report.
 */
#include "uwb/eval/Evaluation.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <system_error>
#include <thread>

#include "uwb/core/Angle.h"
#include "uwb/core/Error.h"
#include "uwb/eval/BiasCalibration.h"
#include "uwb/io/FileAccess.h"

namespace uwb {
namespace {

struct Job {
  std::string kernel;
  int inducing = 0;
  int repeat = 0;
};

struct JobOutput {
  std::vector<EvaluationRun> runs;  ///< one per test flight
  std::map<std::string, LocalizationRun> corrected;  ///< kept for repeat 0 only
  std::vector<std::pair<std::string, PositionErrorSample>> errors;
  BiasModel model;  ///< kept for repeat 0 only
};

std::string configKey(const std::string& kernel, int inducing) { return fmt::format("{}/{}", kernel, inducing); }

/// Airborne samples of a metrics object, decimated to at most rate_hz.
std::vector<PositionErrorSample> decimatedAirborne(const TrajectoryMetrics& metrics, double rate_hz) {
  std::vector<PositionErrorSample> out;
  double next_t = -std::numeric_limits<double>::infinity();
  for (const auto& s : metrics.samples) {
    if (!s.airborne || s.t_s < next_t) continue;
    out.push_back(s);
    next_t = s.t_s + 1.0 / rate_hz;
  }
  return out;
}

/// RMSE of ε and of ε − GP mean over a dataset's samples (features from ground truth).
std::pair<double, double> biasRmse(const BiasDataset& data, const BiasModel& model) {
  double before = 0.0, after = 0.0;
  for (const auto& s : data.samples) {
    const double r = s.error_m - model.predict(s.feature).mean_m;
    before += s.error_m * s.error_m;
    after += r * r;
  }
  const double n = std::max<std::size_t>(data.samples.size(), 1);
  return {std::sqrt(before / n), std::sqrt(after / n)};
}

double airborneRmse(const LocalizationRun& run, const std::string& flight) {
  if (!run.metrics || run.metrics->airborne.n == 0) {
    throw InputError(fmt::format("{}: no airborne ground truth (z > 0.3 m) to evaluate against", flight));
  }
  return run.metrics->airborne.rmse_m;
}

/// Fig. 7 data for any bias model: the pair with the most training samples; its measured errors over the two anchor
/// yaw angles, and the model's mean at those same samples averaged per 5° cell of (α_A, α_B). Cells without a
/// training sample stay NaN (drawn blank): the figure shows the GP where it has data, not its extrapolation over
/// the whole torus. Inducing points are drawn in angle coordinates when the model's inputs are the yaw angles
/// (z1, z2) or the body-frame anchor vectors (tdoa family: yaw = atan2(y, x) of each vector).
BiasAngleFigure angleFigure(const BiasModel& model, const BiasDataset& train, const std::string& kernel, int inducing) {
  BiasAngleFigure fig;
  std::map<std::pair<int, int>, int> counts;
  for (const auto& s : train.samples) ++counts[{s.feature.id_a, s.feature.id_b}];
  if (counts.empty()) return fig;
  const auto best = std::max_element(counts.begin(), counts.end(),
                                     [](const auto& a, const auto& b) { return a.second < b.second; });
  fig.kernel = kernel;
  fig.inducing = inducing;
  fig.id_a = best->first.first;
  fig.id_b = best->first.second;
  constexpr int kGrid = 73;  // cell centres in 5° steps over [−π, π]
  const double step = 2.0 * kPi / (kGrid - 1);
  for (int i = 0; i < kGrid; ++i) {
    const double a = -kPi + step * i;
    fig.grid_alpha_a_rad.push_back(a);
    fig.grid_alpha_b_rad.push_back(a);
  }
  MatX sum = MatX::Zero(kGrid, kGrid), count = MatX::Zero(kGrid, kGrid);
  const auto cell = [&](double a) {
    const double wrapped = wrapAngle(a);
    return std::clamp(static_cast<int>(std::lround((wrapped + kPi) / step)), 0, kGrid - 1);
  };
  for (const auto& s : train.samples) {
    if (s.feature.id_a != fig.id_a || s.feature.id_b != fig.id_b) continue;
    fig.alpha_a_rad.push_back(s.feature.yaw_a_rad);
    fig.alpha_b_rad.push_back(s.feature.yaw_b_rad);
    fig.error_m.push_back(s.error_m);
    const int r = cell(s.feature.yaw_b_rad), c = cell(s.feature.yaw_a_rad);
    sum(r, c) += model.predict(s.feature).mean_m;
    count(r, c) += 1.0;
  }
  fig.grid_mean_m = MatX::Constant(kGrid, kGrid, std::numeric_limits<double>::quiet_NaN());
  for (int r = 0; r < kGrid; ++r)
    for (int c = 0; c < kGrid; ++c)
      if (count(r, c) > 0) fig.grid_mean_m(r, c) = sum(r, c) / count(r, c);
  for (const auto& entry : model.entries()) {
    const bool covers = entry.id_a < 0 || (entry.id_a == fig.id_a && entry.id_b == fig.id_b);
    if (!covers) continue;
    MatX Z = entry.gp.inducing();  // in the GP's transformed input space
    if (entry.gp.inputShift().size() == Z.cols()) {
      Z = ((Z.array().rowwise() * entry.gp.inputScale().transpose().array()).rowwise() +
           entry.gp.inputShift().transpose().array())
              .matrix();
    }
    for (Eigen::Index i = 0; i < Z.rows(); ++i) {
      if (model.features() == FeatureMap::kYawAngles) {
        fig.inducing_alpha_a_rad.push_back(Z(i, 0));
        fig.inducing_alpha_b_rad.push_back(Z(i, 1));
      } else if (Z.cols() >= 6 && model.features() != FeatureMap::kWorldPosition) {  // [b_p_a, b_p_b, …]
        fig.inducing_alpha_a_rad.push_back(std::atan2(Z(i, 1), Z(i, 0)));
        fig.inducing_alpha_b_rad.push_back(std::atan2(Z(i, 4), Z(i, 3)));
      }
    }
    break;
  }
  fig.valid = true;
  return fig;
}

}  // namespace

void EvaluationParams::validate() const {
  if (kernels.empty()) throw std::invalid_argument("evaluation: no kernel given");
  for (const auto& k : kernels) BiasPreset::byName(k);  // throws with the list of presets
  if (inducing.empty()) throw std::invalid_argument("evaluation: no number of inducing points given");
  for (int m : inducing) {
    if (m < 1) throw std::invalid_argument(fmt::format("evaluation: inducing must be ≥ 1, got {}", m));
  }
  if (repeats < 1) throw std::invalid_argument(fmt::format("evaluation: repeats must be ≥ 1, got {}", repeats));
  if (threads < 1) throw std::invalid_argument(fmt::format("evaluation: threads must be ≥ 1, got {}", threads));
  if (!(figure_rate_hz > 0.0)) throw std::invalid_argument("evaluation: figure_rate_hz must be > 0");
  train.validate();
  dataset.validate();
}

namespace {

/// Results are keyed by test flight name: two flights must never share one.
void checkDistinctNames(const std::vector<NamedFlight>& test) {
  for (std::size_t i = 0; i < test.size(); ++i) {
    for (std::size_t k = 0; k < i; ++k) {
      if (test[i].name == test[k].name)
        throw std::invalid_argument(fmt::format("evaluation: two test flights are named '{}'", test[i].name));
    }
  }
}

/// Every (kernel, M, repeat) in the order of the parameters.
std::vector<Job> makeJobs(const EvaluationParams& params) {
  std::vector<Job> jobs;
  for (const auto& kernel : params.kernels) {
    for (int m : params.inducing) {
      for (int r = 0; r < params.repeats; ++r) jobs.push_back({kernel, m, r});
    }
  }
  return jobs;
}

/// What every job reads; nothing in it changes while the jobs run.
struct JobInputs {
  const std::vector<NamedFlight>& test;
  const AnchorSurvey& survey;
  const EvaluationParams& params;
  const BiasDataset& train_data;
  const std::map<std::string, BiasDataset>& test_data;  ///< by test flight
  const std::map<std::string, LocalizationRun>& uncorrected;  ///< by test flight
};

/// One job: train the bias model, localize every test flight with its correction and score it. Returns the train
/// time and the per-flight part of the progress line.
std::pair<double, std::string> runJob(const Job& job, const JobInputs& in, JobOutput& out) {
  BiasTrainParams tp = in.params.train;
  tp.preset = job.kernel;
  tp.num_inducing = job.inducing;
  tp.svgp.seed = static_cast<std::uint64_t>(job.repeat + 1);
  if (in.params.threads > 1) tp.svgp.num_threads = 1;  // the configurations already run in parallel
  BiasTrainReport report;
  BiasModel model = trainBiasModel(in.train_data, tp, &report);
  const BiasPredictor predictor = model.predictor();
  LocalizationOptions corrected = in.params.localization;
  applyBiasModelLevel(model, &corrected.params);  // (F24b)
  std::string line;
  for (const auto& f : in.test) {
    LocalizationRun run = localizeFlight(f.flight, in.survey, corrected, predictor);
    EvaluationRun er;
    er.kernel = job.kernel;
    er.inducing = job.inducing;
    er.repeat = job.repeat;
    er.flight = f.name;
    er.rmse_uncorrected_m = airborneRmse(in.uncorrected.at(f.name), f.name);
    er.rmse_corrected_m = airborneRmse(run, f.name);
    std::tie(er.bias_rmse_before_m, er.bias_rmse_after_m) = biasRmse(in.test_data.at(f.name), model);
    const BiasCalibration cal = biasCalibration(in.test_data.at(f.name), model);  // (P43)
    er.coverage_1sigma = cal.coverage_1sigma;
    er.coverage_2sigma = cal.coverage_2sigma;
    er.nlpd = cal.nlpd;
    er.coverage = cal.coverage;
    er.train_seconds = report.train_seconds;
    out.runs.push_back(er);
    for (const auto& s : decimatedAirborne(*run.metrics, in.params.figure_rate_hz)) out.errors.emplace_back(f.name, s);
    line += fmt::format(" {} {:.3f}→{:.3f} m", f.name, er.rmse_uncorrected_m, er.rmse_corrected_m);
    if (job.repeat == 0) out.corrected.emplace(f.name, std::move(run));
  }
  if (job.repeat == 0) out.model = std::move(model);
  return {report.train_seconds, line};
}

/// Runs run_one(0 … n − 1) on up to `threads` threads, the calling one included. After the first exception no job
/// starts; it is rethrown once every thread has stopped.
void runInParallel(std::size_t n, int threads, const std::function<void(std::size_t)>& run_one) {
  std::atomic<std::size_t> next{0};
  std::mutex mutex;
  std::exception_ptr failure;
  const auto worker = [&] {
    for (std::size_t j = next++; j < n; j = next++) {
      try {
        run_one(j);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!failure) failure = std::current_exception();
        next = n;
      }
    }
  };
  const int n_threads = std::min<int>(threads, static_cast<int>(n));
  std::vector<std::thread> pool;
  for (int i = 1; i < n_threads; ++i) {
    try {
      pool.emplace_back(worker);
    } catch (const std::system_error&) {
      break;  // no more threads to be had: the jobs go to the threads started (results do not depend on which)
    }
  }
  worker();
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

/// The repeat-0 job of a configuration.
std::size_t findJob(const std::vector<Job>& jobs, const std::string& kernel, int inducing) {
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    if (jobs[j].kernel == kernel && jobs[j].inducing == inducing && jobs[j].repeat == 0) return j;
  }
  throw std::logic_error("evaluation: configuration not found");
}

/// Merges the jobs' outputs into result: runs, the table rows, the error samples and, from the best configuration
/// (largest error reduction), the corrected trajectories and Fig. 7.
void collectJobs(const std::vector<Job>& jobs, std::vector<JobOutput>& outputs, const BiasDataset& train_data,
                 EvaluationResult& result) {
  for (auto& out : outputs) {
    result.runs.insert(result.runs.end(), out.runs.begin(), out.runs.end());
  }
  result.rows = aggregateRuns(result.runs);
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    auto& dst = result.corrected_errors[configKey(jobs[j].kernel, jobs[j].inducing)];
    dst.insert(dst.end(), outputs[j].errors.begin(), outputs[j].errors.end());
  }

  const auto best_row = std::max_element(result.rows.begin(), result.rows.end(), [](const auto& a, const auto& b) {
    return a.change_pct > b.change_pct;  // max_element of the reverse order: the most negative change
  });
  result.best_kernel = best_row->kernel;
  result.best_inducing = best_row->inducing;
  result.best_corrected = std::move(outputs[findJob(jobs, result.best_kernel, result.best_inducing)].corrected);
  // Fig. 7 for the best configuration (repeat 1), whatever its inputs.
  result.angle_figure = angleFigure(outputs[findJob(jobs, result.best_kernel, result.best_inducing)].model, train_data,
                                    result.best_kernel, result.best_inducing);
}

}  // namespace

EvaluationResult runEvaluation(const std::vector<NamedFlight>& train, const std::vector<NamedFlight>& test,
                               const AnchorSurvey& survey, const EvaluationParams& params,
                               const EvaluationProgress& progress) {
  params.validate();
  if (train.empty()) throw std::invalid_argument("evaluation: no training flight given");
  if (test.empty()) throw std::invalid_argument("evaluation: no test flight given");
  checkDistinctNames(test);
  const auto t0 = std::chrono::steady_clock::now();
  const auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };
  EvaluationResult result;

  // Training data (paper eq. 6) from the training flights' ground truth.
  std::vector<Flight> train_flights;
  for (const auto& f : train) train_flights.push_back(f.flight);
  BiasDatasetParams dataset_params = params.dataset;
  dataset_params.localization = params.localization;  // estimated GP inputs come from the same filter
  const BiasDataset train_data = buildBiasDataset(train_flights, survey, dataset_params);
  result.dataset_report = train_data.reportText();
  result.n_train_samples = train_data.samples.size();
  result.inputs_from_estimate = dataset_params.inputs == BiasInputSource::kFilterEstimate;
  say(fmt::format("training data: {} samples from {} flight(s)", train_data.samples.size(), train.size()));

  // Test data for the bias RMSE (ground-truth features), and the uncorrected localization once per flight.
  std::map<std::string, BiasDataset> test_data;
  for (const auto& f : test) {
    // The bias RMSE on a test flight uses GP inputs of the same source as training (ε from its ground truth).
    test_data.emplace(f.name, buildBiasDataset({f.flight}, survey, dataset_params));
    LocalizationRun run = localizeFlight(f.flight, survey, params.localization);
    say(fmt::format("{}: uncorrected airborne RMSE {:.3f} m", f.name, airborneRmse(run, f.name)));
    result.uncorrected.emplace(f.name, std::move(run));
  }

  const std::vector<Job> jobs = makeJobs(params);
  std::vector<JobOutput> outputs(jobs.size());
  const JobInputs inputs{test, survey, params, train_data, test_data, result.uncorrected};
  std::mutex mutex;
  std::size_t done = 0;
  runInParallel(jobs.size(), params.threads, [&](std::size_t j) {
    const Job& job = jobs[j];
    const auto [train_seconds, line] = runJob(job, inputs, outputs[j]);
    std::lock_guard<std::mutex> lock(mutex);
    say(fmt::format("[{}/{}] {} M={} repeat {}: trained in {:.1f} s;{}", ++done, jobs.size(), job.kernel,
                    job.inducing, job.repeat + 1, train_seconds, line));
  });

  collectJobs(jobs, outputs, train_data, result);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

namespace {

/// Each report file appears complete or not at all (io/FileAccess.h).
void writeText(const std::filesystem::path& path, const std::string& text) {
  writeFileAtomically(path.string(), text, "report file");
}

std::string trajectoryRows(const std::string& flight, const std::string& variant, const Trajectory& traj,
                           double rate_hz) {
  std::string out;
  double next_t = -std::numeric_limits<double>::infinity();
  for (const auto& s : traj) {
    if (s.t_s < next_t) continue;
    out += fmt::format("{},{},{:.4f},{:.4f},{:.4f},{:.4f}\n", flight, variant, s.t_s, s.w_p_b.x(), s.w_p_b.y(),
                       s.w_p_b.z());
    next_t = s.t_s + 1.0 / rate_hz;
  }
  return out;
}

nlohmann::json toVector(const std::vector<double>& v) { return nlohmann::json(v); }

/// figdata/calibration.csv (P43): coverage of the predicted bias intervals per run and nominal level.
std::string calibrationCsv(const EvaluationResult& result) {
  std::string calibration = "kernel,inducing,repeat,flight,level,coverage\n";
  for (const auto& r : result.runs) {
    for (std::size_t k = 0; k < r.coverage.size() && k < calibrationLevels().size(); ++k) {
      calibration += fmt::format("{},{},{},{},{:.2f},{:.5f}\n", r.kernel, r.inducing, r.repeat, r.flight,
                                 calibrationLevels()[k], r.coverage[k]);
    }
  }
  return calibration;
}

constexpr double kFigureRate_hz = 50.0;  ///< decimation of the error and trajectory figure data

/// figdata/errors.csv (Fig. 6): uncorrected rows as kernel "none", inducing 0.
std::string errorsCsv(const EvaluationResult& result) {
  std::string errors = "kernel,inducing,flight,corrected,t,error_m\n";
  for (const auto& [flight, run] : result.uncorrected) {
    for (const auto& s : decimatedAirborne(*run.metrics, kFigureRate_hz)) {
      errors += fmt::format("none,0,{},0,{:.4f},{:.5f}\n", flight, s.t_s, s.error_norm_m);
    }
  }
  for (const auto& [key, samples] : result.corrected_errors) {
    const auto slash = key.find('/');
    const std::string kernel = key.substr(0, slash);
    const std::string m = key.substr(slash + 1);
    for (const auto& [flight, s] : samples) {
      errors += fmt::format("{},{},{},1,{:.4f},{:.5f}\n", kernel, m, flight, s.t_s, s.error_norm_m);
    }
  }
  return errors;
}

/// figdata/trajectories.csv (top view): ground truth, uncorrected, best corrected.
std::string trajectoriesCsv(const EvaluationResult& result) {
  const double rate_hz = kFigureRate_hz;
  std::string traj = "flight,variant,t,x,y,z\n";
  const std::string corrected_label = fmt::format("corrected {} M={}", result.best_kernel, result.best_inducing);
  for (const auto& [flight, run] : result.uncorrected) {
    if (run.metrics) {
      double next_t = -std::numeric_limits<double>::infinity();
      for (const auto& s : run.metrics->samples) {
        if (s.t_s < next_t) continue;
        traj += fmt::format("{},ground_truth,{:.4f},{:.4f},{:.4f},{:.4f}\n", flight, s.t_s, s.w_p_true.x(),
                            s.w_p_true.y(), s.w_p_true.z());
        next_t = s.t_s + 1.0 / rate_hz;
      }
    }
    traj += trajectoryRows(flight, "uncorrected", run.trajectory, rate_hz);
    if (const auto it = result.best_corrected.find(flight); it != result.best_corrected.end()) {
      traj += trajectoryRows(flight, corrected_label, it->second.trajectory, rate_hz);
    }
  }
  return traj;
}

/// figdata/anchors.csv
std::string anchorsCsv(const AnchorSurvey& survey) {
  std::string anchors = "id,x,y,z\n";
  for (const auto& a : survey.anchors) {
    anchors += fmt::format("{},{:.6f},{:.6f},{:.6f}\n", a.id, a.w_p.x(), a.w_p.y(), a.w_p.z());
  }
  return anchors;
}

/// figdata/fig7.json (Fig. 7); a cell without data is null.
nlohmann::json angleFigureJson(const BiasAngleFigure& fig) {
  nlohmann::json grid = nlohmann::json::array();
  for (Eigen::Index r = 0; r < fig.grid_mean_m.rows(); ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index c = 0; c < fig.grid_mean_m.cols(); ++c) {
      const double v = fig.grid_mean_m(r, c);
      row.push_back(std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr));  // no data: null
    }
    grid.push_back(row);
  }
  const nlohmann::json j = {{"kernel", fig.kernel},
                            {"inducing", fig.inducing},
                            {"id_a", fig.id_a},
                            {"id_b", fig.id_b},
                            {"alpha_i_rad", toVector(fig.alpha_a_rad)},
                            {"alpha_j_rad", toVector(fig.alpha_b_rad)},
                            {"error_m", toVector(fig.error_m)},
                            {"grid_alpha_i_rad", toVector(fig.grid_alpha_a_rad)},
                            {"grid_alpha_j_rad", toVector(fig.grid_alpha_b_rad)},
                            {"grid_mean_m", grid},
                            {"inducing_alpha_i_rad", toVector(fig.inducing_alpha_a_rad)},
                            {"inducing_alpha_j_rad", toVector(fig.inducing_alpha_b_rad)}};
  return j;
}

/// REPORT.md up to its figures: how it was made, the table (Fig. 5), the uncorrected and per-flight results.
std::string reportResultsMarkdown(const EvaluationResult& result, const std::string& command) {
  std::string md = "# uwbtdoa evaluation report\n\n";
  md += "Made by\n\n```sh\n" + command + "\n```\n\n";
  md += fmt::format(
      "Bias models trained on {} samples; each configuration trained {} time(s) (seeds 1…); airborne RMSE "
      "(ground-truth z > 0.3 m) of the filter without and with the GP correction, the GP fed from the filter's own "
      "estimate (paper III-D). Change = 100 (corrected / uncorrected − 1): negative means the correction reduced "
      "the error (e.g. −18.4 %). The table's RMSEs are computed per test flight and then averaged over the test "
      "flights and repeats (not pooled over their samples). Total time {:.0f} s.\n\n",
      result.n_train_samples, result.rows.empty() ? 0 : result.rows.front().n_repeats, result.seconds);
  md += "## Localization error per kernel and number of inducing points (paper Fig. 5)\n\n";
  md += toMarkdown(result.rows) + "\n";
  md += fmt::format(
      "The bias RMSE column is the TDoA measurement error (paper eq. 6) on the test flights before and after "
      "subtracting the GP mean, with GP inputs from {} (as in training).\n\n",
      result.inputs_from_estimate ? "the uncorrected filter's estimate" : "the ground-truth pose");
  md += "Uncorrected filter per test flight:\n\n| flight | airborne RMSE [m] | p50 [m] | p90 [m] | p99 [m] |\n"
        "|---|---:|---:|---:|---:|\n";
  for (const auto& [flight, run] : result.uncorrected) {
    const auto& a = run.metrics->airborne;
    md += fmt::format("| {} | {:.3f} | {:.3f} | {:.3f} | {:.3f} |\n", flight, a.rmse_m, a.p50_m, a.p90_m, a.p99_m);
  }
  md += fmt::format("\nBest configuration: **{} with M = {}**.\n\n", result.best_kernel, result.best_inducing);
  md += fmt::format(
      "## Per test flight, best configuration ({} M = {}; repeats averaged)\n\n"
      "Airborne RMSE without and with the correction, and the calibration of the predicted bias on the test flight "
      "(docs/math/gp.md P43, P43b): the share of TDoA errors ε inside the central intervals of 68.3 % and 95.4 % of the "
      "model's predictive distribution around µ with σ² = var_f + σ_n² (a Student-t of the model file's degrees of "
      "freedom and scale, or a Gaussian) and its negative log predictive density per sample.\n\n",
      result.best_kernel, result.best_inducing);
  md += perFlightMarkdown(result.runs, result.best_kernel, result.best_inducing) + "\n";
  return md;
}

/// REPORT.md's figure section: one paragraph per figure listed (all when figures is empty).
std::string reportFiguresMarkdown(const EvaluationResult& result, const std::vector<std::string>& figures) {
  std::string md = "## Figures\n\n";
  const auto addFigure = [&](const std::string& name, const std::string& text) {
    if (figures.empty() || std::find(figures.begin(), figures.end(), name) != figures.end()) md += text;
  };
  addFigure("fig5_improvement.png",
            "Change of the airborne RMSE (negative = reduced) against the number of inducing points per kernel, with "
            "the spread over repeats (Fig. 5):\n\n"
            "![Fig. 5](fig5_improvement.png)\n\n");
  addFigure("fig6_error_distribution.png",
            "Distribution of the airborne position error without and with correction, best configuration, all "
            "airborne samples of the test flights pooled (decimated to 50 Hz; its RMSEs therefore differ from the "
            "table's per-flight mean) (Fig. 6):\n\n"
            "![Fig. 6](fig6_error_distribution.png)\n\n");
  const auto& fig = result.angle_figure;
  if (fig.valid) {
    addFigure("fig7_bias_vs_angles.png",
              fmt::format("Measured TDoA error of anchor pair ({}, {}) on the training flights over the two anchor "
                          "yaw angles, next to the mean of the best model ({} with M = {}) at the same samples, "
                          "averaged per 5° cell; cells without training data are blank (the model is not shown where "
                          "it would extrapolate). Red: inducing points in angle coordinates (Fig. 7):\n\n"
                          "![Fig. 7](fig7_bias_vs_angles.png)\n\n",
                          fig.id_a, fig.id_b, fig.kernel, fig.inducing));
  }
  addFigure("calibration.png",
            "Coverage of the predicted bias intervals against their nominal probability, per configuration (mean "
            "over repeats and test flights; on the diagonal = calibrated, below = over-confident):\n\n"
            "![calibration](calibration.png)\n\n");
  addFigure("per_flight.png",
            "Per test flight, best configuration: airborne RMSE without and with the correction, and the 1σ/2σ "
            "coverage of the predicted bias:\n\n![per flight](per_flight.png)\n\n");
  for (const auto& [flight, run] : result.uncorrected) {
    const std::string png = "trajectory_" + flight + ".png";
    addFigure(png, fmt::format("Top view of {} (ground truth, uncorrected, corrected):\n\n![{}]({})\n\n", flight,
                               flight, png));
  }
  return md;
}

}  // namespace

void writeEvaluation(const EvaluationResult& result, const AnchorSurvey& survey, const std::string& dir,
                     const std::string& command, const std::vector<std::string>& figures) {
  namespace fs = std::filesystem;
  const fs::path root(dir);
  std::error_code ec;
  fs::create_directories(root / "figdata", ec);
  if (ec) throw FileError(fmt::format("cannot create {}: {}", (root / "figdata").string(), ec.message()));

  writeText(root / "table.md", toMarkdown(result.rows));
  writeText(root / "table.csv", toCsv(result.rows));
  writeText(root / "results.json", toJson(result.rows).dump(2) + "\n");
  writeText(root / "runs.csv", runsToCsv(result.runs));
  writeText(root / "figdata" / "calibration.csv", calibrationCsv(result));
  writeText(root / "figdata" / "errors.csv", errorsCsv(result));
  writeText(root / "figdata" / "trajectories.csv", trajectoriesCsv(result));
  writeText(root / "figdata" / "anchors.csv", anchorsCsv(survey));
  if (result.angle_figure.valid) {
    writeText(root / "figdata" / "fig7.json", angleFigureJson(result.angle_figure).dump() + "\n");
  } else {
    fs::remove(root / "figdata" / "fig7.json", ec);
  }

  std::string md = reportResultsMarkdown(result, command);
  md += reportFiguresMarkdown(result, figures);
  md += "## Training data\n\n```\n" + result.dataset_report + "\n```\n\n";
  md += "Files: `table.md`, `table.csv`, `results.json` (one object per kernel and M), `runs.csv` (every repeat and "
        "flight), `figdata/` (the data behind every figure; see docs/python.md).\n";
  writeText(root / "REPORT.md", md);
}

}  // namespace uwb
