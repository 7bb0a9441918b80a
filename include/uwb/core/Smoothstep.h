/** @file Smoothstep.h
 *  @brief The cubic smoothstep, used where a quantity fades in or out over an interval: the simulator's floor-level
 *         bias and NLOS shadow (docs/math/simulation.md S18) and the filter's fade of the floor-level delays
 *         (docs/math/filter.md F16f).
 */
#pragma once

#include <algorithm>

namespace uwb {

/// S(x) = 3x² − 2x³ on [0, 1], x clamped to [0, 1]: S(0) = 0, S(1) = 1, S′(0) = S′(1) = 0.
inline double smoothstep3(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

}  // namespace uwb
