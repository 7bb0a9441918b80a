/** @file Ekf.cpp
 *  @brief Error-state Kalman filter core; docs/math/filter.md F1–F8, F14. The correction goes through the
 *         graph's equality node (paper Fig. 3; docs/math/message-passing.md G18).
 */
#include "uwb/filter/Ekf.h"

#include "uwb/filter/InMotionAlignment.h"
#include "uwb/graph/HalfLine.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace uwb {

void AccumulatedTransition::accumulate(const ImuStepJacobian& J) {
  // docs/math/filter.md (F7): Φ ← F Φ with F from (F4); only the non-trivial blocks change.
  // F_pθ = ½dt F_vθ and F_pba = ½dt F_vba (F4), so the position rows reuse the velocity rows' products
  // F_vθ Φ_θθ and F_vθ Φ_θbg: four 3×3 products per step instead of six.
  // F_pv and F_vv are diagonal (F2a): the velocity rows are scaled per axis before they are added to the position
  // rows (old velocity rows) and to themselves.
  const double dt = J.dt_s;
  const double half_dt = 0.5 * dt;
  const auto Fpv = J.F_p_v_diag.asDiagonal();
  const auto Fvv = J.F_v_v_diag.asDiagonal();
  const Mat3 Fva_att_att = J.F_v_att * att_att;
  const Mat3 Fva_att_gyrobias = J.F_v_att * att_gyrobias;
  pos_vel += J.F_p_v_diag.cwiseProduct(vel_vel);
  pos_att += Fpv * vel_att + half_dt * Fva_att_att;
  pos_accbias += Fpv * vel_accbias + half_dt * J.F_v_accbias;
  pos_gyrobias += Fpv * vel_gyrobias + half_dt * Fva_att_gyrobias;
  vel_vel = J.F_v_v_diag.cwiseProduct(vel_vel);
  vel_att = (Fvv * vel_att).eval() + Fva_att_att;
  vel_accbias = (Fvv * vel_accbias).eval() + J.F_v_accbias;
  vel_gyrobias = (Fvv * vel_gyrobias).eval() + Fva_att_gyrobias;
  att_gyrobias = J.F_att_att * att_gyrobias + J.F_att_gyrobias;
  att_att = J.F_att_att * att_att;
  T_s += dt;
}

ErrMat AccumulatedTransition::dense() const {
  ErrMat F = ErrMat::Identity();
  F.block<3, 3>(kPos, kVel) = pos_vel.asDiagonal();
  F.block<3, 3>(kVel, kVel) = vel_vel.asDiagonal();
  F.block<3, 3>(kPos, kAtt) = pos_att;
  F.block<3, 3>(kPos, kAccBias) = pos_accbias;
  F.block<3, 3>(kPos, kGyroBias) = pos_gyrobias;
  F.block<3, 3>(kVel, kAtt) = vel_att;
  F.block<3, 3>(kVel, kAccBias) = vel_accbias;
  F.block<3, 3>(kVel, kGyroBias) = vel_gyrobias;
  F.block<3, 3>(kAtt, kAtt) = att_att;
  F.block<3, 3>(kAtt, kGyroBias) = att_gyrobias;
  return F;
}

ErrMat AccumulatedTransition::leftMultiply(const ErrMat& M) const {
  // Row blocks of Φ M; bias rows of Φ are identity rows.
  ErrMat out = M;
  out.middleRows<3>(kPos).noalias() += pos_vel.asDiagonal() * M.middleRows<3>(kVel);
  out.middleRows<3>(kVel) = vel_vel.asDiagonal() * M.middleRows<3>(kVel);
  out.middleRows<3>(kPos).noalias() += pos_att * M.middleRows<3>(kAtt);
  out.middleRows<3>(kPos).noalias() += pos_accbias * M.middleRows<3>(kAccBias);
  out.middleRows<3>(kPos).noalias() += pos_gyrobias * M.middleRows<3>(kGyroBias);
  out.middleRows<3>(kVel).noalias() += vel_att * M.middleRows<3>(kAtt);
  out.middleRows<3>(kVel).noalias() += vel_accbias * M.middleRows<3>(kAccBias);
  out.middleRows<3>(kVel).noalias() += vel_gyrobias * M.middleRows<3>(kGyroBias);
  out.middleRows<3>(kAtt).noalias() = att_att * M.middleRows<3>(kAtt);
  out.middleRows<3>(kAtt).noalias() += att_gyrobias * M.middleRows<3>(kGyroBias);
  return out;
}

