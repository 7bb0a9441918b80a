/** @file TdoaUpdate.cpp
 *  @brief TDoA correction through the graph's TDoA node and equality node (paper III-A, Fig. 2–3);
 *         docs/math/filter.md F10–F13.
 */
#include "uwb/filter/TdoaUpdate.h"

#include <cmath>

#include "uwb/model/TdoaLinearization.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {

void AnchorTable::set(int id, const Vec3& w_p, double sigma_m) {
  if (id < 0 || id > 4095) throw std::invalid_argument("AnchorTable::set: anchor id must be in [0, 4095]");
  if (static_cast<int>(anchors_.size()) <= id) {
    anchors_.resize(id + 1);
    known_.resize(id + 1, false);
  }
  anchors_[id].m = w_p;
  anchors_[id].V = Mat3::Identity() * (sigma_m * sigma_m);
  known_[id] = true;
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

std::optional<ScalarLinearMessage<kDim>> tdoaMessage(const NavState& x, const AnchorTable& anchors,
                                                     const TdoaObservation& z, double z_corrected_m, double var_m2,
                                                     const Vec3& b_t_tag) {
  const Moments3* anchor_a = anchors.find(z.id_a);
  const Moments3* anchor_b = anchors.find(z.id_b);
  if (!anchor_a || !anchor_b) return std::nullopt;
  // (F10) linearise at the tag position x̃_k = p + R b_t; UTIL convention ⇒ x_i = anchor B, x_j = anchor A.
  // One rotation matrix serves the tag position (M2) and its attitude Jacobian −R[b_t]× (M4).
  const Mat3 w_R_b = x.w_q_b.toRotationMatrix();
  const Vec3 w_p_tag = x.w_p_b + w_R_b * b_t_tag;
  const std::optional<TdoaLinearization> lin = linearizeTdoa(w_p_tag, anchor_b->m, anchor_a->m);
  if (!lin) return std::nullopt;
  // Paper Fig. 2: the TDoA node's forward pass (G11–G13) …
  const TdoaNodeMessages node = tdoaNodeForward(*lin, *anchor_b, *anchor_a, z_corrected_m, var_m2);
  // … and the message on δx through x_k = x̃_k + C δx, C = [I 0 −R[b_t]× 0 0] (G16; model M4).
  const Mat3 J_tag_att = -(w_R_b * skew(b_t_tag));  // = tagPositionJacobianAttitude(w_q_b, b_t_tag) (M4)
  return tdoaMessageOnPositionAttitude(node, J_tag_att, w_p_tag);
}

TdoaUpdateResult updateTdoa(Ekf& ekf, const AnchorTable& anchors, const TdoaObservation& z,
                            const TdoaUpdateOptions& options, const BiasPredictor* bias) {
  TdoaUpdateResult res;
  const NavState& x = ekf.state();
  const Moments3* anchor_a = anchors.find(z.id_a);
  const Moments3* anchor_b = anchors.find(z.id_b);
  if (!anchor_a || !anchor_b) {
    res.outcome = UpdateOutcome::kUnknownAnchor;
    return res;
  }
  // (F12) bias correction from the predictor, evaluated at the filter's current estimate (paper III-B).
  double z_corr = z.tdoa_m;
  double var = options.sigma_m * options.sigma_m;
  if (bias && *bias) {
    const BiasPrediction b =
        (*bias)(makeTdoaFeature(z.id_a, z.id_b, x.w_p_b, x.w_q_b, anchor_a->m, anchor_b->m));
    if (std::isfinite(b.mean_m) && std::isfinite(b.variance_m2) && b.variance_m2 >= 0.0) {
      z_corr -= b.mean_m;
      var += b.variance_m2;
      res.bias_mean_m = b.mean_m;
    }
  }
  std::optional<ScalarLinearMessage<kDim>> msg = tdoaMessage(x, anchors, z, z_corr, var, options.b_t_tag);
  if (!msg) {
    res.outcome = UpdateOutcome::kDegenerate;
    return res;
  }
  // (F11) χ² gate on the unweighted innovation
  // The message row a = B12 C is non-zero only in the position and attitude blocks, so a P aᵀ needs only the
  // 6×6 sub-block of P (F11; the same value as innovationOf, G17, at a sixth of the cost), read in place by blocks.
  const ErrMat& P = ekf.covariance();
  const Vec3 a_p = msg->a.segment<3>(kPos).transpose();
  const Vec3 a_att = msg->a.segment<3>(kAtt).transpose();
  const Vec3 Pa_p = P.block<3, 3>(kPos, kPos) * a_p + P.block<3, 3>(kPos, kAtt) * a_att;
  const Vec3 Pa_att = P.block<3, 3>(kAtt, kPos) * a_p + P.block<3, 3>(kAtt, kAtt) * a_att;
  InnovationStats st;
  st.innovation_m = msg->y;  // prior error state is zero
  st.innovation_var_m2 = a_p.dot(Pa_p) + a_att.dot(Pa_att) + msg->var;
  st.nis = st.innovation_m * st.innovation_m / st.innovation_var_m2;
  res.innovation_m = st.innovation_m;
  res.nis = st.nis;
  if (options.gate_sigma > 0.0 && !OutlierGate(options.gate_sigma).accept(st.nis)) {
    res.outcome = UpdateOutcome::kRejectedOutlier;
    return res;
  }
  // (F13) IRLS weight of the robust loss; the weight inflates the variance of the message (Σ6 / w).
  const double hph = st.innovation_var_m2 - msg->var;
  res.weight = robustUpdateWeight(options.loss, options.robust_k, st.innovation_m, hph, msg->var,
                                  options.robust_iterations);
  msg->var /= res.weight;
  if (!ekf.correctPositionAttitude(*msg)) {  // the TDoA row touches only δp and δθ (G16)
    res.outcome = UpdateOutcome::kDegenerate;
    return res;
  }
  res.outcome = UpdateOutcome::kApplied;
  return res;
}

}  // namespace uwb
