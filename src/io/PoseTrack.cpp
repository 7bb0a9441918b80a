/** @file PoseTrack.cpp
 *  @brief Ground-truth track: glitch rejection, interpolation, TDoA residuals (docs/io.md, "Ground truth").
 */
#include "uwb/io/PoseTrack.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>


namespace uwb {

void PoseTrackParams::validate() const {
  const auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      throw std::invalid_argument(fmt::format("PoseTrackParams::{} must be positive and finite, got {}", name, v));
    }
  };
  positive(max_gap_s, "max_gap_s");
  positive(max_attitude_jump_rad, "max_attitude_jump_rad");
  if (!(max_angular_rate_radps >= 0.0)) throw std::invalid_argument("PoseTrackParams::max_angular_rate_radps < 0");
  positive(max_glitch_run_s, "max_glitch_run_s");
  positive(max_position_jump_m, "max_position_jump_m");
}

namespace {

/// Rotation angle between two (not necessarily unit) quaternions, in [0, π]; q and −q are the same rotation.
double angleBetween(const Quat& a, const Quat& b) {
  const Quat d = a.normalized().conjugate() * b.normalized();
  return 2.0 * std::atan2(d.vec().norm(), std::abs(d.w()));
}

/// Attitude glitches: a sequential scan that compares each sample with the last accepted one. A sample whose angle
/// to it exceeds jump + rate·Δt is rejected; a rejected run lasting longer than max_glitch_run_s is real motion
/// (the reference was wrong), so it is accepted again and the reference moves to it.
void detectAttitudeGlitches(const std::vector<PoseSample>& s, const PoseTrackParams& params,
                            std::vector<char>& rejected, std::vector<double>& magnitude) {
  const std::size_t n = s.size();
  if (n < 2) return;
  // Start from the first sample that agrees with its next two neighbours (a glitch rarely does).
  std::size_t start = 0;
  for (std::size_t i = 0; i + 2 < n; ++i) {
    if (angleBetween(s[i].w_q_b, s[i + 1].w_q_b) < params.max_attitude_jump_rad &&
        angleBetween(s[i].w_q_b, s[i + 2].w_q_b) < params.max_attitude_jump_rad) {
      start = i;
      break;
    }
  }
  const auto scan = [&](std::size_t from, int step) {
    std::size_t ref = from;
    std::vector<std::size_t> run;
    for (std::ptrdiff_t k = static_cast<std::ptrdiff_t>(from) + step; k >= 0 && k < static_cast<std::ptrdiff_t>(n);
         k += step) {
      const std::size_t i = static_cast<std::size_t>(k);
      const double dt = std::abs(s[i].t_s - s[ref].t_s);
      const double angle = angleBetween(s[ref].w_q_b, s[i].w_q_b);
      if (angle > params.max_attitude_jump_rad + params.max_angular_rate_radps * dt) {
        run.push_back(i);
        rejected[i] = 1;
        magnitude[i] = angle;
        if (std::abs(s[i].t_s - s[run.front()].t_s) > params.max_glitch_run_s) {
          for (std::size_t j : run) rejected[j] = 0;  // a lasting change is motion, not a glitch
          run.clear();
          ref = i;
        }
      } else {
        run.clear();
        ref = i;
      }
    }
  };
  scan(start, +1);
  scan(start, -1);
}

}  // namespace

PoseTrack::PoseTrack(const Flight& flight, const PoseTrackParams& params)
    : PoseTrack(flight.pose, flight.pose_has_orientation, params) {}

PoseTrack::PoseTrack(const std::vector<PoseSample>& samples, bool has_orientation, const PoseTrackParams& params)
    : params_(params), has_orientation_(has_orientation), n_input_(samples.size()) {
  params_.validate();
  const std::size_t n = samples.size();
  for (std::size_t i = 1; i < n; ++i) {
    if (samples[i].t_s < samples[i - 1].t_s) {
      throw std::invalid_argument(fmt::format("PoseTrack: samples not sorted by time at index {} ({} after {})", i,
                                              samples[i].t_s, samples[i - 1].t_s));
    }
  }
  std::vector<char> att_rejected(n, 0);
  std::vector<double> att_magnitude(n, 0.0);
  if (has_orientation) detectAttitudeGlitches(samples, params_, att_rejected, att_magnitude);

  // Position spikes, among the samples with a valid attitude (a flipped Vicon solution also shifts the position
  // by ~1.5 cm, so its samples must not serve as neighbours): farther from the neighbours' chord than the
  // neighbours are from each other, and farther than max_position_jump_m.
  std::vector<std::size_t> kept;
  kept.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (att_rejected[i] == 0) kept.push_back(i);
  }
  std::vector<char> pos_rejected(n, 0);
  std::vector<double> pos_magnitude(n, 0.0);
  for (std::size_t k = 1; k + 1 < kept.size(); ++k) {
    const PoseSample& a = samples[kept[k - 1]];
    const PoseSample& b = samples[kept[k + 1]];
    const PoseSample& c = samples[kept[k]];
    const double span_t = b.t_s - a.t_s;
    const double u = span_t > 0.0 ? (c.t_s - a.t_s) / span_t : 0.5;
    const Vec3 chord = a.w_p_b + u * (b.w_p_b - a.w_p_b);
    const double dev = (c.w_p_b - chord).norm();
    if (dev > params_.max_position_jump_m && dev > (b.w_p_b - a.w_p_b).norm()) {
      pos_rejected[kept[k]] = 1;
      pos_magnitude[kept[k]] = dev;
    }
  }

  samples_.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (att_rejected[i] != 0) {
      glitches_.push_back({i, samples[i].t_s, PoseGlitchKind::kAttitude, att_magnitude[i]});
    } else if (pos_rejected[i] != 0) {
      glitches_.push_back({i, samples[i].t_s, PoseGlitchKind::kPosition, pos_magnitude[i]});
    } else {
      PoseSample p = samples[i];
      p.w_q_b = has_orientation ? p.w_q_b.normalized() : Quat::Identity();
      samples_.push_back(p);
    }
  }
}

double PoseTrack::startTime() const { return samples_.empty() ? 0.0 : samples_.front().t_s; }
double PoseTrack::endTime() const { return samples_.empty() ? 0.0 : samples_.back().t_s; }

std::size_t PoseTrack::countGlitches(PoseGlitchKind kind) const {
  return static_cast<std::size_t>(
      std::count_if(glitches_.begin(), glitches_.end(), [kind](const PoseGlitch& g) { return g.kind == kind; }));
}

std::optional<PoseSample> PoseTrack::interpolate(double t_s) const {
  return interpolatePose(samples_, t_s, params_.max_gap_s, has_orientation_);
}

}  // namespace uwb
