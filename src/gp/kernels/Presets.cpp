/** @file Presets.cpp
 *  @brief The paper's kernel compositions (eq. 7–9, docs/math/gp.md P6) and those of the pair presets (P26b, P29).
 */
#include "uwb/gp/kernels/Presets.h"

#include <stdexcept>

namespace uwb::gp {

Kernel Kernel::preset(const std::string& name) {
  if (name == "z1") {  // paper eq. (7): k_p(α_i) + k_p(α_j), T = 2π
    PartSpec a{PartType::kPeriodic, {0}, 0.05, {1.0}, {2.0 * kPi}};
    PartSpec b = a;
    b.active_dims = {1};
    return sum({a, b});
  }
  if (name == "z2") {  // paper eq. (8): Matérn-5/2(α_i) + Matérn-5/2(α_j)
    PartSpec a{PartType::kMatern52, {0}, 0.05, {1.0}};
    PartSpec b = a;
    b.active_dims = {1};
    return sum({a, b});
  }
  if (name == "tdoa") {  // paper eq. (9): k_L(x_ki) + k_L(x_kj)
    PartSpec a{PartType::kLedergerber, {0, 1, 2}, 0.05};
    a.t1 = 0.5;
    a.t2 = 4.0;
    PartSpec b = a;
    b.active_dims = {3, 4, 5};
    return sum({a, b});
  }
  throw std::invalid_argument("unknown kernel preset '" + name + "' (expected z1, z2 or tdoa)");
}

Kernel anchorTdoaKernel() {
  PartSpec la{PartType::kLedergerber, {0, 1, 2}, 0.05};
  la.t1 = 0.5;
  la.t2 = 4.0;
  PartSpec lb = la;
  lb.active_dims = {3, 4, 5};
  const PartSpec ra{PartType::kRbf, {6, 7, 8}, 1.0, {1.0}};
  PartSpec rb = ra;
  rb.active_dims = {9, 10, 11};
  Kernel k({la, ra, lb, rb}, {{0, 1}, {2, 3}});
  for (const auto& n : k.paramNames()) {
    if (n.find("rbf.sigma2") != std::string::npos) k.setTrainable(n, false);
  }
  return k;
}

Kernel positionMapKernel() {
  const PartSpec s{PartType::kRbf, {0, 1, 2}, 0.02, {0.5, 0.5, 0.5}};
  return Kernel::sum({s});
}

Kernel tdoaPositionKernel() {
  const Kernel eq9 = Kernel::preset("tdoa");
  std::vector<PartSpec> parts;
  for (int p = 0; p < eq9.numParts(); ++p) parts.push_back(eq9.partSpec(p));
  parts.push_back(PartSpec{PartType::kRbf, {6, 7, 8}, 0.02, {0.5, 0.5, 0.5}});
  return Kernel::sum(parts);
}

}  // namespace uwb::gp
