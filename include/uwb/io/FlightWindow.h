/** @file FlightWindow.h
 *  @brief A flight cut to a time window: every stream keeps the samples with t0 ≤ t ≤ t1, as a log that starts
 *         and ends there would hold them (a log started in the air, stopped before landing).
 */
#pragma once

#include "uwb/io/Flight.h"

namespace uwb {

/// The samples of every stream of `flight` with t0_s ≤ t ≤ t1_s; stamps are kept (not shifted). Throws
/// std::invalid_argument when t0_s > t1_s or either is not finite.
Flight sliceFlight(const Flight& flight, double t0_s, double t1_s);

}  // namespace uwb
