/** @file FlightSimulator.h
 *  @brief Simulates a whole Crazyflie flight in the UTIL layout: IMU (~1 kHz), Vicon pose (300 Hz) and TDoA2
 *  neighbour pairs (~400 Hz) with a pose-dependent bias, noise, outliers and the ground phase, plus the truth.
 *
 *  Deterministic for a given seed (std::mt19937_64, no global state). docs/math/simulation.md (S1)–(S20).
 */
#pragma once

#include <cstdint>
#include <vector>

#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"
#include "uwb/sim/SimulatedBias.h"
#include "uwb/sim/Scenario.h"
#include "uwb/sim/SimParams.h"

namespace uwb::sim {

/// Truth of one TDoA measurement (same index as Flight::tdoa).
struct TdoaTruth {
  double tdoa_true_m = 0.0;  ///< |p_tag − a_B| − |p_tag − a_A| at the exact pose (S20)
  TdoaErrorParts error;      ///< measured = tdoa_true_m + error.total()
  bool on_ground = false;    ///< in a ground phase of the trajectory
  bool airborne = false;     ///< isAirborne(body z in the world frame), io/Airborne.h
};

/// IMU truth of one sample (same index as Flight::acc and Flight::gyro).
struct ImuTruth {
  Vec3 b_specific_force = Vec3::Zero();  ///< [m/s²]
  Vec3 b_omega = Vec3::Zero();           ///< [rad/s]
  Vec3 b_acc_bias = Vec3::Zero();        ///< [m/s²]
  Vec3 b_gyro_bias = Vec3::Zero();       ///< [rad/s]
};

struct SimResult {
  Flight flight;                    ///< SI units; the writer converts to g and deg/s
  AnchorSurvey survey;
  std::vector<TdoaTruth> tdoa_truth;
  std::vector<ImuTruth> imu_truth;
  std::vector<PoseSample> pose_exact;  ///< unquantized pose at the pose timestamps
};

/// Simulates the scenario. Throws std::invalid_argument when the scenario or the params are invalid.
SimResult simulateFlight(const Scenario& scenario, const SimParams& params, std::uint64_t seed);

/// The 27 UTIL flight-CSV columns in file order.
const std::vector<std::string>& utilFlightColumns();

}  // namespace uwb::sim