namespace {

/// out.middleCols<3>(j) += cols Bᵀ on the first Rows rows, for a block `cols` of 3 columns: per written column, its
/// rows held in full 4-wide SIMD packets (Eigen vectorises a fixed 15-row column only with 2-wide packets) while the
/// three axpys B(r, c) cols_c are added in the order c = 0, 1, 2, then stored once. When 4 does not divide Rows the
/// last packet covers the last 4 rows and overlaps the one before; both give the overlapping rows the same value
/// (the same additions from the same loaded values), so no row is updated twice. `cols` must not overlap the written
/// columns.
template <int Rows, class Matrix, class Columns>
void addColumnBlockTimesTransposed(Matrix& out, int j, const Columns& cols, const Mat3& B) {
  static_assert(Rows >= 4);
  constexpr int kPackets = (Rows + 3) / 4;
  constexpr auto start = [](int p) { return std::min(4 * p, Rows - 4); };
  for (int r = 0; r < 3; ++r) {
    Eigen::Matrix<double, 4, kPackets> acc;
    for (int p = 0; p < kPackets; ++p) acc.col(p) = out.col(j + r).template segment<4>(start(p));
    for (int c = 0; c < 3; ++c)
      for (int p = 0; p < kPackets; ++p) acc.col(p) += B(r, c) * cols.col(c).template segment<4>(start(p));
    for (int p = 0; p < kPackets; ++p) out.col(j + r).template segment<4>(start(p)) = acc.col(p);
  }
}

/// The first Rows rows of M ← M Φᵀ in place, using the block structure of Φ (F7); M has the 15 columns of δx (P, or the
/// range-bias rows P_βx of F27b).
template <int Rows, class Matrix>
void rightMultiplyTransposedTopRows(const AccumulatedTransition& phi, Matrix& M) {
  // Column blocks of M Φᵀ = (Φ Mᵀ)ᵀ: column block j of the result is Σ_k M_{:,k} Φ_jkᵀ; bias columns are unchanged.
  // Written in the order position, velocity, attitude: each block reads only blocks that are still unchanged, except
  // the velocity block, scaled in place per column (Φ_vv is diagonal), and the attitude block, which reads its own old
  // value (kept in a copy).
  auto top = [&M](int j) { return M.template block<Rows, 3>(0, j); };
  for (int c = 0; c < 3; ++c)
    M.col(kPos + c).template head<Rows>() += phi.pos_vel(c) * M.col(kVel + c).template head<Rows>();
  if (phi.vel_vel(0) != 1.0 || phi.vel_vel(1) != 1.0 || phi.vel_vel(2) != 1.0)
    for (int c = 0; c < 3; ++c) M.col(kVel + c).template head<Rows>() *= phi.vel_vel(c);
  addColumnBlockTimesTransposed<Rows>(M, kPos, top(kAtt), phi.pos_att);
  addColumnBlockTimesTransposed<Rows>(M, kPos, top(kAccBias), phi.pos_accbias);
  addColumnBlockTimesTransposed<Rows>(M, kPos, top(kGyroBias), phi.pos_gyrobias);
  addColumnBlockTimesTransposed<Rows>(M, kVel, top(kAtt), phi.vel_att);
  addColumnBlockTimesTransposed<Rows>(M, kVel, top(kAccBias), phi.vel_accbias);
  addColumnBlockTimesTransposed<Rows>(M, kVel, top(kGyroBias), phi.vel_gyrobias);
  const Eigen::Matrix<double, Rows, 3> M_att = top(kAtt);
  top(kAtt).setZero();  // Φ_θθ replaces the identity block
  addColumnBlockTimesTransposed<Rows>(M, kAtt, M_att, phi.att_att);
  addColumnBlockTimesTransposed<Rows>(M, kAtt, top(kGyroBias), phi.att_gyrobias);
}

}  // namespace

void AccumulatedTransition::rightMultiplyTransposedInPlace(ErrMat& M) const {
  rightMultiplyTransposedTopRows<kDim>(*this, M);
}

