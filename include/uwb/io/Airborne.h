/** @file Airborne.h
 *  @brief The one definition of "airborne" used by every evaluation, residual statistic and simulator flag:
 *         ground-truth body z strictly above kAirborneMinZ_m in the world frame (util-pilot SOURCE.md evaluates
 *         the airborne part of a flight with this threshold; on the ground the TDoA is grossly wrong).
 */
#pragma once

namespace uwb {

/// Airborne threshold on the ground-truth body height in the world frame [m].
inline constexpr double kAirborneMinZ_m = 0.3;

/// True when a body at world height w_z_m counts as airborne: w_z_m > min_z_m (default kAirborneMinZ_m).
constexpr bool isAirborne(double w_z_m, double min_z_m = kAirborneMinZ_m) { return w_z_m > min_z_m; }

}  // namespace uwb
