/** @file RestGyroWindow.cpp
 *  @brief Window statistics of the gyro at rest (docs/math/filter.md F18z).
 */
#include "uwb/filter/RestGyroWindow.h"

#include <stdexcept>

namespace uwb {

RestGyroWindow::RestGyroWindow(double window_s, int min_samples) : window_s_(window_s), min_samples_(min_samples) {
  if (!(window_s > 0.0) || min_samples < 2)
    throw std::invalid_argument("RestGyroWindow: window_s must be > 0 and min_samples ≥ 2");
}

void RestGyroWindow::clear() {
  sum_.setZero();
  sum_sq_.setZero();
  n_ = 0;
}

std::optional<GyroWindowStats> RestGyroWindow::add(double t_s, const Vec3& gyro_radps) {
  if (!gyro_radps.allFinite()) return std::nullopt;
  if (n_ == 0) t0_s_ = t_s;
  sum_ += gyro_radps;
  sum_sq_ += gyro_radps.cwiseProduct(gyro_radps);
  ++n_;
  if (t_s - t0_s_ < window_s_) return std::nullopt;
  std::optional<GyroWindowStats> out;
  if (n_ >= min_samples_) {
    // (F18z) ω̄ = Σω/n, var(ω̄) = s²/n with the unbiased sample variance s² = (Σω² − n ω̄²)/(n − 1)
    const double n = static_cast<double>(n_);
    GyroWindowStats s;
    s.n = n_;
    s.mean_radps = sum_ / n;
    const Vec3 sample_var = ((sum_sq_ - n * s.mean_radps.cwiseProduct(s.mean_radps)) / (n - 1.0)).cwiseMax(0.0);
    s.mean_var_radps2 = sample_var / n;
    out = s;
  }
  clear();
  return out;
}

}  // namespace uwb
