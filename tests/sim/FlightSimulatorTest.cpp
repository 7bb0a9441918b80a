/** @file FlightSimulatorTest.cpp
 *  @brief Whole simulated flights: determinism, streams and rates, TDoA2 schedule, noise-free model, error
 *  composition, outliers, ground phase, and residual statistics within the documented (real-flight) ranges.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "support/TestSupport.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/model/TdoaModel.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/ResidualProfile.h"

namespace uwb::sim {
namespace {

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

SimResult defaultFlight(TrajectoryShape shape, double duration_s, std::uint64_t seed) {
  return simulateFlight(makeScenario(paperAnchors(), shape, duration_s), SimParams{}, seed);
}

TEST(FlightSimulator, FlightsWithOneFieldSeedShareTheLearnableBias) {
  // GIVEN circle flights with different seeds: two sharing field_seed 42, one with its own field
  const Scenario sc = makeScenario(paperAnchors(), TrajectoryShape::kCircle, 30.0);
  SimParams shared;
  shared.bias.field_seed = 42;
  const SimResult a = simulateFlight(sc, shared, 1);
  const SimResult b = simulateFlight(sc, shared, 2);
  const SimResult c = simulateFlight(sc, SimParams{}, 2);
  // WHEN comparing the pattern part (S12–S14) of measurements of the same pair taken within 2 ms of each other
  // (the schedule jitter differs per seed; the pose moves by millimetres in 2 ms)
  // THEN it is the same function of the pose for a and b, not for a and c
  auto matchedRms = [&](const SimResult& x, const SimResult& y) {
    double sq = 0.0;
    int n = 0;
    std::size_t j = 0;
    for (std::size_t i = 0; i < x.flight.tdoa.size(); ++i) {
      const auto& m = x.flight.tdoa[i];
      while (j + 1 < y.flight.tdoa.size() && y.flight.tdoa[j].t_s < m.t_s - 0.05) ++j;
      for (std::size_t k = j; k < y.flight.tdoa.size() && y.flight.tdoa[k].t_s < m.t_s + 0.05; ++k) {
        const auto& o = y.flight.tdoa[k];
        if (o.id_a != m.id_a || o.id_b != m.id_b || std::abs(o.t_s - m.t_s) > 0.002 || x.tdoa_truth[i].on_ground) continue;
        const double d = x.tdoa_truth[i].error.pattern_m - y.tdoa_truth[k].error.pattern_m;
        sq += d * d;
        ++n;
      }
    }
    EXPECT_GT(n, 100);
    return std::sqrt(sq / std::max(n, 1));
  };
  const double shared_rms = matchedRms(a, b);
  const double own_rms = matchedRms(a, c);
  EXPECT_LT(shared_rms, 0.01) << "same hardware: only the 2 ms time mismatch differs";
  EXPECT_GT(own_rms, 5.0 * shared_rms + 0.02) << "own hardware per flight";
  // AND the noise is the flight's own
  EXPECT_NE(a.tdoa_truth[10].error.noise_m, b.tdoa_truth[10].error.noise_m);
}

TEST(FlightSimulator, SameSeedSameFlightDifferentSeedDifferentFlight) {
  // GIVEN two runs with the same seed and one with another seed
  const SimResult a = defaultFlight(TrajectoryShape::kCircle, 30.0, 42);
  const SimResult b = defaultFlight(TrajectoryShape::kCircle, 30.0, 42);
  const SimResult c = defaultFlight(TrajectoryShape::kCircle, 30.0, 43);
  // THEN the first two agree bit for bit, and the third does not
  ASSERT_EQ(a.flight.tdoa.size(), b.flight.tdoa.size());
  for (std::size_t i = 0; i < a.flight.tdoa.size(); ++i) {
    ASSERT_EQ(a.flight.tdoa[i].t_s, b.flight.tdoa[i].t_s);
    ASSERT_EQ(a.flight.tdoa[i].tdoa_m, b.flight.tdoa[i].tdoa_m);
  }
  for (std::size_t i = 0; i < a.flight.acc.size(); ++i) ASSERT_EQ(a.flight.acc[i].b_value, b.flight.acc[i].b_value);
  EXPECT_NE(a.flight.tdoa[100].tdoa_m, c.flight.tdoa[100].tdoa_m);
}

TEST(FlightSimulator, StreamsHaveTheUtilRatesAndLayout) {
  // GIVEN a one-minute flight
  const SimResult r = defaultFlight(TrajectoryShape::kCircle, 60.0, 1);
  const Flight& f = r.flight;
  const auto rate = [](const auto& s) { return static_cast<double>(s.size() - 1) / (s.back().t_s - s.front().t_s); };
  // THEN IMU ≈ 1 kHz, pose 300 Hz, TDoA ≈ 400 Hz in total, with the full 27-column UTIL header
  EXPECT_NEAR(rate(f.acc), 1000.0, 1.0);
  EXPECT_NEAR(rate(f.gyro), 1000.0, 1.0);
  EXPECT_NEAR(rate(f.pose), 300.0, 0.5);
  EXPECT_NEAR(rate(f.tdoa), 400.0, 8.0);
  EXPECT_EQ(f.columns.size(), 27u);
  EXPECT_TRUE(f.pose_has_orientation);
  EXPECT_TRUE(f.tof.empty() && f.flow.empty() && f.baro.empty());
  EXPECT_EQ(r.tdoa_truth.size(), f.tdoa.size());
  EXPECT_EQ(r.imu_truth.size(), f.acc.size());
  // AND the ground phases take 7–38 % of the pose samples, as in the real files
  const auto ground = std::count_if(f.pose.begin(), f.pose.end(), [](const PoseSample& p) { return p.w_p_b.z() < 0.3; });
  const double ground_fraction = static_cast<double>(ground) / static_cast<double>(f.pose.size());
  EXPECT_GT(ground_fraction, 0.07);
  EXPECT_LT(ground_fraction, 0.38);
}

TEST(FlightSimulator, TdoaScheduleIsRoundRobinOverNeighbourPairs) {
  // GIVEN a flight with the 8 paper anchors
  const SimResult r = defaultFlight(TrajectoryShape::kCircle, 40.0, 5);
  const auto& m = r.flight.tdoa;
  const TdoaScheduleParams sp;
  std::map<std::pair<int, int>, int> counts;
  for (std::size_t i = 0; i < m.size(); ++i) {
    // THEN every measurement is a neighbour pair (k, k+1 mod 8), the next one follows in turn,
    EXPECT_EQ(m[i].id_b, (m[i].id_a + 1) % 8);
    if (i > 0) {
      EXPECT_EQ(m[i].id_a, (m[i - 1].id_a + 1) % 8);
      const double dt = m[i].t_s - m[i - 1].t_s;
      // and the intervals are jittered around 1/400 s within the configured band
      EXPECT_GE(dt, (1.0 - sp.jitter_fraction) / sp.rate_hz - 1e-12);
      EXPECT_LE(dt, (1.0 + sp.jitter_fraction) / sp.rate_hz + 1e-12);
    }
    ++counts[{m[i].id_a, m[i].id_b}];
  }
  // AND all 8 pairs come at ≈ 50 Hz each
  EXPECT_EQ(counts.size(), 8u);
  for (const auto& [pair, n] : counts) EXPECT_NEAR(n / 40.0, 50.0, 1.5);
}

TEST(FlightSimulator, NoiseFreeTdoaEqualsTheMeasurementModel) {
  // GIVEN a noise-free flight
  const SimResult r = simulateFlight(makeScenario(paperAnchors(), TrajectoryShape::kFigureEight, 30.0),
                                     SimParams::noiseFree(), 9);
  // WHEN we evaluate the model at the exact pose of each measurement (pose stream is exact, 300 Hz: check the
  // measurements that fall on pose instants within 0.1 ms; elsewhere compare with the recorded truth)
  const auto& pose = r.pose_exact;
  int checked = 0;
  for (std::size_t i = 0; i < r.flight.tdoa.size(); ++i) {
    const TdoaMeasurement& m = r.flight.tdoa[i];
    EXPECT_DOUBLE_EQ(m.tdoa_m, r.tdoa_truth[i].tdoa_true_m);
    const auto k = static_cast<std::size_t>(std::lround(m.t_s * 300.0));
    if (k >= pose.size() || std::abs(pose[k].t_s - m.t_s) > 1e-4) continue;
    // THEN z = |p_tag − a_B| − |p_tag − a_A| (UTIL convention, tag lever arm included), up to 0.1 ms of motion
    const double model = predictTdoa(pose[k].w_p_b, pose[k].w_q_b, kUtilTagOffset_b, r.survey.position(m.id_a),
                                     r.survey.position(m.id_b));
    EXPECT_NEAR(m.tdoa_m, model, 2e-4);
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST(FlightSimulator, MeasurementIsTruthPlusTheRecordedErrorParts) {
  const SimResult r = defaultFlight(TrajectoryShape::kZigzag, 40.0, 2);
  for (std::size_t i = 0; i < r.flight.tdoa.size(); ++i) {
    const TdoaTruth& t = r.tdoa_truth[i];
    EXPECT_NEAR(r.flight.tdoa[i].tdoa_m, t.tdoa_true_m + t.error.total(), 1e-12);
    if (t.airborne) {
      EXPECT_EQ(t.error.ground_m, 0.0);
    }
  }
}

TEST(FlightSimulator, OutlierSpikesAreRareHeavyTailedAndOfBothSigns) {
  // GIVEN a ten-minute flight with spikes only (bursts off)
  SimParams params;
  params.bias.burst_probability = 0.0;
  const SimResult r = simulateFlight(makeScenario(paperAnchors(), TrajectoryShape::kZigzag, 600.0), params, 8);
  const BiasParams& bp = params.bias;
  std::size_t n = 0, positive = 0, beyond_1m = 0;
  for (const TdoaTruth& t : r.tdoa_truth) {
    if (t.error.outlier_m == 0.0) continue;
    ++n;
    positive += t.error.outlier_m > 0.0 ? 1 : 0;
    beyond_1m += std::abs(t.error.outlier_m) > 1.0 ? 1 : 0;
    EXPECT_LE(std::abs(t.error.outlier_m), bp.outlier_max_m);
  }
  const double fraction = static_cast<double>(n) / static_cast<double>(r.tdoa_truth.size());
  // THEN about outlier_probability of the measurements are spikes, half of each sign, some beyond 1 m
  EXPECT_NEAR(fraction, bp.outlier_probability, 0.15 * bp.outlier_probability);
  EXPECT_NEAR(static_cast<double>(positive) / static_cast<double>(n), 0.5, 0.06);
  EXPECT_GT(beyond_1m, n / 20);
}

TEST(FlightSimulator, NlosBurstsLastOneBinAndHitTheConfiguredFraction) {
  // GIVEN the bias model of a flight
  const BiasParams bp;
  std::mt19937_64 rng(12);
  const SimulatedBias model(bp, paperAnchors(), rng);
  // WHEN we sample anchor 2's burst excess over many time bins
  std::size_t bins_in_burst = 0;
  const std::size_t n_bins = 20000;
  for (std::size_t k = 0; k < n_bins; ++k) {
    const double t = (static_cast<double>(k) + 0.5) * bp.burst_length_s;
    const double b = model.burstBias(2, t);
    // THEN it is a non-negative range excess, constant for a while (bursts, not spikes)
    EXPECT_GE(b, 0.0);
    EXPECT_LE(b, bp.outlier_max_m);
    if (b > 0.0) {
      ++bins_in_burst;
      const double nearby = model.burstBias(2, t + 0.02);
      const double other_side = model.burstBias(2, t - 0.02);
      EXPECT_TRUE(nearby == b || other_side == b);
    }
  }
  // AND the anchor is in a burst in about burst_probability of the bins
  EXPECT_NEAR(static_cast<double>(bins_in_burst) / n_bins, bp.burst_probability, 0.2 * bp.burst_probability);
}

TEST(FlightSimulator, GroundPhaseOffsetsAreSteadyPerPairAndUpToFourMetres) {
  // GIVEN a flight with the ground effect on (default)
  const SimResult r = defaultFlight(TrajectoryShape::kCircle, 60.0, 4);
  std::map<std::pair<int, int>, std::vector<double>> on_ground;
  for (std::size_t i = 0; i < r.tdoa_truth.size(); ++i) {
    const TdoaTruth& t = r.tdoa_truth[i];
    if (!t.on_ground) continue;
    on_ground[{r.flight.tdoa[i].id_a, r.flight.tdoa[i].id_b}].push_back(t.error.ground_m);
  }
  ASSERT_EQ(on_ground.size(), 8u);
  double largest = 0.0;
  for (const auto& [pair, v] : on_ground) {
    const double med = median(v);
    double sq = 0.0;
    for (double x : v) sq += (x - med) * (x - med);
    // THEN each pair is off by a steady amount with little scatter, never beyond ±3.9 m
    EXPECT_LT(std::sqrt(sq / static_cast<double>(v.size())), 0.1);
    EXPECT_LE(std::abs(med), 3.9);
    largest = std::max(largest, std::abs(med));
  }
  EXPECT_GT(largest, 1.0);  // low-anchor pairs are far off
  // AND with the effect switched off nothing is added
  SimParams off;
  off.bias.ground_effect = false;
  const SimResult q = simulateFlight(makeScenario(paperAnchors(), TrajectoryShape::kCircle, 60.0), off, 4);
  for (const TdoaTruth& t : q.tdoa_truth) ASSERT_EQ(t.error.ground_m, 0.0);
}

class AirborneResiduals : public ::testing::TestWithParam<std::pair<TrajectoryShape, std::uint64_t>> {};

TEST_P(AirborneResiduals, ResembleTheRealFlights) {
  // GIVEN a default flight of one shape and seed
  const auto [shape, seed] = GetParam();
  SCOPED_TRACE(toString(shape) + " seed " + std::to_string(seed));
  const SimResult r = defaultFlight(shape, 120.0, seed);
  // WHEN we compute the airborne residual statistics against the (quantized) pose stream
  const ResidualProfile s = residualProfile(r.flight, r.survey, Phase::kAirborne);
  // THEN they fall in the documented ranges of the util-pilot flights (docs/math/simulation.md, Calibration)
  EXPECT_LT(std::abs(s.overall.median_m), 0.03);
  EXPECT_GT(s.overall.mean_abs_dev_m, 0.13);
  EXPECT_LT(s.overall.mean_abs_dev_m, 0.27);
  for (const auto& [pair, ps] : s.pairs) EXPECT_LT(std::abs(ps.median_m), 0.25) << pair.first << "-" << pair.second;
  ASSERT_EQ(s.autocorrelation.size(), 4u);
  EXPECT_GT(s.autocorrelation[0].second, 0.45);  // 0.1 s
  EXPECT_LT(s.autocorrelation[0].second, 0.8);
  EXPECT_LT(s.autocorrelation[2].second, 0.4);   // 1 s
  EXPECT_GT(s.outlier_fraction, 0.001);  // real: 0.26–2.8 % beyond 1 m
  EXPECT_LT(s.outlier_fraction, 0.03);
}

INSTANTIATE_TEST_SUITE_P(ShapesAndSeeds, AirborneResiduals,
                         ::testing::Values(std::pair{TrajectoryShape::kCircle, 1ull},
                                           std::pair{TrajectoryShape::kCircle, 2ull},
                                           std::pair{TrajectoryShape::kZigzag, 3ull},
                                           std::pair{TrajectoryShape::kCircleSine, 4ull},
                                           std::pair{TrajectoryShape::kFigureEight, 5ull}));

TEST(FlightSimulator, MostOfTheBiasVarianceIsAFunctionOfBodyFrameDirections) {
  // GIVEN a zigzag training flight with yaw rotation (the paper's setting)
  const SimResult r = defaultFlight(TrajectoryShape::kZigzag, 300.0, 6);
  // WHEN we split the airborne error variance into its parts
  double pattern = 0.0, rest = 0.0, total = 0.0;
  std::size_t n = 0;
  for (const TdoaTruth& t : r.tdoa_truth) {
    if (!t.airborne) continue;
    pattern += t.error.pattern_m * t.error.pattern_m;
    rest += t.error.multipath_m * t.error.multipath_m + t.error.noise_m * t.error.noise_m;
    total += t.error.total() * t.error.total();
    ++n;
  }
  // THEN the learnable part (body-frame directions) is substantial, and so is the part that is not
  const double share = pattern / total;
  // (SOURCE.md: body-frame models explain about 25 % of the real error variance across flights)
  EXPECT_GT(share, 0.12) << share;
  EXPECT_LT(share, 0.6) << share;
  EXPECT_GT(rest / total, 0.25);
}

TEST(FlightSimulator, UtilConstellationPresetsLoadFromTheDataDirectory) {
  const auto path = test::dataDir() / "real" / "util-final-extract" / "survey" / "anchor_const4_survey.txt";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "real data not found under " << test::dataDir();
  const AnchorSurvey s = anchorPreset("util-const4", test::dataDir().string());
  EXPECT_EQ(s.anchors.size(), 8u);
  const SimResult r = simulateFlight(makeScenario(s, TrajectoryShape::kCircle, 30.0), SimParams{}, 1);
  EXPECT_GT(r.flight.tdoa.size(), 10000u);
  EXPECT_THROW(anchorPreset("util-const9", test::dataDir().string()), std::invalid_argument);
  EXPECT_THROW(anchorPreset("util-const1", "/nonexistent"), std::exception);
}

TEST(FlightSimulator, WrittenFlightReadsBackWithTheSameMeasurements) {
  // GIVEN a simulated flight written in the UTIL layout
  const SimResult r = defaultFlight(TrajectoryShape::kCircleSine, 30.0, 7);
  const auto dir = std::filesystem::temp_directory_path() / "uwb_sim_test";
  std::filesystem::create_directories(dir);
  const std::string flight_path = (dir / "flight.csv").string();
  const std::string survey_path = (dir / "survey.txt").string();
  writeFlightCsv(r.flight, flight_path);
  writeAnchorSurvey(r.survey, survey_path);
  // WHEN we read it back
  const Flight f = readFlightCsv(flight_path);
  const AnchorSurvey s = readAnchorSurvey(survey_path);
  // THEN the streams are the same (the writer converts acc to g and gyro to deg/s and back)
  ASSERT_EQ(f.tdoa.size(), r.flight.tdoa.size());
  ASSERT_EQ(f.acc.size(), r.flight.acc.size());
  ASSERT_EQ(f.pose.size(), r.flight.pose.size());
  ASSERT_EQ(s.anchors.size(), r.survey.anchors.size());
  for (std::size_t i = 0; i < f.tdoa.size(); i += 97) EXPECT_NEAR(f.tdoa[i].tdoa_m, r.flight.tdoa[i].tdoa_m, 1e-6);
  for (std::size_t i = 0; i < f.acc.size(); i += 997) {
    EXPECT_LT((f.acc[i].b_value - r.flight.acc[i].b_value).norm(), 1e-5);
    EXPECT_LT((f.gyro[i].b_value - r.flight.gyro[i].b_value).norm(), 1e-6);
  }
  std::filesystem::remove_all(dir);
}

TEST(FlightSimulator, RejectsInvalidParameters) {
  const Scenario sc = makeScenario(paperAnchors(), TrajectoryShape::kCircle, 30.0);
  SimParams p;
  p.tdoa.rate_hz = -1.0;
  EXPECT_THROW(simulateFlight(sc, p, 1), std::invalid_argument);
  p = SimParams{};
  p.bias.outlier_probability = 2.0;
  EXPECT_THROW(simulateFlight(sc, p, 1), std::invalid_argument);
  Scenario one = sc;
  one.survey.anchors.resize(1);
  EXPECT_THROW(simulateFlight(one, SimParams{}, 1), std::invalid_argument);
}

TEST(FlightSimulator, RejectsAPathAQuadrotorCannotFly) {
  // GIVEN a take-off of 1.47 m in 1 s: the septic smoothstep (S2) brakes it at up to 7.5 × 1.47 m/s² = 11 m/s², more
  // than gravity, which would take a thrust that pulls (the body would flip over in the air)
  Scenario sc = makeScenario(paperAnchors(), TrajectoryShape::kCircle, 30.0);
  sc.trajectory.takeoff_s = 1.0;
  // THEN the simulator refuses it, naming the parameter to change
  try {
    simulateFlight(sc, SimParams{}, 1);
    ADD_FAILURE() << "a path braking faster than gravity was simulated";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("takeoff_s"), std::string::npos) << e.what();
  }
  // AND 1.2 s (7.7 m/s²) is flown
  sc.trajectory.takeoff_s = 1.2;
  EXPECT_NO_THROW(simulateFlight(sc, SimParams{}, 1));
}

}  // namespace
}  // namespace uwb::sim
