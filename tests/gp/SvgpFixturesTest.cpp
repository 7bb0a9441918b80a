/** @file SvgpFixturesTest.cpp
 *  @brief Reproduces every value of the GPyTorch reference fixtures (../shared/fixtures, FIXTURES.md) to 1e-8
 *         relative: ELBO, KL, ELL, predictions, every gradient (incl. grad_elbo_paper) and the intermediates.
 *
 *  Path: env UWBTDOA_SVGP_FIXTURES (a file, or a directory of *.json), else UWB_DEFAULT_FIXTURES_DIR. A path
 *  that cannot be read is a FAILURE, never a skip.
 */
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "uwb/gp/Svgp.h"

namespace uwb::gp {
namespace {

namespace fs = std::filesystem;
constexpr double kTol = 1e-8;

MatX toMat(const nlohmann::json& j) {
  MatX M(j.size(), j.empty() ? 0 : j[0].size());
  for (std::size_t i = 0; i < j.size(); ++i)
    for (std::size_t k = 0; k < j[i].size(); ++k) M(i, k) = j[i][k].get<double>();
  return M;
}
VecX toVec(const nlohmann::json& j) {
  VecX v(j.size());
  for (std::size_t i = 0; i < j.size(); ++i) v[i] = j[i].get<double>();
  return v;
}
MatX scalar(double x) { return MatX::Constant(1, 1, x); }

/// Fixture files named by the environment (or the default directory). Empty + failure message on error.
std::vector<fs::path> fixtureFiles(std::string& error) {
  const char* env = std::getenv("UWBTDOA_SVGP_FIXTURES");
  const fs::path root = (env && *env) ? fs::path(env) : fs::path(UWB_DEFAULT_FIXTURES_DIR);
  std::vector<fs::path> files;
  std::error_code ec;
  if (fs::is_directory(root, ec)) {
    for (const auto& e : fs::directory_iterator(root))
      if (e.path().extension() == ".json") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    if (files.empty()) error = "no *.json fixture files in " + root.string();
  } else if (fs::is_regular_file(root, ec)) {
    files.push_back(root);
  } else {
    error = "cannot read SVGP fixture path '" + root.string() + "' (UWBTDOA_SVGP_FIXTURES)";
  }
  return files;
}

nlohmann::json readJson(const fs::path& p, std::string& error) {
  std::ifstream in(p);
  if (!in) {
    error = "cannot open fixture file " + p.string();
    return {};
  }
  try {
    return nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    error = "cannot parse fixture file " + p.string() + ": " + e.what();
    return {};
  }
}

/// Maps our flat kernel gradient (paper parameters) to the fixture's per-part blocks.
struct PartGrads {
  double sigma2;
  VecX l, T;
  double t1 = 0, t2 = 0;
};

PartGrads partGrads(const Kernel& k, int p, const VecX& g) {
  const PartSpec s = k.partSpec(p);
  // the flat layout is σ², l..., T... | t0, t1, t2 (Kernel.cpp build())
  int offset = 0;
  for (int q = 0; q < p; ++q) {
    const PartSpec sq = k.partSpec(q);
    offset += sq.type == PartType::kLedergerber ? 3 : 1 + static_cast<int>(sq.l.size() + sq.T.size());
  }
  PartGrads out;
  out.sigma2 = g[offset];
  if (s.type == PartType::kLedergerber) {
    out.t1 = g[offset + 1];
    out.t2 = g[offset + 2];
  } else {
    out.l = g.segment(offset + 1, static_cast<Eigen::Index>(s.l.size()));
    out.T = g.segment(offset + 1 + static_cast<Eigen::Index>(s.l.size()), static_cast<Eigen::Index>(s.T.size()));
  }
  return out;
}

void checkFixture(const nlohmann::json& fx, ElboMode mode, double tol) {
  // GIVEN the fixture's kernel (paper parameters), state and data
  const Kernel kernel = Kernel::fromJson(fx.at("kernel"));
  Svgp gp(kernel, toMat(fx.at("inducing_points")), fx.at("jitter").get<double>());
  gp.setVariational(toVec(fx.at("variational").at("m")), toMat(fx.at("variational").at("L")));
  gp.setMean(fx.at("mean").at("constant").get<double>());
  gp.setNoiseVariance(fx.at("likelihood").at("noise").get<double>());
  const MatX X = toMat(fx.at("data").at("X"));
  const VecX y = toVec(fx.at("data").at("y"));
  const double num_data = fx.at("num_data").get<double>();
  const auto& ex = fx.at("expected");

  // WHEN we evaluate the ELBO with its gradient, and predict at the test inputs
  SvgpGradient g;
  const ElboTerms e = gp.elbo(X, y, num_data, &g, mode);
  const SvgpPrediction pred = gp.predict(toMat(fx.at("test").at("X")));

  // THEN every value matches
  EXPECT_LT(relativeError(scalar(e.elbo), scalar(ex.at("elbo").get<double>())), tol);
  EXPECT_LT(relativeError(scalar(e.kl), scalar(ex.at("kl").get<double>())), tol);
  EXPECT_LT(relativeError(scalar(e.exp_log_lik), scalar(ex.at("exp_log_lik").get<double>())), tol);
  EXPECT_LT(relativeError(scalar(e.exp_log_lik_sum), scalar(ex.at("exp_log_lik_sum").get<double>())), tol);
  EXPECT_LT(relativeError(scalar(e.kl / num_data), scalar(ex.at("kl_over_num_data").get<double>())), tol);
  EXPECT_LT(relativeError(pred.mean, toVec(ex.at("pred_mean"))), tol);
  EXPECT_LT(relativeError(pred.var_f, toVec(ex.at("pred_var_f"))), tol);
  EXPECT_LT(relativeError(pred.var_y, toVec(ex.at("pred_var_y"))), tol);

  const auto& ge = ex.at("grad_elbo");
  EXPECT_LT(relativeError(scalar(g.mean), scalar(ge.at("constant_mean").get<double>())), tol);
  EXPECT_LT(relativeError(scalar(g.noise), scalar(ge.at("noise").get<double>())), tol);
  EXPECT_LT(relativeError(g.Z, toMat(ge.at("inducing_points"))), tol) << "grad Z";
  EXPECT_LT(relativeError(g.m, toVec(ge.at("m"))), tol) << "grad m";
  const MatX gL_ref = toMat(ge.at("L")).triangularView<Eigen::Lower>();
  EXPECT_LT(relativeError(g.L, gL_ref), tol) << "grad L";

  // kernel gradients: GPyTorch convention (grad_elbo) and paper convention (grad_elbo_paper)
  const auto& gparts = ge.at("kernel_parts");
  const auto& pparts = ex.at("grad_elbo_paper").at("kernel_parts");
  ASSERT_EQ(static_cast<int>(gparts.size()), kernel.numParts());
  for (int p = 0; p < kernel.numParts(); ++p) {
    SCOPED_TRACE("kernel part " + std::to_string(p));
    const PartSpec s = kernel.partSpec(p);
    const PartGrads pg = partGrads(kernel, p, g.kernel);
    const auto& gp_ref = gparts[p];
    const auto& pp_ref = pparts[p];
    EXPECT_LT(relativeError(scalar(pg.sigma2), scalar(gp_ref.at("outputscale").get<double>())), tol);
    if (s.type == PartType::kLedergerber) {
      EXPECT_LT(relativeError(scalar(pg.sigma2), scalar(pp_ref.at("t0").get<double>())), tol);
      EXPECT_LT(relativeError(scalar(pg.t1), scalar(gp_ref.at("t1").get<double>())), tol);
      EXPECT_LT(relativeError(scalar(pg.t2), scalar(gp_ref.at("t2").get<double>())), tol);
      EXPECT_LT(relativeError(scalar(pg.t1), scalar(pp_ref.at("t1").get<double>())), tol);
      EXPECT_LT(relativeError(scalar(pg.t2), scalar(pp_ref.at("t2").get<double>())), tol);
      continue;
    }
    EXPECT_LT(relativeError(scalar(pg.sigma2), scalar(pp_ref.at("sigma2").get<double>())), tol);
    EXPECT_LT(relativeError(pg.l, toVec(pp_ref.at("l"))), tol) << "paper l";
    if (s.type == PartType::kPeriodic) {
      // GPyTorch lengthscale λ = l²: ∂/∂λ = ∂/∂l / (2l)
      const VecX l = Eigen::Map<const VecX>(s.l.data(), static_cast<Eigen::Index>(s.l.size()));
      const VecX g_lambda = pg.l.cwiseQuotient(2.0 * l);
      EXPECT_LT(relativeError(g_lambda, toVec(gp_ref.at("lengthscale"))), tol) << "gpytorch lengthscale";
      EXPECT_LT(relativeError(pg.T, toVec(gp_ref.at("period_length"))), tol) << "period";
      EXPECT_LT(relativeError(pg.T, toVec(pp_ref.at("T"))), tol) << "paper T";
    } else {
      EXPECT_LT(relativeError(pg.l, toVec(gp_ref.at("lengthscale"))), tol) << "gpytorch lengthscale";
    }
  }

  // intermediates
  const auto& im = fx.at("intermediate");
  MatX Kzz = kernel.gram(gp.inducing());
  std::vector<MatX> blocks;
  kernel.cross(gp.inducing(), gp.inducing(), &blocks);
  for (int p = 0; p < kernel.numParts(); ++p)
    EXPECT_LT(relativeError(blocks[p], toMat(im.at("Kzz_parts")[p])), tol) << "Kzz part " << p;
  Kzz.diagonal().array() += gp.jitter();
  EXPECT_LT(relativeError(Kzz, toMat(im.at("Kzz"))), tol) << "Kzz";
  const MatX Lz = Eigen::LLT<MatX>(Kzz).matrixL();
  EXPECT_LT(relativeError(Lz, toMat(im.at("Lz"))), tol) << "Lz";
  const MatX Xt = toMat(fx.at("test").at("X"));
  const MatX Kzt = kernel.cross(gp.inducing(), Xt);
  EXPECT_LT(relativeError(Kzt, toMat(im.at("Kzt"))), tol) << "Kzt";
  const MatX At = Lz.triangularView<Eigen::Lower>().solve(Kzt);
  EXPECT_LT(relativeError(At, toMat(im.at("A_test"))), tol) << "A_test";
  EXPECT_LT(relativeError(kernel.diag(Xt), toVec(im.at("k_test_diag"))), tol) << "k_test_diag";

  // single-point predictions agree with the batch
  const SvgpPredictor predictor = gp.predictor();
  for (Eigen::Index i = 0; i < Xt.rows(); ++i) {
    double mean = 0, var_f = 0;
    predictor.predictOne(Xt.row(i), mean, var_f);
    // the predictor's Q path (P20) against the reference triangular solves of Svgp::predict
    EXPECT_NEAR(mean, pred.mean[i], 1e-10 * std::max(1.0, std::abs(pred.mean[i])));
    EXPECT_NEAR(var_f, pred.var_f[i], 1e-10 * std::max(1.0, pred.var_f[i]));
  }
}

void runAll(ElboMode mode, double tol) {
  std::string error;
  const auto files = fixtureFiles(error);
  ASSERT_TRUE(error.empty()) << error;
  int n = 0;
  for (const auto& f : files) {
    SCOPED_TRACE(f.string());
    const nlohmann::json doc = readJson(f, error);
    ASSERT_TRUE(error.empty()) << error;
    ASSERT_TRUE(doc.contains("fixtures")) << f << " has no \"fixtures\" array";
    for (const auto& fx : doc.at("fixtures")) {
      SCOPED_TRACE(fx.at("name").get<std::string>());
      checkFixture(fx, mode, tol);
      ++n;
    }
  }
  EXPECT_GT(n, 0) << "no fixtures found";
}

TEST(SvgpFixtures, ReproducesEveryReferenceValueExactPath) { runAll(ElboMode::kExact, kTol); }

TEST(SvgpFixtures, ReproducesEveryReferenceValueFastPath) { runAll(ElboMode::kFast, kTol); }

}  // namespace
}  // namespace uwb::gp
