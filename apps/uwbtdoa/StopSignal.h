/** @file StopSignal.h
 *  @brief SIGINT/SIGTERM as a stop request for the live commands (`stream`, `replay`): the handler only sets a flag
 *         (installed without SA_RESTART, so a blocking read returns); the command then flushes and exits 0. SIGPIPE
 *         is ignored so a closed consumer shows as a write error instead of killing the process.
 */
#pragma once

#include <csignal>

namespace uwb::app {

void installStopHandlers();
/// Set (non-zero) once SIGINT or SIGTERM arrived.
const volatile std::sig_atomic_t* stopFlag();

}  // namespace uwb::app
