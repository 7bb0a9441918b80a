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
    : estimator_(params, std::move(anchors), std::move(bias)), output_period_s_(output_period_s) {
  if (!(output_period_s >= 0.0) || !std::isfinite(output_period_s))
    throw std::invalid_argument("EstimateStream: the output period must be finite and ≥ 0");
  if (params.bias_guard && estimator_.hasBiasModel())
    throw std::invalid_argument(
        "EstimateStream: bias_guard (docs/math/filter.md F24) runs in the batch path only (localize, evaluate); "
        "the stream would give other estimates than `localize` with the same flags");
}

bool EstimateStream::add(const StreamEvent& ev) {
  switch (ev.kind) {
    case StreamEvent::Kind::kNone: return false;
    case StreamEvent::Kind::kImu: estimator_.addImu(ev.t_s, ev.imu); break;
    case StreamEvent::Kind::kTdoa: estimator_.addTdoa(ev.tdoa); break;
    case StreamEvent::Kind::kTof:
      ++n_events_;
      t_max_ = std::max(t_max_, ev.t_s);
      estimator_.addTof(ev.tof);
      return false;  // as in the batch path: outputs follow the IMU and TDoA events only
  }
  ++n_events_;
  t_max_ = std::max(t_max_, ev.t_s);
  if (estimator_.ready() && ev.t_s - t_last_out_ >= output_period_s_) return emit(ev.t_s);
  return false;
}

bool EstimateStream::finish() {
  if (n_events_ == 0 || !estimator_.ready()) return false;
  if (any_out_ && !(t_last_out_ < t_max_)) return false;
  return emit(t_max_);
}

bool EstimateStream::emit(double t_s) {
  last_ = estimator_.estimate();
  last_.t_s = t_s;
  t_last_out_ = t_s;
  any_out_ = true;
  return true;
}

}  // namespace uwb
