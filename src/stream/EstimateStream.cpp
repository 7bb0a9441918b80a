/** @file EstimateStream.cpp
 *  @brief The online loop with the batch path's output cadence (TdoaLocalizer::run, docs/math/filter.md F17).
 */
#include "uwb/stream/EstimateStream.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace uwb {

EstimateStream::EstimateStream(const EkfParams& params, AnchorTable anchors, double output_period_s,
                               BiasPredictor bias)
    : output_period_s_(output_period_s) {
  if (!(output_period_s >= 0.0) || !std::isfinite(output_period_s))
    throw std::invalid_argument("EstimateStream: the output period must be finite and ≥ 0");
  // as TdoaLocalizer::run: with a bias model and bias_guard the corrected and the uncorrected filter run side by side
  if (usesBiasGuard(params, bias)) guarded_ = std::make_unique<GuardedEstimator>(params, anchors, std::move(bias));
  else plain_.emplace(params, std::move(anchors), std::move(bias));
}

bool EstimateStream::add(const StreamEvent& ev) {
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

bool EstimateStream::finish() {
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
