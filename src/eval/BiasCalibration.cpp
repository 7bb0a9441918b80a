/** @file BiasCalibration.cpp
 *  @brief Coverage and NLPD of the predicted TDoA bias (docs/math/gp.md P43).
 */
#include "uwb/eval/BiasCalibration.h"

#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "uwb/core/Types.h"

namespace uwb {

const std::vector<double>& calibrationLevels() {
  static const std::vector<double> levels = [] {
    std::vector<double> l;
    for (int i = 1; i <= 19; ++i) l.push_back(0.05 * i);
    l.push_back(0.99);
    return l;
  }();
  return levels;
}

double centralIntervalHalfWidth(double p) {
  if (!(p > 0.0) || !(p < 1.0)) throw std::invalid_argument("central interval: probability must be in (0, 1)");
  // P(|Z| ≤ z) = erf(z/√2) is increasing in z: bisection to machine precision on [0, 40].
  double lo = 0.0, hi = 40.0;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (std::erf(mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double centralIntervalHalfWidth(double p, const PredictiveShape& shape) {
  shape.validate();
  if (shape.dof == 0.0) return shape.scale * centralIntervalHalfWidth(p);
  if (!(p > 0.0) || !(p < 1.0)) throw std::invalid_argument("central interval: probability must be in (0, 1)");
  // (P43b) P(|T_ν| ≤ w) = p  ⇔  w = t_ν⁻¹((1 + p)/2)
  return shape.scale * boost::math::quantile(boost::math::students_t_distribution<double>(shape.dof), 0.5 * (1.0 + p));
}

double predictiveLogDensity(double r_m, double variance_m2, const PredictiveShape& shape) {
  const double s2 = shape.scale * shape.scale * variance_m2;  // the scale's square, (κσ)²
  if (shape.dof == 0.0) return -0.5 * (std::log(2.0 * kPi * s2) + r_m * r_m / s2);  // (P43)
  // (P43b) Student-t: Γ((ν+1)/2) / (Γ(ν/2) √(νπ) s) · (1 + r²/(ν s²))^{−(ν+1)/2}
  const double nu = shape.dof;
  return std::lgamma(0.5 * (nu + 1.0)) - std::lgamma(0.5 * nu) - 0.5 * std::log(nu * kPi * s2) -
         0.5 * (nu + 1.0) * std::log1p(r_m * r_m / (nu * s2));
}

BiasCalibration biasCalibration(const std::vector<double>& residual_m, const std::vector<double>& variance_m2,
                                const PredictiveShape& shape) {
  if (residual_m.size() != variance_m2.size()) throw std::invalid_argument("bias calibration: sizes differ");
  shape.validate();
  const std::vector<double>& levels = calibrationLevels();
  std::vector<double> half(levels.size());
  for (std::size_t k = 0; k < levels.size(); ++k) half[k] = centralIntervalHalfWidth(levels[k], shape);
  const double w1 = centralIntervalHalfWidth(kOneSigmaMass, shape), w2 = centralIntervalHalfWidth(kTwoSigmaMass, shape);
  BiasCalibration c;
  c.shape = shape;
  c.coverage.assign(levels.size(), 0.0);
  double in1 = 0, in2 = 0, nlpd = 0, se = 0, sum_std = 0;
  for (std::size_t i = 0; i < residual_m.size(); ++i) {
    const double var = variance_m2[i], r = residual_m[i];
    if (!(var > 0.0) || !std::isfinite(var) || !std::isfinite(r))
      throw std::invalid_argument("bias calibration: predictive variance must be positive and finite");
    const double sd = std::sqrt(var), z = std::abs(r) / sd;
    in1 += z <= w1 ? 1 : 0;
    in2 += z <= w2 ? 1 : 0;
    for (std::size_t k = 0; k < levels.size(); ++k) c.coverage[k] += z <= half[k] ? 1 : 0;
    nlpd -= predictiveLogDensity(r, var, shape);  // (P43, P43b)
    se += r * r;
    sum_std += sd;
  }
  c.n = residual_m.size();
  if (c.n == 0) {
    c.coverage_1sigma = c.coverage_2sigma = c.nlpd = c.rmse_m = c.mean_std_m = std::nan("");
    for (auto& v : c.coverage) v = std::nan("");
    return c;
  }
  const double n = static_cast<double>(c.n);
  c.coverage_1sigma = in1 / n;
  c.coverage_2sigma = in2 / n;
  c.nlpd = nlpd / n;
  c.rmse_m = std::sqrt(se / n);
  c.mean_std_m = sum_std / n;
  for (auto& v : c.coverage) v /= n;
  return c;
}

BiasCalibration biasCalibration(const BiasDataset& data, const BiasModel& model) {
  std::vector<double> r, var;
  r.reserve(data.samples.size());
  var.reserve(data.samples.size());
  std::size_t uncovered = 0;
  // (P43c) each sample on its flight: the level the dataset's filter run measured there and that of the model's mean
  const std::vector<BiasPredictive> predictive = datasetPredictives(model, data).samples;
  for (std::size_t i = 0; i < predictive.size(); ++i) {
    const BiasPredictive& p = predictive[i];
    if (!p.covered) {
      ++uncovered;
      continue;
    }
    r.push_back(data.samples[i].error_m - p.mean_m);
    var.push_back(p.varianceM2());
  }
  BiasCalibration c = biasCalibration(r, var, model.predictiveShape());
  c.n_uncovered = uncovered;
  return c;
}

nlohmann::json toJson(const BiasCalibration& c) {
  return {{"n", c.n},
          {"n_uncovered", c.n_uncovered},
          {"coverage_1sigma", c.coverage_1sigma},
          {"coverage_2sigma", c.coverage_2sigma},
          {"nlpd", c.nlpd},
          {"rmse_m", c.rmse_m},
          {"mean_std_m", c.mean_std_m},
          {"levels", calibrationLevels()},
          {"coverage", c.coverage},
          {"predictive_dof", c.shape.dof},
          {"predictive_scale", c.shape.scale}};
}

}  // namespace uwb
