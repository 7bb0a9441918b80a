/** @file Tdoa.h
 *  @brief One TDoA measurement, as the files, the simulator, the stream and the filter carry it
 *         (docs/math/measurement.md M1; UTIL sign convention).
 */
#pragma once

namespace uwb {

/// One TDoA measurement between anchors A and B: tdoa_m = |p_tag − a_B| − |p_tag − a_A| + noise (M1).
struct TdoaMeasurement {
  double t_s = 0.0;     ///< time of the measurement, on the drone's clock [s]
  int id_a = 0;         ///< anchor A (its range is subtracted)
  int id_b = 0;         ///< anchor B
  double tdoa_m = 0.0;  ///< the range difference [m]
};

}  // namespace uwb
