/** @file TdoaUpdate.cpp
 *  @brief TDoA correction through the graph's TDoA node and equality node (paper III-A, Fig. 2–3);
 *         docs/math/filter.md F10–F13.
 */
#include "uwb/filter/TdoaUpdate.h"

#include <cmath>
#include <stdexcept>

#include "uwb/filter/QuadImuProcess.h"
#include "uwb/model/TdoaLinearization.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {

void AnchorTable::set(int id, const Vec3& w_p, double sigma_m) {
  if (id < 0 || id > 4095) throw std::invalid_argument("AnchorTable::set: anchor id must be in [0, 4095]");
  if (static_cast<int>(anchors_.size()) <= id) {
    anchors_.resize(id + 1);
    known_.resize(id + 1, 0);
  }
  anchors_[id].m = w_p;
  anchors_[id].V = Mat3::Identity() * (sigma_m * sigma_m);
  known_[id] = 1;
}

AnchorBox anchorBox(const AnchorTable& anchors) {
  const std::vector<int> ids = anchors.ids();
  if (ids.empty()) throw std::invalid_argument("anchorBox: no anchors");
  AnchorBox box{Vec3::Constant(1e300), Vec3::Constant(-1e300), Vec3::Zero()};
  for (int id : ids) {
    const Vec3& a = anchors.find(id)->m;
    box.min = box.min.cwiseMin(a);
    box.max = box.max.cwiseMax(a);
    box.centroid += a;
  }
  box.centroid /= static_cast<double>(ids.size());
  return box;
}

std::vector<int> AnchorTable::ids() const {
  std::vector<int> out;
  for (std::size_t i = 0; i < known_.size(); ++i)
    if (known_[i]) out.push_back(static_cast<int>(i));
  return out;
}

std::size_t AnchorTable::size() const { return ids().size(); }

ScalarLinearMessage<kDim> tdoaMessageOnPositionAttitude(const TdoaNodeMessages& node, const Mat3& J_tag_att,
                                                        const Vec3& w_p_tag) {
  // (G16) a = B12 C, y = m7 − B12 x̃_k, var = Σ7, with the structure of C = [I 0 J_tag_att 0 0] used directly:
  // a_p = B12 I = B12, a_θ = B12 J_tag_att, and every other entry of a is zero (no 3×15 C, no 1×3·3×15 product).
  ScalarLinearMessage<kDim> out;
  out.a.setZero();
  out.a.segment<3>(kPos) = node.B12;
  out.a.segment<3>(kAtt).noalias() = node.B12 * J_tag_att;
  out.y = node.mu7.m - node.B12.dot(w_p_tag);
  out.var = node.mu7.V;
  return out;
}

namespace {

/// tdoaMessage for anchors already looked up (ids z.id_a, z.id_b; updateTdoa needs them anyway).
std::optional<ScalarLinearMessage<kDim>> tdoaMessageFromAnchors(const NavState& x, const Moments3* anchor_a,
                                                                const Moments3* anchor_b, double z_corrected_m,
                                                                double var_m2, const Vec3& b_t_tag) {
  // (F10) linearise at the tag position x̃_k = p + R b_t; UTIL convention ⇒ x_i = anchor B, x_j = anchor A.
  // One rotation matrix serves the tag position (M2) and its attitude Jacobian −R[b_t]× (M4).
  const Mat3 w_R_b = x.w_q_b.toRotationMatrix();
  const Vec3 w_p_tag = x.w_p_b + w_R_b * b_t_tag;
  const std::optional<TdoaLinearization> lin = linearizeTdoa(w_p_tag, anchor_b->m, anchor_a->m);
  if (!lin) return std::nullopt;
  // Paper Fig. 2: the TDoA node's forward pass (G11–G12; the filter needs µ7 and B12 only) …
  const TdoaNodeMessages node = tdoaNodeForwardToTag(*lin, *anchor_b, *anchor_a, z_corrected_m, var_m2);
  // … and the message on δx through x_k = x̃_k + C δx, C = [I 0 −R[b_t]× 0 0] (G16; model M4), as in
  // tdoaMessageOnPositionAttitude but without forming C's attitude block: a_θ = −B12 R [b_t]× = (b_t × Rᵀ B12ᵀ)ᵀ.
  ScalarLinearMessage<kDim> out;
  out.a.setZero();
  out.a.segment<3>(kPos) = node.B12;
  const Vec3 R_B12 = w_R_b.transpose() * node.B12.transpose();
  out.a.segment<3>(kAtt) = b_t_tag.cross(R_B12).transpose();
  out.y = node.mu7.m - node.B12.dot(w_p_tag);
  out.var = node.mu7.V;
  return out;
}

}  // namespace

