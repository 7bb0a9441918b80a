/** @file Cooperative.h
 *  @brief Cooperative localization by Gaussian message passing (paper III-A, last paragraph; Li et al., Signal
 *         Processing 111, 2015): TDoA nodes whose "anchors" are other agents with their own uncertainty
 *         (docs/math/message-passing.md G19, built from G4, G11–G14).
 *
 *  Variables are 3-D positions (agents or anchors), each with a Gaussian prior (zero covariance allowed for a
 *  surveyed anchor). Each TDoA factor connects a receiver k and two transmitters i, j:
 *  z = |x_k − x_i| − |x_k − x_j| + ε (paper eq. 2 order; UTIL data: i = anchor B, j = anchor A).
 *  One iteration: every variable sends its extrinsic belief (prior ⊙ all other factors' messages, G4) to each factor;
 *  every factor relinearizes at those means (eq. 4) and sends G13/G14 back. On a tree one iteration is exact for the
 *  linearized model; with loops (two agents measuring each other) it is loopy Gaussian belief propagation.
 */
#pragma once

#include <optional>
#include <vector>

#include "uwb/graph/GaussianMessage.h"

namespace uwb {

/// One TDoA between variables (indices into the beliefs vector): receiver k, transmitters i and j.
struct CooperativeTdoa {
  int k = 0;
  int i = 1;
  int j = 2;
  double z_m = 0.0;     ///< measured (bias-corrected) TDoA [m]
  double var_m2 = 0.0;  ///< its variance [m²], > 0
};

/// Posterior beliefs of all variables after `iterations` rounds of message passing (≥ 1). Measurements whose
/// geometry is degenerate at the current means are skipped. Throws std::invalid_argument on bad indices.
std::vector<Moments3> cooperativeTdoaUpdate(const std::vector<Moments3>& priors,
                                            const std::vector<CooperativeTdoa>& measurements, int iterations = 1);

}  // namespace uwb
