/** @file BiasModel.cpp
 *  @brief Bias-model presets, training from a BiasDataset, prediction and model files (docs/math/gp.md P25–P27).
 */
#include "uwb/eval/BiasModel.h"

#include "uwb/eval/BiasCalibration.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "uwb/core/Error.h"
#include "uwb/filter/BiasLevel.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/FileAccess.h"
#include "uwb/io/JsonFile.h"
#include "uwb/gp/kernels/Presets.h"

namespace uwb {

std::string toString(FeatureMap map) {
  switch (map) {
    case FeatureMap::kYawAngles: return "yaw_angles";
    case FeatureMap::kBodyPositions: return "body_positions";
    case FeatureMap::kWorldPosition: return "world_position";
    case FeatureMap::kBodyPositionsAnchors: return "body_positions_anchors";
    case FeatureMap::kBodyPositionsWorld: return "body_positions_world";
  }
  return "unknown";
}

FeatureMap featureMapFromString(const std::string& name) {
  if (name == "yaw_angles") return FeatureMap::kYawAngles;
  if (name == "body_positions") return FeatureMap::kBodyPositions;
  if (name == "world_position") return FeatureMap::kWorldPosition;
  if (name == "body_positions_anchors") return FeatureMap::kBodyPositionsAnchors;
  if (name == "body_positions_world") return FeatureMap::kBodyPositionsWorld;
  throw std::invalid_argument("unknown feature map '" + name +
                              "' (yaw_angles, body_positions, world_position, body_positions_anchors, "
                              "body_positions_world)");
}

int featureDim(FeatureMap map) {
  switch (map) {
    case FeatureMap::kYawAngles: return 2;
    case FeatureMap::kBodyPositions: return 6;
    case FeatureMap::kWorldPosition: return 3;
    case FeatureMap::kBodyPositionsAnchors: return 12;
    case FeatureMap::kBodyPositionsWorld: return 9;
  }
  return 0;
}

void featureRow(FeatureMap map, const TdoaFeature& f, double* row) {
  switch (map) {
    case FeatureMap::kYawAngles:  // paper eq. (7)/(8): [α_A, α_B]
      row[0] = f.yaw_a_rad;
      row[1] = f.yaw_b_rad;
      return;
    case FeatureMap::kBodyPositions:  // paper eq. (9): [x_kA, x_kB]
      for (int i = 0; i < 3; ++i) {
        row[i] = f.b_p_a[i];
        row[3 + i] = f.b_p_b[i];
      }
      return;
    case FeatureMap::kWorldPosition:
      for (int i = 0; i < 3; ++i) row[i] = f.w_p_b[i];
      return;
    case FeatureMap::kBodyPositionsAnchors:  // eq. (9) inputs plus the anchors' world positions (P29)
      for (int i = 0; i < 3; ++i) {
        row[i] = f.b_p_a[i];
        row[3 + i] = f.b_p_b[i];
        row[6 + i] = f.w_p_anchor_a[i];
        row[9 + i] = f.w_p_anchor_b[i];
      }
      return;
    case FeatureMap::kBodyPositionsWorld:  // eq. (9) inputs plus the body position (P26b)
      for (int i = 0; i < 3; ++i) {
        row[i] = f.b_p_a[i];
        row[3 + i] = f.b_p_b[i];
        row[6 + i] = f.w_p_b[i];
      }
      return;
  }
}

MatX featureMatrix(FeatureMap map, const std::vector<TdoaFeature>& features) {
  // Filled in place (column-major, as the GP takes it): no second N×D copy.
  const int D = featureDim(map);
  MatX X(static_cast<Eigen::Index>(features.size()), D);
  double row[kMaxFeatureDim];
  for (std::size_t i = 0; i < features.size(); ++i) {
    featureRow(map, features[i], row);
    for (int d = 0; d < D; ++d) X(static_cast<Eigen::Index>(i), d) = row[d];
  }
  return X;
}

std::vector<std::string> featureColumnNames(FeatureMap map) {
  const auto xyz = [](const std::string& prefix) {
    return std::vector<std::string>{prefix + "_x_m", prefix + "_y_m", prefix + "_z_m"};
  };
  std::vector<std::string> names;
  const auto add = [&](const std::vector<std::string>& more) { names.insert(names.end(), more.begin(), more.end()); };
  switch (map) {
    case FeatureMap::kYawAngles: return {"yaw_a_rad", "yaw_b_rad"};
    case FeatureMap::kBodyPositions: add(xyz("b_p_a")); add(xyz("b_p_b")); break;
    case FeatureMap::kWorldPosition: add(xyz("w_p_b")); break;
    case FeatureMap::kBodyPositionsAnchors:
      add(xyz("b_p_a")); add(xyz("b_p_b")); add(xyz("w_p_anchor_a")); add(xyz("w_p_anchor_b"));
      break;
    case FeatureMap::kBodyPositionsWorld: add(xyz("b_p_a")); add(xyz("b_p_b")); add(xyz("w_p_b")); break;
  }
  return names;
}

// ---------------------------------------------------------------------------------------------------------------

gp::Kernel BiasPreset::kernel() const {
  // the compositions and their starting parameters: gp/kernels/Presets.h
  if (name == "z1" || name == "z2" || name == "tdoa") return gp::Kernel::preset(name);
  if (name == "pair-tdoa" || name == "tdoa-pm") return gp::Kernel::preset("tdoa");
  if (name == "anchor-tdoa" || name == "anchor-tdoa-pm") return gp::anchorTdoaKernel();  // docs/math/gp.md (P29)
  if (name == "pair-pos") return gp::positionMapKernel();
  if (name == "pair-tdoa-pos") return gp::tdoaPositionKernel();  // docs/math/gp.md (P26b)
  throw std::invalid_argument("unknown bias-model preset '" + name + "'");
}

BiasPreset BiasPreset::byName(const std::string& name) {
  BiasPreset p;
  p.name = name;
  if (name == "z1" || name == "z2") {
    p.features = FeatureMap::kYawAngles;
  } else if (name == "tdoa") {
    p.features = FeatureMap::kBodyPositions;
  } else if (name == "pair-tdoa") {
    p.features = FeatureMap::kBodyPositions;
    p.per_pair = true;
  } else if (name == "tdoa-pm") {
    p.features = FeatureMap::kBodyPositions;
    p.pair_mean = true;
  } else if (name == "anchor-tdoa" || name == "anchor-tdoa-pm") {
    p.features = FeatureMap::kBodyPositionsAnchors;
    p.pair_mean = name == "anchor-tdoa-pm";
  } else if (name == "pair-pos") {
    p.features = FeatureMap::kWorldPosition;
    p.per_pair = true;
    p.normalization = gp::InputNormalization::kStandardize;
  } else if (name == "pair-tdoa-pos") {
    p.features = FeatureMap::kBodyPositionsWorld;
    p.per_pair = true;
  } else {
    throw std::invalid_argument("unknown bias-model kernel/preset '" + name + "' (expected z1, z2, tdoa, pair-tdoa, pair-pos, tdoa-pm, "
                                "anchor-tdoa, anchor-tdoa-pm, pair-tdoa-pos)");
  }
  return p;
}

std::vector<std::string> BiasPreset::names() {
  return {"z1", "z2", "tdoa", "pair-tdoa", "pair-pos", "tdoa-pm", "anchor-tdoa", "anchor-tdoa-pm", "pair-tdoa-pos"};
}

void BiasTrainParams::validate() const {
  BiasPreset::byName(preset);
  if (num_inducing < 1) throw std::invalid_argument("number of inducing points must be ≥ 1");
  if (!(holdout_fraction >= 0) || holdout_fraction >= 1) throw std::invalid_argument("holdout_fraction must be in [0, 1)");
  if (!(holdout_block_s > 0)) throw std::invalid_argument("holdout_block_s must be > 0");
  if (min_samples_per_inducing < 1) throw std::invalid_argument("min_samples_per_inducing must be ≥ 1");
  if (!(extra_sigma_m >= 0) || !std::isfinite(extra_sigma_m)) throw std::invalid_argument("extra_sigma_m must be ≥ 0");
  if (!(mean_scale >= 0) || mean_scale > 1) throw std::invalid_argument("mean_scale must be in [0, 1]");
  predictive_shape.validate();
  svgp.validate();
}

// ---------------------------------------------------------------------------------------------------------------

BiasModel::BiasModel(std::string preset, FeatureMap features, std::vector<Entry> entries,
                     std::vector<PairMean> pair_means)
    : preset_(std::move(preset)), features_(features), entries_(std::move(entries)), pair_means_(std::move(pair_means)) {
  for (const auto& e : entries_) {
    if (e.gp.inputDim() != featureDim(features_))
      throw std::invalid_argument("bias model: GP input dimension " + std::to_string(e.gp.inputDim()) +
                                  " does not match the feature map " + toString(features_) + " (" +
                                  std::to_string(featureDim(features_)) + ")");
  }
  buildPredictors();
}

void BiasModel::buildPredictors() {
  auto preds = std::make_shared<std::vector<gp::SvgpPredictor>>();
  preds->reserve(entries_.size());
  for (const auto& e : entries_) preds->emplace_back(e.gp);
  predictors_ = preds;
}

void BiasModel::setMeanScale(double w) {
  if (!(w >= 0.0) || w > 1.0) throw std::invalid_argument("bias model: mean_scale must be in [0, 1]");
  mean_scale_ = w;
}

void PredictiveShape::validate() const {
  if (!std::isfinite(dof) || !(dof == 0.0 || dof > 2.0))
    throw std::invalid_argument("predictive_dof must be 0 (Gaussian) or > 2 (a finite variance)");
  if (!std::isfinite(scale) || !(scale > 0.0) || scale > 10.0)
    throw std::invalid_argument("predictive_scale must be in (0, 10]");
}

namespace {
/// A bias level of the model file (F24b, F24c): finite and in [0, 10] m.
double checkedLevel(double level_m, const char* field) {
  if (!std::isfinite(level_m) || !(level_m >= 0.0) || level_m > 10.0)
    throw std::invalid_argument(std::string(field) + " must be in [0, 10] m");
  return level_m;
}
}  // namespace

void BiasModel::setTrainingBiasLevel(double level_m) {
  training_bias_level_m_ = checkedLevel(level_m, "training_bias_level_m");
}

void BiasModel::setTrainingMeanLevel(double level_m) {
  training_mean_level_m_ = checkedLevel(level_m, "training_mean_level_m");
}

void BiasModel::setPredictiveShape(const PredictiveShape& shape) {
  shape.validate();
  predictive_shape_ = shape;
}

void BiasModel::setExtraVariance(double variance_m2) {
  if (!(variance_m2 >= 0) || !std::isfinite(variance_m2))
    throw std::invalid_argument("bias model: extra variance must be finite and ≥ 0");
  extra_variance_m2_ = variance_m2;
}

double BiasModel::pairMean(int id_a, int id_b) const {
  for (const auto& p : pair_means_) {
    if (p.id_a == id_a && p.id_b == id_b) return p.mean_m;
  }
  return 0.0;
}

namespace {
BiasPrediction predictWith(const std::vector<BiasModel::Entry>& entries, const std::vector<gp::SvgpPredictor>& preds,
                           FeatureMap map, const TdoaFeature& f) {
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto& e = entries[i];
    if (e.id_a >= 0 && (e.id_a != f.id_a || e.id_b != f.id_b)) continue;
    double row[kMaxFeatureDim];
    featureRow(map, f, row);
    double mean = 0, var = 0;
    preds[i].predictOne(Eigen::Map<const RowVecX>(row, featureDim(map)), mean, var);
    return {mean, std::max(var, 0.0)};
  }
  return {0.0, 0.0};
}
}  // namespace

