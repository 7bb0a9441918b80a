/** @file PoseTrack.h
 *  @brief Ground-truth pose track of a flight (Vicon pose logged on board).
 *
 *  - interpolatePose / bracketPose: the one pose interpolation of the project (linear in position, slerp in
 *    attitude) between the two samples around a time, for any sorted sequence of samples with t_s, w_p_b and w_q_b
 *    (ground-truth PoseSample, the filter's TrajectorySample). Used by PoseTrack, the GP training data
 *    (eval/BiasDataset), the trajectory metrics (eval/TrajectoryMetrics) and the simulator's residual statistics.
 *  - PoseTrack: the flight's pose samples minus detected glitches; interpolation at any time t, nullopt outside the
 *    track or across a gap longer than PoseTrackParams::max_gap_s.
 *  - Glitches (util-pilot SOURCE.md, "Caveats"): Vicon occasionally reports a flipped attitude (roll ≈ ±170°) for
 *    one or a few samples, and single-sample position spikes up to 0.23 m. They are detected, counted, reported
 *    and excluded from interpolation (docs/io.md, "Ground truth").
 *
 *  Used by: the TDoA residuals against ground truth (sim/TdoaResiduals.h), `uwbtdoa inspect`
 *  (eval/FlightSummary.h), GP training-data extraction and evaluation.
 */
#pragma once

#include <algorithm>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "uwb/core/Types.h"
#include "uwb/io/Airborne.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"

namespace uwb {

/// Position a + u (b − a) at the fraction u ∈ [0, 1] between two positions.
inline Vec3 interpolatePosition(const Vec3& w_p_a, const Vec3& w_p_b, double u) { return w_p_a + u * (w_p_b - w_p_a); }

/// Attitude slerp(q_a, q_b, u), renormalised, at the fraction u ∈ [0, 1] between two attitudes.
inline Quat interpolateAttitude(const Quat& w_q_a, const Quat& w_q_b, double u) {
  return w_q_a.slerp(u, w_q_b).normalized();
}

/// The two samples around a time and the fraction between them (u = 0 at `a`, 1 at `b`).
template <class Sample>
struct PoseBracket {
  const Sample* a = nullptr;
  const Sample* b = nullptr;
  double u = 0.0;
};

/// Brackets t_s in `samples` (sorted by t_s): a is the last sample with a.t_s ≤ t_s, b the next one (b = a at the
/// last sample). nullopt when `samples` is empty, t_s lies outside [front().t_s, back().t_s], or a and b are more
/// than max_gap_s apart.
template <class Sample>
std::optional<PoseBracket<Sample>> bracketPose(const std::vector<Sample>& samples, double t_s, double max_gap_s) {
  if (samples.empty() || !(t_s >= samples.front().t_s) || !(t_s <= samples.back().t_s)) return std::nullopt;
  const auto it =
      std::upper_bound(samples.begin(), samples.end(), t_s, [](double t, const Sample& s) { return t < s.t_s; });
  if (it == samples.end()) return PoseBracket<Sample>{&samples.back(), &samples.back(), 0.0};  // t_s == last time
  const Sample& b = *it;
  const Sample& a = *(it - 1);  // it != begin since t_s >= front().t_s
  const double dt = b.t_s - a.t_s;
  if (dt > max_gap_s) return std::nullopt;
  return PoseBracket<Sample>{&a, &b, dt > 0.0 ? (t_s - a.t_s) / dt : 0.0};
}

/// Pose at t_s between the samples of `samples` (sorted by t_s): interpolatePosition and, when has_orientation,
/// interpolateAttitude (identity otherwise). nullopt as for bracketPose.
template <class Sample>
std::optional<PoseSample> interpolatePose(const std::vector<Sample>& samples, double t_s, double max_gap_s,
                                          bool has_orientation = true) {
  const auto br = bracketPose(samples, t_s, max_gap_s);
  if (!br) return std::nullopt;
  PoseSample out;
  out.t_s = t_s;
  if (br->a == br->b) {
    out.w_p_b = br->a->w_p_b;
    out.w_q_b = has_orientation ? br->a->w_q_b : Quat::Identity();
    return out;
  }
  out.w_p_b = interpolatePosition(br->a->w_p_b, br->b->w_p_b, br->u);
  out.w_q_b = has_orientation ? interpolateAttitude(br->a->w_q_b, br->b->w_q_b, br->u) : Quat::Identity();
  return out;
}

/// Glitch detection and interpolation settings. Defaults fit the UTIL pilot logs (200–300 Hz Vicon).
struct PoseTrackParams {
  /// Longest interval between two accepted samples that is interpolated across [s].
  double max_gap_s = 0.05;
  /// Attitude glitch: angle between a sample and the last accepted attitude above
  /// max_attitude_jump_rad + max_angular_rate_radps · Δt.
  double max_attitude_jump_rad = 0.35;
  double max_angular_rate_radps = 10.0;
  /// A run of rejected attitudes that lasts longer than this is accepted as real motion (re-anchoring) [s].
  double max_glitch_run_s = 0.1;
  /// Position spike: a sample farther than this from the chord of its two neighbours (linear interpolation at
  /// its time) AND farther from that chord than the neighbours are from each other [m].
  double max_position_jump_m = 0.02;

  /// Throws std::invalid_argument naming the offending field.
  void validate() const;
};

enum class PoseGlitchKind { kAttitude, kPosition };

/// One rejected pose sample.
struct PoseGlitch {
  std::size_t index = 0;  ///< index into the input pose vector (Flight::pose)
  double t_s = 0.0;
  PoseGlitchKind kind = PoseGlitchKind::kAttitude;
  double magnitude = 0.0;  ///< attitude: angle to the reference [rad]; position: distance to the chord [m]
};

/// Ground truth as a function of time. Immutable after construction; cheap to query (binary search).
class PoseTrack {
 public:
  PoseTrack() = default;
  /// Builds the track from samples sorted by time (as Flight::pose is). has_orientation = false: position only,
  /// interpolated attitudes are identity and no attitude glitches are detected.
  PoseTrack(const std::vector<PoseSample>& samples, bool has_orientation, const PoseTrackParams& params = {});
  /// The flight's pose stream (uses flight.pose_has_orientation).
  explicit PoseTrack(const Flight& flight, const PoseTrackParams& params = {});

  /// Pose at time t_s: linear position, slerp attitude between the two accepted samples around t_s.
  /// nullopt when the track is empty, t_s is outside [startTime, endTime], or the bracketing samples are more than
  /// max_gap_s apart. The returned quaternion is unit norm.
  std::optional<PoseSample> interpolate(double t_s) const;

  bool empty() const { return samples_.empty(); }
  bool hasOrientation() const { return has_orientation_; }
  double startTime() const;  ///< first accepted sample [s]; 0 when empty
  double endTime() const;    ///< last accepted sample [s]; 0 when empty
  /// Accepted samples (quaternions normalised), sorted by time.
  const std::vector<PoseSample>& samples() const { return samples_; }
  /// Rejected samples, by input index.
  const std::vector<PoseGlitch>& glitches() const { return glitches_; }
  std::size_t countGlitches(PoseGlitchKind kind) const;
  /// Number of input samples.
  std::size_t inputSize() const { return n_input_; }
  const PoseTrackParams& params() const { return params_; }

 private:
  PoseTrackParams params_;
  bool has_orientation_ = false;
  std::vector<PoseSample> samples_;
  std::vector<PoseGlitch> glitches_;
  std::size_t n_input_ = 0;
};

}  // namespace uwb
