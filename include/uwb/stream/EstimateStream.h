/** @file EstimateStream.h
 *  @brief The online loop: events in, estimates out at a minimum spacing. The same cadence as the batch path
 *         (TdoaLocalizer::run): an estimate after an IMU or TDoA event once the position is known and at least
 *         output_period_s after the previous one, stamped with the event's time; ToF events give none; at the end
 *         one more at the last event's stamp when that is later than the last estimate. The same events in the same
 *         order therefore give the same estimates.
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

#include "uwb/filter/BiasGuard.h"
#include "uwb/filter/Estimator.h"
#include "uwb/stream/LineProtocol.h"

namespace uwb {

class EstimateStream {
 public:
  /// output_period_s ≥ 0 (0: one estimate per IMU/TDoA event). Throws std::invalid_argument otherwise and on what
  /// the Estimator rejects.
  EstimateStream(const EkfParams& params, AnchorTable anchors, double output_period_s, BiasPredictor bias = {});

  /// Folds one event in; true when an estimate is due (then last() holds it). kNone events are ignored.
  bool add(const StreamEvent& ev);
  /// End of input: true when a final estimate is due (then last() holds it).
  bool finish();
  const LocalizerEstimate& last() const { return last_; }
  /// The online estimator (with the bias guard, F24: its corrected filter).
  const Estimator& estimator() const { return guarded_ ? guarded_->corrected() : *plain_; }
  std::size_t eventsIn() const { return n_events_; }
  bool ready() const { return guarded_ ? guarded_->ready() : plain_->ready(); }

 private:
  bool emit(double t_s);
  /// Calls f with the estimator in use: the guarded pair (a bias model and bias_guard, F24) or the single filter.
  template <class F>
  void withEstimator(F&& f) {
    if (guarded_) f(*guarded_);
    else f(*plain_);
  }
  std::optional<Estimator> plain_;
  std::unique_ptr<GuardedEstimator> guarded_;
  double output_period_s_;
  double t_last_out_ = -1e300;
  double t_max_ = -std::numeric_limits<double>::infinity();
  bool any_out_ = false;
  std::size_t n_events_ = 0;
  LocalizerEstimate last_;
};

}  // namespace uwb
