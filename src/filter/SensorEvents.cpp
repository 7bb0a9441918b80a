/** @file SensorEvents.cpp
 *  @brief Stream pairing and merging (docs/math/filter.md F17).
 */
#include "uwb/filter/SensorEvents.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace uwb {

std::vector<std::string> MergeReport::notes() const {
  std::vector<std::string> out;
  auto add = [&](std::size_t n, const char* what) {
    if (n) out.push_back(std::to_string(n) + " " + what);
  };
  add(n_imu_duplicate, "duplicate IMU timestamps dropped");
  add(n_tdoa_duplicate, "duplicate TDoA samples dropped");
  add(n_imu_out_of_order, "out-of-order IMU samples re-sorted");
  add(n_tdoa_out_of_order, "out-of-order TDoA samples re-sorted");
  add(n_tof_out_of_order, "out-of-order ToF samples re-sorted");
  add(n_nonfinite, "non-finite samples dropped");
  add(n_imu_gaps, "IMU gaps longer than the limit");
  add(n_tdoa_gaps, "TDoA gaps longer than the limit");
  add(n_imu_unpaired, "accelerometer samples without a nearby gyro sample");
  return out;
}

std::vector<TimedImu> pairImuStreams(const std::vector<TimedVec3>& acc_in, const std::vector<TimedVec3>& gyro_in,
                                     MergeReport* report) {
  auto sorted = [](std::vector<TimedVec3> v) {
    std::stable_sort(v.begin(), v.end(), [](const TimedVec3& a, const TimedVec3& b) { return a.t_s < b.t_s; });
    return v;
  };
  const std::vector<TimedVec3> acc = sorted(acc_in);
  const std::vector<TimedVec3> gyro = sorted(gyro_in);
  std::vector<TimedImu> out;
  out.reserve(acc.size());
  if (gyro.empty()) return out;
  std::size_t g = 0;
  std::size_t unpaired = 0;
  for (const TimedVec3& a : acc) {
    while (g + 1 < gyro.size() && gyro[g + 1].t_s <= a.t_s) ++g;
    if (std::abs(gyro[g].t_s - a.t_s) > 0.005) ++unpaired;
    TimedImu s;
    s.t_s = a.t_s;
    s.imu.b_acc_mps2 = a.value;
    s.imu.b_gyro_radps = gyro[g].value;
    out.push_back(s);
  }
  if (report) report->n_imu_unpaired += unpaired;
  return out;
}

namespace {

bool imuBad(const TimedImu& s) {
  // 0·x is ±0 for a finite x and NaN for ±∞ or NaN: the sum is zero iff all seven values are finite
  return 0.0 * s.t_s + (0.0 * s.imu.b_acc_mps2 + 0.0 * s.imu.b_gyro_radps).sum() != 0.0;
}
bool tdoaBad(const TdoaMeasurement& z) { return !std::isfinite(z.t_s) || !std::isfinite(z.tdoa_m); }
/// The TDoA duplicate rule: same stamp, pair and value (same stamp, other pair is legal).
bool tdoaSame(const TdoaMeasurement& a, const TdoaMeasurement& b) {
  return a.t_s == b.t_s && a.id_a == b.id_a && a.id_b == b.id_b && a.tdoa_m == b.tdoa_m;
}

/// Largest gap between consecutive stamps of a time-ordered stream, and the number of gaps above max_gap_s.
template <class Sample>
void countGaps(const std::vector<Sample>& v, double max_gap_s, double& max_gap, std::size_t& n_gaps) {
  for (std::size_t i = 1; i < v.size(); ++i) {
    const double gap = v[i].t_s - v[i - 1].t_s;
    max_gap = std::max(max_gap, gap);
    n_gaps += gap > max_gap_s;
  }
}

/// Gap statistics of a clean (time-ordered, duplicate-free, finite) log.
void countStreamGaps(const SensorLog& log, double max_gap_s, MergeReport& rep) {
  countGaps(log.imu, max_gap_s, rep.max_imu_gap_s, rep.n_imu_gaps);
  countGaps(log.tdoa, max_gap_s, rep.max_tdoa_gap_s, rep.n_tdoa_gaps);
}

/// All events of a clean log, in SensorEventCursor's order.
std::vector<SensorEvent> collectEvents(const SensorLog& log) {
  SensorEventCursor cursor(log);
  std::vector<SensorEvent> events(cursor.size());
  for (SensorEvent& e : events) cursor.next(e);
  return events;
}

}  // namespace

bool sensorLogIsClean(const SensorLog& log) {
  return cleanSensorLogReportIfClean(log, std::numeric_limits<double>::infinity()).has_value();
}

