/** @file Presets.h
 *  @brief Named compositions of kernel parts: the paper's (Kernel::preset "z1", "z2", "tdoa": eq. 7–9,
 *         docs/math/gp.md P6) and those of the bias model's pair presets (eval/BiasModel.h), each with its
 *         starting parameters.
 */
#pragma once

#include "uwb/gp/Kernel.h"

namespace uwb::gp {

/// docs/math/gp.md (P29): k = k_L(x_A) k_rbf(a_A) + k_L(x_B) k_rbf(a_B) on 12 columns (the body-frame anchor
/// positions, then the anchors' world positions); the RBF outputscales are fixed to 1 (the product's scale is k_L's
/// θ0, paper eq. 9), the RBF length scale [m] sets how much anchors share. Preset "anchor-tdoa".
Kernel anchorTdoaKernel();
/// An RBF-ARD map over the 3 position columns (0.5 start length scale in standardized units). Preset "pair-pos".
Kernel positionMapKernel();
/// docs/math/gp.md (P26b): paper eq. 9 on the body-frame anchor positions (columns 0–5) plus an RBF-ARD map over
/// the arena (columns 6–8, raw metres: the k_L inputs must not be standardized). Preset "pair-tdoa-pos".
Kernel tdoaPositionKernel();

}  // namespace uwb::gp
