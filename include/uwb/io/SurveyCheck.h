/** @file SurveyCheck.h
 *  @brief The anchor positions a Crazyflie user has, as a survey, and its checks (docs/crazyflie.md).
 *
 *  The Crazyflie client (cfclient) saves the positions of its Loco Positioning tab ("Configure positions" →
 *  Save) as YAML, one mapping per anchor id, written by PyYAML's `yaml.dump`:
 *
 *      0:                     or, from older PyYAML versions,     0: {x: 0.0, y: 0.0, z: 0.15}
 *        x: 0.0
 *        y: 0.0
 *        z: 0.15
 *
 *  The checks turn what would make an estimate lie into warnings with numbers: anchors closer together than a
 *  UWB antenna can be told apart, anchors in one plane (the axis normal to it poorly observed; vertical for the
 *  common all-on-the-ceiling layout), a flight that leaves the anchors' box, an anchor id the flight's TDoA use
 *  that the survey lacks.
 */
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "uwb/core/Types.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"
#include "uwb/io/InputChecks.h"

namespace uwb {

/// Reads the cfclient anchor-position YAML (block or flow mappings; `#` comments; `---`). InputError naming the
/// line for anything else: a key that is not an id in [0, kMaxAnchorId], a duplicate id, a coordinate that is not
/// a finite number, a key other than x, y, z, a missing coordinate, no anchor at all.
AnchorSurvey parseCfclientAnchors(std::string_view text, const std::string& source);
AnchorSurvey readCfclientAnchors(const std::string& path);
/// The same file format, as cfclient writes it (block style), for tests and round trips.
std::string formatCfclientAnchors(const AnchorSurvey& survey);

/// A flight position outside the anchors' box by more than this counts as outside [m] (a drone on the floor below
/// anchors mounted 0.2 m high is not).
inline constexpr double kFlightOutsideMargin_m = 0.25;
/// Share of the flight's positions outside the anchors' box above which it is a warning.
inline constexpr double kMaxShareOutside = 0.01;

/// All anchors within ±kMinAnchorDepth_m of one plane: a warning naming the plane, its normal and the axis that is
/// poorly observed (the vertical when the plane is near horizontal). Nothing for fewer than 4 anchors.
std::vector<InputIssue> checkAnchorPlane(const AnchorSurvey& survey);
/// Anchor ids in the flight's TDoA (idA, idB) or TWR that the survey lacks: one warning per id with its count.
std::vector<InputIssue> checkFlightAnchorIds(const AnchorSurvey& survey, const Flight& flight);
/// Positions (the flight's motion capture, or an estimated trajectory) outside the anchors' bounding box by more
/// than kFlightOutsideMargin_m: a warning with the share outside, the largest excursion and its axis.
std::vector<InputIssue> checkFlightInsideAnchors(const AnchorSurvey& survey, const std::vector<Vec3>& w_p_flight,
                                                 const std::string& source);

/// Every check of `uwbtdoa survey`, in its order: checkSurveyGeometry (errors: fewer than 2 anchors, all at one
/// point, on one line; its coplanar warning replaced by checkAnchorPlane's), with checkAnchorSeparation,
/// checkAnchorPlane, then with a flight checkFlightAnchorIds, and checkFlightInsideAnchors on `w_p_flight` (none:
/// no volume check) named `positions_source`.
std::vector<InputIssue> checkSurvey(const AnchorSurvey& survey, const Flight* flight,
                                    const std::vector<Vec3>& w_p_flight, const std::string& positions_source);

}  // namespace uwb