std::optional<ScalarLinearMessage<kDim>> tdoaMessage(const NavState& x, const AnchorTable& anchors,
                                                     const TdoaMeasurement& z, double z_corrected_m, double var_m2,
                                                     const Vec3& b_t_tag) {
  const Moments3* anchor_a = anchors.find(z.id_a);
  const Moments3* anchor_b = anchors.find(z.id_b);
  if (!anchor_a || !anchor_b) return std::nullopt;
  return tdoaMessageFromAnchors(x, anchor_a, anchor_b, z_corrected_m, var_m2, b_t_tag);
}

Eigen::Matrix<double, 1, 6> biasPoseJacobian(const BiasPredictor& bias, const NavState& x, int id_a, int id_b,
                                             const Vec3& w_p_anchor_a, const Vec3& w_p_anchor_b) {
  // (P47) the correction as a function of the error state: µ(x̂ ⊞ δx), δx = (δp, δθ)
  constexpr double kStepPos_m = 1e-4, kStepAtt_rad = 1e-4;
  Eigen::Matrix<double, 1, 6> g = Eigen::Matrix<double, 1, 6>::Zero();
  for (int k = 0; k < 6; ++k) {
    double mu[2];
    const double h = k < 3 ? kStepPos_m : kStepAtt_rad;
    for (int s = 0; s < 2; ++s) {
      const double d = s == 0 ? h : -h;
      Vec3 p = x.w_p_b;
      Quat q = x.w_q_b;
      if (k < 3)
        p(k) += d;
      else
        q = (q * expQuat(Vec3::Unit(k - 3) * d)).normalized();
      mu[s] = bias(makeTdoaFeature(id_a, id_b, p, q, w_p_anchor_a, w_p_anchor_b)).mean_m;
    }
    if (!std::isfinite(mu[0]) || !std::isfinite(mu[1])) return Eigen::Matrix<double, 1, 6>::Zero();
    g(k) = (mu[0] - mu[1]) / (2.0 * h);
  }
  return g;
}

namespace {

/// The measurement after the bias model's correction (F12, gp.md P45) and the row of ∂µ/∂δx it carries (P47).
struct BiasCorrectedTdoa {
  double z_m = 0.0;
  double var_m2 = 0.0;
  double bias_mean_m = 0.0;
  Eigen::Matrix<double, 1, 6> bias_row = Eigen::Matrix<double, 1, 6>::Zero();  ///< zero unless kJacobian applies
};

BiasCorrectedTdoa correctBias(const Ekf& ekf, const TdoaMeasurement& z, const Vec3& w_p_anchor_a,
                              const Vec3& w_p_anchor_b, const TdoaUpdateOptions& options, const BiasPredictor* bias) {
  const NavState& x = ekf.state();
  // (F12) bias correction from the predictor, evaluated at the filter's current estimate (paper III-B).
  BiasCorrectedTdoa c;
  c.z_m = z.tdoa_m;
  c.var_m2 = options.sigma_m * options.sigma_m;
  if (!bias || !*bias) return c;
  // (P47) before the nominal prediction: a predictor may keep the last prediction's state (F25)
  const bool bias_pose = options.bias_pose != BiasPoseUncertainty::kNone;
  if (bias_pose) c.bias_row = biasPoseJacobian(*bias, x, z.id_a, z.id_b, w_p_anchor_a, w_p_anchor_b);
  const BiasPrediction b = (*bias)(makeTdoaFeature(z.id_a, z.id_b, x.w_p_b, x.w_q_b, w_p_anchor_a, w_p_anchor_b));
  if (!(std::isfinite(b.mean_m) && std::isfinite(b.variance_m2) && b.variance_m2 >= 0.0 &&
        std::isfinite(b.noise_scale) && b.noise_scale > 0.0)) {
    c.bias_row.setZero();
    return c;
  }
  c.z_m -= b.mean_m;
  c.var_m2 = c.var_m2 * b.noise_scale + b.variance_m2;  // docs/math/gp.md (P45); noise_scale = 1: R + var_f
  c.bias_mean_m = b.mean_m;
  if (bias_pose && options.bias_pose == BiasPoseUncertainty::kVariance) {
    // (P47a) σ_in² = ∇µᵀ P ∇µ over the position and attitude blocks of P
    const ErrMat& P = ekf.covariance();
    Eigen::Matrix<double, 6, 6> P6;
    P6 << P.block<3, 3>(kPos, kPos), P.block<3, 3>(kPos, kAtt), P.block<3, 3>(kAtt, kPos), P.block<3, 3>(kAtt, kAtt);
    c.var_m2 += (c.bias_row * P6 * c.bias_row.transpose())(0, 0);
  }
  return c;
}

}  // namespace

