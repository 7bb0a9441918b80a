/** @file TdoaResiduals.h
 *  @brief TDoA residuals against a flight's ground truth: r = tdoa_meas − h(p_gt), with h the TDoA model of
 *         model/TdoaModel.h (paper eq. 1–2, docs/math/measurement.md M1–M2) and the tag lever arm b_t_tag. For
 *         position-only tracks (util-final-extract) the lever arm is added in the world frame (identity attitude),
 *         as that data's SOURCE.md prescribes.
 *
 *  The measurement model applied to recorded data: above model and io (the layering of docs/CONTRIBUTING.md), in
 *  the lowest module that has both. Used by the simulator's residual profile (sim/ResidualProfile.h),
 *  `uwbtdoa inspect` (eval/FlightSummary.h), GP training-data extraction and `predict-bias`.
 */
#pragma once

#include <cstddef>
#include <vector>

#include "uwb/core/Types.h"
#include "uwb/io/Airborne.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"
#include "uwb/io/PoseTrack.h"

namespace uwb {

/// Settings of the residual computation.
struct TdoaResidualParams {
  Vec3 b_t_tag = kUtilTagOffset_b;  ///< tag (antenna) offset in the body frame [m]
  double airborne_min_z_m = kAirborneMinZ_m;  ///< isAirborne threshold on the ground-truth body z [m]
};

/// One TDoA measurement compared with the ground truth.
struct TdoaResidual {
  std::size_t index = 0;  ///< index into Flight::tdoa
  double t_s = 0.0;
  int id_a = 0;
  int id_b = 0;
  double measured_m = 0.0;   ///< tdoa_meas
  double predicted_m = 0.0;  ///< |p_tag − a_B| − |p_tag − a_A| at the ground truth
  double residual_m = 0.0;   ///< measured_m − predicted_m (the measurement bias + noise the GP learns)
  Vec3 w_p_b = Vec3::Zero();      ///< interpolated ground-truth body position [m]
  Quat w_q_b = Quat::Identity();  ///< interpolated ground-truth attitude (identity for position-only tracks)
  bool airborne = false;          ///< isAirborne(w_p_b.z(), airborne_min_z_m)
};

/// What tdoaResiduals could not compare (nothing is dropped silently).
struct TdoaResidualReport {
  std::size_t n_measurements = 0;     ///< flight.tdoa.size()
  std::size_t n_residuals = 0;        ///< returned
  std::size_t n_no_ground_truth = 0;  ///< outside the pose track or in a gap > max_gap_s
  std::size_t n_unknown_anchor = 0;   ///< an anchor id missing from the survey
};

/// Residual of every TDoA measurement that has ground truth, in measurement order. See the file comment.
std::vector<TdoaResidual> tdoaResiduals(const Flight& flight, const AnchorSurvey& survey, const PoseTrack& track,
                                        const TdoaResidualParams& params = {}, TdoaResidualReport* report = nullptr);

}  // namespace uwb
