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
Flight readFlightCsv(const std::string& path, const FlightReadOptions& options = {}, ReadReport* report = nullptr);

/// Writes a flight in the UTIL layout with the columns in flight.columns (all streams present when empty).
/// readFlightCsv(writeFlightCsv(f)) reproduces f exactly, including the unit conversions.
void writeFlightCsv(const Flight& flight, const std::string& path);

/// Reads a UTIL anchor survey (`an{i}_p,x,y,z` lines, then `an{i}_quat,qx,qy,qz,qw`), any number of anchors.
AnchorSurvey readAnchorSurvey(const std::string& path);

/// Writes a survey that readAnchorSurvey reads back exactly.
void writeAnchorSurvey(const AnchorSurvey& survey, const std::string& path);

}  // namespace uwb
