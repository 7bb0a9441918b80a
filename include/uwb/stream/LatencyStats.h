/** @file LatencyStats.h
 *  @brief Per-event latencies of `stream --stats` (a message's arrival to the end of its handling, including the
 *         estimate's send when one is due) and their percentiles.
 */
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace uwb {

class LatencyStats {
 public:
  void add(double latency_s) { samples_s_.push_back(latency_s); }
  std::size_t size() const { return samples_s_.size(); }
  /// The q-quantile (0 ≤ q ≤ 1) by the nearest-rank rule; NaN when empty.
  double quantile(double q) const;
  /// "n=…, p50 … µs, p99 … µs, max … µs".
  std::string summary() const;

 private:
  std::vector<double> samples_s_;
};

}  // namespace uwb
