/** @file BiasGuard.h
 *  @brief A bias correction that never makes the estimate worse than no correction: the corrected and the
 *         uncorrected filter run side by side on the same events, and the output is their mixture weighted by how
 *         well each predicted the recent TDoA (docs/math/filter.md F24).
 *
 *  A bias model learned on other flights may not transfer to this one (another path, day or drone). Which of the
 *  two filters describes the flight better is a model-comparison question that the flight itself answers: each
 *  filter's innovation r with its variance S is its one-step predictive density of the next TDoA, and their
 *  log-likelihood ratio, forgotten over bias_guard_tau_s, is the log-odds of "the correction fits this flight".
 *  Nothing is decided for good: the weight follows the evidence both ways.
 *
 *  @code
 *    GuardedEstimator est(params, anchors, bias);   // same event interface as Estimator
 *    est.addImu(t, imu);  est.addTdoa(z);
 *    if (est.ready()) { LocalizerEstimate e = est.estimate(); double w = est.weight(); }
 *  @endcode
 */
#pragma once

#include <limits>

#include "uwb/filter/Estimator.h"

namespace uwb {

/// (F24) Robust negative log predictive density of one TDoA: ρ_k(√(r²/S)) + ½ log S, with ρ_k the Huber loss
/// (k = 3): a gross outlier costs linearly, so one bad TDoA cannot decide the comparison. +∞ when S ≤ 0.
double predictiveNll(double nis, double innovation_var_m2);

/// Whether the online paths (TdoaLocalizer::run, EstimateStream) run the guarded pair: a bias model and bias_guard.
inline bool usesBiasGuard(const EkfParams& params, const BiasPredictor& bias) {
  return static_cast<bool>(bias) && params.bias_guard;
}

class GuardedEstimator {
 public:
  /// params.bias_guard_tau_s is the comparison's memory. Throws as Estimator does.
  GuardedEstimator(const EkfParams& params, const AnchorTable& anchors, BiasPredictor bias);
  GuardedEstimator(const GuardedEstimator&) = delete;
  GuardedEstimator& operator=(const GuardedEstimator&) = delete;

  void addImu(double t_s, const ImuReading& imu);
  void addTdoa(const TdoaMeasurement& z);
  void addTof(const TofObservation& tof);

  bool ready() const { return corrected_.ready() && plain_.ready(); }
  double time() const { return corrected_.time(); }
  /// The moment-matched mixture of the two filters' estimates with weight() on the corrected one (F24).
  LocalizerEstimate estimate() const;
  /// The corrected filter's summary with the guard's weights filled in.
  LocalizerSummary summary() const;
  /// Current weight of the corrected filter in the output, in [0, 1].
  double weight() const { return w_; }
  /// Forgotten log-likelihood ratio log p(z | corrected) − log p(z | uncorrected) (F24).
  double logOdds() const { return log_odds_; }
  const Estimator& corrected() const { return corrected_; }
  const Estimator& uncorrected() const { return plain_; }

 private:
  Estimator corrected_;
  Estimator plain_;
  double tau_s_;
  double log_odds_ = 0.0;
  double w_ = 0.5;
  double t_last_ = std::numeric_limits<double>::quiet_NaN();
  double w_time_sum_ = 0.0, time_sum_ = 0.0;
};

}  // namespace uwb
