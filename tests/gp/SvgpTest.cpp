/** @file SvgpTest.cpp
 *  @brief SVGP: ELBO gradients vs finite differences for every parameter (both evaluation paths), natural-gradient
 *         optimum, deterministic training, fast single predictions, model-file round trip and errors.
 */
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <functional>
#include <random>
#include <utility>
#include <vector>

#include "support/DerivativeChecker.h"
#include "uwb/gp/SvgpTrainer.h"

namespace uwb::gp {
namespace {

struct Problem {
  Svgp gp;
  MatX X;
  VecX y;
  double num_data = 500;
};

/// A small random problem with kernel parts on their own columns (like the paper kernels) plus a product.
Problem makeProblem(std::uint64_t seed, int N = 40, int M = 7) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-2, 2);
  std::normal_distribution<double> n(0, 1);
  PartSpec per{PartType::kPeriodic, {0}, 0.6, {0.9}, {2.5}, 0, 0, true};
  PartSpec mat{PartType::kMatern52, {1, 2}, 0.8, {0.7, 1.3}};
  PartSpec rbf{PartType::kRbf, {0, 2}, 0.5, {1.1}};
  Kernel k({per, mat, rbf}, {{0}, {1, 2}});
  Problem p;
  p.X.resize(N, 3);
  p.y.resize(N);
  for (int i = 0; i < N; ++i) {
    for (int d = 0; d < 3; ++d) p.X(i, d) = u(rng);
    p.y[i] = std::sin(p.X(i, 0)) + 0.3 * p.X(i, 1) + 0.1 * n(rng);
  }
  MatX Z(M, 3);
  for (int i = 0; i < M; ++i)
    for (int d = 0; d < 3; ++d) Z(i, d) = u(rng);
  p.gp = Svgp(k, Z);
  VecX m(M);
  MatX L = MatX::Zero(M, M);
  for (int i = 0; i < M; ++i) {
    m[i] = 0.5 * n(rng);
    L(i, i) = 0.4 + 0.5 * std::abs(n(rng));
    for (int j = 0; j < i; ++j) L(i, j) = 0.15 * n(rng);
  }
  p.gp.setVariational(m, L);
  p.gp.setMean(0.1);
  p.gp.setNoiseVariance(0.05);
  return p;
}

void checkGradient(ElboMode mode) {
  // GIVEN a random SVGP state and batch
  const Problem p = makeProblem(7);
  SvgpGradient g;
  p.gp.elbo(p.X, p.y, p.num_data, &g, mode);
  auto elboWith = [&](const std::function<void(Svgp&)>& edit) {
    Svgp q = p.gp;
    edit(q);
    return q.elbo(p.X, p.y, p.num_data, nullptr, ElboMode::kExact).elbo;
  };
  // THEN every gradient matches 4th-order central differences (test::checkGradient), block by block
  const test::DifferenceOptions fd4{1e-4, 0.1, 4};
  const auto expectMatches = [&](const std::function<void(Svgp&, const VecX&)>& set, const VecX& x, const VecX& g_x,
                                 const std::string& what) {
    const test::JacobianCheck c =
        test::checkGradient([&](const VecX& v) { return elboWith([&](Svgp& q) { set(q, v); }); }, x, g_x, fd4);
    EXPECT_LT(c.max_scaled_error, 1e-6) << what << ": " << c;
  };
  expectMatches([](Svgp& q, const VecX& v) { q.kernel().setTheta(v); }, p.gp.kernel().theta(), g.kernel, "kernel θ");
  expectMatches([](Svgp& q, const VecX& v) { q.setNoiseVariance(v[0]); }, VecX::Constant(1, p.gp.noiseVariance()),
                VecX::Constant(1, g.noise), "noise");
  expectMatches([](Svgp& q, const VecX& v) { q.setMean(v[0]); }, VecX::Constant(1, p.gp.meanConstant()),
                VecX::Constant(1, g.mean), "mean");
  const MatX Z = p.gp.inducing();
  expectMatches([&](Svgp& q, const VecX& v) { q.setInducing(Eigen::Map<const MatX>(v.data(), Z.rows(), Z.cols())); },
                Eigen::Map<const VecX>(Z.data(), Z.size()), Eigen::Map<const VecX>(g.Z.data(), g.Z.size()), "Z");
  const VecX m = p.gp.variationalMean();
  const MatX L = p.gp.variationalCholesky();
  expectMatches([&](Svgp& q, const VecX& v) { q.setVariational(v, L); }, m, g.m, "m");
  // L: its lower triangle, column by column
  std::vector<std::pair<Eigen::Index, Eigen::Index>> lower;
  for (Eigen::Index j = 0; j < L.cols(); ++j)
    for (Eigen::Index i = j; i < L.rows(); ++i) lower.emplace_back(i, j);
  VecX l(static_cast<Eigen::Index>(lower.size())), g_l(l.size());
  for (std::size_t k = 0; k < lower.size(); ++k) {
    l[static_cast<Eigen::Index>(k)] = L(lower[k].first, lower[k].second);
    g_l[static_cast<Eigen::Index>(k)] = g.L(lower[k].first, lower[k].second);
  }
  expectMatches(
      [&](Svgp& q, const VecX& v) {
        MatX Lq = L;
        for (std::size_t k = 0; k < lower.size(); ++k) Lq(lower[k].first, lower[k].second) = v[static_cast<Eigen::Index>(k)];
        q.setVariational(m, Lq);
      },
      l, g_l, "L (lower triangle, column-major)");
  EXPECT_EQ(g.L.triangularView<Eigen::StrictlyUpper>().toDenseMatrix().cwiseAbs().maxCoeff(), 0.0);
}

