/** @file Cooperative.cpp
 *  @brief Loopy Gaussian belief propagation over TDoA nodes between agents (docs/math/message-passing.md G19).
 */
#include "uwb/graph/Cooperative.h"

#include <array>
#include <stdexcept>

#include "uwb/graph/Nodes.h"
#include "uwb/graph/TdoaNode.h"

namespace uwb {
namespace {

Information3 zeroInformation() { return {Vec3::Zero(), Mat3::Zero()}; }

/// Prior ⊙ sum of information messages (G3 then G4), as 3-D moments.
Moments3 combine(const Moments3& prior, const Information3& incoming) {
  const std::optional<Moments> z = equality(Moments{prior.m, prior.V}, Information{incoming.xi, incoming.W});
  if (!z) return prior;  // cannot happen for V ⪰ 0, W ⪰ 0 (G4); keep the prior rather than a NaN
  return {z->m, z->V};
}

}  // namespace

std::vector<Moments3> cooperativeTdoaUpdate(const std::vector<Moments3>& priors,
                                            const std::vector<CooperativeTdoa>& measurements, int iterations) {
  const int n = static_cast<int>(priors.size());
  if (iterations < 1) throw std::invalid_argument("cooperativeTdoaUpdate: iterations must be >= 1");
  for (const CooperativeTdoa& f : measurements) {
    for (int v : {f.k, f.i, f.j}) {
      if (v < 0 || v >= n) throw std::invalid_argument("cooperativeTdoaUpdate: variable index out of range");
    }
    if (f.k == f.i || f.k == f.j || f.i == f.j) throw std::invalid_argument("cooperativeTdoaUpdate: repeated variable");
  }
  // factor → variable messages, [factor][0 = k, 1 = i, 2 = j], information form (G13, G14)
  std::vector<std::array<Information3, 3>> to_var(measurements.size(),
                                                  {zeroInformation(), zeroInformation(), zeroInformation()});
  std::vector<Information3> total(n, zeroInformation());  // sum of incoming factor messages per variable (G3)
  for (int it = 0; it < iterations; ++it) {
    std::vector<std::array<Information3, 3>> next = to_var;
    for (std::size_t f = 0; f < measurements.size(); ++f) {
      const CooperativeTdoa& m = measurements[f];
      const std::array<int, 3> idx{m.k, m.i, m.j};
      std::array<Moments3, 3> extrinsic;  // variable → factor: prior ⊙ all other factors (G3, G4)
      for (int r = 0; r < 3; ++r) {
        const Information3 others{total[idx[r]].xi - to_var[f][r].xi, total[idx[r]].W - to_var[f][r].W};
        extrinsic[r] = combine(priors[idx[r]], others);
      }
      const auto lin = linearizeTdoa(extrinsic[0].m, extrinsic[1].m, extrinsic[2].m);  // eq. (4) at current means
      if (!lin) {
        next[f] = {zeroInformation(), zeroInformation(), zeroInformation()};
        continue;
      }
      next[f][0] = tdoaNodeForward(*lin, extrinsic[1], extrinsic[2], m.z_m, m.var_m2).mu8;        // G13
      next[f][1] = tdoaNodeBackwardToI(*lin, extrinsic[0], extrinsic[2], m.z_m, m.var_m2);         // G14
      next[f][2] = tdoaNodeBackwardToJ(*lin, extrinsic[0], extrinsic[1], m.z_m, m.var_m2);         // G14
    }
    to_var = std::move(next);  // parallel ("flooding") schedule: every agent uses last round's messages
    for (Information3& t : total) t = zeroInformation();
    for (std::size_t f = 0; f < measurements.size(); ++f) {
      const std::array<int, 3> idx{measurements[f].k, measurements[f].i, measurements[f].j};
      for (int r = 0; r < 3; ++r) {
        total[idx[r]].xi += to_var[f][r].xi;
        total[idx[r]].W += to_var[f][r].W;
      }
    }
  }
  std::vector<Moments3> posteriors(n);
  for (int v = 0; v < n; ++v) posteriors[v] = combine(priors[v], total[v]);  // belief = prior ⊙ all messages (G4)
  return posteriors;
}

}  // namespace uwb
