/** @file RestGyroWindow.h
 *  @brief The gyro at rest, window by window: the mean reading of a body that does not turn is the gyro's bias, and
 *         the spread of the readings about it says how well one window knows it (docs/math/filter.md F18z). The
 *         estimator turns each full window into a zero-angular-rate update of its gyro-bias state.
 */
#pragma once

#include <optional>

#include "uwb/core/Types.h"

namespace uwb {

/// Mean and variance of the gyro over one window of readings taken at rest (F18z).
struct GyroWindowStats {
  Vec3 mean_radps = Vec3::Zero();
  Vec3 mean_var_radps2 = Vec3::Zero();  ///< variance of the mean: the readings' sample variance / their count
  int n = 0;
};

class RestGyroWindow {
 public:
  /// window_s: length of one window [s]; min_samples: fewer readings in a full window say nothing.
  RestGyroWindow(double window_s, int min_samples);

  /// Adds a reading at t_s. Returns the window's statistics when it is full (window_s since its first reading) and
  /// starts the next; nothing otherwise.
  std::optional<GyroWindowStats> add(double t_s, const Vec3& gyro_radps);
  /// Forgets the readings of the current window (the body left rest: a partial window may hold the turn).
  void clear();

 private:
  double window_s_;
  int min_samples_;
  double t0_s_ = 0.0;
  Vec3 sum_ = Vec3::Zero();
  Vec3 sum_sq_ = Vec3::Zero();
  int n_ = 0;
};

}  // namespace uwb
