/** @file KernelTest.cpp
 *  @brief Kernel properties (symmetry, PSD Gram, sum/product identities, periodicity), named parameters, JSON,
 *         and analytic hyperparameter / input gradients against central differences (STYLE §10).
 */
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>
#include <random>

#include "uwb/gp/Kernel.h"

namespace uwb::gp {
namespace {

MatX randomInputs(int n, int D, std::uint64_t seed, double lo = -2.0, double hi = 2.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  MatX X(n, D);
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < D; ++d) X(i, d) = u(rng);
  return X;
}

/// Inputs for k_L: 3-vectors with norm in [1, 4].
MatX ledergerberInputs(int n, int D, std::uint64_t seed) {
  MatX X = randomInputs(n, D, seed, -3.0, 3.0);
  for (int i = 0; i < n; ++i)
    for (int b = 0; b + 3 <= D; b += 3) {
      Vec3 v = X.row(i).segment<3>(b).transpose();
      if (v.norm() < 1.0) v = v.normalized() * 1.5;
      X.row(i).segment<3>(b) = v.transpose();
    }
  return X;
}

struct NamedKernel {
  std::string name;
  Kernel kernel;
  bool ledergerber_inputs = false;
};

std::vector<NamedKernel> kernelZoo() {
  PartSpec rbf{PartType::kRbf, {0, 1, 2}, 0.7, {0.8, 1.3, 0.6}};
  PartSpec mat{PartType::kMatern52, {1, 2}, 1.1, {0.9}};
  PartSpec per{PartType::kPeriodic, {0, 2}, 0.5, {0.7, 1.2}, {1.5, 2.5}, 0.0, 0.0, true};
  PartSpec kl{PartType::kLedergerber, {0, 1, 2}, 0.9};
  kl.t1 = 0.6;
  kl.t2 = 2.5;
  PartSpec kl2 = kl;
  kl2.active_dims = {3, 4, 5};
  kl2.t1 = 1.1;
  std::vector<NamedKernel> zoo;
  zoo.push_back({"rbf_ard", Kernel::sum({rbf})});
  zoo.push_back({"matern52", Kernel::sum({mat})});
  zoo.push_back({"periodic_ard", Kernel::sum({per})});
  zoo.push_back({"sum", Kernel::sum({rbf, mat, per})});
  zoo.push_back({"product", Kernel::product({rbf, per})});
  zoo.push_back({"sum_of_products", Kernel({rbf, mat, per}, {{0, 2}, {1}})});
  zoo.push_back({"z1", Kernel::preset("z1")});
  zoo.push_back({"z2", Kernel::preset("z2")});
  zoo.push_back({"ledergerber", Kernel::sum({kl}), true});
  zoo.push_back({"tdoa", Kernel::preset("tdoa"), true});
  zoo.push_back({"kl_sum", Kernel::sum({kl, kl2}), true});
  return zoo;
}

MatX inputsFor(const NamedKernel& k, int n, std::uint64_t seed) {
  const int D = std::max(3, k.kernel.inputDim());
  return k.ledergerber_inputs ? ledergerberInputs(n, std::max(6, D), seed) : randomInputs(n, D, seed);
}

TEST(Kernel, GramIsSymmetricAndPositiveSemiDefinite) {
  for (const auto& nk : kernelZoo()) {
    SCOPED_TRACE(nk.name + " seed 3");
    // GIVEN random inputs
    const MatX X = inputsFor(nk, 40, 3);
    // WHEN we build the Gram matrix
    const MatX K = nk.kernel.gram(X);
    // THEN it is symmetric and PSD
    EXPECT_LT((K - K.transpose()).cwiseAbs().maxCoeff(), 1e-14 * K.cwiseAbs().maxCoeff());
    const Eigen::SelfAdjointEigenSolver<MatX> es(K);
    EXPECT_GE(es.eigenvalues().minCoeff(), -1e-10 * std::max(1.0, es.eigenvalues().maxCoeff()));
    // and its diagonal is diagValue()
    EXPECT_LT((K.diagonal() - nk.kernel.diag(X)).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(Kernel, CrossColumnEqualsCross) {
  for (const auto& nk : kernelZoo()) {
    SCOPED_TRACE(nk.name);
    // GIVEN 150 points (three chunks of the allocation-free path) and one more point
    const MatX X = inputsFor(nk, 150, 5), Y = inputsFor(nk, 1, 6);
    // WHEN we evaluate the column both ways
    VecX col(X.rows());
    nk.kernel.crossColumn(X, Y.row(0), col);
    // THEN they agree to rounding
    EXPECT_LT((col - nk.kernel.cross(X, Y).col(0)).cwiseAbs().maxCoeff(), 1e-14);
  }
}

TEST(Kernel, SumAndProductIdentities) {
  // GIVEN two kernels and a pair of points
  PartSpec a{PartType::kRbf, {0, 1}, 0.7, {0.8, 1.3}};
  PartSpec b{PartType::kPeriodic, {1, 2}, 0.5, {0.7}, {2.0}};
  const Kernel ka = Kernel::sum({a}), kb = Kernel::sum({b});
  const Kernel ksum = Kernel::sum({a, b}), kprod = Kernel::product({a, b});
  const MatX X = randomInputs(7, 3, 11), Y = randomInputs(5, 3, 12);
  // THEN (k1 + k2) = k1 + k2 and (k1 · k2) = k1 · k2 elementwise
  const MatX Ka = ka.cross(X, Y), Kb = kb.cross(X, Y);
  EXPECT_LT((ksum.cross(X, Y) - (Ka + Kb)).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((kprod.cross(X, Y) - Ka.cwiseProduct(Kb)).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_NEAR(ksum(X.row(0), Y.row(1)), ka(X.row(0), Y.row(1)) + kb(X.row(0), Y.row(1)), 1e-15);
  EXPECT_EQ(ksum.name(), "(rbf[0,1]+periodic[1,2])");
  EXPECT_EQ(kprod.name(), "(rbf[0,1]*periodic[1,2])");
}

TEST(Kernel, PeriodicKernelRepeatsWithItsPeriod) {
  // GIVEN the z1 preset (T = 2π on each angle)
  const Kernel k = Kernel::preset("z1");
  const MatX X = randomInputs(6, 2, 5, -kPi, kPi), Y = randomInputs(4, 2, 6, -kPi, kPi);
  MatX Xs = X;
  Xs.col(0).array() += 2.0 * kPi;
  Xs.col(1).array() -= 4.0 * kPi;
  // THEN shifting any input by a multiple of T changes nothing
  EXPECT_LT((k.cross(X, Y) - k.cross(Xs, Y)).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(Kernel, PaperKernelsMatchTheirFormulas) {
  // GIVEN scalar inputs for the paper kernels (eq. 7–9)
  Kernel z1 = Kernel::preset("z1");
  z1.setParam("p0.periodic.sigma2", 0.3);
  z1.setParam("p0.periodic.l", 0.9);
  z1.setParam("p1.periodic.sigma2", 0.2);
  z1.setParam("p1.periodic.l", 1.4);
  RowVecX a(2), b(2);
  a << 0.3, -1.0;
  b << 2.5, 2.0;
  auto kp = [](double s2, double l, double r) { return s2 * std::exp(-2.0 * std::pow(std::sin(kPi * r / (2 * kPi)), 2) / (l * l)); };
  EXPECT_NEAR(z1(a, b), kp(0.3, 0.9, 2.2) + kp(0.2, 1.4, 3.0), 1e-15);
  Kernel z2 = Kernel::preset("z2");
  auto km = [](double s2, double l, double r) {
    return s2 * (1 + std::sqrt(5.0) * r / l + 5 * r * r / (3 * l * l)) * std::exp(-std::sqrt(5.0) * r / l);
  };
  EXPECT_NEAR(z2(a, b), km(0.05, 1.0, 2.2) + km(0.05, 1.0, 3.0), 1e-15);
  Kernel td = Kernel::preset("tdoa");
  RowVecX x(6), y(6);
  x << 1, 2, 0.5, -2, 1, 1;
  y << 2, 1, 0.2, -1, -1, 2;
  auto kl = [](double t0, double t1, double t2, const Vec3& u, const Vec3& v) {
    return t0 * std::exp(-(1 - u.dot(v) / (u.norm() * v.norm())) / t1 - std::pow(u.norm() - v.norm(), 2) / t2);
  };
  EXPECT_NEAR(td(x, y), kl(0.05, 0.5, 4.0, x.head<3>().transpose(), y.head<3>().transpose()) +
                            kl(0.05, 0.5, 4.0, x.tail<3>().transpose(), y.tail<3>().transpose()),
              1e-15);
}

TEST(Kernel, HyperparameterGradientMatchesCentralDifferences) {
  for (const auto& nk : kernelZoo()) {
    SCOPED_TRACE(nk.name + " seeds 21/22/23");
    // GIVEN inputs, a weight matrix G and f(θ) = Σ_ij G_ij k(x_i, y_j)
    const MatX X = inputsFor(nk, 9, 21), Y = inputsFor(nk, 7, 22);
    const MatX G = randomInputs(9, 7, 23, -1, 1);
    Kernel k = nk.kernel;
    auto f = [&](const VecX& theta) {
      Kernel kk = k;
      kk.setTheta(theta);
      return (G.array() * kk.cross(X, Y).array()).sum();
    };
    // WHEN we compare the analytic gradient with a 4th-order central difference
    std::vector<MatX> blocks;
    k.cross(X, Y, &blocks);
    VecX g = VecX::Zero(k.numParams());
    k.accumulateCrossGradient(X, Y, G, blocks, g, nullptr);
    const VecX theta = k.theta();
    for (int i = 0; i < k.numParams(); ++i) {
      const double h = 1e-4 * std::max(std::abs(theta[i]), 0.1);
      auto at = [&](double d) {
        VecX t = theta;
        t[i] += d;
        return f(t);
      };
      const double fd = (-at(2 * h) + 8 * at(h) - 8 * at(-h) + at(-2 * h)) / (12 * h);
      // THEN they agree
      EXPECT_NEAR(g[i], fd, 1e-7 * std::max(1.0, std::abs(fd))) << k.paramNames()[i];
    }
  }
}

TEST(Kernel, InputGradientMatchesCentralDifferences) {
  for (const auto& nk : kernelZoo()) {
    SCOPED_TRACE(nk.name + " seeds 31/32/33");
    // GIVEN f(X) = Σ_ij G_ij k(x_i, y_j)
    const MatX X = inputsFor(nk, 6, 31), Y = inputsFor(nk, 5, 32);
    const MatX G = randomInputs(6, 5, 33, -1, 1);
    const Kernel& k = nk.kernel;
    std::vector<MatX> blocks;
    k.cross(X, Y, &blocks);
    VecX g = VecX::Zero(k.numParams());
    MatX gX = MatX::Zero(X.rows(), X.cols());
    k.accumulateCrossGradient(X, Y, G, blocks, g, &gX);
    for (Eigen::Index i = 0; i < X.rows(); ++i)
      for (Eigen::Index d = 0; d < X.cols(); ++d) {
        const double h = 1e-5;
        MatX Xp = X, Xm = X;
        Xp(i, d) += h;
        Xm(i, d) -= h;
        const double fd = ((G.array() * k.cross(Xp, Y).array()).sum() - (G.array() * k.cross(Xm, Y).array()).sum()) / (2 * h);
        EXPECT_NEAR(gX(i, d), fd, 1e-7 * std::max(1.0, std::abs(fd))) << "row " << i << " col " << d;
      }
  }
}

TEST(Kernel, ParametersAreNamedReadableAndSettable) {
  // GIVEN the z1 preset
  Kernel k = Kernel::preset("z1");
  const auto p = k.params();
  // THEN its parameters have path-like names, T is fixed by default
  ASSERT_TRUE(p.count("p0.periodic.sigma2"));
  ASSERT_TRUE(p.count("p1.periodic.l"));
  ASSERT_TRUE(p.count("p0.periodic.T"));
  EXPECT_FALSE(p.at("p0.periodic.T").trainable);
  EXPECT_NEAR(p.at("p0.periodic.T").value, 2 * kPi, 1e-15);
  // WHEN we set one by name THEN it reads back
  k.setParam("p1.periodic.l", 0.42);
  EXPECT_EQ(k.param("p1.periodic.l"), 0.42);
  // AND bad names or non-positive values are rejected
  EXPECT_THROW(k.setParam("p9.periodic.l", 1.0), std::invalid_argument);
  EXPECT_THROW(k.setParam("p0.periodic.l", -1.0), std::invalid_argument);
  EXPECT_THROW(Kernel::preset("z3"), std::invalid_argument);
}

TEST(Kernel, JsonRoundTripIsExact) {
  for (const auto& nk : kernelZoo()) {
    SCOPED_TRACE(nk.name);
    const Kernel back = Kernel::fromJson(nlohmann::json::parse(nk.kernel.toJson().dump()));
    EXPECT_EQ(back.name(), nk.kernel.name());
    EXPECT_EQ(back.theta(), nk.kernel.theta());
    EXPECT_EQ(back.trainable(), nk.kernel.trainable());
  }
  EXPECT_THROW(Kernel::fromJson(nlohmann::json::parse(R"({"parts":[{"type":"foo","active_dims":[0]}]})")),
               std::invalid_argument);
}

TEST(Kernel, LedergerberRejectsZeroVector) {
  const Kernel k = Kernel::preset("tdoa");
  const MatX X = MatX::Zero(1, 6);
  EXPECT_THROW(k.gram(X), std::invalid_argument);
}

}  // namespace
}  // namespace uwb::gp
