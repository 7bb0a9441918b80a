/** @file BiasModel.h
 *  @brief A trained TDoA bias model: SVGP(s) plus the feature mapping, as a uwb::BiasPredictor for the filter.
 *
 *  Paper III-B: the measurement is corrected by the GP mean and the GP variance is added to the measurement
 *  variance. Presets (docs/math/gp.md P26):
 *   - "z1"   periodic(yaw_a) + periodic(yaw_b)                 inputs [yaw_a, yaw_b]        (paper eq. 7)
 *   - "z2"   Matérn-5/2(yaw_a) + Matérn-5/2(yaw_b)             inputs [yaw_a, yaw_b]        (paper eq. 8)
 *   - "tdoa" k_L(b_p_a) + k_L(b_p_b)                           inputs [b_p_a, b_p_b]        (paper eq. 9)
 *   beyond the paper:
 *   - "pair-tdoa" one "tdoa" GP per anchor pair
 *   - "pair-pos"  one GP per anchor pair, RBF-ARD on the body position w_p_b (standardized inputs)
 *   - "tdoa-pm"   "tdoa" on ε minus a per-pair constant mean m_AB (docs/math/gp.md P28)
 *   - "anchor-tdoa"    k_L(b_p_a)·k_rbf(w_a_A) + k_L(b_p_b)·k_rbf(w_a_B): the eq. 9 kernel made anchor-specific
 *                      by the anchor's surveyed world position (learned length scale sets how much anchors
 *                      share; docs/math/gp.md P29)
 *   - "anchor-tdoa-pm" "anchor-tdoa" plus the per-pair constant mean
 *   - "pair-tdoa-pos"  one GP per anchor pair, k_L(b_p_a) + k_L(b_p_b) + k_rbf(w_p_b): the eq. 9 kernel plus a
 *                      spatial map of the pair's error in the arena (docs/math/gp.md P26b)
 *  A pair without a model predicts {0, 0} (no correction, no added variance).
 *  Model file: JSON, {"format": "uwbtdoa-bias-model", "version": 1, ...}; see toJson().
 */
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "uwb/eval/BiasDataset.h"
#include "uwb/gp/Svgp.h"
#include "uwb/gp/SvgpTrainer.h"
#include "uwb/model/TdoaFeature.h"

