/** @file FlightSummary.cpp
 *  @brief Flight overview for `uwbtdoa inspect` (docs/io.md, "inspect").
 */
#include "uwb/eval/FlightSummary.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace uwb {

namespace {

template <class Samples>
StreamSummary summarizeStream(Stream s, const Samples& samples, bool present) {
  StreamSummary out;
  out.stream = s;
  out.name = streamName(s);
  out.present = present || !samples.empty();
  out.count = samples.size();
  if (!samples.empty()) {
    out.t_first_s = samples.front().t_s;
    out.t_last_s = samples.back().t_s;
    const double span = out.t_last_s - out.t_first_s;
    if (samples.size() >= 2 && span > 0.0) out.rate_hz = static_cast<double>(samples.size() - 1) / span;
  }
  return out;
}

bool columnsMention(const Flight& f, Stream s) {
  const std::string t = streamColumns(s).front();
  return std::find(f.columns.begin(), f.columns.end(), t) != f.columns.end();
}

}  // namespace

bool isNeighbourPair(int id_a, int id_b, const std::vector<int>& sorted_ids) {
  const auto it = std::lower_bound(sorted_ids.begin(), sorted_ids.end(), id_a);
  if (it == sorted_ids.end() || *it != id_a || sorted_ids.size() < 2) return false;
  const auto next = std::next(it) == sorted_ids.end() ? sorted_ids.begin() : std::next(it);
  return *next == id_b;
}

