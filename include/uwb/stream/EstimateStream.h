/** @file EstimateStream.h
 *  @brief The online loop: events in, estimates out at a minimum spacing. The same cadence as the batch path
 *         (TdoaLocalizer::run): an estimate after an IMU or TDoA event once the position is known and at least
 *         output_period_s after the previous one, stamped with the event's time; ToF events give none; at the end
 *         one more at the last event's stamp when that is later than the last estimate. The same events in the same
 *         order therefore give the same estimates.
 *
 *  A clock guard sits in front of the estimator (docs/io.md §5, "Stamps off the clock"): an event whose stamp lies
 *  more than StreamClockParams::max_lead_s after the latest stamp, or more than max_lag_s before it, is held, not
 *  folded in. If the next event is back on the clock, the held events were outliers: skipped and counted
 *  (stampOutliers()). If instead confirm_events events in a row agree with each other off the clock (a sensor that
 *  rebooted and counts from 0, or a clock that stepped), the clock has jumped: the estimator starts again from
 *  scratch on the new time base with the held events, the jump is recorded (clockJumps()) and estimates follow as
 *  soon as the new estimator has its position. One stamp of 1e12 s therefore costs one event, and a reboot costs a
 *  re-initialisation, never the rest of the flight.
 *
 *  @code
 *    EstimateStream s(params, anchors, 0.01);
 *    for (each StreamEvent ev) if (s.add(ev)) publish(s.last());
 *    if (s.finish()) publish(s.last());
 *  @endcode
 */
#pragma once

#include <limits>

#include <memory>
#include <optional>
#include <vector>

#include "uwb/filter/BiasGuard.h"
#include "uwb/filter/Estimator.h"
#include "uwb/stream/LineProtocol.h"

namespace uwb {

/// The clock guard's tolerances (see above).
struct StreamClockParams {
  double max_lead_s = 5.0;  ///< a stamp further ahead of the latest is off the clock [s] (a longer sensor gap too)
  double max_lag_s = 2.0;   ///< a stamp further behind the latest is off the clock [s]
  std::size_t confirm_events = 10;  ///< events in a row off the clock, agreeing among themselves, that make a jump
};

/// A clock jump the guard accepted: the estimator restarted on the new time base.
struct StreamClockJump {
  double t_from_s = 0.0;  ///< the latest stamp on the old clock [s]
  double t_to_s = 0.0;    ///< the first stamp on the new clock [s]
  std::size_t event_index = 0;  ///< 1-based index (among the non-empty events given to add()) of that first event
};

class EstimateStream {
 public:
  /// output_period_s ≥ 0 (0: one estimate per IMU/TDoA event). Throws std::invalid_argument otherwise and on what
  /// the Estimator rejects.
  EstimateStream(const EkfParams& params, AnchorTable anchors, double output_period_s, BiasPredictor bias = {},
                 StreamClockParams clock = {});

  /// Folds one event in (through the clock guard); true when an estimate is due (then last() holds it). kNone events
  /// are ignored.
  bool add(const StreamEvent& ev);
  /// End of input: true when a final estimate is due (then last() holds it).
  bool finish();
  const LocalizerEstimate& last() const { return last_; }
  /// The online estimator (with the bias guard, F24: its corrected filter).
  const Estimator& estimator() const { return guarded_ ? guarded_->corrected() : *plain_; }
  /// Events folded into an estimator (held and skipped ones not counted).
  std::size_t eventsIn() const { return n_events_; }
  /// Events skipped because their stamp was off the clock and no jump confirmed it (at finish(): those still held).
  std::size_t stampOutliers() const { return n_outliers_; }
  /// The first stamp of the last group of events skipped as outliers, and the clock's latest stamp then [s].
  double lastOutlierStamp() const { return t_last_outlier_s_; }
  double lastOutlierClock() const { return t_last_outlier_clock_s_; }
  /// Every clock jump accepted, in order (each restarted the estimator).
  const std::vector<StreamClockJump>& clockJumps() const { return jumps_; }
  bool ready() const { return guarded_ ? guarded_->ready() : plain_->ready(); }
  /// Samples skipped outside the sensors' physical ranges (filter.md F31) over the whole stream: the estimators
  /// before each clock jump's restart and the current one.
  SensorRangeReport sensorRange() const;

 private:
  bool emit(double t_s);
  /// Folds an event into the estimator and applies the output cadence.
  bool accept(const StreamEvent& ev);
  /// True when t_s is on the clock whose latest stamp is t_ref_s.
  bool onClock(double t_s, double t_ref_s) const {
    return t_s >= t_ref_s - clock_.max_lag_s && t_s <= t_ref_s + clock_.max_lead_s;
  }
  void dropHeld();
  void restart();
  /// Calls f with the estimator in use: the guarded pair (a bias model and bias_guard, F24) or the single filter.
  template <class F>
  void withEstimator(F&& f) {
    if (guarded_) f(*guarded_);
    else f(*plain_);
  }
  EkfParams params_;
  AnchorTable anchors_;
  BiasPredictor bias_;
  StreamClockParams clock_;
  std::optional<Estimator> plain_;
  std::unique_ptr<GuardedEstimator> guarded_;
  double output_period_s_;
  double t_last_out_ = -1e300;
  double t_max_ = -std::numeric_limits<double>::infinity();
  bool any_out_ = false;
  std::size_t n_events_ = 0;
  std::size_t n_seen_ = 0;  ///< non-empty events given to add()
  LocalizerEstimate last_;
  std::vector<StreamEvent> held_;  ///< events off the clock, agreeing among themselves
  std::size_t held_first_index_ = 0;
  double t_held_max_ = 0.0;
  std::size_t n_outliers_ = 0;
  double t_last_outlier_s_ = 0.0, t_last_outlier_clock_s_ = 0.0;
  std::vector<StreamClockJump> jumps_;
  SensorRangeReport range_before_;  ///< (F31) of the estimators replaced by restarts
};

}  // namespace uwb
