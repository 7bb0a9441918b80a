/** @file EstimateStream.cpp
 *  @brief The online loop with the batch path's output cadence (TdoaLocalizer::run, docs/math/filter.md F17), behind
 *         a clock guard (docs/io.md §5, "Stamps off the clock").
 */
#include "uwb/stream/EstimateStream.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace uwb {

EstimateStream::EstimateStream(const EkfParams& params, AnchorTable anchors, double output_period_s,
                               BiasPredictor bias, StreamClockParams clock)
    : output_period_s_(output_period_s) {
  if (!(output_period_s >= 0.0) || !std::isfinite(output_period_s))
    throw std::invalid_argument("EstimateStream: the output period must be finite and ≥ 0");
  if (!(clock.max_lead_s > 0.0) || !(clock.max_lag_s > 0.0) || !std::isfinite(clock.max_lead_s) ||
      !std::isfinite(clock.max_lag_s) || clock.confirm_events < 1)
    throw std::invalid_argument("EstimateStream: the clock guard's tolerances must be finite and > 0");
  params_ = params;
  anchors_ = std::move(anchors);
  bias_ = std::move(bias);
  clock_ = clock;
  restart();
}

void EstimateStream::restart() {
  // (F31) the range check's counts outlive the estimator
  if (guarded_ || plain_) range_before_.merge(estimator().summary().sensor_range);
  else range_before_ = SensorRangeReport(params_);
  // as TdoaLocalizer::run: with a bias model and bias_guard the corrected and the uncorrected filter run side by side
  guarded_.reset();
  plain_.reset();
  if (usesBiasGuard(params_, bias_)) guarded_ = std::make_unique<GuardedEstimator>(params_, anchors_, bias_);
  else plain_.emplace(params_, anchors_, bias_);
  t_last_out_ = -1e300;
  t_max_ = -std::numeric_limits<double>::infinity();
  any_out_ = false;
}

void EstimateStream::dropHeld() {
  if (held_.empty()) return;
  n_outliers_ += held_.size();
  t_last_outlier_s_ = held_.front().t_s;
  t_last_outlier_clock_s_ = t_max_;
  held_.clear();
}

bool EstimateStream::add(const StreamEvent& ev) {
  if (ev.kind == StreamEvent::Kind::kNone) return false;
  ++n_seen_;
  // the clock guard: the first event sets the clock; later ones on it pass, the others are held
  if (!std::isfinite(t_max_) || onClock(ev.t_s, t_max_)) {
    dropHeld();  // the clock went on: what was held was a group of outlier stamps
    return accept(ev);
  }
  if (!held_.empty() && !onClock(ev.t_s, t_held_max_)) dropHeld();  // off both clocks: start a new candidate
  if (held_.empty()) {
    held_first_index_ = n_seen_;
    t_held_max_ = ev.t_s;
  }
  held_.push_back(ev);
  t_held_max_ = std::max(t_held_max_, ev.t_s);
  if (held_.size() < clock_.confirm_events) return false;
  // confirm_events in a row agree off the old clock: the clock jumped (a reboot, a stepped clock); start again
  jumps_.push_back({t_max_, held_.front().t_s, held_first_index_});
  restart();
  bool out = false;
  for (const StreamEvent& h : held_) out = accept(h);
  held_.clear();
  return out;
}

bool EstimateStream::accept(const StreamEvent& ev) {
  switch (ev.kind) {
    case StreamEvent::Kind::kNone: return false;
    case StreamEvent::Kind::kImu: withEstimator([&](auto& e) { e.addImu(ev.t_s, ev.imu); }); break;
    case StreamEvent::Kind::kTdoa: withEstimator([&](auto& e) { e.addTdoa(ev.tdoa); }); break;
    case StreamEvent::Kind::kTof:
      ++n_events_;
      t_max_ = std::max(t_max_, ev.t_s);
      withEstimator([&](auto& e) { e.addTof(ev.tof); });
      return false;  // as in the batch path: outputs follow the IMU and TDoA events only
  }
  ++n_events_;
  t_max_ = std::max(t_max_, ev.t_s);
  if (ready() && ev.t_s - t_last_out_ >= output_period_s_) return emit(ev.t_s);
  return false;
}

SensorRangeReport EstimateStream::sensorRange() const {
  SensorRangeReport r = range_before_;
  r.merge(estimator().summary().sensor_range);
  return r;
}

bool EstimateStream::finish() {
  dropHeld();  // never confirmed: outliers
  if (n_events_ == 0 || !ready()) return false;
  if (any_out_ && !(t_last_out_ < t_max_)) return false;
  return emit(t_max_);
}

bool EstimateStream::emit(double t_s) {
  withEstimator([&](auto& e) { last_ = e.estimate(); });
  last_.t_s = t_s;
  t_last_out_ = t_s;
  any_out_ = true;
  return true;
}

}  // namespace uwb