namespace {

/// Every stream, in UTIL column order (absent ones with present = false).
std::vector<StreamSummary> summarizeStreams(const Flight& flight) {
  std::vector<StreamSummary> streams;
  for (Stream s : allStreams()) {
    const bool present = columnsMention(flight, s);
    switch (s) {
      case Stream::kTdoa: streams.push_back(summarizeStream(s, flight.tdoa, present)); break;
      case Stream::kTwr: streams.push_back(summarizeStream(s, flight.twr, present)); break;
      case Stream::kAcc: streams.push_back(summarizeStream(s, flight.acc, present)); break;
      case Stream::kGyro: streams.push_back(summarizeStream(s, flight.gyro, present)); break;
      case Stream::kTof: streams.push_back(summarizeStream(s, flight.tof, present)); break;
      case Stream::kFlow: streams.push_back(summarizeStream(s, flight.flow, present)); break;
      case Stream::kBaro: streams.push_back(summarizeStream(s, flight.baro, present)); break;
      case Stream::kPose: streams.push_back(summarizeStream(s, flight.pose, present)); break;
    }
  }
  return streams;
}

/// Anchor ids for the neighbour definition, sorted: the survey's, else 0..max id seen.
std::vector<int> neighbourRingIds(const Flight& flight, const AnchorSurvey* survey) {
  std::vector<int> ids;
  if (survey != nullptr) {
    for (const Anchor& a : survey->anchors) ids.push_back(a.id);
  } else {
    // UTIL numbers its anchors 0..N-1 around the arena: the ring is 0..(largest id seen). Ids beyond kMaxAnchorId
    // (a flight built in memory) use the ids seen, so that no table is sized by an id.
    std::set<int> seen;
    for (const TdoaMeasurement& m : flight.tdoa) {
      seen.insert(m.id_a);
      seen.insert(m.id_b);
    }
    if (!seen.empty() && *seen.begin() >= 0 && *seen.rbegin() <= kMaxAnchorId) {
      for (int i = 0; i <= *seen.rbegin(); ++i) ids.push_back(i);
    } else {
      ids.assign(seen.begin(), seen.end());
    }
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

using PairIndex = std::map<std::pair<int, int>, std::size_t>;  ///< (id_a, id_b) → index into FlightSummary::pairs

/// Fills out.pairs in order of first appearance and out.n_tdoa; returns the number of measurements on neighbour
/// pairs.
std::size_t countPairs(const Flight& flight, const std::vector<int>& ids, FlightSummary& out, PairIndex& pair_index) {
  std::size_t n_neighbour = 0;
  for (const TdoaMeasurement& m : flight.tdoa) {
    const auto key = std::make_pair(m.id_a, m.id_b);
    auto [it, inserted] = pair_index.emplace(key, 0);
    if (inserted) {
      PairSummary p;
      p.id_a = m.id_a;
      p.id_b = m.id_b;
      p.neighbour = isNeighbourPair(m.id_a, m.id_b, ids);
      out.pairs.push_back(p);
      it->second = out.pairs.size() - 1;
    }
    PairSummary& p = out.pairs[it->second];
    ++p.count;
    if (p.neighbour) ++n_neighbour;
  }
  out.n_tdoa = flight.tdoa.size();
  return n_neighbour;
}

/// Residual statistics overall, on neighbour pairs and per pair, each split by phase; notes on what had none.
void summarizeResiduals(const Flight& flight, const AnchorSurvey& survey, const PoseTrack& track,
                        const FlightSummaryParams& params, const PairIndex& pair_index, FlightSummary& out) {
  const std::vector<TdoaResidual> residuals = tdoaResiduals(flight, survey, track, params.residual, &out.residual_report);
  out.has_residuals = !residuals.empty();
  // Collect per phase, overall / neighbour / per pair.
  struct Buckets {
    std::vector<double> all, air, ground;
    void add(const TdoaResidual& r) {
      all.push_back(r.residual_m);
      (r.airborne ? air : ground).push_back(r.residual_m);
    }
    PhaseResiduals stats() const { return {residualStats(all), residualStats(air), residualStats(ground)}; }
  };
  Buckets overall;
  Buckets neighbour;
  std::vector<Buckets> per_pair(out.pairs.size());
  for (const TdoaResidual& r : residuals) {
    overall.add(r);
    const std::size_t pi = pair_index.at({r.id_a, r.id_b});
    per_pair[pi].add(r);
    if (out.pairs[pi].neighbour) neighbour.add(r);
  }
  out.residual = overall.stats();
  out.residual_neighbour = neighbour.stats();
  for (std::size_t i = 0; i < out.pairs.size(); ++i) out.pairs[i].residual = per_pair[i].stats();
  const TdoaResidualReport& rr = out.residual_report;
  if (rr.n_no_ground_truth > 0) {
    out.notes.push_back(fmt::format("{} TDoA measurement(s) without ground truth (outside the pose track or in a "
                                    "gap > {} s)",
                                    rr.n_no_ground_truth, params.pose_track.max_gap_s));
  }
  if (rr.n_unknown_anchor > 0) {
    out.notes.push_back(fmt::format("{} TDoA measurement(s) name an anchor missing from the survey",
                                    rr.n_unknown_anchor));
  }
}

/// The ground-truth part (pose glitches, airborne share) and, with a survey and TDoA data, the residuals.
void summarizeGroundTruth(const Flight& flight, const AnchorSurvey* survey, const FlightSummaryParams& params,
                          const PairIndex& pair_index, FlightSummary& out) {
  out.has_ground_truth = true;
  out.pose_has_orientation = flight.pose_has_orientation;
  const PoseTrack track(flight, params.pose_track);
  out.pose_glitches = track.glitches();
  out.n_pose_glitches_attitude = track.countGlitches(PoseGlitchKind::kAttitude);
  out.n_pose_glitches_position = track.countGlitches(PoseGlitchKind::kPosition);
  if (!track.empty()) {
    const auto n_air = std::count_if(track.samples().begin(), track.samples().end(), [&](const PoseSample& s) {
      return isAirborne(s.w_p_b.z(), params.residual.airborne_min_z_m);
    });
    out.airborne_fraction_pose = static_cast<double>(n_air) / static_cast<double>(track.samples().size());
  }
  if (!track.glitches().empty()) {
    out.notes.push_back(fmt::format("{} pose glitch sample(s) excluded from ground truth ({} attitude, {} position)",
                                    track.glitches().size(), out.n_pose_glitches_attitude,
                                    out.n_pose_glitches_position));
  }
  if (survey != nullptr && !flight.tdoa.empty()) summarizeResiduals(flight, *survey, track, params, pair_index, out);
}

}  // namespace

FlightSummary summarizeFlight(const Flight& flight, const AnchorSurvey* survey, const ReadReport* read_report,
                              const FlightSummaryParams& params) {
  FlightSummary out;
  out.source = flight.source;
  const auto [t0, t1] = flight.timeSpan();
  out.t_start_s = t0;
  out.t_end_s = t1;
  out.duration_s = t1 - t0;
  out.streams = summarizeStreams(flight);
  if (read_report != nullptr) out.notes = read_report->notes;

  PairIndex pair_index;
  const std::size_t n_neighbour = countPairs(flight, neighbourRingIds(flight, survey), out, pair_index);
  out.neighbour_pair_fraction =
      out.n_tdoa > 0 ? static_cast<double>(n_neighbour) / static_cast<double>(out.n_tdoa) : 0.0;

  if (flight.hasGroundTruth()) summarizeGroundTruth(flight, survey, params, pair_index, out);
  const std::size_t n_non_neighbour = out.n_tdoa - n_neighbour;
  if (n_non_neighbour > 0 && out.neighbour_pair_fraction > 0.5) {
    out.notes.push_back(fmt::format("{} TDoA measurement(s) on non-neighbour pairs", n_non_neighbour));
  }
  std::sort(out.pairs.begin(), out.pairs.end(),
            [](const PairSummary& a, const PairSummary& b) { return std::tie(a.id_a, a.id_b) < std::tie(b.id_a, b.id_b); });
  return out;
}

}  // namespace uwb