void BiasModel::setFullVariance(bool on, double target_mean_square_m2) {
  if (on && !(target_mean_square_m2 > 0.0 && std::isfinite(target_mean_square_m2)))
    throw std::invalid_argument("bias model: the full variance needs the training targets' mean square > 0");
  full_variance_ = on;
  target_mean_square_m2_ = on ? target_mean_square_m2 : 0.0;
}

BiasPrediction BiasModel::predict(const TdoaFeature& f) const {
  if (full_variance_) {
    // docs/math/gp.md (P45): R = (var_f + σ_n²)/E[ε²] · σ_tdoa² + σ_x²
    const BiasPredictive q = predictive(f);
    BiasPrediction p;
    p.variance_m2 = extra_variance_m2_;
    if (q.covered) {
      p.mean_m = q.mean_m;
      p.noise_scale = q.varianceM2() / target_mean_square_m2_;
    } else {
      p.mean_m = mean_scale_ * pairMean(f.id_a, f.id_b);
    }
    return p;
  }
  BiasPrediction p = predictWith(entries_, *predictors_, features_, f);
  p.mean_m += pairMean(f.id_a, f.id_b);  // docs/math/gp.md (P28): m_AB + GP mean
  p.variance_m2 += extra_variance_m2_;    // (P31)
  p.mean_m *= mean_scale_;                 // (P44)
  return p;
}

