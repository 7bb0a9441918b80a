/** @file ResidualStats.cpp
 *  @brief Median, mean/median absolute deviations, mean, std and RMS of a set of residuals (docs/io.md,
 *         "Residual statistics").
 */
#include "uwb/io/ResidualStats.h"

#include <algorithm>
#include <cmath>

namespace uwb {

namespace {

double medianInPlace(std::vector<double>& v) {
  const std::size_t n = v.size();
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(v.begin(), mid, v.end());
  const double hi = *mid;
  if (n % 2 == 1) return hi;
  const double lo = *std::max_element(v.begin(), mid);
  return 0.5 * (lo + hi);
}

}  // namespace

ResidualStats residualStats(std::vector<double> values, double gross_residual_m) {
  ResidualStats st;
  st.n = values.size();
  if (values.empty()) return st;
  double sum = 0.0;
  double sum2 = 0.0;
  for (double v : values) {
    sum += v;
    sum2 += v * v;
  }
  st.mean_m = sum / static_cast<double>(st.n);
  double var = 0.0;
  for (double v : values) var += (v - st.mean_m) * (v - st.mean_m);
  st.std_m = std::sqrt(var / static_cast<double>(st.n));
  st.rms_m = std::sqrt(sum2 / static_cast<double>(st.n));
  st.median_m = medianInPlace(values);
  double abs_sum = 0.0;
  double kept_sum = 0.0;
  std::size_t n_kept = 0;
  for (double& v : values) {
    v = std::abs(v - st.median_m);
    abs_sum += v;
    if (v < gross_residual_m) {
      kept_sum += v;
      ++n_kept;
    }
  }
  st.mean_abs_dev_m = abs_sum / static_cast<double>(st.n);
  st.n_gross = st.n - n_kept;
  st.mad_m = n_kept > 0 ? kept_sum / static_cast<double>(n_kept) : 0.0;
  st.median_abs_dev_m = medianInPlace(values);
  return st;
}

}  // namespace uwb