/// The default training with `epochs` passes over mini-batches of `batch_size`.
SvgpTrainParams miniBatches(int epochs, int batch_size) {
  SvgpTrainParams tp;
  tp.epochs = epochs;
  tp.batch_size = batch_size;
  return tp;
}

TEST(Svgp, ElboGradientMatchesFiniteDifferencesExactPath) { checkGradient(ElboMode::kExact); }
TEST(Svgp, ElboGradientMatchesFiniteDifferencesFastPath) { checkGradient(ElboMode::kFast); }

TEST(Svgp, FastAndExactPathsAgree) {
  const Problem p = makeProblem(9);
  SvgpGradient a, b;
  const double ea = p.gp.elbo(p.X, p.y, p.num_data, &a, ElboMode::kExact).elbo;
  const double eb = p.gp.elbo(p.X, p.y, p.num_data, &b, ElboMode::kFast).elbo;
  EXPECT_NEAR(ea, eb, 1e-12 * std::abs(ea));
  EXPECT_LT(relativeError(b.kernel, a.kernel), 1e-10);
  EXPECT_LT(relativeError(b.Z, a.Z), 1e-10);
  EXPECT_LT(relativeError(b.L, a.L), 1e-10);
}

TEST(Svgp, FullBatchNaturalGradientStepOfOneReachesTheOptimalQ) {
  // GIVEN a full batch (B = N_data)
  Problem p = makeProblem(3, 60, 8);
  SvgpGradient g;
  p.gp.elbo(p.X, p.y, 60, &g);
  // WHEN we take a natural-gradient step of size 1
  naturalGradientStep(p.gp, g.AAt, g.Ar + g.AAt * p.gp.variationalMean(), 60, 60, 1.0);
  // THEN q(v) is optimal: ∂ELBO/∂m = 0 and ∂ELBO/∂L = 0
  p.gp.elbo(p.X, p.y, 60, &g);
  EXPECT_LT(g.m.cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(g.L.cwiseAbs().maxCoeff(), 1e-9);
}

TEST(Svgp, TrainingIsDeterministicForASeedAndImprovesTheElbo) {
  // GIVEN data from a smooth function
  Problem p = makeProblem(5, 600, 5);
  SvgpTrainParams tp = miniBatches(4, 128);
  tp.seed = 17;
  Svgp a = initSvgp(p.gp.kernel(), p.X, p.y, 12, 17);
  Svgp b = initSvgp(p.gp.kernel(), p.X, p.y, 12, 17);
  const double before = a.elbo(p.X, p.y, 600).elbo;
  // WHEN we train twice with the same seed
  trainSvgp(a, p.X, p.y, tp);
  trainSvgp(b, p.X, p.y, tp);
  // THEN the results are bit-identical and the ELBO improved
  EXPECT_EQ(a.toJson().dump(), b.toJson().dump());
  EXPECT_GT(a.elbo(p.X, p.y, 600).elbo, before + 0.1);
}

TEST(Svgp, AdamOnlyTrainingAlsoWorks) {
  Problem p = makeProblem(6, 400, 5);
  SvgpTrainParams tp = miniBatches(5, 100);
  tp.natgrad_step = 0.0;
  tp.lr_variational = 0.05;
  Svgp a = initSvgp(p.gp.kernel(), p.X, p.y, 10, 1, InputNormalization::kStandardize);
  const double before = a.elbo(p.X, p.y, 400).elbo;
  trainSvgp(a, p.X, p.y, tp);
  EXPECT_GT(a.elbo(p.X, p.y, 400).elbo, before);
}

TEST(Svgp, SinglePredictionEqualsBatchPrediction) {
  Problem p = makeProblem(8);
  p.gp.setInputTransform(VecX::Constant(3, 0.1), VecX::Constant(3, 1.5));
  const SvgpPredictor pred = p.gp.predictor();
  const SvgpPrediction batch = pred.predict(p.X);
  for (Eigen::Index i = 0; i < p.X.rows(); ++i) {
    double mean, var;
    pred.predictOne(p.X.row(i), mean, var);
    EXPECT_NEAR(mean, batch.mean[i], 1e-13);
    EXPECT_NEAR(var, batch.var_f[i], 1e-13);
    EXPECT_NEAR(batch.var_y[i] - batch.var_f[i], p.gp.noiseVariance(), 1e-15);
  }
}

TEST(SvgpPredictor, SinglePredictionsOfModelsOfDifferentSizeInTurnShareTheThreadsScratch) {
  // GIVEN two models of different size (M = 5 and 40) on the same inputs, and their batch predictions
  Problem small = makeProblem(21, 200, 5);
  small.gp.setInputTransform(VecX::Constant(3, 0.1), VecX::Constant(3, 1.5));
  Problem large = makeProblem(22, 200, 40);
  const SvgpPredictor ps = small.gp.predictor(), pl = large.gp.predictor();
  const SvgpPrediction bs = ps.predict(small.X), bl = pl.predict(small.X);
  // WHEN the single-point path alternates between them on one thread (its scratch grows once and is reused)
  for (Eigen::Index i = 0; i < small.X.rows(); ++i) {
    double ms, vs, ml, vl;
    ps.predictOne(small.X.row(i), ms, vs);
    pl.predictOne(small.X.row(i), ml, vl);
    // THEN each equals its own model's batch prediction
    EXPECT_NEAR(ms, bs.mean[i], 1e-12);
    EXPECT_NEAR(vs, bs.var_f[i], 1e-12);
    EXPECT_NEAR(ml, bl.mean[i], 1e-12);
    EXPECT_NEAR(vl, bl.var_f[i], 1e-12);
  }
  // AND an input row of the wrong width is refused, not read past its end
  double m, v;
  EXPECT_THROW(ps.predictOne(RowVecX::Zero(2), m, v), std::invalid_argument);
}

TEST(SvgpPredictor, BatchedAndSinglePredictionsAgreeWithTheReferencePath) {
  // GIVEN models with an input transform, small and trained-size (M = 60 k-means inducing points)
  for (int M : {7, 60}) {
    SCOPED_TRACE(M);
    Problem p = makeProblem(11, 700, M);
    if (M > 7) p.gp = initSvgp(p.gp.kernel(), p.X, p.y, M, 3, InputNormalization::kStandardize);
    if (M > 7) {
      trainSvgp(p.gp, p.X, p.y, miniBatches(3, 128));
    } else {
      p.gp.setInputTransform(VecX::Constant(3, 0.1), VecX::Constant(3, 1.5));
    }
    // WHEN we predict with the precomputed predictor (α, Q; P20), batched (several blocks) and point by point
    const SvgpPrediction ref = p.gp.predict(p.X);
    const SvgpPredictor pred = p.gp.predictor();
    const SvgpPrediction fast = pred.predict(p.X);
    // THEN it agrees with the triangular-solve reference to 1e-10 relative
    EXPECT_LT(relativeError(fast.mean, ref.mean), 1e-10);
    EXPECT_LT(relativeError(fast.var_f, ref.var_f), 1e-10);
    EXPECT_LT(relativeError(fast.var_y, ref.var_y), 1e-10);
    EXPECT_LT(relativeError(pred.predictMean(p.X), ref.mean), 1e-10);
    VecX mean1(p.X.rows()), var1(p.X.rows());
    for (Eigen::Index i = 0; i < p.X.rows(); ++i) pred.predictOne(p.X.row(i), mean1[i], var1[i]);
    EXPECT_LT(relativeError(mean1, ref.mean), 1e-10);
    EXPECT_LT(relativeError(var1, ref.var_f), 1e-10);
  }
}

TEST(SvgpPredictor, FusedBatchPathEqualsTheReferenceForEveryKernel) {
  // GIVEN the paper presets (on angle / anchor-vector columns), an RBF-ARD and sums/products of parts, with
  // M not a multiple of the SIMD widths (4 lanes, 6-column panels, 8-point tiles) and N = 517 test points (two
  // 256-row blocks and a ragged one that is not a whole number of tiles)
  PartSpec rbf4{PartType::kRbf, {0, 1, 2, 3}, 0.8, {1.7, 2.1, 1.3, 1.9}};
  PartSpec per{PartType::kPeriodic, {0, 2}, 0.5, {0.9, 1.4}, {2.5, 3.5}, 0.0, 0.0, true};
  PartSpec mat{PartType::kMatern52, {1, 3}, 0.7, {1.6}};
  PartSpec kl{PartType::kLedergerber, {3, 4, 5}, 0.6};
  kl.t1 = 0.7;
  kl.t2 = 3.0;
  // Presets with shorter scales than their defaults so that Kzz stays well conditioned at M = 171 on two input
  // columns: the P20 form itself (not its evaluation) loses digits with cond(Kzz), see the class comment.
  auto preset = [](const std::string& name, const std::vector<std::pair<std::string, double>>& values) {
    Kernel k = Kernel::preset(name);
    for (const auto& [param, value] : values) k.setParam(param, value);
    return k;
  };
  const std::vector<std::pair<std::string, Kernel>> kernels = {
      {"z1", preset("z1", {{"p0.periodic.l", 0.05}, {"p1.periodic.l", 0.05}})},
      {"z2", preset("z2", {{"p0.matern52.l", 0.1}, {"p1.matern52.l", 0.1}})},
      {"tdoa", preset("tdoa", {{"p0.ledergerber.t1", 0.05}, {"p1.ledergerber.t1", 0.05}})},
      {"rbf_ard", Kernel::sum({rbf4})},
      {"sum", Kernel::sum({rbf4, per, mat})},
      {"product", Kernel::product({per, mat})},
      {"sum_of_products", Kernel({rbf4, per, kl}, {{0, 2}, {1}})}};
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(-3, 3);
  std::normal_distribution<double> n01(0, 1);
  auto inputs = [&](int rows) {
    MatX X(rows, 6);
    for (int i = 0; i < rows; ++i) {
      for (int d = 0; d < 6; ++d) X(i, d) = u(rng);
      X(i, 0) += 4.0;  // anchor vectors (cols 0–2, 3–5) well away from 0 for the ledergerber parts
      X(i, 3) += 4.0;
    }
    return X;
  };
  // inducing points at least 0.3 apart in columns 0–1 (the presets' angle columns, also modulo 2π): no
  // near-duplicate rows in Kzz
  auto angleDistance = [](const MatX& Z, int i, int j) {
    double d2 = 0.0;
    for (int d = 0; d < 2; ++d) {
      const double a = std::abs(Z(i, d) - Z(j, d));
      d2 += std::pow(std::min(a, 2.0 * kPi - a), 2);
    }
    return std::sqrt(d2);
  };
  auto spread = [&](int rows) {
    MatX Z = inputs(rows);
    for (int i = 1; i < rows; ++i) {
      for (bool close = true; close;) {
        close = false;
        for (int j = 0; j < i && !close; ++j) close = angleDistance(Z, i, j) < 0.3;
        if (close) Z.row(i) = inputs(1);
      }
    }
    return Z;
  };
  const MatX X = inputs(517);
  for (const auto& [name, kernel] : kernels) {
    for (int M : {1, 5, 13, 64, 171}) {
      SCOPED_TRACE(name + " M = " + std::to_string(M));
      Svgp gp(kernel, spread(M));
      VecX m(M);
      MatX L = MatX::Zero(M, M);
      for (int i = 0; i < M; ++i) {
        m[i] = n01(rng);
        L(i, i) = 0.3 + 0.4 * std::abs(n01(rng));
        for (int j = 0; j < i; ++j) L(i, j) = 0.05 * n01(rng);
      }
      gp.setVariational(m, L);
      gp.setMean(-0.2);
      if (M == 13) gp.setInputTransform(VecX::Constant(6, 0.1), VecX::Constant(6, 1.2));
      // WHEN we predict with the fused batch path (P32, P33) and with the reference triangular solves (P13)
      const SvgpPrediction ref = gp.predict(X);
      const SvgpPredictor pred = gp.predictor();
      const SvgpPrediction fast = pred.predict(X);
      // THEN mean and latent variance agree to 1e-12 relative, and the mean-only path gives the same mean
      EXPECT_LT(relativeError(fast.mean, ref.mean), 1e-12);
      EXPECT_LT(relativeError(fast.var_f, ref.var_f), 1e-12);
      EXPECT_EQ(pred.predictMean(X), fast.mean);
      // AND a row gets the same bits wherever it sits in the batch (shifted by 3 rows: other SIMD lanes, other tile)
      // and on whichever of two threads computes it
      const SvgpPrediction tail = pred.predict(X.bottomRows(514), 2);
      EXPECT_EQ(tail.mean, fast.mean.tail(514));
      EXPECT_EQ(tail.var_f, fast.var_f.tail(514));
    }
  }
}

TEST(SvgpPredictor, ThreadedPredictionIsBitIdenticalToOneThread) {
  // GIVEN a model and more test points than one kernel block, with a ragged last block
  Problem p = makeProblem(12, 1300, 9);
  p.gp.setInputTransform(VecX::Constant(3, -0.2), VecX::Constant(3, 0.8));
  const SvgpPredictor pred = p.gp.predictor();
  const SvgpPrediction one = pred.predict(p.X, 1);
  const VecX mean_one = pred.predictMean(p.X, 1);
  // WHEN the rows are split over 2, 3, 7 threads or one per hardware thread (0)
  for (int threads : {2, 3, 7, 0}) {
    SCOPED_TRACE(threads);
    const SvgpPrediction many = pred.predict(p.X, threads);
    // THEN every value is the same bit for bit (each row is computed by the same operations whatever the split)
    EXPECT_EQ(many.mean, one.mean);
    EXPECT_EQ(many.var_f, one.var_f);
    EXPECT_EQ(many.var_y, one.var_y);
    EXPECT_EQ(pred.predictMean(p.X, threads), mean_one);
  }
  // AND the single-point path agrees
  double mean = 0.0, var = 0.0;
  pred.predictOne(p.X.row(1299), mean, var);
  EXPECT_NEAR(mean, one.mean[1299], 1e-12);
  EXPECT_NEAR(var, one.var_f[1299], 1e-12);
  // AND a negative thread count and an empty batch are handled
  EXPECT_THROW(pred.predict(p.X, -1), std::invalid_argument);
  EXPECT_EQ(pred.predict(MatX(0, 3), 4).mean.size(), 0);
}

TEST(SvgpModelFile, RoundTripGivesBitIdenticalPredictions) {
  // GIVEN a trained-looking model with an input transform
  Problem p = makeProblem(4);
  p.gp.setInputTransform(VecX::Constant(3, -0.3), VecX::Constant(3, 0.7));
  p.gp.kernel().setTrainable("p1.matern52.l[1]", false);
  // WHEN we write and read it
  const std::string text = p.gp.toJson().dump();
  const Svgp back = Svgp::fromJson(nlohmann::json::parse(text));
  // THEN predictions are bit-identical and the file is the same
  const SvgpPrediction a = p.gp.predict(p.X), b = back.predict(p.X);
  EXPECT_TRUE((a.mean.array() == b.mean.array()).all());
  EXPECT_TRUE((a.var_y.array() == b.var_y.array()).all());
  EXPECT_EQ(back.toJson().dump(), text);
}

TEST(SvgpModelFile, CorruptOrMismatchedFilesAreClearErrors) {
  const Problem p = makeProblem(4);
  const nlohmann::json good = p.gp.toJson();
  auto expectError = [](const nlohmann::json& j, const std::string& fragment) {
    try {
      Svgp::fromJson(j);
      ADD_FAILURE() << "no error for " << fragment;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  nlohmann::json j = good;
  j["version"] = 99;
  expectError(j, "version");
  j = good;
  j["format"] = "something-else";
  expectError(j, "format");
  j = good;
  j["variational"]["m"].erase(0);
  expectError(j, "M=");
  j = good;
  j.erase("kernel");
  expectError(j, "kernel");
  j = good;
  j["inducing_points"][1].erase(0);
  expectError(j, "ragged");
  j = good;
  j["input_transform"]["shift"] = {1.0};
  j["input_transform"]["scale"] = {1.0};
  expectError(j, "input_transform");
  expectError(nlohmann::json::array(), "object");
}

TEST(KMeansPlusPlus, IsDeterministicAndRejectsTooFewPoints) {
  const Problem p = makeProblem(2, 200, 5);
  EXPECT_EQ(kmeansPlusPlus(p.X, 10, 3), kmeansPlusPlus(p.X, 10, 3));
  EXPECT_THROW(kmeansPlusPlus(p.X.topRows(5), 10, 3), std::invalid_argument);
  EXPECT_THROW(kmeansPlusPlus(MatX::Ones(50, 2), 3, 3), std::invalid_argument);  // one distinct point
}

}  // namespace
}  // namespace uwb::gp