ErrMat AccumulatedTransition::rightMultiplyTransposed(const ErrMat& M) const {
  ErrMat out = M;
  rightMultiplyTransposedInPlace(out);
  return out;
}

Ekf::Ekf(const EkfParams& params) : params_(params) {
  params_.validate();
  P_ = initialCovariance(params_);
  resetRangeBias();
}

void Ekf::resetRangeBias() {
  // (F27) the range-bias states at their prior; (F27e) with the prior's adaptation when asked for
  if (!(params_.range_bias_sigma_m > 0.0)) return;
  range_bias_.emplace(params_.range_bias_sigma_m, params_.range_bias_tau_s);
  range_bias_->enableAdaptation(params_.range_bias_adapt_s, params_.range_bias_min_fraction);
}

ErrMat initialCovariance(const EkfParams& p) {
  ErrMat P = ErrMat::Zero();
  P.block<3, 3>(kPos, kPos).diagonal().setConstant(p.init_pos_sigma_m * p.init_pos_sigma_m);
  P.block<3, 3>(kVel, kVel).diagonal().setConstant(p.init_vel_sigma_mps * p.init_vel_sigma_mps);
  P.block<3, 3>(kAtt, kAtt).diagonal() << p.init_att_sigma_rad * p.init_att_sigma_rad,
      p.init_att_sigma_rad * p.init_att_sigma_rad, p.init_yaw_sigma_rad * p.init_yaw_sigma_rad;
  P.block<3, 3>(kAccBias, kAccBias).diagonal().setConstant(p.init_acc_bias_sigma_mps2 * p.init_acc_bias_sigma_mps2);
  // (F1) roll/pitch components of the gyro bias are seen through gravity and thrust, the yaw component hardly
  P.block<3, 3>(kGyroBias, kGyroBias).diagonal() << p.init_gyro_bias_sigma_xy_radps * p.init_gyro_bias_sigma_xy_radps,
      p.init_gyro_bias_sigma_xy_radps * p.init_gyro_bias_sigma_xy_radps,
      p.init_gyro_bias_sigma_z_radps * p.init_gyro_bias_sigma_z_radps;
  return P;
}

void Ekf::initialize(const NavState& x0, const ErrMat& P0) {
  if (!P0.allFinite()) throw std::invalid_argument("Ekf::initialize: P0 not finite");
  x_ = x0;
  P_ = 0.5 * (P0 + P0.transpose());
  phi_ = AccumulatedTransition{};
  pending_cv_dt_s_ = 0.0;
  resetRangeBias();
}

void Ekf::predict(const ImuReading& imu, double dt_s) {
  if (!(dt_s > 0.0)) return;
  const ProcessStep step = quadImuProcess(x_, imu, dt_s, params_.accel_model, params_.rotor_drag_per_s);  // (F2–F4)
  x_ = step.next;
  phi_.accumulate(step.J);  // (F7)
  // velocity process noise per world axis (F7 Q): vertical/isotropic accelerometer noise, plus lateral
  // model noise when the x/y readings are not integrated (drag and other unmodelled forces).
  const double qa = params_.acc_noise_mps2_sqrthz * params_.acc_noise_mps2_sqrthz * dt_s;
  phi_.q_vel_diag += Vec3::Constant(qa);
  if (params_.accel_model == AccelModel::kThrustOnly) {
    const double ql = params_.lateral_acc_noise_mps2_sqrthz * params_.lateral_acc_noise_mps2_sqrthz * dt_s;
    phi_.q_vel_diag.x() += ql;
    phi_.q_vel_diag.y() += ql;
  }
}

void Ekf::predictTdoaOnly(double dt_s) {
  if (!(dt_s > 0.0)) return;
  tdoaOnlyPredictNominal(x_, dt_s, params_.process_model);  // (F9)
  // The CV/CA transitions and their continuous-white-noise Q compose exactly over time
  // (F(t₂)F(t₁) = F(t₁+t₂), F(t₂)Q(t₁)F(t₂)ᵀ + Q(t₂) = Q(t₁+t₂)), so the pending transition is just its length.
  pending_cv_dt_s_ += dt_s;
}

