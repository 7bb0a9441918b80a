/** @file TdoaLinearization.cpp
 *  @brief B1, B2, D of paper eq. (4) (docs/math/measurement.md M6–M8).
 */
#include "uwb/model/TdoaLinearization.h"

namespace uwb {

std::optional<TdoaLinearization> linearizeTdoa(const Vec3& x_k, const Vec3& x_i, const Vec3& x_j,
                                               double min_range_m) {
  const Vec3 d_ki = x_k - x_i;  // d̃_ki = x̃_k − x̃_i
  const Vec3 d_kj = x_k - x_j;
  const double r_ki = d_ki.norm();
  const double r_kj = d_kj.norm();
  if (!(r_ki >= min_range_m) || !(r_kj >= min_range_m)) return std::nullopt;  // gradient of the norm undefined
  TdoaLinearization lin;
  lin.B1 = d_ki.transpose() / r_ki;  // (M7) B1 = d̃_kiᵀ / d̃_ki
  lin.B2 = d_kj.transpose() / r_kj;  //      B2 = d̃_kjᵀ / d̃_kj
  // (M7) D = d̃_ki − d̃_kj − B1 d̃_ki + B2 d̃_kj  (= 0 up to rounding, since B1 d̃_ki = d̃_ki; kept as in the paper)
  lin.D = r_ki - r_kj - lin.B1.dot(d_ki) + lin.B2.dot(d_kj);
  return lin;
}

}  // namespace uwb
