/** @file KernelTest.cpp
 *  @brief Kernel properties (symmetry, PSD Gram, sum/product identities, periodicity), named parameters, JSON,
 *         and analytic hyperparameter / input gradients against central differences (STYLE §10).
 */
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>

#include "support/DerivativeChecker.h"
#include "support/KernelGradients.h"
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

TEST(Kernel, CrossIntoEqualsCross) {
  for (const auto& nk : kernelZoo()) {
    // GIVEN row counts below, between and above the vector widths of the batch path (4 lanes, 4 packets)
    for (int n1 : {1, 3, 5, 16, 37, 256}) {
      SCOPED_TRACE(nk.name + " n1 = " + std::to_string(n1));
      const MatX X = inputsFor(nk, n1, 7), Z = inputsFor(nk, 23, 8);
      // WHEN we evaluate K(X, Z) by the batch path (P32) and by cross()
      MatX K(n1, 23);
      nk.kernel.crossInto(X, Z, K);
      const MatX ref = nk.kernel.cross(X, Z);
      // THEN every entry agrees to rounding (the polynomial e^x is within a few ulp)
      EXPECT_TRUE(((K - ref).array().abs() <= 1e-14 * ref.array().abs()).all())
          << "max relative difference " << ((K - ref).array().abs() / ref.array().abs()).maxCoeff();
    }
  }
}

TEST(Kernel, CrossIntoRowsDoNotDependOnTheirPosition) {
  // GIVEN 45 points and the same points shifted by 3 rows inside a larger block
  PartSpec rbf{PartType::kRbf, {0, 1, 2, 3}, 0.7, {0.8, 1.3, 0.6, 1.0}};
  const Kernel k = Kernel::sum({rbf});
  const MatX X = randomInputs(48, 4, 9), Z = randomInputs(11, 4, 10);
  MatX Kall(48, 11), Kpart(45, 11);
  // WHEN both are evaluated by the batch path
  k.crossInto(X, Z, Kall);
  k.crossInto(X.bottomRows(45), Z, Kpart);
  // THEN each row is the same bit for bit (vector body and scalar tail do the same operations)
  EXPECT_EQ(Kpart, Kall.bottomRows(45));
}

TEST(Kernel, CrossIntoCoversTheWholeExponentRange) {
  // GIVEN an RBF with a short lengthscale: exponents from 0 down to about −5000 (underflow), plus a NaN input
  PartSpec rbf{PartType::kRbf, {0}, 1.3, {0.04}};
  const Kernel k = Kernel::sum({rbf});
  MatX X(401, 1), Z(2, 1);
  for (int i = 0; i < 401; ++i) X(i, 0) = -2.0 + 0.01 * i;
  Z << 0.0, 1.234567;
  MatX K(401, 2);
  k.crossInto(X, Z, K);
  const MatX ref = k.cross(X, Z);
  // THEN normal results agree to rounding and results below 1e-307 are 0 or subnormal (|error| < 3.3e-308)
  for (Eigen::Index i = 0; i < K.size(); ++i) {
    const double a = K.data()[i], b = ref.data()[i];
    if (std::abs(b) > 1e-300)
      EXPECT_LE(std::abs(a - b), 1e-14 * std::abs(b)) << i;
    else
      EXPECT_LT(std::abs(a - b), 3.3e-308) << i;
  }
  // AND NaN inputs give NaN, wrong sizes throw
  MatX Xn = X.topRows(6);
  Xn(2, 0) = std::numeric_limits<double>::quiet_NaN();
  MatX Kn(6, 2);
  k.crossInto(Xn, Z, Kn);
  EXPECT_TRUE(std::isnan(Kn(2, 0)) && std::isnan(Kn(2, 1)));
  EXPECT_FALSE(std::isnan(Kn(1, 0)));
  MatX wrong(5, 2);
  EXPECT_THROW(k.crossInto(Xn, Z, wrong), std::invalid_argument);
  const Kernel kl = Kernel::preset("tdoa");
  MatX Kl(1, 1);
  EXPECT_THROW(kl.crossInto(MatX::Zero(1, 6), MatX::Ones(1, 6), Kl), std::invalid_argument);
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
    const test::JacobianCheck c = test::checkGradient(f, k.theta(), g, {1e-4, 0.1, 4});
    // THEN they agree
    EXPECT_LT(c.max_scaled_error, 1e-7) << k.paramNames()[static_cast<std::size_t>(c.worst_col)] << ": " << c;
  }
}

TEST(Kernel, InputGradientMatchesCentralDifferences) {
  for (const auto& nk : kernelZoo()) {
    SCOPED_TRACE(nk.name + " seeds 31/32/33");
    // GIVEN f(X) = Σ_ij G_ij k(x_i, y_j)
    const MatX X = inputsFor(nk, 6, 31), Y = inputsFor(nk, 5, 32);
    const MatX G = randomInputs(6, 5, 33, -1, 1);
    const Kernel& k = nk.kernel;
    const MatX gX = test::crossGradients(k, X, Y, G).x;
    const auto f = [&](const VecX& x) {
      return (G.array() * k.cross(Eigen::Map<const MatX>(x.data(), X.rows(), X.cols()), Y).array()).sum();
    };
    const test::JacobianCheck c =
        test::checkGradient(f, Eigen::Map<const VecX>(X.data(), X.size()), Eigen::Map<const VecX>(gX.data(), gX.size()),
                            {1e-5, 1.0, 2});
    // (entry (0, j) is X(j % rows, j / rows))
    EXPECT_LT(c.max_scaled_error, 1e-7) << c;
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
