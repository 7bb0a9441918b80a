/** @file LatencyStats.cpp
 *  @brief Nearest-rank percentiles of the per-event latencies.
 */
#include "uwb/stream/LatencyStats.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

namespace uwb {

double LatencyStats::quantile(double q) const {
  if (samples_s_.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::vector<double> v = samples_s_;
  // nearest rank: the smallest sample with at least q·n samples at or below it
  const std::size_t rank = static_cast<std::size_t>(std::ceil(std::clamp(q, 0.0, 1.0) * v.size()));
  const std::size_t k = rank == 0 ? 0 : rank - 1;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

std::string LatencyStats::summary() const {
  return fmt::format("n={}, p50 {:.1f} µs, p99 {:.1f} µs, max {:.1f} µs", samples_s_.size(), quantile(0.5) * 1e6,
                     quantile(0.99) * 1e6, quantile(1.0) * 1e6);
}

}  // namespace uwb
