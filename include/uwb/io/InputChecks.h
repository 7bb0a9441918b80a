/** @file InputChecks.h
 *  @brief Plausibility checks of inputs that parse but would make an estimator lie: anchor-survey geometry and
 *         the sample rates of a flight's streams (stamps in milliseconds instead of seconds). Each finding is an
 *         error (the command must stop) or a warning (reported, also in `--json`); see docs/robustness.md.
 */
#pragma once

#include <string>
#include <vector>

#include "uwb/core/Error.h"
#include "uwb/core/Types.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"

namespace uwb {

enum class IssueSeverity { kWarning, kError };

/// One finding of a plausibility check: where (file, field) and what.
struct InputIssue {
  IssueSeverity severity = IssueSeverity::kWarning;
  SourceLocation where;
  std::string message;
  /// "file (field): message".
  std::string text() const { return where.toString() + ": " + message; }
};

/// Spread of the anchors: standard deviations along the principal axes of their positions [m], largest first.
struct SurveyGeometry {
  std::size_t n_anchors = 0;
  Vec3 principal_std_m = Vec3::Zero();
  Vec3 w_centroid = Vec3::Zero();
  Vec3 w_min = Vec3::Zero();  ///< bounding box of the anchors [m]
  Vec3 w_max = Vec3::Zero();
};

/// Anchors closer than this along their largest principal axis are "all at one point" (error) [m].
inline constexpr double kMinAnchorSpread_m = 0.5;
/// Second principal std below this: anchors on one line, no 2-D fix (error) [m].
inline constexpr double kMinAnchorWidth_m = 0.2;
/// Third principal std below this: anchors (nearly) coplanar, the axis normal to their plane is poorly observed
/// (warning) [m].
inline constexpr double kMinAnchorDepth_m = 0.2;
/// Largest principal std beyond this: not one UWB arena (an error) [m].
inline constexpr double kMaxAnchorSpread_m = 500.0;

/// Two anchors closer than this are colocated or one place surveyed twice: their TDoA carry almost no position
/// information (warning naming both) [m].
inline constexpr double kMinAnchorSeparation_m = 0.3;
/// An IMU stream that ends this long before the TDoA stream leaves the rest of the flight without it (warning) [s].
inline constexpr double kMaxImuEndGap_s = 1.0;

SurveyGeometry surveyGeometry(const AnchorSurvey& survey);
/// Pairs of anchors closer than min_separation_m: a warning each, with the distance.
std::vector<InputIssue> checkAnchorSeparation(const AnchorSurvey& survey,
                                              double min_separation_m = kMinAnchorSeparation_m);
/// Errors: fewer than 2 anchors, all at one point, on one line. Warnings: fewer than 4 anchors (no 3-D
/// multilateration), coplanar, spread beyond kMaxAnchorSpread_m, two anchors closer than kMinAnchorSeparation_m.
std::vector<InputIssue> checkSurveyGeometry(const AnchorSurvey& survey);

/// Plausible sample-rate range of a stream [Hz] (IMU 20 Hz–10 kHz, TDoA and pose 1 Hz–10 kHz, others 0.2 Hz–10 kHz).
struct RateRange {
  double min_hz;
  double max_hz;
};
RateRange plausibleRate(Stream stream);

/// Median sample rate of each present stream with ≥ 10 samples, checked against plausibleRate; a stream whose time
/// span exceeds 50× the TDoA stream's (stamps in milliseconds) is flagged too. Errors for the TDoA stream and
/// the IMU (acc, gyro), warnings for the other streams. A stream of ≥ 2 samples whose stamps are all equal is an
/// error for TDoA and IMU, a warning otherwise. An IMU stream (acc, gyro) that ends more than kMaxImuEndGap_s
/// before the TDoA stream is a warning giving both end times.
std::vector<InputIssue> checkStreamRates(const Flight& flight);

/// True when any issue is an error.
bool hasError(const std::vector<InputIssue>& issues);
/// Throws InputError with the first error's location and message (all errors listed) when there is one.
void throwOnError(const std::vector<InputIssue>& issues);

}  // namespace uwb
