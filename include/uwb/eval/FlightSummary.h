/** @file FlightSummary.h
 *  @brief What a user wants to know first about a flight: streams, TDoA pairs, reader notes, pose glitches and the
 *  TDoA residual against ground truth. Computed here; `uwbtdoa inspect` only formats it (docs/io.md, "inspect").
 */
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"
#include "uwb/io/PoseTrack.h"
#include "uwb/io/ResidualStats.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/sim/TdoaResiduals.h"

namespace uwb {

/// Count, time span and mean rate of one stream.
struct StreamSummary {
  Stream stream = Stream::kTdoa;
  std::string name;      ///< streamName(stream)
  bool present = false;  ///< its columns were in the file (or it holds samples)
  std::size_t count = 0;
  double t_first_s = 0.0;
  double t_last_s = 0.0;
  double rate_hz = 0.0;  ///< (count − 1) / (t_last − t_first); 0 with fewer than 2 samples
};

/// Residual statistics split by flight phase (airborne: isAirborne(ground-truth z, airborne_min_z_m)).
struct PhaseResiduals {
  ResidualStats all;
  ResidualStats airborne;
  ResidualStats ground;
};

/// One ordered anchor pair (id_a, id_b) of the TDoA stream.
struct PairSummary {
  int id_a = 0;
  int id_b = 0;
  std::size_t count = 0;
  bool neighbour = false;  ///< id_b follows id_a cyclically in the sorted anchor ids (UTIL TDoA2: (0,1)…(7,0))
  PhaseResiduals residual;  ///< empty (n = 0) without ground truth or survey
};

struct FlightSummary {
  std::string source;
  double t_start_s = 0.0;
  double t_end_s = 0.0;
  double duration_s = 0.0;
  std::vector<StreamSummary> streams;  ///< every stream, in UTIL column order (absent ones with present = false)
  std::vector<PairSummary> pairs;      ///< sorted by (id_a, id_b)
  std::size_t n_tdoa = 0;
  double neighbour_pair_fraction = 0.0;  ///< share of TDoA measurements on neighbour pairs
  std::vector<std::string> notes;        ///< reader notes (ReadReport) and summary remarks

  // Ground truth (only when the flight has a pose stream).
  bool has_ground_truth = false;
  bool pose_has_orientation = false;
  std::size_t n_pose_glitches_attitude = 0;
  std::size_t n_pose_glitches_position = 0;
  std::vector<PoseGlitch> pose_glitches;
  double airborne_fraction_pose = 0.0;  ///< share of accepted pose samples that are isAirborne

  // Residuals (only with ground truth and a survey).
  bool has_residuals = false;
  TdoaResidualReport residual_report;
  PhaseResiduals residual;            ///< all pairs
  PhaseResiduals residual_neighbour;  ///< neighbour pairs only
};

struct FlightSummaryParams {
  PoseTrackParams pose_track;
  TdoaResidualParams residual;
};

/// Summarises a flight. `survey` (may be null) enables the residuals and the neighbour definition (without it,
/// neighbours are taken over ids 0..max id seen); `read_report` (may be null) contributes its notes.
FlightSummary summarizeFlight(const Flight& flight, const AnchorSurvey* survey, const ReadReport* read_report = nullptr,
                              const FlightSummaryParams& params = {});

/// True when id_b follows id_a cyclically in the sorted list `ids` (e.g. (0,1), …, (7,0) for ids 0–7).
bool isNeighbourPair(int id_a, int id_b, const std::vector<int>& sorted_ids);

}  // namespace uwb
