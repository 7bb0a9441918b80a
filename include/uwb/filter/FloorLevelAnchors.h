/** @file FloorLevelAnchors.h
 *  @brief Anchors near the floor, and the range delay with which a body sitting on the floor sees each of them
 *         (docs/math/filter.md F16f).
 *
 *  A tag on the floor sees an anchor that is also near the floor along a grazing direct path that the floor, the
 *  body and clutter block; the first path to arrive is longer by metres (util-pilot, both sessions: the TDoA of a
 *  pair of one floor-level and one high anchor are off by 2.5–4.1 m on the floor, pairs of two high or two
 *  floor-level anchors by at most about 0.7 m; the simulator's S18 has the same form). The start on the floor solves
 *  one delay per floor-level anchor with the position (multilaterateOnFloorWithDelays); on the ground the TDoA are
 *  corrected by the delays found, and near the floor after a descent each TDoA takes them where it fits them (F16h).
 *  The delays are nuisance parameters of the floor, never used higher in the air.
 */
#pragma once

#include <vector>

#include "uwb/filter/TdoaUpdate.h"

namespace uwb {

class FloorLevelAnchors {
 public:
  FloorLevelAnchors() = default;
  /// Anchors with z − floor_z_m < max_height_m are floor-level; max_height_m ≤ 0 marks none.
  FloorLevelAnchors(const AnchorTable& anchors, double floor_z_m, double max_height_m);

  /// By anchor id: 1 for a floor-level anchor (the mask multilaterateOnFloorWithDelays takes).
  const std::vector<unsigned char>& mask() const { return floor_level_; }
  bool any() const { return n_floor_level_ > 0; }
  bool isFloorLevel(int id) const;

  /// The delays found on the floor, by anchor id (NaN: not found); entries for other anchors are ignored.
  void setDelays(const std::vector<double>& delay_m);
  bool hasDelays() const { return has_delays_; }
  /// The delay of a known floor-level anchor [m], 0 for any other.
  double delay(int id) const;
  /// (F16f) What the floor adds to a TDoA of pair (A, B), z = ‖p − a_B‖ − ‖p − a_A‖: g_B − g_A [m].
  double pairDelay(int id_a, int id_b) const { return delay(id_b) - delay(id_a); }
  /// (F16f) The fraction of the delays left at a height h above the resting height: 1 − S(h / h_f), S(x) = 3x² − 2x³
  /// on [0, 1], h_f = kFadeHeight_m (the real take-offs lose the floor-level bias over the first 12 cm, S18).
  static double remainingFraction(double h_m);
  /// (F16h) Near the floor in flight (a landing, a low pass) the tag is either within the floor-level bias or above
  /// it, and the IMU cannot tell which before the rest: each TDoA of pair (A, B) with residual r = z − h(x̂) (no floor
  /// correction) is taken to carry the delay g_B − g_A when r lies nearer to it than to 0, and none otherwise.
  /// Returns the delay to subtract from that TDoA [m] (0 or pairDelay).
  double nearerPairDelay(int id_a, int id_b, double residual_m) const;
  static constexpr double kFadeHeight_m = 0.12;

 private:
  std::vector<unsigned char> floor_level_;
  std::vector<double> delay_m_;  ///< by id, 0 where unknown
  int n_floor_level_ = 0;
  bool has_delays_ = false;
};

/// (F16f) The height above the floor of a body that left the ground without a detected climb (the ground evidence
/// ended while it still sat on the floor: rotors spun up without floor shaking), dead-reckoned from the accelerometer
/// alone from rest on the floor (h = 0, v = 0): the floor-level delays fade with the true height, which the estimate,
/// pulled by those very TDoA, does not know. It runs for at most kMaxDuration_s and ends above the fade height.
class ClimbFromFloor {
 public:
  static constexpr double kMaxDuration_s = 1.0;
  void start(double t_s);
  void clear() { running_ = false; }
  /// One IMU step: a_up = (R f)_z − g_ref [m/s²] over dt_s, at t_s.
  void integrate(double t_s, double a_up_mps2, double dt_s);
  bool running() const { return running_; }
  double height() const { return h_m_; }

 private:
  bool running_ = false;
  double t_start_s_ = 0.0, h_m_ = 0.0, v_mps_ = 0.0;
};

}  // namespace uwb
