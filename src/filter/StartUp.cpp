/** @file StartUp.cpp
 *  @brief Start-up and re-acquisition by multilateration (docs/math/filter.md F16, F16b).
 */
#include "uwb/filter/StartUp.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace uwb {

StartUpParams StartUpParams::fromEkfParams(const EkfParams& p) {
  return {.window_s = p.start_window_s, .min_samples = static_cast<std::size_t>(p.start_min_samples),
          .max_window_s = p.start_max_window_s, .min_pos_sigma_m = p.start_min_pos_sigma_m,
          .max_pos_sigma_m = p.init_pos_sigma_m, .min_vel_sigma_mps = p.start_min_vel_sigma_mps,
          .box_margin_m = p.start_box_margin_m, .max_rms_residual_m = p.start_max_rms_residual_m,
          .floor_refute_height_m = p.floor_refute_height_m,
          .floor_refute_residual_ratio = p.floor_refute_residual_ratio, .max_speed_mps = p.start_max_speed_mps,
          .floor_height_sigma_m = p.start_floor_height_sigma_m};
}

StartUp::StartUp(const AnchorTable& anchors, const Vec3& b_t_tag, const StartUpParams& params)
    : anchors_(anchors), b_t_tag_(b_t_tag), params_(params) {
  const AnchorBox box = anchorBox(anchors_);  // throws when there are no anchors
  box_min_ = box.min;
  box_max_ = box.max;
  const Vec3& centroid = box.centroid;
  // starting guesses: near the floor, at flight height, at the anchors' centroid
  guesses_ = {Vec3(centroid.x(), centroid.y(), 0.5), Vec3(centroid.x(), centroid.y(), 1.5), centroid};
  samples_.reserve(4096);  // ≥ max_window_s of TDoA at the LPS rates: no allocation per event
}

void StartUp::begin(double t_s, const NavState& x_ref, bool moving, bool reacquisition) {
  active_ = true;
  moving_ = moving;
  reacquisition_ = reacquisition;
  t_ref_ = t_try_ = t_s;
  x_ref_ = x_ref;
  samples_.clear();
}

int StartUp::distinctAnchors() const {
  DistinctAnchors anchors;
  for (const MultilaterationSample& m : samples_) anchors.add(m.z.id_a, m.z.id_b);
  return anchors.count();
}

std::optional<StartFix> StartUp::add(const TdoaMeasurement& z, const NavState& x_now, std::optional<double> floor_z_m,
                                     bool floor_refutable) {
  if (!active_) return std::nullopt;
  // (F16b) displacement since t_ref from the prediction, without the reference velocity (that is v0's part)
  MultilaterationSample s;
  s.z = z;
  s.w_d_b = x_now.w_p_b - x_ref_.w_p_b - (z.t_s - t_ref_) * x_ref_.w_v_b;
  s.w_q_b = x_now.w_q_b;
  if (samples_.size() < samples_.capacity()) samples_.push_back(s);
  if (!(z.t_s - t_try_ >= params_.window_s && samples_.size() >= params_.min_samples)) return std::nullopt;

  const WindowSolve w = solveWindow(z.t_s, floor_z_m, floor_refutable);
  const std::optional<MultilaterationResult>& r = w.result;
  const bool inside = r && (!reacquisition_ || r->rms_residual_m <= params_.max_rms_residual_m) &&
                      (r->w_p0.array() >= box_min_.array() - params_.box_margin_m).all() &&
                      (r->w_p0.array() <= box_max_.array() + params_.box_margin_m).all() &&
                      (!w.moving || r->w_v0.norm() < params_.max_speed_mps);
  if (!inside) {
    retryLater(z.t_s, x_now);
    return std::nullopt;
  }
  const StartFix fix = fixNow(w, z.t_s, x_now);
  active_ = false;
  samples_.clear();
  return fix;
}

StartUp::WindowSolve StartUp::solveWindow(double t_now_s, std::optional<double> floor_z_m,
                                          bool floor_refutable) const {
  WindowSolve w;
  w.moving = moving_ && !floor_z_m;
  w.on_floor = floor_z_m.has_value();
  std::optional<MultilaterationResult>& r = w.result;
  // (F16k) with fewer anchors in the window than a fix needs, wait for more
  const int n_anchors = distinctAnchors();
  const bool solvable = n_anchors >= minFixAnchors(floor_z_m.has_value());
  if (solvable && floor_z_m) {
    // (F16f) with floor-level anchors, their delays are solved for; without 3 other anchors in view, the plain solve
    // (F29e) not at a floor check: the floor's delays were solved at the start, and solving them again would let
    // the floor explain any window
    if (!floor_level_.empty() && !(floor_refutable && reacquisition_))
      r = multilaterateOnFloorWithDelays(samples_, anchors_, b_t_tag_, guesses_, *floor_z_m, floor_level_);
    if (!r) r = multilaterateOnFloor(samples_, anchors_, b_t_tag_, guesses_, *floor_z_m);
    // (F16j) at the first start, floor contact (F18) is tested against the TDoA (by a solve in the air: F16k)
    // and at a floor check in floor contact (F29e): the caller says when the floor may be refuted
    if (r && floor_refutable && n_anchors >= minFixAnchors(false)) {
      if (std::optional<MultilaterationResult> in_air = refuteFloor(*r, *floor_z_m, t_now_s)) {
        r = in_air;
        w.moving = w.floor_refuted = true;
        w.on_floor = false;
      }
    }
  } else if (solvable) {
    r = w.moving ? multilaterateMoving(samples_, anchors_, b_t_tag_, guesses_, t_ref_)
                 : multilaterate(samples_, anchors_, b_t_tag_, guesses_);
  }
  return w;
}

