/** @file TdoaResiduals.cpp
 *  @brief TDoA residuals against ground truth (docs/math/measurement.md M2).
 */
#include "uwb/sim/TdoaResiduals.h"

#include <unordered_map>

#include "uwb/model/TdoaModel.h"

namespace uwb {

std::vector<TdoaResidual> tdoaResiduals(const Flight& flight, const AnchorSurvey& survey, const PoseTrack& track,
                                        const TdoaResidualParams& params, TdoaResidualReport* report) {
  std::unordered_map<int, Vec3> anchors;
  for (const Anchor& a : survey.anchors) anchors.emplace(a.id, a.w_p);
  TdoaResidualReport rep;
  rep.n_measurements = flight.tdoa.size();
  std::vector<TdoaResidual> out;
  out.reserve(flight.tdoa.size());
  for (std::size_t k = 0; k < flight.tdoa.size(); ++k) {
    const TdoaMeasurement& m = flight.tdoa[k];
    const auto ia = anchors.find(m.id_a);
    const auto ib = anchors.find(m.id_b);
    if (ia == anchors.end() || ib == anchors.end()) {
      ++rep.n_unknown_anchor;
      continue;
    }
    const std::optional<PoseSample> gt = track.interpolate(m.t_s);
    if (!gt) {
      ++rep.n_no_ground_truth;
      continue;
    }
    TdoaResidual r;
    r.index = k;
    r.t_s = m.t_s;
    r.id_a = m.id_a;
    r.id_b = m.id_b;
    r.measured_m = m.tdoa_m;
    r.w_p_b = gt->w_p_b;
    r.w_q_b = gt->w_q_b;  // identity for position-only tracks: the lever arm is then added in the world frame
    // docs/math/measurement.md (M2), paper eq. (2): |p_tag − a_B| − |p_tag − a_A|
    r.predicted_m = predictTdoa(r.w_p_b, r.w_q_b, params.b_t_tag, ia->second, ib->second);
    r.residual_m = r.measured_m - r.predicted_m;
    r.airborne = isAirborne(r.w_p_b.z(), params.airborne_min_z_m);
    out.push_back(r);
  }
  rep.n_residuals = out.size();
  if (report != nullptr) *report = rep;
  return out;
}

}  // namespace uwb
