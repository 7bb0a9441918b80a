/** @file ImuSignature.h
 *  @brief Another drone's IMU on a flight: rotor vibration in flight, a floor with the motors off or idling, another
 *         rate, turn-on biases and a lag of the IMU's stamps behind the TDoA (docs/math/simulation.md S24).
 *
 *  Applied to a simulated flight or to a real one (a transplant): the flight's own IMU is first low-passed (a centred
 *  moving mean over smooth_s, which keeps the manoeuvres and drops the rotor band), then vibration of the asked RMS is
 *  added by phase. Airborne and floor are read from the flight's ground-truth height against its floor level (the 2nd
 *  percentile of the pose heights). The TDoA, pose and other streams are left as they are. A hand-held floor turns the
 *  body about its origin (the pose keeps it still): the gyro sees the wobble's rate and the accelerometer the gravity
 *  that swings with it, so that the two agree with a tag that stays put.
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "uwb/core/Types.h"
#include "uwb/io/Flight.h"

namespace uwb::sim {

enum class FloorImu : unsigned char {
  kUnchanged,  ///< the flight's own floor phases, untouched
  kMotorsOff,  ///< quiet: white noise of a still MEMS IMU
  kIdle,       ///< motors idling on the floor: vibration of floor_gyro_vib_rms_radps / floor_acc_vib_rms_mps2
  kHandHeld,   ///< motors off, held in a hand: an attitude wobble of floor_gyro_vib_rms_radps, gravity swinging with it
};
std::string toString(FloorImu floor);

struct ImuSignature {
  double flight_gyro_vib_rms_radps = 0.0;  ///< rotor vibration in flight, RMS of the norm (S24) [rad/s]
  double flight_acc_vib_rms_mps2 = 0.0;    ///< … of the accelerometer [m/s²]
  bool replace_flight = false;             ///< low-pass the flight phases before adding (a transplant)
  FloorImu floor = FloorImu::kUnchanged;
  double floor_gyro_vib_rms_radps = 0.0;   ///< idle vibration (kIdle) or the hand's wobble (kHandHeld) [rad/s]
  double floor_acc_vib_rms_mps2 = 0.0;     ///< idle vibration of the accelerometer (kIdle) [m/s²]
  double rate_hz = 0.0;                    ///< the IMU resampled to this rate (S24): block means below the logged
                                           ///< rate, linear interpolation above it; 0 = as logged
  Vec3 gyro_bias_radps = Vec3::Zero();     ///< added turn-on bias [rad/s]
  Vec3 acc_bias_mps2 = Vec3::Zero();       ///< [m/s²]
  double lag_s = 0.0;                      ///< the IMU's stamps lag the TDoA by this [s]
  double smooth_s = 0.01;                  ///< low-pass window of the transplant [s]
  double air_height_m = 0.15;              ///< airborne above the floor level + this [m]
  /// Throws std::invalid_argument naming the field.
  void validate() const;
  /// A short human-readable label, e.g. "gyro 20°/s, acc 0.005 g, floor off".
  std::string label() const;
};

/// The ground-truth height at t_s, linear between pose samples and held beyond the ends (pose sorted by time).
double truthHeightAt(const std::vector<PoseSample>& pose, double t_s);
/// The floor level of a flight: the 2nd percentile of its pose heights (S24). Throws on an empty pose.
double truthFloorLevel(const std::vector<PoseSample>& pose);

/// Applies the signature in place (S24). Vibration: three tones per axis at 150–240 Hz with random phases and a
/// quarter of broadband noise, scaled to the asked RMS of the norm; the draws come from `seed` only. Throws
/// std::invalid_argument when the flight has no pose (the phases are read from it) or no IMU.
void applyImuSignature(Flight& flight, const ImuSignature& signature, std::uint64_t seed);

}  // namespace uwb::sim