BiasPredictive BiasModel::predictive(const TdoaFeature& f) const {
  BiasPredictive p;
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    const auto& e = entries_[i];
    if (e.id_a >= 0 && (e.id_a != f.id_a || e.id_b != f.id_b)) continue;
    double row[kMaxFeatureDim];
    featureRow(features_, f, row);
    (*predictors_)[i].predictOne(Eigen::Map<const RowVecX>(row, featureDim(features_)), p.mean_m, p.latent_variance_m2);
    p.latent_variance_m2 = std::max(p.latent_variance_m2, 0.0);
    p.noise_variance_m2 = e.gp.noiseVariance();  // (P43)
    p.mean_m += pairMean(f.id_a, f.id_b);       // (P28)
    p.mean_m *= mean_scale_;                     // (P44)
    p.covered = true;
    return p;
  }
  return p;
}

BiasPredictive BiasModel::predictive(const TdoaFeature& f, double flight_level_m, double flight_mean_level_m) const {
  BiasPredictive p = predictive(f);
  if (p.covered) p.level_variance_m2 = levelExcessVarianceM2(flight_level_m, flight_mean_level_m);
  return p;
}

double BiasModel::levelExcessVarianceM2(double flight_level_m, double flight_mean_level_m) const {
  return levelExcessVariance(flight_level_m, flight_mean_level_m, training_bias_level_m_, training_mean_level_m_);
}

BiasPredictor BiasModel::predictor() const {
  auto self = std::make_shared<const BiasModel>(*this);
  return [self](const TdoaFeature& f) { return self->predict(f); };
}

