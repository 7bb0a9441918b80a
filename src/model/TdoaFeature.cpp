/** @file TdoaFeature.cpp
 *  @brief Body-frame anchor positions and azimuths (paper III-B, Fig. 1; docs/math.md (M10–M11)).
 */
#include "uwb/model/TdoaFeature.h"

#include <cmath>

namespace uwb {

TdoaFeature makeTdoaFeature(int id_a, int id_b, const Vec3& w_p_b, const Quat& w_q_b, const Vec3& w_p_anchor_a,
                            const Vec3& w_p_anchor_b) {
  TdoaFeature f;
  f.id_a = id_a;
  f.id_b = id_b;
  const Mat3 b_R_w = w_q_b.toRotationMatrix().transpose();
  f.b_p_a = b_R_w * (w_p_anchor_a - w_p_b);  // (M10): x_k· = R_kᵀ (a − p_k)
  f.b_p_b = b_R_w * (w_p_anchor_b - w_p_b);
  f.yaw_a_rad = std::atan2(f.b_p_a.y(), f.b_p_a.x());  // (M11): α = atan2(y, x) of the body-frame direction
  f.yaw_b_rad = std::atan2(f.b_p_b.y(), f.b_p_b.x());
  f.w_p_b = w_p_b;
  f.w_p_anchor_a = w_p_anchor_a;
  f.w_p_anchor_b = w_p_anchor_b;
  return f;
}

}  // namespace uwb