void StartUp::retryLater(double t_now_s, const NavState& x_now) {
  // keep the most recent part and try again later (the earliest samples are the worst: take-off, faults)
  const double t_keep = t_now_s - std::min(params_.max_window_s, 0.5 * params_.window_s);
  std::erase_if(samples_, [&](const MultilaterationSample& m) { return m.z.t_s < t_keep; });
  t_try_ = t_now_s - 0.5 * params_.window_s;
  // (F16b) the reference moves to the newest prediction: a displacement predicted over a long failed search
  // (seconds of IMU dead reckoning) would put p0 and v0 out of bounds however good the fresh TDoA are.
  // d'_i = p̂(t_i) − p̂_now − (t_i − t_now) v̂_now with p̂(t_i) = d_i + p̂_ref + (t_i − t_ref) v̂_ref.
  for (MultilaterationSample& m : samples_)
    m.w_d_b += x_ref_.w_p_b - x_now.w_p_b + (m.z.t_s - t_ref_) * x_ref_.w_v_b - (m.z.t_s - t_now_s) * x_now.w_v_b;
  x_ref_ = x_now;
  t_ref_ = t_now_s;
}

StartFix StartUp::fixNow(const WindowSolve& w, double t_now_s, const NavState& x_now) const {
  const MultilaterationResult& r = *w.result;
  const bool moving = w.moving;
  StartFix fix;
  fix.with_velocity = moving;
  fix.floor_refuted = w.floor_refuted;
  fix.w_p0 = r.w_p0;
  fix.w_v0 = moving ? r.w_v0 : x_ref_.w_v_b;
  fix.t_ref_s = t_ref_;
  fix.rms_residual_m = r.rms_residual_m;
  fix.anchor_delay_m = r.anchor_delay_m;
  const double T = t_now_s - t_ref_;
  const Vec3 d_now = x_now.w_p_b - x_ref_.w_p_b - T * x_ref_.w_v_b;
  // (F16b) p_now = p0 + v0 T + d_now, v_now = v0 + (v_pred_now − v_pred_ref)
  Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Identity();
  Eigen::Matrix<double, 6, 6> S = Eigen::Matrix<double, 6, 6>::Zero();
  if (moving) {
    fix.w_p_b = r.w_p0 + T * r.w_v0 + d_now;
    fix.w_v_b = r.w_v0 + (x_now.w_v_b - x_ref_.w_v_b);
    J.block<3, 3>(0, 3) = T * Mat3::Identity();
    S = J * r.covariance_pv * J.transpose();
  } else {
    fix.w_p_b = r.w_p0 + d_now;
    fix.w_v_b = x_now.w_v_b;
    S.block<3, 3>(0, 0) = r.covariance;
  }
  // floors on the stds: the solve's own covariance ignores the correlated TDoA bias
  const double sp = std::clamp(std::sqrt(S.block<3, 3>(0, 0).trace() / 3.0), params_.min_pos_sigma_m,
                               params_.max_pos_sigma_m);
  const double sv = moving ? std::max(std::sqrt(S.block<3, 3>(3, 3).trace() / 3.0), params_.min_vel_sigma_mps)
                           : params_.min_vel_sigma_mps;
  fix.cov.setZero();
  fix.cov.block<3, 3>(0, 0) = sp * sp * Mat3::Identity();
  // on the floor: the height is known to a few cm (F16c, F22)
  if (w.on_floor) fix.cov(2, 2) = params_.floor_height_sigma_m * params_.floor_height_sigma_m;
  fix.cov.block<3, 3>(3, 3) = sv * sv * Mat3::Identity();
  return fix;
}

std::optional<MultilaterationResult> StartUp::refuteFloor(const MultilaterationResult& on_floor, double floor_z_m,
                                                          double t_now_s) const {
  // (F16j) On a floor the floor-level TDoA bias puts the free solve metres off, mostly above the room (util-pilot:
  // z = 3.6…10 m, RMS residual 1.2…2.3 times the floor solve's). A body in the air is where the free solve says,
  // inside the anchors' box, and the floor solve fits it only with invented delays. A window that holds a take-off
  // (the body still near the floor at one end) is not refuted: the take-off detector (F15) restarts it in motion.
  const std::optional<MultilaterationResult> free = multilaterate(samples_, anchors_, b_t_tag_, guesses_);
  if (!free) return std::nullopt;
  const Vec3& p = free->w_p0;
  const bool inside = (p.head<2>().array() >= box_min_.head<2>().array() - params_.box_margin_m).all() &&
                      (p.head<2>().array() <= box_max_.head<2>().array() + params_.box_margin_m).all() &&
                      p.z() <= box_max_.z();
  if (!inside || p.z() - floor_z_m < params_.floor_refute_height_m ||
      free->rms_residual_m > params_.floor_refute_residual_ratio * on_floor.rms_residual_m)
    return std::nullopt;
  std::optional<MultilaterationResult> moving = multilaterateMoving(samples_, anchors_, b_t_tag_, guesses_, t_ref_);
  if (!moving) return std::nullopt;
  const double z_first = moving->w_p0.z(), z_last = z_first + (t_now_s - t_ref_) * moving->w_v0.z();
  if (std::min(z_first, z_last) - floor_z_m < params_.floor_refute_height_m) return std::nullopt;
  return moving;
}

}  // namespace uwb