nlohmann::json BiasModel::toJson() const {
  nlohmann::json models = nlohmann::json::array();
  for (const auto& e : entries_) models.push_back({{"id_a", e.id_a}, {"id_b", e.id_b}, {"svgp", e.gp.toJson()}});
  nlohmann::json means = nlohmann::json::array();
  for (const auto& p : pair_means_) means.push_back({{"id_a", p.id_a}, {"id_b", p.id_b}, {"mean_m", p.mean_m}});
  nlohmann::json meta = nlohmann::json::parse(metadata_json, nullptr, false);
  if (meta.is_discarded()) meta = nlohmann::json::object();
  return {{"format", "uwbtdoa-bias-model"},
          {"version", 1},
          {"preset", preset_},
          {"features", toString(features_)},
          {"feature_columns", featureDim(features_)},
          {"per_pair", !entries_.empty() && entries_[0].id_a >= 0},
          {"models", models},
          {"pair_means", means},
          {"extra_variance_m2", extra_variance_m2_},
          {"mean_scale", mean_scale_},
          {"training_bias_level_m", training_bias_level_m_},
          {"training_mean_level_m", training_mean_level_m_},
          {"predictive_dof", predictive_shape_.dof},
          {"predictive_scale", predictive_shape_.scale},
          {"full_variance", full_variance_},
          {"target_mean_square_m2", target_mean_square_m2_},
          {"training", meta}};
}

namespace {

/// Plausible magnitude of a TDoA bias [m]: UWB NLOS and antenna effects reach a metre or two; a mean of 10⁶ m in a
/// model file is a corrupt or foreign file, not a bias (issue: such a model moved the estimate by 1.9 km).
constexpr double kMaxPlausibleBias_m = 10.0;
/// Largest plausible extra TDoA variance (P31) [m²] and SVGP jitter.
constexpr double kMaxExtraVariance_m2 = 100.0;
constexpr double kMaxJitter = 1.0;

/// Anchor id of a model entry: -1 (global model) or a valid anchor id; checked before conversion.
int modelAnchorId(const nlohmann::json& m, const std::string& key, const char* name) {
  return jsonInt(jsonMember(m, key, name), key + "." + name, -1, kMaxAnchorId);
}

/// Largest magnitude of any number of a model's SVGP block (kernel parameters, inducing points, variational mean and
/// factor, input transform). Trained models stay orders of magnitude below; a value such as 1e300 passes the finite
/// check but overflows the predictions to inf and NaN.
constexpr double kMaxModelMagnitude = 1e6;

/// Every number under `v` is finite and of magnitude ≤ kMaxModelMagnitude; std::invalid_argument naming the first
/// that is not, by its path (e.g. `models[0].svgp.variational.m[3]`). The nesting is bounded by the reader's depth cap.
void checkMagnitudes(const nlohmann::json& v, const std::string& key) {
  if (v.is_number()) {
    const double x = v.get<double>();
    if (!std::isfinite(x) || std::abs(x) > kMaxModelMagnitude)
      throw std::invalid_argument(fmt::format("{} = {:g} is not a plausible model value (|x| ≤ {:g})", key, x,
                                              kMaxModelMagnitude));
  } else if (v.is_array()) {
    for (std::size_t i = 0; i < v.size(); ++i) checkMagnitudes(v[i], fmt::format("{}[{}]", key, i));
  } else if (v.is_object()) {
    for (const auto& [name, child] : v.items()) checkMagnitudes(child, key + "." + name);
  }
}

/// Range checks of the SVGP block that the GP reader leaves to the caller (values it accepts but that make the
/// model useless or its factorisation fail without naming the file).
void checkSvgpValues(const nlohmann::json& svgp, const std::string& key) {
  const double jitter = jsonDouble(jsonMember(svgp, key, "jitter"), key + ".jitter");
  if (jitter < 0 || jitter > kMaxJitter)
    throw std::invalid_argument(key + ".jitter must be in [0, " + std::to_string(kMaxJitter) + "], got " +
                                std::to_string(jitter));
  const nlohmann::json& mean = jsonMember(svgp, key, "mean");
  const double c = jsonDouble(jsonMember(mean, key + ".mean", "constant"), key + ".mean.constant");
  if (std::abs(c) > kMaxPlausibleBias_m)
    throw std::invalid_argument(key + ".mean.constant = " + std::to_string(c) + " m is not a plausible TDoA bias (|m| ≤ " +
                                std::to_string(kMaxPlausibleBias_m) + " m)");
  const nlohmann::json& likelihood = jsonMember(svgp, key, "likelihood");
  const double noise = jsonDouble(jsonMember(likelihood, key + ".likelihood", "noise"), key + ".likelihood.noise");
  if (!(noise > 0) || noise > kMaxExtraVariance_m2)
    throw std::invalid_argument(key + ".likelihood.noise must be in (0, " + std::to_string(kMaxExtraVariance_m2) +
                                "] m², got " + std::to_string(noise));
}

}  // namespace

