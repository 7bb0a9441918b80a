/** @file UtilCsv.h
 *  @brief Read and write flights and anchor surveys in the UTIL dataset layout (Zhao et al., IJRR 2022).
 *
 *  Flight CSV: a header naming the columns, then rows; streams are column-stacked, each with its own time
 *  column and length, shorter streams padded with empty cells. Units in the file: acc [g], gyro [deg/s];
 *  in memory: SI (see Flight.h). Every error is an InputError naming file, line, column and field.
 */
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"

namespace uwb {

/// Oddities that the reader tolerates; each is counted, never silently dropped.
struct ReadReport {
  std::size_t n_rows = 0;    ///< data rows in the file
  std::size_t n_bytes = 0;   ///< file size
  std::vector<std::string> notes;  ///< human-readable remarks (e.g. "3 duplicate timestamps in stream acc")
};

struct FlightReadOptions {
  /// Streams that must be present and non-empty (an error otherwise), e.g. {Stream::kTdoa}.
  std::vector<Stream> required;
  /// When non-null, every TDoA/TWR anchor id must have a survey entry (error names the row otherwise).
  const AnchorSurvey* survey = nullptr;
};

/// Reads a UTIL flight CSV (full 27-column layout, any subset of its streams, or the TWR variant).
/// Header columns may come in any order; a stream's columns are all present or all absent (the pose quaternion
/// columns form their own group: position-only files set pose_has_orientation = false). Units are converted once
/// here: acc g → m/s² (× kGravity_mps2), gyro deg/s → rad/s (× kDegToRad). Quaternions are stored as read (not
/// renormalised; |‖q‖ − 1| ≤ kMaxQuaternionNormError is checked). Errors: InputError("file:line:column (field):
/// ..."), column = 1-based CSV field index; FileError when the file cannot be read. See docs/io.md.
Flight readFlightCsv(const std::string& path, const FlightReadOptions& options = {}, ReadReport* report = nullptr);

/// Same as readFlightCsv on text already in memory; `source` names it in messages (and becomes flight.source).
Flight parseFlightCsv(std::string_view text, const std::string& source, const FlightReadOptions& options = {},
                      ReadReport* report = nullptr);

/// Writes a flight in the UTIL layout with the columns in flight.columns (all streams present when empty).
/// readFlightCsv(writeFlightCsv(f)) reproduces f exactly, including the unit conversions.
/// Throws std::invalid_argument when flight.columns names an unknown column, splits a stream, or omits a stream
/// that holds samples (data would be lost); FileError when the file cannot be written.
void writeFlightCsv(const Flight& flight, const std::string& path);

/// The CSV text writeFlightCsv writes.
std::string formatFlightCsv(const Flight& flight);

/// Largest tolerated |‖q‖ − 1| of a pose quaternion in a file (UTIL quantises components to ≈0.0014).
inline constexpr double kMaxQuaternionNormError = 0.02;
/// The reader's check of a pose quaternion: |‖q‖ − 1| ≤ kMaxQuaternionNormError; `norm` receives ‖q‖.
bool isFileQuaternionNormOk(double qx, double qy, double qz, double qw, double& norm);

/// UTIL column names of one stream, in UTIL order (pose: position columns then quaternion columns).
std::vector<std::string> streamColumns(Stream stream);
/// Short stream name used in messages and summaries: "tdoa", "twr", "acc", "gyro", "tof", "flow", "baro", "pose".
const char* streamName(Stream stream);
/// All streams, in UTIL column order (TWR first, as in the TWR variant).
const std::vector<Stream>& allStreams();
/// The 27 columns of the full UTIL TDoA layout, in UTIL order.
const std::vector<std::string>& utilTdoaColumns();

/// Reads a UTIL anchor survey (`an{i}_p,x,y,z` lines, then `an{i}_quat,qx,qy,qz,qw`), any number of anchors.
AnchorSurvey readAnchorSurvey(const std::string& path);
/// Same as readAnchorSurvey on text already in memory; `source` names it in messages (and becomes survey.source).
AnchorSurvey parseAnchorSurvey(std::string_view text, const std::string& source);

/// Writes a survey that readAnchorSurvey reads back exactly.
void writeAnchorSurvey(const AnchorSurvey& survey, const std::string& path);

}  // namespace uwb
