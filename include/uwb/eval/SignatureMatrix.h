/** @file SignatureMatrix.h
 *  @brief The sensor-signature matrix of `uwbtdoa protocol --signatures`: each flight localized with other drones'
 *         IMU signatures (docs/math/simulation.md S24) against the same flight with its own (docs/robustness.md).
 *
 *  Flights: simulated flights from the floor (the simulator's plain IMU) and transplants of real development flights
 *  (their own IMU low-passed, then the signature added by phase). Cells: in-flight gyro vibration 0–40 °/s, in-flight
 *  accelerometer vibration 0.005–0.3 g, the floor with the motors off, idling at 10–40 °/s or hand-held (a wobble of
 *  10–30 °/s), the IMU at 100, 500 and 1000 Hz, a gyro bias of 3 °/s, an accelerometer bias of 0.1 g, IMU stamps 10
 *  and 30 ms behind the TDoA, the signature of a drone whose floor is quiet and whose gyro shakes in flight, and three
 *  cells that combine several of these.
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "uwb/eval/Localization.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"
#include "uwb/sim/ImuSignature.h"

namespace uwb {

struct SignatureCell {
  std::string name;
  sim::ImuSignature signature;
};

struct SignatureFlight {
  std::string name;
  Flight flight;
  AnchorSurvey survey;
  bool transplant = false;  ///< a real flight: its own in-flight vibration is replaced (S24)
};

/// What one cell did on one flight, against the same flight with its own signature.
struct SignatureRow {
  std::string flight, cell;
  double rmse_plain_m = 0.0, rmse_cell_m = 0.0;  ///< airborne RMSE [m]
  double ratio = 0.0;                            ///< rmse_cell / rmse_plain
  /// Airborne TDoA (by the truth) that were not taken at the floor's σ: 1 − (at-floor TDoA while the truth flies, in
  /// excess of the plain run's) / airborne TDoA
  double in_flight_fraction = 0.0;
  double longest_floor_stuck_s = 0.0;  ///< longest span with the estimate within 0.2 m of the floor, truth above 0.5 m
  Vec3 coverage_2sigma = Vec3::Zero();
  std::size_t mode_overrules = 0;      ///< mode changes the TDoA forced against the IMU (filter.md F29)
  bool pass = false;                   ///< ratio ≤ 1.2, in-flight ≥ 95 %, stuck ≤ 1 s
  int n_draws = 1;                     ///< vibration draws behind the row (evaluateSignatureDraws)
  int n_draws_pass = 0;                ///< … of which passed
};

/// The cells of the matrix; transplant cells replace the flight's own in-flight vibration.
std::vector<SignatureCell> signatureCells(bool transplant);

/// The flights: simulated circle and zigzag from the floor (seed 11, the paper's anchors) and the transplants of
/// 0425-traj2, 0426-traj1 and 0426-traj11 when data_dir holds them. `only` keeps names containing it.
std::vector<SignatureFlight> signatureFlights(const std::string& data_dir, const std::string& only = "");

/// Seed of one vibration draw of a cell: a function of the flight's and the cell's names and the draw's index alone
/// (FNV-1a), so a cell draws the same whether the whole matrix runs or `--only` picks it.
std::uint64_t signatureSeed(const std::string& flight, const std::string& cell, int draw);

/// Localizes the flight with the cell's signature (the vibration drawn from `seed`) and compares it with `plain`,
/// the run on the flight as it is.
SignatureRow evaluateSignature(const SignatureFlight& flight, const SignatureCell& cell, const LocalizationRun& plain,
                               const LocalizationOptions& options, std::uint64_t seed);

/// The cell over `draws` vibration draws (signatureSeed(flight, cell, 0 … draws − 1)), reported by its worst draw in
/// each figure (largest ratio, time on the floor and TDoA overrules; smallest in-flight fraction and 2σ coverage per
/// axis); it passes when every draw passes. One draw is a sample of a random vibration: a cell that passes one
/// draw and fails the next sits at a cliff edge.
SignatureRow evaluateSignatureDraws(const SignatureFlight& flight, const SignatureCell& cell,
                                    const LocalizationRun& plain, const LocalizationOptions& options, int draws);

}  // namespace uwb
