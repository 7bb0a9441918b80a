/** @file SensorEvents.h
 *  @brief Merging the IMU, TDoA and (optional) ToF streams into one time-ordered event sequence, with duplicates,
 *         out-of-order stamps, non-finite values and gaps counted (docs/math/filter.md F17).
 */
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "uwb/filter/NavState.h"
#include "uwb/filter/TdoaUpdate.h"
#include "uwb/filter/TofUpdate.h"

namespace uwb {

/// A time-stamped 3-vector (one accelerometer or gyroscope sample) [s], [SI].
struct TimedVec3 {
  double t_s = 0.0;
  Vec3 value = Vec3::Zero();
};

/// A paired IMU sample.
struct TimedImu {
  double t_s = 0.0;
  ImuReading imu;
};

/// Sensor streams as the filter consumes them.
struct SensorLog {
  std::vector<TimedImu> imu;
  std::vector<TdoaMeasurement> tdoa;
  std::vector<TofObservation> tof;  ///< optional downward range (F21); empty unless ToF fusion is wanted
};

/// What merging found; nothing is dropped silently.
struct MergeReport {
  std::size_t n_imu_in = 0, n_tdoa_in = 0, n_tof_in = 0;
  std::size_t n_imu_duplicate = 0;      ///< identical stamp as the previous IMU sample (later one dropped)
  std::size_t n_tdoa_duplicate = 0;     ///< identical stamp, pair and value (later one dropped)
  std::size_t n_imu_out_of_order = 0;   ///< stamp earlier than its predecessor in the file (re-sorted)
  std::size_t n_tdoa_out_of_order = 0;
  std::size_t n_tof_out_of_order = 0;
  std::size_t n_nonfinite = 0;          ///< samples with a non-finite stamp or value (dropped; ToF: stamp only,
                                        ///< a non-finite ToF range is left to the filter, which counts it)
  std::size_t n_imu_gaps = 0;           ///< gaps longer than max_gap_s between consecutive IMU samples
  std::size_t n_tdoa_gaps = 0;
  double max_imu_gap_s = 0.0;
  double max_tdoa_gap_s = 0.0;
  std::size_t n_imu_unpaired = 0;       ///< acc samples without a gyro sample close in time (held gyro used)
  /// Human-readable one-liners of everything non-zero above.
  std::vector<std::string> notes() const;
};

/// Pairs accelerometer and gyroscope streams into IMU samples at the accelerometer stamps; the gyro value is
/// the latest gyro sample at or before that stamp (zero-order hold; the first gyro sample before any).
std::vector<TimedImu> pairImuStreams(const std::vector<TimedVec3>& acc, const std::vector<TimedVec3>& gyro,
                                     MergeReport* report = nullptr);

/// One event of the merged sequence: an index into SensorLog::imu, SensorLog::tdoa or SensorLog::tof.
struct SensorEvent {
  enum class Kind : unsigned char { kImu, kTdoa, kTof };
  double t_s = 0.0;
  Kind kind = Kind::kImu;
  unsigned index = 0;
};

/// The merged event sequence of a clean log (sensorLogIsClean), produced one event at a time without materialising
/// it (F17): ordered by time; at equal stamps IMU comes before TDoA, and both before ToF. The log must outlive the
/// cursor and stay unchanged. This is the one definition of the merge order; mergeSensorStreams collects it.
///   SensorEventCursor cursor(log);
///   for (SensorEvent ev; cursor.next(ev);) { ... }
class SensorEventCursor {
 public:
  explicit SensorEventCursor(const SensorLog& log)
      : imu_(log.imu.data()), tdoa_(log.tdoa.data()), tof_(log.tof.data()), n_imu_(log.imu.size()),
        n_tdoa_(log.tdoa.size()), n_tof_(log.tof.size()) {
    updateNextOther();
  }
  /// Total number of events.
  std::size_t size() const { return n_imu_ + n_tdoa_ + n_tof_; }
  bool empty() const { return size() == 0; }
  /// Stamp of the first / last event [s]; only for a non-empty log.
  double firstStamp() const;
  double lastStamp() const;
  /// Writes the next event to `ev` and returns true, or returns false when all events were produced.
  bool next(SensorEvent& ev) {
    // IMU (the densest stream) first at equal stamps: one comparison against the earliest pending TDoA/ToF stamp
    if (i_imu_ < n_imu_ && imu_[i_imu_].t_s <= t_next_other_) {
      ev = {imu_[i_imu_].t_s, SensorEvent::Kind::kImu, static_cast<unsigned>(i_imu_)};
      ++i_imu_;
      return true;
    }
    if (i_tdoa_ < n_tdoa_ && tdoa_[i_tdoa_].t_s == t_next_other_) {  // TDoA before ToF at equal stamps
      ev = {t_next_other_, SensorEvent::Kind::kTdoa, static_cast<unsigned>(i_tdoa_)};
      ++i_tdoa_;
    } else if (i_tof_ < n_tof_) {
      ev = {t_next_other_, SensorEvent::Kind::kTof, static_cast<unsigned>(i_tof_)};
      ++i_tof_;
    } else {
      return false;  // all streams exhausted
    }
    updateNextOther();
    return true;
  }

 private:
  /// The earliest pending TDoA or ToF stamp; +∞ when both are exhausted.
  void updateNextOther() {
    constexpr double kNever = std::numeric_limits<double>::infinity();
    const double t_tdoa = i_tdoa_ < n_tdoa_ ? tdoa_[i_tdoa_].t_s : kNever;
    const double t_tof = i_tof_ < n_tof_ ? tof_[i_tof_].t_s : kNever;
    t_next_other_ = t_tdoa <= t_tof ? t_tdoa : t_tof;
  }
  const TimedImu* imu_;
  const TdoaMeasurement* tdoa_;
  const TofObservation* tof_;
  std::size_t n_imu_, n_tdoa_, n_tof_;
  std::size_t i_imu_ = 0, i_tdoa_ = 0, i_tof_ = 0;
  double t_next_other_ = 0.0;
};

/// Cleans `log` in place (drops non-finite samples and duplicates, stably sorts each stream by time; afterwards
/// sensorLogIsClean(log) holds) and returns what it found, with the gap statistics of the cleaned streams.
MergeReport cleanSensorLog(SensorLog& log, double max_gap_s);

/// Cleans `log` in place (cleanSensorLog) and returns the merged event sequence (SensorEventCursor's order).
std::vector<SensorEvent> mergeSensorStreams(SensorLog& log, double max_gap_s, MergeReport* report = nullptr);

/// True when mergeSensorStreams would leave `log` unchanged: all stamps and values finite, IMU stamps strictly
/// increasing, TDoA stamps non-decreasing with no duplicate, ToF stamps finite and non-decreasing.
bool sensorLogIsClean(const SensorLog& log);

/// The clean test and cleanSensorLog's report in one pass over the streams: for a clean log (sensorLogIsClean) the
/// report cleanSensorLog would return (input counts, gap statistics) without copying or modifying it; nullopt otherwise.
std::optional<MergeReport> cleanSensorLogReportIfClean(const SensorLog& log, double max_gap_s);

}  // namespace uwb