BiasModel BiasModel::fromJson(const nlohmann::json& j) {
  try {
    if (!j.is_object()) throw std::invalid_argument("not a JSON object");
    if (j.value("format", std::string()) != "uwbtdoa-bias-model")
      throw std::invalid_argument("\"format\" is not \"uwbtdoa-bias-model\" (is this a bias model file?)");
    const int version = jsonInt(jsonMember(j, "", "version"), "version", 0, 1000000);
    if (version != 1) throw std::invalid_argument("unsupported bias model version " + std::to_string(version) + " (expected 1)");
    const FeatureMap map = featureMapFromString(jsonString(jsonMember(j, "", "features"), "features"));
    if (j.contains("feature_columns") && jsonInt(j.at("feature_columns"), "feature_columns", 0, 1000) != featureDim(map))
      throw std::invalid_argument("feature_columns does not match the feature map");
    for (const char* key : {"extra_variance_m2", "mean_scale", "training_bias_level_m", "training_mean_level_m",
                            "predictive_dof", "predictive_scale", "target_mean_square_m2"}) {
      if (j.contains(key)) checkMagnitudes(j.at(key), key);
    }
    std::vector<Entry> entries;
    const nlohmann::json& models = jsonMember(j, "", "models");
    if (!models.is_array()) throw std::invalid_argument("'models' must be an array");
    for (std::size_t i = 0; i < models.size(); ++i) {
      const std::string key = "models[" + std::to_string(i) + "]";
      const nlohmann::json& m = models[i];
      const int id_a = modelAnchorId(m, key, "id_a"), id_b = modelAnchorId(m, key, "id_b");
      if ((id_a < 0) != (id_b < 0))
        throw std::invalid_argument(key + ": id_a and id_b are both -1 (global model) or both anchor ids");
      checkSvgpValues(jsonMember(m, key, "svgp"), key + ".svgp");
      checkMagnitudes(m.at("svgp"), key + ".svgp");
      entries.push_back({id_a, id_b, gp::Svgp::fromJson(m.at("svgp"))});
    }
    if (entries.empty()) throw std::invalid_argument("no models in the file");
    std::vector<PairMean> means;  // optional (P28); absent in files of the paper presets
    if (j.contains("pair_means")) {
      const nlohmann::json& pm = j.at("pair_means");
      if (!pm.is_array()) throw std::invalid_argument("'pair_means' must be an array");
      for (std::size_t i = 0; i < pm.size(); ++i) {
        const std::string key = "pair_means[" + std::to_string(i) + "]";
        const int id_a = modelAnchorId(pm[i], key, "id_a"), id_b = modelAnchorId(pm[i], key, "id_b");
        const double mean_m = jsonDouble(jsonMember(pm[i], key, "mean_m"), key + ".mean_m");
        if (std::abs(mean_m) > kMaxPlausibleBias_m)
          throw std::invalid_argument(key + ".mean_m = " + std::to_string(mean_m) +
                                      " m is not a plausible TDoA bias (|mean| ≤ " + std::to_string(kMaxPlausibleBias_m) +
                                      " m); is this the right model file?");
        means.push_back({id_a, id_b, mean_m});
      }
    }
    BiasModel model(jsonString(jsonMember(j, "", "preset"), "preset"), map, std::move(entries), std::move(means));
    if (j.contains("training")) model.metadata_json = j.at("training").dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    if (j.contains("extra_variance_m2")) {
      const double v = jsonDouble(j.at("extra_variance_m2"), "extra_variance_m2");
      if (v > kMaxExtraVariance_m2)
        throw std::invalid_argument("extra_variance_m2 = " + std::to_string(v) + " m² is not plausible (≤ " +
                                    std::to_string(kMaxExtraVariance_m2) + ")");
      model.setExtraVariance(v);
    }
    if (j.contains("mean_scale")) model.setMeanScale(jsonDouble(j.at("mean_scale"), "mean_scale"));
    if (j.contains("training_bias_level_m"))  // (F24b) an older file: unknown, no scaling
      model.setTrainingBiasLevel(jsonDouble(j.at("training_bias_level_m"), "training_bias_level_m"));
    if (j.contains("training_mean_level_m"))  // (F24c) an older file: unknown, µ's level not compared
      model.setTrainingMeanLevel(jsonDouble(j.at("training_mean_level_m"), "training_mean_level_m"));
    PredictiveShape shape;  // (P43b) a file without the fields gets the defaults
    if (j.contains("predictive_dof")) shape.dof = jsonDouble(j.at("predictive_dof"), "predictive_dof");
    if (j.contains("predictive_scale")) shape.scale = jsonDouble(j.at("predictive_scale"), "predictive_scale");
    model.setPredictiveShape(shape);
    if (j.contains("full_variance") && jsonBool(j.at("full_variance"), "full_variance"))
      model.setFullVariance(true, jsonDouble(jsonMember(j, "", "target_mean_square_m2"), "target_mean_square_m2"));
    return model;
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(std::string("bias model: ") + e.what());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("bias model: ") + e.what());
  }
}