TdoaUpdateResult updateTdoa(Ekf& ekf, const AnchorTable& anchors, const TdoaMeasurement& z,
                            const TdoaUpdateOptions& options, const BiasPredictor* bias) {
  TdoaUpdateResult res;
  const Moments3* anchor_a = anchors.find(z.id_a);
  const Moments3* anchor_b = anchors.find(z.id_b);
  if (!anchor_a || !anchor_b) {
    res.outcome = UpdateOutcome::kUnknownAnchor;
    return res;
  }
  const BiasCorrectedTdoa c = correctBias(ekf, z, anchor_a->m, anchor_b->m, options, bias);
  res.bias_mean_m = c.bias_mean_m;
  double z_corr = c.z_m;
  // (F27) the anchors' range biases the filter carries as states: β̂_B − β̂_A
  const bool range_bias = ekf.rangeBias() != nullptr;
  if (range_bias) z_corr -= ekf.rangeBiasDifference(z.id_a, z.id_b);
  std::optional<ScalarLinearMessage<kDim>> msg =
      tdoaMessageFromAnchors(ekf.state(), anchor_a, anchor_b, z_corr, c.var_m2, options.b_t_tag);
  if (!msg) {
    res.outcome = UpdateOutcome::kDegenerate;
    return res;
  }
  // (P47b) z − µ(x̂) − h(x̂) ≈ (∂h/∂δx + ∂µ/∂δx) δx: the corrected measurement's row
  if (options.bias_pose == BiasPoseUncertainty::kJacobian && bias && *bias) {
    msg->a.segment<3>(kPos) += c.bias_row.head<3>();
    msg->a.segment<3>(kAtt) += c.bias_row.tail<3>();
  }
  // (F11) χ² gate on the unweighted innovation
  // The message row a = B12 C is non-zero only in the position and attitude blocks, so u = P aᵀ needs only those
  // 6 columns of P (G17). u is formed once, in full, for both the gate (a u) and the equality node (G18).
  // With range-bias states the row also reaches δβ_A and δβ_B, and S the cross terms (F27c).
  ErrVec P_a = ErrVec::Zero();
  double a_P_a = 0.0;
  Ekf::RangeBiasGain gain;
  if (range_bias) {
    gain = ekf.rangeBiasGain(*msg, z.id_a, z.id_b);
  } else {
    const ErrMat& P = ekf.covariance();
    const Vec3 a_p = msg->a.segment<3>(kPos).transpose();
    const Vec3 a_att = msg->a.segment<3>(kAtt).transpose();
    P_a.noalias() = P.middleCols<3>(kPos) * a_p;
    P_a.noalias() += P.middleCols<3>(kAtt) * a_att;
    a_P_a = a_p.dot(P_a.segment<3>(kPos)) + a_att.dot(P_a.segment<3>(kAtt));
  }
  res.innovation_m = msg->y;  // prior error state is zero
  res.innovation_var_m2 = (range_bias ? gain.h_u : a_P_a) + msg->var;
  res.nis = res.innovation_m * res.innovation_m / res.innovation_var_m2;
  if (options.gate_sigma > 0.0 && !OutlierGate(options.gate_sigma).accept(res.nis)) {
    res.outcome = UpdateOutcome::kRejectedOutlier;
    return res;
  }
  // (F13) IRLS weight of the robust loss; the weight inflates the variance of the message (Σ6 / w).
  const double hph = res.innovation_var_m2 - msg->var;
  res.weight = robustUpdateWeight(options.loss, options.robust_k, res.innovation_m, hph, msg->var,
                                  options.robust_iterations);
  msg->var /= res.weight;
  const bool corrected = range_bias ? ekf.correctWithRangeBias(*msg, gain).has_value()
                                    : ekf.correctPositionAttitude(*msg, P_a, a_P_a).has_value();  // δp, δθ only (G16)
  res.outcome = corrected ? UpdateOutcome::kApplied : UpdateOutcome::kDegenerate;
  return res;
}

}  // namespace uwb
