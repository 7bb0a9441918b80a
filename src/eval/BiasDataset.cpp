/** @file BiasDataset.cpp
 *  @brief GP training samples from flights with ground truth (paper eq. 6; docs/math/gp.md P25).
 */
#include "uwb/eval/BiasDataset.h"

#include <algorithm>
#include <optional>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "uwb/core/Error.h"
#include "uwb/eval/FlightSummary.h"
#include "uwb/sim/TdoaResiduals.h"

namespace uwb {

std::string toString(BiasInputSource source) {
  return source == BiasInputSource::kGroundTruth ? "truth" : "estimate";
}

BiasInputSource biasInputSourceFromString(const std::string& name) {
  if (name == "truth") return BiasInputSource::kGroundTruth;
  if (name == "estimate") return BiasInputSource::kFilterEstimate;
  throw std::invalid_argument("unknown GP input source '" + name + "' (known: truth, estimate)");
}

void BiasDatasetParams::validate() const {
  if (!std::isfinite(min_z_m)) throw std::invalid_argument("BiasDatasetParams.min_z_m must be finite");
  if (!(glitch_margin_s >= 0)) throw std::invalid_argument("BiasDatasetParams.glitch_margin_s must be ≥ 0");
  if (!std::isfinite(max_abs_error_m)) throw std::invalid_argument("BiasDatasetParams.max_abs_error_m must be finite");
  if (!b_t_tag.allFinite()) throw std::invalid_argument("BiasDatasetParams.b_t_tag must be finite");
  pose_track.validate();
}

void requireFeatureFrame(const Flight& flight, BiasInputSource inputs, const std::string& name) {
  if (!flight.hasGroundTruth())
    throw InputError(SourceLocation{flight.source, 0, 0, "pose_x"},
                     "flight " + name + " has no ground-truth pose (pose_* columns are empty)");
  // A position-only pose (util-final-extract) leaves the body frame unknown: the track then carries the level,
  // unturned attitude (io/PoseTrack.h), so the lever arm is added in the world frame (as SOURCE.md prescribes) and
  // the features' anchor angles are taken in the world frame. That is the frame the filter itself reports without
  // an IMU, so features from such a flight match the ones the filter forms at run time. With an IMU the filter
  // knows the body frame, and features from a level, unturned truth would not be the ones it forms: there the
  // estimate must give them.
  if (!flight.pose_has_orientation && inputs == BiasInputSource::kGroundTruth && flight.hasImu())
    throw InputError(SourceLocation{flight.source, 0, 0, "pose_qw"},
                     "flight " + name +
                         " has an IMU but no ground-truth orientation; the bias features need the body frame: take "
                         "the GP inputs from the filter's estimate (--inputs estimate)");
}

namespace {

/// The filter's run on a flight, when the GP inputs come from its estimate (else empty).
struct FilterEstimate {
  Trajectory trajectory;
  double bias_level_m = std::numeric_limits<double>::quiet_NaN();
  SensorRangeReport sensor_range;
};

FilterEstimate filterEstimate(const Flight& flight, const AnchorSurvey& survey, const BiasDatasetParams& params) {
  FilterEstimate e;
  if (params.inputs == BiasInputSource::kFilterEstimate) {
    LocalizationRun run = localizeFlight(flight, survey, params.localization, params.estimate_bias);
    e.trajectory = std::move(run.trajectory);
    // (F24b) the level before the correction: with estimate_bias the raw one, else the corrected one is it
    e.bias_level_m = params.estimate_bias ? run.summary.raw_bias_level_m : run.summary.bias_level_m;
    e.sensor_range = run.summary.sensor_range;
  }
  return e;
}

/// The exclusion rules, in order; the first that applies is counted in rep. True when the residual is kept.
bool keepResidual(const TdoaResidual& r, const std::vector<double>& glitch_times, const std::vector<int>& ids,
                  const BiasDatasetParams& params, BiasFlightReport& rep) {
  // rule: near a pose glitch
  if (!glitch_times.empty()) {
    const auto it = std::lower_bound(glitch_times.begin(), glitch_times.end(), r.t_s - params.glitch_margin_s);
    if (it != glitch_times.end() && *it <= r.t_s + params.glitch_margin_s) {
      ++rep.n_pose_glitch;
      return false;
    }
  }
  // rule: on the ground (TDoA grossly wrong there, SOURCE.md Caveats)
  if (!isAirborne(r.w_p_b.z(), params.min_z_m)) {
    ++rep.n_on_ground;
    return false;
  }
  // rule: neighbour pairs only (optional)
  if (params.neighbour_pairs_only && !isNeighbourPair(r.id_a, r.id_b, ids) && !isNeighbourPair(r.id_b, r.id_a, ids)) {
    ++rep.n_non_neighbour;
    return false;
  }
  // paper eq. (6) with the UTIL sign convention and the lever arm (computed by tdoaResiduals)
  const double eps = r.residual_m;
  if (!std::isfinite(eps) || (params.max_abs_error_m > 0 && std::abs(eps) > params.max_abs_error_m)) {
    ++rep.n_outlier;
    return false;
  }
  return true;
}

/// The samples of flight number fi (named `name`) into ds; returns the flight's report.
BiasFlightReport addFlightSamples(const Flight& flight, std::size_t fi, const std::string& name,
                                  const AnchorSurvey& survey, const std::vector<int>& ids,
                                  const BiasDatasetParams& params, BiasDataset& ds) {
  const PoseTrack track(flight, params.pose_track);
  TdoaResidualParams rp;
  rp.b_t_tag = params.b_t_tag;
  rp.airborne_min_z_m = params.min_z_m;
  TdoaResidualReport rr;
  const std::vector<TdoaResidual> residuals = tdoaResiduals(flight, survey, track, rp, &rr);
  const auto [estimate, bias_level_m, sensor_range] = filterEstimate(flight, survey, params);

  BiasFlightReport rep;
  rep.source = name;
  rep.orientation_from_truth = flight.pose_has_orientation;
  rep.bias_level_m = bias_level_m;
  rep.sensor_range = sensor_range;
  rep.n_measurements = rr.n_measurements;
  rep.n_unknown_anchor = rr.n_unknown_anchor;
  rep.n_no_ground_truth = rr.n_no_ground_truth;
  rep.n_pose_glitches_detected = track.glitches().size();
  std::vector<double> glitch_times;
  for (const auto& g : track.glitches()) glitch_times.push_back(g.t_s);
  std::sort(glitch_times.begin(), glitch_times.end());

  for (const TdoaResidual& r : residuals) {
    if (!keepResidual(r, glitch_times, ids, params, rep)) continue;
    Vec3 w_p_b = r.w_p_b;
    Quat w_q_b = r.w_q_b;
    if (params.inputs == BiasInputSource::kFilterEstimate) {
      const std::optional<PoseSample> pose = interpolatePose(estimate, r.t_s, 0.1);  // io/PoseTrack.h
      if (!pose) {
        ++rep.n_no_estimate;
        continue;
      }
      w_p_b = pose->w_p_b;
      w_q_b = pose->w_q_b;
    }
    BiasSample s;
    s.feature = makeTdoaFeature(r.id_a, r.id_b, w_p_b, w_q_b, survey.position(r.id_a), survey.position(r.id_b));
    s.error_m = r.residual_m;  // ε, paper eq. (6)
    s.measured_m = r.measured_m;
    s.t_s = r.t_s;
    s.flight = static_cast<int>(fi);
    ds.samples.push_back(s);
    ++rep.n_used;
  }
  return rep;
}

}  // namespace

BiasDataset buildBiasDataset(const std::vector<Flight>& flights, const AnchorSurvey& survey,
                             const BiasDatasetParams& params) {
  params.validate();
  BiasDataset ds;
  ds.params = params;
  std::vector<int> ids;
  for (const Anchor& a : survey.anchors) ids.push_back(a.id);
  std::sort(ids.begin(), ids.end());

  for (std::size_t fi = 0; fi < flights.size(); ++fi) {
    const Flight& flight = flights[fi];
    const std::string name = flight.source.empty() ? "flight #" + std::to_string(fi + 1) : flight.source;
    requireFeatureFrame(flight, params.inputs, name);
    ds.flights.push_back(addFlightSamples(flight, fi, name, survey, ids, params, ds));
  }
  return ds;
}

std::string BiasDataset::reportText() const {
  std::ostringstream os;
  os << "training data (paper eq. 6): rules min_z=" << params.min_z_m << " m, glitch margin=" << params.glitch_margin_s
     << " s, |eps| > " << params.max_abs_error_m << " m, neighbour pairs only=" << (params.neighbour_pairs_only ? "yes" : "no")
     << ", GP inputs from " << (params.inputs == BiasInputSource::kGroundTruth ? "the ground-truth pose" : "the filter's estimate")
     << "\n";
  os << "  flight: measurements | unknown anchor | no ground truth | pose glitch | on ground | non-neighbour | outlier | "
        "no estimate | used\n";
  for (const auto& f : flights) {
    os << "  " << f.source << ": " << f.n_measurements << " | " << f.n_unknown_anchor << " | " << f.n_no_ground_truth
       << " | " << f.n_pose_glitch << " (" << f.n_pose_glitches_detected << " glitch samples) | " << f.n_on_ground << " | "
       << f.n_non_neighbour << " | " << f.n_outlier << " | " << f.n_no_estimate << " | " << f.n_used << "\n";
    if (!f.orientation_from_truth)
      os << "    (position-only pose: lever arm added in the world frame"
         << (params.inputs == BiasInputSource::kGroundTruth ? ", features in the level, unturned body frame)\n" : ")\n");
  }
  return os.str();
}

}  // namespace uwb