void BiasModel::save(const std::string& path) const {
  writeFileAtomically(path, toJson().dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n", "bias model");
}

BiasModel BiasModel::load(const std::string& path) {
  const nlohmann::json j = readJsonFile(path, "bias model");
  try {
    return fromJson(j);
  } catch (const std::exception& e) {  // also the GP's own errors (e.g. a factorisation that fails)
    throw InputError(SourceLocation{path, 0, 0, ""}, e.what());
  }
}

// ---------------------------------------------------------------------------------------------------------------

std::vector<bool> holdoutMask(const std::vector<BiasSample>& samples, double fraction, double block_s) {
  std::vector<bool> mask(samples.size(), false);
  if (fraction <= 0) return mask;
  const long k = std::max(2L, std::lround(1.0 / fraction));
  std::map<int, double> t0;
  for (const auto& s : samples) {
    auto it = t0.find(s.flight);
    if (it == t0.end() || s.t_s < it->second) t0[s.flight] = s.t_s;
  }
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const long block = static_cast<long>(std::floor((samples[i].t_s - t0[samples[i].flight]) / block_s));
    mask[i] = (block % k) == k - 1;
  }
  return mask;
}

std::vector<BiasModel::PairMean> pairMeans(const std::vector<BiasSample>& samples, const std::vector<bool>& use,
                                           double n0) {
  if (!(n0 >= 0)) throw std::invalid_argument("pairMeans: n0 must be ≥ 0");
  std::map<std::pair<int, int>, std::pair<double, double>> acc;  // sum ε, n
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!use.empty() && !use[i]) continue;
    auto& a = acc[{samples[i].feature.id_a, samples[i].feature.id_b}];
    a.first += samples[i].error_m;
    a.second += 1.0;
  }
  std::vector<BiasModel::PairMean> out;
  for (const auto& [key, a] : acc) {
    if (a.second + n0 > 0) out.push_back({key.first, key.second, a.first / (a.second + n0)});  // (P28)
  }
  return out;
}

namespace {

using SampleGroups = std::map<std::pair<int, int>, std::vector<std::size_t>>;

/// Sample indices per model: one group per pair (per-pair presets) or one global group.
SampleGroups groupSamples(const BiasDataset& data, const BiasPreset& preset) {
  SampleGroups groups;
  for (std::size_t i = 0; i < data.samples.size(); ++i) {
    const auto& f = data.samples[i].feature;
    groups[preset.per_pair ? std::make_pair(f.id_a, f.id_b) : std::make_pair(-1, -1)].push_back(i);
  }
  return groups;
}

std::size_t countTraining(const std::vector<std::size_t>& idx, const std::vector<bool>& hold) {
  std::size_t n = 0;
  for (std::size_t i : idx) n += hold[i] ? 0 : 1;
  return n;
}

/// Throws unless the groups hold at least `need` training samples together.
void requireTrainingSamples(const SampleGroups& groups, const std::vector<bool>& hold, std::size_t need,
                            const BiasTrainParams& params) {
  std::size_t n_train_total = 0;
  for (const auto& [key, idx] : groups) n_train_total += countTraining(idx, hold);
  if (n_train_total < need)
    throw std::invalid_argument("too few usable training samples: " + std::to_string(n_train_total) + " after exclusions and hold-out, need ≥ " +
                                std::to_string(need) + " for " + std::to_string(params.num_inducing) +
                                " inducing points (reduce --inducing or add flights)");
}

double pairMeanOf(const std::vector<BiasModel::PairMean>& means, const TdoaFeature& f) {
  for (const auto& m : means) {
    if (m.id_a == f.id_a && m.id_b == f.id_b) return m.mean_m;
  }
  return 0.0;
}

/// One group's GP inputs and targets (ε minus its pair mean), training and held-out rows apart.
struct GroupData {
  MatX X, Xh;
  VecX y, yh;
};

GroupData groupData(const BiasDataset& data, const std::vector<std::size_t>& idx, const std::vector<bool>& hold,
                    std::size_t n_tr, FeatureMap features, const std::vector<BiasModel::PairMean>& means) {
  // The GP inputs are written straight into the matrices the trainer reads (no intermediate feature copies).
  const int D = featureDim(features);
  GroupData g;
  g.X.resize(static_cast<Eigen::Index>(n_tr), D);
  g.Xh.resize(static_cast<Eigen::Index>(idx.size() - n_tr), D);
  g.y.resize(g.X.rows());
  g.yh.resize(g.Xh.rows());
  Eigen::Index itr = 0, iho = 0;
  double row[kMaxFeatureDim];
  for (std::size_t i : idx) {
    const TdoaFeature& f = data.samples[i].feature;
    featureRow(features, f, row);
    MatX& dst = hold[i] ? g.Xh : g.X;
    Eigen::Index& k = hold[i] ? iho : itr;
    for (int d = 0; d < D; ++d) dst(k, d) = row[d];
    (hold[i] ? g.yh : g.y)[k] = data.samples[i].error_m - pairMeanOf(means, f);
    ++k;
  }
  return g;
}

/// The levels and variance the model carries from its training data: (F24b), (F24c), (P45).
void setTrainingLevels(BiasModel& model, const BiasDataset& data, const std::vector<bool>& hold,
                       const BiasTrainParams& params) {
  {  // (F24b) the training flights' bias level, as the filter measured it on them
    double sum = 0.0;
    int n = 0;
    for (const BiasFlightReport& f : data.flights) {
      if (std::isfinite(f.bias_level_m) && f.bias_level_m > 0.0) {
        sum += f.bias_level_m;
        ++n;
      }
    }
    if (n > 0) model.setTrainingBiasLevel(sum / n);
  }
  // (F24c) and the level of the model's own mean on them, with the filter's memory, for flights whose level is known
  if (model.trainingBiasLevel() > 0.0)
    model.setTrainingMeanLevel(modelMeanLevel(model, data, data.params.localization.params.output_bias_memory_s));
  if (params.full_variance) {  // (P45): E[ε²] of the training targets
    double sum_sq = 0.0, n = 0.0;
    for (std::size_t i = 0; i < data.samples.size(); ++i) {
      if (hold[i]) continue;
      sum_sq += data.samples[i].error_m * data.samples[i].error_m;
      n += 1.0;
    }
    model.setFullVariance(true, sum_sq / n);
  }
}

/// The report's hold-out part: sample counts, bias RMSE before and after, predicted spread and calibration (P43).
void scoreHoldout(const BiasModel& model, const BiasDataset& data, const std::vector<bool>& hold, BiasTrainReport& r) {
  double se_before = 0, se_after = 0, sum_std = 0;
  std::vector<double> residual_m, variance_m2;  // (P43) of the held-out samples with a covering GP
  for (std::size_t i = 0; i < data.samples.size(); ++i) {
    if (!hold[i]) {
      ++r.n_train;
      continue;
    }
    ++r.n_holdout;
    const double eps = data.samples[i].error_m;
    const BiasPrediction p = model.predict(data.samples[i].feature);
    se_before += eps * eps;
    se_after += (eps - p.mean_m) * (eps - p.mean_m);
    sum_std += std::sqrt(p.variance_m2);
    const BiasPredictive q = model.predictive(data.samples[i].feature);
    if (q.covered && q.varianceM2() > 0.0) {
      residual_m.push_back(eps - q.mean_m);
      variance_m2.push_back(q.varianceM2());
    }
  }
  const double n = static_cast<double>(r.n_holdout);
  r.bias_rmse_before_m = n > 0 ? std::sqrt(se_before / n) : std::nan("");
  r.bias_rmse_after_m = n > 0 ? std::sqrt(se_after / n) : std::nan("");
  r.mean_predicted_std_m = n > 0 ? sum_std / n : std::nan("");
  const BiasCalibration cal = biasCalibration(residual_m, variance_m2, model.predictiveShape());  // NaN when empty
  r.mean_predictive_std_m = cal.mean_std_m;
  r.holdout_coverage_1sigma = cal.coverage_1sigma;
  r.holdout_coverage_2sigma = cal.coverage_2sigma;
  r.holdout_nlpd = cal.nlpd;
}

}  // namespace