namespace {

/// (F9) M ← F(T) M for the TDoA-only transition, on the rows of any 15-row M (the position row uses the old velocity
/// row, so it goes first).
template <typename Derived>
void tdoaOnlyTransitionRows(Eigen::MatrixBase<Derived>& M, double T, bool ca) {
  M.template middleRows<3>(kPos) += T * M.template middleRows<3>(kVel);
  if (ca) {
    M.template middleRows<3>(kPos) += (0.5 * T * T) * M.template middleRows<3>(kAccBias);
    M.template middleRows<3>(kVel) += T * M.template middleRows<3>(kAccBias);
  }
}

}  // namespace

void Ekf::propagateTdoaOnlyCovariance() {
  // docs/math/filter.md (F9, F7): P ← F(T) P F(T)ᵀ + Q(T) using the structure of F(T) = I + T E_pv
  // (+ ½T² E_pa + T E_va for constant acceleration), per axis: O(15·3) instead of dense 15×15 products.
  const double T = pending_cv_dt_s_;
  const double T2 = T * T, T3 = T2 * T;
  const bool ca = params_.process_model == ProcessModel::kConstantAcceleration;
  // rows: P ← F P; the range-bias cross-covariance's rows alike, P_xβ ← F P_xβ (F27b)
  tdoaOnlyTransitionRows(P_, T, ca);
  if (range_bias_) {
    auto P_xb = range_bias_->biasRows().transpose();  // a writable view: P_xβ ← F P_xβ
    tdoaOnlyTransitionRows(P_xb, T, ca);
  }
  // columns: P ← (F P) Fᵀ
  P_.middleCols<3>(kPos) += T * P_.middleCols<3>(kVel);
  if (ca) {
    P_.middleCols<3>(kPos) += (0.5 * T2) * P_.middleCols<3>(kAccBias);
    P_.middleCols<3>(kVel) += T * P_.middleCols<3>(kAccBias);
  }
  for (int i = 0; i < 3; ++i) {
    if (ca) {
      const double q = params_.ca_jerk_noise_mps3_sqrthz * params_.ca_jerk_noise_mps3_sqrthz;
      const double T4 = T3 * T, T5 = T4 * T;
      P_(kPos + i, kPos + i) += q * T5 / 20.0;
      P_(kPos + i, kVel + i) += q * T4 / 8.0;
      P_(kVel + i, kPos + i) += q * T4 / 8.0;
      P_(kPos + i, kAccBias + i) += q * T3 / 6.0;
      P_(kAccBias + i, kPos + i) += q * T3 / 6.0;
      P_(kVel + i, kVel + i) += q * T3 / 3.0;
      P_(kVel + i, kAccBias + i) += q * T2 / 2.0;
      P_(kAccBias + i, kVel + i) += q * T2 / 2.0;
      P_(kAccBias + i, kAccBias + i) += q * T;
    } else {
      const double q = params_.cv_acc_noise_mps2_sqrthz * params_.cv_acc_noise_mps2_sqrthz;
      P_(kPos + i, kPos + i) += q * T3 / 3.0;
      P_(kPos + i, kVel + i) += q * T2 / 2.0;
      P_(kVel + i, kPos + i) += q * T2 / 2.0;
      P_(kVel + i, kVel + i) += q * T;
    }
  }
  pending_cv_dt_s_ = 0.0;
}

