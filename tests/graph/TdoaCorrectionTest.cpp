/** @file TdoaCorrectionTest.cpp
 *  @brief The correction step of paper Fig. 3 (docs/math/message-passing.md G15–G18) equals the textbook EKF update
 *         in Joseph form; the fixed-size fast path equals the generic message-passing route.
 */
#include "uwb/graph/TdoaCorrection.h"

#include <gtest/gtest.h>

#include "GraphTestUtil.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

using namespace graphtest;

constexpr int kN = 15;
enum StateBlock : int { kPos = 0, kVel = 3, kAtt = 6, kAccBias = 9, kGyroBias = 12 };
using VecN = Eigen::Matrix<double, kN, 1>;
using MatN = Eigen::Matrix<double, kN, kN>;
using Mat3N = Eigen::Matrix<double, 3, kN>;

struct FilterScene {
  Vec3 w_p_b;
  Quat w_q_b;
  Vec3 b_t_tag;
  Moments3 anchor_a, anchor_b;
  double z_m, var_m2;
  VecN m;
  MatN P;
};

FilterScene randomFilterScene(unsigned seed) {
  std::mt19937 rng(seed);
  FilterScene s;
  s.w_p_b = Vec3(randomVector(rng, 3)) + Vec3(0, 0, 1.5);
  s.w_q_b = Quat(Eigen::AngleAxisd(randomVector(rng, 1)[0], Vec3(randomVector(rng, 3)).normalized()));
  s.b_t_tag = Vec3(randomVector(rng, 3, 0.1));
  s.anchor_a = {Vec3(randomVector(rng, 3) + Vec3(4, -3, 0.5)), Mat3(randomSpd(rng, 3, 0.01) * 1e-3)};
  s.anchor_b = {Vec3(randomVector(rng, 3) + Vec3(-4, 3, 2.5)), Mat3(randomSpd(rng, 3, 0.01) * 1e-3)};
  s.var_m2 = 0.01 + 0.05 * std::abs(randomVector(rng, 1)[0]);
  s.m = VecN(randomVector(rng, kN, 0.05));  // a non-zero prior mean of the error state, for generality
  s.P = MatN(randomSpd(rng, kN, 0.01) * 0.1);
  s.P = (0.5 * (s.P + s.P.transpose())).eval();  // the filter keeps P exactly symmetric
  const Vec3 p_tag = tagPosition(s.w_p_b, s.w_q_b, s.b_t_tag);
  s.z_m = (p_tag - s.anchor_b.m).norm() - (p_tag - s.anchor_a.m).norm() + randomVector(rng, 1, 0.2)[0];
  return s;
}

/// C = ∂x_k/∂δx = [I, 0, −R [b_t]×, 0, 0] for the right attitude error.
Mat3N tagJacobian(const FilterScene& s) {
  Mat3N C = Mat3N::Zero();
  C.block<3, 3>(0, kPos) = Mat3::Identity();
  C.block<3, 3>(0, kAtt) = tagPositionJacobianAttitude(s.w_q_b, s.b_t_tag);
  return C;
}

TdoaNodeMessages nodeMessages(const FilterScene& s, Vec3* p_tag_out) {
  const Vec3 p_tag = tagPosition(s.w_p_b, s.w_q_b, s.b_t_tag);
  *p_tag_out = p_tag;
  const auto lin = linearizeTdoa(p_tag, s.anchor_b.m, s.anchor_a.m);  // UTIL: x_i = B, x_j = A
  EXPECT_TRUE(lin);
  return tdoaNodeForward(*lin, s.anchor_b, s.anchor_a, s.z_m, s.var_m2);
}

/// A random scene (randomFilterScene) with its tag position and the TDoA node's messages (nodeMessages).
struct SceneMessages {
  FilterScene s;
  Vec3 p_tag;
  TdoaNodeMessages msg;
};

SceneMessages sceneMessages(unsigned seed) {
  SceneMessages r{randomFilterScene(seed), Vec3::Zero(), {}};
  r.msg = nodeMessages(r.s, &r.p_tag);
  return r;
}

TEST(TdoaCorrection, EqualsTextbookEkfJosephUpdate) {
  for (unsigned seed = 1; seed <= 50; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN a random 15-dim error-state prior, pose, lever arm, uncertain anchors and a TDoA
    const auto [s, p_tag, msg] = sceneMessages(seed);
    // WHEN we run the graph correction (Fig. 3)
    const auto graph = correctTdoa<kN>(GaussianMoments<kN>{s.m, s.P}, tagJacobian(s), p_tag, msg);
    ASSERT_TRUE(graph);
    // AND the textbook EKF: H from the model Jacobians, R = Σ6 + anchor contributions, Joseph form
    TdoaModelParams params;
    params.b_t_tag = s.b_t_tag;
    TdoaJacobians J;
    const auto h = evaluateTdoa(s.w_p_b, s.w_q_b, s.anchor_a.m, s.anchor_b.m, params, &J);
    ASSERT_TRUE(h);
    Eigen::Matrix<double, 1, kN> H = Eigen::Matrix<double, 1, kN>::Zero();
    H.block<1, 3>(0, kPos) = J.J_z_p_b;
    H.block<1, 3>(0, kAtt) = J.J_z_dtheta;
    const double R = s.var_m2 + (J.J_z_anchor_a * s.anchor_a.V * J.J_z_anchor_a.transpose())(0, 0) +
                     (J.J_z_anchor_b * s.anchor_b.V * J.J_z_anchor_b.transpose())(0, 0);
    const double r = s.z_m - *h - H.dot(s.m);
    const double S = (H * s.P * H.transpose())(0, 0) + R;
    const VecN K = s.P * H.transpose() / S;
    const MatN IKH = MatN::Identity() - K * H;
    const VecN m_ekf = s.m + K * r;
    const MatN P_ekf = IKH * s.P * IKH.transpose() + K * R * K.transpose();
    // THEN posterior, innovation, its variance and NIS agree to 1e-9
    EXPECT_LT(maxAbs(graph->posterior.m - m_ekf), 1e-9);
    EXPECT_LT(maxAbs(graph->posterior.V - P_ekf), 1e-9);
    EXPECT_NEAR(graph->stats.innovation_m, r, 1e-9);
    EXPECT_NEAR(graph->stats.innovation_var_m2, S, 1e-9);
    EXPECT_NEAR(graph->stats.nis, r * r / S, 1e-9);
    EXPECT_EQ(graph->posterior.V, graph->posterior.V.transpose());  // exactly symmetric
  }
}