BiasModel trainBiasModel(const BiasDataset& data, const BiasTrainParams& params, BiasTrainReport* report,
                         const BiasTrainProgress& progress) {
  params.validate();
  const BiasPreset preset = BiasPreset::byName(params.preset);
  const auto t_start = std::chrono::steady_clock::now();
  const std::vector<bool> hold = holdoutMask(data.samples, params.holdout_fraction, params.holdout_block_s);
  const SampleGroups groups = groupSamples(data, preset);
  const std::size_t need = static_cast<std::size_t>(params.min_samples_per_inducing) * params.num_inducing;
  requireTrainingSamples(groups, hold, need, params);

  // docs/math/gp.md (P28): per-pair constant means from the training part; the GP learns what remains.
  std::vector<BiasModel::PairMean> means;
  if (preset.pair_mean) {
    std::vector<bool> use(hold.size());
    for (std::size_t i = 0; i < hold.size(); ++i) use[i] = !hold[i];
    means = pairMeans(data.samples, use);
  }

  std::vector<BiasModel::Entry> entries;
  double elbo_weighted = 0.0, elbo_samples = 0.0;
  int model_index = 0;
  const int num_models = static_cast<int>(groups.size());
  for (const auto& [key, idx] : groups) {
    ++model_index;
    const std::size_t n_tr = countTraining(idx, hold);
    if (n_tr < need) continue;  // per-pair: too few for this pair → no model (predicts 0)
    const GroupData g = groupData(data, idx, hold, n_tr, preset.features, means);
    gp::Svgp svgp = gp::initSvgp(preset.kernel(), g.X, g.y, params.num_inducing, params.svgp.seed, preset.normalization);
    const int mi = model_index;
    const gp::SvgpTrainSummary ts = gp::trainSvgp(svgp, g.X, g.y, params.svgp, g.yh.size() > 0 ? &g.Xh : nullptr,
                                                  g.yh.size() > 0 ? &g.yh : nullptr, [&](const gp::EpochReport& r) {
                                                    if (progress) progress(mi, num_models, r);
                                                  });
    elbo_weighted += ts.final_elbo * static_cast<double>(g.X.rows());
    elbo_samples += static_cast<double>(g.X.rows());
    entries.push_back({key.first, key.second, std::move(svgp)});
  }
  if (entries.empty()) throw std::invalid_argument("no anchor pair has enough training samples for the requested inducing points");
  BiasModel model(preset.name, preset.features, std::move(entries), std::move(means));
  model.setExtraVariance(params.extra_sigma_m * params.extra_sigma_m);  // (P31)
  model.setMeanScale(params.mean_scale);                                 // (P44)
  model.setPredictiveShape(params.predictive_shape);                     // (P43b)
  setTrainingLevels(model, data, hold, params);

  if (report) {
    BiasTrainReport r;
    r.train_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    r.num_models = static_cast<int>(model.entries().size());
    r.final_elbo = elbo_samples > 0 ? elbo_weighted / elbo_samples : std::nan("");
    scoreHoldout(model, data, hold, r);
    *report = r;
  }
  return model;
}

