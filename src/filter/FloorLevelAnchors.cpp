/** @file FloorLevelAnchors.cpp
 *  @brief Floor-level anchors and their delays on the floor (docs/math/filter.md F16f).
 */
#include "uwb/filter/FloorLevelAnchors.h"

#include <cmath>

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

}  // namespace uwb