namespace uwb {

/// Which TdoaFeature fields form the GP input row.
enum class FeatureMap {
  kYawAngles,      ///< [yaw_a_rad, yaw_b_rad]
  kBodyPositions,  ///< [b_p_a (3), b_p_b (3)] [m]
  kWorldPosition,  ///< [w_p_b (3)] [m]
  kBodyPositionsAnchors,  ///< [b_p_a (3), b_p_b (3), w_p_anchor_a (3), w_p_anchor_b (3)] [m]
  kBodyPositionsWorld,    ///< [b_p_a (3), b_p_b (3), w_p_b (3)] [m]
};
constexpr int kMaxFeatureDim = 12;
std::string toString(FeatureMap map);
FeatureMap featureMapFromString(const std::string& name);
int featureDim(FeatureMap map);
/// Writes the GP input row of f into row (featureDim(map) values).
void featureRow(FeatureMap map, const TdoaFeature& f, double* row);
MatX featureMatrix(FeatureMap map, const std::vector<TdoaFeature>& features);
/// Names of the featureDim(map) input columns, with units (e.g. "b_p_a_x_m", "yaw_a_rad").
std::vector<std::string> featureColumnNames(FeatureMap map);

/// Paper and extra presets: kernel, feature map, one GP per pair or one global GP.
struct BiasPreset {
  std::string name;
  FeatureMap features = FeatureMap::kYawAngles;
  bool per_pair = false;
  bool pair_mean = false;  ///< subtract a per-pair constant mean before the GP (docs/math/gp.md P28)
  gp::InputNormalization normalization = gp::InputNormalization::kNone;
  gp::Kernel kernel() const;  ///< fresh kernel with default hyperparameters
  static BiasPreset byName(const std::string& name);  ///< throws std::invalid_argument listing the presets
  static std::vector<std::string> names();
};

/// (P43b) Shape of the predictive distribution of ε around µ with σ² = var_f + σ_n²: a Student-t with `dof` degrees of
/// freedom and scale `scale`·σ; dof = 0 is the Gaussian N(µ, scale² σ²). The TDoA error's tails are heavier than a
/// Gaussian's (kurtosis 4–6 on a flight the model was not trained on). The defaults were chosen on the 0426 splits of
/// docs/math/gp.md P43b with the default kernel and reported on 0425. The filter is not affected: it uses µ and a
/// variance (P45).
struct PredictiveShape {
  double dof = 3.0;
  double scale = 0.8;
  static PredictiveShape gaussian() { return {0.0, 1.0}; }
  /// Throws std::invalid_argument unless dof = 0 or dof > 2 (a finite variance), and 0 < scale ≤ 10, both finite.
  void validate() const;
};

/// The preset the front ends (`uwbtdoa train`, Python's train_bias_model) train unless told otherwise, with
/// BiasTrainParams::num_inducing: the model that transferred best to flights outside the training set (docs/math/
/// gp.md P26c). BiasTrainParams itself keeps the paper's z1.
inline constexpr const char* kDefaultTrainPreset = "pair-tdoa-pos";

struct BiasTrainParams {
  std::string preset = "z1";
  int num_inducing = 30;            ///< M (per GP)
  gp::SvgpTrainParams svgp;         ///< epochs, batch, seed, learning rates, natural-gradient step
  double holdout_fraction = 0.2;    ///< share of the data held out (whole time blocks) for the before/after RMSE
  double holdout_block_s = 5.0;     ///< block length of the held-out split [s] (the error is correlated in time)
  int min_samples_per_inducing = 2; ///< need ≥ this × M training samples (per GP)
  /// Std added (in quadrature) to every predicted bias variance, i.e. to the filter's TDoA noise R when the
  /// correction is on [m] (docs/math/gp.md P31). 0: the paper's R + latent variance only.
  double extra_sigma_m = 0.0;
  /// Factor on the predicted mean stored in the model (P44); 1 = the paper's correction.
  double mean_scale = 1.0;
  /// Shape of the predictive distribution stored in the model (P43b).
  PredictiveShape predictive_shape;
  /// The filter's TDoA variance scaled by the unexplained share of the error (P45) instead of R + var_f.
  bool full_variance = false;
  void validate() const;
};

/// What training did; RMSEs on the held-out part.
struct BiasTrainReport {
  std::size_t n_train = 0, n_holdout = 0;
  double bias_rmse_before_m = 0.0;  ///< RMSE of raw ε on the held-out part
  double bias_rmse_after_m = 0.0;   ///< RMSE of ε − predicted mean on the held-out part
  double mean_predicted_std_m = 0.0;  ///< mean std of the predicted mean (latent, what the filter adds) on the held-out part
  /// The predictive distribution of ε (latent + likelihood noise, the model's shape; docs/math/gp.md P43, P43b) on the
  /// held-out time blocks: mean σ, coverage of its 68.3 % and 95.4 % intervals, NLPD [nats] (NaN without a held-out
  /// part). Blocks of the training flights: a flight the model was not trained on is scored by predict-bias/evaluate.
  double mean_predictive_std_m = 0.0;
  double holdout_coverage_1sigma = 0.0, holdout_coverage_2sigma = 0.0, holdout_nlpd = 0.0;
  double train_seconds = 0.0;
  int num_models = 0;
  /// Full-data ELBO per datum of the returned model(s) on their training samples (docs/math/gp.md P41); with
  /// several GPs, their mean weighted by training samples.
  double final_elbo = 0.0;
};

/// Predictive distribution of a measurement's error ε (docs/math/gp.md P43): ε ~ N(mean, latent + noise).
struct BiasPredictive {
  double mean_m = 0.0;              ///< pair mean (P28) + GP mean
  double latent_variance_m2 = 0.0;  ///< var_f of the GP mean (with the jitter)
  double noise_variance_m2 = 0.0;   ///< σ_n² of the GP's likelihood: the part of ε the inputs do not explain
  /// (P43c) the flight's bias variance beyond its training flights' and beyond what the mean explains
  /// (BiasModel::levelExcessVarianceM2); 0 when a level is unknown
  double level_variance_m2 = 0.0;
  bool covered = false;             ///< false: no GP covers the pair (mean 0, variances 0)
  double varianceM2() const { return latent_variance_m2 + noise_variance_m2 + level_variance_m2; }
};

/// Progress: (model index, number of models, epoch report).
using BiasTrainProgress = std::function<void(int, int, const gp::EpochReport&)>;

class BiasModel {
 public:
  struct Entry {
    int id_a = -1, id_b = -1;  ///< -1: the global model (all pairs)
    gp::Svgp gp;
  };
  /// Constant mean of one ordered anchor pair, added to the GP mean (docs/math/gp.md P28).
  struct PairMean {
    int id_a = -1, id_b = -1;
    double mean_m = 0.0;
  };