void Ekf::propagateCovariance() {
  // (F27b) the range biases' Ornstein–Uhlenbeck transition over the same time
  const double T_pending = pendingDt();
  if (pending_cv_dt_s_ > 0.0) propagateTdoaOnlyCovariance();
  if (phi_.empty()) {
    if (range_bias_) range_bias_->decay(T_pending);
    return;
  }
  if (range_bias_) {
    rightMultiplyTransposedTopRows<kMaxBiasAnchors>(phi_, range_bias_->biasRows());  // P_βx ← P_βx Φᵀ
    range_bias_->decay(T_pending);
  }
  // docs/math/filter.md (F7): P ← Φ P Φᵀ + Q(T). With A = (δp, δv, δθ) (rows 0..8) and B = the biases (rows 9..14),
  // the bias rows of Φ are identity rows, so for Y = P Φᵀ (column operations, vectorised along the columns):
  //   (Φ P Φᵀ)_{B,:} = Y_{B,:},   (Φ P Φᵀ)_{A,B} = Y_{B,A}ᵀ (symmetry),   (Φ P Φᵀ)_{A,A} = (Y_{:,A})ᵀ_{A-rows} Φᵀ.
  // The second right-multiplication by Φᵀ therefore runs over the 9 rows of A only (the same block sums as
  // Φ (Φ P)ᵀ with row operations), and the A/B blocks stay exactly symmetric.
  phi_.rightMultiplyTransposedInPlace(P_);                           // Y = P Φᵀ; rows B are final
  P_.topLeftCorner<kAccBias, kAccBias>().transposeInPlace();         // rows A ← (Y_{:,A})ᵀ …
  P_.topRightCorner<kAccBias, kDim - kAccBias>() = P_.bottomLeftCorner<kDim - kAccBias, kAccBias>().transpose();
  rightMultiplyTransposedTopRows<kAccBias>(phi_, P_);                // … times Φᵀ: rows A of Φ P Φᵀ
  const double T = phi_.T_s;
  P_.diagonal().segment<3>(kVel) += phi_.q_vel_diag;
  P_.diagonal().segment<3>(kPos).array() += params_.pos_noise_m_sqrts * params_.pos_noise_m_sqrts * T;
  P_.diagonal().segment<3>(kAtt).array() += params_.gyro_noise_radps_sqrthz * params_.gyro_noise_radps_sqrthz * T;
  P_.diagonal().segment<3>(kAccBias).array() +=
      params_.acc_bias_rw_mps3_sqrthz * params_.acc_bias_rw_mps3_sqrthz * T;
  P_.diagonal().segment<3>(kGyroBias).array() +=
      params_.gyro_bias_rw_radps2_sqrthz * params_.gyro_bias_rw_radps2_sqrthz * T;
  phi_ = AccumulatedTransition{};
}

InnovationStats Ekf::innovation(const ScalarLinearMessage<kDim>& message) const {
  if (range_bias_) {
    InnovationStats st;
    st.innovation_m = message.y;
    st.innovation_var_m2 = jointGain(message.a, -1, -1).h_u + message.var;
    st.nis = st.innovation_m * st.innovation_m / st.innovation_var_m2;
    return st;
  }
  return innovationOf<kDim>(message, ErrVec::Zero(), P_);
}

double Ekf::rangeBiasDifference(int id_a, int id_b) const {
  return range_bias_ ? range_bias_->mean(id_b) - range_bias_->mean(id_a) : 0.0;
}

Ekf::RangeBiasGain Ekf::jointGain(const ErrRow& a, int slot_a, int slot_b) const {
  // (F27c) u = J hᵀ for the joint covariance J = [[P, P_xβ], [P_βx, P_ββ]] and the row h = [a, e_B − e_A] (no entry for
  // a slot < 0), from the blocks: with v = P_βx aᵀ, u = [P aᵀ + P_xβ (e_B − e_A); v + P_ββ (e_B − e_A)] and
  // h u = a P aᵀ + 2 (v_B − v_A) + P_ββ,BB + P_ββ,AA − 2 P_ββ,AB. A TDoA row a (G16) is non-zero only in δp and δθ: those
  // are read as 3-column blocks (as equalityRankOneTwoBlocksInPlace); other rows (ZUPT, floor, ToF) by entry.
  const BiasRowsMat& P_bx = range_bias_->biasRows();
  const BiasMat& P_bb = range_bias_->covariance();
  RangeBiasGain g;
  if (a.segment<3>(kVel).isZero() && a.segment<6>(kAccBias).isZero()) {
    const Vec3 a_p = a.segment<3>(kPos).transpose(), a_att = a.segment<3>(kAtt).transpose();
    g.u_x.noalias() = P_.middleCols<3>(kPos) * a_p;
    g.u_x.noalias() += P_.middleCols<3>(kAtt) * a_att;
    g.u_b.noalias() = P_bx.middleCols<3>(kPos) * a_p;
    g.u_b.noalias() += P_bx.middleCols<3>(kAtt) * a_att;
  } else {
    for (int c = 0; c < kDim; ++c) {
      if (a(c) == 0.0) continue;
      g.u_x.noalias() += P_.col(c) * a(c);
      g.u_b.noalias() += P_bx.col(c) * a(c);
    }
  }
  const auto entry = [](const BiasVec& v, int k) { return k < 0 ? 0.0 : v(k); };
  const auto cov = [&P_bb](int i, int j) { return i < 0 || j < 0 ? 0.0 : P_bb(i, j); };
  g.h_u = a.dot(g.u_x.transpose()) + 2.0 * (entry(g.u_b, slot_b) - entry(g.u_b, slot_a)) + cov(slot_b, slot_b) +
          cov(slot_a, slot_a) - 2.0 * cov(slot_a, slot_b);
  if (slot_b >= 0) {
    g.u_x.noalias() += P_bx.row(slot_b).transpose();
    g.u_b.noalias() += P_bb.col(slot_b);
  }
  if (slot_a >= 0) {
    g.u_x.noalias() -= P_bx.row(slot_a).transpose();
    g.u_b.noalias() -= P_bb.col(slot_a);
  }
  return g;
}

