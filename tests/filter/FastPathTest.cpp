/** @file FastPathTest.cpp
 *  @brief The structure-exploiting fast paths of the filter against their dense references:
 *         Taylor-series SO(3) Exp and right Jacobian (F6, F8), column-block covariance fold (F7), the TDoA message
 *         built from C's two blocks (G16), and the two-block equality node (G18); the filter's part of the TDoA node
 *         (G11–G12), its attitude row without C, and the equality node given the gate's P aᵀ.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "support/TestSupport.h"
#include "uwb/filter/Ekf.h"
#include "uwb/filter/QuadImuProcess.h"
#include "uwb/filter/TdoaUpdate.h"
#include "uwb/graph/TdoaCorrection.h"
#include "uwb/graph/TdoaNode.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

/// Reference Exp(φ) with sin/cos (the closed form, F8).
Quat expQuatClosedForm(const Vec3& phi) {
  const double angle = phi.norm();
  const double s = std::sin(0.5 * angle) / angle;
  return Quat(std::cos(0.5 * angle), s * phi.x(), s * phi.y(), s * phi.z());
}

/// Reference J_r(φ) with sin/cos (F6).
Mat3 rightJacobianClosedForm(const Vec3& phi) {
  const double theta = phi.norm();
  const Mat3 S = skew(phi);
  return Mat3::Identity() - (1.0 - std::cos(theta)) / (theta * theta) * S +
         (theta - std::sin(theta)) / (theta * theta * theta) * S * S;
}

TEST(So3Series, ExpEqualsClosedFormToRounding) {
  // GIVEN rotation vectors on both sides of the series threshold (0.1 rad), down to 1e-6 rad
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  for (double angle : {1e-6, 1e-4, 1e-2, 0.05, 0.0999, 0.1001, 0.5}) {
    SCOPED_TRACE("angle " + std::to_string(angle));
    const Vec3 phi = angle * Vec3(n(rng), n(rng), n(rng)).normalized();
    // WHEN evaluating Exp with the filter's implementation and with sin/cos
    const Quat q = expQuat(phi), q_ref = expQuatClosedForm(phi);
    // THEN they agree to a few ulp and the quaternion is unit
    EXPECT_LT((q.coeffs() - q_ref.coeffs()).cwiseAbs().maxCoeff(), 4e-16);
    EXPECT_NEAR(q.norm(), 1.0, 4e-16);
  }
}

TEST(So3Series, RightJacobianMatchesClosedFormAndCentralDifferences) {
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  for (double angle : {1e-3, 0.03, 0.0999, 0.1001, 0.7}) {
    SCOPED_TRACE("angle " + std::to_string(angle));
    // GIVEN a rotation vector (series branch below 0.1 rad, closed form above)
    const Vec3 phi = angle * Vec3(n(rng), n(rng), n(rng)).normalized();
    // WHEN evaluating J_r analytically and by central differences of Exp(φ)⁻¹ Exp(φ + δ) ≈ Exp(J_r δ)
    const Mat3 J = rightJacobianSo3(phi);
    const auto f = [&](const VecX& d) -> VecX { return logQuat(expQuat(phi).conjugate() * expQuat(phi + Vec3(d))); };
    const test::JacobianCheck c = test::checkJacobian(f, VecX::Zero(3), J);
    // THEN both agree, and the series agrees with the closed form (whose 1 − cos θ cancels: ~1e-16/θ² relative)
    EXPECT_LT(c.max_abs_error, 1e-8) << c;
    EXPECT_LT((J - rightJacobianClosedForm(phi)).cwiseAbs().maxCoeff(), 1e-15 / (angle * angle) + 1e-15);
  }
}

TEST(CovarianceFold, ColumnBlockProductEqualsDenseProduct) {
  // GIVEN an accumulated transition of random IMU steps and a random matrix M
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  AccumulatedTransition phi;
  NavState x;
  x.w_q_b = Quat(Eigen::AngleAxisd(0.4, Vec3(0.2, -0.5, 1.0).normalized()));
  for (int k = 0; k < 4; ++k) {
    ImuReading imu;
    imu.b_acc_mps2 = Vec3(n(rng), n(rng), kGravity_mps2 + n(rng));
    imu.b_gyro_radps = Vec3(n(rng), n(rng), n(rng));
    // the thrust model with rotor drag on every other step (F2a: diagonal F_pv, F_vv)
    const ProcessStep step = k % 2 == 0 ? quadImuProcess(x, imu, 0.003, AccelModel::kFull)
                                        : quadImuProcess(x, imu, 0.05, AccelModel::kThrustOnly, 0.8);
    phi.accumulate(step.J);
    x = step.next;
  }
  const ErrMat M = ErrMat::Random();
  // WHEN multiplying by Φᵀ on the right with the column-block form (F7)
  const ErrMat fast = phi.rightMultiplyTransposed(M);
  // THEN it equals the dense M Φᵀ and the row form (Φ Mᵀ)ᵀ
  const ErrMat dense = M * phi.dense().transpose();
  EXPECT_LT((fast - dense).cwiseAbs().maxCoeff(), 1e-13 * dense.cwiseAbs().maxCoeff());
  EXPECT_LT((fast - phi.leftMultiply(M.transpose()).transpose()).cwiseAbs().maxCoeff(),
            1e-13 * dense.cwiseAbs().maxCoeff());
}

/// A random SPD 15×15 covariance.
ErrMat randomCovariance(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  ErrMat L;
  for (int i = 0; i < kDim; ++i)
    for (int j = 0; j < kDim; ++j) L(i, j) = 0.1 * n(rng);
  const ErrMat P = L * L.transpose() + 0.01 * ErrMat::Identity();
  return 0.5 * (P + P.transpose());
}

TEST(TdoaFastPath, MessageFromTwoBlocksEqualsDenseC) {
  // GIVEN a pose, two anchors and the TDoA node's forward pass
  NavState x;
  x.w_p_b = Vec3(0.4, -0.7, 1.2);
  x.w_q_b = Quat(Eigen::AngleAxisd(0.5, Vec3(0.3, 0.2, 1.0).normalized()));
  const Moments3 anchor_a{Vec3(-3.0, -4.0, 0.2), Mat3::Zero()}, anchor_b{Vec3(3.5, 4.0, 2.8), Mat3::Zero()};
  const Vec3 w_p_tag = tagPosition(x.w_p_b, x.w_q_b, kUtilTagOffset_b);
  const TdoaLinearization lin = *linearizeTdoa(w_p_tag, anchor_b.m, anchor_a.m);
  const TdoaNodeMessages node = tdoaNodeForward(lin, anchor_b, anchor_a, 1.3, 0.1);
  // WHEN building the message on δx from C's blocks and from the dense C = [I 0 −R[b_t]× 0 0] (G16)
  const Mat3 J_tag_att = tagPositionJacobianAttitude(x.w_q_b, kUtilTagOffset_b);
  const ScalarLinearMessage<kDim> fast = tdoaMessageOnPositionAttitude(node, J_tag_att, w_p_tag);
  Eigen::Matrix<double, 3, kDim> C = Eigen::Matrix<double, 3, kDim>::Zero();
  C.block<3, 3>(0, kPos).setIdentity();
  C.block<3, 3>(0, kAtt) = J_tag_att;
  const ScalarLinearMessage<kDim> dense = tdoaMessageOnState<kDim>(node, C, w_p_tag);
  // THEN they are the same message, zero outside δp and δθ
  EXPECT_LT((fast.a - dense.a).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_DOUBLE_EQ(fast.y, dense.y);
  EXPECT_DOUBLE_EQ(fast.var, dense.var);
  EXPECT_EQ(fast.a.segment<3>(kVel).squaredNorm() + fast.a.segment<6>(kAccBias).squaredNorm(), 0.0);
}

TEST(TdoaFastPath, TwoBlockEqualityNodeEqualsDenseEqualityNode) {
  for (int seed : {1, 2, 3}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    // GIVEN a random prior N(m, P) and a message whose row is non-zero only on δp and δθ
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, 1.0);
    ErrVec m;
    for (int i = 0; i < kDim; ++i) m(i) = 0.1 * n(rng);
    const ErrMat P = randomCovariance(rng);
    ScalarLinearMessage<kDim> msg;
    msg.a.setZero();
    msg.a.segment<3>(kPos) = Vec3(n(rng), n(rng), n(rng)).transpose();
    msg.a.segment<3>(kAtt) = 0.1 * Vec3(n(rng), n(rng), n(rng)).transpose();
    msg.y = 0.3 * n(rng);
    msg.var = 0.04;
    // WHEN applying the dense and the two-block equality node (G18)
    ErrVec m_dense = m, m_fast = m;
    ErrMat P_dense = P, P_fast = P;
    const auto st_dense = equalityRankOneInPlace<kDim>(m_dense, P_dense, msg);
    const auto st_fast = equalityRankOneTwoBlocksInPlace<kDim>(m_fast, P_fast, msg, kPos, kAtt);
    // THEN the posteriors and statistics agree to rounding, and P stays exactly symmetric
    ASSERT_TRUE(st_dense && st_fast);
    EXPECT_NEAR(st_fast->innovation_m, st_dense->innovation_m, 1e-15);
    EXPECT_NEAR(st_fast->innovation_var_m2, st_dense->innovation_var_m2, 1e-15);
    EXPECT_LT((m_fast - m_dense).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LT((P_fast - P_dense).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_EQ((P_fast - P_fast.transpose()).cwiseAbs().maxCoeff(), 0.0);
  }
}

TEST(TdoaFastPath, TwoBlockEqualityNodeRefusesExactPriorAndMessage) {
  // GIVEN a prior with zero variance along the message and an exact message
  ErrVec m = ErrVec::Zero();
  ErrMat P = ErrMat::Identity();
  P.block<3, 3>(kPos, kPos).setZero();
  P.block<3, 3>(kAtt, kAtt).setZero();
  ScalarLinearMessage<kDim> msg;
  msg.a.setZero();
  msg.a(kPos) = 1.0;
  msg.var = 0.0;
  const ErrMat P0 = P;
  // WHEN applying the two-block equality node, THEN it refuses and leaves the prior untouched (S = 0)
  EXPECT_FALSE(equalityRankOneTwoBlocksInPlace<kDim>(m, P, msg, kPos, kAtt));
  EXPECT_EQ((P - P0).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(m.norm(), 0.0);
}

TEST(TdoaFastPath, NodeForwardToTagEqualsFullForwardPass) {
  for (double anchor_sigma : {0.0, 0.05}) {
    SCOPED_TRACE("anchor sigma " + std::to_string(anchor_sigma));
    // GIVEN a linearization at a tag position and two anchors, exact or uncertain
    const Moments3 anchor_a{Vec3(-3.0, -4.0, 0.2), Mat3::Identity() * anchor_sigma * anchor_sigma};
    const Moments3 anchor_b{Vec3(3.5, 4.0, 2.8), Mat3::Identity() * 2.0 * anchor_sigma * anchor_sigma};
    const TdoaLinearization lin = *linearizeTdoa(Vec3(0.4, -0.7, 1.2), anchor_b.m, anchor_a.m);
    // WHEN running the full forward pass (G11–G13) and the filter's part of it
    const TdoaNodeMessages full = tdoaNodeForward(lin, anchor_b, anchor_a, 1.3, 0.1);
    const TdoaNodeMessages tag = tdoaNodeForwardToTag(lin, anchor_b, anchor_a, 1.3, 0.1);
    // THEN µ3, µ4, µ7 and B12 are the same (the anchor terms are exactly 0 for exact anchors)
    EXPECT_NEAR(tag.mu3.m, full.mu3.m, 1e-15);
    EXPECT_NEAR(tag.mu4.m, full.mu4.m, 1e-15);
    EXPECT_NEAR(tag.mu3.V, full.mu3.V, 1e-18);
    EXPECT_NEAR(tag.mu4.V, full.mu4.V, 1e-18);
    EXPECT_NEAR(tag.mu7.m, full.mu7.m, 1e-15);
    EXPECT_NEAR(tag.mu7.V, full.mu7.V, 1e-17);
    EXPECT_EQ(tag.B12, full.B12);
    if (anchor_sigma == 0.0) {
      EXPECT_EQ(tag.mu7.V, 0.1);
    } else {
      EXPECT_GT(tag.mu7.V, 0.1);
    }
  }
  EXPECT_THROW(tdoaNodeForwardToTag(TdoaLinearization{}, Moments3{}, Moments3{}, 0.0, 0.0), std::invalid_argument);
}

TEST(TdoaFastPath, MessageAttitudeRowEqualsJacobianProduct) {
  // GIVEN a tilted pose and two exact anchors
  AnchorTable anchors;
  anchors.set(0, Vec3(-3.0, -4.0, 0.2));
  anchors.set(1, Vec3(3.5, 4.0, 2.8));
  NavState x;
  x.w_p_b = Vec3(0.4, -0.7, 1.2);
  x.w_q_b = Quat(Eigen::AngleAxisd(0.5, Vec3(0.3, 0.2, 1.0).normalized()));
  // WHEN building the filter's TDoA message and the reference from the node and J_tag_att = −R[b_t]× (G16, M4)
  const std::optional<ScalarLinearMessage<kDim>> msg =
      tdoaMessage(x, anchors, TdoaMeasurement{0.0, 0, 1, 1.3}, 1.3, 0.1, kUtilTagOffset_b);
  const Vec3 w_p_tag = tagPosition(x.w_p_b, x.w_q_b, kUtilTagOffset_b);
  const TdoaLinearization lin = *linearizeTdoa(w_p_tag, anchors.find(1)->m, anchors.find(0)->m);
  const ScalarLinearMessage<kDim> ref = tdoaMessageOnPositionAttitude(
      tdoaNodeForward(lin, *anchors.find(1), *anchors.find(0), 1.3, 0.1),
      tagPositionJacobianAttitude(x.w_q_b, kUtilTagOffset_b), w_p_tag);
  // THEN they agree to rounding
  ASSERT_TRUE(msg);
  EXPECT_LT((msg->a - ref.a).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_NEAR(msg->y, ref.y, 1e-14);
  EXPECT_DOUBLE_EQ(msg->var, ref.var);
}

TEST(TdoaFastPath, EqualityNodeWithCallersPaEqualsTwoBlockNode) {
  // GIVEN a filter with a random covariance and a position/attitude message
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  Ekf a(EkfParams{}), b(EkfParams{});
  NavState x;
  x.w_p_b = Vec3(0.3, -0.2, 1.5);
  const ErrMat P = randomCovariance(rng);
  a.initialize(x, P);
  b.initialize(x, P);
  ScalarLinearMessage<kDim> msg;
  msg.a.setZero();
  msg.a.segment<3>(kPos) = Vec3(n(rng), n(rng), n(rng)).transpose();
  msg.a.segment<3>(kAtt) = 0.1 * Vec3(n(rng), n(rng), n(rng)).transpose();
  msg.y = 0.2;
  msg.var = 0.04;
  // WHEN one update forms P aᵀ itself and the other is given P aᵀ and a P aᵀ (as updateTdoa does for its gate)
  const ErrVec P_a = a.covariance() * msg.a.transpose();
  const auto st_a = a.correctPositionAttitude(msg, P_a, msg.a.dot(P_a));
  const auto st_b = b.correctPositionAttitude(msg);
  // THEN the posteriors agree to rounding
  ASSERT_TRUE(st_a && st_b);
  EXPECT_NEAR(st_a->innovation_var_m2, st_b->innovation_var_m2, 1e-14);
  EXPECT_LT((a.covariance() - b.covariance()).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((a.state().w_p_b - b.state().w_p_b).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_EQ((a.covariance() - a.covariance().transpose()).cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace uwb