  BiasModel() = default;
  BiasModel(std::string preset, FeatureMap features, std::vector<Entry> entries, std::vector<PairMean> pair_means = {});

  /// Predicted bias (mean, latent variance) for one measurement's feature. {0, 0} when no model covers the pair.
  BiasPrediction predict(const TdoaFeature& f) const;
  /// Predictive distribution of ε itself (latent and likelihood variance, without the extra variance P31).
  BiasPredictive predictive(const TdoaFeature& f) const;
  /// The same on a flight whose uncorrected TDoA bias level the filter measured as flight_level_m (F23c) and on
  /// which the model's mean has the level flight_mean_level_m (F24c), with the excess variance of P43c added where
  /// the model covers the pair.
  BiasPredictive predictive(const TdoaFeature& f, double flight_level_m, double flight_mean_level_m) const;
  /// (P43c) The part of a flight's TDoA error variance that neither the model's mean explains nor its training
  /// flights showed. A pair level ℓ is the RMS of a pair's error (filter.md F23c), ℓ_µ that of the model's mean
  /// (F24c): with ε = µ + r, E[r²] ≈ ℓ² − ℓ_µ² on the flight and ℓ_train² − ℓ_µ,train² on the training flights,
  /// where the likelihood noise was learned. The excess is max(0, (ℓ² − ℓ_µ²) − (ℓ_train² − ℓ_µ,train²)); with ℓ_µ
  /// or ℓ_µ,train unknown (NaN, ≤ 0) both mean terms drop; 0 when ℓ or ℓ_train is unknown. A flight at a lower level
  /// gets nothing taken away.
  double levelExcessVarianceM2(double flight_level_m, double flight_mean_level_m) const;
  /// A cheap-to-copy, thread-compatible callable for the filter (shares this model's immutable state).
  BiasPredictor predictor() const;

  const std::string& preset() const { return preset_; }
  FeatureMap features() const { return features_; }
  const std::vector<Entry>& entries() const { return entries_; }
  const std::vector<PairMean>& pairMeans() const { return pair_means_; }
  /// Variance added to every prediction [m²] (P31).
  double extraVariance() const { return extra_variance_m2_; }
  void setExtraVariance(double variance_m2);  ///< throws std::invalid_argument when negative or not finite
  /// P45: with the full variance on, predict() asks the filter for R = (var_f + σ_n²)/E[ε²] · σ_tdoa² + extra (the
  /// filter's TDoA variance scaled by the share of the training error power the model leaves unexplained) instead
  /// of the paper's σ_tdoa² + var_f + extra. E[ε²]: mean square of the training targets.
  bool fullVariance() const { return full_variance_; }
  double targetMeanSquare() const { return target_mean_square_m2_; }
  void setFullVariance(bool on, double target_mean_square_m2);  ///< throws when on and the mean square is not > 0
  /// Factor w ∈ [0, 1] on the predicted mean (docs/math/gp.md P44): the correction subtracts w·µ. 1 = the paper.
  double meanScale() const { return mean_scale_; }
  void setMeanScale(double w);  ///< throws std::invalid_argument outside [0, 1]
  /// (P43b) The shape of the predictive distribution the calibration scores (default: PredictiveShape{}).
  const PredictiveShape& predictiveShape() const { return predictive_shape_; }
  void setPredictiveShape(const PredictiveShape& shape);  ///< throws std::invalid_argument (PredictiveShape::validate)
  /// (F24b) The TDoA bias level of the training flights, measured by the filter in flight (filter.md F23c; the mean
  /// of the flights' levels); 0 when unknown (trained on ground-truth inputs, or an older file). The filter scales
  /// the mean down on a flight whose own level is lower (EkfParams::bias_model_training_level_m).
  double trainingBiasLevel() const { return training_bias_level_m_; }
  void setTrainingBiasLevel(double level_m);  ///< throws std::invalid_argument unless finite and ≥ 0
  /// (F24c) The level of the model's own mean on its training flights: the statistic of F23c on µ at the training
  /// samples (the mean over the flights); 0 when unknown. The filter compares it with µ's level on the flight at hand
  /// (EkfParams::bias_model_training_mean_level_m).
  double trainingMeanLevel() const { return training_mean_level_m_; }
  void setTrainingMeanLevel(double level_m);  ///< throws std::invalid_argument unless finite and in [0, 10] m
  /// Constant mean of the pair (0 when none was learned).
  double pairMean(int id_a, int id_b) const;

