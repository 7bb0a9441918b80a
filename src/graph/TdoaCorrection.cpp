/** @file TdoaCorrection.cpp
 *  @brief Reference (dynamic-size) correction through the generic node functions (docs/math/message-passing.md
 *         G15–G18 via G9', G7, G4).
 */
#include "uwb/graph/TdoaCorrection.h"

#include <stdexcept>

#include "uwb/graph/Nodes.h"

namespace uwb {

std::optional<Moments> correctTdoaByMessages(const Moments& prior, const MatX& C, const Vec3& x_k_lin,
                                             const TdoaNodeMessages& msg) {
  if (C.rows() != 3 || C.cols() != prior.m.size()) throw std::invalid_argument("correctTdoaByMessages: C is not 3×n");
  const Information mu8{msg.mu8.xi, msg.mu8.W};                              // message on x_k (G13)
  const Information on_dx_plus = additionBackwardConstant(mu8, x_k_lin);     // x_k = x̃_k + (C δx)   (G9')
  const Information on_dx = multiplyBackward(C, on_dx_plus);                 // (C δx) = C · δx       (G7)
  return equality(prior, on_dx);                                              // prior = δx = message (G4)
}

}  // namespace uwb
