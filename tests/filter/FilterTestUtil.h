/** @file FilterTestUtil.h
 *  @brief Shared set-ups of the synthetic-flight filter tests: the UTIL-like anchor arena and a take-off profile.
 */
#pragma once

#include "uwb/filter/TdoaUpdate.h"

namespace uwb::filtertest {

/// 8 anchors alternating low/high on a 7 × 8 × 3 m box (as the UTIL arena).
inline AnchorTable arenaAnchors() {
  AnchorTable t;
  const Vec3 c[8] = {{-3, -4, 0.2}, {-3, 4, 3.0}, {3.5, 4, 0.2}, {4, -4, 3.0},
                     {-3, -4.2, 3.0}, {4, -3.8, 0.2}, {4, 4, 3.0}, {-3, 3.5, 0.2}};
  for (int i = 0; i < 8; ++i) t.set(i, c[i]);
  return t;
}

/// Height z [m], vertical velocity vz [m/s] and acceleration az [m/s²] of a take-off.
struct Vertical {
  double z, vz, az;
};

/// 2 s on the floor at 0.05 m, a 1 m climb (±1 m/s² for 1 s each), then hover at 1.05 m.
inline Vertical takeoffProfile(double t) {
  const double tc = t - 2.0;
  if (tc <= 0.0) return {0.05, 0.0, 0.0};
  if (tc <= 1.0) return {0.05 + 0.5 * tc * tc, tc, 1.0};
  if (tc <= 2.0) {
    const double s = tc - 1.0;
    return {0.55 + s - 0.5 * s * s, 1.0 - s, -1.0};
  }
  return {1.05, 0.0, 0.0};
}

}  // namespace uwb::filtertest
