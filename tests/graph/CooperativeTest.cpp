/** @file CooperativeTest.cpp
 *  @brief Cooperative localization with agents as "anchors" of the TDoA node (docs/math/message-passing.md G19).
 */
#include "uwb/graph/Cooperative.h"

#include <gtest/gtest.h>

#include "GraphTestUtil.h"
#include "uwb/graph/Nodes.h"
#include "uwb/model/TdoaLinearization.h"

namespace uwb {
namespace {

using namespace graphtest;

double tdoa(const Vec3& k, const Vec3& i, const Vec3& j) { return (k - i).norm() - (k - j).norm(); }

TEST(Cooperative, SingleMeasurementIsExactForTheLinearizedModel) {
  // GIVEN agent 0 receiving a TDoA between agent 1 (uncertain) and a surveyed anchor 2, z at the linearization point
  std::mt19937 rng(17);
  const std::vector<Moments3> priors{{Vec3(0.5, 0.2, 1.0), Mat3(randomSpd(rng, 3, 0.05) * 0.2)},
                                     {Vec3(3.0, -1.0, 1.5), Mat3(randomSpd(rng, 3, 0.05) * 0.2)},
                                     {Vec3(-4.0, 3.0, 2.5), Mat3::Zero()}};
  const auto lin = *linearizeTdoa(priors[0].m, priors[1].m, priors[2].m);
  const double z = lin.evaluate(priors[0].m, priors[1].m, priors[2].m) + 0.3, var = 0.02;
  // WHEN one round of message passing runs
  const auto post = cooperativeTdoaUpdate(priors, {{0, 1, 2, z, var}});
  // THEN both agents' beliefs equal the dense joint of (x_0, x_1, x_2, ε) conditioned on z; the anchor is unchanged
  VecX m(10);
  m << priors[0].m, priors[1].m, priors[2].m, 0.0;
  MatX V = MatX::Zero(10, 10);
  V.block<3, 3>(0, 0) = priors[0].V;
  V.block<3, 3>(3, 3) = priors[1].V;
  V(9, 9) = var;
  Eigen::RowVectorXd L(10);
  // by segments: GCC 12 reads a comma-initialized 3-vector with a 4-wide AVX load (a -Warray-bounds false positive)
  L.segment<3>(0) = lin.B12();
  L.segment<3>(3) = -lin.B1;
  L.segment<3>(6) = lin.B2;
  L(9) = 1.0;
  for (int which = 0; which < 2; ++which) {
    SCOPED_TRACE("agent " + std::to_string(which));
    MatX T = MatX::Zero(4, 10);
    T.block<3, 3>(0, 3 * which).setIdentity();
    T.row(3) = L;
    VecX mt = T * m;
    mt(3) += lin.D;
    const Moments brute = condition(mt, T * V * T.transpose(), 3, VecX::Constant(1, z));
    EXPECT_LT(maxAbsDifference(post[which], brute), 1e-9);
  }
  EXPECT_LT(maxAbs(post[2].m - priors[2].m), 1e-15);
  EXPECT_LT(maxAbs(post[2].V), 1e-15);
}

TEST(Cooperative, TwoUncertainAgentsMeasuringEachOtherBothImprove) {
  double err_prior[2] = {0, 0}, err_post[2] = {0, 0};
  const int kTrials = 200;
  for (int trial = 0; trial < kTrials; ++trial) {
    const unsigned seed = 1000 + trial;
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN two agents (0, 1) with 0.5 m prior uncertainty and four surveyed anchors (2…5); each agent receives
    //       TDoAs between the other agent and every anchor (they measure each other), σ = 5 cm
    std::mt19937 rng(seed);
    const std::vector<Vec3> truth{Vec3(0.5, -0.3, 1.2), Vec3(-0.8, 0.9, 1.6), Vec3(4, 4, 0.2), Vec3(-4, 4, 2.8),
                                  Vec3(-4, -4, 0.2), Vec3(4, -4, 2.8)};
    std::vector<Moments3> priors(6);
    const double sigma0 = 0.5, sigma_z = 0.05;
    for (int a = 0; a < 2; ++a) priors[a] = {truth[a] + Vec3(randomVector(rng, 3, sigma0)), Mat3::Identity() * sigma0 * sigma0};
    for (int a = 2; a < 6; ++a) priors[a] = {truth[a], Mat3::Zero()};
    std::vector<CooperativeTdoa> meas;
    for (int a = 2; a < 6; ++a) {
      meas.push_back({0, 1, a, tdoa(truth[0], truth[1], truth[a]) + randomVector(rng, 1, sigma_z)[0], sigma_z * sigma_z});
      meas.push_back({1, 0, a, tdoa(truth[1], truth[0], truth[a]) + randomVector(rng, 1, sigma_z)[0], sigma_z * sigma_z});
    }
    // WHEN the agents exchange messages for a few rounds (loopy Gaussian BP, relinearized each round)
    const auto post = cooperativeTdoaUpdate(priors, meas, 5);
    // THEN each agent's covariance shrank (in the Loewner order, checked along the trace) and stays PD
    for (int a = 0; a < 2; ++a) {
      EXPECT_LT(post[a].V.trace(), priors[a].V.trace());
      EXPECT_EQ(Eigen::LLT<Mat3>(post[a].V).info(), Eigen::Success);
      err_prior[a] += (priors[a].m - truth[a]).squaredNorm();
      err_post[a] += (post[a].m - truth[a]).squaredNorm();
    }
  }
  // AND both agents' RMS position error improves clearly over their priors
  for (int a = 0; a < 2; ++a) {
    SCOPED_TRACE("agent " + std::to_string(a));
    const double rms_prior = std::sqrt(err_prior[a] / kTrials), rms_post = std::sqrt(err_post[a] / kTrials);
    EXPECT_LT(rms_post, 0.7 * rms_prior) << rms_post << " vs " << rms_prior;
    RecordProperty("rms_prior_m_agent" + std::to_string(a), std::to_string(rms_prior));
    RecordProperty("rms_post_m_agent" + std::to_string(a), std::to_string(rms_post));
  }
}

TEST(Cooperative, BadIndicesThrow) {
  // GIVEN two variables, WHEN a measurement refers to a third or repeats one, THEN std::invalid_argument
  const std::vector<Moments3> priors(2, Moments3{Vec3::Zero(), Mat3::Identity()});
  EXPECT_THROW(cooperativeTdoaUpdate(priors, {{0, 1, 2, 0.0, 0.1}}), std::invalid_argument);
  EXPECT_THROW(cooperativeTdoaUpdate(priors, {{0, 1, 1, 0.0, 0.1}}), std::invalid_argument);
}

}  // namespace
}  // namespace uwb