std::optional<MergeReport> cleanSensorLogReportIfClean(const SensorLog& log, double max_gap_s) {
  // the clean tests (what cleanSensorLog would change) and countStreamGaps' statistics, sample by sample
  MergeReport rep;
  rep.n_imu_in = log.imu.size();
  rep.n_tdoa_in = log.tdoa.size();
  rep.n_tof_in = log.tof.size();
  for (std::size_t i = 0; i < log.imu.size(); ++i) {
    if (imuBad(log.imu[i])) return std::nullopt;
    if (i == 0) continue;
    if (!(log.imu[i].t_s > log.imu[i - 1].t_s)) return std::nullopt;
    const double gap = log.imu[i].t_s - log.imu[i - 1].t_s;
    rep.max_imu_gap_s = std::max(rep.max_imu_gap_s, gap);
    rep.n_imu_gaps += gap > max_gap_s;
  }
  for (std::size_t i = 0; i < log.tdoa.size(); ++i) {
    if (tdoaBad(log.tdoa[i])) return std::nullopt;
    if (i == 0) continue;
    if (log.tdoa[i].t_s < log.tdoa[i - 1].t_s || tdoaSame(log.tdoa[i], log.tdoa[i - 1])) return std::nullopt;
    const double gap = log.tdoa[i].t_s - log.tdoa[i - 1].t_s;
    rep.max_tdoa_gap_s = std::max(rep.max_tdoa_gap_s, gap);
    rep.n_tdoa_gaps += gap > max_gap_s;
  }
  for (std::size_t i = 0; i < log.tof.size(); ++i)
    if (!std::isfinite(log.tof[i].t_s) || (i > 0 && log.tof[i].t_s < log.tof[i - 1].t_s)) return std::nullopt;
  return rep;
}

double SensorEventCursor::firstStamp() const {
  double t = std::numeric_limits<double>::infinity();
  if (n_imu_) t = std::min(t, imu_[0].t_s);
  if (n_tdoa_) t = std::min(t, tdoa_[0].t_s);
  if (n_tof_) t = std::min(t, tof_[0].t_s);
  return t;
}

double SensorEventCursor::lastStamp() const {
  double t = -std::numeric_limits<double>::infinity();
  if (n_imu_) t = std::max(t, imu_[n_imu_ - 1].t_s);
  if (n_tdoa_) t = std::max(t, tdoa_[n_tdoa_ - 1].t_s);
  if (n_tof_) t = std::max(t, tof_[n_tof_ - 1].t_s);
  return t;
}

MergeReport cleanSensorLog(SensorLog& log, double max_gap_s) {
  MergeReport rep;
  rep.n_imu_in = log.imu.size();
  rep.n_tdoa_in = log.tdoa.size();
  rep.n_tof_in = log.tof.size();
  // drop non-finite samples
  const std::size_t n0 = log.imu.size() + log.tdoa.size();
  std::erase_if(log.imu, imuBad);
  std::erase_if(log.tdoa, tdoaBad);
  rep.n_nonfinite = n0 - log.imu.size() - log.tdoa.size();
  if (!log.tof.empty()) {
    // (F21) ToF: only a non-finite stamp is dropped here; invalid ranges are counted by the filter
    const std::size_t nf = log.tof.size();
    std::erase_if(log.tof, [](const TofObservation& z) { return !std::isfinite(z.t_s); });
    rep.n_nonfinite += nf - log.tof.size();
    for (std::size_t i = 1; i < log.tof.size(); ++i) rep.n_tof_out_of_order += log.tof[i].t_s < log.tof[i - 1].t_s;
    if (rep.n_tof_out_of_order)
      std::stable_sort(log.tof.begin(), log.tof.end(),
                       [](const TofObservation& a, const TofObservation& b) { return a.t_s < b.t_s; });
  }
  // count out-of-order stamps, then sort stably
  for (std::size_t i = 1; i < log.imu.size(); ++i) rep.n_imu_out_of_order += log.imu[i].t_s < log.imu[i - 1].t_s;
  for (std::size_t i = 1; i < log.tdoa.size(); ++i)
    rep.n_tdoa_out_of_order += log.tdoa[i].t_s < log.tdoa[i - 1].t_s;
  if (rep.n_imu_out_of_order)
    std::stable_sort(log.imu.begin(), log.imu.end(), [](const TimedImu& a, const TimedImu& b) { return a.t_s < b.t_s; });
  if (rep.n_tdoa_out_of_order)
    std::stable_sort(log.tdoa.begin(), log.tdoa.end(),
                     [](const TdoaMeasurement& a, const TdoaMeasurement& b) { return a.t_s < b.t_s; });
  // duplicates: IMU with the same stamp; TDoA with same stamp, pair and value (same stamp, other pair is legal)
  const std::size_t ni = log.imu.size();
  log.imu.erase(std::unique(log.imu.begin(), log.imu.end(),
                            [](const TimedImu& a, const TimedImu& b) { return a.t_s == b.t_s; }),
                log.imu.end());
  rep.n_imu_duplicate = ni - log.imu.size();
  const std::size_t nt = log.tdoa.size();
  log.tdoa.erase(std::unique(log.tdoa.begin(), log.tdoa.end(), tdoaSame), log.tdoa.end());
  rep.n_tdoa_duplicate = nt - log.tdoa.size();
  countStreamGaps(log, max_gap_s, rep);
  return rep;
}

std::vector<SensorEvent> mergeSensorStreams(SensorLog& log, double max_gap_s, MergeReport* report) {
  MergeReport rep = cleanSensorLog(log, max_gap_s);
  if (report) {
    rep.n_imu_unpaired = report->n_imu_unpaired;
    *report = rep;
  }
  return collectEvents(log);
}

}  // namespace uwb
