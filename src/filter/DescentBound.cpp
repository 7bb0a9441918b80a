/** @file DescentBound.cpp
 *  @brief Dead-reckoned height bound while landing (docs/math/filter.md F26).
 */
#include "uwb/filter/DescentBound.h"

#include <algorithm>
#include <cmath>

namespace uwb {

void DescentBound::integrate(double a_up_mps2, double dt_s) {
  if (!valid_ || !(dt_s > 0.0)) return;
  // (F26) h ← h + v Δt + ½ a Δt², v ← v + a Δt; the body does not sink into the floor
  h_m_ += (v_mps_ + 0.5 * a_up_mps2 * dt_s) * dt_s;
  v_mps_ += a_up_mps2 * dt_s;
  if (h_m_ < 0.0) {
    h_m_ = 0.0;
    v_mps_ = std::max(v_mps_, 0.0);
  }
}

double DescentBound::update(double t_s, double h_est_m, double vz_est_mps) {
  // restart while the estimate is well above the floor and the dead reckoning does not contradict it: a climb
  // out of the band is confirmed by both
  if (h_est_m > params_.reset_height_m && (!valid_ || h_m_ >= params_.band_m)) {
    valid_ = true;
    h_m_ = h_est_m;
    v_mps_ = vz_est_mps;
    t_restart_s_ = t_s;
  }
  if (!valid_ || t_s - t_restart_s_ > params_.max_age_s || h_m_ >= params_.band_m)
    return std::numeric_limits<double>::quiet_NaN();
  return h_m_ + params_.margin_m;
}

}  // namespace uwb
