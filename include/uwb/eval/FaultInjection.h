/** @file FaultInjection.h
 *  @brief Faults a flight or a radio link can have, applied to a recorded flight (the fault-injection suite of
 *         `uwbtdoa protocol --faults`): outlier bursts, garbage TDoA, a dead anchor, an anchor surveyed off, IMU
 *         dropouts, accelerometer clipping, a clock jump in one stream or in all, a TDoA clock offset, a survey
 *         shifted or of another arena.
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"

namespace uwb {

enum class FaultKind {
  kOutlierBurst,    ///< 20 % of the TDoA in the window get ±5 m
  kGarbageTdoa,     ///< every TDoA in the window uniform in [−10, 10] m
  kDeadAnchor,      ///< no TDoA of one anchor in the window
  kAnchorSurveyOff, ///< one anchor's surveyed position 1 m off (whole flight; the window is not used)
  kImuDropout,      ///< no accelerometer and gyroscope samples in the window
  kAccClipping,     ///< accelerometer saturated at ±1.2 g per axis in the window
  kClockJumpTdoa,   ///< the TDoA stamps from the window start on 0.5 s late
  kClockJumpAll,    ///< every stream's stamps from the window start on 5 s late (the truth moves with them)
  kClockOffsetTdoa, ///< the TDoA stamps 0.5 s late over the whole flight (window not used)
  kSurveyShifted,   ///< the whole survey shifted by 10 m along x (window not used)
  kSurveyOtherArena,///< the survey of another arena: each anchor id at the next anchor's position
};

struct FaultSpec {
  FaultKind kind = FaultKind::kOutlierBurst;
  double t0_s = 0.0;     ///< fault start [s]
  double t1_s = 0.0;     ///< fault end [s]
  int anchor_id = 0;     ///< kDeadAnchor, kAnchorSurveyOff
  std::uint64_t seed = 1;
};

/// The faults of the suite for a flight whose airborne part spans [t_air0, t_air1]: each placed mid-flight with its
/// usual length (bursts 5 s, dead anchor 10 s, IMU dropout 0.5 s, clipping 2 s).
std::vector<FaultSpec> standardFaults(double t_air0_s, double t_air1_s, int anchor_id);

std::string toString(FaultKind kind);

/// The flight and survey with the fault applied. Stamps stay sorted per stream.
void injectFault(const FaultSpec& fault, Flight& flight, AnchorSurvey& survey);

}  // namespace uwb
