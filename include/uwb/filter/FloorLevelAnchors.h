/** @file FloorLevelAnchors.h
 *  @brief Anchors near the floor, and the range delay with which a body sitting on the floor sees each of them
 *         (docs/math/filter.md F16f).
 *
 *  A tag on the floor sees an anchor that is also near the floor along a grazing direct path that the floor, the
 *  body and clutter block; the first path to arrive is longer by metres (util-pilot, both sessions: the TDoA of a
 *  pair of one floor-level and one high anchor are off by 2.5–4 m on the floor, pairs of two high or two
 *  floor-level anchors by at most about 0.5 m; the simulator's S18 has the same form). The start on the floor solves
 *  one delay per floor-level anchor with the position (multilaterateOnFloorWithDelays); on the ground the TDoA are
 *  corrected by the delays found. The delays are nuisance parameters of the floor, never used in the air.
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

 private:
  std::vector<unsigned char> floor_level_;
  std::vector<double> delay_m_;  ///< by id, 0 where unknown
  int n_floor_level_ = 0;
  bool has_delays_ = false;
};

}  // namespace uwb
