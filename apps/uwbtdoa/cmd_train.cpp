/** @file cmd_train.cpp
 *  @brief `uwbtdoa train FLIGHT.csv [FLIGHT2.csv …] --anchors SURVEY.txt [--kernel pair-tdoa-pos|z1|z2|tdoa|…] [--inducing M]
 *         [--epochs E] [--batch B] [--seed S] [--lr LR] [--threads T] [--dump-arrays ARRAYS.csv] --out MODEL.json
 *         [--json]`
 *
 *  Builds the training set (paper eq. 6, eval/BiasDataset.h), trains the bias SVGP(s) (eval/BiasModel.h) with a
 *  progress bar on stderr, and prints the held-out bias RMSE before/after and the learned hyperparameters.
 */
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "Command.h"
#include "uwb/core/Error.h"
#include "uwb/eval/BiasModel.h"
#include "uwb/io/Airborne.h"
#include "uwb/io/FileAccess.h"
#include "uwb/io/InputChecks.h"
#include "uwb/io/UtilCsv.h"
#include "InputGuards.h"

namespace {

using nlohmann::json;

struct TrainOptions {
  std::vector<std::string> flights;
  std::string anchors, kernel = uwb::kDefaultTrainPreset, out, inputs = "estimate";
  int inducing = uwb::BiasTrainParams{}.num_inducing, epochs = 20, batch = 1024, passes = 1, threads = 0;
  std::string dump_arrays;
  std::uint64_t seed = 1;
  double lr = 0.01, lr_inducing = 0.01, natgrad = 0.2, holdout = 0.2, extra_sigma = uwb::BiasTrainParams{}.extra_sigma_m;
  double min_z = uwb::kAirborneMinZ_m, max_abs_error = 1.0, mean_scale = 1.0;
  uwb::PredictiveShape predictive_shape;
  bool neighbour_only = false, json_out = false, quiet = false, full_variance = false;
};

void progressBar(int model, int models, const uwb::gp::EpochReport& r) {
  const int width = 24;
  const int filled = static_cast<int>(std::round(width * static_cast<double>(r.epoch) / r.epochs));
  const double left = r.epoch > 0 ? r.elapsed_s / r.epoch * (r.epochs - r.epoch) : 0.0;
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(width, '.');
  std::cerr << fmt::format("\r[{}] model {}/{} epoch {:3d}/{:<3d} ELBO {:9.4f}  val bias RMSE {:.4f} m  {:5.1f} s left ",
                           bar, model, models, r.epoch, r.epochs, r.elbo, r.val_rmse, left);
  if (r.epoch == r.epochs) std::cerr << '\n';
  std::cerr.flush();
}

/// The training arrays as CSV, one row per sample, named columns: the flight (file stem), time [s], the anchor pair,
/// the GP inputs of the preset (featureColumnNames),
/// the target ε [m] (paper eq. 6; the pair-mean presets subtract their per-pair constant from it before the GP),
/// whether the sample is in the held-out time blocks, and where it comes from.
void dumpArrays(const std::string& path, const uwb::BiasDataset& data, const uwb::BiasTrainParams& tp) {
  const uwb::BiasPreset preset = uwb::BiasPreset::byName(tp.preset);
  const std::vector<bool> hold = uwb::holdoutMask(data.samples, tp.holdout_fraction, tp.holdout_block_s);
  std::ostringstream out;
  out << "flight,t_s,id_a,id_b";
  for (const auto& name : uwb::featureColumnNames(preset.features)) out << ',' << name;
  out << ",error_m,holdout\n";
  const int D = uwb::featureDim(preset.features);
  double row[uwb::kMaxFeatureDim];
  for (std::size_t i = 0; i < data.samples.size(); ++i) {
    const uwb::BiasSample& s = data.samples[i];
    uwb::featureRow(preset.features, s.feature, row);
    const std::string flight = std::filesystem::path(data.flights.at(static_cast<std::size_t>(s.flight)).source).stem().string();
    out << fmt::format("{},{:.6f},{},{}", flight, s.t_s, s.feature.id_a, s.feature.id_b);
    for (int d = 0; d < D; ++d) out << fmt::format(",{:.17g}", row[d]);
    out << fmt::format(",{:.17g},{}\n", s.error_m, hold[i] ? 1 : 0);
  }
  uwb::writeFileAtomically(path, out.str(), "training arrays");
}

uwb::BiasDatasetParams datasetParams(const TrainOptions& o) {
  uwb::BiasDatasetParams dp;
  dp.min_z_m = o.min_z;
  dp.max_abs_error_m = o.max_abs_error;
  dp.neighbour_pairs_only = o.neighbour_only;
  dp.inputs = uwb::biasInputSourceFromString(o.inputs);
  return dp;
}

uwb::BiasTrainParams trainParams(const TrainOptions& o) {
  uwb::BiasTrainParams tp;
  tp.preset = o.kernel;
  tp.num_inducing = o.inducing;
  tp.holdout_fraction = o.holdout;
  tp.svgp.epochs = o.epochs;
  tp.svgp.batch_size = o.batch;
  tp.svgp.seed = o.seed;
  tp.svgp.lr = o.lr;
  tp.svgp.lr_inducing = o.lr_inducing;
  tp.svgp.natgrad_step = o.natgrad;
  tp.svgp.num_threads = o.threads;
  tp.extra_sigma_m = o.extra_sigma;
  tp.mean_scale = o.mean_scale;
  tp.predictive_shape = o.predictive_shape;
  tp.full_variance = o.full_variance;
  return tp;
}

/// The trained model, the training data of its last pass and that pass's report.
struct Trained {
  uwb::BiasModel model;
  uwb::BiasDataset data;
  uwb::BiasTrainReport rep;
};

/// Builds the training set and trains; docs/math/gp.md (P30): further passes take the GP inputs from the filter
/// corrected by the previous pass's model.
Trained trainPasses(const TrainOptions& o, const std::vector<uwb::Flight>& flights, const uwb::AnchorSurvey& survey) {
  uwb::BiasDatasetParams dp = datasetParams(o);
  Trained t;
  t.data = uwb::buildBiasDataset(flights, survey, dp);
  if (!o.quiet) std::cerr << t.data.reportText();
  for (const uwb::BiasFlightReport& f : t.data.flights)  // (F31) the estimated inputs' filter skipped sensor values
    for (const std::string& w : uwb::sensorRangeWarnings(f.sensor_range)) uwb::app::Warnings().add(f.source + ": " + w);
  const uwb::BiasTrainParams tp = trainParams(o);
  if (!o.dump_arrays.empty()) dumpArrays(o.dump_arrays, t.data, tp);
  const uwb::BiasTrainProgress progress = o.quiet ? uwb::BiasTrainProgress{} : uwb::BiasTrainProgress{progressBar};
  t.model = uwb::trainBiasModel(t.data, tp, &t.rep, progress);
  for (int pass = 2; pass <= o.passes; ++pass) {
    if (dp.inputs != uwb::BiasInputSource::kFilterEstimate)
      throw std::invalid_argument("--passes > 1 needs --inputs estimate");
    dp.estimate_bias = t.model.predictor();
    t.data = uwb::buildBiasDataset(flights, survey, dp);
    if (!o.quiet) std::cerr << "pass " << pass << ": GP inputs from the filter corrected by pass " << pass - 1 << '\n';
    t.model = uwb::trainBiasModel(t.data, tp, &t.rep, progress);
  }
  if (!o.dump_arrays.empty() && o.passes > 1) dumpArrays(o.dump_arrays, t.data, tp);  // the last pass's arrays
  return t;
}

/// The learned hyperparameters of each GP of the model: {"global" or "pair_A_B": {name: value, num_inducing}}.
json hyperparametersJson(const uwb::BiasModel& model) {
  json hyper = json::object();
  for (const auto& e : model.entries()) {
    json h;
    for (const auto& [name, p] : e.gp.params()) h[name] = p.value;
    h["num_inducing"] = e.gp.numInducing();
    hyper[e.id_a < 0 ? std::string("global") : fmt::format("pair_{}_{}", e.id_a, e.id_b)] = h;
  }
  return hyper;
}

/// The summary printed with --json and stored in the model file (metadata_json).
json trainSummaryJson(const TrainOptions& o, const Trained& t) {
  const uwb::BiasTrainReport& rep = t.rep;
  json summary{{"kernel", o.kernel},
               {"inducing", o.inducing},
               {"epochs", o.epochs},
               {"batch", o.batch},
               {"seed", o.seed},
               {"passes", o.passes},
               {"inputs", o.inputs},
               {"extra_sigma_m", o.extra_sigma},
               {"mean_scale", o.mean_scale},
               {"training_bias_level_m", t.model.trainingBiasLevel()},
               {"training_mean_level_m", t.model.trainingMeanLevel()},
               {"predictive_dof", o.predictive_shape.dof},
               {"predictive_scale", o.predictive_shape.scale},
               {"full_variance", o.full_variance},
               {"flights", o.flights},
               {"n_train", rep.n_train},
               {"n_holdout", rep.n_holdout},
               {"bias_rmse_before_m", rep.bias_rmse_before_m},
               {"bias_rmse_after_m", rep.bias_rmse_after_m},
               {"mean_predicted_std_m", rep.mean_predicted_std_m},
               {"mean_predictive_std_m", rep.mean_predictive_std_m},
               {"holdout_coverage_1sigma", rep.holdout_coverage_1sigma},
               {"holdout_coverage_2sigma", rep.holdout_coverage_2sigma},
               {"holdout_nlpd", rep.holdout_nlpd},
               {"train_seconds", rep.train_seconds},
               {"final_elbo", rep.final_elbo},
               {"threads", o.threads},
               {"num_models", rep.num_models},
               {"hyperparameters", hyperparametersJson(t.model)},
               {"model", o.out}};
  json excl = json::array();
  for (const auto& f : t.data.flights)
    excl.push_back({{"flight", f.source}, {"measurements", f.n_measurements}, {"unknown_anchor", f.n_unknown_anchor},
                    {"no_ground_truth", f.n_no_ground_truth}, {"pose_glitch", f.n_pose_glitch}, {"on_ground", f.n_on_ground},
                    {"non_neighbour", f.n_non_neighbour}, {"outlier", f.n_outlier}, {"used", f.n_used},
                    {"bias_level_m", std::isnan(f.bias_level_m) ? json(nullptr) : json(f.bias_level_m)}});
  summary["exclusions"] = excl;
  return summary;
}

void printTrainText(const TrainOptions& o, const Trained& t, const json& hyper) {
  const uwb::BiasTrainReport& rep = t.rep;
  std::cout << fmt::format("trained {} ({} GP{}, M = {}) on {} samples in {:.1f} s; held out {} samples; full-data "
                           "ELBO per datum {:.4f}\n",
                           o.kernel, rep.num_models, rep.num_models == 1 ? "" : "s", o.inducing, rep.n_train,
                           rep.train_seconds, rep.n_holdout, rep.final_elbo);
  std::cout << fmt::format("bias RMSE on the held-out part: before {:.4f} m, after {:.4f} m ({:+.1f} %), mean std of "
                           "the predicted mean {:.4f} m\n",
                           rep.bias_rmse_before_m, rep.bias_rmse_after_m,
                           100.0 * (rep.bias_rmse_after_m - rep.bias_rmse_before_m) / rep.bias_rmse_before_m,
                           rep.mean_predicted_std_m);
  std::cout << fmt::format("predictive distribution on the held-out part (docs/math/gp.md P43): mean σ {:.4f} m, "
                           "68.3 % interval covers {:.1f} %, 95.4 % interval {:.1f} %, NLPD {:.3f} nats (other flights: "
                           "`uwbtdoa predict-bias`)\n",
                           rep.mean_predictive_std_m, 100.0 * rep.holdout_coverage_1sigma,
                           100.0 * rep.holdout_coverage_2sigma, rep.holdout_nlpd);
  if (t.model.trainingBiasLevel() > 0.0)
    std::cout << fmt::format("TDoA bias level of the training flights (filter.md F23c) {:.3f} m: the filter scales the "
                             "mean down on a flight of a lower level (F24b)\n",
                             t.model.trainingBiasLevel());
  if (t.model.trainingMeanLevel() > 0.0)
    std::cout << fmt::format("level of the model's own mean on them {:.3f} m: the filter compares it with the mean's "
                             "level on the flight at hand (F24c)\n",
                             t.model.trainingMeanLevel());
  std::cout << "learned hyperparameters:\n";
  for (const auto& [model_name, h] : hyper.items()) {
    std::cout << "  " << model_name << ":";
    for (const auto& [k, v] : h.items()) std::cout << ' ' << k << '=' << v.dump();
    std::cout << '\n';
  }
  std::cout << "model written to " << o.out << '\n';
}

void run(const TrainOptions& o) {
  {  // before minutes of training; the model must not replace one of the inputs
    std::vector<std::string> inputs = o.flights;
    inputs.push_back(o.anchors);
    uwb::checkOutputFile(o.out, "bias model", inputs);
  }
  if (o.passes > 1 && o.inputs != "estimate") throw std::invalid_argument("--passes > 1 needs --inputs estimate");
  const uwb::AnchorSurvey survey = uwb::readAnchorSurvey(o.anchors);
  uwb::app::Warnings().addIssues(uwb::checkSurveyGeometry(survey));  // errors stop, warnings go to stderr
  std::vector<uwb::Flight> flights;
  uwb::FlightReadOptions ro;
  ro.required = {uwb::Stream::kTdoa};
  for (const auto& f : o.flights) flights.push_back(uwb::readFlightCsv(f, ro));

  Trained t = trainPasses(o, flights, survey);
  const json summary = trainSummaryJson(o, t);
  t.model.metadata_json = uwb::app::dumpJson(summary);
  t.model.save(o.out);
  if (o.json_out) {
    std::cout << uwb::app::dumpJson(summary) << '\n';
    return;
  }
  printTrainText(o, t, summary.at("hyperparameters"));
}

void setup(CLI::App& sub) {
  auto o = std::make_shared<TrainOptions>();
  sub.add_option("flights", o->flights, "Training flight CSV files (UTIL layout, with ground-truth pose)")->required()->check(CLI::ExistingFile);
  sub.add_option("--anchors", o->anchors, "Anchor survey (UTIL format)")->required()->check(CLI::ExistingFile);
  sub.add_option("--kernel", o->kernel, "pair-tdoa-pos (default: per pair, eq. 9 plus a map over the arena, docs/math/gp.md P26b–P26c) | z1 | z2 | tdoa (paper eq. 7–9), pair-tdoa | pair-pos (one GP per anchor pair), tdoa-pm | anchor-tdoa | anchor-tdoa-pm (per-pair mean / anchor-specific eq. 9, docs/math/gp.md P28–P29)")->capture_default_str();
  sub.add_option("--inducing", o->inducing, "Number of inducing points M (per GP)")->check(CLI::PositiveNumber)->capture_default_str();
  sub.add_option("--epochs", o->epochs, "Training epochs")->check(CLI::PositiveNumber);
  sub.add_option("--batch", o->batch, "Minibatch size")->check(CLI::PositiveNumber);
  sub.add_option("--passes", o->passes,
                 "Training passes; pass k > 1 takes the GP inputs from the filter corrected by pass k-1's model")
      ->check(CLI::PositiveNumber)->capture_default_str();
  sub.add_option("--extra-sigma", o->extra_sigma,
                 "Std [m] added in quadrature to the filter's TDoA noise when the correction is on (docs/math/gp.md P31)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  sub.add_option("--mean-scale", o->mean_scale,
                 "Factor w in [0, 1] on the predicted bias mean stored in the model (docs/math/gp.md P44)")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  sub.add_option("--predictive-dof", o->predictive_shape.dof,
                 "Degrees of freedom of the Student-t predictive distribution the calibration scores; 0 = Gaussian "
                 "(docs/math/gp.md P43b)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  sub.add_option("--predictive-scale", o->predictive_shape.scale,
                 "Scale of that distribution in units of the predictive std (docs/math/gp.md P43b)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  sub.add_flag("--full-variance", o->full_variance,
               "The filter uses the TDoA variance scaled by (var_f + noise)/E[eps^2] for corrected measurements instead "
               "of adding var_f (docs/math/gp.md P45)");
  sub.add_option("--seed", o->seed, "Random seed (k-means++, shuffling)");
  sub.add_option("--lr", o->lr, "Adam learning rate of the hyperparameters");
  sub.add_option("--lr-inducing", o->lr_inducing, "Adam learning rate of the inducing points");
  sub.add_option("--natgrad", o->natgrad, "Natural-gradient step for q(v) (0: Adam instead)");
  sub.add_option("--threads", o->threads, "Threads sharing each minibatch (0: one per hardware thread); the model "
                 "is bit-identical for a given seed and thread count")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  sub.add_option("--dump-arrays", o->dump_arrays,
                 "Write the training arrays (flight, t_s, id_a, id_b, the preset's GP input columns, error_m, holdout) "
                 "as CSV, to train elsewhere");
  sub.add_option("--holdout", o->holdout, "Held-out fraction (time blocks) for the before/after RMSE");
  sub.add_option("--min-z", o->min_z, "Exclude samples with ground-truth z below this [m] (on the ground)");
  sub.add_option("--max-abs-error", o->max_abs_error, "Exclude gross outliers |eps| above this [m] (0: off)");
  sub.add_flag("--neighbour-only", o->neighbour_only, "Keep only neighbour anchor pairs");
  sub.add_option("--inputs", o->inputs,
                 "GP inputs from the uncorrected filter's 'estimate' (as at run time) or the ground 'truth' pose")
      ->check(CLI::IsMember({"estimate", "truth"}))
      ->capture_default_str();
  sub.add_option("--out", o->out, "Output model JSON")->required();
  sub.add_flag("--json", o->json_out, "Print one JSON summary object on stdout");
  sub.add_flag("--quiet", o->quiet, "No progress or exclusion report on stderr");
  sub.callback([o] { run(*o); });
}

const bool kRegistered = uwb::app::registerCommand({"train", "Train a TDoA bias GP from flights with ground truth", setup});

}  // namespace
