/** @file cmd_predict_bias.cpp
 *  @brief `uwbtdoa predict-bias FLIGHT.csv --anchors SURVEY.txt --model MODEL.json --out OUT.csv [--json]`
 *
 *  Applies a bias model (eval/BiasModel.h) to every TDoA measurement that has ground truth and writes t, ids,
 *  measured TDoA, ε (paper eq. 6), the predicted mean, the std of that mean (latent, var_f) and the predictive std of ε
 *  (latent and likelihood noise, docs/math/gp.md P43). The summary scores the airborne samples (|ε| ≤ 1 m) against the
 *  predictive distribution: coverage of the 1σ and 2σ intervals and the NLPD (eval/BiasCalibration.h). GP inputs (--inputs): "truth" = the interpolated
 *  ground-truth pose (every measurement, airborne flag), "estimate" = the uncorrected filter's estimate on this
 *  flight, as at run time (only the samples of the training-data rules, eval/BiasDataset.h). The default is the
 *  source the model was trained with (its file's "training.inputs"), else "truth". A model trained on estimated
 *  inputs must be scored on estimated inputs: on ground-truth inputs its bias RMSE does not drop.
 */
#include <fmt/format.h>

#include <cmath>
#include <initializer_list>
#include <iostream>
#include <stdexcept>
#include <nlohmann/json.hpp>

#include "Command.h"
#include "uwb/core/Error.h"
#include "uwb/eval/BiasCalibration.h"
#include "uwb/eval/BiasDataset.h"
#include "uwb/eval/BiasModel.h"
#include "uwb/io/FileAccess.h"
#include "uwb/io/InputChecks.h"
#include "InputGuards.h"
#include "uwb/io/PoseTrack.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/sim/TdoaResiduals.h"

