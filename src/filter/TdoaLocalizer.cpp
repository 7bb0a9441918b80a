/** @file TdoaLocalizer.cpp
 *  @brief The batch path over the online Estimator (docs/math/filter.md F17).
 */
#include "uwb/filter/TdoaLocalizer.h"

#include "uwb/filter/BiasGuard.h"

#include <stdexcept>

namespace uwb {
namespace {

/// Feeds every event of the log to the online estimator (Estimator or GuardedEstimator) and takes its estimate at the
/// output spacing.
template <class OnlineEstimator>
void runEvents(OnlineEstimator& estimator, const SensorLog& log, SensorEventCursor& events, double output_period_s,
               LocalizerResult& result) {
  if (events.empty()) {
    result.summary = estimator.summary();
    return;
  }
  // outputs spaced by output_period_s (plus one at the end): reserve once, no regrowth
  const double span_s = events.lastStamp() - events.firstStamp();
  const double n_out_max = output_period_s > 0.0 ? span_s / output_period_s + 2.0 : 0.0;
  result.estimates.reserve(output_period_s > 0.0 && n_out_max < static_cast<double>(events.size())
                               ? static_cast<std::size_t>(n_out_max)
                               : events.size() + 1);
  double t_last_out = -1e300;
  for (SensorEvent ev; events.next(ev);) {
    switch (ev.kind) {
      case SensorEvent::Kind::kImu: estimator.addImu(ev.t_s, log.imu[ev.index].imu); break;
      case SensorEvent::Kind::kTdoa: estimator.addTdoa(log.tdoa[ev.index]); break;
      case SensorEvent::Kind::kTof:
        estimator.addTof(log.tof[ev.index]);
        continue;  // outputs follow the IMU and TDoA events only: the trajectory does not depend on the ToF stream
    }
    if (estimator.ready() && ev.t_s - t_last_out >= output_period_s) {
      result.estimates.push_back(estimator.estimate());
      result.estimates.back().t_s = ev.t_s;
      t_last_out = ev.t_s;
    }
  }
  if (estimator.ready() && (result.estimates.empty() || result.estimates.back().t_s < events.lastStamp())) {
    result.estimates.push_back(estimator.estimate());
    result.estimates.back().t_s = events.lastStamp();
  }
  result.summary = estimator.summary();
}

}  // namespace

TdoaLocalizer::TdoaLocalizer(const EkfParams& params, AnchorTable anchors, BiasPredictor bias)
    : params_(params), anchors_(std::move(anchors)), bias_(std::move(bias)) {
  params_.validate();
  if (anchors_.size() < 4) throw std::invalid_argument("TdoaLocalizer: at least 4 anchors are needed");
}

LocalizerResult TdoaLocalizer::run(const SensorLog& input, double output_period_s) const {
  LocalizerResult result;
  // (F17) streams cleaned and merged; the input is copied only when it needs cleaning, and the merged sequence is
  // walked by a cursor over the clean streams instead of being stored
  SensorLog cleaned;
  const std::optional<MergeReport> clean_report = cleanSensorLogReportIfClean(input, params_.max_gap_s);
  const bool input_clean = clean_report.has_value();
  if (!input_clean) cleaned = input;
  const SensorLog& log = input_clean ? input : cleaned;
  const MergeReport merge = input_clean ? *clean_report : cleanSensorLog(cleaned, params_.max_gap_s);
  SensorEventCursor events(log);

  EkfParams p = params_;
  if (log.imu.empty() && p.process_model == ProcessModel::kImu) p.process_model = ProcessModel::kConstantVelocity;
  if (p.process_model != ProcessModel::kImu) p.ground_phase = GroundPhase::kNone;
  if (usesBiasGuard(p, bias_)) {
    // (F24) the corrected filter beside the uncorrected one, mixed by their recent predictive likelihood
    GuardedEstimator estimator(p, anchors_, bias_);
    runEvents(estimator, log, events, output_period_s, result);
  } else {
    Estimator estimator(p, anchors_, bias_);
    runEvents(estimator, log, events, output_period_s, result);
  }
  result.summary.merge = merge;
  if (!events.empty()) {
    result.summary.start_t_s = events.firstStamp();
    result.summary.end_t_s = events.lastStamp();
  }
  return result;
}

}  // namespace uwb