std::optional<InnovationStats> Ekf::correctAugmented(double y, double var, const RangeBiasGain& g) {
  // (G18) the equality node on [δx, δβ] with the joint prior N(0, J) (F27c), by blocks: S = h u + var,
  // [δx, δβ] = u r/S, J ← J − w wᵀ with w = u/√S (detail::applyRankOneGain on the joint J).
  InnovationStats st;
  st.innovation_m = y;  // the prior error state [δx, δβ] is zero
  st.innovation_var_m2 = g.h_u + var;
  if (!(st.innovation_var_m2 > 0.0) || !std::isfinite(st.innovation_var_m2) || !std::isfinite(st.innovation_m))
    return std::nullopt;
  st.nis = st.innovation_m * st.innovation_m / st.innovation_var_m2;
  const double S = st.innovation_var_m2;
  const double inv_sqrt_S = 1.0 / std::sqrt(S);
  const ErrVec w_x = g.u_x * inv_sqrt_S;
  // formed before the downdates, so that inject reads a vector written long before (no store-forwarding stall)
  const ErrVec dx = g.u_x * (st.innovation_m / S);
  detail::rankOneDowndate<kDim>(P_, w_x);
  range_bias_->downdate(w_x, g.u_b * inv_sqrt_S, g.u_b * (st.innovation_m / S));
  inject(dx);  // (F8)
  return st;
}

Ekf::RangeBiasGain Ekf::rangeBiasGain(const ScalarLinearMessage<kDim>& message, int id_a, int id_b) {
  const int slot_a = range_bias_->slot(id_a), slot_b = range_bias_->slot(id_b);
  RangeBiasGain g = jointGain(message.a, slot_a, slot_b);
  g.slot_a = slot_a;
  g.slot_b = slot_b;
  return g;
}

std::optional<InnovationStats> Ekf::correctWithRangeBias(const ScalarLinearMessage<kDim>& message,
                                                         const RangeBiasGain& gain) {
  std::optional<InnovationStats> st = correctAugmented(message.y, message.var, gain);
  if (st) range_bias_->adapt(gain.slot_a, gain.slot_b);  // (F27e)
  return st;
}

void Ekf::scaleCovariance(double factor) {
  P_ *= factor;
  if (range_bias_) range_bias_->scale(factor);
}

bool Ekf::inflateAlongPosition(double factor) {
  if (!(factor > 1.0) || !std::isfinite(factor)) return false;
  const Eigen::LLT<Mat3> llt(P_.block<3, 3>(kPos, kPos));
  if (llt.info() != Eigen::Success) return false;
  // (G21) with G = P_·p and P_pp = L Lᵀ: P += c WᵀW, W = L⁻¹ Gᵀ, c = f − 1 (= c G P_pp⁻¹ Gᵀ, symmetric as written);
  // the range-bias rows likewise with W_β = L⁻¹ P_pβ
  const double c = factor - 1.0;
  const Eigen::Matrix<double, 3, kDim> W = llt.matrixL().solve(P_.middleCols<3>(kPos).transpose());
  if (range_bias_) {
    const Eigen::Matrix<double, 3, kMaxBiasAnchors> Wb =
        llt.matrixL().solve(range_bias_->biasRows().middleCols<3>(kPos).transpose());
    range_bias_->inflate(c * Wb.transpose() * W, c * Wb.transpose() * Wb);
  }
  P_.noalias() += c * W.transpose() * W;
  return true;
}

