/** @file FloorLevelAnchors.cpp
 *  @brief Floor-level anchors and their delays on the floor (docs/math/filter.md F16f).
 */
#include "uwb/filter/FloorLevelAnchors.h"

#include <algorithm>
#include <cmath>

#include "uwb/core/Smoothstep.h"

namespace uwb {

FloorLevelAnchors::FloorLevelAnchors(const AnchorTable& anchors, double floor_z_m, double max_height_m) {
  for (const int id : anchors.ids()) {
    const Moments3* a = anchors.find(id);
    if (!a || !(max_height_m > 0.0) || !(a->m.z() - floor_z_m < max_height_m)) continue;
    const auto i = static_cast<std::size_t>(id);
    if (floor_level_.size() <= i) floor_level_.resize(i + 1, 0);
    floor_level_[i] = 1;
    ++n_floor_level_;
  }
  delay_m_.assign(floor_level_.size(), 0.0);
}

bool FloorLevelAnchors::isFloorLevel(int id) const {
  return id >= 0 && static_cast<std::size_t>(id) < floor_level_.size() && floor_level_[static_cast<std::size_t>(id)];
}

void FloorLevelAnchors::setDelays(const std::vector<double>& delay_m) {
  has_delays_ = false;
  for (std::size_t id = 0; id < delay_m_.size(); ++id) {
    const bool known = id < delay_m.size() && floor_level_[id] && std::isfinite(delay_m[id]);
    delay_m_[id] = known ? delay_m[id] : 0.0;
    has_delays_ = has_delays_ || known;
  }
}

double FloorLevelAnchors::delay(int id) const {
  return id >= 0 && static_cast<std::size_t>(id) < delay_m_.size() ? delay_m_[static_cast<std::size_t>(id)] : 0.0;
}

double FloorLevelAnchors::remainingFraction(double h_m) { return 1.0 - smoothstep3(h_m / kFadeHeight_m); }

double FloorLevelAnchors::nearerPairDelay(int id_a, int id_b, double residual_m) const {
  const double d = pairDelay(id_a, id_b);
  // |r − d| < |r|  ⇔  r d > d² / 2 (F16h)
  return residual_m * d > 0.5 * d * d ? d : 0.0;
}

void ClimbFromFloor::start(double t_s) {
  running_ = true;
  t_start_s_ = t_s;
  h_m_ = v_mps_ = 0.0;
}

void ClimbFromFloor::integrate(double t_s, double a_up_mps2, double dt_s) {
  if (!running_ || !(dt_s > 0.0)) return;
  h_m_ = std::max(0.0, h_m_ + v_mps_ * dt_s + 0.5 * a_up_mps2 * dt_s * dt_s);
  v_mps_ = h_m_ > 0.0 ? v_mps_ + a_up_mps2 * dt_s : std::max(0.0, v_mps_ + a_up_mps2 * dt_s);  // the floor holds it
  if (t_s - t_start_s_ > kMaxDuration_s || h_m_ > FloorLevelAnchors::kFadeHeight_m) running_ = false;
}

}  // namespace uwb