TEST(TdoaCorrection, FastPathEqualsGenericMessagePassing) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN a random scene
    const auto [s, p_tag, msg] = sceneMessages(seed);
    const Mat3N C = tagJacobian(s);
    // WHEN we correct with the fixed-size fast path, the dynamic-size instantiation, and the generic node route
    //      (ξ8, W8 → G9' → G7 → G4, information form with singular W)
    const auto fast = correctTdoa<kN>(GaussianMoments<kN>{s.m, s.P}, C, p_tag, msg);
    const auto dyn = correctTdoa<Eigen::Dynamic>(Moments{s.m, s.P}, MatX(C), p_tag, msg);
    const auto generic = correctTdoaByMessages(Moments{s.m, s.P}, C, p_tag, msg);
    ASSERT_TRUE(fast && dyn && generic);
    // THEN all agree
    EXPECT_LT(maxAbsDifference(fast->posterior, *generic), 1e-9);
    EXPECT_LT(maxAbsDifference(fast->posterior, dyn->posterior), 1e-12);
  }
}

TEST(TdoaCorrection, InnovationBeforeUpdateMatchesUpdateStats) {
  // GIVEN a scene and its rank-one message on the state
  const auto [s, p_tag, msg] = sceneMessages(7);
  const ScalarLinearMessage<kN> on_state = tdoaMessageOnState<kN>(msg, tagJacobian(s), p_tag);
  // WHEN we compute the innovation for gating and then apply the update in place
  const InnovationStats before = innovationOf<kN>(on_state, s.m, s.P);
  VecN m = s.m;
  MatN P = s.P;
  const auto after = equalityRankOneInPlace<kN>(m, P, on_state);
  // THEN both report the same statistics, and the information view of the message is ξ = aᵀy/var, W = aᵀa/var
  ASSERT_TRUE(after);
  EXPECT_DOUBLE_EQ(before.innovation_m, after->innovation_m);
  EXPECT_NEAR(before.innovation_var_m2, after->innovation_var_m2, 1e-14);
  const GaussianInformation<kN> info = on_state.information();
  EXPECT_LT(maxAbs(info.W - on_state.a.transpose() * on_state.a / on_state.var), 1e-15);
}

TEST(TdoaCorrection, ZeroErrorStateInnovationIsMeasuredMinusPredictedTdoa) {
  // GIVEN a zero error-state mean (as in the filter)
  FilterScene s = randomFilterScene(9);
  s.m.setZero();
  Vec3 p_tag;
  const TdoaNodeMessages msg = nodeMessages(s, &p_tag);
  // WHEN we compute the innovation
  const InnovationStats st = innovationOf<kN>(tdoaMessageOnState<kN>(msg, tagJacobian(s), p_tag), s.m, s.P);
  // THEN r = z − ẑ(x̃) exactly (G16)
  EXPECT_NEAR(st.innovation_m, s.z_m - predictTdoa(s.w_p_b, s.w_q_b, s.b_t_tag, s.anchor_a.m, s.anchor_b.m), 1e-12);
}

TEST(TdoaCorrection, ExactPriorAndExactMessageIsRefusedUntouched) {
  // GIVEN a zero prior covariance and a zero-variance rank-one message (S = 0)
  VecN m = VecN::Constant(0.1);
  MatN P = MatN::Zero();
  ScalarLinearMessage<kN> msg;
  msg.a = Eigen::Matrix<double, 1, kN>::Unit(kPos);
  msg.y = 1.0;
  msg.var = 0.0;
  // WHEN we try to update
  const auto st = equalityRankOneInPlace<kN>(m, P, msg);
  // THEN the update is refused and the state is unchanged (no NaN escapes)
  EXPECT_FALSE(st);
  EXPECT_EQ(m, VecN::Constant(0.1));
  EXPECT_EQ(P, MatN::Zero());
}

TEST(TdoaCorrection, UpdateReducesVarianceAlongTheMeasurement) {
  // GIVEN a scene
  const auto [s, p_tag, msg] = sceneMessages(12);
  const auto post = correctTdoa<kN>(GaussianMoments<kN>{s.m, s.P}, tagJacobian(s), p_tag, msg);
  ASSERT_TRUE(post);
  // WHEN we look at the variance along a = B12 C, THEN it shrank, and the posterior stays PD
  const Eigen::Matrix<double, 1, kN> a = msg.B12 * tagJacobian(s);
  EXPECT_LT(a * post->posterior.V * a.transpose(), a * s.P * a.transpose());
  EXPECT_EQ(Eigen::LLT<MatN>(post->posterior.V).info(), Eigen::Success);
}

}  // namespace
}  // namespace uwb