std::optional<InnovationStats> Ekf::correct(const ScalarLinearMessage<kDim>& message) {
  if (range_bias_) return correctAugmented(message.y, message.var, jointGain(message.a, -1, -1));
  // Paper Fig. 3: equality node between the predicted error state N(0, P) and the TDoA message (G18).
  ErrVec dx = ErrVec::Zero();
  const std::optional<InnovationStats> st = equalityRankOneInPlace<kDim>(dx, P_, message);
  if (!st) return std::nullopt;
  inject(dx);  // (F8)
  return st;
}

std::optional<InnovationStats> Ekf::correctPositionAttitude(const ScalarLinearMessage<kDim>& message) {
  if (range_bias_) return correct(message);
  // As correct(); the equality node (G18) skips the velocity and bias columns, where the TDoA row is zero (G16).
  ErrVec dx = ErrVec::Zero();
  const std::optional<InnovationStats> st = equalityRankOneTwoBlocksInPlace<kDim>(dx, P_, message, kPos, kAtt);
  if (!st) return std::nullopt;
  inject(dx);  // (F8)
  return st;
}

std::optional<InnovationStats> Ekf::correctPositionAttitude(const ScalarLinearMessage<kDim>& message,
                                                            const ErrVec& P_a, double a_P_a) {
  if (range_bias_) return correct(message);  // P_a and a_P_a do not hold the cross terms
  // The equality node (G18) from u = P aᵀ and a u; a m = 0 since the prior error state m is zero.
  ErrVec dx = ErrVec::Zero();
  const std::optional<InnovationStats> st = detail::applyRankOneGain<kDim>(dx, P_, message, P_a, 0.0, a_P_a);
  if (!st) return std::nullopt;
  inject(dx);  // (F8)
  return st;
}

void Ekf::zeroVelocityUpdate(double sigma_mps) {
  // (F14) v = 0 observed per world axis. The row a = e_{v,i} is a unit vector, so the equality node's u = P aᵀ is
  // column kVel+i of P and a u its diagonal entry (G18; what correct() sums from the one non-zero entry of a).
  for (int i = 0; i < 3; ++i) {
    ScalarLinearMessage<kDim> m;
    m.a.setZero();
    m.a(kVel + i) = 1.0;
    m.y = -x_.w_v_b(i);
    m.var = sigma_mps * sigma_mps;
    if (range_bias_) {
      correct(m);
      continue;
    }
    ErrVec dx = ErrVec::Zero();
    const ErrVec u = P_.col(kVel + i);
    if (detail::applyRankOneGain<kDim>(dx, P_, m, u, 0.0, u(kVel + i))) inject(dx);  // (F8)
  }
}

int Ekf::zeroAngularRateUpdate(const Vec3& mean_gyro_radps, const Vec3& var_radps2, double gate_sigma) {
  // (F18z) ω̄ = b_g + noise per body axis: the row is the unit vector of the bias component, the innovation ω̄ − b̂_g
  int widened = 0;
  for (int i = 0; i < 3; ++i) {
    const int k = kGyroBias + i;
    ScalarLinearMessage<kDim> m;
    m.a.setZero();
    m.a(k) = 1.0;
    m.y = mean_gyro_radps(i) - x_.b_gyro_bias(i);
    m.var = var_radps2(i);
    // never confidently wrong: a reading of the bias beyond chance widens its variance before it is fused
    if (m.y * m.y > gate_sigma * gate_sigma * (P_(k, k) + m.var)) {
      P_(k, k) += m.y * m.y;
      ++widened;
    }
    correct(m);
  }
  return widened;
}

void Ekf::positionUpdate(int axis, double value_m, double sigma_m) {
  if (axis < 0 || axis > 2) throw std::invalid_argument("Ekf::positionUpdate: axis must be 0, 1 or 2");
  ScalarLinearMessage<kDim> m;
  m.a.setZero();
  m.a(kPos + axis) = 1.0;
  m.y = value_m - x_.w_p_b(axis);
  m.var = sigma_m * sigma_m;
  correct(m);
}

bool Ekf::constrainPosition(int axis, double bound_m, double sign) {
  if (axis < 0 || axis > 2) throw std::invalid_argument("Ekf::constrainPosition: axis must be 0, 1 or 2");
  const double v = P_(kPos + axis, kPos + axis);
  if (!(v > 0.0) || !std::isfinite(v)) return false;
  // (G23b) on s·p ≥ s·bound: the message to s·p, mapped back to p by the same sign
  const std::optional<ScalarObservation> msg = halfLineMessage(sign * x_.w_p_b(axis), v, sign * bound_m);
  if (!msg) return false;
  positionUpdate(axis, sign * msg->y, std::sqrt(msg->var));
  return true;
}

