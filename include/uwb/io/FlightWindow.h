/** @file FlightWindow.h
 *  @brief A flight cut to a time window: every stream keeps the samples with t0 ≤ t ≤ t1, as a log that starts
 *         and ends there would hold them (a log started in the air, stopped before landing).
 */
#pragma once

#include "uwb/io/Flight.h"

namespace uwb {

/// The samples of every stream of `flight` with t0_s ≤ t ≤ t1_s; stamps are kept (not shifted). Throws
/// std::invalid_argument unless both are finite and t0_s < t1_s (the one check of a window, for
/// the CLI's --window and Python's Flight.window as well).
Flight sliceFlight(const Flight& flight, double t0_s, double t1_s);

}  // namespace uwb
