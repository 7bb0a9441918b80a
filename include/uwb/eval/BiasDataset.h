/** @file BiasDataset.h
 *  @brief Training data for the TDoA bias GP from flights with ground truth (paper eq. 6, III-B;
 *         docs/math/gp.md P25).
 *
 *  For every TDoA measurement z (UTIL convention z = |p_tag − a_B| − |p_tag − a_A|):
 *    ε = z − (‖p_tag − a_B‖ − ‖p_tag − a_A‖),  p_tag = w_p_b + w_R_b b_t_tag        (paper eq. 6 with lever arm)
 *  and the GP inputs from the interpolated ground-truth pose (model/TdoaFeature.h: makeTdoaFeature).
 *  Exclusion rules are explicit, user-settable and each one's count is reported (util-pilot SOURCE.md Caveats).
 */
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "uwb/core/Types.h"
#include "uwb/eval/Localization.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"
#include "uwb/io/PoseTrack.h"
#include "uwb/model/TdoaFeature.h"

namespace uwb {

/// Where the GP inputs of a training sample come from. The target ε always comes from the ground truth (eq. 6).
enum class BiasInputSource {
  kGroundTruth,  ///< the ground-truth pose (the paper's reading of eq. 6)
  /// The uncorrected filter's own estimate on the training flight, as the GP will see it at run time (paper III-D:
  /// "the Kalman filter was run on the uncorrected data and the actual GP input was computed"). On util-pilot this
  /// is what makes the correction transfer: the run-time inputs carry the filter's position error (0.2–0.3 m).
  kFilterEstimate,
};
std::string toString(BiasInputSource source);
BiasInputSource biasInputSourceFromString(const std::string& name);  ///< "truth" | "estimate"

/// The exclusion rules, applied in this order; a sample is counted under the first rule that removes it.
struct BiasDatasetParams {
  BiasInputSource inputs = BiasInputSource::kGroundTruth;
  LocalizationOptions localization;  ///< the filter run for BiasInputSource::kFilterEstimate
  /// Bias correction of that filter run (empty: uncorrected). A second training pass sets it to the first pass's
  /// model, so the GP inputs carry the error of the corrected filter that will use the model (docs/math/gp.md P30).
  BiasPredictor estimate_bias;
  Vec3 b_t_tag = kUtilTagOffset_b;  ///< tag (antenna) offset in the body frame [m]
  double min_z_m = kAirborneMinZ_m;  ///< samples not isAirborne(ground-truth z, min_z_m) are excluded [m]
  double glitch_margin_s = 0.05;    ///< measurements within this time of a rejected (glitch) pose sample [s]
  double max_abs_error_m = 1.0;     ///< gross outliers: |ε| above this [m]; ≤ 0 disables the rule
  bool neighbour_pairs_only = false;  ///< keep only cyclic neighbour pairs (0,1)…(7,0) (UTIL TDoA2)
  PoseTrackParams pose_track;       ///< ground-truth glitch detection and interpolation
  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
};

/// One training sample: the feature from the ground-truth pose and the measurement error ε (paper eq. 6).
struct BiasSample {
  TdoaFeature feature;
  double error_m = 0.0;  ///< ε [m]
  double measured_m = 0.0;  ///< the measured TDoA [m] (the flight's tdoa_meas)
  double t_s = 0.0;
  int flight = 0;        ///< index of the source flight
};

/// Per-flight bookkeeping: every measurement lands in exactly one counter.
struct BiasFlightReport {
  std::string source;
  std::size_t n_measurements = 0;
  std::size_t n_unknown_anchor = 0;    ///< anchor id missing from the survey
  std::size_t n_no_ground_truth = 0;   ///< outside the pose track or in a pose gap
  std::size_t n_no_estimate = 0;       ///< outside the filter's trajectory (kFilterEstimate only)
  std::size_t n_pose_glitch = 0;       ///< within glitch_margin_s of a rejected pose sample
  std::size_t n_on_ground = 0;         ///< not isAirborne(ground-truth z, min_z_m)
  std::size_t n_non_neighbour = 0;     ///< non-neighbour pair (only when neighbour_pairs_only)
  std::size_t n_outlier = 0;           ///< |ε| > max_abs_error_m
  std::size_t n_used = 0;
  std::size_t n_pose_glitches_detected = 0;  ///< rejected pose samples (attitude + position)
  /// false for a position-only pose: the lever arm was added in the world frame and, with ground-truth inputs, the
  /// features took the level, unturned attitude (buildBiasDataset)
  bool orientation_from_truth = true;
  /// The TDoA bias level the filter measured in flight before any correction (filter.md F23c, F24b); NaN without a
  /// filter run (ground-truth inputs) or when it counted no window
  double bias_level_m = std::numeric_limits<double>::quiet_NaN();
  /// Samples the filter skipped outside the sensors' physical ranges (filter.md F31); none counted without a filter run
  SensorRangeReport sensor_range;
};

struct BiasDataset {
  std::vector<BiasSample> samples;
  std::vector<BiasFlightReport> flights;
  BiasDatasetParams params;

  /// Human-readable table of the exclusion counts per flight.
  std::string reportText() const;
};

/// Throws InputError (naming the flight's source) when the GP features of `flight` cannot be formed as the filter
/// forms them at run time: without a ground-truth pose, or with `inputs` from the truth of a flight with an IMU whose
/// pose has no orientation. A position-only pose of a flight without IMU is taken level and unturned, the attitude
/// the filter reports without an IMU.
void requireFeatureFrame(const Flight& flight, BiasInputSource inputs, const std::string& name);

/// Builds the dataset. Throws InputError where requireFeatureFrame does, and std::invalid_argument for bad params.
BiasDataset buildBiasDataset(const std::vector<Flight>& flights, const AnchorSurvey& survey,
                             const BiasDatasetParams& params = {});

}  // namespace uwb