bool Ekf::constrainPositionAbove(int axis, double lower_m) { return constrainPosition(axis, lower_m, 1.0); }

bool Ekf::constrainPositionBelow(int axis, double upper_m) { return constrainPosition(axis, upper_m, -1.0); }

void Ekf::inflatePosition(double sigma_m, double vel_sigma_mps) {
  P_.diagonal().segment<3>(kPos).array() += sigma_m * sigma_m;
  P_.diagonal().segment<3>(kVel).array() += vel_sigma_mps * vel_sigma_mps;
}

void Ekf::inflateHorizontalPosition(double sigma_m, double vel_sigma_mps) {
  P_(kPos, kPos) += sigma_m * sigma_m;
  P_(kPos + 1, kPos + 1) += sigma_m * sigma_m;
  P_.diagonal().segment<3>(kVel).array() += vel_sigma_mps * vel_sigma_mps;
}

void Ekf::resetPosition(const Vec3& w_p_b, double sigma_m) {
  x_.w_p_b = w_p_b;
  P_.middleRows<3>(kPos).setZero();
  P_.middleCols<3>(kPos).setZero();
  P_.block<3, 3>(kPos, kPos).diagonal().setConstant(sigma_m * sigma_m);
  if (range_bias_) range_bias_->biasRows().middleCols<3>(kPos).setZero();
}

void Ekf::resetHeight(double z_m, double var_m2) {
  constexpr int kZ = kPos + 2;
  x_.w_p_b.z() = z_m;
  P_.row(kZ).setZero();
  P_.col(kZ).setZero();
  P_(kZ, kZ) = var_m2;
  if (range_bias_) range_bias_->biasRows().col(kZ).setZero();
}

void Ekf::resetPositionVelocity(const Vec3& w_p_b, const Vec3& w_v_b, const Eigen::Matrix<double, 6, 6>& cov) {
  static_assert(kVel == kPos + 3, "position and velocity are adjacent in the error state");
  x_.w_p_b = w_p_b;
  x_.w_v_b = w_v_b;
  P_.middleRows<6>(kPos).setZero();
  P_.middleCols<6>(kPos).setZero();
  P_.block<6, 6>(kPos, kPos) = 0.5 * (cov + cov.transpose());
  if (range_bias_) range_bias_->biasRows().middleCols<6>(kPos).setZero();
}

void Ekf::headingUpdate(double heading_rad, double sigma_rad) {
  // (F28) y = ψ_meas − ψ(q), wrapped; a = ∂ψ/∂δθ_b
  ScalarLinearMessage<kDim> m;
  m.a.setZero();
  m.a.segment<3>(kAtt) = headingJacobian(x_.w_q_b);
  m.y = wrapAngle(heading_rad - headingOf(x_.w_q_b));
  m.var = sigma_rad * sigma_rad;
  correct(m);
}

void Ekf::resetAttitude(const Quat& w_q_b, const Mat3& cov) {
  x_.w_q_b = w_q_b.normalized();
  P_.middleRows<3>(kAtt).setZero();
  P_.middleCols<3>(kAtt).setZero();
  P_.block<3, 3>(kAtt, kAtt) = 0.5 * (cov + cov.transpose());
  if (range_bias_) range_bias_->biasRows().middleCols<3>(kAtt).setZero();
}

void Ekf::inflateThrustBias(double sigma_mps2) { P_(kAccBias + 2, kAccBias + 2) += sigma_mps2 * sigma_mps2; }

void Ekf::inject(const ErrVec& dx) {
  // x ← x ⊞ δx (F8), in place: the arithmetic of boxPlus without copying the state twice
  x_.w_p_b += dx.segment<3>(kPos);
  x_.w_v_b += dx.segment<3>(kVel);
  x_.w_q_b = (x_.w_q_b * expQuat(dx.segment<3>(kAtt))).normalized();
  x_.b_acc_bias += dx.segment<3>(kAccBias);
  x_.b_gyro_bias += dx.segment<3>(kGyroBias);
}

}  // namespace uwb
