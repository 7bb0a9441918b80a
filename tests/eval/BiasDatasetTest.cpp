/** @file BiasDatasetTest.cpp
 *  @brief Bias training data (paper eq. 6) and the bias model: ε with lever arm, exclusion rules and counts,
 *         clear errors, model files (bit-identical round trip, corrupt/mismatched files), and a real-data check.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "support/TestSupport.h"
#include "uwb/core/Error.h"
#include "uwb/eval/BiasCalibration.h"
#include "uwb/eval/BiasDataset.h"
#include "uwb/eval/BiasModel.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

AnchorSurvey ringSurvey() {
  AnchorSurvey s;
  for (int i = 0; i < 8; ++i) {
    const double a = 2 * kPi * i / 8;
    s.anchors.push_back({i, Vec3(4 * std::cos(a), 4 * std::sin(a), i % 2 ? 0.2 : 2.5), Quat::Identity()});
  }
  s.source = "ring";
  return s;
}

/// A circle flight at 200 Hz pose; TDoA on neighbour pairs with a known bias 0.1·sin(yaw_a) + a ground phase.
/// A circle at 1.5 m after 2 s on the ground; TDoA bias 0.1 sin(yaw_a) plus white noise of std noise_sd_m (fixed seed).
Flight circleFlight(double duration_s = 20.0, double noise_sd_m = 0.0) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 1.0);
  Flight f;
  f.source = "synthetic-circle";
  f.pose_has_orientation = true;
  const AnchorSurvey s = ringSurvey();
  for (int k = 0; k <= static_cast<int>(duration_s * 200); ++k) {
    const double t = k / 200.0;
    PoseSample p;
    p.t_s = t;
    const double z = t < 2.0 ? 0.05 : 1.5;  // 2 s on the ground
    p.w_p_b = Vec3(1.5 * std::cos(0.5 * t), 1.5 * std::sin(0.5 * t), z);
    p.w_q_b = Quat(Eigen::AngleAxisd(0.1 * std::sin(t), Vec3::UnitZ()));
    f.pose.push_back(p);
  }
  const PoseTrack track(f.pose, true);
  for (int k = 0; k < static_cast<int>(duration_s * 100); ++k) {
    const double t = 0.0025 + k / 100.0;
    const int a = k % 8, b = (a + 1) % 8;
    const auto gt = track.interpolate(t);
    if (!gt) continue;
    const TdoaFeature feat = makeTdoaFeature(a, b, gt->w_p_b, gt->w_q_b, s.position(a), s.position(b));
    double bias = 0.1 * std::sin(feat.yaw_a_rad) + noise_sd_m * noise(rng);
    if (gt->w_p_b.z() < 0.3) bias = 2.0;                     // grossly wrong on the ground
    if (k % 97 == 5 && gt->w_p_b.z() > 0.3) bias = 3.0;      // gross outliers
    const double tdoa = predictTdoa(gt->w_p_b, gt->w_q_b, kUtilTagOffset_b, s.position(a), s.position(b)) + bias;
    f.tdoa.push_back({t, a, b, tdoa});
  }
  return f;
}

TEST(BiasDataset, ErrorIsMeasurementMinusModelWithLeverArmAndRulesAreCounted) {
  // GIVEN a synthetic flight with a known bias, a ground phase and outliers
  const Flight f = circleFlight();
  const AnchorSurvey s = ringSurvey();
  // WHEN we build the dataset with the default rules
  const BiasDataset ds = buildBiasDataset({f}, s);
  // THEN ε equals the injected bias (paper eq. 6, UTIL sign convention, with lever arm)
  ASSERT_FALSE(ds.samples.empty());
  for (const auto& smp : ds.samples) EXPECT_NEAR(smp.error_m, 0.1 * std::sin(smp.feature.yaw_a_rad), 1e-6);
  // AND every measurement is counted under exactly one rule
  const BiasFlightReport& r = ds.flights.at(0);
  EXPECT_EQ(r.n_measurements, f.tdoa.size());
  EXPECT_EQ(r.n_unknown_anchor + r.n_no_ground_truth + r.n_pose_glitch + r.n_on_ground + r.n_non_neighbour + r.n_outlier + r.n_used,
            r.n_measurements);
  EXPECT_NEAR(static_cast<double>(r.n_on_ground), 200.0, 2.0);  // 2 s at 100 Hz
  EXPECT_GT(r.n_outlier, 10u);
  EXPECT_EQ(r.n_used, ds.samples.size());
  EXPECT_NE(ds.reportText().find("on ground"), std::string::npos);
}

TEST(BiasDataset, RulesCanBeChanged) {
  const Flight f = circleFlight();
  BiasDatasetParams p;
  p.max_abs_error_m = 0.0;  // outlier rule off
  p.min_z_m = -1.0;         // ground rule off
  const BiasDataset ds = buildBiasDataset({f}, ringSurvey(), p);
  EXPECT_EQ(ds.flights[0].n_outlier, 0u);
  EXPECT_EQ(ds.flights[0].n_on_ground, 0u);
  EXPECT_EQ(ds.flights[0].n_used + ds.flights[0].n_no_ground_truth, f.tdoa.size());
}

TEST(BiasDataset, FlightWithoutGroundTruthIsAClearError) {
  Flight f = circleFlight(5);
  f.pose.clear();
  EXPECT_THROW(buildBiasDataset({f}, ringSurvey()), InputError);
}

TEST(BiasDataset, PositionOnlyPoseWithoutAnImuGivesWorldFrameFeaturesAsTheFilterFormsThem) {
  // GIVEN a flight without IMU whose pose has no orientation (the util-final-extract layout)
  Flight g = circleFlight(5);
  g.pose_has_orientation = false;
  const AnchorSurvey s = ringSurvey();
  // WHEN we build the dataset from the ground truth
  const BiasDataset ds = buildBiasDataset({g}, s);
  // THEN it trains, and says that the body frame was taken level and unturned
  ASSERT_FALSE(ds.samples.empty());
  EXPECT_FALSE(ds.flights.at(0).orientation_from_truth);
  EXPECT_NE(ds.reportText().find("position-only pose"), std::string::npos) << ds.reportText();
  // AND each sample is eq. 6 with the lever arm in the world frame and the features of the identity attitude, the
  // attitude the filter reports without an IMU
  const PoseTrack track(g.pose, false);
  for (const BiasSample& smp : ds.samples) {
    const auto gt = track.interpolate(smp.t_s);
    ASSERT_TRUE(gt);
    const TdoaFeature want = makeTdoaFeature(smp.feature.id_a, smp.feature.id_b, gt->w_p_b, Quat::Identity(),
                                             s.position(smp.feature.id_a), s.position(smp.feature.id_b));
    EXPECT_NEAR(smp.feature.yaw_a_rad, want.yaw_a_rad, 1e-12);
    EXPECT_NEAR(smp.feature.yaw_b_rad, want.yaw_b_rad, 1e-12);
    EXPECT_LT((smp.feature.b_p_a - want.b_p_a).norm(), 1e-12);
    const double predicted = predictTdoa(gt->w_p_b, Quat::Identity(), kUtilTagOffset_b, s.position(smp.feature.id_a),
                                         s.position(smp.feature.id_b));
    EXPECT_NEAR(smp.error_m, smp.measured_m - predicted, 1e-12);
  }
}

TEST(BiasDataset, PositionOnlyPoseOfAFlightWithAnImuNeedsTheEstimatedInputs) {
  // GIVEN a flight with an IMU whose pose has no orientation: the filter knows a body frame the truth does not give
  Flight g = circleFlight(5);
  g.pose_has_orientation = false;
  for (int k = 0; k < 100; ++k) {
    g.acc.push_back({0.01 * k, Vec3(0, 0, kGravity_mps2)});
    g.gyro.push_back({0.01 * k, Vec3::Zero()});
  }
  // WHEN the GP inputs are to come from the ground truth THEN a clear error names the column and the way out
  try {
    buildBiasDataset({g}, ringSurvey());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pose_qw"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--inputs estimate"), std::string::npos) << e.what();
  }
}

TEST(BiasModel, TooFewSamplesForTheInducingPointsIsAClearError) {
  const BiasDataset ds = buildBiasDataset({circleFlight(5)}, ringSurvey());
  BiasTrainParams p;
  p.num_inducing = 5000;
  try {
    trainBiasModel(ds, p);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("too few"), std::string::npos) << e.what();
  }
}

/// A z1 model with M = 15, 15 epochs of batches of 256: enough for the synthetic circle, in a fraction of a second.
BiasTrainParams smallZ1Training() {
  BiasTrainParams p;
  p.preset = "z1";
  p.num_inducing = 15;
  p.svgp.epochs = 15;
  p.svgp.batch_size = 256;
  return p;
}

TEST(BiasModel, TheHeldOutPartScoresThePredictiveDistribution) {
  // GIVEN the synthetic bias with white noise of 5 cm
  const BiasDataset ds = buildBiasDataset({circleFlight(40, 0.05)}, ringSurvey());
  const BiasTrainParams p = smallZ1Training();
  BiasTrainReport rep;
  // WHEN we train
  trainBiasModel(ds, p, &rep);
  // THEN the held-out report has the predictive σ (latent + likelihood noise, near the noise's 5 cm) beside the std of
  // the mean, and the intervals of the default t₄ shape cover about what they claim on data like the training data:
  // Gaussian residuals fall within its 68.3 % interval (±0.970σ) 67 % of the time and its 95.4 % one (±2.44σ) 98.5 %
  EXPECT_GT(rep.mean_predictive_std_m, rep.mean_predicted_std_m);
  EXPECT_NEAR(rep.mean_predictive_std_m, 0.05, 0.015);
  EXPECT_NEAR(rep.holdout_coverage_1sigma, 0.668, 0.08);
  EXPECT_NEAR(rep.holdout_coverage_2sigma, 0.985, 0.03);
  EXPECT_TRUE(std::isfinite(rep.holdout_nlpd));
}

TEST(BiasModel, AFlightMoreBiasedThanTheTrainingFlightsWidensThePredictiveDistributionByTheExcess) {
  // GIVEN a model trained on the synthetic flight (5 cm noise), whose training flights' level is 0.10 m
  const BiasDataset train = buildBiasDataset({circleFlight(40, 0.05)}, ringSurvey());
  BiasModel model = trainBiasModel(train, smallZ1Training());
  model.setTrainingBiasLevel(0.10);
  model.setTrainingMeanLevel(0.0);  // the level of its mean there unknown
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const TdoaFeature& f = train.samples.front().feature;
  const BiasPredictive plain = model.predictive(f);
  ASSERT_TRUE(plain.covered);
  // THEN a flight at level 0.25 m adds ℓ² − ℓ_train² = 0.0525 m² (P43c); a less biased flight or an unknown level
  // adds nothing, and the mean is never touched
  const BiasPredictive more = model.predictive(f, 0.25, nan);
  EXPECT_NEAR(more.level_variance_m2, 0.25 * 0.25 - 0.10 * 0.10, 1e-15);
  EXPECT_NEAR(more.varianceM2(), plain.varianceM2() + 0.0525, 1e-12);
  EXPECT_EQ(more.mean_m, plain.mean_m);
  EXPECT_EQ(model.predictive(f, 0.05, nan).level_variance_m2, 0.0);
  EXPECT_EQ(model.predictive(f, nan, nan).level_variance_m2, 0.0);
  // AND with the levels of the model's mean known on both sides, only what the mean does not explain counts:
  // (0.25² − 0.20²) − (0.10² − 0.06²) = 0.0225 − 0.0064 = 0.0161 m²; a mean that explains the whole excess adds 0
  model.setTrainingMeanLevel(0.06);
  EXPECT_NEAR(model.predictive(f, 0.25, 0.20).level_variance_m2, 0.0161, 1e-15);
  EXPECT_EQ(model.predictive(f, 0.25, 0.24).level_variance_m2, 0.0);
  EXPECT_NEAR(model.predictive(f, 0.25, nan).level_variance_m2, 0.0525, 1e-15);  // ℓ_µ unknown: both terms drop
  // AND a model of unknown training level adds nothing
  BiasModel unknown = model;
  unknown.setTrainingBiasLevel(0.0);
  EXPECT_EQ(unknown.predictive(f, 0.25, 0.20).level_variance_m2, 0.0);
  // AND on a flight with 25 cm of extra white error, which no mean explains, the calibration takes the flight's
  // level from its dataset: the intervals that under-cover without the excess cover near their nominal mass with it
  model.setTrainingMeanLevel(0.0);
  BiasDataset test = buildBiasDataset({circleFlight(40, 0.25)}, ringSurvey());
  const BiasCalibration blind = biasCalibration(test, model);
  test.flights.at(0).bias_level_m = std::sqrt(0.10 * 0.10 + 0.25 * 0.25);
  const BiasCalibration aware = biasCalibration(test, model);
  EXPECT_LT(blind.coverage_1sigma, 0.4);
  EXPECT_NEAR(aware.coverage_1sigma, 0.683, 0.08);
  EXPECT_NEAR(aware.coverage_2sigma, 0.954, 0.04);
}

TEST(BiasModel, DatasetPredictivesEvaluateTheGpOnceAndEqualThePerSampleReference) {
  // GIVEN a model with known training levels and a dataset whose flight has a measured level
  const BiasDataset train = buildBiasDataset({circleFlight(30, 0.05)}, ringSurvey());
  BiasModel model = trainBiasModel(train, smallZ1Training());
  model.setTrainingBiasLevel(0.10);
  model.setTrainingMeanLevel(0.05);
  BiasDataset test = buildBiasDataset({circleFlight(30, 0.25)}, ringSurvey());
  test.flights.at(0).bias_level_m = 0.3;
  // WHEN the predictive distributions are formed for the whole dataset at once
  const DatasetPredictives d = datasetPredictives(model, test);
  // THEN the level of the mean is modelMeanLevels', and every sample equals predictive(f, ℓ, ℓ_µ) bit for bit
  const double memory_s = test.params.localization.params.output_bias_memory_s;
  const std::vector<double> reference_levels = modelMeanLevels(model, test, memory_s);
  ASSERT_EQ(d.flight_mean_level_m.size(), reference_levels.size());
  EXPECT_EQ(d.flight_mean_level_m[0], reference_levels[0]);
  ASSERT_EQ(d.samples.size(), test.samples.size());
  int n_wider = 0;
  for (std::size_t i = 0; i < test.samples.size(); ++i) {
    const BiasPredictive ref = model.predictive(test.samples[i].feature, 0.3, reference_levels[0]);
    EXPECT_EQ(d.samples[i].mean_m, ref.mean_m) << i;
    EXPECT_EQ(d.samples[i].latent_variance_m2, ref.latent_variance_m2) << i;
    EXPECT_EQ(d.samples[i].noise_variance_m2, ref.noise_variance_m2) << i;
    EXPECT_EQ(d.samples[i].level_variance_m2, ref.level_variance_m2) << i;
    EXPECT_EQ(d.samples[i].covered, ref.covered) << i;
    n_wider += d.samples[i].level_variance_m2 > 0.0 ? 1 : 0;
  }
  EXPECT_EQ(n_wider, static_cast<int>(test.samples.size()));  // the flight is more biased than the training ones
}

TEST(BiasModel, LearnsTheSyntheticBiasAndRoundTripsBitIdentically) {
  // GIVEN a synthetic dataset with bias 0.1 sin(yaw_a)
  const BiasDataset ds = buildBiasDataset({circleFlight(30)}, ringSurvey());
  const BiasTrainParams p = smallZ1Training();
  BiasTrainReport rep;
  // WHEN we train
  const BiasModel model = trainBiasModel(ds, p, &rep);
  // THEN the held-out bias RMSE drops substantially
  EXPECT_LT(rep.bias_rmse_after_m, 0.5 * rep.bias_rmse_before_m);
  EXPECT_GT(rep.n_holdout, 0u);
  // AND a saved model loads back with bit-identical predictions
  const std::string path = ::testing::TempDir() + "/bias_model_test.json";
  model.save(path);
  const BiasModel back = BiasModel::load(path);
  const BiasPredictor pred = back.predictor();
  for (std::size_t i = 0; i < ds.samples.size(); i += 37) {
    const BiasPrediction a = model.predict(ds.samples[i].feature), b = pred(ds.samples[i].feature);
    EXPECT_EQ(a.mean_m, b.mean_m);
    EXPECT_EQ(a.variance_m2, b.variance_m2);
    EXPECT_GE(a.variance_m2, 0.0);
  }
  std::remove(path.c_str());
}

TEST(BiasModel, CorruptOrMismatchedModelFilesAreClearErrors) {
  const BiasDataset ds = buildBiasDataset({circleFlight(10)}, ringSurvey());
  BiasTrainParams p;
  p.num_inducing = 5;
  p.svgp.epochs = 1;
  const BiasModel model = trainBiasModel(ds, p);
  const std::string path = ::testing::TempDir() + "/bias_model_bad.json";
  auto write = [&](const std::string& text) {
    std::ofstream(path) << text;
  };
  // truncated file
  const std::string good = model.toJson().dump();
  write(good.substr(0, good.size() / 2));
  EXPECT_THROW(BiasModel::load(path), InputError);
  // wrong feature map for the GP input dimension
  nlohmann::json j = nlohmann::json::parse(good);
  j["features"] = "body_positions";
  j.erase("feature_columns");
  write(j.dump());
  try {
    BiasModel::load(path);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("dimension"), std::string::npos) << e.what();
  }
  // an SVGP file is not a bias model
  write(model.entries()[0].gp.toJson().dump());
  EXPECT_THROW(BiasModel::load(path), InputError);
  EXPECT_THROW(BiasModel::load(path + ".missing"), FileError);
  std::remove(path.c_str());
}

TEST(BiasDataset, RealFlightPoseGlitchesAndGroundPhaseAreExcluded) {
  const auto path = test::pilotFlight("0425-traj9");
  UWB_REQUIRE_REAL_DATA(path);
  const AnchorSurvey s = readAnchorSurvey(test::pilotSurvey("0425").string());
  const BiasDataset ds = buildBiasDataset({readFlightCsv(path->string())}, s);
  const auto& r = ds.flights[0];
  EXPECT_GT(r.n_pose_glitches_detected, 0u);  // SOURCE.md: glitches at t ≈ 14.1 s
  EXPECT_GT(r.n_pose_glitch, 0u);
  EXPECT_GT(r.n_on_ground, 0u);
  EXPECT_GT(r.n_used, r.n_measurements / 2);
}

}  // namespace
}  // namespace uwb
