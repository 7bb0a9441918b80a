/** @file StartReplay.h
 *  @brief The filter run again over the start-up window once the multilateration has found where it began
 *         (docs/math/filter.md F16g).
 *
 *  While the start-up collects TDoA (F16) the filter only predicts. A fix in motion (F16b) gives the position p₀ and
 *  velocity v₀ at the window's reference instant t_ref from 0.6 s of TDoA with a level attitude and without the
 *  range-bias states; written into the filter as the state *now* with the solve's covariance, its velocity error
 *  (0.3–1 m/s on the real flights cut in the air) is taken for known to 0.15 m/s and carried for seconds. Here the
 *  fix only supplies the starting point: the filter restarts at t_ref from the state predicted then, with p₀ and v₀
 *  under a wide prior, and runs the recorded predictions and TDoA of the window again, so that every state (attitude,
 *  thrust bias, range biases) and their correlations come from the same model as afterwards.
 *
 *  The record is bounded (no allocation per event after construction); a window that overflows it, or in which
 *  anything but predictions and TDoA changed the filter, is not replayed and the fix is applied as before (F16b).
 */
#pragma once

#include <cstddef>
#include <vector>

#include "uwb/filter/Ekf.h"
#include "uwb/filter/TdoaUpdate.h"

namespace uwb {

class StartReplay {
 public:
  /// params: the filter's; capacity: the most predictions plus TDoA one window may record.
  explicit StartReplay(const EkfParams& params, std::size_t capacity = 6144);

  /// Starts a record at t_ref_s from the filter as it is then (its state is the one the fix's p₀, v₀ refer to).
  void begin(const Ekf& filter, double t_ref_s);
  /// Ends recording; nothing can be replayed until the next begin().
  void stop() { recording_ = false; }
  bool recording() const { return recording_; }
  /// Reference instant of the record [s] (NaN when none).
  double referenceTime() const { return t_ref_s_; }

  /// One prediction step of the filter, as it was made (Ekf::predict(imu, dt)).
  void recordPredict(const ImuReading& imu, double dt_s);
  /// One TDoA, in its place among the predictions.
  void recordTdoa(const TdoaMeasurement& z);

  /// Restarts `filter` from the recorded one with position p0 and velocity v0 under the std pos_sigma_m and
  /// vel_sigma_mps (no correlation with the other states) and runs the record again: every TDoA through
  /// update(filter, z), the covariance propagated first when at least cov_period_s of transition is pending (as the
  /// estimator does, EkfParams::cov_period_s). Returns false (filter untouched) when there is no valid record; the
  /// record ends either way.
  template <class Update>
  bool replay(Ekf& filter, const Vec3& p0, const Vec3& v0, double pos_sigma_m, double vel_sigma_mps,
              double cov_period_s, Update&& update);

 private:
  struct Prediction {
    double acc[3], gyro[3], dt_s;
  };
  /// A prediction (imu, dt_s) or a TDoA (z), 64 bytes either way.
  struct Entry {
    bool is_tdoa = false;
    union {
      Prediction predict;
      TdoaMeasurement z;
    };
    Entry() : predict{} {}
  };
  Ekf base_;
  std::vector<Entry> entries_;
  double t_ref_s_;
  bool recording_ = false;
  bool overflow_ = false;
  void append(const Entry& e);
  /// base_ with p, v replaced (F16g prior).
  Ekf restart(const Vec3& p0, const Vec3& v0, double pos_sigma_m, double vel_sigma_mps) const;
};

template <class Update>
bool StartReplay::replay(Ekf& filter, const Vec3& p0, const Vec3& v0, double pos_sigma_m, double vel_sigma_mps,
                         double cov_period_s, Update&& update) {
  const bool valid = recording_ && !overflow_;
  recording_ = false;
  if (!valid) return false;
  filter = restart(p0, v0, pos_sigma_m, vel_sigma_mps);
  for (const Entry& e : entries_) {
    if (e.is_tdoa) {
      if (filter.pendingDt() >= cov_period_s) filter.propagateCovariance();
      update(filter, e.z);
    } else {
      ImuReading imu;
      imu.b_acc_mps2 = Vec3(e.predict.acc[0], e.predict.acc[1], e.predict.acc[2]);
      imu.b_gyro_radps = Vec3(e.predict.gyro[0], e.predict.gyro[1], e.predict.gyro[2]);
      filter.predict(imu, e.predict.dt_s);
    }
  }
  filter.propagateCovariance();
  entries_.clear();
  return true;
}

}  // namespace uwb