namespace {

struct Options {
  std::string flight, anchors, model, out;
  double min_z = uwb::kAirborneMinZ_m;
  std::string inputs;  ///< "" = from the model file, else "truth" | "estimate"
  bool json_out = false;
};

/// The GP input source: --inputs, else the one the model was trained with (its file's "training.inputs"), else truth.
std::string inputSource(const Options& o, const uwb::BiasModel& model) {
  if (!o.inputs.empty()) return o.inputs;
  const auto meta = nlohmann::json::parse(model.metadata_json, nullptr, false);
  return meta.is_object() && meta.contains("inputs") && meta.at("inputs").is_string()
             ? meta.at("inputs").get<std::string>()
             : "truth";
}

/// The CSV rows and the score of the airborne samples against the predictive distribution.
struct BiasRows {
  std::string out;
  double se_b = 0, se_a = 0;
  std::size_t n_air = 0, n_rows = 0;
  std::vector<double> residual_m, variance_m2;  // (P43) of the scored samples with a covering GP
  std::size_t n_non_finite = 0;  ///< rows with a non-finite value (an error in run(): no such row is written)
  std::string first_non_finite;
  /// (P43c) the flight's uncorrected bias level, measured by the filter that gives the GP inputs, and the level of
  /// the model's mean on it; unknown (nothing added) with ground-truth inputs
  double flight_level_m = std::numeric_limits<double>::quiet_NaN(), mean_level_m = flight_level_m;
};

/// The rows of every TDoA measurement with GP inputs from `source`: "estimate" = the uncorrected filter's estimate
/// (the samples of the training-data rules, all scored), "truth" = the interpolated ground-truth pose (every
/// measurement, the airborne ones with |ε| ≤ 1 m scored). The sums are accumulated here, in one function, in
/// the order and form that make the summary's numbers.
BiasRows collectRows(const Options& o, const uwb::Flight& flight, const uwb::AnchorSurvey& survey,
                     const uwb::BiasModel& model, uwb::BiasInputSource source) {
  std::string out = "t,idA,idB,tdoa_meas,error_m,bias_mean_m,bias_std_m,airborne,predictive_std_m\n";
  double se_b = 0, se_a = 0;
  std::size_t n_air = 0, n_rows = 0;
  std::vector<double> residual_m, variance_m2;  // (P43) of the scored samples with a covering GP
  const auto score = [&](double error_m, const uwb::BiasPredictive& p) {
    ++n_air;
    se_b += error_m * error_m;
    se_a += (error_m - p.mean_m) * (error_m - p.mean_m);
    if (p.covered && p.varianceM2() > 0.0) {
      residual_m.push_back(error_m - p.mean_m);
      variance_m2.push_back(p.varianceM2());
    }
  };
  // No row with a non-finite value is written: counted here, an error in run().
  std::size_t n_non_finite = 0;
  std::string first_non_finite;
  const auto checkRow = [&](double t_s, int id_a, int id_b, std::initializer_list<double> values) {
    for (const double v : values) {
      if (std::isfinite(v)) continue;
      if (n_non_finite++ == 0) first_non_finite = fmt::format("t = {:.3f} s, pair {}-{}", t_s, id_a, id_b);
      return;
    }
  };
  double flight_level_m = std::numeric_limits<double>::quiet_NaN(), mean_level_m = flight_level_m;
  if (source == uwb::BiasInputSource::kFilterEstimate) {
    uwb::BiasDatasetParams dp;
    dp.inputs = source;
    dp.min_z_m = o.min_z;
    const uwb::BiasDataset data = uwb::buildBiasDataset({flight}, survey, dp);
    flight_level_m = data.flights.at(0).bias_level_m;
    for (const std::string& w : uwb::sensorRangeWarnings(data.flights.at(0).sensor_range))  // (F31)
      uwb::app::Warnings().add(w);
    const uwb::DatasetPredictives predictives = uwb::datasetPredictives(model, data);
    mean_level_m = predictives.flight_mean_level_m.at(0);
    for (std::size_t i = 0; i < data.samples.size(); ++i) {
      const uwb::BiasSample& smp = data.samples[i];
      const uwb::BiasPredictive& p = predictives.samples[i];
      out += fmt::format("{:.6f},{},{},{:.7g},{:.7g},{:.7g},{:.7g},1,{:.7g}\n", smp.t_s, smp.feature.id_a,
                         smp.feature.id_b, smp.measured_m, smp.error_m, p.mean_m, std::sqrt(p.latent_variance_m2),
                         std::sqrt(p.varianceM2()));
      checkRow(smp.t_s, smp.feature.id_a, smp.feature.id_b,
               {smp.measured_m, smp.error_m, p.mean_m, p.latent_variance_m2, p.varianceM2()});
      score(smp.error_m, p);
    }
    n_rows = data.samples.size();
  }
  const uwb::PoseTrack track(flight);
  const auto residuals =
      source == uwb::BiasInputSource::kGroundTruth ? uwb::tdoaResiduals(flight, survey, track) : std::vector<uwb::TdoaResidual>{};
  if (source == uwb::BiasInputSource::kGroundTruth) n_rows = residuals.size();
  for (const auto& r : residuals) {
    const uwb::TdoaFeature f = uwb::makeTdoaFeature(r.id_a, r.id_b, r.w_p_b, r.w_q_b, survey.position(r.id_a), survey.position(r.id_b));
    const uwb::BiasPredictive p = model.predictive(f);
    const bool air = uwb::isAirborne(r.w_p_b.z(), o.min_z);
    out += fmt::format("{:.6f},{},{},{:.7g},{:.7g},{:.7g},{:.7g},{},{:.7g}\n", r.t_s, r.id_a, r.id_b, r.measured_m,
                       r.residual_m, p.mean_m, std::sqrt(p.latent_variance_m2), air ? 1 : 0, std::sqrt(p.varianceM2()));
    checkRow(r.t_s, r.id_a, r.id_b, {r.measured_m, r.residual_m, p.mean_m, p.latent_variance_m2, p.varianceM2()});
    if (air && std::abs(r.residual_m) <= 1.0) score(r.residual_m, p);
  }
  return {std::move(out), se_b, se_a, n_air, n_rows, std::move(residual_m), std::move(variance_m2), n_non_finite,
          std::move(first_non_finite), flight_level_m, mean_level_m};
}

void printPredictBiasText(const Options& o, const std::string& inputs, const BiasRows& rows, double before,
                          double after, const uwb::BiasCalibration& cal) {
  std::cout << fmt::format("{} rows written to {}; GP inputs from the {}; airborne (|eps| ≤ 1 m, {} samples) bias RMSE "
                           "before {:.4f} m, after {:.4f} m\n",
                           rows.n_rows, o.out, inputs == "truth" ? "ground truth" : "uncorrected filter's estimate",
                           rows.n_air, before, after);
  const std::string shape = cal.shape.dof > 0.0
                                ? fmt::format("Student-t, {:g} dof, scale {:g} σ", cal.shape.dof, cal.shape.scale)
                                : fmt::format("Gaussian, scale {:g} σ", cal.shape.scale);
  std::cout << fmt::format("predictive distribution (P43, {}; {} samples with a model): 1σ-mass interval coverage "
                           "{:.1f} % (nominal 68.3), 2σ-mass {:.1f} % (95.4), NLPD {:.3f} nats, mean σ {:.3f} m\n",
                           shape, cal.n, 100.0 * cal.coverage_1sigma, 100.0 * cal.coverage_2sigma, cal.nlpd,
                           cal.mean_std_m);
}

void run(const Options& o) {
  uwb::checkOutputFile(o.out, "bias CSV", {o.flight, o.anchors, o.model});
  const uwb::AnchorSurvey survey = uwb::readAnchorSurvey(o.anchors);
  uwb::app::Warnings().addIssues(uwb::checkSurveyGeometry(survey));  // errors stop, warnings go to stderr
  uwb::FlightReadOptions ro;
  ro.required = {uwb::Stream::kTdoa};
  const uwb::Flight flight = uwb::readFlightCsv(o.flight, ro);
  const uwb::BiasModel model = uwb::BiasModel::load(o.model);
  const std::string inputs = inputSource(o, model);
  const uwb::BiasInputSource source = uwb::biasInputSourceFromString(inputs);
  uwb::requireFeatureFrame(flight, source, o.flight);
  const BiasRows rows = collectRows(o, flight, survey, model, source);
  if (rows.n_non_finite > 0) {
    throw std::runtime_error(fmt::format("{} of {} bias rows hold a value that is not finite (first at {}): the model {} or "
                                         "the estimate of {} is broken; nothing written",
                                         rows.n_non_finite, rows.n_rows, rows.first_non_finite, o.model, o.flight));
  }
  const std::size_t n_air = rows.n_air;
  const double before = n_air ? std::sqrt(rows.se_b / n_air) : std::nan(""),
               after = n_air ? std::sqrt(rows.se_a / n_air) : std::nan("");
  const uwb::BiasCalibration cal = uwb::biasCalibration(rows.residual_m, rows.variance_m2, model.predictiveShape());
  nlohmann::json cal_json = uwb::toJson(cal);
  cal_json["n_uncovered"] = n_air - cal.n;
  const double flight_level_m = rows.flight_level_m, mean_level_m = rows.mean_level_m;
  const std::string json_text = uwb::app::dumpJson(
      nlohmann::json{{"flight", o.flight}, {"model", o.model}, {"inputs", inputs}, {"n_rows", rows.n_rows},
                     {"n_airborne", n_air}, {"bias_rmse_before_m", before}, {"bias_rmse_after_m", after},
                     {"calibration", cal_json}, {"out", o.out},
                     {"flight_bias_level_m", flight_level_m},
                     {"training_bias_level_m", model.trainingBiasLevel()},
                     {"model_mean_level_m", mean_level_m},
                     {"training_mean_level_m", model.trainingMeanLevel()},
                     {"level_excess_std_m", std::sqrt(model.levelExcessVarianceM2(flight_level_m, mean_level_m))}});
  uwb::writeFileAtomically(o.out, rows.out, "bias CSV");
  if (o.json_out) std::cout << json_text << '\n';
  else printPredictBiasText(o, inputs, rows, before, after, cal);
}

void setup(CLI::App& sub) {
  auto o = std::make_shared<Options>();
  sub.add_option("flight", o->flight, "Flight CSV (UTIL layout) with ground-truth pose")->required()->check(CLI::ExistingFile);
  sub.add_option("--anchors", o->anchors, "Anchor survey")->required()->check(CLI::ExistingFile);
  sub.add_option("--model", o->model, "Bias model JSON from `uwbtdoa train`")->required()->check(CLI::ExistingFile);
  sub.add_option("--out", o->out, "Output CSV")->required();
  sub.add_option("--min-z", o->min_z, "Airborne threshold for the summary [m]");
  sub.add_option("--inputs", o->inputs,
                 "GP inputs: 'truth' (ground-truth pose) or 'estimate' (uncorrected filter); default: as in training")
      ->check(CLI::IsMember({"truth", "estimate"}));
  sub.add_flag("--json", o->json_out, "Print one JSON summary object on stdout");
  sub.callback([o] { run(*o); });
}

const bool kRegistered = uwb::app::registerCommand(
    {"predict-bias", "Apply a bias model to a flight: per-measurement bias mean and std", setup});

}  // namespace
