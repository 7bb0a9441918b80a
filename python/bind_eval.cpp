/** @file bind_eval.cpp
 *  @brief Python bindings of uwb/eval (and the filter's parameters): GP training data from flights (BiasDataset),
 *  trained bias models (BiasModel), localization of a flight with or without a bias model, trajectory metrics.
 *
 *  Feature dicts (one row per measurement), as returned by make_tdoa_features / BiasDataset.arrays():
 *    id_a, id_b (int32), yaw_a, yaw_b [rad], b_p_a, b_p_b (N, 3) [m, body frame], w_p_b (N, 3) [m, world],
 *    w_p_anchor_a, w_p_anchor_b (N, 3) [m, world]. A key that the model's feature map reads must be present.
 */
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <nlohmann/json.hpp>

#include "bindings.h"
#include "uwb/eval/BiasCalibration.h"
#include "uwb/eval/BiasDataset.h"
#include "uwb/eval/BiasModel.h"
#include "uwb/eval/Evaluation.h"
#include "uwb/eval/Localization.h"
#include "uwb/eval/LocalizationJson.h"
#include "uwb/eval/TrajectoryMetrics.h"
#include "uwb/filter/EkfParamRegistry.h"
#include "uwb/filter/EkfParams.h"

namespace uwb::python {
namespace {

// ---------------------------------------------------------------------------------------------- features
/// The feature-dict keys that the GP inputs of `map` read (featureRow): a missing one is an error, not zeros.
std::vector<const char*> requiredFeatureKeys(FeatureMap map) {
  switch (map) {
    case FeatureMap::kYawAngles: return {"yaw_a", "yaw_b"};
    case FeatureMap::kBodyPositions: return {"b_p_a", "b_p_b"};
    case FeatureMap::kWorldPosition: return {"w_p_b"};
    case FeatureMap::kBodyPositionsAnchors: return {"b_p_a", "b_p_b", "w_p_anchor_a", "w_p_anchor_b"};
    case FeatureMap::kBodyPositionsWorld: return {"b_p_a", "b_p_b", "w_p_b"};
  }
  return {};
}

/// Feature dict → TdoaFeature rows. Keys other than id_a/id_b are optional (zeros) unless `map` reads them.
std::vector<TdoaFeature> featuresFromDict(const py::dict& d, std::optional<FeatureMap> map) {
  if (map) {
    for (const char* key : requiredFeatureKeys(*map)) {
      if (!d.contains(key)) {
        throw std::invalid_argument(std::string("features: key '") + key + "' is missing; the feature map '" +
                                    toString(*map) + "' reads it");
      }
    }
  }
  const Eigen::VectorXi ia = toIntVector(requireKey(d, "id_a", "features"), "features['id_a']");
  const auto n = ia.size();
  const Eigen::VectorXi ib = toIntVector(requireKey(d, "id_b", "features"), "features['id_b']");
  const auto opt = [&](const char* key, Eigen::Index cols) -> RowMat {
    if (!d.contains(key)) return RowMat::Zero(1, cols == 0 ? 1 : cols);
    RowMat m = toMatrix(d[key], cols, (std::string("features['") + key + "']").c_str());
    if (m.rows() != n && m.rows() != 1) {
      throw std::invalid_argument(std::string("features['") + key + "']: " + std::to_string(m.rows()) +
                                  " rows, expected " + std::to_string(n) + " (as id_a)");
    }
    return m;
  };
  if (ib.size() != n) throw std::invalid_argument("features['id_b']: length differs from id_a");
  const RowMat ya = opt("yaw_a", 0), yb = opt("yaw_b", 0), pa = opt("b_p_a", 3), pb = opt("b_p_b", 3),
               wp = opt("w_p_b", 3), wa = opt("w_p_anchor_a", 3), wb = opt("w_p_anchor_b", 3);
  const auto r = [](const RowMat& m, Eigen::Index i) { return m.rows() == 1 ? 0 : i; };
  std::vector<TdoaFeature> out(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    TdoaFeature& f = out[i];
    f.id_a = ia(i), f.id_b = ib(i);
    f.yaw_a_rad = ya(r(ya, i), 0), f.yaw_b_rad = yb(r(yb, i), 0);
    f.b_p_a = row3(pa, r(pa, i)), f.b_p_b = row3(pb, r(pb, i)), f.w_p_b = row3(wp, r(wp, i));
    f.w_p_anchor_a = row3(wa, r(wa, i)), f.w_p_anchor_b = row3(wb, r(wb, i));
  }
  return out;
}

}  // namespace

py::dict featuresToDict(const std::vector<const TdoaFeature*>& fs) {
  const auto n = static_cast<Eigen::Index>(fs.size());
  auto ia = newIntArray(n), ib = newIntArray(n);
  auto ma = ia.mutable_unchecked<1>(), mb = ib.mutable_unchecked<1>();
  RowMat yaw(n, 2), pa(n, 3), pb(n, 3), wp(n, 3), wa(n, 3), wb(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const TdoaFeature& f = *fs[i];
    ma(i) = f.id_a, mb(i) = f.id_b;
    yaw.row(i) << f.yaw_a_rad, f.yaw_b_rad;
    pa.row(i) = f.b_p_a.transpose(), pb.row(i) = f.b_p_b.transpose(), wp.row(i) = f.w_p_b.transpose();
    wa.row(i) = f.w_p_anchor_a.transpose(), wb.row(i) = f.w_p_anchor_b.transpose();
  }
  py::dict d;
  d["id_a"] = ia, d["id_b"] = ib, d["yaw_a"] = toNumpy(yaw.col(0), true), d["yaw_b"] = toNumpy(yaw.col(1), true);
  d["b_p_a"] = toNumpy(pa), d["b_p_b"] = toNumpy(pb), d["w_p_b"] = toNumpy(wp);
  d["w_p_anchor_a"] = toNumpy(wa), d["w_p_anchor_b"] = toNumpy(wb);
  return d;
}

namespace {

// ------------------------------------------------------------------------------------------- parameters
/// One setter per EkfParams field, from the parameter registry (uwb/filter/EkfParamRegistry.h): the Python value
/// is converted to the field's kind and checked against its range before it is set.
const Setters<EkfParams>& ekfSetters() {
  static const Setters<EkfParams> s = [] {
    Setters<EkfParams> out;
    for (const EkfParamInfo& info : ekfParamRegistry()) {
      out[info.name] = [&info](EkfParams& p, const py::handle& v) {
        EkfParamValue value;
        switch (info.kind) {
          case EkfParamKind::kReal:
          case EkfParamKind::kInteger: value = py::cast<double>(v); break;
          case EkfParamKind::kBool: value = py::cast<bool>(v); break;
          case EkfParamKind::kVec3: value = Vec3(row3(toMatrix(v, 3, info.name.c_str()), 0)); break;
          case EkfParamKind::kChoice: value = py::cast<std::string>(v); break;
        }
        setEkfParam(p, info, value, "params");
      };
    }
    return out;
  }();
  return s;
}

EkfParams ekfParams(const std::string& preset, const py::dict& overrides) {
  EkfParams p;
  if (preset == "defaults") p = EkfParams::defaults();
  else if (preset == "crazyflie") p = EkfParams::crazyflieLike();
  else if (preset == "tdoa-only") p = EkfParams::tdoaOnly();
  else throw std::invalid_argument("unknown filter preset '" + preset + "' (expected defaults, crazyflie, tdoa-only)");
  applyOverrides(p, ekfSetters(), overrides, "filter");
  p.validate();
  return p;
}

BiasDatasetParams datasetParams(const py::kwargs& kw) {
  BiasDatasetParams p;
  // GP inputs from the uncorrected filter's estimate unless inputs='truth', as `uwbtdoa train` and `evaluate` do: the
  // model then sees at training the pose error it will see at run time (eval/BiasDataset.h, BiasInputSource).
  p.inputs = BiasInputSource::kFilterEstimate;
  for (const auto& [key, value] : kw) {
    const std::string n = py::str(key);
    if (n == "b_t_tag") p.b_t_tag = row3(toMatrix(value, 3, "b_t_tag"), 0);
    else if (n == "min_z_m") p.min_z_m = py::cast<double>(value);
    else if (n == "glitch_margin_s") p.glitch_margin_s = py::cast<double>(value);
    else if (n == "max_abs_error_m") p.max_abs_error_m = py::cast<double>(value);
    else if (n == "neighbour_pairs_only") p.neighbour_pairs_only = py::cast<bool>(value);
    else if (n == "inputs") p.inputs = biasInputSourceFromString(py::cast<std::string>(value));
    else
      throw std::invalid_argument("unknown dataset parameter '" + n +
                                  "' (known: b_t_tag, min_z_m, glitch_margin_s, max_abs_error_m, "
                                  "neighbour_pairs_only, inputs)");
  }
  p.validate();
  return p;
}

// ---------------------------------------------------------------------------------------------- results
py::dict statsDict(const PositionErrorStats& s) {
  py::dict d;
  d["n"] = s.n, d["rmse_m"] = s.rmse_m, d["rmse_axis_m"] = toNumpy(s.rmse_axis_m, true), d["mean_m"] = s.mean_m;
  d["p50_m"] = s.p50_m, d["p90_m"] = s.p90_m, d["p99_m"] = s.p99_m, d["max_m"] = s.max_m;
  return d;
}

py::dict metricsDict(const TrajectoryMetrics& m) {
  const auto n = static_cast<Eigen::Index>(m.samples.size());
  RowMat t(n, 2), pt(n, 3), pe(n, 3), e(n, 3);
  py::array_t<bool> airborne(static_cast<py::ssize_t>(n));
  auto ma = airborne.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& s = m.samples[i];
    t.row(i) << s.t_s, s.error_norm_m;
    pt.row(i) = s.w_p_true.transpose(), pe.row(i) = s.w_p_est.transpose(), e.row(i) = s.error_m.transpose();
    ma(i) = s.airborne;
  }
  py::dict samples;
  samples["t"] = toNumpy(t.col(0), true), samples["p_true"] = toNumpy(pt), samples["p_est"] = toNumpy(pe);
  samples["error"] = toNumpy(e), samples["error_norm"] = toNumpy(t.col(1), true), samples["airborne"] = airborne;
  py::dict d;
  d["whole"] = statsDict(m.whole), d["airborne"] = statsDict(m.airborne), d["samples"] = samples;
  d["n_truth_not_covered"] = m.n_truth_not_covered;
  return d;
}

/// JSON as Python objects, numbers kept as they are (NaN stays float('nan'); json.loads of the dump would give None).
py::object jsonToPythonKeepingNan(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null: return py::none();
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float: return py::float_(j.get<double>());
    case nlohmann::json::value_t::string: return py::str(j.get<std::string>());
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& v : j) l.append(jsonToPythonKeepingNan(v));
      return l;
    }
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (auto it = j.begin(); it != j.end(); ++it) d[py::str(it.key())] = jsonToPythonKeepingNan(it.value());
      return d;
    }
    default: return py::none();
  }
}

}  // namespace