  nlohmann::json toJson() const;
  static BiasModel fromJson(const nlohmann::json& j);  ///< throws std::invalid_argument (clear message)
  void save(const std::string& path) const;             ///< throws FileError
  static BiasModel load(const std::string& path);       ///< throws FileError / InputError naming the file

  /// Extra metadata stored with the model (training summary); free-form JSON object.
  std::string metadata_json = "{}";

 private:
  void buildPredictors();
  std::string preset_;
  FeatureMap features_ = FeatureMap::kYawAngles;
  std::vector<Entry> entries_;
  std::vector<PairMean> pair_means_;
  double extra_variance_m2_ = 0.0;
  double mean_scale_ = 1.0;
  double training_bias_level_m_ = 0.0;
  double training_mean_level_m_ = 0.0;
  PredictiveShape predictive_shape_;
  bool full_variance_ = false;
  double target_mean_square_m2_ = 0.0;
  std::shared_ptr<const std::vector<gp::SvgpPredictor>> predictors_;
};

/// Splits the dataset into train / held-out by time blocks (deterministic), trains the preset's GP(s) and reports
/// the held-out bias RMSE before and after. Throws std::invalid_argument when there are too few samples for M.
BiasModel trainBiasModel(const BiasDataset& data, const BiasTrainParams& params, BiasTrainReport* report = nullptr,
                         const BiasTrainProgress& progress = {});

/// Per-pair constant means of ε over the samples with use[i] (P28): m_AB = Σ ε / (n_AB + n0), shrunk to 0 by
/// n0 pseudo-samples.
std::vector<BiasModel::PairMean> pairMeans(const std::vector<BiasSample>& samples, const std::vector<bool>& use,
                                           double n0 = 10.0);

/// (F24c) The level of `model`'s mean on the samples of each flight of `data` (F23c statistic on µ, windows of
/// BiasLevel over each flight's samples in time order, forgotten with memory_s), averaged over the flights that
/// counted a window; 0 when none did.
double modelMeanLevel(const BiasModel& model, const BiasDataset& data, double memory_s);
/// The same per flight (indexed by BiasSample::flight, at least data.flights.size() entries); NaN for a flight that
/// counted no window.
std::vector<double> modelMeanLevels(const BiasModel& model, const BiasDataset& data, double memory_s);

/// The predictive distribution of every sample's ε (BiasModel::predictive, P43) on its flight, with the GP evaluated
/// once per sample: the level of the model's mean per flight (F24c, the filter's memory of data.params) from those
/// means, and each covered sample's level excess of P43c from its flight's bias_level_m (none where unknown, e.g.
/// ground-truth inputs).
struct DatasetPredictives {
  std::vector<BiasPredictive> samples;       ///< one per data.samples entry, in order
  std::vector<double> flight_mean_level_m;   ///< as modelMeanLevels
};
DatasetPredictives datasetPredictives(const BiasModel& model, const BiasDataset& data);

/// Indices of held-out samples: every k-th block of `block_s` seconds of each flight, k = round(1/fraction).
std::vector<bool> holdoutMask(const std::vector<BiasSample>& samples, double fraction, double block_s);

/// (F24b, F24c) Gives the filter the model's training levels: sets params->bias_model_training_level_m to
/// model.trainingBiasLevel() and params->bias_model_training_mean_level_m to model.trainingMeanLevel(), each unless
/// it is already > 0 (given by the user).
void applyBiasModelLevel(const BiasModel& model, EkfParams* params);

}  // namespace uwb