void applyBiasModelLevel(const BiasModel& model, EkfParams* params) {
  if (!(params->bias_model_training_level_m > 0.0)) params->bias_model_training_level_m = model.trainingBiasLevel();
  if (!(params->bias_model_training_mean_level_m > 0.0))
    params->bias_model_training_mean_level_m = model.trainingMeanLevel();
}

namespace {
/// (F24c) per flight, the samples in time order through the F23c windows, mean_m[i] (the model's mean at sample i)
/// in place of the residual; the body origin stands for the tag (the lever arm is centimetres, the windows' geometry
/// does not feel it). Indexed by BiasSample::flight, NaN for a flight that counted no window.
std::vector<double> meanLevels(const BiasDataset& data, const std::vector<double>& mean_m, double memory_s) {
  std::map<int, BiasLevel> levels;
  for (std::size_t i = 0; i < data.samples.size(); ++i) {
    const BiasSample& s = data.samples[i];
    auto it = levels.try_emplace(s.flight, memory_s).first;
    const TdoaFeature& f = s.feature;
    it->second.add(s.t_s, f.id_a, f.w_p_anchor_a, f.id_b, f.w_p_anchor_b, f.w_p_b, mean_m[i]);
  }
  std::size_t n = data.flights.size();
  for (const auto& [flight, level] : levels)
    if (flight >= 0) n = std::max(n, static_cast<std::size_t>(flight) + 1);
  std::vector<double> out(n, std::numeric_limits<double>::quiet_NaN());
  for (const auto& [flight, level] : levels) {
    const double l = level.pairLevelData();
    if (flight >= 0 && std::isfinite(l)) out[static_cast<std::size_t>(flight)] = l;
  }
  return out;
}
}  // namespace

std::vector<double> modelMeanLevels(const BiasModel& model, const BiasDataset& data, double memory_s) {
  std::vector<double> mean_m(data.samples.size());
  for (std::size_t i = 0; i < data.samples.size(); ++i) mean_m[i] = model.predict(data.samples[i].feature).mean_m;
  return meanLevels(data, mean_m, memory_s);
}

DatasetPredictives datasetPredictives(const BiasModel& model, const BiasDataset& data) {
  // the GP once per sample: its predictive mean is the model's mean of predict() where it covers the pair (the same
  // operations); an uncovered pair's mean (its pair mean, no GP) comes from predict()
  DatasetPredictives d;
  d.samples.reserve(data.samples.size());
  std::vector<double> mean_m(data.samples.size());
  for (std::size_t i = 0; i < data.samples.size(); ++i) {
    d.samples.push_back(model.predictive(data.samples[i].feature));
    mean_m[i] = d.samples.back().covered ? d.samples.back().mean_m : model.predict(data.samples[i].feature).mean_m;
  }
  d.flight_mean_level_m = meanLevels(data, mean_m, data.params.localization.params.output_bias_memory_s);
  // (P43c) each covered sample gains the excess of its flight, from the level the dataset's filter run measured
  for (std::size_t i = 0; i < data.samples.size(); ++i) {
    const int fi = data.samples[i].flight;
    if (fi < 0 || static_cast<std::size_t>(fi) >= data.flights.size() || !d.samples[i].covered) continue;
    d.samples[i].level_variance_m2 = model.levelExcessVarianceM2(data.flights[static_cast<std::size_t>(fi)].bias_level_m,
                                                                 d.flight_mean_level_m[static_cast<std::size_t>(fi)]);
  }
  return d;
}

double modelMeanLevel(const BiasModel& model, const BiasDataset& data, double memory_s) {
  double sum = 0.0;
  int n = 0;
  for (const double l : modelMeanLevels(model, data, memory_s)) {
    if (!std::isfinite(l)) continue;
    sum += l;
    ++n;
  }
  return n > 0 ? sum / n : 0.0;
}

}  // namespace uwb