/// The run's summary: the keys of `uwbtdoa localize --json` (eval/LocalizationJson.h, one writer for both), and the
/// warnings of the samples skipped outside the sensors' ranges (filter.md F31), which the CLI prints.
py::dict summaryDict(const LocalizerSummary& s, const EkfParams& params) {
  py::dict d = jsonToPythonKeepingNan(localizerSummaryJson(s, params));
  d["sensor_range_warnings"] = sensorRangeWarnings(s.sensor_range);
  return d;
}

namespace {

py::dict trainReportDict(const BiasTrainReport& r) {
  py::dict d;
  d["n_train"] = r.n_train, d["n_holdout"] = r.n_holdout, d["bias_rmse_before_m"] = r.bias_rmse_before_m;
  d["bias_rmse_after_m"] = r.bias_rmse_after_m, d["mean_predicted_std_m"] = r.mean_predicted_std_m;
  d["mean_predictive_std_m"] = r.mean_predictive_std_m, d["holdout_coverage_1sigma"] = r.holdout_coverage_1sigma;
  d["holdout_coverage_2sigma"] = r.holdout_coverage_2sigma, d["holdout_nlpd"] = r.holdout_nlpd;
  d["train_seconds"] = r.train_seconds, d["num_models"] = r.num_models, d["final_elbo"] = r.final_elbo;
  return d;
}

py::dict flightReportDict(const BiasFlightReport& r) {
  py::dict d;
  d["source"] = r.source, d["n_measurements"] = r.n_measurements, d["n_unknown_anchor"] = r.n_unknown_anchor;
  d["n_no_ground_truth"] = r.n_no_ground_truth, d["n_pose_glitch"] = r.n_pose_glitch;
  d["n_on_ground"] = r.n_on_ground, d["n_non_neighbour"] = r.n_non_neighbour, d["n_outlier"] = r.n_outlier;
  d["n_used"] = r.n_used, d["n_pose_glitches_detected"] = r.n_pose_glitches_detected;
  d["bias_level_m"] = r.bias_level_m;
  return d;
}

std::vector<NamedFlight> namedFlights(const py::handle& flights, const char* what) {
  std::vector<NamedFlight> out;
  if (py::isinstance<py::dict>(flights)) {
    for (const auto& [name, f] : py::cast<py::dict>(flights)) out.push_back({py::str(name), py::cast<Flight>(f)});
  } else {
    for (const auto& f : flights) {
      Flight flight = py::cast<Flight>(f);
      std::string name = flight.source;
      const auto slash = name.find_last_of('/');
      if (slash != std::string::npos) name = name.substr(slash + 1);
      if (name.size() > 4 && name.substr(name.size() - 4) == ".csv") name.resize(name.size() - 4);
      out.push_back({name, std::move(flight)});
    }
  }
  if (out.empty()) throw std::invalid_argument(std::string(what) + ": no flight given");
  return out;
}

py::object jsonToPython(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

}  // namespace

EkfParams ekfParamsFromPython(const std::string& preset, const py::dict& overrides) {
  return ekfParams(preset, overrides);
}

namespace {

// ------------------------------------------------------------------------------------- training data
py::dict datasetArrays(const BiasDataset& d) {
  std::vector<const TdoaFeature*> fs;
  fs.reserve(d.samples.size());
  const auto n = static_cast<Eigen::Index>(d.samples.size());
  RowMat x(n, 2);
  auto flight = newIntArray(n);
  auto mf = flight.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < n; ++i) {
    fs.push_back(&d.samples[i].feature);
    x.row(i) << d.samples[i].t_s, d.samples[i].error_m;
    mf(i) = d.samples[i].flight;
  }
  py::dict out = featuresToDict(fs);
  out["t"] = toNumpy(x.col(0), true), out["error"] = toNumpy(x.col(1), true), out["flight"] = flight;
  return out;
}

BiasDataset buildDataset(const std::vector<const Flight*>& flights, const AnchorSurvey& survey, const py::kwargs& kw) {
  const BiasDatasetParams params = datasetParams(kw);
  std::vector<Flight> copies;
  copies.reserve(flights.size());
  for (const Flight* f : flights) copies.push_back(*f);
  py::gil_scoped_release release;
  return buildBiasDataset(copies, survey, params);
}

void bindBiasDataset(py::module_& m) {
  py::class_<BiasDataset>(m, "BiasDataset",
                          "GP training data from flights with ground truth: features from the interpolated\n"
                          "ground-truth pose and the TDoA error ε (paper eq. 6), after explicit exclusion rules.")
      .def("__len__", [](const BiasDataset& d) { return d.samples.size(); })
      .def("arrays", &datasetArrays,
           "{t, flight (index), error [m] (ε, the GP target), id_a, id_b, yaw_a, yaw_b, b_p_a, b_p_b, w_p_b}")
      .def_property_readonly("flights",
                             [](const BiasDataset& d) {
                               py::list l;
                               for (const auto& r : d.flights) l.append(flightReportDict(r));
                               return l;
                             },
                             "per-flight exclusion counts")
      .def("report_text", &BiasDataset::reportText, "Text summary: samples per flight and pair, and what was excluded.");

  m.def("build_bias_dataset", &buildDataset, py::arg("flights"), py::arg("survey"),
        "Training data from flights with a ground-truth pose (position-only without IMU: world-frame features).\n"
        "Keyword arguments override\n"
        "BiasDatasetParams (min_z_m, glitch_margin_s, max_abs_error_m, neighbour_pairs_only, b_t_tag, "
        "inputs='estimate'|'truth': GP inputs from the uncorrected filter (the default, as the CLI's train) or from the "
        "ground truth).");

  m.def("bias_preset_names", &BiasPreset::names, "Bias-model presets: z1, z2, tdoa (paper) and extras.");
  m.def(
      "feature_matrix",
      [](const std::string& feature_map, const py::dict& features) {
        const FeatureMap map = featureMapFromString(feature_map);
        return toNumpy(featureMatrix(map, featuresFromDict(features, map)));
      },
      py::arg("feature_map"), py::arg("features"),
      "GP input rows (N, D) of a feature dict for a feature map ('yaw_angles' → [yaw_a, yaw_b], 'body_positions' →\n"
      "[b_p_a, b_p_b], 'world_position' → [w_p_b], 'body_positions_anchors' → [b_p_a, b_p_b, w_p_anchor_a,\n"
      "w_p_anchor_b], 'body_positions_world' → [b_p_a, b_p_b, w_p_b]).");
}

// ---------------------------------------------------------------------------------------- bias model
py::list modelEntries(const BiasModel& b) {
  py::list l;
  for (const auto& e : b.entries()) {
    py::dict d;
    d["id_a"] = e.id_a, d["id_b"] = e.id_b, d["gp"] = e.gp;
    l.append(d);
  }
  return l;
}

py::dict predictBias(const BiasModel& b, const py::dict& features) {
  const std::vector<TdoaFeature> fs = featuresFromDict(features, b.features());
  Eigen::VectorXd mean(static_cast<Eigen::Index>(fs.size())), var(mean.size());
  {
    py::gil_scoped_release release;
    for (std::size_t i = 0; i < fs.size(); ++i) {
      const BiasPrediction p = b.predict(fs[i]);
      mean(i) = p.mean_m, var(i) = p.variance_m2;
    }
  }
  py::dict d;
  d["mean"] = toNumpy(mean, true), d["var"] = toNumpy(var, true);
  return d;
}

void bindBiasModel(py::module_& m) {
  py::class_<BiasModel>(m, "BiasModel",
                        "A trained TDoA bias model (SVGP(s) + feature mapping); the filter's bias predictor.")
      .def(py::init([](const gp::Svgp& svgp, const std::string& feature_map, const std::string& preset) {
             return BiasModel(preset, featureMapFromString(feature_map), {BiasModel::Entry{-1, -1, svgp}});
           }),
           py::arg("svgp"), py::arg("feature_map"), py::arg("preset") = "custom",
           "Wraps one global SVGP trained in Python (inputs given by feature_map) as a bias model.")
      .def_property_readonly("preset", &BiasModel::preset, "name of the training preset the model was made with")
      .def_property_readonly("feature_map", [](const BiasModel& b) { return toString(b.features()); },
                             "the feature map of its inputs (feature_matrix names)")
      .def_property_readonly("entries", &modelEntries, "[{id_a, id_b (-1: all pairs), gp: Svgp}]")
      .def("predict", &predictBias, py::arg("features"),
           "Predicted bias of every row of a feature dict: {mean [m], var [m²] (latent)}; 0, 0 for uncovered pairs.")
      .def_property("training_bias_level_m", &BiasModel::trainingBiasLevel, &BiasModel::setTrainingBiasLevel,
                    "TDoA bias level of the training flights [m] (filter.md F24b; 0 unknown: the mean is not scaled)")
      .def_property("training_mean_level_m", &BiasModel::trainingMeanLevel, &BiasModel::setTrainingMeanLevel,
                    "Level of the model's own mean on its training flights [m] (filter.md F24c; 0 unknown)")
      .def("level_excess_variance_m2", &BiasModel::levelExcessVarianceM2, py::arg("flight_level_m"),
           py::arg("flight_mean_level_m") = std::numeric_limits<double>::quiet_NaN(),
           "Variance [m²] a flight at TDoA bias level flight_level_m (and level flight_mean_level_m of the model's mean\n"
           "on it; NaN unknown) shows beyond the training flights (docs/math/gp.md P43c); 0 when a level is unknown.")
      .def_property("metadata_json", [](const BiasModel& b) { return b.metadata_json; },
                    [](BiasModel& b, const std::string& s) { b.metadata_json = s; },
                    "free-form JSON text stored with the model (training flights, options)")
      .def("save", &BiasModel::save, py::arg("path"), "Writes the model file (the CLI's --bias-model format).")
      .def_static("load", &BiasModel::load, py::arg("path"), "Reads a model file written by save() or the CLI.")
      .def("to_json", [](const BiasModel& b) { return b.toJson().dump(); }, "The model file's JSON text.")
      .def("__repr__", [](const BiasModel& b) {
        return "<BiasModel preset=" + b.preset() + " features=" + toString(b.features()) + " models=" +
               std::to_string(b.entries().size()) + ">";
      });
}

// ------------------------------------------------------------------------------------------ training
/// The SVGP training parameters among train_bias_model's keyword arguments (same names as train_svgp).
void applyTrainKwargs(BiasTrainParams& p, const py::kwargs& kw) {
  for (const auto& [key, value] : kw) {
    const std::string n = py::str(key);
    if (n == "epochs") p.svgp.epochs = py::cast<int>(value);
    else if (n == "batch_size") p.svgp.batch_size = py::cast<int>(value);
    else if (n == "seed") p.svgp.seed = py::cast<std::uint64_t>(value);
    else if (n == "lr") p.svgp.lr = py::cast<double>(value);
    else if (n == "lr_inducing") p.svgp.lr_inducing = py::cast<double>(value);
    else if (n == "natgrad_step") p.svgp.natgrad_step = py::cast<double>(value);
    else if (n == "train_inducing") p.svgp.train_inducing = py::cast<bool>(value);
    else if (n == "num_threads") p.svgp.num_threads = py::cast<int>(value);
    else if (n == "mean_scale") p.mean_scale = py::cast<double>(value);
    else if (n == "full_variance") p.full_variance = py::cast<bool>(value);
    else if (n == "predictive_dof") p.predictive_shape.dof = py::cast<double>(value);
    else if (n == "predictive_scale") p.predictive_shape.scale = py::cast<double>(value);
    else if (n == "min_samples_per_inducing") p.min_samples_per_inducing = py::cast<int>(value);
    else
      throw std::invalid_argument("unknown training parameter '" + n +
                                  "' (known: epochs, batch_size, seed, lr, lr_inducing, natgrad_step, "
                                  "train_inducing, num_threads, mean_scale, full_variance, predictive_dof, predictive_scale, "
                                  "min_samples_per_inducing)");
  }
}

py::tuple trainModel(const BiasDataset& data, const std::string& preset, int num_inducing, double holdout_fraction,
                     double holdout_block_s, const py::object& progress, const py::kwargs& kw) {
  BiasTrainParams p;
  p.preset = preset;
  p.num_inducing = num_inducing;
  p.holdout_fraction = holdout_fraction;
  p.holdout_block_s = holdout_block_s;
  applyTrainKwargs(p, kw);
  p.validate();
  BiasTrainProgress cb;
  if (!progress.is_none()) {
    cb = [&progress](int model, int models, const gp::EpochReport& r) {
      py::gil_scoped_acquire acquire;
      py::dict d;
      d["model"] = model, d["models"] = models, d["epoch"] = r.epoch, d["epochs"] = r.epochs;
      d["elbo"] = r.elbo, d["val_rmse"] = r.val_rmse, d["elapsed_s"] = r.elapsed_s;
      progress(d);
    };
  }
  BiasTrainReport report;
  BiasModel model;
  {
    py::gil_scoped_release release;
    model = trainBiasModel(data, p, &report, cb);
  }
  return py::make_tuple(std::move(model), trainReportDict(report));
}

py::object calibration(const BiasDataset& data, const BiasModel& model) {
  BiasCalibration c;
  {
    py::gil_scoped_release release;
    c = biasCalibration(data, model);
  }
  return jsonToPython(toJson(c));
}

void bindBiasTraining(py::module_& m) {
  m.def("train_bias_model", &trainModel, py::arg("dataset"), py::arg("preset") = std::string(kDefaultTrainPreset),
        py::arg("num_inducing") = BiasTrainParams{}.num_inducing, py::arg("holdout_fraction") = 0.2,
        py::arg("holdout_block_s") = 5.0, py::arg("progress") = py::none(),
        "Trains the preset's GP(s) on the dataset (time blocks held out). Keyword arguments: SVGP training\n"
        "parameters (epochs, batch_size, seed, lr, ...). Returns (BiasModel, report {n_train, n_holdout,\n"
        "bias_rmse_before_m, bias_rmse_after_m, mean_predicted_std_m, mean_predictive_std_m, holdout_coverage_1sigma, "
        "holdout_coverage_2sigma, holdout_nlpd, train_seconds, num_models}).");

  m.def("bias_calibration", &calibration, py::arg("dataset"), py::arg("model"),
        "Calibration of the model's predicted bias on a dataset (docs/math/gp.md P43, P43b, P43c): r = ε − µ against\n"
        "σ² = var_f + σ_n² + the variance the sample's flight shows beyond the model's training flights (from the\n"
        "levels its filter run measured; none for ground-truth inputs) and the central intervals of the model's\n"
        "predictive shape (Student-t or Gaussian).\n"
        "Returns {n, n_uncovered, coverage_1sigma, coverage_2sigma, nlpd [nats], rmse_m, mean_std_m, levels,\n"
        "coverage (at levels), predictive_dof, predictive_scale}.");
}

// -------------------------------------------------------------------------------------- localization
py::dict localize(const Flight& flight, const AnchorSurvey& survey, const BiasModel* bias_model,
                  const std::string& preset, const py::dict& params, double output_period_s, bool tdoa_only,
                  double airborne_min_z_m) {
  LocalizationOptions options;
  options.params = ekfParams(preset, params);
  options.output_period_s = output_period_s;
  options.tdoa_only = tdoa_only;
  options.metrics.airborne_min_z_m = airborne_min_z_m;
  if (bias_model) applyBiasModelLevel(*bias_model, &options.params);  // (F24b)
  LocalizationRun run;
  {
    py::gil_scoped_release release;
    run = localizeFlight(flight, survey, options, bias_model ? bias_model->predictor() : BiasPredictor{});
  }
  py::dict d;
  d["trajectory"] = trajectoryToDict(run.trajectory);
  d["summary"] = summaryDict(run.summary, options.params);
  d["metrics"] = run.metrics ? py::object(metricsDict(*run.metrics)) : py::object(py::none());
  d["duration_s"] = run.duration_s, d["n_truth_glitches"] = run.n_truth_glitches;
  return d;
}

/// With out=DIR: the CLI's report files there, and (render) the figures, which the report then names.
void writeEvaluationReport(const EvaluationResult& result, const AnchorSurvey& survey, const std::string& dir,
                           const std::string& command, bool render, py::dict& d) {
  writeEvaluation(result, survey, dir, command);
  if (!render) return;
  // Same figures as the CLI's report (one implementation: uwbtdoa.plots), then the report names them.
  const py::list written = py::module_::import("uwbtdoa.plots").attr("render_report")(dir);
  std::vector<std::string> names;
  for (const auto& p : written) {
    const std::string path = py::str(p);
    names.push_back(path.substr(path.find_last_of('/') + 1));
  }
  writeEvaluation(result, survey, dir, command, names);
  d["figures"] = names;
}

py::dict evaluate(const py::handle& train, const py::handle& test, const AnchorSurvey& survey,
                  const std::vector<std::string>& kernels, const std::vector<int>& inducing, int repeats, int epochs,
                  int threads, const py::object& out, const std::string& command, bool render,
                  const py::object& progress) {
  EvaluationParams params;
  params.kernels = kernels;
  params.inducing = inducing;
  params.repeats = repeats;
  if (epochs > 0) params.train.svgp.epochs = epochs;
  params.threads = threads;
  params.validate();
  const std::vector<NamedFlight> tr = namedFlights(train, "train"), te = namedFlights(test, "test");
  EvaluationProgress cb;
  if (!progress.is_none()) {
    cb = [&progress](const std::string& line) {
      py::gil_scoped_acquire acquire;
      progress(line);
    };
  }
  EvaluationResult result;
  {
    py::gil_scoped_release release;
    result = runEvaluation(tr, te, survey, params, cb);
  }
  py::dict d;
  d["rows"] = jsonToPython(toJson(result.rows));
  d["runs"] = jsonToPython(runsToJson(result.runs));  // with the bias calibration per run (P43)
  d["best_kernel"] = result.best_kernel, d["best_inducing"] = result.best_inducing;
  d["n_train_samples"] = result.n_train_samples, d["seconds"] = result.seconds;
  d["dataset_report"] = result.dataset_report;
  d["markdown"] = toMarkdown(result.rows);
  if (!out.is_none()) writeEvaluationReport(result, survey, py::str(out), command, render, d);
  return d;
}

py::dict trajectoryMetrics(const py::dict& trajectory, const py::object& truth, double airborne_min_z_m,
                           double max_interp_gap_s) {
  TrajectoryMetricsParams p;
  p.airborne_min_z_m = airborne_min_z_m;
  p.max_interp_gap_s = max_interp_gap_s;
  p.validate();
  std::vector<PoseSample> gt;
  if (py::isinstance<Flight>(truth)) {
    gt = PoseTrack(py::cast<const Flight&>(truth)).samples();
  } else {
    const Trajectory t = trajectoryFromDict(py::cast<py::dict>(truth));
    for (const auto& s : t) gt.push_back({s.t_s, s.w_p_b, s.w_q_b});
  }
  return metricsDict(computeTrajectoryMetrics(trajectoryFromDict(trajectory), gt, p));
}

void bindLocalization(py::module_& m) {
  m.def("localize_flight", &localize, py::arg("flight"), py::arg("survey"), py::arg("bias_model") = nullptr,
        py::arg("preset") = "defaults", py::arg("params") = py::dict(), py::arg("output_period_s") = 0.01,
        py::arg("tdoa_only") = false, py::arg("airborne_min_z_m") = kAirborneMinZ_m,
        "Runs the localization filter on a flight, with the GP correction when bias_model is given (paper III-B:\n"
        "z − mean, variance added). preset: 'defaults' | 'crazyflie' | 'tdoa-only'; params: EkfParams overrides\n"
        "(field names of uwb/filter/EkfParams.h, enums as strings). Returns {trajectory {t, p, q, sigma_p, v, acc_bias,\n"
        "gyro_bias (NaN without IMU)},\n"
        "summary {...}, metrics (None without ground truth) {whole, airborne: {n, rmse_m, rmse_axis_m, mean_m,\n"
        "p50_m, p90_m, p99_m, max_m}, samples {t, p_true, p_est, error, error_norm, airborne}}, duration_s}.");
  m.def("run_evaluation", &evaluate, py::arg("train"), py::arg("test"), py::arg("survey"),
        py::arg("kernels") = std::vector<std::string>{"z1", "z2", "tdoa"},
        py::arg("inducing") = std::vector<int>{10, 30, 50, 100, 170}, py::arg("repeats") = 3, py::arg("epochs") = 0,
        py::arg("threads") = 2, py::arg("out") = py::none(), py::arg("command") = "", py::arg("render") = true,
        py::arg("progress") = py::none(),
        "The paper's evaluation (uwbtdoa evaluate): train every (kernel, M, repeat), localize every test flight\n"
        "without and with correction. train/test: {name: Flight} or a list of Flights (named after their file).\n"
        "Returns {rows (results.json objects), runs (per configuration, repeat and test flight, with change_pct and the\n"
        "bias calibration coverage_1sigma, coverage_2sigma, nlpd), best_kernel, best_inducing, n_train_samples, seconds,\n"
        "dataset_report, markdown}. With out=DIR, writes the CLI's report files there and renders the figures.");
  m.def("filter_param_names",
        [] {
          std::vector<std::string> names;
          for (const auto& [n, _] : ekfSetters()) names.push_back(n);
          return names;
        },
        "Names accepted by localize_flight(params=...).");
  m.def("compute_trajectory_metrics", &trajectoryMetrics, py::arg("trajectory"), py::arg("truth"),
        py::arg("airborne_min_z_m") = 0.3, py::arg("max_interp_gap_s") = 0.1,
        "Position error of an estimated trajectory {t, p, ...} against ground truth (a Flight: its glitch-free pose\n"
        "track; or a dict {t, p[, q]}): {whole, airborne, samples, n_truth_not_covered} as in localize_flight.");
}

}  // namespace

void bindEval(py::module_& m) {
  bindBiasDataset(m);
  bindBiasModel(m);
  bindBiasTraining(m);
  bindLocalization(m);
}

}  // namespace uwb::python
