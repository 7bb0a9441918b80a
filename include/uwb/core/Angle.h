/** @file Angle.h
 *  @brief Angles on the circle: the one wrap used by the filter's heading (docs/math/filter.md F28) and the
 *         evaluation's anchor-angle grid (paper Fig. 7).
 */
#pragma once

#include <cmath>

#include "uwb/core/Types.h"

namespace uwb {

/// The angle wrapped to [−π, π] (the IEEE remainder by 2π; an odd multiple of π may land on either end).
inline double wrapAngle(double a_rad) { return std::remainder(a_rad, 2.0 * kPi); }

}  // namespace uwb
